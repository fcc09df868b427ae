//! The fixed-point transforms against naive O(N²) sums in f64.
//!
//! # Error model behind the floors
//! A stage adds at most two roundings to each value, in units of the
//! stage's last place: the rounded twiddle product (variance 1/12) and, when
//! it scales, the block shift (another 1/12). Both the signal and that
//! noise double in power through each later (unnormalized) stage and are
//! shifted alike, so stage `j` costs `(1/6)/P_j` of noise-to-signal, `P_j`
//! the mean square mantissa at that stage: `SNR ≥ 10·log10(P_min / (L/6))`
//! over `L = log₂N` stages (`2·log₂N` for a 2D block, plus one rounding for
//! the Hao–Bracewell correction).
//!
//! `P_min` follows from the rule. A stage's output peak is at least its
//! input peak over `√2` (a butterfly's larger output is at least its larger
//! input, and the twiddle pair rotates `(y[k], y[m−k])` without changing
//! its norm). The left shift brings the peak above half the no-shift limit
//! (twiddled stages: 13,572 = 2^13.7), a right shift happens only above that
//! limit, so a stage's outputs peak above `13,572 / (2√2)` = 2^12.2 after
//! one halving or none, and above `27,145 / (4√2)` after two: the peak
//! never sits below `2^F / 2^H`, `H = 3` bits. The mean square is the peak
//! squared over the crest factor `κ²` (peak / RMS) of the class:
//! `P_min = (2^(F−H)/κ)²`. So
//! `floor = 20·log10(2^(F−H)) + 10·log10 6 − 10·log10 L − 20·log10 κ`,
//! i.e. `6.02·(F − H) + 7.78 − 10·log10 L − 20·log10 κ` dB.
//!
//! The crest factor of a class at the worst stage: uniform random data
//! start at `√3` and tend to Gaussian, whose peak over `N` values is below
//! `√(2·ln N) + 1` standard deviations; an impulse spreads over `2^j` of
//! the `N` values at stage `j`, but the rounding noise stays on those same
//! values, so its κ is that of the nonzero values, `√2` (the cas values);
//! a constant and the alternating signal concentrate into one value per
//! group whose partner is exactly zero, κ = 1 on the nonzero values.

extern crate std;

mod cube;
mod robustness;

use std::vec;
use std::vec::Vec;

use super::line::stage;
use super::{dht, dht_2d, idht, idht_2d, FixedSample, FixedTwiddles};
use crate::dht::line::for_each_bit_reversed_swap;
use crate::test_support::snr_db;

/// SplitMix64 in `[−1, 1)`.
fn uniform(len: usize, seed: u64) -> Vec<f64> {
    let mut s = seed;
    (0..len)
        .map(|_| {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}

/// The input classes, as fractions of full scale.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Class {
    Random,
    Small,
    Impulse,
    Constant,
    Alternating,
}

const CLASSES: [Class; 5] = [
    Class::Random,
    Class::Small,
    Class::Impulse,
    Class::Constant,
    Class::Alternating,
];

impl Class {
    fn name(self) -> &'static str {
        match self {
            Class::Random => "random, full scale",
            Class::Small => "random, 1e-3 full scale",
            Class::Impulse => "impulse",
            Class::Constant => "constant",
            Class::Alternating => "alternating ±1",
        }
    }

    /// `len` values in `[−1, 1]`; `nx` is the row length (2D alternates
    /// in both directions).
    fn signal(self, len: usize, nx: usize, seed: u64) -> Vec<f64> {
        match self {
            Class::Random => uniform(len, seed),
            Class::Small => uniform(len, seed).iter().map(|v| v * 1e-3).collect(),
            Class::Impulse => {
                let mut v = vec![0.0; len];
                v[(seed as usize * 7 + 3) % len] = 1.0;
                v
            }
            Class::Constant => vec![1.0; len],
            Class::Alternating => (0..len)
                .map(|i| {
                    if (i % nx + i / nx) % 2 == 0 {
                        1.0
                    } else {
                        -1.0
                    }
                })
                .collect(),
        }
    }

    /// Crest factor (peak / RMS) of the class's nonzero values at the
    /// worst stage of a transform of `n` values (see the module docs).
    fn crest(self, n: usize) -> f64 {
        match self {
            Class::Random | Class::Small => {
                (3.0f64).sqrt().max((2.0 * (n as f64).ln()).sqrt() + 1.0)
            }
            Class::Impulse => 2f64.sqrt(),
            Class::Constant | Class::Alternating => 1.0,
        }
    }
}

