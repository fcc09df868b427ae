//! What the per-view transcendental functions (`fvr_firmware_trig`) cost
//! the image: the plain kb3 64² view of every benchmark filter, rendered by
//! the core's steps with the sub-pixel shift's phasors from the core's
//! `libm` f64, from `libm`'s f32 functions and from `micromath`, against
//! the core's own image. `fvr-trig-bench`
//! counts the same functions on the device (`bash scripts/firmware.sh`).

#[path = "../../tests/common/mod.rs"]
mod common;

use common::{host_image, snr_db, tables};
use fvr_core::geometry::Sampling;
use fvr_core::image::{aux_len, finish, grid_len, placement_on_axes, Crop, Placement};
use fvr_core::slice::extract_central_slice_on;
use fvr_firmware::scene::{FrameSpec, BENCH_FRAMES, IMAGE_SIDE};
use fvr_firmware::stored::twiddles;
use fvr_firmware_trig::{apply_phasors, phasors_len, shift_phasors, Trig};

/// `micromath`'s documented bound on its `sin` and `cos` errors.
const MICROMATH_TRIG_ERROR: f64 = 0.002;

/// The sub-pixel shift of the scene's view of an odd-sided volume
/// (`63³`), whose transform origin is half a voxel off its centre: the
/// stored 64³ spectra have none, so without it the core evaluates no phasor.
fn odd_volume_shift(spec: &FrameSpec) -> [f64; 2] {
    let axes = Sampling::UNIT.slice_axes(&spec.view.frame().unwrap());
    placement_on_axes([IMAGE_SIDE - 1; 3], &axes, IMAGE_SIDE, IMAGE_SIDE, 1.0).shift
}

/// The view of `spec` shifted by `shift`, by the core's steps (`render`'s:
/// extraction, shift, 2D inverse, crop) with the shift's phasors from
/// `trig`, or by the core's own `finish` for `None`.
fn image_with(spec: &FrameSpec, shift: [f64; 2], trig: Option<Trig>) -> Vec<f32> {
    let t = tables(spec);
    let spectrum = t.density.spectrum().unwrap();
    let kernel = t.density.kernel_table().unwrap();
    let tw = twiddles().unwrap();
    let n = spectrum.n();
    let sampling = Sampling::UNIT;
    let axes = sampling.slice_axes(&spec.view.frame().unwrap());
    let mut grid = vec![0.0f32; grid_len(n)];
    extract_central_slice_on(&spectrum, &kernel, &axes, n, &mut grid);
    let place = placement_on_axes(spectrum.dims(), &axes, IMAGE_SIDE, IMAGE_SIDE, 1.0);
    let finish_shift = match trig {
        None => shift,
        Some(trig) => {
            let mut table = vec![0.0f32; phasors_len(n)];
            shift_phasors(trig, n, shift, &mut table);
            apply_phasors(&mut grid, n, &table);
            [0.0, 0.0]
        }
    };
    let crop = Crop::new(
        Placement {
            shift: finish_shift,
            ..place
        },
        sampling.gain() / (spectrum.scale() * 1.0 * 1.0),
        IMAGE_SIDE,
        IMAGE_SIDE,
    );
    let mut aux = vec![0.0f32; aux_len(n)];
    let mut out = vec![0.0f32; IMAGE_SIDE * IMAGE_SIDE];
    finish(&mut grid, n, &crop, &tw, &mut aux, &mut out).unwrap();
    out
}

/// The scene's own view has no sub-pixel shift (64³, even): the core
/// evaluates no phasor per view there, and these steps give its image. With
/// a shift, the core's functions give the core's `finish` bit for bit, so
/// the other images differ from it by their functions alone.
#[test]
fn the_core_functions_give_the_core_image() {
    for spec in &BENCH_FRAMES {
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let unshifted = image_with(spec, [0.0, 0.0], None);
        assert_eq!(bits(&unshifted), bits(&host_image(spec)), "{}", spec.name);
        let shift = odd_volume_shift(spec);
        assert!(
            shift[0] != 0.0 && shift[1] != 0.0,
            "{}: {shift:?}",
            spec.name
        );
        let core = image_with(spec, shift, None);
        let steps = image_with(spec, shift, Some(Trig::LibmF64));
        assert_eq!(bits(&core), bits(&steps), "{}", spec.name);
    }
}

/// dB of each function set against the core's image of the shifted view.
/// Floors: f32 functions err by a few ulps of the phase and the
/// phasor, `(2·log₂m + 5)·ε` per value with the inverse's roundings;
/// micromath's phasor products by up to `4·0.002`.
#[test]
fn phasor_functions_against_the_core_image() {
    let m = IMAGE_SIDE as f64;
    let f32_floor = -20.0 * ((2.0 * m.log2() + 5.0) * f32::EPSILON as f64 / 2.0).log10();
    let micromath_floor = -20.0 * (4.0 * MICROMATH_TRIG_ERROR).log10();
    for spec in &BENCH_FRAMES {
        let shift = odd_volume_shift(spec);
        let core: Vec<f64> = image_with(spec, shift, None)
            .iter()
            .map(|&v| v as f64)
            .collect();
        for trig in Trig::ALL {
            let image = image_with(spec, shift, Some(trig));
            let lost = snr_db(&core, &image);
            println!(
                "{} shifted by ({:.3}, {:.3}) {}: {} against the core image",
                spec.name,
                shift[0],
                shift[1],
                trig.name(),
                if lost.is_infinite() {
                    "bit-identical".to_string()
                } else {
                    format!("{lost:.1} dB")
                },
            );
            let floor = match trig {
                Trig::LibmF64 => f64::INFINITY,
                Trig::LibmF32 => f32_floor,
                Trig::Micromath => micromath_floor,
            };
            assert!(
                lost >= floor,
                "{} {}: {lost:.1} dB < {floor:.1} dB",
                spec.name,
                trig.name()
            );
        }
    }
}

/// The square roots of the view frame and the lights: each function's
/// largest relative error over the arguments `fvr-trig-bench` times, and
/// micromath's against its f32 rounding floor.
#[test]
fn square_roots_against_f64() {
    let args: Vec<f64> = (1..=16).map(|i| 0.37 * i as f64).collect();
    for trig in Trig::ALL {
        let worst = args
            .iter()
            .map(|&x| (trig.sqrt(x) - libm::sqrt(x)).abs() / libm::sqrt(x))
            .fold(0.0, f64::max);
        println!("sqrt {}: largest relative error {worst:.2e}", trig.name());
        match trig {
            Trig::LibmF64 => assert_eq!(worst, 0.0),
            Trig::LibmF32 => assert!(worst <= f32::EPSILON as f64, "{worst:e}"),
            Trig::Micromath => assert!(worst > 0.0),
        }
    }
}
