//! `fvr-prepare`: the spectrum prepared on the Cortex-M4F (512 KiB of RAM)
//! from a 32³ u8 volume in flash, at the largest side that fits (32: a 64³
//! f16 cube alone would take all of the RAM), and the plain kb3 view
//! rendered from it (`fvr_firmware::prepare`). Runs on
//! thumbv7em-none-eabihf under QEMU mps2-an386 (`bash scripts/firmware.sh`).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
fvr_firmware::prepare_main!(
    "fvr-prepare",
    fvr_firmware::prepare::PREP_32,
    fvr_firmware::prep_volume::M4F_SIDE
);

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("fvr-prepare runs on thumbv7em-none-eabihf under QEMU: bash scripts/firmware.sh");
    std::process::exit(2);
}
