//! The firmware's images, rendered on a Cortex-M4F under QEMU, against the
//! host core's images of the same scene (plain, depth-cued and shaded, grey
//! and RGB): bit for bit, for the NRRD each frame wrote and for the display
//! bytes it pushed through the SPI sink. Each image's distance to its f64
//! reference is printed too.
//!
//! Needs the QEMU outputs, so it is ignored in `cargo test` and run by
//! `scripts/firmware.sh` as
//! `FVR_QEMU_OUT=<dir> cargo test -p fvr-firmware --test qemu_agreement -- --ignored`.

mod common;

use common::{count_differing, exact_image, host_image, qemu_out_dir, snr_db};
use fvr_firmware::capture::decode_frame;
use fvr_firmware::display::{rgb565, rgb565_gray, Window};
use fvr_firmware::scene::{IMAGE_SIDE, PROGRAMS};
use fvr_host::io::nrrd::parse_nrrd;

#[test]
#[ignore = "needs the firmware's QEMU outputs: bash scripts/firmware.sh"]
fn qemu_images_equal_host_images_bit_for_bit() {
    let dir = qemu_out_dir();
    let mut failures = Vec::new();
    for (program, frames) in PROGRAMS {
        for spec in frames {
            let host = host_image(spec);
            let path = dir.join(format!("{program}-{}.nrrd", spec.name));
            let bytes = std::fs::read(&path)
                .unwrap_or_else(|e| panic!("{}: {e} (did the firmware run?)", path.display()));
            let device = parse_nrrd(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let channels = spec.shading.channels();
            let dims = if channels == 1 {
                [IMAGE_SIDE, IMAGE_SIDE, 1]
            } else {
                [channels, IMAGE_SIDE, IMAGE_SIDE]
            };
            assert_eq!(device.dims, dims, "{}", path.display());
            assert_eq!(host.len(), device.data.len(), "{}", path.display());
            let differing = count_differing(&host, &device.data, f32::to_bits);
            let exact = exact_image(spec);
            let host_f64: Vec<f64> = host.iter().map(|&v| v as f64).collect();
            println!(
                "{program} {}: {differing} of {} values differ from the host core; \
                 QEMU vs host {}; QEMU vs its f64 reference {:.1} dB",
                spec.name,
                host.len(),
                if differing == 0 {
                    "bit-identical".to_string()
                } else {
                    format!("{:.1} dB", snr_db(&host_f64, &device.data))
                },
                snr_db(&exact, &device.data)
            );
            if differing != 0 {
                failures.push(format!(
                    "{program} {}: {differing} values differ",
                    spec.name
                ));
            }

            // The display path: what the SPI sink sent is the host image
            // through the same window, pixel for pixel.
            let spi = dir.join(format!("{program}-{}.spi", spec.name));
            let recording =
                std::fs::read(&spi).unwrap_or_else(|e| panic!("{}: {e}", spi.display()));
            let mut pixels = vec![0u16; host.len() / channels];
            let decoded = decode_frame(&recording, &mut pixels)
                .unwrap_or_else(|e| panic!("{}: {e:?}", spi.display()));
            let last = IMAGE_SIDE as u16 - 1;
            assert_eq!((decoded.columns, decoded.rows), ((0, last), (0, last)));
            let window = Window::fit(&host);
            let expected: Vec<u16> = host
                .chunks_exact(channels)
                .map(|p| match p {
                    [v] => rgb565_gray(window.gray(*v)),
                    [r, g, b] => rgb565(window.gray(*r), window.gray(*g), window.gray(*b)),
                    _ => unreachable!("1 or 3 channels"),
                })
                .collect();
            if pixels != expected {
                failures.push(format!("{program} {}: display bytes differ", spec.name));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
