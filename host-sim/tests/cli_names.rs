//! Everyday names: output extensions in any case, and a misspelt VOLUME
//! answered with the nearest names.

mod common;
use common::{assert_ok, fvr_line, temp_dir};

#[test]
fn output_extensions_are_case_insensitive_and_the_name_is_kept() {
    let dir = temp_dir("names-ext");
    for out in ["x.PNG", "x.Nrrd"] {
        let line = format!("render sphere@16 --dir 1,0,0 --out {out} --quiet");
        assert_ok(&fvr_line(&line, &dir));
        assert!(dir.join(out).is_file(), "{out} not written");
    }
    assert_eq!(&std::fs::read(dir.join("x.PNG")).unwrap()[1..4], b"PNG");
    assert!(std::fs::read(dir.join("x.Nrrd")).unwrap().starts_with(b"NRRD"));
    assert_ok(&fvr_line(
        "turntable sphere@16 --frames 2 --out spin.APNG --quiet",
        &dir,
    ));
    assert!(dir.join("spin.APNG").is_file());
    assert_ok(&fvr_line("convert sphere@8 --out v.NRRD --quiet", &dir));
    assert!(dir.join("v.NRRD").is_file());
}