/// The SNR floor of the module docs for `frac` fraction bits, `roundings`
/// rounded stages and crest factor `crest`.
fn floor_db(frac: u32, roundings: f64, crest: f64) -> f64 {
    const HEADROOM_BITS: f64 = 3.0;
    20.0 * 2f64.log10() * (frac as f64 - HEADROOM_BITS) + 10.0 * 6f64.log10()
        - 10.0 * roundings.log10()
        - 20.0 * crest.log10()
}

/// `cas(2πk/n)` for `k < n`.
fn cas_table(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let a = 2.0 * core::f64::consts::PI * k as f64 / n as f64;
            a.cos() + a.sin()
        })
        .collect()
}

/// The direct O(N²) DHT.
fn naive(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    let cas = cas_table(n);
    (0..n)
        .map(|k| x.iter().enumerate().map(|(j, v)| v * cas[k * j % n]).sum())
        .collect()
}

/// The direct O(N⁴) true 2D DHT (small arrays only).
fn naive_2d_direct(x: &[f64], nx: usize, ny: usize) -> Vec<f64> {
    let cas = cas_table(nx * ny);
    let mut out = vec![0.0; nx * ny];
    for v in 0..ny {
        for u in 0..nx {
            let mut s = 0.0;
            for y in 0..ny {
                for xx in 0..nx {
                    // ux/nx + vy/ny = (u·x·ny + v·y·nx) / (nx·ny)
                    s += x[y * nx + xx] * cas[(u * xx * ny + v * y * nx) % (nx * ny)];
                }
            }
            out[v * nx + u] = s;
        }
    }
    out
}

/// The true 2D DHT by naive 1D sums along rows and columns, then the
/// Hao–Bracewell correction, in f64 (checked against
/// [`naive_2d_direct`] for small sides).
fn naive_2d(x: &[f64], nx: usize, ny: usize) -> Vec<f64> {
    let mut t = vec![0.0; nx * ny];
    for y in 0..ny {
        t[y * nx..(y + 1) * nx].copy_from_slice(&naive(&x[y * nx..(y + 1) * nx]));
    }
    for u in 0..nx {
        let col: Vec<f64> = (0..ny).map(|v| t[v * nx + u]).collect();
        for (v, h) in naive(&col).into_iter().enumerate() {
            t[v * nx + u] = h;
        }
    }
    let at = |u: usize, v: usize| t[(v % ny) * nx + u % nx];
    let mut h = vec![0.0; nx * ny];
    for v in 0..ny {
        for u in 0..nx {
            let (mu, mv) = (nx - u, ny - v);
            h[v * nx + u] = 0.5 * (at(u, v) + at(mu, v) + at(u, mv) - at(mu, mv));
        }
    }
    h
}

/// `v` as mantissas of `S` (`v` in `[−1, 1]`).
fn quantize<S: FixedSample>(v: &[f64]) -> Vec<S> {
    v.iter().map(|&x| S::from_f64(x)).collect()
}

/// The mantissas as integers in f64.
fn integers<S: FixedSample>(v: &[S]) -> Vec<f64> {
    v.iter().map(|m| m.to_i64() as f64).collect()
}

/// `m · 2^exp` for every mantissa.
fn values<S: FixedSample>(v: &[S], exp: i32) -> Vec<f64> {
    v.iter()
        .map(|m| libm::ldexp(m.to_i64() as f64, exp))
        .collect()
}

/// SNR of the 1D forward transform of `class` at length `n`.
fn snr_1d<S: FixedSample>(class: Class, n: usize, seed: u64, tw: &FixedTwiddles<'_, S>) -> f64 {
    let mut data: Vec<S> = quantize(&class.signal(n, n, seed));
    let reference = naive(&integers(&data));
    let exp = dht(&mut data, tw).unwrap();
    snr_db(&reference, &values(&data, exp))
}

/// SNR of the 2D forward transform of `class` on an `n × n` block.
fn snr_2d<S: FixedSample>(class: Class, n: usize, seed: u64, tw: &FixedTwiddles<'_, S>) -> f64 {
    let mut data: Vec<S> = quantize(&class.signal(n * n, n, seed));
    let reference = naive_2d(&integers(&data), n, n);
    let exp = dht_2d(&mut data, n, n, tw).unwrap();
    snr_db(&reference, &values(&data, exp))
}

/// The twiddle table for transforms of length up to `len`, in a buffer
/// that lives as long as the test process.
fn table<S: FixedSample>(len: usize) -> FixedTwiddles<'static, S> {
    table_in(std::boxed::Box::leak(std::boxed::Box::default()), len)
}

/// The twiddle table for transforms of length up to `len`, in `buf`
/// (resized), for a test that reads the stored entries too.
fn table_in<S: FixedSample>(buf: &mut Vec<S>, len: usize) -> FixedTwiddles<'_, S> {
    buf.resize(FixedTwiddles::<S>::buffer_len(len), S::default());
    FixedTwiddles::new(buf, len).unwrap()
}

