//! The fixed-point 3D transform against naive sums in f64.
//!
//! # The floor
//! The model of the module docs with `L = 3·log₂n + 1` roundings (the
//! stages of three passes, all of them over the whole cube with one
//! exponent, and the correction): `6.02·(F − 3) + 7.78 − 10·log10 L −
//! 20·log10 κ` dB, κ the crest factor of the class over the `n³` values. A
//! round trip rounds twice as often, `L = 6·log₂n + 2`. With one exponent
//! per x-line ([`dht_3d_lines`]) the same floor holds: each block's noise
//! is bounded by its own peak, at most the cube's.

use std::vec;
use std::vec::Vec;

use super::*;
use crate::dht::fixed::{dht_3d, dht_3d_lines, idht_3d};
use crate::error::Error;

/// The true 3D DHT by naive 1D sums along x, y and z, then the correction
/// `½[T(−u,v,w) + T(u,−v,w) + T(u,v,−w) − T(−u,−v,−w)]`, in f64.
fn naive_3d(x: &[f64], [nx, ny, nz]: [usize; 3]) -> Vec<f64> {
    let mut t = x.to_vec();
    let mut along = |n: usize, stride: usize, count: usize, base: &dyn Fn(usize) -> usize| {
        for l in 0..count {
            let b = base(l);
            let line: Vec<f64> = (0..n).map(|i| t[b + i * stride]).collect();
            for (i, h) in naive(&line).into_iter().enumerate() {
                t[b + i * stride] = h;
            }
        }
    };
    along(nx, 1, ny * nz, &|l| l * nx);
    along(ny, nx, nx * nz, &|l| (l % nx) + (l / nx) * nx * ny);
    along(nz, nx * ny, nx * ny, &|l| l);
    let at = |u: usize, v: usize, w: usize| t[(u % nx) + nx * ((v % ny) + ny * (w % nz))];
    let mut h = vec![0.0; nx * ny * nz];
    for w in 0..nz {
        for v in 0..ny {
            for u in 0..nx {
                let (mu, mv, mw) = (nx - u, ny - v, nz - w);
                h[u + nx * (v + ny * w)] =
                    0.5 * (at(mu, v, w) + at(u, mv, w) + at(u, v, mw) - at(mu, mv, mw));
            }
        }
    }
    h
}

/// The direct sum (tiny cubes only).
fn naive_3d_direct(x: &[f64], [nx, ny, nz]: [usize; 3]) -> Vec<f64> {
    let tau = 2.0 * core::f64::consts::PI;
    let mut out = vec![0.0; nx * ny * nz];
    for (k, o) in out.iter_mut().enumerate() {
        let (u, v, w) = (k % nx, (k / nx) % ny, k / (nx * ny));
        *o = x
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let (a, b, c) = (i % nx, (i / nx) % ny, i / (nx * ny));
                let th = tau
                    * ((u * a) as f64 / nx as f64
                        + (v * b) as f64 / ny as f64
                        + (w * c) as f64 / nz as f64);
                f * (th.cos() + th.sin())
            })
            .sum();
    }
    out
}

fn floor_3d(n: usize, crest: f64) -> f64 {
    let bits = n.trailing_zeros() as f64;
    floor_db(15, 3.0 * bits + 1.0, crest)
}

fn snr_3d(class: Class, n: usize, seed: u64, tw: &FixedTwiddles<'_, i16>) -> f64 {
    let mut data: Vec<i16> = quantize(&class.signal(n * n * n, n, seed));
    let reference = naive_3d(&integers(&data), [n; 3]);
    let exp = dht_3d(&mut data, [n; 3], tw).unwrap();
    assert!(data.iter().all(|&m| m != i16::MIN));
    snr_db(&reference, &values(&data, exp))
}

