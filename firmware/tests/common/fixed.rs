//! The Cortex-M3's integer view on the host, its f64 reference and the
//! SNR floor of its arithmetic (`tests/fixed_view.rs`, `tests/qemu_fixed.rs`).

use super::NoClock;
use fvr_core::dht::fixed::FixedTwiddles;
use fvr_core::dht::Twiddles;
use fvr_core::filter::KernelTable;
use fvr_core::image::fixed::FixedBuffers;
use fvr_core::image::{aux_len, grid_len};
use fvr_core::render::{render, Buffers, Request, Source};
use fvr_core::slice::extract_slice;
use fvr_core::slice::fixed::FixedPhases;
use fvr_core::spectrum::{prepare_scratch_len, Spectrum};
use fvr_core::volume::DenseVolume;
use fvr_firmware::fixed_view::{render_view, ViewBuffers, AUX_LEN, GRID_LEN, WIDTH};
use fvr_firmware::scene::{DIMS, IMAGE_SIDE, VIEW};
use fvr_firmware::stored::DENSITY_KB3;
use fvr_firmware::stored_q15::DENSITY_KB3_Q15;

/// The integer view as the device renders it: the image's exponent and
/// Q15 mantissas (`fvr_firmware::fixed_view::render_view`, phase table
/// from the f32 kernel table in flash, twiddles by `FixedTwiddles::new`).
pub fn integer_view() -> (i32, Vec<i16>) {
    let kernel = DENSITY_KB3.kernel_table().unwrap();
    let mut phases = Box::new(FixedPhases::<WIDTH>::new());
    phases.fill(&kernel).unwrap();
    let mut tw_buf = vec![0i16; FixedTwiddles::<i16>::buffer_len(IMAGE_SIDE)];
    let tw = FixedTwiddles::new(&mut tw_buf, IMAGE_SIDE).unwrap();
    let (mut grid, mut aux) = (vec![0i32; GRID_LEN], vec![0i32; AUX_LEN]);
    let mut block = vec![0i16; GRID_LEN];
    let (mut image, mut staged) = (vec![0i16; GRID_LEN], vec![0i16; GRID_LEN]);
    let (exponent, _) = render_view(
        &phases,
        &tw,
        ViewBuffers {
            view: FixedBuffers {
                grid: &mut grid,
                aux: &mut aux,
                block: &mut block,
                out: &mut image,
            },
            staged: &mut staged,
        },
        &NoClock,
    )
    .unwrap();
    (exponent, image)
}

/// Mantissas times `2^exponent`.
pub fn values(exponent: i32, mantissas: &[i16]) -> Vec<f64> {
    let scale = (exponent as f64).exp2();
    mantissas.iter().map(|&m| m as f64 * scale).collect()
}

/// The same view by the f64 pipeline (spectrum prepared in f64, f64
/// kernel table and arithmetic): the image and its slice.
pub fn f64_view() -> (Vec<f64>, Vec<f64>) {
    let voxels = super::phantom_voxels();
    let volume = DenseVolume::new(DIMS, &voxels).unwrap();
    let filter = DENSITY_KB3_Q15.filter().unwrap();
    let n = DENSITY_KB3_Q15.header.n;
    let mut tw_buf = vec![0.0f64; Twiddles::<f64>::buffer_len(n)];
    let tw = Twiddles::new(&mut tw_buf, n).unwrap();
    let mut scratch = vec![0.0f64; prepare_scratch_len(n)];
    let mut data = vec![0.0f64; n * n * n];
    let spec = Spectrum::prepare(&volume, filter, &mut data, &mut scratch, &tw).unwrap();
    let kernel = KernelTable::<f64>::new(filter);
    let (mut grid, mut aux) = (vec![0.0; grid_len(n)], vec![0.0; aux_len(n)]);
    let mut out = vec![0.0f64; IMAGE_SIDE * IMAGE_SIDE];
    render(
        &Source::new(&spec, &kernel, &tw),
        &Request::new(VIEW, IMAGE_SIDE, IMAGE_SIDE),
        Buffers::new(&mut grid, &mut aux, &mut out),
    )
    .unwrap();
    let mut slice = vec![0.0f64; grid_len(n)];
    extract_slice(&spec, &kernel, &VIEW.frame().unwrap(), &mut slice);
    (out, slice)
}

/// Peak over RMS of the nonzero values.
pub fn crest(v: &[f64]) -> f64 {
    let nonzero: Vec<f64> = v.iter().copied().filter(|x| *x != 0.0).collect();
    let peak = nonzero.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let rms = (nonzero.iter().map(|x| x * x).sum::<f64>() / nonzero.len() as f64).sqrt();
    peak / rms
}

/// The SNR floor of the integer view against the f64 pipeline, from the
/// error model of the Q15 transforms (`fvr_core::dht::fixed`'s tests):
/// `6.02·(F − 3) + 7.78 − 10·log10 L − 20·log10 κ` dB for `F = 15`. `L`
/// counts the roundings at the slice's Q15 scale: the `2·log₂n + 1` of the
/// inverse, the slice's rounding to Q15, and one each for the spectrum's
/// Q15 storage and the Q15 weights (each at most the slice's own rounding:
/// they are relative to the lines' and the kernel's peaks, which the slice's
/// peak does not exceed). `κ` is the worse crest factor of the f64 slice
/// and image.
pub fn integer_floor_db(slice: &[f64], image: &[f64]) -> f64 {
    let roundings = 2.0 * IMAGE_SIDE.trailing_zeros() as f64 + 4.0;
    let kappa = crest(slice).max(crest(image));
    6.0206 * 12.0 + 10.0 * 6f64.log10() - 10.0 * roundings.log10() - 20.0 * kappa.log10()
}
