//! `fvr-scene`: the scene's frames with the paper's 3³ Kaiser–Bessel
//! filter: the plain X-ray view, a depth-cued view, a shaded view with three
//! coloured lights and one with both (`SCENE_FRAMES`), each written to
//! `fvr-scene-<frame>.nrrd` and pushed through the display sink. It links
//! the density and `|∇f|` spectra and the kernel-derivative table. Runs on
//! thumbv7em-none-eabihf under QEMU (`bash scripts/firmware.sh`).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
fvr_firmware::firmware_main!(
    "fvr-scene",
    fvr_firmware::scene::SCENE_FRAMES,
    [
        &fvr_firmware::stored::DENSITY_KB3,
        &fvr_firmware::stored::GRADIENT_KB3
    ],
    [&fvr_firmware::stored::DERIVATIVE_KB3]
);

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("fvr-scene runs on thumbv7em-none-eabihf under QEMU: bash scripts/firmware.sh");
    std::process::exit(2);
}
