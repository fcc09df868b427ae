//! The strip walk (`fvr_engine::slice::strip`) and the column walk
//! (`fvr_engine::slice::column`) against the core's extraction
//! (`fvr_core::slice::extract_slice_rows`): the same slice to within the
//! rounding of two sums of the same `W³` products,
//! `|walk − core| ≤ 2·γ·Σ|w·c|` at every point, `Σ|w·c|` being the
//! core's walk over `|c|` with `|k|`, `γ = (3W + 2)·ε` for the strip and
//! `(3W + 8)·ε` for the column walk (its reflected weights' rounding).
//! Every filter width; f16 and f32 storage with f32 arithmetic, f64 with
//! f64; rows holding z, y and x and slices containing z, y and x (each
//! with its own strides); oblique, near-axis and axis-aligned slices whose
//! taps wrap around the cube; physical-unit axes; power-of-two and
//! mixed-radix sides; one thread and several. Views the walks do not serve
//! are refused, and the renderer's image follows the walk it is given.

mod common;

use common::lcg_noise;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::{Sampling, SliceAxes, View};
use fvr_core::num::{Real, Sample};
use fvr_core::render::Request;
use fvr_core::slice::extract_slice_rows;
use fvr_core::spectrum::Spectrum;
use fvr_core::volume::GridOversampling;
use fvr_engine::render::turntable::orbit;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::render::view::{render_once, Walk, WalkTaken};
use fvr_engine::slice::column::{self, column_axis};
use fvr_engine::slice::exact::{self, SliceJob, Tiling};
use fvr_engine::slice::strip::{self, held_axis};
use fvr_engine::spectrum::exchange::{exchange_xy, exchanged, rows_along_y};
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_engine::volume::Volume;
use half::f16;

