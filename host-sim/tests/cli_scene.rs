//! `fvr render` with depth cues and lights: RGB outputs, memory report, and
//! clear errors on bad scene values.

mod common;
use common::{assert_error, assert_ok, fvr, temp_dir};

use fvr_host::io::nrrd::read_nrrd;

const BASE: [&str; 5] = ["render", "gaussians@32", "--dir", "1,0.4,-0.3", "--stats"];

#[test]
fn lit_and_cued_render_writes_rgb_nrrd_and_reports_memory() {
    let dir = temp_dir("scene-rgb");
    let mut args = BASE.to_vec();
    args.extend([
        "--light",
        "0,1,0:1,0.2,0.1",
        "--light",
        "-1,-0.5,0.4:0.1,0.2,1",
        "--depth-cue",
        "linear:1,0.3",
        "--exact",
        "--out",
        "lit.nrrd",
    ]);
    let out = fvr(&args, &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_ok(&out);
    assert!(stdout.contains("RGB"), "{stdout}");
    assert!(stdout.contains("second spectrum"), "{stdout}");
    let image = fvr_host::io::nrrd::read_nrrd_image(&dir.join("lit.nrrd")).unwrap();
    assert_eq!(image.dims, [3, 32, 32]);
    assert!(image.data.iter().all(|v| v.is_finite()));
    // Red light from +y, blue from −x: the channels differ.
    let red: f64 = image.data.iter().step_by(3).map(|&v| v as f64).sum();
    let blue: f64 = image
        .data
        .iter()
        .skip(2)
        .step_by(3)
        .map(|&v| v as f64)
        .sum();
    assert!((red - blue).abs() > 1e-3 * red.abs().max(blue.abs()));
    let snr: f64 = stdout
        .lines()
        .find_map(|l| l.trim().strip_prefix("SNR vs exact"))
        .and_then(|v| v.trim().trim_end_matches("dB").trim().parse().ok())
        .expect("an SNR line");
    assert!(snr >= 45.0, "{stdout}");

    let mut plain = BASE.to_vec();
    plain.extend(["--out", "plain.png"]);
    let out = fvr(&plain, &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(stdout.contains("not built (no light needs it)"), "{stdout}");
}

#[test]
fn light_ring_and_profile_cue_render_png() {
    let dir = temp_dir("scene-ring");
    std::fs::write(dir.join("profile.txt"), "# front to back\n0.2, 1\n0.2\n").unwrap();
    let mut args = BASE.to_vec();
    args.extend([
        "--light-ring",
        "3:20",
        "--depth-cue",
        "profile:@profile.txt",
        "--out",
        "ring.png",
    ]);
    let out = fvr(&args, &dir);
    assert_ok(&out);
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.join("ring.png")).unwrap(),
    ));
    let reader = decoder.read_info().unwrap();
    assert_eq!(reader.info().color_type, png::ColorType::Rgb);
}

#[test]
fn bad_scene_values_exit_2_naming_the_problem() {
    let dir = temp_dir("scene-bad");
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["--light", "0,0,0:1,1,1"],
            vec!["light #0", "zero direction"],
        ),
        (vec!["--light", "0,1,0:1,-1,1"], vec!["light colour", "-1"]),
        (
            vec!["--light", "0,1,0:1,nan,1"],
            vec!["light colour", "NaN"],
        ),
        (vec!["--light", "0,1,0"], vec!["X,Y,Z:R,G,B"]),
        (vec!["--ambient", "1,2"], vec!["R,G,B"]),
        (
            vec!["--depth-cue", "linear:1,-0.5"],
            vec!["depth-cue weight", "-0.5"],
        ),
        (vec!["--depth-cue", "linear:1"], vec!["FRONT,BACK"]),
        (vec!["--depth-cue", "fog:1,0"], vec!["unknown depth cue"]),
        (vec!["--depth-cue", "profile:1"], vec!["2 to 64"]),
        (
            vec!["--depth-cue", "profile:@missing.txt"],
            vec!["missing.txt"],
        ),
        (
            vec!["--depth-cue", "profile:1,0", "--cue-harmonics", "40"],
            vec!["harmonics", "at most 16"],
        ),
        (
            vec!["--depth-cue", "linear:1,0", "--filter", "nearest"],
            vec!["nearest-neighbour kernel has no usable derivative"],
        ),
        (vec!["--light-ring", "9"], vec!["1 to 8"]),
        (
            vec!["--light-ring", "5", "--light-ring", "5"],
            vec!["cannot be used multiple times"],
        ),
        (
            vec!["--light-ring", "8", "--light", "0,1,0:1,1,1"],
            vec!["9 lights", "at most 8"],
        ),
    ];
    for (extra, needles) in cases {
        let mut args = BASE.to_vec();
        args.extend(extra.iter().copied());
        args.extend(["--out", "x.png"]);
        let out = fvr(&args, &dir);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{extra:?}: {stderr}");
        assert_error(&out, &needles);
    }
}

