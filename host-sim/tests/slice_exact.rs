//! The host extraction (`fvr_engine::slice::exact`) against the
//! core's (`fvr_core::slice::extract_slice_rows`): the same slice bit for
//! bit, for every filter width, f16 and f32 storage, f32 and f64
//! arithmetic, axis-aligned, oblique and wrap-heavy directions (slices
//! whose taps wrap around the cube at its faces, and near-axis ones whose
//! runs straddle x = n − 1 → 0), physical-unit axes that are not
//! orthonormal, and every tiling and thread split; on power-of-two and
//! on mixed-radix sides; from the linear spectrum and from bricked
//! copies of it (`fvr_engine::spectrum::bricks`).

mod common;

use common::lcg_noise;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::{Sampling, SliceAxes, View};
use fvr_core::num::{Real, Sample};
use fvr_core::render::Request;
use fvr_core::slice::extract_slice_rows;
use fvr_core::volume::GridOversampling;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::render::view::{render_once, Walk};
use fvr_engine::slice::exact::{extract, extract_bricked, supports, SliceJob, Tiling};
use fvr_engine::spectrum::bricks::Bricked;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::Volume;
use half::f16;

/// Uniform values in `[−0.5, 1.5)` from a fixed-seed LCG: white noise, so
/// the spectrum has energy up to the cube's faces and the wrapped taps
/// carry weight.
fn noise_volume(n: usize, seed: u64) -> Volume {
    lcg_noise([n; 3], seed, 0.5)
}

const DIRECTIONS: [[f64; 3]; 6] = [
    [0.0, -1.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 0.3, 0.2],
    [1.0, -1.0, 0.0],
    // Near-axis: rows run almost along x, so many x-runs straddle the
    // wrap from n − 1 to 0.
    [0.02, -1.0, 0.01],
    [-0.4, 0.7, -0.6],
];

fn axes_for(dir: [f64; 3], sampling: &Sampling) -> SliceAxes {
    sampling.slice_axes(&View::along(dir).frame().unwrap())
}

/// Bricks the tests copy spectra into, where they divide the side: cubes,
/// flat and tall ones, narrower and wider than every filter.
const BRICKS: [[usize; 3]; 3] = [[4, 4, 4], [16, 8, 4], [2, 8, 16]];

/// The core's slice over all rows, then the host's with `tiling`, from the
/// linear spectrum and from its bricked copies, compared bit for bit (as
/// f64 bit patterns: exact for f32 and f64 alike).
fn check<S: Sample, T: Real + Send + Sync>(
    spec: &OwnedSpectrum<S>,
    axes: &SliceAxes,
    tilings: &[Tiling],
    what: &str,
) {
    let view = spec.view();
    let n = view.n();
    let kernel = KernelTable::<T>::new(*view.filter());
    let mut core = vec![T::ZERO; n * n];
    extract_slice_rows(&view, &kernel, axes, 0, &mut core).unwrap();
    assert!(
        core.iter().filter(|v| v.to_f64() != 0.0).count() > n * n / 4,
        "{what}: the slice is mostly zero"
    );
    let bricked: Vec<Bricked<S>> = BRICKS
        .iter()
        .filter_map(|&b| Bricked::from_spectrum(&view, b))
        .collect();
    assert!(!bricked.is_empty() || n % 4 != 0, "{what}: no bricked copy");
    let differ = |host: &[T]| {
        core.iter()
            .zip(host)
            .filter(|(a, b)| a.to_f64().to_bits() != b.to_f64().to_bits())
            .count()
    };
    for &tiling in tilings {
        for parallel in [false, true] {
            // Garbage first: every point must be written.
            let mut host = vec![T::from_f64(7.0); n * n];
            let job = SliceJob::new(&view, &kernel, axes, tiling, parallel);
            assert!(extract(&job, &mut host));
            assert_eq!(differ(&host), 0, "{what}, {tiling:?}, parallel {parallel}");
            for copy in &bricked {
                let mut host = vec![T::from_f64(7.0); n * n];
                let job = SliceJob::new(copy, &kernel, axes, tiling, parallel);
                assert!(extract_bricked(&job, &mut host));
                let brick = copy.brick();
                let d = differ(&host);
                assert_eq!(d, 0, "{what}, {brick:?}, {tiling:?}, parallel {parallel}");
            }
        }
    }
}

const TILINGS: [Tiling; 4] = [
    Tiling::new(1, 1, 0),
    Tiling::new(3, 5, 1),
    Tiling::new(8, 32, 8),
    Tiling::new(1000, 1000, 1000),
];