#[test]
fn naive_3d_matches_the_direct_sum() {
    for dims in [[4, 4, 4], [8, 4, 2], [2, 8, 4], [1, 4, 8]] {
        let len = dims.iter().product();
        let x = uniform(len, 7);
        let snr = snr_db(&naive_3d_direct(&x, dims), &naive_3d(&x, dims));
        assert!(snr > 250.0, "{dims:?}: {snr:.1} dB");
    }
}

#[test]
fn q15_3d_snr_meets_the_model_for_every_class_at_8_16_32() {
    let tw = table::<i16>(32);
    for class in CLASSES {
        for n in [8usize, 16, 32] {
            let floor = floor_3d(n, class.crest(n * n * n));
            let snr = snr_3d(class, n, 4, &tw);
            assert!(snr >= floor, "{class:?} {n}³: {snr:.1} < {floor:.1} dB");
        }
    }
}

/// 64³ (2.6 · 10^8 naive multiply-adds): `cargo test -p fvr-core --release
/// q15_3d_at_64 -- --ignored`.
#[test]
#[ignore]
fn q15_3d_at_64() {
    let tw = table::<i16>(64);
    for class in [Class::Random, Class::Impulse, Class::Constant] {
        let floor = floor_3d(64, class.crest(64 * 64 * 64));
        let snr = snr_3d(class, 64, 5, &tw);
        std::println!("{class:?} 64³: {snr:.1} dB (floor {floor:.1})");
        assert!(snr >= floor, "{class:?} 64³: {snr:.1} < {floor:.1} dB");
    }
}

/// Boxes with unequal sides, each side at most 16.
const NON_CUBIC: [[usize; 3]; 6] = [
    [16, 4, 2],
    [2, 16, 4],
    [4, 2, 16],
    [1, 8, 8],
    [8, 8, 1],
    [8, 1, 1],
];

#[test]
fn non_cubic_3d_matches_the_direct_sum() {
    let tw = table::<i16>(16);
    for dims in NON_CUBIC {
        let len: usize = dims.iter().product();
        let mut data: Vec<i16> = quantize(&uniform(len, 6));
        let reference = naive_3d_direct(&integers(&data), dims);
        let exp = dht_3d(&mut data, dims, &tw).unwrap();
        let snr = snr_db(&reference, &values(&data, exp));
        let bits = len.trailing_zeros() as f64;
        let floor = floor_db(15, bits + 1.0, Class::Random.crest(len));
        assert!(snr >= floor, "{dims:?}: {snr:.1} < {floor:.1} dB");
    }
}

#[test]
fn all_zero_stays_zero_with_exponent_zero() {
    let tw = table::<i16>(16);
    let mut data = vec![0i16; 16 * 16 * 16];
    assert_eq!(dht_3d(&mut data, [16; 3], &tw).unwrap(), 0);
    assert!(data.iter().all(|&m| m == 0));
}

/// Every value at the most negative integer, and the two extremes in
/// alternation (all energy into one corner bin): outputs stay in
/// `[−MAX, MAX]` (with overflow checks on, a wrap would panic) and meet
/// the floor with the worst crest factor, `√N`.
#[test]
fn full_scale_extremes_neither_wrap_nor_miss_the_floor() {
    let tw = table::<i16>(32);
    for n in [2usize, 8, 32] {
        let len = n * n * n;
        let patterns: [&dyn Fn(usize) -> i16; 3] = [
            &|_| i16::MIN,
            &|i| {
                let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
                if (x + y + z) % 2 == 0 {
                    i16::MIN
                } else {
                    i16::MAX
                }
            },
            &|i| if i % 3 == 0 { i16::MAX } else { i16::MIN },
        ];
        for f in patterns {
            let mut data: Vec<i16> = (0..len).map(f).collect();
            let reference = naive_3d(&integers(&data), [n; 3]);
            let exp = dht_3d(&mut data, [n; 3], &tw).unwrap();
            assert!(data.iter().all(|&m| m != i16::MIN), "{n}³");
            let snr = snr_db(&reference, &values(&data, exp));
            let floor = floor_3d(n, (len as f64).sqrt());
            assert!(snr >= floor, "{n}³: {snr:.1} < {floor:.1} dB");
        }
    }
}

