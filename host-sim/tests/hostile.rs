//! Hostile requests: each is refused before any large allocation with one
//! line naming the problem (exit 2), never with an abort, and never by
//! touching an input or writing a non-finite image.

mod common;

use std::path::Path;

use common::{assert_error, assert_refused, fvr_line, temp_dir};
use fvr_host::io::nrrd::{encode_nrrd, Encoding::Raw, Endian::Little, SampleType::U8};

/// `line` run in `dir` exits 2 naming every needle and leaves no `output`.
fn refused(dir: &Path, line: &str, needles: &[&str], output: &str) {
    assert_error(&fvr_line(line, dir), needles);
    assert!(!dir.join(output).exists(), "`{line}` wrote {output}");
}

#[test]
fn images_larger_than_the_slice_are_refused_before_allocating() {
    let dir = temp_dir("hostile-size");
    let big = "--dir 1,0,0 --size 100000x100000 --out x.png";
    refused(
        &dir,
        &format!("render sphere@32 {big}"),
        &["100000"],
        "x.png",
    );
    refused(
        &dir,
        &format!("render sphere@32 {big} --preview-level 1"),
        &["100000"],
        "x.png",
    );
    let turn = "turntable sphere@32 --size 100000 --frames 2 --out t.apng";
    refused(&dir, turn, &["100000"], "t.apng");
}

#[test]
fn jobs_beyond_the_memory_limit_name_what_they_need() {
    let dir = temp_dir("hostile-memory");
    assert_refused(
        &dir,
        &[
            (
                "--max-memory 64M render sphere@32 --dir 1,0,0 --resample 2500 --out x.png",
                &["resampled volume", "--max-memory", "--resample"],
            ),
            (
                "--max-memory 1M turntable sphere@16 --frames 3600 --out t.apng",
                &["frames", "--frames"],
            ),
            (
                "--max-memory lots render sphere@16 --dir 1,0,0 --out x.png",
                &["--max-memory `lots`"],
            ),
        ],
    );
}

/// The address-space limit of `ulimit -v` is a memory limit too: under
/// 2 GiB, a 13.5 GB resampling is refused by name, not aborted.
#[test]
fn the_address_space_limit_is_respected() {
    let dir = temp_dir("hostile-rlimit");
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 2097152 && exec '{}' render sphere@32 --dir 1,0,0 --resample 1500 --out x.png",
            env!("CARGO_BIN_EXE_fvr")
        ))
        .current_dir(&dir)
        .output()
        .expect("sh runs");
    assert_error(&out, &["address-space limit", "resampled volume"]);
}

#[test]
fn accuracy_sizes_must_be_powers_of_two_in_range() {
    let dir = temp_dir("hostile-accuracy");
    assert_error(
        &fvr_line("accuracy --sizes 100000", &dir),
        &["100000", "power of two"],
    );
    assert_error(
        &fvr_line("accuracy --sizes 3", &dir),
        &["3 is not", "power of two"],
    );
}

#[test]
fn an_output_equal_to_the_input_is_refused_and_the_input_kept() {
    let dir = temp_dir("hostile-clobber");
    let bytes = encode_nrrd(&[8, 8, 8], U8, Raw, Little, &[3.0; 512]);
    std::fs::write(dir.join("vol.nrrd"), &bytes).unwrap();
    let out = fvr_line("render vol.nrrd --dir 1,0,0 --out vol.nrrd", &dir);
    assert_error(&out, &["vol.nrrd", "overwrite an input"]);
    let out = fvr_line("render vol.nrrd --dir 1,0,0 --out ./sub/../vol.nrrd", &dir);
    assert_eq!(out.status.code(), Some(2));
    let out = fvr_line("turntable vol.nrrd --frames 2 --out vol.nrrd", &dir);
    assert_error(&out, &["vol.nrrd", ".apng"]);
    assert_eq!(std::fs::read(dir.join("vol.nrrd")).unwrap(), bytes);
}

