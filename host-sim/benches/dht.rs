//! Criterion benchmarks: the true 2D DHT in f32 (in place, one thread) at
//! 256² and 512², batched column passes (`dht_2d`) against the line-by-line
//! path (`dht_2d_lines`); the peer figures come from
//! `bash bench/peers/fftw-dht.sh` (FFTW 3's separable FFTW_DHT and r2c).
//! `dht_2d_sparse_f32`: a 256² array whose values lie on 58 rows (an
//! adaptive view's slice), its row pass batched over those rows as lanes
//! (`lanes`, with `dht_2d_sparse_len` of scratch) or one row at a time
//! (`rows`, with `n`), against the same array transformed as a dense one
//! would be (`dense`, every row: one value on each of the other rows).
//!
//! Run: `cargo bench -p fvr-host --bench dht`.

mod common;

use std::hint::black_box;

use common::lcg_values;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::dht::{dht_2d, dht_2d_lines, dht_2d_sparse_len, Twiddles};

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("dht_2d_f32");
    for n in [256usize, 512] {
        let mut tw_buf = vec![0.0f32; Twiddles::<f32>::buffer_len(n)];
        let tw = Twiddles::new(&mut tw_buf, n).unwrap();
        let input = lcg_values(n * n);
        let mut data = input.clone();
        let mut column = vec![0.0f32; n];
        // Each iteration restores the input first (timed separately as
        // `copy_only`, to subtract), so values stay bounded.
        group.bench_function(BenchmarkId::new("batched", n), |b| {
            b.iter(|| {
                data.copy_from_slice(&input);
                dht_2d(black_box(&mut data), n, n, &mut column, &tw).unwrap()
            })
        });
        group.bench_function(BenchmarkId::new("lines", n), |b| {
            b.iter(|| {
                data.copy_from_slice(&input);
                dht_2d_lines(black_box(&mut data), n, n, &mut column, &tw).unwrap()
            })
        });
        group.bench_function(BenchmarkId::new("copy_only", n), |b| {
            b.iter(|| data.copy_from_slice(black_box(&input)))
        });
    }
    group.finish();
    sparse(c);
}

/// The 2D DHT of a slice with few nonzero rows, by scratch given.
fn sparse(c: &mut Criterion) {
    let (n, rows) = (256usize, 58);
    let mut tw_buf = vec![0.0f32; Twiddles::<f32>::buffer_len(n)];
    let tw = Twiddles::new(&mut tw_buf, n).unwrap();
    // Rows 0 … 28 and n − 29 … n − 1, as a slice's low frequencies.
    let held = |y: usize| y < rows / 2 || y >= n - rows / 2;
    let input: Vec<f32> = lcg_values(n * n)
        .into_iter()
        .enumerate()
        .map(|(i, v)| if held(i / n) { v } else { 0.0 })
        .collect();
    let mut dense = input.clone();
    for y in (0..n).filter(|&y| !held(y)) {
        dense[y * n] = 1e-3;
    }
    let mut group = c.benchmark_group("dht_2d_sparse_f32");
    let mut data = input.clone();
    for (name, from, scratch) in [
        ("lanes", &input, dht_2d_sparse_len(n)),
        ("rows", &input, n),
        ("dense", &dense, n),
    ] {
        let mut column = vec![0.0f32; scratch];
        group.bench_function(BenchmarkId::new(name, n), |b| {
            b.iter(|| {
                data.copy_from_slice(from);
                dht_2d(black_box(&mut data), n, n, &mut column, &tw).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(dht, benches);
criterion_main!(dht);
