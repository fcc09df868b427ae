//! Criterion benchmarks: one view with the full filter against the adaptive
//! one (paper §4), kb3 → 1³ at 40 dB, oversampling 2, on a 128³ Gaussian
//! mixture (f16). Compare as ratios within one run.
//!
//! Run: `cargo bench -p fvr-host --bench adaptive`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_host::render::adaptive::{AdaptiveMarks, AdaptiveSettings};
use fvr_host::render::spectrum::{OwnedSpectrum, ViewRenderer};
use fvr_host::sources::phantom::{sample, GaussianMixture};
use half::f16;

fn benches(c: &mut Criterion) {
    let n = 128;
    let volume = sample(&GaussianMixture::random(1, n, 8), [n; 3]);
    let filter = Filter::new(FilterKind::Kb3, 2).unwrap();
    let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
    let marks = AdaptiveMarks::build(&spec, &AdaptiveSettings::new(40.0)).unwrap();
    let view = View::along([1.0, 0.3, 0.2]);
    let mut renderer = ViewRenderer::<f32>::new(spec.n(), filter);
    let mut out = vec![0.0f32; n * n];
    let mut group = c.benchmark_group("adaptive_kb3_os2_128");
    group.sample_size(20);
    group.bench_function("full", |b| {
        b.iter(|| {
            renderer
                .render_into(&spec, black_box(&view), n, n, &mut out)
                .unwrap()
        })
    });
    group.bench_function("adaptive_40db", |b| {
        b.iter(|| {
            marks
                .render::<f16, f32>(&spec, black_box(&view), n, n)
                .unwrap()
        })
    });
    group.finish();
}

criterion_group!(adaptive, benches);
criterion_main!(adaptive);