#[test]
fn overflowing_settings_never_write_a_non_finite_image() {
    let dir = temp_dir("hostile-overflow");
    let view = "render sphere@16 --dir 1,0,0 --out a.nrrd";
    let ambient = format!("{view} --ambient 1e308 --light 0,1,0:1,1,1");
    refused(&dir, &ambient, &["non-finite"], "a.nrrd");
    refused(
        &dir,
        &format!("{view} --light 0,1,0:1e308"),
        &["non-finite"],
        "a.nrrd",
    );
}

#[test]
fn endless_or_blocking_inputs_are_refused_by_kind() {
    let dir = temp_dir("hostile-devices");
    refused(
        &dir,
        "render /dev/zero --dir 1,0,0 --out x.png",
        &["/dev/zero", "not a regular file"],
        "x.png",
    );
    refused(
        &dir,
        "render --scene /dev/zero --out x.png",
        &["scene file", "not a regular file"],
        "x.png",
    );
    let cue = "render sphere@16 --dir 1,0,0 --depth-cue profile:@/dev/zero --out x.png";
    refused(&dir, cue, &["depth profile", "not a regular file"], "x.png");
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\
                  data file: /dev/zero\nbyte skip: 999999999999999\n\n";
    std::fs::write(dir.join("zero.nhdr"), header).unwrap();
    refused(
        &dir,
        "render zero.nhdr --dir 1,0,0 --out x.png",
        &["not a regular file"],
        "x.png",
    );
    let fifo = dir.join("fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        refused(
            &dir,
            "render fifo --dir 1,0,0 --out x.png",
            &["not a regular file"],
            "x.png",
        );
    }
}

#[test]
fn comparing_against_an_all_zero_image_is_an_error() {
    let dir = temp_dir("hostile-compare");
    let zero = "NRRD0004\ntype: float\ndimension: 2\nsizes: 2 2\nencoding: raw\nendian: little\n\n";
    let mut bytes = zero.as_bytes().to_vec();
    bytes.extend_from_slice(&[0u8; 16]);
    std::fs::write(dir.join("z.nrrd"), &bytes).unwrap();
    let out = fvr_line("compare z.nrrd z.nrrd", &dir);
    assert_error(&out, &["all zero", "undefined"]);
}

/// `--ambient -1` reaches the value check (as other numeric flags do) and
/// is refused there by name, not by the parser as an unknown argument.
#[test]
fn a_negative_ambient_is_refused_by_its_value() {
    let dir = temp_dir("hostile-ambient");
    let line = "render sphere@16 --dir 1,0,0 --ambient -1 --out x.nrrd";
    refused(&dir, line, &["ambient", "-1", "not allowed"], "x.nrrd");
}

/// A direction of huge components is the direction it points in, and
/// messages print such numbers short.
#[test]
fn extreme_view_vectors_keep_their_direction_and_short_messages() {
    let dir = temp_dir("hostile-extreme-dir");
    let huge = "render sphere@16 --dir 1e308,1e308,1e308 --out huge.nrrd";
    assert!(fvr_line(huge, &dir).status.success());
    assert!(
        fvr_line("render sphere@16 --dir 1,1,1 --out one.nrrd", &dir)
            .status
            .success()
    );
    let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
    assert_eq!(read("huge.nrrd"), read("one.nrrd"));
    let parallel = "render sphere@16 --dir 1e308,1e308,1e308 --up 1e308,1e308,1e308 --out x.png";
    let out = fvr_line(parallel, &dir);
    assert_error(&out, &["parallel", "1e308"]);
    assert!(
        out.stderr.len() < 200,
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A shared scene cannot write outside its own directory.
#[test]
fn scene_output_paths_stay_beside_the_scene() {
    let dir = temp_dir("hostile-scene-out");
    std::fs::create_dir_all(dir.join("scenes")).unwrap();
    std::fs::write(dir.join("victim.txt"), "keep me").unwrap();
    let scene =
        "[volume]\nbuiltin = \"sphere@16\"\n[turntable]\nframes = 2\npath = \"../victim.txt\"\n";
    std::fs::write(dir.join("scenes/s.toml"), scene).unwrap();
    let out = fvr_line("turntable --scene scenes/s.toml", &dir);
    assert_error(&out, &["turntable.path", "scene's directory"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("victim.txt")).unwrap(),
        "keep me"
    );
}
