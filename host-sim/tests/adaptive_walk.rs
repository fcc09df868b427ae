//! The host's adaptive extraction (`fvr_engine::slice::adaptive::walk`)
//! against the core's (`fvr_core::slice::adaptive::extract_slice_adaptive`):
//! the same slice bit for bit and the same statistics, for chains of one
//! and two cheaper filters, f16 and f32 storage, f32 and f64 arithmetic,
//! axis-aligned, oblique and near-axis directions, volumes that are not
//! cubes inside their power-of-two grid, oversampling 2, and every tiling
//! and thread split; and the adaptive renderer's image against the core's
//! extraction followed by the core's finish. With the large filter's
//! points left to the strip walk (`extract_with_strip`, the renderer's
//! default): those points the strip walk's bits, every other point and
//! the statistics the core's.

use fvr_core::dht::Twiddles;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::View;
use fvr_core::image::{aux_len, finish, placement, Crop};
use fvr_core::num::{Real, Sample};
use fvr_core::slice::adaptive::{extract_slice_adaptive, AdaptiveStats};
use fvr_engine::dht::real::FftReal;
use fvr_engine::dht::store::StoreFormat;
use fvr_engine::render::adaptive::AdaptiveRenderer;
use fvr_engine::render::view::Walk;
use fvr_engine::slice::adaptive::summary::MarksSummary;
use fvr_engine::slice::adaptive::walk::{
    extract, extract_with_strip, extract_with_strip_if, AdaptiveJob, Settled,
};
use fvr_engine::slice::adaptive::{AdaptiveMarks, AdaptiveSettings, Bound, Cheaper};
use fvr_engine::slice::exact::{SliceJob, Tiling};
use fvr_engine::slice::strip;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_engine::volume::Volume;
use half::f16;

const DIRECTIONS: [[f64; 3]; 5] = [
    [0.0, -1.0, 0.0],
    [1.0, 0.3, 0.2],
    [1.0, -1.0, 0.0],
    // Near-axis: rows run almost along x, and many taps wrap at x = n − 1.
    [0.02, -1.0, 0.01],
    [-0.4, 0.7, -0.6],
];

const TILINGS: [Tiling; 3] = [
    Tiling::new(1, 1, 0),
    Tiling::new(3, 5, 1),
    Tiling::new(1000, 1000, 1000),
];

/// A smooth volume of `dims` (Gaussian blobs, fixed seed), whose spectrum
/// is weak over most of the cube, so that both filters are used.
fn smooth(dims: [usize; 3], seed: u64) -> Volume {
    let side = dims.iter().copied().max().unwrap_or(1);
    sample(&GaussianMixture::random(seed, side, 6), dims)
}

/// The kb6 spectrum (oversampling 1) of `volume`, stored in `S` and
/// prepared in `T`.
fn kb6<S: StoreFormat, T: FftReal>(volume: &Volume) -> OwnedSpectrum<S> {
    let filter = Filter::new(FilterKind::Kb6, 1).unwrap();
    OwnedSpectrum::<S>::prepare::<T>(volume, filter).unwrap()
}

/// The marks of `spec` for `db` decibels with the cheaper filters `chain`.
fn marks_for<S: Sample>(spec: &OwnedSpectrum<S>, db: f64, chain: &[Cheaper]) -> AdaptiveMarks {
    let settings = AdaptiveSettings {
        chain: chain.to_vec(),
        ..AdaptiveSettings::new(db)
    };
    AdaptiveMarks::build(spec, &settings).unwrap()
}

/// The core's slice and statistics, then the host's for every tiling and
/// thread split, compared bit for bit (as f64 bit patterns: exact for f32
/// and f64 alike). Returns the core's statistics.
fn check<S: Sample, T: Real>(
    spec: &OwnedSpectrum<S>,
    marks: &AdaptiveMarks,
    dir: [f64; 3],
    what: &str,
) -> AdaptiveStats {
    let n = spec.n();
    check_busy::<S, T>(spec, marks, dir, n * n / 4, what)
}

