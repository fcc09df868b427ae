//! Criterion benchmarks: finishing a view (sub-pixel shift, true 2D
//! inverse DHT, crop of a 256 × 256 image) in f32, the core's
//! `finish_with` on one thread against `render::fast_inverse` on one rayon
//! thread and on all cores: `lines_*` a pair of lines at a time through the
//! core's 1D transforms (`finish_threaded`), `lanes_*` 16 lines as the
//! lanes of one transform (`MixedFinish`, mixed-radix sides, what `fvr`
//! uses); 320 is the CT head's default side (mixed radix), 512 its 2×
//! padding (radix 2).
//!
//! Run: `cargo bench -p fvr-host --bench inverse`.

mod common;

use std::hint::black_box;

use common::lcg_values;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::dht::{mixed_table_len, MixedPlan, Twiddles};
use fvr_core::image::{aux_len, finish_with, Crop, Inverse, Placement};
use fvr_engine::image::inverse::{finish_threaded, MixedFinish};

/// Image side, as the CT head's default view.
const IMAGE: usize = 256;

fn bench_side(c: &mut Criterion, n: usize, inverse: Inverse<'_, f32>) {
    let mut group = c.benchmark_group("finish_f32");
    let input = lcg_values(n * n);
    let place = Placement {
        col0: -(IMAGE as i64) / 2,
        row0: IMAGE as i64 / 2,
        shift: [0.3, 0.6],
    };
    let crop = Crop::new(place, 1.0, IMAGE, IMAGE);
    let mut grid = input.clone();
    let mut aux = vec![0.0f32; aux_len(n)];
    let mut trans = vec![0.0f32; n * n];
    let mut out = vec![0.0f32; IMAGE * IMAGE];
    // Each iteration restores the grid first (timed as `copy_only`).
    group.bench_function(BenchmarkId::new("core", n), |b| {
        b.iter(|| {
            grid.copy_from_slice(&input);
            finish_with(black_box(&mut grid), n, &crop, inverse, &mut aux, &mut out).unwrap()
        })
    });
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get());
    let mut lanes = matches!(inverse, Inverse::Mixed(_)).then(|| MixedFinish::new(n).unwrap());
    for (name, t) in [("1", 1), ("all", threads)] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap();
        if let Some(lanes) = lanes.as_mut() {
            group.bench_function(BenchmarkId::new(format!("lanes_{name}"), n), |b| {
                pool.install(|| {
                    b.iter(|| {
                        grid.copy_from_slice(&input);
                        lanes.finish(black_box(&mut grid), &crop, &mut out).unwrap()
                    })
                })
            });
        }
        group.bench_function(BenchmarkId::new(format!("lines_{name}"), n), |b| {
            pool.install(|| {
                b.iter(|| {
                    grid.copy_from_slice(&input);
                    finish_threaded(
                        black_box(&mut grid),
                        n,
                        &crop,
                        inverse,
                        &mut trans,
                        &mut out,
                    )
                    .unwrap()
                })
            })
        });
    }
    group.bench_function(BenchmarkId::new("copy_only", n), |b| {
        b.iter(|| grid.copy_from_slice(black_box(&input)))
    });
    group.finish();
}

fn benches(c: &mut Criterion) {
    let mut table = vec![0.0f32; mixed_table_len(320)];
    let plan = MixedPlan::new(&mut table, 320).unwrap();
    bench_side(c, 320, Inverse::Mixed(&plan));
    let mut tw_buf = vec![0.0f32; Twiddles::<f32>::buffer_len(512)];
    let tw = Twiddles::new(&mut tw_buf, 512).unwrap();
    bench_side(c, 512, Inverse::Radix2(&tw));
}

criterion_group!(inverse, benches);
criterion_main!(inverse);
