//! `fvr-prepare-q15-m7`: the 64³ Q15 spectrum prepared in integers on a
//! Cortex-M7 with 1 MiB of RAM from a 64³ u8 volume in flash, and the
//! integer kb3 64² view rendered from it (`fvr_firmware::prepare_q15`).
//! Linked with memory-m7.x (build.rs, for every program named `*-m7`)
//! for thumbv7em-none-eabihf and run under QEMU mps2-an500
//! (`bash scripts/firmware.sh`).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
fvr_firmware::prepare_q15_main!(
    "fvr-prepare-q15-m7",
    fvr_firmware::prepare::PREP_64,
    fvr_firmware::prep_volume::M7_SIDE
);

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "fvr-prepare-q15-m7 runs on thumbv7em-none-eabihf (memory-m7.x) under QEMU mps2-an500: \
         bash scripts/firmware.sh"
    );
    std::process::exit(2);
}
