//! Everyday names: output extensions in any case, and a misspelt VOLUME
//! answered with the nearest names.

mod common;
use common::{assert_error, fvr_line, fvr_ok, temp_dir};

#[test]
fn output_extensions_are_case_insensitive_and_the_name_is_kept() {
    let dir = temp_dir("names-ext");
    for out in ["x.PNG", "x.Nrrd"] {
        let line = format!("render sphere@16 --dir 1,0,0 --out {out} --quiet");
        fvr_ok(&line, &dir);
        assert!(dir.join(out).is_file(), "{out} not written");
    }
    assert_eq!(&std::fs::read(dir.join("x.PNG")).unwrap()[1..4], b"PNG");
    assert!(std::fs::read(dir.join("x.Nrrd"))
        .unwrap()
        .starts_with(b"NRRD"));
    fvr_ok(
        "turntable sphere@16 --frames 2 --out spin.APNG --quiet",
        &dir,
    );
    assert!(dir.join("spin.APNG").is_file());
    fvr_ok("convert sphere@8 --out v.NRRD --quiet", &dir);
    assert!(dir.join("v.NRRD").is_file());
}

fn one_line_error(out: &std::process::Output, needles: &[&str]) {
    assert_error(out, needles);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.len() < 200, "short: {err}");
    assert!(!err.contains("left out"), "{err}");
}

#[test]
fn a_misspelt_volume_gets_the_nearest_name() {
    let dir = temp_dir("names-near");
    std::fs::write(dir.join("mni152.nii.gz"), b"").unwrap();
    let out = fvr_line("render mni152.nii --dir 1,0,0 --out x.png", &dir);
    one_line_error(
        &out,
        &["fvr: error: no such file or volume `mni152.nii`; did you mean `mni152.nii.gz`?"],
    );
    let out = fvr_line("render brainsmal --dir 1,0,0 --out x.png", &dir);
    one_line_error(&out, &["did you mean `brainsmall`?"]);
    let out = fvr_line("render sphre@16 --dir 1,0,0 --out x.png", &dir);
    one_line_error(&out, &["did you mean `sphere@16`?"]);
    // A file in another directory: the suggestion keeps the directory.
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(dir.join("sub/head.nrrd"), b"").unwrap();
    let out = fvr_line("render sub/haed.nrrd --dir 1,0,0 --out x.png", &dir);
    one_line_error(&out, &["did you mean `sub/head.nrrd`?"]);
    // Nothing close: no suggestion, one line (the lists it could be).
    let out = fvr_line("render zzzqqq --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["no such file or volume `zzzqqq`", "neither a file"]);
    assert_eq!(String::from_utf8_lossy(&out.stderr).lines().count(), 1);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("did you mean"));
}

#[test]
fn parser_errors_are_one_line_in_the_projects_form() {
    let dir = temp_dir("names-parser");
    for (line, needles) in [
        (
            "render --bogus",
            &["unexpected argument '--bogus'", "usage: fvr render"][..],
        ),
        (
            "render brainsmall --dir nan,0,0 --out x.png",
            &["'--dir", "finite"][..],
        ),
        (
            "render brainsmall",
            &["not provided", "--dir", "--out", "usage:"][..],
        ),
        ("turntable", &["not provided", "usage: fvr turntable"][..]),
        ("rendr", &["unrecognized subcommand 'rendr'", "render"][..]),
    ] {
        let out = fvr_line(line, &dir);
        one_line_error(&out, needles);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("fvr: error: "), "{line}: {err}");
        assert!(!err.contains("error: error"), "{line}: {err}");
    }
    // Help is not an error: whole, on stdout, exit 0.
    let help = fvr_line("render --help", &dir);
    assert!(help.status.success());
    assert!(String::from_utf8_lossy(&help.stdout).lines().count() > 20);
}
