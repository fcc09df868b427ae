//! `fvr render` with depth cues and lights: RGB outputs, memory report, and
//! clear errors on bad scene values.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use fvr_host::nrrd::read_nrrd;

fn fvr(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fvr"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("fvr runs")
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fvr-cli-scene-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn assert_error(out: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "`{n}` not in: {stderr}");
    }
}

const BASE: [&str; 5] = ["render", "gaussians@32", "--dir", "1,0.4,-0.3", "--stats"];

#[test]
fn lit_and_cued_render_writes_rgb_nrrd_and_reports_memory() {
    let dir = temp_dir("rgb");
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("RGB"), "{stdout}");
    assert!(stdout.contains("second spectrum"), "{stdout}");
    let image = read_nrrd(&dir.join("lit.nrrd")).unwrap();
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
    let dir = temp_dir("ring");
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.join("ring.png")).unwrap(),
    ));
    let reader = decoder.read_info().unwrap();
    assert_eq!(reader.info().color_type, png::ColorType::Rgb);
}

#[test]
fn bad_scene_values_exit_2_naming_the_problem() {
    let dir = temp_dir("bad");
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
