//! Every file a job reads is protected, not only VOLUME: the data file of a
//! detached NRRD header, a data set named by `FVR_CT_HEAD`, a depth profile,
//! a scene's files. An output that is one of them is refused (exit 2, one
//! line) and the input is left as it was.

mod common;

use std::path::Path;
use std::process::Command;

use common::{assert_error, fvr_line, fvr_ok, temp_dir};

/// `line` in `dir` is refused as overwriting an input, `file` unchanged.
fn refused(dir: &Path, line: &str, file: &str) {
    let before = std::fs::read(dir.join(file)).unwrap();
    let out = fvr_line(line, dir);
    assert_error(&out, &["refusing to overwrite an input", file]);
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).lines().count(),
        1,
        "{line}"
    );
    assert_eq!(
        std::fs::read(dir.join(file)).unwrap(),
        before,
        "`{line}` changed {file}"
    );
}

/// A `.nhdr` whose samples are in `w.nrrd` (8³ bytes).
fn detached(dir: &Path) {
    std::fs::write(
        dir.join("h.nhdr"),
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 8 8 8\nencoding: raw\ndata file: w.nrrd\n\n",
    )
    .unwrap();
    let data: Vec<u8> = (0..512).map(|i| (i % 7) as u8).collect();
    std::fs::write(dir.join("w.nrrd"), data).unwrap();
}

#[test]
fn the_data_file_of_a_detached_header_is_an_input() {
    let dir = temp_dir("inputs-nhdr");
    detached(&dir);
    refused(&dir, "convert h.nhdr --out w.nrrd", "w.nrrd");
    refused(&dir, "render h.nhdr --dir 1,0,0 --out w.nrrd", "w.nrrd");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_depth_profile_is_an_input() {
    let dir = temp_dir("inputs-profile");
    std::fs::write(dir.join("w.nrrd"), "1, 0.5, 0.25\n").unwrap();
    refused(
        &dir,
        "render sphere@16 --dir 1,0,0 --depth-cue profile:@w.nrrd --out w.nrrd",
        "w.nrrd",
    );
    // The same through a scene file's depth cue.
    std::fs::write(
        dir.join("s.toml"),
        "[volume]\nbuiltin = \"sphere@16\"\n[camera]\ndir = [1, 0, 0]\n\
         [shading]\ndepth_cue = \"profile:@w.nrrd\"\n[output]\npath = \"w.nrrd\"\n",
    )
    .unwrap();
    refused(&dir, "render --scene s.toml", "w.nrrd");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_data_set_named_by_the_environment_is_an_input() {
    let dir = temp_dir("inputs-dataset");
    fvr_ok("convert sphere@16 --out head.nrrd", &dir);
    let before = std::fs::read(dir.join("head.nrrd")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_fvr"))
        .args(["render", "ct-head", "--dir", "1,0,0", "--out", "head.nrrd"])
        .env("FVR_CT_HEAD", dir.join("head.nrrd"))
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_error(&out, &["refusing to overwrite an input", "head.nrrd"]);
    assert_eq!(std::fs::read(dir.join("head.nrrd")).unwrap(), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A hard link to the input is the input.
#[test]
fn a_hard_link_to_an_input_is_the_input() {
    let dir = temp_dir("inputs-hardlink");
    fvr_ok("convert sphere@16 --out v.nrrd", &dir);
    std::fs::hard_link(dir.join("v.nrrd"), dir.join("alias.nrrd")).unwrap();
    refused(&dir, "convert v.nrrd --out alias.nrrd", "alias.nrrd");
    std::fs::remove_dir_all(&dir).unwrap();
}
