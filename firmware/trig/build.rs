//! Links `fvr-trig-bench` with the complete linker script of its part,
//! written to `OUT_DIR` by the firmware's `link_script.rs` (which says
//! why): the layout of the Cortex-M3 (`thumbv7m-none-eabi`),
//! `firmware/memory-m3.x`, or of the Cortex-M4F, the workspace root's
//! `memory.x`, followed by `cortex-m-rt`'s `link.x` without its
//! `INCLUDE memory.x`; and with `defmt.x`.

use std::env;
use std::path::PathBuf;

#[allow(dead_code)]
#[path = "../link_script.rs"]
mod link_script;

use link_script::{write_link_script, Part};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let target = env::var("TARGET").unwrap_or_default();
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../link_script.rs");
    if !target.starts_with("thumb") {
        return;
    }
    let firmware = manifest.parent().expect("firmware/trig is in firmware/");
    let script = write_link_script(&out, firmware, Part::of(&target, "fvr-trig-bench"));
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-T{}", script.display());
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