/// [`check`], the core's slice with more than `busy` nonzero points.
fn check_busy<S: Sample, T: Real>(
    spec: &OwnedSpectrum<S>,
    marks: &AdaptiveMarks,
    dir: [f64; 3],
    busy: usize,
    what: &str,
) -> AdaptiveStats {
    let view = spec.view();
    let n = view.n();
    let frame = View::along(dir).frame().unwrap();
    let kernel = KernelTable::<T>::new(*view.filter());
    let tables = marks.tables::<T>();
    let levels = marks.core_levels(&tables).unwrap();
    let mut core = vec![T::ZERO; n * n];
    let core_stats = extract_slice_adaptive(&view, &kernel, &levels, &frame, &mut core).unwrap();
    assert!(
        core.iter().filter(|v| v.to_f64() != 0.0).count() > busy,
        "{what}: the slice is mostly zero"
    );
    // With the summary of the first level's marks, and without.
    let wholes = [marks.summary(), None];
    for (tiling, whole) in TILINGS.into_iter().zip(wholes.into_iter().cycle()) {
        for parallel in [false, true] {
            // Garbage first: every point must be written.
            let mut host = vec![T::from_f64(7.0); n * n];
            let job = AdaptiveJob::new(&view, &kernel, &levels, whole, &frame, tiling, parallel);
            let stats = extract(&job, &mut host).unwrap_or_else(|| panic!("{what}: not served"));
            assert_eq!(stats, core_stats, "{what}, {tiling:?}, parallel {parallel}");
            let differ = core
                .iter()
                .zip(&host)
                .filter(|(a, b)| a.to_f64().to_bits() != b.to_f64().to_bits())
                .count();
            assert_eq!(differ, 0, "{what}, {tiling:?}, parallel {parallel}");
        }
    }
    core_stats
}

/// Both the large filter and every level filtered some of the slice.
fn assert_mixed(stats: &AdaptiveStats, levels: usize, what: &str) {
    for (slot, &count) in stats.per_filter[..=levels].iter().enumerate() {
        assert!(count > 0, "{what}: filter {slot} unused ({stats:?})");
    }
}

#[test]
fn kb6_to_nearest_bit_identical_f16() {
    let n = 32;
    let spec = kb6::<f16, f32>(&smooth([n; 3], 1));
    let marks = AdaptiveMarks::build(&spec, &AdaptiveSettings::new(40.0)).unwrap();
    for dir in DIRECTIONS {
        let stats = check::<f16, f32>(&spec, &marks, dir, &format!("kb6 → 1³ {dir:?}"));
        assert_mixed(&stats, 1, &format!("kb6 → 1³ {dir:?}"));
    }
}

#[test]
fn two_level_chain_f32_and_f64_bit_identical() {
    // `fvr render gaussians@16 --filter kb6 --adaptive 30 --adaptive-chain
    // nearest,kb3` puts slice samples on all three filters.
    let n = 16;
    let volume = sample(&GaussianMixture::random(1, n, 8), [n; 3]);
    let chain = [
        Cheaper::Filter(FilterKind::Nearest),
        Cheaper::Filter(FilterKind::Kb3),
    ];
    let spec32 = kb6::<f32, f32>(&volume);
    let spec64 = kb6::<f64, f64>(&volume);
    let marks32 = marks_for(&spec32, 30.0, &chain);
    let marks64 = marks_for(&spec64, 30.0, &chain);
    let mut used = [0u64; 3];
    for dir in DIRECTIONS {
        let s = check::<f32, f32>(&spec32, &marks32, dir, &format!("kb6 f32 {dir:?}"));
        check::<f64, f64>(&spec64, &marks64, dir, &format!("kb6 f64 {dir:?}"));
        for (u, c) in used.iter_mut().zip(s.per_filter) {
            *u += c;
        }
    }
    assert!(
        used.iter().all(|&c| c > 0),
        "a filter of the chain unused: {used:?}"
    );
}

