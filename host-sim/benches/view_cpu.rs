//! CPU time per view on one thread (the thread's own user + system time
//! from `/proc/thread-self/stat`, so time the thread spends waiting for a
//! core shared with other processes is not counted): the host extraction
//! (`fvr_host::render::fast_slice`) against the core's render, at 256³
//! f16, kb4 and kb6, along an axis, an oblique direction and the orbit
//! direction at 45°. A companion of the `view` criterion bench for a
//! loaded machine, where wall-clock times of threaded views mean little.
//!
//! Run: `cargo bench -p fvr-host --bench view_cpu` (Linux only).
//! `FVR_BENCH_TILING=B,C` sets the tiling, `FVR_BENCH_VIEWS` the views
//! per figure (default 40), `FVR_BENCH_N` the volume's side (default 256),
//! `FVR_BENCH_SIDE` the spectrum's (default `FVR_BENCH_N`; up to twice it,
//! e.g. 320 for a mixed-radix side, with the filter of σ = 1.25).

use std::hint::black_box;

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::render::Request;
use fvr_core::volume::GridOversampling;
use fvr_host::render::fast_slice::Tiling;
use fvr_host::render::spectrum::{OwnedSpectrum, ViewRenderer};
use fvr_host::render::view::render_once;
use fvr_host::sources::phantom::{sample, GaussianMixture};
use half::f16;

/// This thread's user + system time in ms (clock ticks of 10 ms).
fn thread_cpu_ms() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
    // Fields after the command name in parentheses; utime and stime are
    // fields 14 and 15 of the whole line.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) * 10.0
}

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
        .and_then(|s| {
            let (b, c) = s.split_once(',')?;
            Some(Tiling {
                band: b.trim().parse().ok()?,
                chunk: c.trim().parse().ok()?,
            })
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
        let mut renderer = ViewRenderer::<f32>::new(side, filter)
            .with_threads(1)
            .with_tiling(tiling);
        for (name, dir) in [
            ("axis", [0.0, -1.0, 0.0]),
            ("oblique", [1.0, 0.3, 0.2]),
            ("orbit45", [1.0, -1.0, 0.0]),
        ] {
            let view = View::along(dir);
            let host = per_view(views, || {
                renderer
                    .render_into(&spec, black_box(&view), n, n, &mut out)
                    .unwrap()
            });
            let request = Request::new(view, n, n);
            let core = per_view(views, || {
                black_box(render_once::<f16, f32>(&spec.view(), &request).unwrap());
            });
            println!(
                "{kind:?} {name:8} host {host:6.2}  core {core:6.2}  core/host {:.2}",
                core / host
            );
        }
    }
}
