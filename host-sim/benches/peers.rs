//! Criterion benchmarks: the frequency-domain view (kb3, f16; extraction on
//! all cores and on one) against the spatial-domain peer ray caster (f32,
//! trilinear, step 1 voxel, all cores), one view of n² pixels at 128³ and
//! 256³. Compare as ratios within one run.
//!
//! Run: `cargo bench -p fvr-host --bench peers`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_host::reference::raycast::RayCaster;
use half::f16;

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("view_vs_peer");
    group.sample_size(10);
    let view = View::along([1.0, 0.3, 0.2]);
    for n in [128usize, 256] {
        let volume = sample(&GaussianMixture::random(1, n, 8), [n, n, n]);
        let filter = Filter::new(FilterKind::Kb3, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        let mut out = vec![0.0f32; n * n];
        for (name, threads) in [("frequency_kb3_f16", 0), ("frequency_kb3_f16_1thread", 1)] {
            let mut renderer = ViewRenderer::<f32>::new(n, filter).with_threads(threads);
            group.bench_function(BenchmarkId::new(name, n), |b| {
                b.iter(|| {
                    renderer
                        .render_into(&spec, black_box(&view), n, n, &mut out)
                        .unwrap()
                })
            });
        }
        let caster = RayCaster::new(&volume);
        group.bench_function(BenchmarkId::new("raycast_trilinear_f32", n), |b| {
            b.iter(|| caster.project(black_box(&view), n, n, 1.0, 0).unwrap())
        });
    }
    group.finish();
}

criterion_group!(peers, benches);
criterion_main!(peers);
