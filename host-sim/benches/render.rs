//! Criterion benchmarks: preprocessing (premultiply, pad, 3D DHT into f16)
//! and per-view rendering (slice extraction and 2D inverse DHT), at 64³,
//! 128³ and 256³ on the Gaussian-mixture phantom.
//!
//! Run: `cargo bench -p fvr-host --bench render`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use half::f16;

fn benches(c: &mut Criterion) {
    let mut prep = c.benchmark_group("preprocess_f16");
    prep.sample_size(10);
    for n in [64usize, 128, 256] {
        let volume = sample(&GaussianMixture::random(1, n, 8), [n, n, n]);
        let filter = Filter::new(FilterKind::Kb3, 1).unwrap();
        prep.bench_with_input(BenchmarkId::from_parameter(n), &volume, |b, v| {
            b.iter(|| OwnedSpectrum::<f16>::prepare::<f32>(black_box(v), filter).unwrap())
        });
    }
    prep.finish();

    let mut view = c.benchmark_group("view_f16");
    view.sample_size(20);
    for n in [64usize, 128, 256] {
        let volume = sample(&GaussianMixture::random(1, n, 8), [n, n, n]);
        for kind in [FilterKind::Kb3, FilterKind::Kb4, FilterKind::Kb6] {
            let filter = Filter::new(kind, 1).unwrap();
            let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
            let mut renderer = ViewRenderer::<f32>::new(n, filter);
            let mut out = vec![0.0f32; n * n];
            let v = View::along([1.0, 0.3, 0.2]);
            view.bench_function(BenchmarkId::new(kind.name(), n), |b| {
                b.iter(|| {
                    renderer
                        .render_into(&spec, black_box(&v), n, n, &mut out)
                        .unwrap()
                })
            });
        }
    }
    view.finish();
}

criterion_group!(render, benches);
criterion_main!(render);
