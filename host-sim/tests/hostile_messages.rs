//! Hostile values get short, right messages: no echo of a 5 MB key, no
//! 300-digit number, the right culprit named, and extreme but valid
//! settings handled instead of refused.

mod common;

use common::{assert_error, assert_ok, fvr_line, temp_dir};
use fvr_host::text::MAX_LINE_CHARS;

/// No line of stderr is longer than the bound (plus its marker).
fn short_lines(out: &std::process::Output) {
    let err = String::from_utf8_lossy(&out.stderr);
    for line in err.lines() {
        assert!(
            line.chars().count() <= MAX_LINE_CHARS + 40,
            "a line of {} characters",
            line.chars().count()
        );
    }
}

#[test]
fn huge_values_and_keys_are_not_echoed_whole() {
    let dir = temp_dir("messages-long");
    let digits = "1".repeat(100_000);
    let out = fvr_line(
        &format!("render sphere@16 --dir 1,0,0 --out x.png --resample {digits}"),
        &dir,
    );
    assert_error(&out, &["--resample", "characters left out"]);
    short_lines(&out);
    let key = "k".repeat(900_000);
    std::fs::write(dir.join("key.toml"), format!("[camera]\n{key} = 1\n")).unwrap();
    let out = fvr_line("render --scene key.toml", &dir);
    assert_error(&out, &["unknown key", "camera.kkk", "characters left out"]);
    short_lines(&out);
    std::fs::write(
        dir.join("num.toml"),
        format!("[camera]\ndir = [{digits}, 0, 0]\n"),
    )
    .unwrap();
    let out = fvr_line("render --scene num.toml", &dir);
    assert_error(&out, &["num.toml: not valid TOML at line 2, column 8"]);
    short_lines(&out);
    assert_eq!(String::from_utf8_lossy(&out.stderr).lines().count(), 1);
    let path = format!("{}.png", "p".repeat(5000));
    let out = fvr_line(&format!("render {path} --dir 1,0,0 --out x.png"), &dir);
    assert_error(&out, &["pppp"]);
    short_lines(&out);
}

#[test]
fn large_numbers_print_in_exponent_form() {
    let dir = temp_dir("messages-exp");
    std::fs::write(
        dir.join("s.toml"),
        "[camera]\ndir = [1, 0, 0]\nup = \"x\"\n[shading]\nambient = 1e300\n",
    )
    .unwrap();
    let out = fvr_line("render sphere@16 --scene s.toml --out x.png", &dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("000000000000"), "{err}");
    let out = fvr_line(
        "render sphere@16 --dir 1,0,0 --out x.png --depth-cue profile:1e300,0,1e-300",
        &dir,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("000000000000"), "{err}");
}

#[test]
fn raw_dims_overflow_names_raw_dims() {
    let dir = temp_dir("messages-raw");
    std::fs::write(dir.join("r.bin"), [0u8; 64]).unwrap();
    let out = fvr_line(
        "render r.bin --raw-dims 4294967296,4294967296,2 --raw-type u8 --dir 1,0,0 --out x.png",
        &dir,
    );
    assert_error(&out, &["--raw-dims 4294967296x4294967296x2", "overflows"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("NRRD"));
}

/// Voxels near 1e-38 cannot be scaled to f16's working range by f32
/// arithmetic: a clear error that says to rescale, not "overflow".
#[test]
fn tiny_voxels_get_their_own_message() {
    let dir = temp_dir("messages-tiny");
    let data: Vec<u8> = (0..64).flat_map(|_| 1e-38f32.to_le_bytes()).collect();
    std::fs::write(dir.join("t.raw"), data).unwrap();
    let out = fvr_line(
        "render t.raw --raw-dims 4,4,4 --raw-type f32 --dir 1,0,0 --out x.png",
        &dir,
    );
    assert_error(&out, &["magnitude", "rescale the voxel values"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("overflowed"));
}

/// Light directions are scaled before they are normalized, so components
/// of 1e-300 or 1e300 give a lit image, not a NaN one.
#[test]
fn extreme_light_directions_light_the_volume() {
    let dir = temp_dir("messages-light");
    for light in [
        "1e-300,0,0:1",
        "1e300,1e300,0:1",
        "-1e-300,1e-300,0:1,0.5,0.2",
    ] {
        let out = fvr_line(
            &format!("render sphere@16 --dir 0,0,1 --up 0,1,0 --out x.nrrd --light {light}"),
            &dir,
        );
        assert_ok(&out);
        let img = fvr_host::io::nrrd::read_nrrd_image(&dir.join("x.nrrd")).unwrap();
        assert!(img.data.iter().all(|v| v.is_finite()), "{light}");
        assert!(img.data.iter().any(|&v| v > 0.0), "{light}: a dark image");
    }
}
