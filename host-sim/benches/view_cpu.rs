//! CPU time per view on one thread (the thread's own user + system time
//! from `/proc/thread-self/stat`, so time the thread spends waiting for a
//! core shared with other processes is not counted): the host extraction
//! (`fvr_engine::slice::column` where the slice contains an axis,
//! `fvr_engine::slice::strip` where its rows hold a coordinate, the
//! exact walk `fvr_engine::slice::exact` beside it; and each walk's
//! slice alone, the strip walk also on the exchanged copy for rows along y)
//! against the core's render, at 256³
//! f16, kb4 and kb6, along an axis, an oblique direction and the orbit
//! direction at 45°. A companion of the `view` criterion bench for a
//! loaded machine, where wall-clock times of threaded views mean little.
//!
//! Run: `cargo bench -p fvr-host --bench view_cpu` (Linux only).
//! `FVR_BENCH_TILING=B,C[,A]` sets the tiling, `FVR_BENCH_VIEWS` the views
//! per figure (default 40), `FVR_BENCH_N` the volume's side (default 256),
//! `FVR_BENCH_SIDE` the spectrum's (default `FVR_BENCH_N`; up to twice it,
//! e.g. 320 for a mixed-radix side, with the filter of σ = 1.25).
//! `FVR_BENCH_DIRS="x,y,z;x,y,z"` replaces the three directions.
//! `FVR_BENCH_BRICKS=4x4x4,8x4x4` times the slice alone instead, from the
//! linear spectrum and from bricked copies of it
//! (`fvr_engine::spectrum::bricks`), alternating, one thread.
//! `FVR_BENCH_AHEAD=0,8` times whole views instead, on renderers that
//! prefetch that many lines ahead (`Tiling::ahead`), alternating, one
//! thread.

mod common;

use std::hint::black_box;

use common::thread_cpu_ms;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::{Sampling, View};
use fvr_core::render::Request;
use fvr_core::volume::GridOversampling;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::render::view::{render_once, Walk};
use fvr_engine::slice::exact::{extract, extract_bricked, SliceJob, Tiling};
use fvr_engine::slice::{column, strip};
use fvr_engine::spectrum::bricks::Bricked;
use fvr_engine::spectrum::exchange::{exchanged, rows_along_y};
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use half::f16;

