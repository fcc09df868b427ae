//! `fvr-filter-bench`: the plain view with kb3, kb4 and kb6, for instruction
//! counts, each image written to `fvr-filter-bench-<frame>.nrrd`. Runs on
//! thumbv7em-none-eabihf under QEMU (`bash scripts/firmware.sh`).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
fvr_firmware::firmware_main!(
    "fvr-filter-bench",
    fvr_firmware::scene::BENCH_FRAMES,
    [
        &fvr_firmware::stored::DENSITY_KB3,
        &fvr_firmware::stored::DENSITY_KB4,
        &fvr_firmware::stored::DENSITY_KB6
    ],
    []
);

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "fvr-filter-bench runs on thumbv7em-none-eabihf under QEMU: bash scripts/firmware.sh"
    );
    std::process::exit(2);
}
