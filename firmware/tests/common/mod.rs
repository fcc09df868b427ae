//! Host-side helpers shared by the firmware's integration tests.
#![allow(dead_code)] // each test binary uses a different part

use fvr_core::geometry::{center, Frame};
use fvr_firmware::scene::{Blob, FrameSpec, BLOBS, DIMS, IMAGE_SIDE};
use fvr_firmware::stored::{all, twiddles, StoredSpectrum};
use fvr_host::phantom::{Gaussian, Phantom};

/// The stored spectrum a frame renders from.
pub fn stored_for(spec: &FrameSpec) -> &'static StoredSpectrum {
    fvr_firmware::frame::spectrum_for(spec, &all()).expect("every stored filter is in all()")
}

/// The host core's image of a frame: `fvr_core::render::render` in f32 from
/// the same flash tables the firmware links.
pub fn host_image(spec: &FrameSpec) -> Vec<f32> {
    let stored = stored_for(spec);
    let spectrum = stored.spectrum().unwrap();
    let kernel = stored.kernel_table().unwrap();
    let tw = twiddles().unwrap();
    let n = spectrum.n();
    let mut grid = vec![0.0f32; fvr_core::render::grid_len(n)];
    let mut aux = vec![0.0f32; fvr_core::render::aux_len(n)];
    let mut out = vec![0.0f32; IMAGE_SIDE * IMAGE_SIDE];
    fvr_core::render::render(
        &spectrum, &kernel, &spec.view, IMAGE_SIDE, IMAGE_SIDE, &tw, &mut grid, &mut aux, &mut out,
    )
    .unwrap();
    out
}

fn gaussian(b: &Blob) -> Gaussian {
    Gaussian {
        amplitude: b.amplitude,
        center: b.center,
        sigmas: b.sigmas,
        rotation: b.rotation,
    }
}

/// Exact line integrals of the scene's phantom through every pixel.
pub fn exact_image(spec: &FrameSpec) -> Vec<f64> {
    let frame: Frame = spec.view.frame().unwrap();
    let blobs: Vec<Gaussian> = BLOBS.iter().map(gaussian).collect();
    let c = center(DIMS);
    let mut out = Vec::with_capacity(IMAGE_SIDE * IMAGE_SIDE);
    for row in 0..IMAGE_SIDE {
        for col in 0..IMAGE_SIDE {
            let p = frame.pixel_position(c, IMAGE_SIDE, IMAGE_SIDE, col as f64, row as f64);
            out.push(blobs.iter().map(|g| g.line_integral(p, frame.dir)).sum());
        }
    }
    out
}

/// SNR in dB of `img` against `reference`: 10·log10(Σref² / Σ(img − ref)²).
pub fn snr_db(reference: &[f64], img: &[f32]) -> f64 {
    let (mut s, mut e) = (0.0, 0.0);
    for (r, v) in reference.iter().zip(img) {
        s += r * r;
        e += (*v as f64 - r) * (*v as f64 - r);
    }
    10.0 * (s / e).log10()
}

/// The README's accuracy floor for a filter at oversampling 1 with f16
/// storage, against exact line integrals (tests/tests/projection.rs).
pub fn floor_db(filter: fvr_core::filter::FilterKind) -> f64 {
    use fvr_core::filter::FilterKind::*;
    match filter {
        Kb3 => 40.0,
        Kb4 => 50.0,
        Kb6 => 65.0,
        _ => unreachable!("the scene stores Kaiser–Bessel spectra only"),
    }
}
