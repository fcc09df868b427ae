//! The per-view cost the accuracy planner compares
//! (`fvr_engine::plan::cost_grid`), measured: CPU time per view on
//! one thread (the thread's own user + system time, so a loaded machine
//! counts little) for each candidate filter × grid on a real head, over an
//! orbit of views, and the least-squares fit of the model
//! `t = n²·(a + b·W³) + n²·log₂n·(c on powers of two, d on mixed sides)`
//! whose ratios the planner uses.
//!
//! Volume: the CT head resampled to 256 when `FVR_CT_HEAD` names
//! `Cranium.inv3` (`bash scripts/fetch-ct-head.sh`), else `brainsmall`.
//!
//! Beside each whole view, the slice extraction alone
//! (`fvr_engine::slice::exact::extract` on one thread, the rest of
//! the view being the 2D inverse transform and the crop).
//!
//! Run: `FVR_CT_HEAD=$(bash scripts/fetch-ct-head.sh) cargo bench -p fvr-host --bench plan_cost`
//! (Linux only). `FVR_BENCH_VIEWS` sets the views per figure (default 24).

mod common;

use std::hint::black_box;

use common::thread_cpu_ms;
use fvr_core::filter::KernelTable;
use fvr_core::geometry::Sampling;
use fvr_core::volume::GridOversampling;
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::plan::{grid_filter, image_side, ALL_GRIDS, CANDIDATE_FILTERS};
use fvr_engine::render::turntable::orbit;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::slice::exact::{self, SliceJob, Tiling};
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_host::sources::datasets::load_dataset;
use half::f16;

/// Solve the normal equations `AᵀA x = Aᵀy` by Gaussian elimination.
fn least_squares<const P: usize>(rows: &[([f64; P], f64)]) -> [f64; P] {
    let mut m = [[0.0; P]; P];
    let mut v = [0.0; P];
    for (a, y) in rows {
        for i in 0..P {
            v[i] += a[i] * y;
            for j in 0..P {
                m[i][j] += a[i] * a[j];
            }
        }
    }
    for col in 0..P {
        let pivot = (col..P)
            .max_by(|&x, &y| m[x][col].abs().total_cmp(&m[y][col].abs()))
            .unwrap_or(col);
        m.swap(col, pivot);
        v.swap(col, pivot);
        for r in 0..P {
            if r != col && m[col][col] != 0.0 {
                let f = m[r][col] / m[col][col];
                for j in 0..P {
                    m[r][j] -= f * m[col][j];
                }
                v[r] -= f * v[col];
            }
        }
    }
    let mut x = [0.0; P];
    for i in 0..P {
        x[i] = if m[i][i] == 0.0 { 0.0 } else { v[i] / m[i][i] };
    }
    x
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let views = std::env::var("FVR_BENCH_VIEWS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(24);
    let (name, volume) = if std::env::var_os("FVR_CT_HEAD").is_some() {
        let ct = load_dataset("ct-head").unwrap().unwrap();
        ("ct-head@256", ct.resample_isotropic(256).unwrap())
    } else {
        ("brainsmall", load_dataset("brainsmall").unwrap().unwrap())
    };
    let orbit = orbit([1.0, 0.35, 0.2], [0.0, 0.0, 1.0], views).unwrap();
    println!(
        "{name} {:?}: CPU ms per view on one thread, {views} views",
        volume.dims
    );
    let mut rows = Vec::new();
    for grid in ALL_GRIDS {
        let n = grid.side(volume.dims).unwrap();
        let side = image_side(volume.dims, n).unwrap();
        let mut out = vec![0.0f32; side * side];
        for kind in CANDIDATE_FILTERS {
            let filter = grid_filter(&volume, kind, grid, KbDesign::Auto).unwrap();
            let spec = OwnedSpectrum::<f16>::prepare_on::<f32>(&volume, filter, n).unwrap();
            let mut renderer = ViewRenderer::<f32>::new(n, filter).with_threads(1);
            renderer
                .render_into(&spec, &orbit[0], side, side, &mut out)
                .unwrap();
            let start = thread_cpu_ms();
            for v in &orbit {
                renderer
                    .render_into(&spec, black_box(v), side, side, &mut out)
                    .unwrap();
            }
            let ms = (thread_cpu_ms() - start) / views as f64;
            let kernel = KernelTable::<f32>::new(filter);
            let axes: Vec<_> = orbit
                .iter()
                .map(|v| Sampling::UNIT.slice_axes(&v.frame().unwrap()))
                .collect();
            let mut slice = vec![0.0f32; n * n];
            let start = thread_cpu_ms();
            for a in &axes {
                let (spec, tiling) = (spec.view(), Tiling::default());
                let job = SliceJob::new(&spec, &kernel, black_box(a), tiling, false);
                assert!(exact::extract(&job, &mut slice));
            }
            let extract_ms = (thread_cpu_ms() - start) / views as f64;
            let w = kind.width() as f64;
            let nn = (n * n) as f64;
            let log = nn * (n as f64).log2();
            let pow2 = grid == GridOversampling::X1 || grid == GridOversampling::X2;
            rows.push((
                [
                    nn,
                    nn * w * w * w,
                    if pow2 { log } else { 0.0 },
                    if pow2 { 0.0 } else { log },
                ],
                ms,
            ));
            println!(
                "{:5} σ={:4} n={n:4}: {ms:7.2} ms (extraction {extract_ms:7.2} ms)",
                kind.name(),
                grid.name()
            );
        }
    }
    let [a, b, c, d] = least_squares(&rows);
    println!(
        "fit, ns: per sample {:.3}, per tap {:.3}, per n²·log₂n radix-2 {:.3}, mixed {:.3}",
        a * 1e6,
        b * 1e6,
        c * 1e6,
        d * 1e6
    );
    println!(
        "model ratios to a tap: sample {:.1}, radix-2 {:.2}, mixed {:.2}",
        a / b,
        c / b,
        d / b
    );
    for ((x, y), (grid, kind)) in rows.iter().zip(
        ALL_GRIDS
            .iter()
            .flat_map(|g| CANDIDATE_FILTERS.iter().map(move |k| (g, k))),
    ) {
        let fit: f64 = x.iter().zip([a, b, c, d]).map(|(x, p)| x * p).sum();
        println!(
            "{:5} σ={:4}: measured {y:7.2} ms, model {fit:7.2} ms",
            kind.name(),
            grid.name()
        );
    }
}
