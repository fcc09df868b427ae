//! `fvr prepare`: the files it writes parse and hold what was asked for,
//! and a budget overrun or bad flag is one line, exit 2, nothing written.

use std::path::Path;
use std::process::Command;

use fvr_core::fvrs::{Part, Precision};
use fvr_host::io::fvrs::FvrsFile;

/// Run `fvr` with the words of `line` (split at white space) in `dir`: the
/// exit code and stderr.
fn fvr(dir: &Path, line: &str) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_fvr"))
        .current_dir(dir)
        .args(line.split_whitespace())
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

#[test]
fn brainsmall_for_the_m4f_as_c_is_resampled_to_fit_and_parses() {
    let dir = tempdir();
    let (code, err) = fvr(
        dir.path(),
        "prepare brainsmall --for m4f --emit c --out bs --filter kb3",
    );
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("resampled to 64 x 64 x 42"), "{err}");
    let h = std::fs::read_to_string(dir.path().join("bs.h")).unwrap();
    let c = std::fs::read_to_string(dir.path().join("bs.c")).unwrap();
    assert!(h.contains("#define BS_LEN 530756u"), "{h}");
    assert!(h.contains("extern const uint8_t bs[BS_LEN];"));
    assert!(c.contains("_Alignas(64) const uint8_t bs[BS_LEN] = {"));
    // The array's bytes are an image that parses.
    let bytes: Vec<u8> = c
        .split("= {")
        .nth(1)
        .unwrap()
        .split(',')
        .filter_map(|t| t.trim().strip_prefix("0x"))
        .map(|t| u8::from_str_radix(t, 16).unwrap())
        .collect();
    assert_eq!(bytes.len(), 530_756);
    let file = FvrsFile::from_bytes(&bytes);
    let f = file.parse().unwrap();
    assert_eq!(f.header().n, 64);
    assert_eq!(f.header().part, Part::M4f);
    assert_eq!(f.header().precision, Precision::F16);
    assert_eq!(f.header().filter.kind().name(), "kb3");
    assert!(f.spectrum_f16().is_ok() && f.kernel().is_ok() && f.twiddles().is_ok());
}