/// Uniform values in `[−1, 1)` from a fixed-seed LCG: white noise, so the
/// spectrum has energy up to the cube's faces and wrapped taps carry
/// weight, and no mean, so that no DC coefficient dwarfs the others and
/// loosens the bound.
fn noise_volume(dims: [usize; 3], seed: u64) -> Volume {
    lcg_noise(dims, seed, 0.0)
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

/// Slice axes containing z (turntables about z: oblique, along an axis
/// and diagonal), y and x.
fn column_axes_list() -> Vec<(SliceAxes, usize)> {
    let mut list = Vec::new();
    for (up, dirs) in [
        (
            [0.0, 0.0, 1.0],
            vec![
                [0.0, -1.0, 0.0],
                [1.0, -0.3, 0.0],
                [-0.6, -0.8, 0.0],
                [1.0, 1.0, 0.0],
            ],
        ),
        (
            [0.0, 1.0, 0.0],
            vec![[0.3, 0.0, 1.0], [-1.0, 0.0, 0.05], [0.0, 0.0, 1.0]],
        ),
        (
            [1.0, 0.0, 0.0],
            vec![[0.0, 0.4, -0.9], [0.0, 1.0, 0.0], [0.0, -0.7, 0.7]],
        ),
    ] {
        let axis = up.iter().position(|&c| c == 1.0).unwrap();
        for dir in dirs {
            let axes = Sampling::UNIT.slice_axes(&View { dir, up }.frame().unwrap());
            list.push((axes, axis));
        }
    }
    list
}

/// The walk under test.
#[derive(Clone, Copy, Debug)]
enum Fast {
    Strip,
    Column,
    /// The strip walk on the spectrum with x and y exchanged, with the
    /// axes exchanged to match (`fvr_engine::spectrum::exchange`): also
    /// checked bit for bit against the strip walk on the spectrum itself.
    Exchanged,
    /// The exact walk with each point's sum reordered into lanes
    /// (`fvr_engine::slice::exact::extract_reordered`), on any plane.
    Reordered,
}

impl Fast {
    fn extract<S: Sample, T: Real + Send + Sync>(
        self,
        spec: &Spectrum<'_, S>,
        kernel: &KernelTable<T>,
        axes: &SliceAxes,
        parallel: bool,
        grid: &mut [T],
    ) -> bool {
        let tiling = Tiling::default();
        let job = SliceJob::new(spec, kernel, axes, tiling, parallel);
        match self {
            Self::Strip => strip::extract(&job, grid),
            Self::Column => column::extract(&job, grid, &mut Vec::new()),
            Self::Reordered => exact::extract_reordered(&job, grid),
            Self::Exchanged => {
                let n = spec.n();
                let data = exchange_xy(spec.data(), n).unwrap();
                let [a, b, c] = spec.dims();
                let swapped =
                    Spectrum::from_parts(&data, n, spec.scale(), *spec.filter(), [b, a, c])
                        .unwrap();
                let axes = exchanged(axes);
                let done = strip::extract_exchanged(
                    &SliceJob {
                        spec: &swapped,
                        axes: &axes,
                        ..job
                    },
                    grid,
                );
                // Summed as the strip walk sums on the spectrum itself.
                let mut linear = vec![T::from_f64(3.0); grid.len()];
                let unswapped = exchanged(&axes);
                assert!(strip::extract(
                    &SliceJob {
                        axes: &unswapped,
                        ..job
                    },
                    &mut linear
                ));
                assert!(grid
                    .iter()
                    .zip(&linear)
                    .all(|(a, b)| a.to_f64().to_bits() == b.to_f64().to_bits()));
                done
            }
        }
    }

    /// `γ / ε` for width `w`.
    fn sums(self, w: usize) -> f64 {
        match self {
            // The reordered sums round `2W + 4` times (`u = ε/2` each)
            // and the core's `3W + 1`: `(5W + 5)·u`, inside `(3W + 2)·ε`.
            Self::Strip | Self::Exchanged | Self::Reordered => 3.0 * w as f64 + 2.0,
            Self::Column => 3.0 * w as f64 + 8.0,
        }
    }
}

/// The core's slice and the walk's, on one thread and several (garbage
/// first: every point must be written), within the bound.
fn check<S: Sample, T: Real + Send + Sync>(
    fast: Fast,
    spec: &OwnedSpectrum<S>,
    axes: &SliceAxes,
    what: &str,
) {
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
    // Each point's Σ|w·c|: the core's walk over |c| with |k|, in `T` so
    // that it keeps the rows the core keeps (in f64 an up axis a rounding
    // longer than 1 drops row n/2 at the cube's face). Its own rounding,
    // at most 3W·ε of it, is inside the bound's 1.001 margin.
    let abs_data: Vec<S> = view
        .data()
        .iter()
        .map(|&c| S::from_f64(c.to_f64().abs()))
        .collect();
    let abs_spec = Spectrum::from_parts(&abs_data, n, view.scale(), filter, view.dims()).unwrap();
    let abs_values: Vec<T> = kernel
        .values()
        .iter()
        .map(|&v| T::from_f64(v.to_f64().abs()))
        .collect();
    let abs_kernel = KernelTable::<T>::from_values(filter, &abs_values).unwrap();
    let mut mass_t = vec![T::ZERO; n * n];
    extract_slice_rows(&abs_spec, &abs_kernel, axes, 0, &mut mass_t).unwrap();
    let mass: Vec<f64> = mass_t.iter().map(|m| m.to_f64()).collect();
    let gamma = 2.0 * fast.sums(filter.width()) * 2.0 * T::EPSILON_HALF * 1.001;
    for parallel in [false, true] {
        let mut host = vec![T::from_f64(7.0); n * n];
        assert!(
            fast.extract(&view, &kernel, axes, parallel, &mut host),
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
            check::<f16, f32>(Fast::Strip, &spec, &axes, &format!("{kind:?} f16 {axes:?}"));
            if held == 2 {
                let what = format!("{kind:?} exchanged f16 {axes:?}");
                check::<f16, f32>(Fast::Exchanged, &spec, &axes, &what);
            }
        }
        for (axes, axis) in column_axes_list() {
            assert_eq!(column_axis(&axes), Some(axis), "{axes:?}");
            let what = format!("{kind:?} column f16 {axes:?}");
            check::<f16, f32>(Fast::Column, &spec, &axes, &what);
        }
    }
}

/// The reordered exact walk on every plane the other walks take and on
/// those they refuse, every filter, a power-of-two and a mixed-radix side
/// with physical units; it declines where the core has no lanes for it
/// (binary16 in f32 only), leaving the grid as it was.
#[test]
fn reordered_sums_within_rounding_on_any_plane() {
    let volume = noise_volume([32; 3], 9);
    // Random rolls: no image axis holds a coordinate.
    let refused = [
        ([0.7, 0.2, 1.0], [0.3, 1.0, 0.1]),
        ([1.0, 0.35, -0.6], [0.2, -0.4, 1.0]),
        ([0.15, 0.8, -1.0], [1.0, 0.3, 0.4]),
    ]
    .map(|(dir, up)| {
        let view = View { dir, up };
        let axes = Sampling::UNIT.slice_axes(&view.frame().unwrap());
        assert_eq!(held_axis(&axes), None, "{view:?}");
        (axes, view)
    });
    let f32_spec = {
        let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
        OwnedSpectrum::<f32>::prepare::<f32>(&volume, filter).unwrap()
    };
    let (spec, kernel) = (
        f32_spec.view(),
        KernelTable::<f32>::new(*f32_spec.view().filter()),
    );
    let job = SliceJob::new(&spec, &kernel, &refused[0].0, Tiling::default(), true);
    let mut untouched = vec![5.0f32; 32 * 32];
    assert!(!exact::extract_reordered(&job, &mut untouched));
    assert!(untouched.iter().all(|&v| v == 5.0));
    if !exact::reorders::<f16, f32>() {
        eprintln!("this core has no F16C, AVX and FMA: the reordered walk declines");
        return;
    }
    for kind in FilterKind::ALL {
        let filter = Filter::new(kind, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        let planes = axes_list().into_iter().chain(column_axes_list());
        for axes in planes
            .map(|(a, _)| a)
            .chain(refused.iter().map(|(a, _)| *a))
        {
            let what = format!("{kind:?} reordered {axes:?}");
            check::<f16, f32>(Fast::Reordered, &spec, &axes, &what);
        }
    }
    let sampling = Sampling::new([0.7, 1.0, 1.9], 1.3).unwrap();
    for kind in [FilterKind::Kb3, FilterKind::Kb6] {
        let filter = Filter::for_grid(kind, GridOversampling::X1_25).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare_on::<f32>(&volume, filter, 40).unwrap();
        for (_, view) in &refused {
            let axes = sampling.slice_axes(&view.frame().unwrap());
            let what = format!("{kind:?} reordered n 40 {view:?}");
            check::<f16, f32>(Fast::Reordered, &spec, &axes, &what);
        }
    }
}

/// Every frame of a turntable about an axis, from a start square to it,
/// contains that axis exactly: the column walk serves the whole orbit.
#[test]
fn turntables_about_an_axis_contain_it_in_every_frame() {
    for (start, axis, a) in [
        ([0.0, -1.0, 0.0], [0.0, 0.0, 1.0], 2),
        ([1.0, 0.0, 0.3], [0.0, 1.0, 0.0], 1),
        ([0.0, 0.6, -0.8], [1.0, 0.0, 0.0], 0),
    ] {
        for view in orbit(start, axis, 37).unwrap() {
            let axes = Sampling::UNIT.slice_axes(&view.frame().unwrap());
            assert_eq!(column_axis(&axes), Some(a), "{view:?}");
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
            check::<f32, f32>(
                Fast::Strip,
                &spec32,
                &axes,
                &format!("{kind:?} f32 {axes:?}"),
            );
            check::<f64, f64>(
                Fast::Strip,
                &spec64,
                &axes,
                &format!("{kind:?} f64 {axes:?}"),
            );
        }
        for (axes, _) in column_axes_list() {
            let what = format!("{kind:?} column {axes:?}");
            check::<f32, f32>(Fast::Column, &spec32, &axes, &what);
            check::<f64, f64>(Fast::Column, &spec64, &axes, &what);
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
                check::<f16, f32>(
                    Fast::Strip,
                    &spec,
                    &axes,
                    &format!("{kind:?} n {n} {dir:?}"),
                );
                if held_axis(&axes) == Some(2) {
                    let what = format!("{kind:?} exchanged n {n} {dir:?}");
                    check::<f16, f32>(Fast::Exchanged, &spec, &axes, &what);
                }
            }
            for dir in [[0.0, -1.0, 0.0], [1.0, 0.3, 0.0], [0.3, -0.9, 0.0]] {
                let axes = sampling.slice_axes(&View::along(dir).frame().unwrap());
                assert_eq!(column_axis(&axes), Some(2), "{axes:?}");
                let what = format!("{kind:?} column n {n} {dir:?}");
                check::<f16, f32>(Fast::Column, &spec, &axes, &what);
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
    assert_eq!(column_axis(&axes), None);
    for fast in [Fast::Strip, Fast::Column] {
        assert!(!fast.extract(&view, &kernel, &axes, true, &mut grid));
        assert!(
            grid.iter().all(|&v| v == 7.0),
            "{fast:?}: a refused grid was written"
        );
    }
    // Rows holding z but the slice containing no axis: the strip walk's.
    let (axes, _) = axes_list().remove(0);
    assert_eq!(column_axis(&axes), None);
    assert!(!Fast::Column.extract(&view, &kernel, &axes, true, &mut grid));
    assert!(grid.iter().all(|&v| v == 7.0), "a refused grid was written");
}

/// The renderer sums by the walk it is given: `Walk::Exact` is the
/// core's image bit for bit, `Walk::Strip` (the default: the column walk
/// on a slice containing an axis, else the strip walk) the same or another
/// rounding of it, at least 100 dB from it on a phantom: 34 dB below f16 storage's
/// own floor (`2^−11`, 66 dB), so the walk never shows in a measured SNR.
#[test]
fn renderer_follows_its_walk() {
    let n = 64;
    let volume = sample(&GaussianMixture::random(5, n, 8), [n; 3]);
    // Rows holding z (the strip walk), a slice containing z (the column
    // walk) and rows holding no axis (the reordered exact walk, where the
    // core has its lanes).
    let lanes = if exact::reorders::<f16, f32>() {
        WalkTaken::Reordered
    } else {
        WalkTaken::Exact
    };
    for (dir, up, taken) in [
        ([1.0, 0.3, 0.2], [0.0, 0.0, 1.0], WalkTaken::Strip),
        ([1.0, 0.3, 0.0], [0.0, 0.0, 1.0], WalkTaken::Column),
        ([0.7, 0.2, 1.0], [0.3, 1.0, 0.1], lanes),
    ] {
        let view = View { dir, up };
        let held = held_axis(&Sampling::UNIT.slice_axes(&view.frame().unwrap())).is_some();
        for kind in [FilterKind::Kb4, FilterKind::Kb6] {
            let filter = Filter::new(kind, 1).unwrap();
            let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
            let render = |walk: Walk, taken: WalkTaken| {
                let mut out = vec![0.0f32; n * n];
                let mut renderer = ViewRenderer::<f32>::new(n, filter).with_walk(walk);
                assert_eq!(renderer.walked(), None);
                renderer.render_into(&spec, &view, n, n, &mut out).unwrap();
                assert_eq!(renderer.walked(), Some(taken), "{kind:?} {dir:?}");
                out
            };
            let core = render_once::<f16, f32>(&spec.view(), &Request::new(view, n, n)).unwrap();
            let exact = render(Walk::Exact, WalkTaken::Exact);
            assert!(core
                .iter()
                .zip(&exact)
                .all(|(a, b)| a.to_bits() == (*b as f64).to_bits()));
            let fast = render(Walk::default(), taken);
            let (mut signal, mut noise) = (0.0f64, 0.0f64);
            for (a, b) in core.iter().zip(&fast) {
                signal += a * a;
                noise += (a - *b as f64).powi(2);
            }
            // The column walk nests its sums as the core does (x, then y,
            // then z) and may match it bit for bit; the strip walk and the
            // reordered sums cannot.
            if dir[2] != 0.0 && (held || exact::reorders::<f16, f32>()) {
                assert!(noise > 0.0, "{kind:?} {dir:?}: the fast walk was not used");
            }
            let snr = 10.0 * (signal / noise).log10();
            assert!(
                snr >= 100.0,
                "{kind:?} {dir:?}: fast walk against core {snr:.1} dB"
            );
        }
    }
}

/// Views whose strip rows run along y take the spectrum with x and y
/// exchanged from the second such view a renderer draws: the first leaves
/// the spectrum alone, a view whose rows run along x or that contains z
/// does not count, the views that take it are the strip walk's on the
/// spectrum itself bit for bit, and every image stays at least 100 dB
/// from the core's.
#[test]
fn the_renderer_exchanges_x_and_y_from_the_second_view_along_y() {
    let n = 64;
    let volume = sample(&GaussianMixture::random(5, n, 8), [n; 3]);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
    let mut renderer = ViewRenderer::<f32>::new(n, filter);
    let along_y = View::along([1.0, 0.3, 0.2]);
    let along_x = View::along([0.3, 1.0, 0.2]);
    let containing_z = View::along([1.0, 0.3, 0.0]);
    // The strip walk on the spectrum itself, for the first view along y.
    let mut linear = vec![0.0f32; n * n];
    ViewRenderer::<f32>::new(n, filter)
        .render_into(&spec, &along_y, n, n, &mut linear)
        .unwrap();
    assert_eq!(spec.exchanged_bytes(), 0);
    for (view, holds) in [
        (along_y, false),
        (along_x, false),
        (containing_z, false),
        (along_y, true),
        (along_x, true),
        (along_y, true),
    ] {
        let axes = Sampling::UNIT.slice_axes(&view.frame().unwrap());
        let mut out = vec![0.0f32; n * n];
        renderer.render_into(&spec, &view, n, n, &mut out).unwrap();
        assert_eq!(spec.exchanged_bytes() > 0, holds, "{view:?}");
        if view == along_y {
            // Exchanged or not, the strip walk's bits.
            assert!(out
                .iter()
                .zip(&linear)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        let core = render_once::<f16, f32>(&spec.view(), &Request::new(view, n, n)).unwrap();
        let (mut signal, mut noise) = (0.0f64, 0.0f64);
        for (a, b) in core.iter().zip(&out) {
            signal += a * a;
            noise += (a - *b as f64).powi(2);
        }
        let snr = 10.0 * (signal / noise).log10();
        assert!(
            snr >= 100.0,
            "{view:?}: {snr:.1} dB (rows along y: {})",
            rows_along_y(&axes)
        );
    }
    assert_eq!(spec.exchanged_bytes(), spec.bytes());
}

/// A walk with its tiling and threading chosen.
type Walker<'a> = dyn Fn(Tiling, bool, &mut [f32]) -> bool + 'a;

/// Prefetching is a hint: the strip, exchanged and column walks give the
/// same bits however far ahead they prefetch, past the last line too, on
/// one thread and several, on a power-of-two and a mixed-radix side.
#[test]
fn prefetching_leaves_every_value_unchanged() {
    let volume = noise_volume([32, 32, 32], 13);
    for (grid, n) in [(GridOversampling::X1, 32), (GridOversampling::X1_25, 40)] {
        let filter = Filter::for_grid(FilterKind::Kb4, grid).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare_on::<f32>(&volume, filter, n).unwrap();
        let view = spec.view();
        let swapped_data = exchange_xy(view.data(), n).unwrap();
        let [a, b, c] = view.dims();
        let swapped =
            Spectrum::from_parts(&swapped_data, n, view.scale(), filter, [b, a, c]).unwrap();
        let kernel = KernelTable::<f32>::new(filter);
        let strip = Sampling::UNIT.slice_axes(&View::along([1.0, 0.3, 0.2]).frame().unwrap());
        let column = Sampling::UNIT.slice_axes(&View::along([1.0, -0.3, 0.0]).frame().unwrap());
        let walks: [(&str, &Walker); 3] = [
            ("strip", &|t, p, g| {
                strip::extract(&SliceJob::new(&view, &kernel, &strip, t, p), g)
            }),
            ("exchanged", &|t, p, g| {
                let axes = exchanged(&strip);
                strip::extract_exchanged(&SliceJob::new(&swapped, &kernel, &axes, t, p), g)
            }),
            ("column", &|t, p, g| {
                column::extract(
                    &SliceJob::new(&view, &kernel, &column, t, p),
                    g,
                    &mut Vec::new(),
                )
            }),
        ];
        for (what, walk) in walks {
            let run = |ahead: usize, parallel: bool| {
                let tiling = Tiling {
                    ahead,
                    ..Tiling::default()
                };
                let mut grid = vec![7.0f32; n * n];
                assert!(walk(tiling, parallel, &mut grid), "{what} n {n}");
                grid
            };
            let plain = run(0, false);
            assert!(plain.iter().any(|&v| v != 0.0 && v != 7.0), "{what} n {n}");
            for ahead in [1, 3, 8, 1000] {
                for parallel in [false, true] {
                    let got = run(ahead, parallel);
                    assert!(
                        got.iter()
                            .zip(&plain)
                            .all(|(a, b)| a.to_bits() == b.to_bits()),
                        "{what} n {n}, ahead {ahead}, parallel {parallel}"
                    );
                }
            }
        }
    }
}
