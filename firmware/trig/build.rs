//! Links `fvr-trig-bench` with `cortex-m-rt`'s `link.x` and `defmt.x`, and
//! with the memory layout of its target from the firmware's directory:
//! `memory-m3.x` for the Cortex-M3 (`thumbv7m-none-eabi`), `memory.x`
//! otherwise.

use std::env;
use std::fs;
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let target = env::var("TARGET").unwrap_or_default();
    println!("cargo:rerun-if-changed=build.rs");
    if !target.starts_with("thumb") {
        return;
    }
    let name = if target.starts_with("thumbv7m-") {
        "memory-m3.x"
    } else {
        "memory.x"
    };
    let layout = manifest.join("..").join(name);
    println!("cargo:rerun-if-changed={}", layout.display());
    let text = fs::read_to_string(&layout)
        .unwrap_or_else(|e| panic!("cannot read the memory layout {}: {e}", layout.display()));
    fs::write(out.join("memory.x"), text).expect("write memory.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
