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
