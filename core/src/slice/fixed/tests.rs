//! The fixed-point extraction against the f64 extraction of the same Q15
//! spectrum, at extremes, and its refusals.
//!
//! # The bound
//! Both paths read the same mantissas and exponents with the same taps;
//! they differ in the weights and the sums. A fixed-point weight is within
//! `δ = 2·2^−F` of the f64 one (½ unit from rounding the table entries, up
//! to 1 from rounding the interpolation down, and the 14-bit fraction and
//! the axes' 2^−42 rounding far below). A point's value
//! `Σ wx·wy·wz·c` then moves by at most `3·W·δ·S²·max|c|` (one weight of
//! each product wrong at a time, first order; `S = (2^16 − 1)·2^−F` bounds
//! `Σ|w|` per axis), and the three shifts that round down add less than
//! `S²·2^(E−30) + S·2^(E−29) + 2^(E−28)` (`E` the top exponent; with
//! `F = 15` these are the units of the sums).

extern crate std;

use std::vec;
use std::vec::Vec;

use super::*;
use crate::filter::{Filter, FilterKind, KernelTable};
use crate::geometry::{SliceAxes, View};
use crate::num::BlockExponents;
use crate::slice::extract_central_slice_on;

const N: usize = 16;

/// [`phases::MAX_ABS_SUM`] as a real number.
const MAX_ABS_SUM_REAL: f64 = phases::MAX_ABS_SUM as f64;

/// A deterministic LCG.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 33) as u32
    }
}

fn filter(kind: FilterKind) -> Filter {
    Filter::new(kind, 1).unwrap()
}

fn axes(dir: [f64; 3]) -> SliceAxes {
    View::along(dir).frame().unwrap().slice_axes()
}

fn phases<const W: usize>(filter: Filter) -> std::boxed::Box<FixedPhases<W>> {
    let mut p = std::boxed::Box::new(FixedPhases::<W>::new());
    p.fill(&KernelTable::<f64>::new(filter)).unwrap();
    p
}

/// The fixed-point slice (as f64) and the f64 extraction of the same
/// spectrum, point by point within the bound of the module docs.
fn check_against_f64<const W: usize>(
    kind: FilterKind,
    mantissas: &[Q15],
    exponents: Option<&[i8]>,
    dir: [f64; 3],
) {
    let f = filter(kind);
    let spec = match exponents {
        Some(e) => Spectrum::from_blocks(
            mantissas,
            BlockExponents::new(BlockLayout::Line, e, N).unwrap(),
            N,
            1.0,
            f,
            [N; 3],
        ),
        None => Spectrum::from_parts(mantissas, N, 1.0, f, [N; 3]),
    }
    .unwrap();
    let axes = axes(dir);
    let table = phases::<W>(f);
    let mut grid = vec![0i32; N * N];
    let exponent = extract_slice_fixed(&spec, &table, &axes, &mut grid).unwrap();
    let mut reference = vec![0.0f64; N * N];
    extract_central_slice_on(&spec, &KernelTable::<f64>::new(f), &axes, N, &mut reference);
    let top = exponents.map_or(0, |e| e.iter().copied().max().unwrap() as i32);
    let max_c = (0..N * N * N)
        .map(|i| spec.value(i).abs())
        .fold(0.0, f64::max);
    let unit = (-(table.fraction_bits() as f64)).exp2();
    let (delta, sum) = (2.0 * unit, MAX_ABS_SUM_REAL * unit);
    let bound = 3.0 * W as f64 * delta * sum * sum * max_c
        + (sum * sum + 2.0 * sum + 4.0) * ((top - 30) as f64).exp2();
    let scale = (exponent as f64).exp2();
    for (i, (g, r)) in grid.iter().zip(&reference).enumerate() {
        let v = *g as f64 * scale;
        assert!(
            (v - r).abs() <= bound,
            "{kind:?} point {i}: fixed {v} against f64 {r} (bound {bound})"
        );
    }
}