#[test]
fn too_large_for_the_part_is_refused_with_the_numbers_before_writing() {
    let dir = tempdir();
    let (code, err) = fvr(
        dir.path(),
        "prepare brainsmall --for m4f --resample 128 --out x.fvrs",
    );
    assert_eq!(code, 2);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("fvr: error: brainsmall at 128 x 128 x 84 does not fit the m4f")
            && err.contains("of flash")
            && err.contains("the part has 2.0 MiB (2097152)"),
        "{err}"
    );
    // The RAM budget too: a 64-side image loaded into the M4F's RAM.
    let (code, err) = fvr(
        dir.path(),
        "prepare brainsmall --for m4f --resample 64 --emit bin --out x.bin",
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("of RAM") && err.contains("(524288)"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn host_f32_fvrs_and_bin_are_the_same_image() {
    let dir = tempdir();
    for (emit, out) in [("fvrs", "p.fvrs"), ("bin", "p.bin")] {
        let (code, err) = fvr(dir.path(), &format!("prepare gaussians@32 --for host --precision f32 --filter kb4 --emit {emit} --out {out} --quiet"));
        assert_eq!(code, 0, "{err}");
        assert!(err.is_empty(), "--quiet: {err}");
    }
    let a = std::fs::read(dir.path().join("p.fvrs")).unwrap();
    assert_eq!(a, std::fs::read(dir.path().join("p.bin")).unwrap());
    let file = FvrsFile::read(&dir.path().join("p.fvrs")).unwrap();
    let f = file.parse().unwrap();
    assert_eq!(f.header().precision, Precision::F32);
    assert_eq!(f.header().part, Part::Host);
    assert!(f.spectrum_f32().is_ok());
}

#[test]
fn bad_flags_are_one_line_and_write_nothing() {
    let dir = tempdir();
    for line in [
        "prepare gaussians@32 --for m9 --out a.fvrs",
        "prepare gaussians@32 --for m4f --out a.png",
        "prepare gaussians@32 --for m4f --emit c --out a.txt",
        "prepare gaussians@32 --for m4f --emit c --out 9bad",
        "prepare gaussians@32 --for m4f --precision q15 --out a.fvrs",
    ] {
        let (code, err) = fvr(dir.path(), line);
        assert_eq!(code, 2, "{line}: {err}");
        assert!(err.contains("error"), "{line}: {err}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_corrupt_file_is_named_in_one_line() {
    let dir = tempdir();
    let (code, err) = fvr(
        dir.path(),
        "prepare gaussians@32 --for host --out p.fvrs --quiet",
    );
    assert_eq!(code, 0, "{err}");
    let path = dir.path().join("p.fvrs");
    let mut bytes = std::fs::read(&path).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(&path, &bytes).unwrap();
    let e = FvrsFile::read(&path).err().unwrap();
    assert!(
        e.contains("p.fvrs") && e.contains("checksum mismatch in the twiddle section"),
        "{e}"
    );
    std::fs::write(&path, &bytes[..1000]).unwrap();
    let e = FvrsFile::read(&path).err().unwrap();
    assert!(e.contains("truncated"), "{e}");
}

/// `fvr render X.fvrs` renders the stored spectrum without the volume: the
/// same image, bit for bit, as `fvr render VOLUME --ignore-spacing` with the
/// filter, grid and precision the file holds (f16 and f32, two views, NRRD
/// and PNG); options that need the volume and corrupt files are one line,
/// exit 2, nothing written.
#[test]
fn a_prepared_spectrum_renders_as_the_volume_does() {
    let dir = tempdir();
    let d = dir.path();
    for (precision, filter) in [("f16", "kb4"), ("f32", "kb3")] {
        let file = format!("s-{precision}.fvrs");
        let (code, err) = fvr(d, &format!("prepare sphere@32 --for host --precision {precision} --filter {filter} --out {file} --quiet"));
        assert_eq!(code, 0, "{err}");
        for (k, view) in ["1,0.3,0.2", "0.2,-1,0.4"].into_iter().enumerate() {
            for ext in ["nrrd", "png"] {
                let (a, b) = (format!("a{k}.{ext}"), format!("b{k}.{ext}"));
                let (code, err) = fvr(d, &format!("render {file} --dir {view} --out {a}"));
                assert_eq!(code, 0, "{err}");
                let (code, err) = fvr(d, &format!("render sphere@32 --ignore-spacing --filter {filter} --oversample 1 --precision {precision} --dir {view} --out {b} --quiet"));
                assert_eq!(code, 0, "{err}");
                let (a, b) = (
                    std::fs::read(d.join(a)).unwrap(),
                    std::fs::read(d.join(b)).unwrap(),
                );
                assert!(a == b, "{precision} {filter} {view} {ext}: images differ");
            }
        }
    }
    // Only the JSON on stdout, in the stats schema's keys.
    let out = Command::new(env!("CARGO_BIN_EXE_fvr"))
        .current_dir(d)
        .args("render s-f16.fvrs --dir 1,0,0 --out j.png --stats-json".split_whitespace())
        .output()
        .unwrap();
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["spectrum_side"], 32);
    assert_eq!(json["precision"], "f16");
    assert_eq!(json["filter"], "kb4");
    assert_eq!(json["image"], serde_json::json!([32, 32, 1]));
    assert!(json["ms_per_view"].as_f64().unwrap() > 0.0);
    // Options that need the volume, and a corrupt file.
    for (option, needle) in [
        (
            "--light 1,0,0:1",
            "--light does not apply to a prepared spectrum",
        ),
        ("--filter kb6", "--filter does not apply"),
        ("--accuracy 60", "--accuracy does not apply"),
        ("--adaptive 40", "--adaptive does not apply"),
    ] {
        let line = format!("render s-f16.fvrs --dir 1,0,0 --out x.png {option}");
        let (code, err) = fvr(d, &line);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(needle), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!d.join("x.png").exists());
    }
    // The image and the spectrum's copy are budgeted before reading.
    let (code, err) = fvr(
        d,
        "--max-memory 64K render s-f16.fvrs --dir 1,0,0 --out x.png",
    );
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("s-f16.fvrs") && err.contains("--max-memory"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!d.join("x.png").exists());
    let mut bytes = std::fs::read(d.join("s-f16.fvrs")).unwrap();
    let last = bytes.len() - 100;
    bytes[last] ^= 1;
    std::fs::write(d.join("bad.fvrs"), bytes).unwrap();
    let (code, err) = fvr(d, "render bad.fvrs --dir 1,0,0 --out x.png");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("bad.fvrs") && err.contains("CRC"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!d.join("x.png").exists());
}
