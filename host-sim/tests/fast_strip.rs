//! The strip walk (`fvr_host::render::fast_strip`) against the core's
//! extraction (`fvr_core::slice::extract_slice_rows`): the same slice to
//! within the rounding of two sums of the same `W³` products,
//! `|strip − core| ≤ 2·(3W + 2)·ε·Σ|w·c|` at every point, `Σ|w·c|` being
//! the core's walk over `|c|` with `|k|`. Every filter width; f16 and f32 storage
//! with f32 arithmetic, f64 with f64; rows holding z, y and x (each with
//! its own strides); oblique and near-axis slices whose strips wrap
//! around the cube; physical-unit axes; power-of-two and mixed-radix
//! sides; one thread and several. Views whose rows hold no coordinate are
//! refused, and the renderer's image follows the walk it is given.

use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::{Sampling, SliceAxes, View};
use fvr_core::num::{Real, Sample};
use fvr_core::render::Request;
use fvr_core::slice::extract_slice_rows;
use fvr_core::spectrum::Spectrum;
use fvr_core::volume::GridOversampling;
use fvr_host::render::fast_slice::Tiling;
use fvr_host::render::fast_strip::{extract, held_axis};
use fvr_host::render::spectrum::{OwnedSpectrum, ViewRenderer};
use fvr_host::render::view::{render_once, Walk};
use fvr_host::sources::phantom::{sample, GaussianMixture};
use fvr_host::volume::Volume;
use half::f16;

/// Uniform values in `[−1, 1)` from a fixed-seed LCG: white noise, so the
/// spectrum has energy up to the cube's faces and wrapped taps carry
/// weight, and no mean, so that no DC coefficient dwarfs the others and
/// loosens the bound.
fn noise_volume(dims: [usize; 3], seed: u64) -> Volume {
    let mut state = seed;
    let data = (0..dims.iter().product::<usize>())
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        })
        .collect();
    Volume::new(dims, data)
}