#[test]
fn zero_level_reads_nothing_and_matches_the_core() {
    // The zero filter first, then 1³: points on all three, the zero ones 0
    // and without taps, the slice and statistics the core's bit for bit.
    let n = 32;
    let volume = sample(&GaussianMixture::random(4, n, 8), [n; 3]);
    let spec = kb6::<f16, f32>(&volume);
    let marks = marks_for(
        &spec,
        40.0,
        &[Cheaper::Zero, Cheaper::Filter(FilterKind::Nearest)],
    );
    assert_eq!(marks.levels[0].gain, 0.0);
    // The walks settle some points from the summary of the zero level.
    let summary = marks.summary().unwrap();
    let corners = (0..n).step_by(8);
    let corner = |x, y, z| summary.holds([x, y, z]);
    assert!(corners.clone().any(|z| corners
        .clone()
        .any(|y| corners.clone().any(|x| corner(x, y, z)))));
    let mut used = [0u64; 3];
    for dir in DIRECTIONS {
        let s = check::<f16, f32>(&spec, &marks, dir, &format!("kb6 zero {dir:?}"));
        assert_eq!(s.taps, s.per_filter[0] * 216 + s.per_filter[2], "{dir:?}");
        for (u, c) in used.iter_mut().zip(s.per_filter) {
            *u += c;
        }
    }
    assert!(
        used.iter().all(|&c| c > 0),
        "a link of the chain unused: {used:?}"
    );
}

/// The f16 kb6 spectrum of a smooth volume at 64, whose strong samples lie
/// near the origin.
fn smooth_kb6_64() -> OwnedSpectrum<f16> {
    kb6::<f16, f32>(&sample(&GaussianMixture::random(4, 64, 8), [64; 3]))
}

#[test]
fn points_among_whole_zero_bricks_are_counted_as_the_core_walks_them() {
    // A zero level on a smooth volume at 64, most of its bricks whole: the
    // walk only counts the points of each row outside its spans, which
    // end at every angle to the bricks' faces.
    let (n, spec) = (64, smooth_kb6_64());
    for chain in [
        vec![Cheaper::Zero],
        vec![Cheaper::Zero, Cheaper::Filter(FilterKind::Nearest)],
    ] {
        let levels = chain.len();
        let marks = marks_for(&spec, 40.0, &chain);
        let partial = marks.summary().unwrap().partial().unwrap().len();
        let m = n / 8;
        // Few enough for the walk to take spans (at most 2m²).
        assert!(
            partial > 0 && partial <= 2 * m * m,
            "{partial} bricks not whole"
        );
        for dir in DIRECTIONS {
            let what = format!("{levels} levels, {dir:?}");
            let s = check_busy::<f16, f32>(&spec, &marks, dir, n, &what);
            assert!(s.per_filter[0] > 0 && s.per_filter[1] > 0, "{what}: {s:?}");
        }
    }
}

#[test]
fn spans_reach_scattered_unmarked_bricks() {
    // Marks of the zero level replaced by whole bricks marked or not (one
    // in eight not, at random): a point that reaches a brick not marked
    // but lies outside its row's spans would be counted as zero where the
    // core filters it.
    let (n, spec) = (64, smooth_kb6_64());
    let mut marks = marks_for(&spec, 40.0, &[Cheaper::Zero]);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let m = n / 8;
    let unmarked: Vec<bool> = (0..m * m * m)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % 8 == 0
        })
        .collect();
    let level = &mut marks.levels[0];
    level.words.fill(0);
    for i in 0..n * n * n {
        let (x, y, z) = (i % n / 8, i / n % n / 8, i / (n * n) / 8);
        if !unmarked[x + m * (y + m * z)] {
            level.words[i / 32] |= 1 << (i % 32);
        }
    }
    level.summary = MarksSummary::new(&level.words, n);
    for dir in DIRECTIONS {
        let what = format!("scattered bricks, {dir:?}");
        let s = check_busy::<f16, f32>(&spec, &marks, dir, n, &what);
        assert!(s.per_filter[0] > n as u64, "{what}: {s:?}");
    }
}

/// Volumes that are not cubes inside their grid, and oversampling 2 (the
/// spectrum twice the volume's side), with both bounds.
#[test]
fn non_cubic_volumes_and_oversampling_bit_identical() {
    for (dims, kind, oversample) in [
        ([40, 28, 17], FilterKind::Kb3, 1),
        ([12, 30, 9], FilterKind::Kb6, 1),
        ([20, 14, 11], FilterKind::Kb4, 2),
    ] {
        let volume = smooth(dims, 3);
        let filter = Filter::new(kind, oversample).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        for bound in [Bound::Exact, Bound::Paper] {
            let settings = AdaptiveSettings {
                bound,
                ..AdaptiveSettings::new(35.0)
            };
            let marks = AdaptiveMarks::build(&spec, &settings).unwrap();
            for dir in [[1.0, 0.3, 0.2], [0.1, 0.2, 1.0], [0.3, -0.9, 0.5]] {
                let what = format!("{dims:?} {kind:?} σ={oversample} {bound:?} {dir:?}");
                let stats = check::<f16, f32>(&spec, &marks, dir, &what);
                // The paper's bound may mark nothing on these small volumes.
                if bound == Bound::Exact {
                    assert_mixed(&stats, 1, &what);
                }
            }
        }
    }
}