#[test]
fn naive_2d_matches_the_direct_sum() {
    for (nx, ny) in [(4, 4), (8, 4), (4, 16), (8, 8)] {
        let x = uniform(nx * ny, 5);
        let a = naive_2d(&x, nx, ny);
        let b = naive_2d_direct(&x, nx, ny);
        assert!(snr_db(&b, &a) > 250.0, "{nx}x{ny}");
    }
}

/// Every class at each side `2^bits` meets the model floor of `S`'s
/// fraction bits: the 1D transform (`bits` roundings) for each seed.
fn assert_1d_model<S: FixedSample>(
    tw: &FixedTwiddles<'_, S>,
    sides: impl IntoIterator<Item = u32> + Clone,
    seeds: core::ops::Range<u64>,
) {
    for class in CLASSES {
        for bits in sides.clone() {
            let n = 1usize << bits;
            let floor = floor_db(S::FRAC_BITS, bits as f64, class.crest(n));
            for seed in seeds.clone() {
                let snr = snr_1d(class, n, seed, tw);
                assert!(
                    snr >= floor,
                    "Q{} {class:?} N={n} seed {seed}: {snr:.1} < {floor:.1} dB",
                    S::FRAC_BITS
                );
            }
        }
    }
}

/// As [`assert_1d_model`] for the `n × n` 2D transform (`2·bits + 1`
/// roundings, the correction's included), one seed.
fn assert_2d_model<S: FixedSample>(
    tw: &FixedTwiddles<'_, S>,
    sides: impl IntoIterator<Item = u32> + Clone,
    seed: u64,
) {
    for class in CLASSES {
        for bits in sides.clone() {
            let n = 1usize << bits;
            let floor = floor_db(S::FRAC_BITS, 2.0 * bits as f64 + 1.0, class.crest(n * n));
            let snr = snr_2d(class, n, seed, tw);
            assert!(
                snr >= floor,
                "Q{} {class:?} {n}²: {snr:.1} < {floor:.1} dB",
                S::FRAC_BITS
            );
        }
    }
}

#[test]
fn q15_1d_snr_meets_the_model_for_every_class_and_size() {
    assert_1d_model(&table::<i16>(1024), 1..=10, 0..3);
}

#[test]
fn q15_2d_snr_meets_the_model_for_every_class_and_size() {
    assert_2d_model(&table::<i16>(256), 3..=8, 1);
}

#[test]
fn q31_meets_the_same_model_with_31_fraction_bits() {
    let tw = table::<i32>(1024);
    assert_1d_model(&tw, [1, 4, 7, 10], 2..3);
    assert_2d_model(&tw, [3, 5], 2);
}

#[test]
fn every_impulse_position_and_sign_at_64() {
    let tw = table::<i16>(64);
    let floor = floor_db(15, 6.0, Class::Impulse.crest(64));
    for p in 0..64 {
        for amp in [i16::MAX, -i16::MAX, i16::MIN, 1, -1, 12345] {
            let mut data = vec![0i16; 64];
            data[p] = amp;
            let reference = naive(&integers(&data));
            let exp = dht(&mut data, &tw).unwrap();
            let snr = snr_db(&reference, &values(&data, exp));
            assert!(snr >= floor, "impulse {amp} at {p}: {snr:.1} dB");
            assert!(data.iter().all(|&m| m != i16::MIN));
        }
    }
}

#[test]
fn every_2d_impulse_position_at_8x8() {
    let tw = table::<i16>(8);
    let floor = floor_db(15, 7.0, Class::Impulse.crest(64));
    for p in 0..64 {
        let mut data = vec![0i16; 64];
        data[p] = i16::MIN;
        let reference = naive_2d_direct(&integers(&data), 8, 8);
        let exp = dht_2d(&mut data, 8, 8, &tw).unwrap();
        let snr = snr_db(&reference, &values(&data, exp));
        assert!(snr >= floor, "2D impulse at {p}: {snr:.1} dB");
    }
}