/// Slice axes whose rows hold z (the default frame's), y and x, oblique
/// and near-axis, and rows along an axis (two held coordinates).
fn axes_list() -> Vec<(SliceAxes, usize)> {
    let unit = |v: [f64; 3]| {
        let l = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        v.map(|c| c / l)
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let with_up = |right: [f64; 3], dir: [f64; 3]| {
        let right = unit(right);
        SliceAxes {
            right,
            up: unit(cross(unit(dir), right)),
        }
    };
    let mut list = Vec::new();
    for dir in [
        [1.0, 0.3, 0.2],
        [0.02, -1.0, 0.01],
        [-0.4, 0.7, -0.6],
        [1.0, -1.0, 0.0],
    ] {
        let axes = Sampling::UNIT.slice_axes(&View::along(dir).frame().unwrap());
        list.push((axes, 2));
    }
    // Rows holding y, then x: right with a zero there, up completing the frame.
    list.push((with_up([0.8, 0.0, -0.6], [0.6, 0.1, 0.8]), 1));
    list.push((with_up([0.0, 0.3, 0.95], [0.5, -0.9, 0.3]), 0));
    list.push((with_up([1.0, 0.0, 0.0], [0.0, 0.4, 0.9]), 2));
    list
}

/// The core's slice and the strip's, on one thread and several (garbage
/// first: every point must be written), within the bound.
fn check<S: Sample, T: Real + Send + Sync>(spec: &OwnedSpectrum<S>, axes: &SliceAxes, what: &str) {
    let view = spec.view();
    let n = view.n();
    let filter = *view.filter();
    let kernel = KernelTable::<T>::new(filter);
    let mut core = vec![T::ZERO; n * n];
    extract_slice_rows(&view, &kernel, axes, 0, &mut core).unwrap();
    assert!(
        core.iter().filter(|v| v.to_f64() != 0.0).count() > n * n / 4,
        "{what}: the slice is mostly zero"
    );
    // Each point's Σ|w·c|: the core's walk in f64 over |c| with |k|.
    let abs_data: Vec<S> = view
        .data()
        .iter()
        .map(|&c| S::from_f64(c.to_f64().abs()))
        .collect();
    let abs_spec = Spectrum::from_parts(&abs_data, n, view.scale(), filter, view.dims()).unwrap();
    let exact = KernelTable::<f64>::new(filter);
    let abs_values: Vec<f64> = exact.values().iter().map(|v| v.abs()).collect();
    let abs_kernel = KernelTable::<f64>::from_values(filter, &abs_values).unwrap();
    let mut mass = vec![0.0f64; n * n];
    extract_slice_rows(&abs_spec, &abs_kernel, axes, 0, &mut mass).unwrap();
    // The two sums' rounding, with the f64 mass's own as margin.
    let gamma = 2.0 * (3.0 * filter.width() as f64 + 2.0) * 2.0 * T::EPSILON_HALF * 1.001;
    for parallel in [false, true] {
        let mut host = vec![T::from_f64(7.0); n * n];
        let tiling = Tiling::default();
        assert!(
            extract(&view, &kernel, axes, tiling, parallel, &mut host),
            "{what}"
        );
        let over = core
            .iter()
            .zip(&host)
            .zip(&mass)
            .filter(|((a, b), m)| (a.to_f64() - b.to_f64()).abs() > gamma * *m)
            .count();
        assert_eq!(
            over, 0,
            "{what}, parallel {parallel}: points beyond the bound"
        );
    }
}

#[test]
fn every_filter_and_held_axis_within_rounding_f16() {
    let n = 32;
    let volume = noise_volume([n; 3], 7);
    for kind in FilterKind::ALL {
        let filter = Filter::new(kind, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        for (axes, held) in axes_list() {
            assert_eq!(held_axis(&axes), Some(held), "{axes:?}");
            check::<f16, f32>(&spec, &axes, &format!("{kind:?} f16 {axes:?}"));
        }
    }
}

#[test]
fn f32_storage_and_f64_arithmetic_within_rounding() {
    let n = 16;
    let volume = noise_volume([n; 3], 11);
    for kind in [FilterKind::Kb3, FilterKind::Kb4, FilterKind::Kb6] {
        let filter = Filter::new(kind, 1).unwrap();
        let spec32 = OwnedSpectrum::<f32>::prepare::<f32>(&volume, filter).unwrap();
        let spec64 = OwnedSpectrum::<f64>::prepare::<f64>(&volume, filter).unwrap();
        for (axes, _) in axes_list() {
            check::<f32, f32>(&spec32, &axes, &format!("{kind:?} f32 {axes:?}"));
            check::<f64, f64>(&spec64, &axes, &format!("{kind:?} f64 {axes:?}"));
        }
    }
}

#[test]
fn physical_units_and_mixed_radix_sides_within_rounding() {
    let sampling = Sampling::new([0.7, 1.0, 1.9], 1.3).unwrap();
    let volume = noise_volume([32, 32, 32], 3);
    for kind in [FilterKind::Kb3, FilterKind::Kb4, FilterKind::Kb6] {
        for (grid, n) in [(GridOversampling::X1_25, 40), (GridOversampling::X1_5, 48)] {
            let filter = Filter::for_grid(kind, grid).unwrap();
            let spec = OwnedSpectrum::<f16>::prepare_on::<f32>(&volume, filter, n).unwrap();
            for dir in [[1.0, 0.3, 0.2], [0.0, -1.0, 0.0], [0.3, -0.9, 0.5]] {
                let axes = sampling.slice_axes(&View::along(dir).frame().unwrap());
                check::<f16, f32>(&spec, &axes, &format!("{kind:?} n {n} {dir:?}"));
            }
        }
    }
}

#[test]
fn rows_holding_no_coordinate_are_refused() {
    let n = 16;
    let volume = noise_volume([n; 3], 5);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
    let view = spec.view();
    let kernel = KernelTable::<f32>::new(filter);
    let axes = SliceAxes {
        right: [0.6, 0.64, 0.48],
        up: [-0.8, 0.48, 0.36],
    };
    assert_eq!(held_axis(&axes), None);
    let mut grid = vec![7.0f32; n * n];
    assert!(!extract(
        &view,
        &kernel,
        &axes,
        Tiling::default(),
        true,
        &mut grid
    ));
    assert!(grid.iter().all(|&v| v == 7.0), "a refused grid was written");
}

/// The renderer sums by the walk it is given: `Walk::Exact` is the
/// core's image bit for bit, `Walk::Strip` (the default) another rounding
/// of it, at least 100 dB from it on a phantom: 34 dB below f16 storage's
/// own floor (`2^−11`, 66 dB), so the walk never shows in a measured SNR.
#[test]
fn renderer_follows_its_walk() {
    let n = 64;
    let volume = sample(&GaussianMixture::random(5, n, 8), [n; 3]);
    let view = View::along([1.0, 0.3, 0.2]);
    for kind in [FilterKind::Kb4, FilterKind::Kb6] {
        let filter = Filter::new(kind, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        let render = |walk: Walk| {
            let mut out = vec![0.0f32; n * n];
            ViewRenderer::<f32>::new(n, filter)
                .with_walk(walk)
                .render_into(&spec, &view, n, n, &mut out)
                .unwrap();
            out
        };
        let core = render_once::<f16, f32>(&spec.view(), &Request::new(view, n, n)).unwrap();
        let exact = render(Walk::Exact);
        assert!(core
            .iter()
            .zip(&exact)
            .all(|(a, b)| a.to_bits() == (*b as f64).to_bits()));
        let strip = render(Walk::default());
        let (mut signal, mut noise) = (0.0f64, 0.0f64);
        for (a, b) in core.iter().zip(&strip) {
            signal += a * a;
            noise += (a - *b as f64).powi(2);
        }
        assert!(noise > 0.0, "{kind:?}: the strip walk was not used");
        let snr = 10.0 * (signal / noise).log10();
        assert!(snr >= 100.0, "{kind:?}: strip against core {snr:.1} dB");
    }
}
