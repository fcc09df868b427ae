//! Mixed-radix against radix-2 DHTs in f32, one thread: 1D lines of 320
//! against 256 and 512, and 3D cubes of 160³ against 128³ and 256³ (f32
//! storage). Plain timing (no criterion): the median of repeated runs,
//! each on a fresh copy of the input.
//!
//! Run: `cargo bench -p fvr-core --bench mixed`.

use std::hint::black_box;
use std::time::Instant;

use fvr_core::dht::{
    dht, dht_3d, dht_3d_mixed, dht_3d_mixed_scratch_len, dht_3d_scratch_len, dht_mixed,
    mixed_scratch_len, mixed_table_len, MixedPlan, Twiddles,
};

fn signal(n: usize) -> Vec<f32> {
    let mut s = 12345u32;
    (0..n)
        .map(|_| {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (s >> 8) as f32 / 16_777_216.0 - 0.5
        })
        .collect()
}

/// Median seconds of `runs` timed calls of `f` (each restores its input).
fn median(runs: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(|a, b| a.total_cmp(b));
    t[runs / 2]
}

/// Nanoseconds per line, `batch` lines per timed call, copy included.
fn line(n: usize, mixed: bool) -> f64 {
    const BATCH: usize = 1000;
    let input = signal(n);
    let mut data = input.clone();
    let mut table = vec![0.0f32; mixed_table_len(n).max(Twiddles::<f32>::buffer_len(n))];
    let mut scratch = vec![0.0f32; mixed_scratch_len(n)];
    let secs = if mixed {
        let plan = MixedPlan::new(&mut table, n).unwrap();
        median(101, || {
            for _ in 0..BATCH {
                data.copy_from_slice(&input);
                dht_mixed(black_box(&mut data), &mut scratch, &plan).unwrap();
            }
        })
    } else {
        let tw = Twiddles::new(&mut table, n).unwrap();
        median(101, || {
            for _ in 0..BATCH {
                data.copy_from_slice(&input);
                dht(black_box(&mut data), &tw).unwrap();
            }
        })
    };
    secs / BATCH as f64 * 1e9
}

/// Milliseconds per 3D transform of an `n³` cube in f32, copy included.
fn cube(n: usize, mixed: bool, runs: usize) -> f64 {
    let input = signal(n * n * n);
    let mut data = input.clone();
    let dims = [n; 3];
    let mut table = vec![0.0f32; mixed_table_len(n).max(Twiddles::<f32>::buffer_len(n))];
    let secs = if mixed {
        let plan = MixedPlan::new(&mut table, n).unwrap();
        let mut scratch = vec![0.0f32; dht_3d_mixed_scratch_len(dims)];
        median(runs, || {
            data.copy_from_slice(&input);
            dht_3d_mixed(black_box(&mut data), dims, &mut scratch, [&plan; 3]).unwrap();
        })
    } else {
        let tw = Twiddles::new(&mut table, n).unwrap();
        let mut scratch = vec![0.0f32; dht_3d_scratch_len(dims)];
        median(runs, || {
            data.copy_from_slice(&input);
            dht_3d(black_box(&mut data), dims, &mut scratch, &tw).unwrap();
        })
    };
    secs * 1e3
}

fn main() {
    println!("1D f32, ns per line (median of 101 batches of 1000):");
    for (n, mixed) in [
        (256, false),
        (320, true),
        (512, false),
        (256, true),
        (512, true),
    ] {
        let kind = if mixed { "mixed" } else { "radix-2" };
        let ns = line(n, mixed);
        println!(
            "  {kind:8} {n:4}: {ns:8.0} ns  ({:.2} ns per n·log₂n)",
            ns / (n as f64 * (n as f64).log2())
        );
    }
    println!("3D f32, ms per cube (median):");
    for (n, mixed, runs) in [
        (128, false, 7),
        (160, true, 7),
        (256, false, 3),
        (128, true, 7),
    ] {
        let kind = if mixed { "mixed" } else { "radix-2" };
        let ms = cube(n, mixed, runs);
        println!("  {kind:8} {n:4}³: {ms:8.1} ms");
    }
}
