//! Criterion benchmarks: preparing an f16 spectrum (f32 arithmetic, Kaiser–
//! Bessel W = 4, σ = 1) of a Gaussian mixture at 128³ and 256³, through the
//! FFTs on all cores (`fast`) and through the core's in-place transform on
//! one core (`in_place`, at 128³ only: it takes about 0.75 s at 256³).
//!
//! Run: `cargo bench -p fvr-host --bench prepare`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::filter::{Filter, FilterKind};
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use half::f16;

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("prepare_f16_kb4");
    group.sample_size(10);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    for n in [128usize, 256] {
        let volume = sample(&GaussianMixture::random(1, n, 8), [n, n, n]);
        group.bench_function(BenchmarkId::new("fast", n), |b| {
            b.iter(|| OwnedSpectrum::<f16>::prepare::<f32>(black_box(&volume), filter).unwrap())
        });
        if n <= 128 {
            group.bench_function(BenchmarkId::new("in_place", n), |b| {
                b.iter(|| {
                    OwnedSpectrum::<f16>::prepare_in_place::<f32>(black_box(&volume), filter)
                        .unwrap()
                })
            });
        }
    }
    group.finish();
}

criterion_group!(prepare, benches);
criterion_main!(prepare);