fn per_view(views: usize, mut f: impl FnMut()) -> f64 {
    f();
    let start = thread_cpu_ms();
    for _ in 0..views {
        f();
    }
    (thread_cpu_ms() - start) / views as f64
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let env = |k: &str| std::env::var(k).ok();
    let tiling = env("FVR_BENCH_TILING")
        .map(|s| {
            s.parse::<Tiling>()
                .unwrap_or_else(|e| panic!("FVR_BENCH_TILING: {e}"))
        })
        .unwrap_or_default();
    let views = env("FVR_BENCH_VIEWS")
        .and_then(|v| v.parse().ok())
        .unwrap_or(40);
    let n = env("FVR_BENCH_N")
        .and_then(|v| v.parse().ok())
        .unwrap_or(256);
    let side: usize = env("FVR_BENCH_SIDE")
        .and_then(|v| v.parse().ok())
        .unwrap_or(n);
    let kinds = env("FVR_BENCH_FILTERS").unwrap_or_else(|| "kb4,kb6".into());
    let volume = sample(&GaussianMixture::random(1, n, 8), [n, n, n]);
    let mut out = vec![0.0f32; n * n];
    println!(
        "n = {n}, side {side}, {views} views a figure, {tiling:?}; CPU ms per view on one thread"
    );
    for kind in kinds.split(',') {
        let kind = match kind {
            "kb3" => FilterKind::Kb3,
            "kb4" => FilterKind::Kb4,
            "kb5" => FilterKind::Kb5,
            _ => FilterKind::Kb6,
        };
        let filter = if side == n {
            Filter::new(kind, 1)
        } else {
            Filter::for_grid(kind, GridOversampling::X1_25)
        }
        .unwrap();
        let spec = OwnedSpectrum::<f16>::prepare_on::<f32>(&volume, filter, side).unwrap();
        if let Some(bricks) = env("FVR_BENCH_BRICKS") {
            slices(&spec, &bricks, tiling, views);
            continue;
        }
        if let Some(aheads) = env("FVR_BENCH_AHEAD") {
            for (name, dir) in directions(env("FVR_BENCH_DIRS")) {
                let line = prefetching(&spec, &View::along(dir), &aheads, tiling, views);
                println!("{kind:?} {name:8} {line}");
            }
            continue;
        }
        let mut renderer = ViewRenderer::<f32>::new(side, filter)
            .with_threads(1)
            .with_tiling(tiling);
        let mut exact_renderer = ViewRenderer::<f32>::new(side, filter)
            .with_threads(1)
            .with_tiling(tiling)
            .with_walk(Walk::Exact);
        for (name, dir) in directions(env("FVR_BENCH_DIRS")) {
            let view = View::along(dir);
            let host = per_view(views, || {
                renderer
                    .render_into(&spec, black_box(&view), n, n, &mut out)
                    .unwrap()
            });
            let exact = per_view(views, || {
                exact_renderer
                    .render_into(&spec, black_box(&view), n, n, &mut out)
                    .unwrap()
            });
            let request = Request::new(view, n, n);
            let core = per_view(views, || {
                black_box(render_once::<f16, f32>(&spec.view(), &request).unwrap());
            });
            println!(
                "{kind:?} {name:8} host {host:6.2}  exact walk {exact:6.2}  core {core:6.2}  \
                 exact/host {:.2}  core/host {:.2}  slice alone: {}",
                exact / host,
                core / host,
                slice_walks(&spec, &view, tiling, views)
            );
        }
    }
}

/// Slice-only CPU ms per view of the column, strip and exact walks on
/// `view`, each where it applies.
fn slice_walks(spec: &OwnedSpectrum<f16>, view: &View, tiling: Tiling, views: usize) -> String {
    let n = spec.n();
    let kernel = KernelTable::<f32>::new(spec.filter());
    let axes = Sampling::UNIT.slice_axes(&view.frame().unwrap());
    let mut grid = vec![0.0f32; n * n];
    let owned = spec;
    let spec = spec.view();
    let job = SliceJob::new(&spec, &kernel, &axes, tiling, false);
    let mut time = |walk: &dyn Fn(&mut [f32]) -> bool| {
        if walk(&mut grid) {
            format!("{:6.2}", per_view(views, || assert!(walk(&mut grid))))
        } else {
            "     —".into()
        }
    };
    let along = std::cell::RefCell::new(Vec::new());
    let column = time(&|g| column::extract(&job, g, &mut along.borrow_mut()));
    let strip = time(&|g| strip::extract(&job, g));
    // Built before the timing, on all cores, where the memory limit holds it.
    let swapped = owned.exchanged_xy().filter(|_| rows_along_y(&axes));
    let swapped_axes = exchanged(&axes);
    let exchanged = time(&|g| {
        swapped.as_ref().is_some_and(|s| {
            strip::extract_exchanged(
                &SliceJob {
                    spec: s,
                    axes: &swapped_axes,
                    ..job
                },
                g,
            )
        })
    });
    let exact = time(&|g| extract(&job, g));
    format!("column {column}  strip {strip}  exchanged {exchanged}  exact {exact}")
}