#[test]
fn round_trip_1d_and_2d() {
    let tw = table::<i16>(256);
    for bits in 1..=8 {
        let n = 1usize << bits;
        let original: Vec<i16> = quantize(&uniform(n, 9));
        let mut data = original.clone();
        let e1 = dht(&mut data, &tw).unwrap();
        let e2 = idht(&mut data, &tw).unwrap();
        let back = values(&data, e1 + e2);
        let snr = snr_db(&integers(&original), &back);
        let floor = floor_db(15, 2.0 * bits as f64, Class::Random.crest(n));
        assert!(snr >= floor, "1D round trip N={n}: {snr:.1} dB");
    }
    for n in [4usize, 16, 64] {
        let original: Vec<i16> = quantize(&uniform(n * n, 11));
        let mut data = original.clone();
        let e1 = dht_2d(&mut data, n, n, &tw).unwrap();
        let e2 = idht_2d(&mut data, n, n, &tw).unwrap();
        let back = values(&data, e1 + e2);
        let snr = snr_db(&integers(&original), &back);
        let bits = n.trailing_zeros() as f64;
        let floor = floor_db(15, 4.0 * bits + 2.0, Class::Random.crest(n * n));
        assert!(snr >= floor, "2D round trip {n}²: {snr:.1} dB");
    }
}

#[test]
fn non_square_2d_matches_the_reference() {
    let tw = table::<i16>(64);
    for (nx, ny) in [(64, 4), (4, 64), (16, 2), (2, 16), (1, 8), (8, 1), (32, 8)] {
        let mut data: Vec<i16> = quantize(&uniform(nx * ny, 3));
        let reference = naive_2d_direct(&integers(&data), nx, ny);
        let exp = dht_2d(&mut data, nx, ny, &tw).unwrap();
        let snr = snr_db(&reference, &values(&data, exp));
        let bits = (nx * ny).trailing_zeros() as f64;
        let floor = floor_db(15, bits + 1.0, Class::Random.crest(nx * ny));
        assert!(snr >= floor, "{nx}x{ny}: {snr:.1} dB");
    }
}

/// The table of `docs/precision.md`:
/// `cargo test -p fvr-core --release q15_table -- --ignored --nocapture`.
#[test]
#[ignore]
fn q15_table() {
    let tw = table::<i16>(1024);
    std::println!(
        "| transform | N | {} |",
        CLASSES.map(Class::name).join(" | ")
    );
    std::println!("|---|---|---|---|---|---|---|");
    let cell = |snr: f64| {
        // Beyond 250 dB the difference is the f64 reference's own rounding.
        if snr < 250.0 {
            std::format!("{snr:.1}")
        } else {
            "exact".into()
        }
    };
    for bits in [1, 2, 4, 6, 8, 10] {
        let n = 1usize << bits;
        let row: Vec<_> = CLASSES.map(|c| cell(snr_1d(c, n, 1, &tw))).into();
        std::println!("| 1D | {n} | {} |", row.join(" | "));
    }
    for bits in [3, 4, 5, 6, 7, 8] {
        let n = 1usize << bits;
        let row: Vec<_> = CLASSES.map(|c| cell(snr_2d(c, n, 1, &tw))).into();
        std::println!("| 2D | {n}² | {} |", row.join(" | "));
    }
    let tw31 = table::<i32>(1024);
    let row: Vec<_> = CLASSES.map(|c| cell(snr_1d(c, 1024, 1, &tw31))).into();
    std::println!("| 1D, Q31 | 1024 | {} |", row.join(" | "));
    let row: Vec<_> = CLASSES.map(|c| cell(snr_2d(c, 256, 1, &tw31))).into();
    std::println!("| 2D, Q31 | 256² | {} |", row.join(" | "));
    std::println!();
    std::println!("| N | input | conditional (this rule) | unconditional ½ per stage |");
    std::println!("|---|---|---|---|");
    for n in [64usize, 1024] {
        for class in [Class::Random, Class::Small, Class::Impulse] {
            let mut data: Vec<i16> = quantize(&class.signal(n, n, 1));
            let reference = naive(&integers(&data));
            let exp = dht_unconditional(&mut data, &tw);
            let unconditional = snr_db(&reference, &values(&data, exp));
            let conditional = snr_1d(class, n, 1, &tw);
            std::println!(
                "| {n} | {} | {} | {} |",
                class.name(),
                cell(conditional),
                cell(unconditional)
            );
        }
    }
}

/// The alternative scaling rule, for the comparison in [`q15_table`]: no
/// normalization, every stage halves its outputs (exponent `log₂N`).
/// Overflow-free by the global bound: after `j` halved stages each value is
/// a length-`2^j` DHT of `2^j` inputs divided by `2^j`, so at most the
/// input peak, plus the rounding of the halvings (the input below stays
/// under 32,767 − log₂N).
fn dht_unconditional(data: &mut [i16], tw: &FixedTwiddles<'_, i16>) -> i32 {
    let n = data.len();
    for v in data.iter_mut() {
        *v = (*v).clamp(-32757, 32757);
    }
    for_each_bit_reversed_swap(n, |i, j| data.swap(i, j));
    let mut m = 1;
    while m < n {
        stage::<i16, 1>(data, 1, m, tw);
        m *= 2;
    }
    n.trailing_zeros() as i32
}
