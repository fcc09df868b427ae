//! `fvr-prepare-q15`: the Q15 spectrum prepared in integers on the device
//! from a u8 volume in flash, and the integer kb3 view rendered from it
//! (`fvr_firmware::prepare_q15`). Each target takes the largest cube its
//! RAM holds: 32³ on the Cortex-M4F (thumbv7em-none-eabihf, QEMU
//! mps2-an386, 512 KiB: a 64³ Q15 cube alone is all of it) and 64³ on the
//! Cortex-M3 (thumbv7m-none-eabi, QEMU mps2-an385, 4 MiB), which has no
//! FPU (`bash scripts/firmware.sh`).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(all(target_os = "none", target_abi = "eabihf"))]
fvr_firmware::prepare_q15_main!(
    "fvr-prepare-q15",
    fvr_firmware::prepare::PREP_32,
    fvr_firmware::prep_volume::M4F_SIDE
);

#[cfg(all(target_os = "none", not(target_abi = "eabihf")))]
fvr_firmware::prepare_q15_main!(
    "fvr-prepare-q15-m3",
    fvr_firmware::prepare::PREP_64,
    fvr_firmware::prep_volume::M7_SIDE
);

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "fvr-prepare-q15 runs on thumbv7em-none-eabihf (QEMU mps2-an386) or thumbv7m-none-eabi \
         (QEMU mps2-an385): bash scripts/firmware.sh"
    );
    std::process::exit(2);
}