/// CPU ms per whole view (one thread) on renderers prefetching each
/// distance in `aheads` (comma-separated), two rounds alternating, the
/// faster round kept.
fn prefetching(
    spec: &OwnedSpectrum<f16>,
    view: &View,
    aheads: &str,
    tiling: Tiling,
    views: usize,
) -> String {
    let n = spec.n();
    let mut out = vec![0.0f32; n * n];
    let mut renderers: Vec<(usize, ViewRenderer<f32>, f64)> = aheads
        .split(',')
        .map(|a| {
            let ahead = a
                .trim()
                .parse()
                .unwrap_or_else(|_| panic!("FVR_BENCH_AHEAD: {a:?} is not a whole number"));
            let renderer = ViewRenderer::<f32>::new(n, spec.filter())
                .with_threads(1)
                .with_tiling(Tiling { ahead, ..tiling });
            (ahead, renderer, f64::INFINITY)
        })
        .collect();
    for _ in 0..2 {
        for (_, renderer, best) in &mut renderers {
            let t = per_view(views, || {
                renderer
                    .render_into(spec, black_box(view), n, n, &mut out)
                    .unwrap()
            });
            *best = best.min(t);
        }
    }
    renderers
        .iter()
        .map(|(ahead, _, t)| format!("ahead {ahead}: {t:6.2}"))
        .collect::<Vec<_>>()
        .join("  ")
}

/// Slice-only CPU ms per view from the linear spectrum and from each
/// bricked copy in `bricks` (`BXxBYxBZ`, comma-separated), two rounds
/// alternating, with a check that the slices agree bit for bit.
fn slices(spec: &OwnedSpectrum<f16>, bricks: &str, tiling: Tiling, views: usize) {
    let n = spec.n();
    let kernel = KernelTable::<f32>::new(spec.filter());
    let copies: Vec<(String, Bricked<f16>)> = bricks
        .split(',')
        .filter_map(|b| {
            let d: Vec<usize> = b.split('x').filter_map(|v| v.parse().ok()).collect();
            let brick = [*d.first()?, *d.get(1)?, *d.get(2)?];
            Some((b.to_string(), Bricked::from_spectrum(&spec.view(), brick)?))
        })
        .collect();
    let mut grid = vec![0.0f32; n * n];
    let mut other = vec![0.0f32; n * n];
    for (name, dir) in [
        ("axis", [0.0, -1.0, 0.0]),
        ("oblique", [1.0, 0.3, 0.2]),
        ("orbit45", [1.0, -1.0, 0.0]),
    ] {
        let axes = Sampling::UNIT.slice_axes(&View::along(dir).frame().unwrap());
        let mut line = format!("{:?} {name:8}", spec.filter().kind());
        let mut linear = Vec::new();
        let mut bricked = vec![Vec::new(); copies.len()];
        for _ in 0..2 {
            linear.push(per_view(views, || {
                assert!(extract(
                    &SliceJob::new(&spec.view(), &kernel, &axes, tiling, false),
                    &mut grid
                ));
            }));
            for (i, (_, copy)) in copies.iter().enumerate() {
                bricked[i].push(per_view(views, || {
                    let job = SliceJob::new(copy, &kernel, &axes, tiling, false);
                    assert!(extract_bricked(&job, &mut other));
                }));
                assert!(grid
                    .iter()
                    .zip(&other)
                    .all(|(a, b)| a.to_bits() == b.to_bits()));
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        line += &format!("  linear {:6.2}", mean(&linear));
        for ((b, _), t) in copies.iter().zip(&bricked) {
            line += &format!("  {b} {:6.2} ({:.2}x)", mean(t), mean(&linear) / mean(t));
        }
        println!("{line}");
    }
}

/// The named directions timed: `dirs` (`x,y,z;x,y,z`, each named by
/// itself) or the axis, an oblique direction and the orbit at 45°.
fn directions(dirs: Option<String>) -> Vec<(String, [f64; 3])> {
    let given: Vec<(String, [f64; 3])> = dirs
        .iter()
        .flat_map(|d| d.split(';'))
        .filter_map(|d| {
            let v: Vec<f64> = d.split(',').filter_map(|x| x.trim().parse().ok()).collect();
            Some((d.trim().to_string(), [*v.first()?, *v.get(1)?, *v.get(2)?]))
        })
        .collect();
    if !given.is_empty() {
        return given;
    }
    [
        ("axis", [0.0, -1.0, 0.0]),
        ("oblique", [1.0, 0.3, 0.2]),
        ("orbit45", [1.0, -1.0, 0.0]),
    ]
    .map(|(name, d)| (name.to_string(), d))
    .to_vec()
}
