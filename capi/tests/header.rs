//! `capi/include/fvr.h` is what cbindgen makes of the crate now. With
//! `FVR_BLESS=1` the test writes it instead.

use std::path::Path;

#[test]
fn the_committed_header_is_current() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let config = cbindgen::Config::from_file(Path::new(dir).join("cbindgen.toml")).unwrap();
    let mut made = Vec::new();
    cbindgen::Builder::new()
        .with_crate(dir)
        .with_config(config)
        .generate()
        .expect("cbindgen parses capi/src")
        .write(&mut made);
    let made = String::from_utf8(made).unwrap();
    let path = Path::new(dir).join("include/fvr.h");
    if std::env::var_os("FVR_BLESS").is_some() {
        std::fs::write(&path, &made).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == made,
        "capi/include/fvr.h is not current: run `FVR_BLESS=1 cargo test -p fvr-capi --test header` and commit it"
    );
}
