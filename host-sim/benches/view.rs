//! Criterion benchmarks of one view at 256³ (f16): the host extraction
//! (`fvr_engine::slice::exact`, on all cores and on one) against the
//! core's single-threaded render, for kb4 and kb6, along an axis, an
//! oblique direction and an orbit direction (45° in the xy-plane, the
//! turntable's slowest); and kb4 at 128³ and 512³ on the oblique
//! direction, for the growth per doubling of n.
//!
//! Run: `cargo bench -p fvr-host --bench view`. Compare as ratios within
//! one run. `FVR_BENCH_TILING=B,C[,A]` sets the tiling (pairs per band,
//! columns per tile, lines prefetched ahead).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::render::Request;
use fvr_engine::render::view::render_once;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::slice::exact::Tiling;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use half::f16;

fn tiling() -> Tiling {
    std::env::var("FVR_BENCH_TILING")
        .ok()
        .map(|s| {
            s.parse::<Tiling>()
                .unwrap_or_else(|e| panic!("FVR_BENCH_TILING: {e}"))
        })
        .unwrap_or_default()
}

fn directions() -> [(&'static str, [f64; 3]); 3] {
    [
        ("axis", [0.0, -1.0, 0.0]),
        ("oblique", [1.0, 0.3, 0.2]),
        ("orbit45", [1.0, -1.0, 0.0]),
    ]
}

fn view_256(c: &mut Criterion) {
    let mut group = c.benchmark_group("view_256");
    group.sample_size(10);
    let n = 256;
    let volume = sample(&GaussianMixture::random(1, n, 8), [n, n, n]);
    let mut out = vec![0.0f32; n * n];
    for kind in [FilterKind::Kb4, FilterKind::Kb6] {
        let filter = Filter::new(kind, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        let name = format!("{kind:?}").to_lowercase();
        for (dir_name, dir) in directions() {
            let view = View::along(dir);
            for (label, threads) in [("host", 0), ("host_1thread", 1)] {
                let mut renderer = ViewRenderer::<f32>::new(n, filter)
                    .with_threads(threads)
                    .with_tiling(tiling());
                group.bench_function(BenchmarkId::new(format!("{name}_{label}"), dir_name), |b| {
                    b.iter(|| {
                        renderer
                            .render_into(&spec, black_box(&view), n, n, &mut out)
                            .unwrap()
                    })
                });
            }
            let core_spec = spec.view();
            let request = Request::new(view, n, n);
            group.bench_function(
                BenchmarkId::new(format!("{name}_core_1thread"), dir_name),
                |b| b.iter(|| render_once::<f16, f32>(&core_spec, black_box(&request)).unwrap()),
            );
        }
    }
    group.finish();
}

fn growth(c: &mut Criterion) {
    let mut group = c.benchmark_group("view_growth_kb4_oblique");
    group.sample_size(10);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let view = View::along([1.0, 0.3, 0.2]);
    for n in [128usize, 256, 512] {
        let volume = sample(&GaussianMixture::random(1, n, 8), [n, n, n]);
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        drop(volume);
        let mut out = vec![0.0f32; n * n];
        let mut renderer = ViewRenderer::<f32>::new(n, filter).with_tiling(tiling());
        group.bench_function(BenchmarkId::new("host", n), |b| {
            b.iter(|| {
                renderer
                    .render_into(&spec, black_box(&view), n, n, &mut out)
                    .unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(views, view_256, growth);
criterion_main!(views);