#[test]
fn every_filter_and_direction_bit_identical_f16() {
    let n = 32;
    let volume = noise_volume(n, 7);
    for kind in FilterKind::ALL {
        let filter = Filter::new(kind, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        assert!(supports(&spec.view()));
        for dir in DIRECTIONS {
            let axes = axes_for(dir, &Sampling::UNIT);
            check::<f16, f32>(&spec, &axes, &TILINGS, &format!("{kind:?} f16 {dir:?}"));
        }
    }
}

#[test]
fn f32_storage_and_f64_arithmetic_bit_identical() {
    let n = 16;
    let volume = noise_volume(n, 11);
    for kind in [FilterKind::Kb3, FilterKind::Kb4, FilterKind::Kb6] {
        let filter = Filter::new(kind, 1).unwrap();
        let spec32 = OwnedSpectrum::<f32>::prepare::<f32>(&volume, filter).unwrap();
        let spec64 = OwnedSpectrum::<f64>::prepare::<f64>(&volume, filter).unwrap();
        for dir in DIRECTIONS {
            let axes = axes_for(dir, &Sampling::UNIT);
            check::<f32, f32>(&spec32, &axes, &TILINGS, &format!("{kind:?} f32 {dir:?}"));
            check::<f64, f64>(&spec64, &axes, &TILINGS, &format!("{kind:?} f64 {dir:?}"));
        }
    }
}

#[test]
fn physical_units_and_larger_cube_bit_identical() {
    let n = 64;
    let volume = noise_volume(n, 3);
    let sampling = Sampling::new([0.7, 1.0, 1.9], 1.3).unwrap();
    for kind in [FilterKind::Kb3, FilterKind::Kb4, FilterKind::Kb6] {
        let filter = Filter::new(kind, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        for dir in [[1.0, 0.3, 0.2], [0.0, -1.0, 0.0], [0.3, -0.9, 0.5]] {
            let axes = axes_for(dir, &sampling);
            check::<f16, f32>(&spec, &axes, &TILINGS[1..3], &format!("{kind:?} {dir:?}"));
        }
    }
}

/// The exact walk's renderer of side `n` with `filter`, on 0, 1 and 3
/// threads, renders `spec` along each of [`DIRECTIONS`] at `width × height`
/// as the core's single-threaded render does, bit for bit.
fn assert_renderer_is_core(
    spec: &OwnedSpectrum<f16>,
    n: usize,
    filter: Filter,
    (width, height): (usize, usize),
    what: &str,
) {
    for dir in DIRECTIONS {
        let view = View::along(dir);
        let request = Request::new(view, width, height);
        let core = render_once::<f16, f32>(&spec.view(), &request).unwrap();
        for threads in [0, 1, 3] {
            let mut out = vec![0.0f32; width * height];
            ViewRenderer::<f32>::new(n, filter)
                .with_threads(threads)
                .with_walk(Walk::Exact)
                .render_into(spec, &view, width, height, &mut out)
                .unwrap();
            for (a, b) in core.iter().zip(&out) {
                assert_eq!(a.to_bits(), (*b as f64).to_bits(), "{what} {dir:?}");
            }
        }
    }
}

/// The renderer's whole view (host extraction, then the core's finish)
/// equals the core's single-threaded render, pixel for pixel.
#[test]
fn renderer_image_equals_core_render() {
    let n = 32;
    let volume = noise_volume(n, 5);
    for kind in [FilterKind::Kb3, FilterKind::Kb4, FilterKind::Kb6] {
        let filter = Filter::new(kind, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        assert_renderer_is_core(&spec, n, filter, (24, 20), &format!("{kind:?}"));
    }
}

/// Even mixed-radix sides (`2^a·3^b·5^c`, the grids of σ = 1.25 and 1.5)
/// with their filters (`Filter::for_grid`): the same slice as the core's
/// mixed-radix walk, bit for bit, for kb3 … kb6, f16 and f32 storage, f32
/// and f64 arithmetic, on and off axis and near-axis.
#[test]
fn mixed_radix_sides_bit_identical() {
    for (n, dims, seed) in [(20, 16, 1), (40, 32, 2), (48, 32, 3), (80, 64, 4)] {
        let volume = noise_volume(dims, seed);
        for kind in [
            FilterKind::Kb3,
            FilterKind::Kb4,
            FilterKind::Kb5,
            FilterKind::Kb6,
        ] {
            let filter = Filter::for_grid(kind, GridOversampling::X1_25).unwrap();
            let spec16 = OwnedSpectrum::<f16>::prepare_on::<f32>(&volume, filter, n).unwrap();
            let spec32 = OwnedSpectrum::<f32>::prepare_on::<f32>(&volume, filter, n).unwrap();
            assert_eq!(spec16.n(), n);
            assert!(supports(&spec16.view()) && supports(&spec32.view()));
            for dir in DIRECTIONS {
                let axes = axes_for(dir, &Sampling::UNIT);
                let what = format!("n {n} {kind:?} {dir:?}");
                check::<f16, f32>(&spec16, &axes, &TILINGS, &format!("{what} f16"));
                check::<f32, f32>(&spec32, &axes, &TILINGS[1..3], &format!("{what} f32"));
            }
        }
    }
}

#[test]
fn mixed_radix_f64_and_physical_units_bit_identical() {
    let volume = noise_volume(32, 9);
    let sampling = Sampling::new([0.7, 1.0, 1.9], 1.3).unwrap();
    for kind in [FilterKind::Kb4, FilterKind::Kb6] {
        let filter = Filter::for_grid(kind, GridOversampling::X1_5).unwrap();
        let spec = OwnedSpectrum::<f64>::prepare_on::<f64>(&volume, filter, 48).unwrap();
        for dir in [[1.0, 0.3, 0.2], [0.3, -0.9, 0.5]] {
            for sampling in [Sampling::UNIT, sampling] {
                let axes = axes_for(dir, &sampling);
                check::<f64, f64>(&spec, &axes, &TILINGS[1..3], &format!("{kind:?} {dir:?}"));
            }
        }
    }
}

/// On a mixed side the renderer's whole view (host extraction, then the
/// core's mixed-radix finish) equals the core's single-threaded render.
#[test]
fn renderer_image_equals_core_render_on_mixed_sides() {
    let (n, volume) = (40, noise_volume(32, 13));
    for kind in [FilterKind::Kb3, FilterKind::Kb5] {
        let filter = Filter::for_grid(kind, GridOversampling::X1_25).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare_on::<f32>(&volume, filter, n).unwrap();
        assert_renderer_is_core(&spec, n, filter, (30, 28), &format!("{kind:?}"));
    }
}
