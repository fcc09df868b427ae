//! Inputs at and beyond the edges: extremes, zeros, bad lengths and
//! tables, and the scaling limits against every twiddle pair.

use std::vec;
use std::vec::Vec;

use super::*;
use crate::dht::fixed::{dht, dht_2d, idht, idht_2d, FixedSample, FixedTwiddles};
use crate::error::Error;

/// Extreme inputs: every value the most negative integer, or the two
/// extremes in patterns that drive the largest growth; outputs must stay
/// in `[−MAX, MAX]` (with overflow checks on, any wrap would panic).
#[test]
fn extreme_inputs_neither_wrap_nor_panic() {
    let tw = table::<i16>(1024);
    for bits in 0..=10 {
        let n = 1usize << bits;
        let patterns: [&dyn Fn(usize) -> i16; 4] = [
            &|_| i16::MIN,
            &|i| if i % 2 == 0 { i16::MIN } else { i16::MAX },
            &|i| {
                if (i * 5 / 3) % 2 == 0 {
                    i16::MIN
                } else {
                    i16::MAX
                }
            },
            &|i| {
                if i.count_ones() % 2 == 0 {
                    i16::MAX
                } else {
                    i16::MIN
                }
            },
        ];
        for f in patterns {
            let mut data: Vec<i16> = (0..n).map(f).collect();
            let reference = naive(&integers(&data));
            let exp = dht(&mut data, &tw).unwrap();
            assert!(data.iter().all(|&m| m != i16::MIN));
            let snr = snr_db(&reference, &values(&data, exp));
            let floor = floor_db(15, bits.max(1) as f64, (n as f64).sqrt().max(1.0));
            assert!(snr >= floor, "N={n}: {snr:.1} dB");
        }
    }
    for (nx, ny) in [(64, 64), (1, 1), (1, 8), (8, 1), (2, 2)] {
        let mut data = vec![i16::MIN; nx * ny];
        data[0] = 3;
        let reference = naive_2d_direct(&integers(&data), nx, ny);
        let exp = dht_2d(&mut data, nx, ny, &tw).unwrap();
        assert!(data.iter().all(|&m| m != i16::MIN), "{nx}x{ny}");
        let snr = snr_db(&reference, &values(&data, exp));
        let worst_crest = ((nx * ny) as f64).sqrt();
        let floor = floor_db(15, (nx * ny).trailing_zeros().max(1) as f64, worst_crest);
        assert!(snr >= floor, "{nx}x{ny}: {snr:.1} dB");
    }
}

/// Random mixtures of the extremes, zeros and random values, 1D and 2D,
/// both widths: no output may hold the most negative integer, and the
/// result must meet the floor for the worst crest factor `√N`.
#[test]
fn random_extremes_stay_in_range() {
    fn run<S: FixedSample>(extremes: [S; 2], tw: &FixedTwiddles<'_, S>) {
        let frac = S::FRAC_BITS;
        for seed in 0..40u64 {
            let bits = 1 + seed as usize % 10;
            let n = 1usize << bits;
            let u = uniform(2 * n, seed);
            let pick = |i: usize| match ((u[2 * i] + 1.0) * 2.0) as usize {
                0 => extremes[0],
                1 => extremes[1],
                2 => S::default(),
                _ => S::from_f64(u[2 * i + 1]),
            };
            let mut data: Vec<S> = (0..n).map(pick).collect();
            let reference = naive(&integers(&data));
            let exp = dht(&mut data, tw).unwrap();
            assert!(data.iter().all(|&m| m != extremes[0]), "N={n} seed {seed}");
            let snr = snr_db(&reference, &values(&data, exp));
            let floor = floor_db(frac, bits as f64, (n as f64).sqrt());
            assert!(snr >= floor, "N={n} seed {seed}: {snr:.1} dB");
            let side = 1usize << (bits / 2).max(1);
            if side * side <= n {
                let mut data: Vec<S> = (0..side * side).map(pick).collect();
                let reference = naive_2d(&integers(&data), side, side);
                let exp = dht_2d(&mut data, side, side, tw).unwrap();
                assert!(
                    data.iter().all(|&m| m != extremes[0]),
                    "{side}² seed {seed}"
                );
                let snr = snr_db(&reference, &values(&data, exp));
                let stages = 2.0 * (side.trailing_zeros() as f64) + 1.0;
                let floor = floor_db(frac, stages, side as f64);
                assert!(snr >= floor, "{side}² seed {seed}: {snr:.1} dB");
            }
        }
    }
    run([i16::MIN, i16::MAX], &table::<i16>(1024));
    run([i32::MIN, i32::MAX], &table::<i32>(1024));
}

