//! The second round of hostile requests: non-finite outputs, wrong blame,
//! subnormal vectors, unbounded study counts, `--resample` limits and
//! output directories checked late. Each is refused with one line naming
//! the real cause (exit 2), before any work, writing nothing.

mod common;

use std::path::Path;

use common::{assert_error, fvr, fvr_line, fvr_ok, temp_dir};
use fvr_host::io::nrrd::{encode_nrrd, Encoding::Raw, Endian::Little, SampleType::F32};

/// `line` in `dir` exits 2 with one stderr line holding every needle and
/// none of `absent`, and leaves no `output`.
fn refused(dir: &Path, line: &str, needles: &[&str], absent: &[&str], output: &str) {
    let out = fvr_line(line, dir);
    assert_error(&out, needles);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "`{line}`: {err}");
    for a in absent {
        assert!(!err.contains(a), "`{line}` blames {a}: {err}");
    }
    assert!(!dir.join(output).exists(), "`{line}` wrote {output}");
}

/// Class 6: an f64 render whose pixels fit f64 but not the f32 of a NRRD
/// image is refused, and so is a `--background` that overflows f32.
#[test]
fn values_beyond_f32_are_never_written() {
    let dir = temp_dir("round2-f32");
    refused(
        &dir,
        "render sphere@16 --dir 1,0,0 --precision f64 --ambient 1e300 --out p.nrrd",
        &["non-finite", "--ambient"],
        &["--light", "--depth-cue"],
        "p.nrrd",
    );
    refused(
        &dir,
        "convert sphere@16 --background -1e308 --out c.nrrd",
        &["--background", "f32"],
        &[],
        "c.nrrd",
    );
}

/// Class 7: an overflow of a plain X-ray view blames the volume, not
/// options the user never gave.
#[test]
fn an_overflow_blames_only_what_was_given() {
    let dir = temp_dir("round2-blame");
    let values = vec![1e38; 16 * 16 * 16];
    std::fs::write(
        dir.join("hot.nrrd"),
        encode_nrrd(&[16, 16, 16], F32, Raw, Little, &values),
    )
    .unwrap();
    refused(
        &dir,
        "render hot.nrrd --dir 1,0,0 --precision f64 --out x.nrrd",
        &["volume"],
        &["--ambient", "--light", "--depth-cue"],
        "x.nrrd",
    );
}

/// Class 8: subnormal vectors pass a zero test but cannot be normalised;
/// they are refused up front, naming the option.
#[test]
fn subnormal_vectors_are_refused_by_name() {
    let dir = temp_dir("round2-subnormal");
    for (line, option) in [
        ("render sphere@16 --dir 1e-320,0,0 --out a.png", "--dir"),
        (
            "render sphere@16 --dir 1,0,0 --up 0,0,1e-320 --out a.png",
            "--up",
        ),
        (
            "render sphere@16 --dir 1,0,0 --light 1e-320,0,0:1 --out a.png",
            "--light",
        ),
        (
            "turntable sphere@16 --dir 1e-320,0,0 --frames 2 --out a.png",
            "--dir",
        ),
    ] {
        refused(&dir, line, &[option, "too short"], &["non-finite"], "a.png");
    }
    std::fs::write(
        dir.join("s.toml"),
        "[volume]\nbuiltin = \"sphere@16\"\n[camera]\ndir = [1e-320, 0, 0]\n\
         [output]\npath = \"a.png\"\n",
    )
    .unwrap();
    refused(
        &dir,
        "render --scene s.toml",
        &["camera.dir", "too short"],
        &[],
        "a.png",
    );
}

/// Class 9: the study commands bound their repetition counts (no abort on
/// a huge allocation), and `adaptive-table --runs 0` is refused like
/// `growth --runs 0`.
#[test]
fn study_counts_are_bounded() {
    let dir = temp_dir("round2-counts");
    for (line, option) in [
        (
            "trade --repeats 100000000000 --out-dir t",
            "--repeats 100000000000",
        ),
        (
            "growth --sizes 16,32 --runs 100000000000 --out-dir g",
            "--runs 100000000000",
        ),
        ("growth --sizes 16,32 --runs 0 --out-dir g", "--runs 0"),
        (
            "adaptive-table --volumes sphere@16 --runs 100000000000",
            "--runs 100000000000",
        ),
        ("adaptive-table --volumes sphere@16 --runs 0", "--runs 0"),
    ] {
        let out = fvr_line(line, &dir);
        assert_error(&out, &[option]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "`{line}`: {err}");
    }
}