/// The number at `key`, at any depth, in the first line of `out` that is
/// a JSON object.
fn json_number(out: &str, key: &str) -> f64 {
    fn find(v: &serde_json::Value, key: &str) -> Option<f64> {
        match v {
            serde_json::Value::Object(map) => map
                .get(key)
                .and_then(|x| x.as_f64())
                .or_else(|| map.values().find_map(|x| find(x, key))),
            _ => None,
        }
    }
    out.lines()
        .filter(|l| l.starts_with('{'))
        .find_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .and_then(|v| find(&v, key))
        .unwrap_or_else(|| panic!("no number for {key} in {out}"))
}

#[test]
fn adaptive_and_preview_options_report_and_refuse_conflicts() {
    let dir = temp_dir("scene-adaptive");
    let base = [
        "render",
        "gaussians@32",
        "--dir",
        "1,0.3,0.2",
        "--oversample",
        "2",
    ];
    let mut args = base.to_vec();
    // The paper's 1³ filter with the exact bound (the search's regression
    // case, docs/adaptive.md), on the adaptive walk always (the plain
    // walk's image is the full one's).
    args.extend(["--adaptive", "40", "--adaptive-plain-below", "0"]);
    args.extend(["--adaptive-chain", "nearest", "--adaptive-bound", "exact"]);
    args.extend(["--stats-json", "--out", "a.nrrd"]);
    let out = fvr(&args, &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_ok(&out);
    let json = stdout
        .lines()
        .find(|l| l.starts_with('{'))
        .expect("a JSON line");
    for key in [
        "\"taps_ratio\"",
        "\"snr_vs_full_db\"",
        "\"levels\"",
        "\"marks_bytes\"",
        "\"bound\": \"exact\"",
        "\"error_field_db\"",
    ] {
        assert!(json.contains(key), "{key} not in {json}");
    }
    let snr = json_number(json, "snr_vs_full_db");
    assert!(snr >= 40.0, "{json}");

    // The defaults: the zero filter and Parseval's bound.
    let mut defaults = base.to_vec();
    defaults.extend(["--adaptive", "40", "--stats-json", "--out", "d.nrrd"]);
    let out = fvr(&defaults, &dir);
    assert_ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    for key in [
        "\"bound\": \"parseval\"",
        "\"filter\": \"zero\"",
        "\"probes\": 0",
        "\"error_field_evaluated\": false",
    ] {
        assert!(stdout.contains(key), "{key} not in {stdout}");
    }
    // Probes above Parseval's threshold: one or two transforms run, and
    // the image still meets the tolerance.
    let mut probed = base.to_vec();
    probed.extend(["--adaptive", "40", "--adaptive-probes", "2"]);
    probed.extend([
        "--adaptive-plain-below",
        "0",
        "--stats-json",
        "--out",
        "q.nrrd",
    ]);
    let out = fvr(&probed, &dir);
    assert_ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("\"probes\": 1") || stdout.contains("\"probes\": 2"),
        "{stdout}"
    );
    let snr = json_number(&stdout, "snr_vs_full_db");
    assert!(snr >= 40.0, "{stdout}");

    let mut preview = base.to_vec();
    preview.extend(["--preview-level", "1", "--out", "p.nrrd"]);
    let out = fvr(&preview, &dir);
    assert_ok(&out);
    // 32³ at oversampling 2: a 32² image by default, 16² at level 1.
    assert_eq!(read_nrrd(&dir.join("p.nrrd")).unwrap().dims, [16, 16, 1]);

    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (vec!["--adaptive", "0"], vec!["positive number of dB"]),
        (vec!["--adaptive", "abc"], vec!["positive number of dB"]),
        (vec!["--adaptive", "-3"], vec!["positive number of dB"]),
        (
            vec!["--adaptive", "40", "--adaptive-chain", "kb6"],
            vec!["not cheaper"],
        ),
        (
            vec!["--adaptive", "40", "--preview-level", "1"],
            vec!["cannot be combined"],
        ),
        (
            vec!["--adaptive", "40", "--light", "0,1,0:1,1,1"],
            vec!["plain X-ray views"],
        ),
        (vec!["--preview-level", "9"], vec!["progressive levels"]),
        (
            vec!["--adaptive", "40", "--adaptive-bound", "tight"],
            vec!["unknown adaptive bound", "tight"],
        ),
        (
            vec![
                "--adaptive",
                "40",
                "--adaptive-bound",
                "exact",
                "--adaptive-hd",
                "0.3",
            ],
            vec!["--adaptive-bound paper"],
        ),
    ];
    for (extra, needles) in cases {
        let mut a = base.to_vec();
        a.extend(extra.iter().copied());
        a.extend(["--out", "x.png"]);
        assert_error(&fvr(&a, &dir), &needles);
    }
}
