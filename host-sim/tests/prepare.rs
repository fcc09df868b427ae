//! `fvr prepare`: the files it writes parse and hold what was asked for,
//! and a budget overrun or bad flag is one line, exit 2, nothing written.

use std::path::Path;
use std::process::Command;

use fvr_core::fvrs::{Part, Precision};
use fvr_host::io::fvrs::FvrsFile;

fn fvr(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_fvr"))
        .current_dir(dir)
        .args(args)
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
        &[
            "prepare",
            "brainsmall",
            "--for",
            "m4f",
            "--emit",
            "c",
            "--out",
            "bs",
            "--filter",
            "kb3",
        ],
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
        &[
            "prepare",
            "brainsmall",
            "--for",
            "m4f",
            "--resample",
            "128",
            "--out",
            "x.fvrs",
        ],
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
        &[
            "prepare",
            "brainsmall",
            "--for",
            "m4f",
            "--resample",
            "64",
            "--emit",
            "bin",
            "--out",
            "x.bin",
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("of RAM") && err.contains("(524288)"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn host_f32_fvrs_and_bin_are_the_same_image() {
    let dir = tempdir();
    for (emit, out) in [("fvrs", "p.fvrs"), ("bin", "p.bin")] {
        let (code, err) = fvr(
            dir.path(),
            &[
                "prepare",
                "gaussians@32",
                "--for",
                "host",
                "--precision",
                "f32",
                "--filter",
                "kb4",
                "--emit",
                emit,
                "--out",
                out,
                "--quiet",
            ],
        );
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
    let cases: [&[&str]; 5] = [
        &["prepare", "gaussians@32", "--for", "m9", "--out", "a.fvrs"],
        &["prepare", "gaussians@32", "--for", "m4f", "--out", "a.png"],
        &[
            "prepare",
            "gaussians@32",
            "--for",
            "m4f",
            "--emit",
            "c",
            "--out",
            "a.txt",
        ],
        &[
            "prepare",
            "gaussians@32",
            "--for",
            "m4f",
            "--emit",
            "c",
            "--out",
            "9bad",
        ],
        &[
            "prepare",
            "gaussians@32",
            "--for",
            "m4f",
            "--precision",
            "q15",
            "--out",
            "a.fvrs",
        ],
    ];
    for args in cases {
        let (code, err) = fvr(dir.path(), args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains("error"), "{args:?}: {err}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_corrupt_file_is_named_in_one_line() {
    let dir = tempdir();
    let (code, err) = fvr(
        dir.path(),
        &[
            "prepare",
            "gaussians@32",
            "--for",
            "host",
            "--out",
            "p.fvrs",
            "--quiet",
        ],
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
