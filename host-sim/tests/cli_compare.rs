//! `fvr compare`: `--json` (one object on stdout), `--min-db` (exit 1 below
//! it), identical images (infinite SNR as `null`), bad input (exit 2) and a
//! PNG given as an image (its bytes never echoed).

mod common;
use common::{assert_error, fvr_line, temp_dir};

use std::path::Path;

use fvr_host::io::nrrd::write_nrrd_f32;

/// A reference image and one with 1% noise-like error (SNR near 40 dB).
fn pair(dir: &Path) {
    let a: Vec<f32> = (0..64).map(|i| 1.0 + (i % 7) as f32).collect();
    let b: Vec<f32> = a
        .iter()
        .enumerate()
        .map(|(i, v)| v + if i % 2 == 0 { 0.04 } else { -0.04 })
        .collect();
    write_nrrd_f32(&dir.join("a.nrrd"), &[8, 8], &a).unwrap();
    write_nrrd_f32(&dir.join("b.nrrd"), &[8, 8], &b).unwrap();
}

fn json(stdout: &[u8]) -> serde_json::Value {
    let text = String::from_utf8_lossy(stdout);
    assert_eq!(text.lines().count(), 1, "one line of JSON: {text}");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}"))
}

#[test]
fn json_and_a_passing_threshold() {
    let dir = temp_dir("compare-pass");
    pair(&dir);
    let out = fvr_line("compare a.nrrd b.nrrd --json --min-db 30", &dir);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let v = json(&out.stdout);
    assert_eq!(v["a"], "a.nrrd");
    assert_eq!(v["b"], "b.nrrd");
    assert_eq!(v["width"], 8);
    assert_eq!(v["height"], 8);
    assert_eq!(v["identical"], false);
    assert_eq!(v["passed"], true);
    assert_eq!(v["min_db"], 30.0);
    let db = v["snr_db"].as_f64().unwrap();
    assert!((35.0..60.0).contains(&db), "{db}");
    let err = v["max_abs_error"].as_f64().unwrap();
    assert!((err - 0.04).abs() < 1e-4, "{err}");
    // Without --min-db: no `passed`.
    let out = fvr_line("compare a.nrrd b.nrrd --json", &dir);
    assert_eq!(out.status.code(), Some(0));
    let v = json(&out.stdout);
    assert!(v.get("passed").is_none(), "{v}");
    // The line form gates too.
    let out = fvr_line("compare a.nrrd b.nrrd --min-db 30", &dir);
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stdout).contains(" dB"));
}