#[test]
fn every_impulse_position_at_8_cubed() {
    let tw = table::<i16>(8);
    let floor = floor_3d(8, Class::Impulse.crest(512));
    for p in 0..512 {
        for amp in [i16::MIN, 1, 12345] {
            let mut data = vec![0i16; 512];
            data[p] = amp;
            let reference = naive_3d(&integers(&data), [8; 3]);
            let exp = dht_3d(&mut data, [8; 3], &tw).unwrap();
            let snr = snr_db(&reference, &values(&data, exp));
            assert!(
                snr >= floor,
                "impulse {amp} at {p}: {snr:.1} < {floor:.1} dB"
            );
        }
    }
}

#[test]
fn round_trip_3d() {
    let tw = table::<i16>(32);
    for n in [2usize, 8, 16, 32] {
        let len = n * n * n;
        let original: Vec<i16> = quantize(&uniform(len, 12));
        let mut data = original.clone();
        let e1 = dht_3d(&mut data, [n; 3], &tw).unwrap();
        let e2 = idht_3d(&mut data, [n; 3], &tw).unwrap();
        let back = values(&data, e1 + e2);
        let snr = snr_db(&integers(&original), &back);
        let bits = n.trailing_zeros() as f64;
        let floor = floor_db(15, 6.0 * bits + 2.0, Class::Random.crest(len));
        assert!(snr >= floor, "round trip {n}³: {snr:.1} < {floor:.1} dB");
    }
}

#[test]
fn q31_3d_meets_the_model_with_31_fraction_bits() {
    let tw = table::<i32>(16);
    for class in CLASSES {
        let n = 16;
        let mut data: Vec<i32> = quantize(&class.signal(n * n * n, n, 3));
        let reference = naive_3d(&integers(&data), [n; 3]);
        let exp = dht_3d(&mut data, [n; 3], &tw).unwrap();
        let snr = snr_db(&reference, &values(&data, exp));
        let floor = floor_db(31, 13.0, class.crest(n * n * n));
        assert!(snr >= floor, "Q31 {class:?} {n}³: {snr:.1} < {floor:.1} dB");
    }
}

