//! Criterion benchmarks: the true 2D DHT in f32 (in place, one thread) at
//! 256² and 512², batched column passes (`dht_2d`) against the line-by-line
//! path (`dht_2d_lines`); the peer figures come from
//! `bash bench/peers/fftw-dht.sh` (FFTW 3's separable FFTW_DHT and r2c).
//!
//! Run: `cargo bench -p fvr-host --bench dht`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::dht::{dht_2d, dht_2d_lines, Twiddles};

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("dht_2d_f32");
    for n in [256usize, 512] {
        let mut tw_buf = vec![0.0f32; Twiddles::<f32>::buffer_len(n)];
        let tw = Twiddles::new(&mut tw_buf, n).unwrap();
        let mut state = 12345u32;
        let input: Vec<f32> = (0..n * n)
            .map(|_| {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (state >> 8) as f32 / 16_777_216.0 - 0.5
            })
            .collect();
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
}

criterion_group!(dht, benches);
criterion_main!(dht);