fn random_mantissas(rng: &mut Lcg) -> Vec<Q15> {
    (0..N * N * N)
        .map(|_| Q15((rng.next() >> 16) as u16 as i16))
        .collect()
}

#[test]
fn random_spectra_agree_with_f64_within_the_weight_bound() {
    let mut rng = Lcg(17);
    for dir in [[1.0, 0.3, 0.2], [-0.4, 0.9, 0.55], [0.0, 1.0, 0.0]] {
        let m = random_mantissas(&mut rng);
        let e: Vec<i8> = (0..N * N).map(|_| (rng.next() % 12) as i8 - 8).collect();
        check_against_f64::<3>(FilterKind::Kb3, &m, Some(&e), dir);
        check_against_f64::<4>(FilterKind::Kb4, &m, Some(&e), dir);
        check_against_f64::<6>(FilterKind::Kb6, &m, None, dir);
        check_against_f64::<2>(FilterKind::Linear, &m, Some(&e), dir);
    }
}

/// Full-scale mantissas (the overflow flag −32768 included, read as −1)
/// and exponents at both ends: no overflow (the test profile checks), and
/// still within the bound. Lines 31 or more below the top read as 0 or −1
/// in the sums, which the bound's `2^(E−25)` covers.
#[test]
fn extremes_neither_overflow_nor_leave_the_bound() {
    let patterns: [&dyn Fn(usize) -> i16; 3] = [&|_| i16::MIN, &|_| i16::MAX, &|i| {
        if (i / 3) % 2 == 0 {
            i16::MIN
        } else {
            i16::MAX
        }
    }];
    let exponent_sets: [&dyn Fn(usize) -> i8; 3] = [&|_| i8::MAX, &|_| i8::MIN, &|i| {
        if i % 5 == 0 {
            i8::MAX
        } else {
            i8::MIN
        }
    }];
    for p in patterns {
        let m: Vec<Q15> = (0..N * N * N).map(|i| Q15(p(i))).collect();
        for e in exponent_sets {
            let e: Vec<i8> = (0..N * N).map(e).collect();
            check_against_f64::<3>(FilterKind::Kb3, &m, Some(&e), [1.0, 0.3, 0.2]);
        }
        check_against_f64::<3>(FilterKind::Kb3, &m, None, [0.2, -1.0, 0.7]);
    }
}

#[test]
fn a_zero_spectrum_gives_a_zero_slice() {
    let f = filter(FilterKind::Kb3);
    let m = vec![Q15(0); N * N * N];
    let e = vec![i8::MIN; N * N];
    let blocks = BlockExponents::new(BlockLayout::Line, &e, N).unwrap();
    let spec = Spectrum::from_blocks(&m, blocks, N, 1.0, f, [N; 3]).unwrap();
    let mut grid = vec![7i32; N * N];
    extract_slice_fixed(&spec, &phases::<3>(f), &axes([1.0, 0.3, 0.2]), &mut grid).unwrap();
    assert!(grid.iter().all(|&v| v == 0));
}

#[test]
fn refusals_name_the_problem() {
    let f = filter(FilterKind::Kb3);
    let m = vec![Q15(100); N * N * N];
    let table = phases::<3>(f);
    let mut grid = vec![0i32; N * N];
    let good = axes([1.0, 0.3, 0.2]);
    let plain = Spectrum::from_parts(&m, N, 1.0, f, [N; 3]).unwrap();

    let bricks = vec![0i8; 8];
    let blocks = BlockExponents::new(BlockLayout::Brick(8), &bricks, N).unwrap();
    let bricked = Spectrum::from_blocks(&m, blocks, N, 1.0, f, [N; 3]).unwrap();
    assert!(matches!(
        extract_slice_fixed(&bricked, &table, &good, &mut grid),
        Err(Error::UnsupportedFormat { .. })
    ));

    let other = phases::<3>(Filter::from_parts(FilterKind::Kb3, 1, f.beta() + 1.0).unwrap());
    assert_eq!(
        extract_slice_fixed(&plain, &other, &good, &mut grid),
        Err(Error::FilterMismatch)
    );

    let mut short = vec![0i32; N * N - 1];
    assert!(matches!(
        extract_slice_fixed(&plain, &table, &good, &mut short),
        Err(Error::LengthMismatch { .. })
    ));

    for bad in [100.0, f64::NAN, f64::INFINITY] {
        let axes = SliceAxes {
            right: [bad, 0.0, 0.0],
            up: good.up,
        };
        assert!(matches!(
            extract_slice_fixed(&plain, &table, &axes, &mut grid),
            Err(Error::FixedPointRange { .. })
        ));
    }

    let mut wrong_width = FixedPhases::<4>::new();
    assert!(matches!(
        wrong_width.fill(&KernelTable::<f64>::new(f)),
        Err(Error::LengthMismatch { .. })
    ));
    assert_eq!(wrong_width.filter(), None);
}

