//! Criterion benchmarks: one view with the full filter against the adaptive
//! one (paper §4), both with reusable buffers on all cores (the host's
//! extractions, then the same 2D inverse transform), for four chains at
//! 40 dB: with the exact bound the 1³ filter (`adaptive_40db_nearest`), the
//! zero filter (`adaptive_40db_zero`) and both (`adaptive_40db_zero_nearest`);
//! the zero filter with Parseval's bound (`adaptive_40db_zero_parseval`,
//! `fvr render --adaptive`'s defaults, which also decide per view between
//! the adaptive and the plain walk), also raised by one probe
//! (`adaptive_40db_zero_parseval_probe`) and
//! with the large filter's points summed point by point in the core's
//! arithmetic (`adaptive_40db_zero_parseval_exact`, [`Walk::Exact`])
//! instead of by the strip walk:
//!
//! - `adaptive_kb3_os2_128`: kb3, oversampling 2, on a 128³ Gaussian
//!   mixture (f16);
//! - `adaptive_kb6_256`: kb6, oversampling 1, on the 256³ Gaussian mixture
//!   of `fvr render gaussians@256` (f16), along the oblique direction
//!   (1, 0.3, 0.2);
//!
//! each also with the core's single-threaded adaptive extraction of the
//! 1³ filter (`adaptive_40db_core`); `marks_kb6_256`: the marks at 40 dB
//! for each chain (`marks_40db_<chain>`, and Parseval's bound raised by
//! one probe, `marks_40db_zero_parseval_probe`) against the preprocessing
//! they follow (`prepare`), on the same volume; and `breakeven_kb4_256`,
//! `breakeven_kb6_256`: the plain view (`plain`) against the adaptive walk
//! (never the plain fallback) at tolerances that substitute from none to
//! nearly all of the view's samples (`adaptive_<dB>db_<share>pct`, the
//! share in the name), where the adaptive walk breaks even with the plain
//! one. Compare as ratios within one run.
//!
//! Run: `cargo bench -p fvr-host --bench adaptive` (the break-even groups
//! alone with `FVR_BENCH_BREAKEVEN=1`).

use std::hint::black_box;

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion};
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_engine::render::adaptive::AdaptiveRenderer;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::render::view::Walk;
use fvr_engine::slice::adaptive::{AdaptiveMarks, AdaptiveSettings, Bound, Cheaper};
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_engine::volume::Volume;
use half::f16;

/// The chains compared, each with its bound: the 1³ filter, the zero
/// filter, and both, with the exact bound (`fvr adaptive-table`'s default);
/// the zero filter with Parseval's (`fvr render --adaptive`'s).
const CHAINS: [(&str, &[Cheaper], Bound); 4] = [
    (
        "nearest",
        &[Cheaper::Filter(FilterKind::Nearest)],
        Bound::Exact,
    ),
    ("zero", &[Cheaper::Zero], Bound::Exact),
    (
        "zero_nearest",
        &[Cheaper::Zero, Cheaper::Filter(FilterKind::Nearest)],
        Bound::Exact,
    ),
    ("zero_parseval", &[Cheaper::Zero], Bound::Parseval),
];

/// Times `render`, one view into the bench's buffers, as `id` in `group`.
fn time_view<R>(group: &mut BenchmarkGroup<'_, WallTime>, id: &str, mut render: impl FnMut() -> R) {
    group.bench_function(id, |b| b.iter(&mut render));
}

/// The full and adaptive views of `volume` with `filter`, in group `name`.
fn group(c: &mut Criterion, name: &str, volume: &Volume, filter: Filter) {
    let spec = OwnedSpectrum::<f16>::prepare::<f32>(volume, filter).unwrap();
    let n = spec.n();
    let side = volume.dims[0];
    // The adaptive walk always (the plain fallback is `breakeven`'s peer).
    let settings = AdaptiveSettings {
        plain_below: 0.0,
        ..AdaptiveSettings::new(40.0)
    };
    let marks = AdaptiveMarks::build(&spec, &settings).unwrap();
    let view = View::along([1.0, 0.3, 0.2]);
    let mut renderer = ViewRenderer::<f32>::new(n, filter);
    let mut out = vec![0.0f32; side * side];
    let mut group = c.benchmark_group(name);
    group.sample_size(20);
    time_view(&mut group, "full", || {
        renderer
            .render_into(&spec, black_box(&view), side, side, &mut out)
            .unwrap()
    });
    for (label, chain, bound) in CHAINS {
        // `fvr render`'s defaults also decide between the walks per view.
        let plain_below = match bound {
            Bound::Parseval => AdaptiveSettings::new(40.0).plain_below,
            _ => settings.plain_below,
        };
        let marks = AdaptiveMarks::build(
            &spec,
            &AdaptiveSettings {
                chain: chain.to_vec(),
                bound,
                plain_below,
                ..settings.clone()
            },
        )
        .unwrap();
        let mut adaptive = AdaptiveRenderer::<f32>::new(&marks, &spec).unwrap();
        time_view(&mut group, &format!("adaptive_40db_{label}"), || {
            adaptive
                .render_into(&spec, black_box(&view), side, side, &mut out)
                .unwrap()
        });
        if label == "zero_parseval" {
            let probe_marks = AdaptiveMarks::build(
                &spec,
                &AdaptiveSettings {
                    chain: chain.to_vec(),
                    bound,
                    plain_below,
                    probes: 1,
                    ..settings.clone()
                },
            )
            .unwrap();
            let mut probed = AdaptiveRenderer::<f32>::new(&probe_marks, &spec).unwrap();
            time_view(&mut group, &format!("adaptive_40db_{label}_probe"), || {
                probed
                    .render_into(&spec, black_box(&view), side, side, &mut out)
                    .unwrap()
            });
            let mut exact = AdaptiveRenderer::<f32>::new(&marks, &spec)
                .unwrap()
                .with_walk(Walk::Exact);
            time_view(&mut group, &format!("adaptive_40db_{label}_exact"), || {
                exact
                    .render_into(&spec, black_box(&view), side, side, &mut out)
                    .unwrap()
            });
        }
    }
    let mut core = AdaptiveRenderer::<f32>::new(&marks, &spec)
        .unwrap()
        .with_core(true);
    time_view(&mut group, "adaptive_40db_core", || {
        core.render_into(&spec, black_box(&view), side, side, &mut out)
            .unwrap()
    });
    group.finish();
}