/// Class 10: `--resample 0` names the option (not a petabyte budget), and
/// the command line refuses `--resample 1` as a scene does.
#[test]
fn resample_counts_agree_with_scenes() {
    let dir = temp_dir("round2-resample");
    for n in ["0", "1"] {
        refused(
            &dir,
            &format!("render sphere@16 --dir 1,0,0 --resample {n} --out a.png"),
            &[&format!("--resample {n}")],
            &["TiB"],
            "a.png",
        );
    }
    std::fs::write(
        dir.join("s.toml"),
        "[volume]\nbuiltin = \"sphere@16\"\nresample = 1\n[camera]\ndir = [1, 0, 0]\n\
         [output]\npath = \"a.png\"\n",
    )
    .unwrap();
    assert_error(&fvr_line("render --scene s.toml", &dir), &["resample"]);
}

/// Class 11: `growth` and `precision` check `--out-dir` before measuring
/// (nothing measured, one line).
#[test]
fn study_output_directories_are_checked_first() {
    let dir = temp_dir("round2-outdir");
    std::fs::write(dir.join("file"), b"not a directory").unwrap();
    for line in [
        "growth --sizes 16,32 --runs 1 --out-dir file/sub",
        "precision --volumes sphere@16 --formats f32 --out-dir file/sub",
        "trade --out-dir file/sub",
    ] {
        let out = fvr(&line.split(' ').collect::<Vec<_>>(), &dir);
        assert_error(&out, &["file/sub"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "`{line}` measured first: {err}");
    }
}

/// Class 13: namespace-prefixed collections count towards the plist depth
/// guard (55,000 levels of `<x:array>` once overflowed the stack).
#[test]
fn prefixed_plist_collections_are_depth_limited() {
    use fvr_host::io::inv3::parse_plist;
    for (open, close) in [
        ("<x:array>", "</x:array>"),
        ("<ns:dict>", "</ns:dict>"),
        ("<a:b:array >", "</a:b:array>"),
    ] {
        let deep = format!(
            "<plist>{}{}</plist>",
            open.repeat(55_000),
            close.repeat(55_000)
        );
        let e = parse_plist(&deep).unwrap_err();
        assert!(e.contains("nested deeper"), "{open}: {e}");
    }
    // A shallow prefixed document still parses.
    assert!(parse_plist("<plist><array><x:array></x:array></array></plist>").is_ok());
}

/// Class 14: a scene's depth profile stays in the scene's directory, and a
/// profile that is not numbers is never quoted (it may hold secrets).
#[test]
fn scene_profiles_are_confined_and_never_quoted() {
    let dir = temp_dir("round2-profile");
    std::fs::create_dir_all(dir.join("scene")).unwrap();
    std::fs::write(dir.join("secret.txt"), "API_TOKEN=hunter2hunter2\n").unwrap();
    std::fs::write(dir.join("scene/secret.txt"), "API_TOKEN=hunter2hunter2\n").unwrap();
    for (cue, needle) in [
        ("profile:@../secret.txt", "inside the scene's directory"),
        ("profile:@/etc/hostname", "inside the scene's directory"),
        ("profile:@secret.txt", "not a list of numbers"),
    ] {
        std::fs::write(
            dir.join("scene/s.toml"),
            format!(
                "[volume]\nbuiltin = \"sphere@16\"\n[camera]\ndir = [1, 0, 0]\n\
                 [shading]\ndepth_cue = \"{cue}\"\n[output]\npath = \"a.png\"\n"
            ),
        )
        .unwrap();
        refused(
            &dir,
            "render --scene scene/s.toml",
            &[needle],
            &["hunter2", "API_TOKEN"],
            "scene/a.png",
        );
    }
    refused(
        &dir,
        "render sphere@16 --dir 1,0,0 --depth-cue profile:@secret.txt --out a.png",
        &["secret.txt", "not a list of numbers"],
        &["hunter2", "API_TOKEN"],
        "a.png",
    );
}

/// Class 14, the scene's other input: `volume.path` stays in the scene's
/// directory too (a shared scene cannot read `/proc/self/environ` or a
/// file beside it); a volume given on the command line replaces it.
#[test]
fn scene_volumes_are_confined() {
    let dir = temp_dir("round2-volume");
    std::fs::create_dir_all(dir.join("scene/data")).unwrap();
    let vol = encode_nrrd(&[8, 8, 8], F32, Raw, Little, &[1.0; 512]);
    std::fs::write(dir.join("outside.nrrd"), &vol).unwrap();
    std::fs::write(dir.join("scene/data/inside.nrrd"), &vol).unwrap();
    let scene = |path: &str| {
        std::fs::write(
            dir.join("scene/s.toml"),
            format!(
                "[volume]\npath = \"{path}\"\n[camera]\ndir = [1, 0, 0]\n\
                 [output]\npath = \"a.png\"\n"
            ),
        )
        .unwrap();
    };
    for path in [
        "../outside.nrrd",
        "/proc/self/environ",
        "data/../../outside.nrrd",
    ] {
        scene(path);
        refused(
            &dir,
            "render --scene scene/s.toml",
            &["volume.path", "inside the scene's directory"],
            &[],
            "scene/a.png",
        );
    }
    scene("data/inside.nrrd");
    let ok = fvr_line("render --scene scene/s.toml --quiet", &dir);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    assert!(dir.join("scene/a.png").is_file());
    // The command line's VOLUME replaces a scene's path; the scene is still
    // checked whole, so a path outside it is refused even then.
    let ok = fvr_line("render outside.nrrd --scene scene/s.toml --quiet", &dir);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    std::fs::remove_file(dir.join("scene/a.png")).unwrap();
    scene("/proc/self/environ");
    refused(
        &dir,
        "render outside.nrrd --scene scene/s.toml",
        &["volume.path", "inside the scene's directory"],
        &[],
        "scene/a.png",
    );
}

/// Class 15: DICOM samples keep only their BitsStored low bits (0xF123 with
/// 12 bits stored is 0x123 = 291), and a raw file longer than `--raw-dims`
/// is refused like a shorter one.
#[test]
fn dicom_high_bits_are_masked_and_raw_sizes_must_match() {
    use fvr_host::io::dicom::{parse_slice, CtSlice};
    let pixels = [0xF123u16 as i16, 0x0123, 0x0FFF, 0];
    let mut bytes = CtSlice::axial([2, 2], &pixels).encode();
    // BitsStored 16 → 12, HighBit 15 → 11, PixelRepresentation 1 → 0
    // (explicit VR little endian: group, element, "US", length 2, value).
    for (element, value) in [(0x0101u16, 12u16), (0x0102, 11), (0x0103, 0)] {
        let mut key = vec![0x28, 0x00];
        key.extend(element.to_le_bytes());
        key.extend(b"US\x02\x00");
        let at = bytes
            .windows(key.len())
            .position(|w| w == key.as_slice())
            .expect("the element");
        bytes[at + 8..at + 10].copy_from_slice(&value.to_le_bytes());
    }
    let slice = parse_slice(&bytes).unwrap();
    assert_eq!(slice.pixels, [291.0, 291.0, 4095.0, 0.0]);

    let dir = temp_dir("round2-raw");
    std::fs::write(dir.join("r.raw"), vec![7u8; 1000]).unwrap();
    refused(
        &dir,
        "render r.raw --raw-dims 10,10,9 --dir 1,0,0 --out a.png",
        &["--raw-dims", "holds more"],
        &[],
        "a.png",
    );
    assert_error(
        &fvr_line(
            "render r.raw --raw-dims 10,10,11 --dir 1,0,0 --out a.png",
            &dir,
        ),
        &["truncated"],
    );
    fvr_ok(
        "render r.raw --raw-dims 10,10,10 --dir 1,0,0 --out a.png",
        &dir,
    );
}