/// An empty table matches no spectrum; one filled from a kernel's values
/// equals one filled from the kernel table; bad values leave it empty.
#[test]
fn phase_tables_from_values() {
    let f = filter(FilterKind::Kb3);
    let n = 8;
    let mantissas = vec![Q15(0); n * n * n];
    let spec = Spectrum::from_parts(&mantissas[..], n, 1.0, f, [n; 3]).unwrap();
    let mut grid = vec![0i32; n * n];
    let empty = FixedPhases::<3>::new();
    assert_eq!(empty.filter(), None);
    assert!(matches!(
        extract_slice_fixed(&spec, &empty, &axes([1.0, 0.3, 0.2]), &mut grid),
        Err(Error::FilterMismatch)
    ));

    let kernel = KernelTable::<f32>::new(f);
    let mut from_table = std::boxed::Box::new(FixedPhases::<3>::new());
    from_table.fill(&kernel).unwrap();
    let mut from_values = std::boxed::Box::new(FixedPhases::<3>::new());
    from_values.fill_from(f, kernel.values()).unwrap();
    assert_eq!(from_values.filter(), Some(f));
    assert_eq!(from_values.fraction_bits(), from_table.fraction_bits());
    for i in [0usize, 1, 600, 1023] {
        let y = ((i as i64) << 32) + (3 << 28);
        assert_eq!(from_values.taps(y), from_table.taps(y), "row {i}");
    }

    let mut values = kernel.values().to_vec();
    assert!(matches!(
        from_values.fill_from(f, &values[1..]),
        Err(Error::LengthMismatch { .. })
    ));
    assert_eq!(from_values.filter(), None);
    values[7] = f32::NAN;
    assert!(matches!(
        from_values.fill_from(f, &values),
        Err(Error::NonFiniteTableEntry { index: 7, .. })
    ));
    assert_eq!(from_values.filter(), None);
}

/// Each filter keeps the most fraction bits its weight sums allow (15 for
/// the narrow kernels, 14 for kb4 and kb6, whose weights sum to more than
/// 2), and the table's rows are the kernel's entries rounded (within half a
/// unit).
#[test]
fn phase_tables_keep_the_most_fraction_bits() {
    fn check<const W: usize>(kind: FilterKind, bits: u32) {
        let f = filter(kind);
        let table = phases::<W>(f);
        assert_eq!(table.fraction_bits(), bits, "{kind:?}");
        let one = (1u32 << bits) as f64;
        let kernel = KernelTable::<f64>::new(f);
        for i in [0usize, 1, 511, 512, 1023] {
            let y = (i as i64) << 32;
            let (_, w) = table.taps(y);
            for (m, w) in w.iter().enumerate() {
                let index = crate::filter::phase_entry::<W>(i, m).unsigned_abs() as usize;
                let exact = kernel.values().get(index).copied().unwrap_or(0.0) * one;
                assert!((*w as f64 - exact).abs() <= 0.5, "{kind:?} row {i} tap {m}");
            }
        }
    }
    check::<1>(FilterKind::Nearest, 15);
    check::<2>(FilterKind::Linear, 15);
    check::<3>(FilterKind::Kb3, 15);
    check::<4>(FilterKind::Kb4, 14);
    check::<6>(FilterKind::Kb6, 14);
}