/// Preparing `volume` with `filter` (f16) against building its exact marks.
fn marking(c: &mut Criterion, name: &str, volume: &Volume, filter: Filter) {
    let spec = OwnedSpectrum::<f16>::prepare::<f32>(volume, filter).unwrap();
    let mut group = c.benchmark_group(name);
    group.sample_size(10);
    group.bench_function("prepare", |b| {
        b.iter(|| OwnedSpectrum::<f16>::prepare::<f32>(black_box(volume), filter).unwrap())
    });
    for (label, chain, bound) in CHAINS {
        let settings = AdaptiveSettings {
            chain: chain.to_vec(),
            bound,
            ..AdaptiveSettings::new(40.0)
        };
        group.bench_function(format!("marks_40db_{label}"), |b| {
            b.iter(|| AdaptiveMarks::build(black_box(&spec), &settings).unwrap())
        });
        if bound == Bound::Parseval {
            let probe = AdaptiveSettings {
                probes: 1,
                ..settings.clone()
            };
            group.bench_function(format!("marks_40db_{label}_probe"), |b| {
                b.iter(|| AdaptiveMarks::build(black_box(&spec), &probe).unwrap())
            });
        }
    }
    group.finish();
}

/// The plain view against the adaptive walk at several tolerances, each
/// named with the share of the view's samples it substitutes.
fn breakeven(c: &mut Criterion, name: &str, volume: &Volume, filter: Filter) {
    let spec = OwnedSpectrum::<f16>::prepare::<f32>(volume, filter).unwrap();
    let n = spec.n();
    let side = volume.dims[0];
    let view = View::along([1.0, 0.3, 0.2]);
    let mut renderer = ViewRenderer::<f32>::new(n, filter);
    let mut out = vec![0.0f32; side * side];
    let mut group = c.benchmark_group(name);
    group.sample_size(20);
    time_view(&mut group, "plain", || {
        renderer
            .render_into(&spec, black_box(&view), side, side, &mut out)
            .unwrap()
    });
    for db in [400.0, 120.0, 90.0, 70.0, 55.0, 40.0] {
        let settings = AdaptiveSettings {
            plain_below: 0.0,
            ..AdaptiveSettings::new(db)
        };
        let marks = AdaptiveMarks::build(&spec, &settings).unwrap();
        let mut adaptive = AdaptiveRenderer::<f32>::new(&marks, &spec).unwrap();
        let stats = adaptive
            .render_into(&spec, &view, side, side, &mut out)
            .unwrap();
        let share = 100.0 * (stats.samples - stats.per_filter[0]) as f64 / stats.samples as f64;
        time_view(
            &mut group,
            &format!("adaptive_{db}db_{share:.1}pct"),
            || {
                adaptive
                    .render_into(&spec, black_box(&view), side, side, &mut out)
                    .unwrap()
            },
        );
    }
    group.finish();
}

fn benches(c: &mut Criterion) {
    if std::env::var_os("FVR_BENCH_BREAKEVEN").is_some() {
        let n = 256;
        let volume = sample(&GaussianMixture::random(1, n, 8), [n; 3]);
        for (name, kind) in [
            ("breakeven_kb4_256", FilterKind::Kb4),
            ("breakeven_kb6_256", FilterKind::Kb6),
        ] {
            breakeven(c, name, &volume, Filter::new(kind, 1).unwrap());
        }
        return;
    }
    let n = 128;
    let volume = sample(&GaussianMixture::random(1, n, 8), [n; 3]);
    group(
        c,
        "adaptive_kb3_os2_128",
        &volume,
        Filter::new(FilterKind::Kb3, 2).unwrap(),
    );
    let n = 256;
    let volume = sample(&GaussianMixture::random(1, n, 8), [n; 3]);
    group(
        c,
        "adaptive_kb6_256",
        &volume,
        Filter::new(FilterKind::Kb6, 1).unwrap(),
    );
    marking(
        c,
        "marks_kb6_256",
        &volume,
        Filter::new(FilterKind::Kb6, 1).unwrap(),
    );
}

criterion_group!(adaptive, benches);
criterion_main!(adaptive);