#[test]
fn below_the_threshold_exits_1_with_one_line() {
    let dir = temp_dir("compare-fail");
    pair(&dir);
    for json_flag in ["", " --json"] {
        let out = fvr_line(
            &format!("compare a.nrrd b.nrrd --min-db 80{json_flag}"),
            &dir,
        );
        assert_eq!(out.status.code(), Some(1), "{out:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("fvr: compare: "), "{err}");
        assert!(err.contains("dB is below --min-db 80"), "{err}");
        if !json_flag.is_empty() {
            assert_eq!(json(&out.stdout)["passed"], false);
        }
    }
}

#[test]
fn identical_images_have_a_null_snr_and_pass() {
    let dir = temp_dir("compare-same");
    pair(&dir);
    let out = fvr_line("compare a.nrrd a.nrrd --json --min-db 1000", &dir);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let v = json(&out.stdout);
    assert!(v["snr_db"].is_null(), "{v}");
    assert_eq!(v["identical"], true);
    assert_eq!(v["passed"], true);
    assert_eq!(v["max_abs_error"], 0.0);
}

#[test]
fn bad_input_exits_2() {
    let dir = temp_dir("compare-bad");
    pair(&dir);
    let out = fvr_line("compare a.nrrd missing.nrrd --json --min-db 10", &dir);
    assert_error(&out, &["missing.nrrd"]);
    assert!(out.stdout.is_empty());
    let out = fvr_line("compare a.nrrd b.nrrd --min-db nan", &dir);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
}

/// A PNG is not a NRRD: the message quotes its first line in printable
/// ASCII only.
#[test]
fn a_png_is_refused_without_echoing_its_bytes() {
    let dir = temp_dir("compare-png");
    pair(&dir);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend_from_slice(&[0, 0, 0, 13, b'I', b'H', b'D', b'R', 0xff, 0xfe]);
    std::fs::write(dir.join("x.png"), &png).unwrap();
    let out = fvr_line("compare a.nrrd x.png", &dir);
    assert_error(&out, &["not a NRRD file", "PNG"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.chars()
            .all(|c| c == '\n' || c.is_ascii_graphic() || c == ' '),
        "non-printable or non-ASCII in: {err:?}"
    );
}

/// Two stacks of the same views from `fvr project` at different
/// accuracies: compared view by view, gated on the worst view, and a
/// stack refused as a volume to render. A colour image reports its width
/// and height, not its channel axis.
#[test]
fn stacks_of_views_are_compared_view_by_view() {
    let dir = temp_dir("compare-stacks");
    for (name, filter) in [("fine", "kb6 --oversample 2"), ("coarse", "linear")] {
        let cmd = format!(
            "project gaussians@32 --random 5 --seed 3 --filter {filter} --out {name}.nrrd --quiet"
        );
        let out = fvr_line(&cmd, &dir);
        assert_eq!(out.status.code(), Some(0), "{out:?}");
    }
    let out = fvr_line("compare fine.nrrd coarse.nrrd --json", &dir);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let v = json(&out.stdout);
    assert_eq!(v["views"], 5);
    // The same stacks as `.npy` (and one of each) give the same figures.
    for (name, filter) in [("fine", "kb6 --oversample 2"), ("coarse", "linear")] {
        let cmd = format!(
            "project gaussians@32 --random 5 --seed 3 --filter {filter} --out {name}.npy --quiet"
        );
        assert_eq!(fvr_line(&cmd, &dir).status.code(), Some(0));
    }
    for pair in ["fine.npy coarse.npy", "fine.nrrd coarse.npy"] {
        let w = json(&fvr_line(&format!("compare {pair} --json"), &dir).stdout);
        for key in [
            "views",
            "width",
            "height",
            "snr_db",
            "worst_view",
            "worst_view_db",
        ] {
            assert_eq!(w[key], v[key], "{pair}: {key}");
        }
    }
    assert_eq!(
        (v["width"].clone(), v["height"].clone()),
        (32.into(), 32.into())
    );
    let (db, worst) = (
        v["snr_db"].as_f64().unwrap(),
        v["worst_view_db"].as_f64().unwrap(),
    );
    let view = v["worst_view"].as_u64().unwrap();
    assert!(view < 5 && worst <= db && worst > 5.0, "{v}");
    // The gate is the worst view: between it and the whole stack's SNR, a
    // threshold fails.
    let between = format!(
        "compare fine.nrrd coarse.nrrd --min-db {}",
        (worst + db) / 2.0
    );
    let out = fvr_line(&between, &dir);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("worst view"), "{err}");
    let line = fvr_line("compare fine.nrrd coarse.nrrd", &dir);
    let text = String::from_utf8_lossy(&line.stdout);
    assert!(
        text.contains(&format!("worst of 5 views: {worst:.2} dB at view {view}")),
        "{text}"
    );
    // A stack is not a volume.
    let out = fvr_line("render fine.nrrd --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["axis 2 is `list`"]);

    let out = fvr_line(
        "render teapot@32 --dir 1,0.2,0 --light-ring 3 --out rgb.nrrd --quiet",
        &dir,
    );
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let v = json(&fvr_line("compare rgb.nrrd rgb.nrrd --json", &dir).stdout);
    assert_eq!(
        (v["width"].clone(), v["height"].clone(), v["views"].clone()),
        (32.into(), 32.into(), 1.into())
    );
}