/// `renderer`'s `width × height` image of `view` is the core's finish of
/// `grid` (the slice of `view`, with twiddles `tw`), bit for bit, and its
/// statistics are `stats`.
fn assert_renders_the_finish(
    renderer: &mut AdaptiveRenderer<'_, f32>,
    spec: &OwnedSpectrum<f16>,
    view: &View,
    (mut grid, stats, tw): (Vec<f32>, AdaptiveStats, &Twiddles<'_, f32>),
    (width, height): (usize, usize),
    what: &str,
) {
    let (view_spec, n) = (spec.view(), spec.n());
    let frame = view.frame().unwrap();
    let mut aux = vec![0f32; aux_len(n)];
    let mut image = vec![0f32; width * height];
    let place = placement(view_spec.dims(), &frame, width, height);
    let crop = Crop::new(place, 1.0 / view_spec.scale(), width, height);
    finish(&mut grid, n, &crop, tw, &mut aux, &mut image).unwrap();
    let mut out = vec![0f32; width * height];
    let got = renderer
        .render_into(spec, view, width, height, &mut out)
        .unwrap();
    assert_eq!(got, stats, "{what}");
    for (a, b) in image.iter().zip(&out) {
        assert_eq!(a.to_bits(), b.to_bits(), "{what}");
    }
}

/// The renderer's image (host extraction, then the core's finish) equals
/// the core's adaptive extraction followed by the same finish, and its
/// statistics the core's; `None` where the walk does not serve.
#[test]
fn renderer_image_equals_core_extraction() {
    let n = 32;
    let (width, height) = (24, 20);
    let spec = kb6::<f16, f32>(&smooth([n, n, 20], 4));
    let filter = spec.filter();
    // Always the adaptive walk: this compares it with the core's.
    let settings = AdaptiveSettings {
        plain_below: 0.0,
        ..AdaptiveSettings::new(40.0)
    };
    let marks = AdaptiveMarks::build(&spec, &settings).unwrap();
    let view_spec = spec.view();
    let kernel = KernelTable::<f32>::new(filter);
    let tables = marks.tables::<f32>();
    let levels = marks.core_levels(&tables).unwrap();
    let mut tw_buf = vec![0f32; Twiddles::<f32>::buffer_len(n)];
    let tw = Twiddles::new(&mut tw_buf, n).unwrap();
    for parallel in [false, true] {
        let mut renderer = AdaptiveRenderer::<f32>::new(&marks, &spec)
            .unwrap()
            .with_parallel(parallel)
            .with_walk(Walk::Exact);
        for dir in DIRECTIONS {
            let view = View::along(dir);
            let frame = view.frame().unwrap();
            let mut grid = vec![0f32; n * n];
            let core_stats =
                extract_slice_adaptive(&view_spec, &kernel, &levels, &frame, &mut grid).unwrap();
            let what = format!("{dir:?}, parallel {parallel}");
            let finished = (grid, core_stats, &tw);
            assert_renders_the_finish(
                &mut renderer,
                &spec,
                &view,
                finished,
                (width, height),
                &what,
            );
        }
    }
    // A kernel for another filter: the walk declines, the core reports it.
    let other = KernelTable::<f32>::new(Filter::new(FilterKind::Kb4, 1).unwrap());
    let frame = View::along([1.0, 0.3, 0.2]).frame().unwrap();
    let mut grid = vec![0f32; n * n];
    let tiling = Tiling::default();
    let whole = marks.summary();
    let job = AdaptiveJob::new(&view_spec, &other, &levels, whole, &frame, tiling, true);
    assert!(extract(&job, &mut grid).is_none());
}

/// The slice [`extract_with_strip`] should give: the core's adaptive
/// slice where `strip_point` says the point is not on the large filter,
/// else the plain strip walk's value.
fn merged(core: &[f32], plain: &[f32], strip_point: impl Fn(usize) -> bool) -> Vec<f32> {
    (0..core.len())
        .map(|i| if strip_point(i) { plain[i] } else { core[i] })
        .collect()
}

/// With a zero first level, the points on the large filter are exactly
/// the core's nonzero ones: there [`extract_with_strip`] gives the plain
/// strip walk's bits, elsewhere `+0`, with the core's statistics, for every
/// tiling and thread split; with a nearest level after the zero one, each
/// point is the core's or the strip walk's, the strip walk's on at most
/// the large filter's share. The renderer's default image is that slice
/// through the core's finish, bit for bit.
#[test]
fn strip_walk_sums_the_large_filters_points_and_nothing_else() {
    let spec = smooth_kb6_64();
    let view_spec = spec.view();
    let n = spec.n();
    let kernel = KernelTable::<f32>::new(*view_spec.filter());
    let chains: [(&[Cheaper], Bound); 3] = [
        (&[Cheaper::Zero], Bound::Parseval),
        (&[Cheaper::Zero], Bound::Exact),
        (
            &[Cheaper::Zero, Cheaper::Filter(FilterKind::Nearest)],
            Bound::Exact,
        ),
    ];
    let mut tw_buf = vec![0f32; Twiddles::<f32>::buffer_len(n)];
    let tw = Twiddles::new(&mut tw_buf, n).unwrap();
    for (chain, bound) in chains {
        let settings = AdaptiveSettings {
            plain_below: 0.0,
            chain: chain.to_vec(),
            bound,
            ..AdaptiveSettings::new(40.0)
        };
        let marks = AdaptiveMarks::build(&spec, &settings).unwrap();
        let tables = marks.tables::<f32>();
        let levels = marks.core_levels(&tables).unwrap();
        let mut renderer = AdaptiveRenderer::<f32>::new(&marks, &spec).unwrap();
        for dir in DIRECTIONS {
            let what = format!("{chain:?} {bound:?} {dir:?}");
            let view = View::along(dir);
            let frame = view.frame().unwrap();
            let axes = frame.slice_axes();
            let mut core = vec![0f32; n * n];
            let core_stats =
                extract_slice_adaptive(&view_spec, &kernel, &levels, &frame, &mut core).unwrap();
            let mut plain = vec![0f32; n * n];
            let tiling = Tiling::default();
            let job = SliceJob::new(&view_spec, &kernel, &axes, tiling, true);
            assert!(strip::extract(&job, &mut plain));
            let large = core_stats.per_filter[0] as usize;
            assert!(
                large > 0 && large < core_stats.samples as usize / 4,
                "{what}: {core_stats:?}"
            );
            let expected = match chain.len() {
                1 => {
                    let nonzero = core.iter().filter(|v| v.to_bits() != 0).count();
                    assert_eq!(nonzero, large, "{what}: a large-filter point is +0");
                    merged(&core, &plain, |i| core[i].to_bits() != 0)
                }
                _ => Vec::new(),
            };
            for tiling in TILINGS {
                for parallel in [false, true] {
                    // Garbage first: every point must be written.
                    let mut host = vec![7f32; n * n];
                    let mut strong = vec![-3f32; n * n];
                    let whole = marks.summary();
                    let job = AdaptiveJob::new(
                        &view_spec, &kernel, &levels, whole, &frame, tiling, parallel,
                    );
                    let stats = extract_with_strip(&job, &mut host, &mut strong).unwrap();
                    let at = format!("{what}, {tiling:?}, parallel {parallel}");
                    assert_eq!(stats, core_stats, "{at}");
                    if !expected.is_empty() {
                        for (i, (a, b)) in expected.iter().zip(&host).enumerate() {
                            assert_eq!(a.to_bits(), b.to_bits(), "{at}, point {i}");
                        }
                        continue;
                    }
                    let mut from_strip = 0;
                    for i in 0..n * n {
                        let h = host[i].to_bits();
                        assert!(
                            h == core[i].to_bits() || h == plain[i].to_bits(),
                            "{at}, {i}"
                        );
                        from_strip += usize::from(h != core[i].to_bits());
                    }
                    assert!(from_strip > 0 && from_strip <= large, "{at}: {from_strip}");
                }
            }
            if expected.is_empty() {
                continue;
            }
            let finished = (expected, core_stats, &tw);
            let what = format!("{what}: renderer");
            assert_renders_the_finish(&mut renderer, &spec, &view, finished, (48, 40), &what);
        }
    }
}

/// Where the slice's rows hold no coordinate (an up hint off the axes),
/// the strip walk does not serve, and [`extract_with_strip`] is
/// [`extract`]: the core's slice bit for bit.
#[test]
fn without_a_held_axis_the_strip_extraction_is_the_cores() {
    let spec = smooth_kb6_64();
    let view_spec = spec.view();
    let n = spec.n();
    let kernel = KernelTable::<f32>::new(*view_spec.filter());
    let settings = AdaptiveSettings {
        plain_below: 0.0,
        ..AdaptiveSettings::new(40.0)
    };
    let marks = AdaptiveMarks::build(&spec, &settings).unwrap();
    let tables = marks.tables::<f32>();
    let levels = marks.core_levels(&tables).unwrap();
    let view = View {
        dir: [1.0, 0.3, 0.2],
        up: [0.2, 0.5, 1.0],
    };
    let frame = view.frame().unwrap();
    assert!(frame.right.iter().all(|&c| c != 0.0), "{frame:?}");
    let mut core = vec![0f32; n * n];
    let core_stats =
        extract_slice_adaptive(&view_spec, &kernel, &levels, &frame, &mut core).unwrap();
    assert!(core_stats.per_filter[0] > 0, "{core_stats:?}");
    let mut host = vec![7f32; n * n];
    let mut strong = vec![0f32; n * n];
    let (whole, tiling) = (marks.summary(), Tiling::default());
    let job = AdaptiveJob::new(&view_spec, &kernel, &levels, whole, &frame, tiling, true);
    let stats = extract_with_strip(&job, &mut host, &mut strong).unwrap();
    assert_eq!(stats, core_stats);
    for (a, b) in core.iter().zip(&host) {
        assert_eq!(a.to_bits(), b.to_bits());
    }
}

/// [`extract_with_strip_if`] hands its condition the core's statistics
/// before summing the large filter's points: declined, it returns them;
/// accepted, it is [`extract_with_strip`] bit for bit. Both where the
/// strip walk serves and where it does not (an up hint off the axes).
#[test]
fn the_strip_walk_decides_on_the_cores_statistics() {
    let spec = smooth_kb6_64();
    let view_spec = spec.view();
    let n = spec.n();
    let kernel = KernelTable::<f32>::new(*view_spec.filter());
    let marks = AdaptiveMarks::build(&spec, &AdaptiveSettings::new(40.0)).unwrap();
    let tables = marks.tables::<f32>();
    let levels = marks.core_levels(&tables).unwrap();
    let mut views: Vec<View> = DIRECTIONS.iter().map(|&dir| View::along(dir)).collect();
    views.push(View {
        dir: [1.0, 0.3, 0.2],
        up: [0.2, 0.5, 1.0],
    });
    let (whole, tiling) = (marks.summary(), Tiling::default());
    for view in views {
        let frame = view.frame().unwrap();
        let mut core = vec![0f32; n * n];
        let core_stats =
            extract_slice_adaptive(&view_spec, &kernel, &levels, &frame, &mut core).unwrap();
        let mut expected = vec![7f32; n * n];
        let mut strong = vec![0f32; n * n];
        let job = AdaptiveJob::new(&view_spec, &kernel, &levels, whole, &frame, tiling, true);
        extract_with_strip(&job, &mut expected, &mut strong).unwrap();
        for parallel in [false, true] {
            for accept in [false, true] {
                let mut seen = None;
                let mut host = vec![7f32; n * n];
                let settled = extract_with_strip_if(
                    &AdaptiveJob { parallel, ..job },
                    &mut host,
                    &mut strong,
                    |stats| {
                        seen = Some(*stats);
                        accept
                    },
                )
                .unwrap();
                let at = format!("{view:?} parallel {parallel} accept {accept}");
                assert_eq!(seen, Some(core_stats), "{at}");
                match accept {
                    false => assert_eq!(settled, Settled::Declined(core_stats), "{at}"),
                    true => {
                        assert_eq!(settled, Settled::Extracted(core_stats), "{at}");
                        for (a, b) in expected.iter().zip(&host) {
                            assert_eq!(a.to_bits(), b.to_bits(), "{at}");
                        }
                    }
                }
            }
        }
    }
}