#[test]
fn bad_shapes_are_errors() {
    let tw = table::<i16>(8);
    let mut data = vec![0i16; 8 * 8 * 8];
    assert!(matches!(
        dht_3d(&mut data, [8, 8, 4], &tw),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(dht_3d(&mut data[..6 * 8 * 8], [6, 8, 8], &tw).is_err());
    assert!(matches!(
        dht_3d(&mut vec![0i16; 16 * 16 * 2], [16, 16, 2], &tw),
        Err(Error::TwiddlesTooShort { .. })
    ));
}

/// `m · 2^(e + e_l)` for every mantissa of x-line `l`.
fn line_values<S: FixedSample>(v: &[S], nx: usize, e: i32, exps: &[i8]) -> Vec<f64> {
    v.chunks_exact(nx)
        .zip(exps)
        .flat_map(|(line, &el)| values(line, e + el as i32))
        .collect()
}

fn snr_3d_lines<S: FixedSample>(
    data: &mut [S],
    dims: [usize; 3],
    tw: &FixedTwiddles<'_, S>,
) -> f64 {
    let reference = naive_3d(&integers(data), dims);
    let mut exps = vec![0i8; dims[1] * dims[2]];
    let e = dht_3d_lines(data, dims, &mut exps, tw).unwrap();
    assert!(data.iter().all(|m| m.to_i64() > -(1 << S::FRAC_BITS)));
    snr_db(&reference, &line_values(data, dims[0], e, &exps))
}

#[test]
fn per_line_exponents_meet_the_model_for_every_class_and_shape() {
    let tw = table::<i16>(32);
    for class in CLASSES {
        for n in [2usize, 8, 16, 32] {
            let floor = floor_3d(n, class.crest(n * n * n));
            let mut data: Vec<i16> = quantize(&class.signal(n * n * n, n, 8));
            let snr = snr_3d_lines(&mut data, [n; 3], &tw);
            assert!(snr >= floor, "{class:?} {n}³: {snr:.1} < {floor:.1} dB");
        }
    }
    for dims in NON_CUBIC {
        let len: usize = dims.iter().product();
        let mut data: Vec<i16> = quantize(&uniform(len, 2));
        let snr = snr_3d_lines(&mut data, dims, &tw);
        let floor = floor_db(
            15,
            len.trailing_zeros() as f64 + 1.0,
            Class::Random.crest(len),
        );
        assert!(snr >= floor, "{dims:?}: {snr:.1} < {floor:.1} dB");
    }
    let tw31 = table::<i32>(16);
    let mut data: Vec<i32> = quantize(&uniform(4096, 1));
    let snr = snr_3d_lines(&mut data, [16; 3], &tw31);
    let floor = floor_db(31, 13.0, Class::Random.crest(4096));
    assert!(snr >= floor, "Q31 16³: {snr:.1} < {floor:.1} dB");
}

#[test]
fn per_line_exponents_at_the_extremes() {
    let tw = table::<i16>(32);
    let mut zeros = vec![0i16; 8 * 8 * 8];
    let mut exps = vec![1i8; 64];
    assert_eq!(dht_3d_lines(&mut zeros, [8; 3], &mut exps, &tw).unwrap(), 0);
    assert!(zeros.iter().all(|&m| m == 0));
    for n in [2usize, 8, 32] {
        let len = n * n * n;
        for f in [&|_| i16::MIN, &|i: usize| {
            if i % 3 == 0 {
                i16::MAX
            } else {
                i16::MIN
            }
        }] as [&dyn Fn(usize) -> i16; 2]
        {
            let mut data: Vec<i16> = (0..len).map(f).collect();
            let snr = snr_3d_lines(&mut data, [n; 3], &tw);
            let floor = floor_3d(n, (len as f64).sqrt());
            assert!(snr >= floor, "{n}³: {snr:.1} < {floor:.1} dB");
        }
    }
    let floor = floor_3d(8, Class::Impulse.crest(512));
    for p in 0..512 {
        let mut data = vec![0i16; 512];
        data[p] = i16::MIN;
        let snr = snr_3d_lines(&mut data, [8; 3], &tw);
        assert!(snr >= floor, "impulse at {p}: {snr:.1} < {floor:.1} dB");
    }
    let mut exps = vec![0i8; 63];
    assert!(dht_3d_lines(&mut vec![0i16; 512], [8; 3], &mut exps, &tw).is_err());
}

/// A volume-like input (a smooth ball, the energy of whose spectrum
/// concentrates near the origin): per-line exponents keep more than one
/// exponent for the cube. Printed with `--nocapture`.
#[test]
fn per_line_exponents_keep_more_on_a_ball() {
    let tw = table::<i16>(32);
    for n in [16usize, 32] {
        let c = n as f64 / 2.0;
        let ball: Vec<f64> = (0..n * n * n)
            .map(|i| {
                let r2: f64 = [i % n, (i / n) % n, i / (n * n)]
                    .map(|v| (v as f64 + 0.5 - c) / c)
                    .iter()
                    .map(|d| d * d)
                    .sum();
                (1.0 - r2).max(0.0)
            })
            .collect();
        let mut one: Vec<i16> = quantize(&ball);
        let mut lines = one.clone();
        let reference = naive_3d(&integers(&one), [n; 3]);
        let e = dht_3d(&mut one, [n; 3], &tw).unwrap();
        let single = snr_db(&reference, &values(&one, e));
        let per_line = snr_3d_lines(&mut lines, [n; 3], &tw);
        std::println!("ball {n}³: one exponent {single:.1} dB, per x-line {per_line:.1} dB");
        assert!(per_line > single, "{n}³: {per_line:.1} <= {single:.1} dB");
    }
}
