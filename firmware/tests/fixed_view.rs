//! The Cortex-M3's integer view (`fvr_firmware::fixed_view`) on the host:
//! its agreement with the f64 pipeline and with exact line integrals.

mod common;

use common::{exact_image, host_image};
use fvr_core::dht::fixed::FixedTwiddles;
use fvr_core::dht::Twiddles;
use fvr_core::filter::KernelTable;
use fvr_core::image::{aux_len, grid_len};
use fvr_core::render::{render, Buffers, Request, Source};
use fvr_core::slice::fixed::FixedPhases;
use fvr_core::spectrum::{prepare_scratch_len, Spectrum};
use fvr_core::volume::DenseVolume;
use fvr_firmware::fixed_view::{render_view, ViewBuffers, AUX_LEN, GRID_LEN, WIDTH};
use fvr_firmware::frame::InstructionClock;
use fvr_firmware::scene::{density, DIMS, IMAGE_SIDE, SCENE_FRAMES, VIEW};
use fvr_firmware::stored::DENSITY_KB3;
use fvr_firmware::stored_q15::DENSITY_KB3_Q15;

struct NoClock;

impl InstructionClock for NoClock {
    fn now(&self) -> u64 {
        0
    }
}

/// The integer view's image in voxel units.
fn integer_image() -> Vec<f64> {
    let kernel = DENSITY_KB3.kernel_table().unwrap();
    let mut phases = Box::new(FixedPhases::<WIDTH>::zeroed(kernel.filter().clone()));
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
            grid: &mut grid,
            aux: &mut aux,
            block: &mut block,
            image: &mut image,
            staged: &mut staged,
        },
        &NoClock,
    )
    .unwrap();
    image
        .iter()
        .map(|&m| m as f64 * (exponent as f64).exp2())
        .collect()
}

/// The same view by the f64 pipeline: spectrum prepared in f64, f64 kernel
/// table and arithmetic.
fn f64_image() -> Vec<f64> {
    let [nx, ny, nz] = DIMS;
    let mut voxels = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                voxels.push(density([i as f64, j as f64, k as f64]) as f32);
            }
        }
    }
    let volume = DenseVolume::new(DIMS, &voxels).unwrap();
    let filter = DENSITY_KB3_Q15.filter().unwrap();
    let n = DENSITY_KB3_Q15.n;
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
    out
}

fn snr(reference: &[f64], got: &[f64]) -> f64 {
    let (mut s, mut e) = (0.0, 0.0);
    for (r, v) in reference.iter().zip(got) {
        s += r * r;
        e += (v - r) * (v - r);
    }
    10.0 * (s / e).log10()
}

#[test]
fn integer_view_agrees_with_f64() {
    let integer = integer_image();
    let f64_pipeline = f64_image();
    let exact = exact_image(&SCENE_FRAMES[0]);
    let f32_image: Vec<f64> = host_image(&SCENE_FRAMES[0])
        .iter()
        .map(|&v| v as f64)
        .collect();
    println!(
        "integer vs f64 pipeline {:.1} dB, vs exact {:.1} dB; f32 (f16 spectrum) vs f64 pipeline {:.1} dB, vs exact {:.1} dB; f64 pipeline vs exact {:.1} dB",
        snr(&f64_pipeline, &integer),
        snr(&exact, &integer),
        snr(&f64_pipeline, &f32_image),
        snr(&exact, &f32_image),
        snr(&exact, &f64_pipeline),
    );
}