/// The limits against the butterflies' worst cases, for every twiddle
/// pair of a table of 4096 (the pairs nearest `π/4` have the largest
/// `c + s`): inputs of the limit's peak with the signs that add up.
#[test]
fn limits_hold_for_every_twiddle_pair() {
    let tw = table::<i16>(4096);
    let limits = <i16 as FixedSample>::LIMITS;
    let max = i16::MAX as i64;
    let stored = |v: i64, post: u32| {
        if post == 0 {
            v
        } else {
            let r = (v + (1 << (post - 1)) - 1 + ((v >> post) & 1)) >> post;
            assert_eq!(r, crate::dht::fixed::round_shift(v, post));
            r
        }
    };
    for k in 1..1024 {
        let (c, s) = tw.cos_sin(k);
        let (c, s) = (c as i64, s as i64);
        for post in 0..=2u32 {
            let m = if post < 2 {
                limits.twiddled[post as usize]
            } else {
                max + 1
            };
            let t = (c * m + s * m + (1 << 14)) >> 15;
            assert!(stored(m + t, post) <= max, "k={k} post {post}");
        }
    }
    for post in 0..2u32 {
        let m = limits.plain[post as usize];
        assert!(stored(2 * m, post) <= max);
        assert!(
            stored(2 * (m + 1), post) > max,
            "plain limit {post} is not the largest"
        );
        let m = limits.hao_bracewell[post as usize];
        assert!(stored(4 * m, post + 1) <= max);
    }
}

#[test]
fn zeros_stay_zero_with_exponent_zero() {
    let tw = table::<i16>(64);
    let mut data = vec![0i16; 64];
    assert_eq!(dht(&mut data, &tw), Ok(0));
    assert!(data.iter().all(|&v| v == 0));
    let mut data = vec![0i16; 64];
    assert_eq!(dht_2d(&mut data, 8, 8, &tw), Ok(0));
    assert!(data.iter().all(|&v| v == 0));
}

#[test]
fn bad_lengths_and_tables_are_errors() {
    let mut buf = Vec::new();
    let tw = table_in::<i16>(&mut buf, 64);
    let mut data = vec![0i16; 48];
    assert!(matches!(
        dht(&mut data, &tw),
        Err(Error::NotPowerOfTwo { len: 48, .. })
    ));
    assert!(matches!(
        idht(&mut data, &tw),
        Err(Error::NotPowerOfTwo { .. })
    ));
    let mut data = vec![0i16; 128];
    assert!(matches!(
        dht(&mut data, &tw),
        Err(Error::TwiddlesTooShort { .. })
    ));
    assert!(matches!(
        dht(&mut [], &tw),
        Err(Error::NotPowerOfTwo { len: 0, .. })
    ));
    assert!(matches!(
        dht_2d(&mut data, 128, 1, &tw),
        Err(Error::TwiddlesTooShort { .. })
    ));
    assert!(matches!(
        dht_2d(&mut data, 16, 4, &tw),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(matches!(
        idht_2d(&mut data, 12, 4, &tw),
        Err(Error::NotPowerOfTwo { len: 12, .. })
    ));
    assert!(matches!(
        dht_2d(&mut data, usize::MAX / 2 + 1, 64, &tw),
        Err(Error::TwiddlesTooShort { .. })
    ));

    let mut short = [0i16; 16];
    assert!(matches!(
        FixedTwiddles::new(&mut short, 64),
        Err(Error::BufferTooSmall { needed: 17, .. })
    ));
    assert!(matches!(
        FixedTwiddles::<i16>::new(&mut short, 24),
        Err(Error::NotPowerOfTwo { .. })
    ));
    // Stored tables: negative, the overflow flag, or a pair too large.
    let good = buf.clone();
    for (index, bad) in [(3, -1i16), (5, i16::MIN), (1, i16::MAX)] {
        let mut t = good.clone();
        t[index] = bad;
        assert_eq!(
            FixedTwiddles::from_table(&t, 64).map(|_| ()),
            Err(Error::TableEntryOutOfRange {
                what: "fixed-point twiddle table",
                index
            })
        );
    }
    assert!(FixedTwiddles::from_table(&good, 64).is_ok());
    assert!(FixedTwiddles::from_table(&good[..16], 64).is_err());
}

/// The stored table against the definition, for both widths and a length
/// where cosines clamp (`cos(2π/4096)·2^15` rounds to 2^15).
#[test]
fn twiddle_tables_round_sines_to_nearest() {
    fn check<S: FixedSample>(len: usize) {
        let mut buf = vec![S::default(); FixedTwiddles::<S>::buffer_len(len)];
        FixedTwiddles::new(&mut buf, len).unwrap();
        let scale = (1u64 << S::FRAC_BITS) as f64;
        for (k, v) in buf.iter().enumerate() {
            let exact = (2.0 * core::f64::consts::PI * k as f64 / len as f64).sin() * scale;
            let err = (v.to_i64() as f64 - exact).abs();
            assert!(
                err <= 0.5 + 1e-6 || (exact > scale - 1.0 && err <= 1.0),
                "{k}: {err}"
            );
        }
    }
    for len in [1, 2, 4, 8, 1024, 4096] {
        check::<i16>(len);
        check::<i32>(len);
    }
}
