//! The integer finish against the f64 one ([`super::super::finish`]) on
//! the same slice, with and without a sub-pixel shift, and at extremes.
//!
//! # The floor
//! The error model of the Q15 transforms (`crate::dht::fixed`'s tests):
//! `6.02·(F − 3) + 7.78 − 10·log10 L − 20·log10 κ` dB for `F = 15`, with
//! `L` the roundings: `2·log₂m + 1` in the inverse, one to Q15 and one in
//! the shift; `κ` the Gaussian crest bound `√(2·ln m²) + 1` of random
//! data.

extern crate std;

use std::vec;
use std::vec::Vec;

use super::*;
use crate::dht::fixed::FixedTwiddles;
use crate::dht::Twiddles;
use crate::image::{finish, Crop};
use crate::test_support::snr_db;

const M: usize = 32;

fn floor_db() -> f64 {
    let roundings = 2.0 * M.trailing_zeros() as f64 + 3.0;
    let crest = libm::sqrt(2.0 * libm::log((M * M) as f64)) + 1.0;
    6.0206 * 12.0 + 10.0 * libm::log10(6.0)
        - 10.0 * libm::log10(roundings)
        - 20.0 * libm::log10(crest)
}

/// The `M × M` slice at `exponent` of a `size` image at `place`.
fn at<'a>(
    exponent: i32,
    place: Placement,
    size: (usize, usize),
    tw: &'a FixedTwiddles<'a, i16>,
) -> FixedSlice<'a> {
    FixedSlice {
        exponent,
        m: M,
        place,
        size,
        tw,
    }
}

/// [`finish_fixed`] of a copy of `grid` (`M × M`) at `exponent` into fresh
/// buffers: the image's exponent and mantissas.
fn finish_fixed_owned(
    grid: &[i32],
    exponent: i32,
    place: &Placement,
    size: (usize, usize),
    tw16: &FixedTwiddles<'_, i16>,
) -> (i32, Vec<i16>) {
    let mut grid = grid.to_vec();
    let mut aux = vec![0i32; fixed_aux_len(M)];
    let mut block = vec![0i16; M * M];
    let mut out = vec![0i16; size.0 * size.1];
    let buffers = FixedBuffers {
        grid: &mut grid,
        aux: &mut aux,
        block: &mut block,
        out: &mut out,
    };
    let exponent = finish_fixed(buffers, &at(exponent, *place, size, tw16)).unwrap();
    (exponent, out)
}

/// The image of `grid` by both finishes, the fixed one in f64.
fn both(grid: &[i32], place: Placement, size: (usize, usize)) -> (Vec<f64>, Vec<f64>) {
    let mut tw16 = vec![0i16; FixedTwiddles::<i16>::buffer_len(M)];
    let tw16 = FixedTwiddles::new(&mut tw16, M).unwrap();
    let (exponent, out) = finish_fixed_owned(grid, 0, &place, size, &tw16);
    let fixed = out
        .iter()
        .map(|&v| v as f64 * (exponent as f64).exp2())
        .collect();
    let mut tw = vec![0.0f64; Twiddles::<f64>::buffer_len(M)];
    let tw = Twiddles::new(&mut tw, M).unwrap();
    let mut g: Vec<f64> = grid.iter().map(|&v| v as f64).collect();
    let mut aux = vec![0.0f64; crate::image::aux_len(M)];
    let mut reference = vec![0.0f64; size.0 * size.1];
    finish(
        &mut g,
        M,
        &Crop::new(place, 1.0, size.0, size.1),
        &tw,
        &mut aux,
        &mut reference,
    )
    .unwrap();
    (fixed, reference)
}

/// An `M × M` slice of pseudo-random values below `2^(31 − shift)` in
/// magnitude (a linear congruential generator from `seed`).
fn random_grid(seed: u32, shift: u32) -> Vec<i32> {
    let mut state = seed;
    (0..M * M)
        .map(|_| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state as i32) >> shift
        })
        .collect()
}

#[test]
fn random_slices_meet_the_q15_floor_with_and_without_a_shift() {
    let grid = random_grid(0x1234_5678, 9);
    for (shift, size) in [
        ([0.0, 0.0], (M, M)),
        ([0.3, 0.75], (M, M)),
        ([0.5, 0.0], (M - 3, M / 2)),
    ] {
        let place = Placement {
            col0: -(size.0 as i64) / 2,
            row0: size.1 as i64 / 2,
            shift,
        };
        let (fixed, reference) = both(&grid, place, size);
        let snr = snr_db(&reference, &fixed);
        assert!(
            snr >= floor_db(),
            "shift {shift:?}: {snr:.1} dB below the floor {:.1} dB",
            floor_db()
        );
    }
}

/// A zero slice gives a zero image; slices of `i32` extremes (both ends,
/// alternating) finish without overflow (the test profile checks) and
/// still meet the floor against f64.
#[test]
fn zero_and_extreme_slices() {
    let place = Placement {
        col0: -(M as i64) / 2,
        row0: M as i64 / 2,
        shift: [0.25, 0.5],
    };
    let (fixed, _) = both(&vec![0; M * M], place, (M, M));
    assert!(fixed.iter().all(|&v| v == 0.0));
    let patterns: [&dyn Fn(usize) -> i32; 3] = [&|_| i32::MIN, &|_| i32::MAX, &|i| {
        if i % 3 == 0 {
            i32::MIN
        } else {
            i32::MAX
        }
    }];
    for p in patterns {
        let grid: Vec<i32> = (0..M * M).map(p).collect();
        let (fixed, reference) = both(&grid, place, (M, M));
        assert!(fixed.iter().all(|v| v.is_finite()));
        let snr = snr_db(&reference, &fixed);
        // A constant slice is an impulse in the image (κ up to M): the
        // floor for that crest factor.
        let floor = floor_db() + 20.0 * libm::log10(5.0 / M as f64);
        assert!(snr >= floor, "{snr:.1} dB below {floor:.1} dB");
    }
}

#[test]
fn bad_buffers_are_refused() {
    let mut tw16 = vec![0i16; FixedTwiddles::<i16>::buffer_len(M)];
    let tw16 = FixedTwiddles::new(&mut tw16, M).unwrap();
    let place = Placement {
        col0: 0,
        row0: 0,
        shift: [0.0, 0.0],
    };
    let (mut grid, mut aux) = (vec![0i32; M * M], vec![0i32; fixed_aux_len(M)]);
    let (mut block, mut out) = (vec![0i16; M * M], vec![0i16; M * M]);
    for (size, short_aux) in [((0, M), false), ((M + 1, M), false), ((M, M), true)] {
        let aux_len = if short_aux { M } else { aux.len() };
        let out_len = size.0.min(M) * size.1;
        let result = finish_fixed(
            FixedBuffers {
                grid: &mut grid,
                aux: &mut aux[..aux_len],
                block: &mut block,
                out: &mut out[..out_len],
            },
            &at(0, place, size, &tw16),
        );
        assert!(result.is_err(), "{size:?}, short aux {short_aux}");
    }
}

/// The image cut into the block equals the one written to `out`, bit for
/// bit and with the same exponent, for placements whose rows and columns
/// wrap around the grid either way, with and without a shift, full and
/// partial images; bad sizes are refused as by [`finish_fixed`].
#[test]
fn the_image_cut_into_the_block_is_the_image() {
    let mut tw16 = vec![0i16; FixedTwiddles::<i16>::buffer_len(M)];
    let tw16 = FixedTwiddles::new(&mut tw16, M).unwrap();
    let grid = random_grid(0x9E37_79B9, 7);
    let m = M as i64;
    for (col0, row0, shift, size) in [
        (-m / 2, m / 2, [0.0, 0.0], (M, M)),
        (-m / 2, m / 2 - 1, [0.3, 0.75], (M, M)),
        (5, -7, [0.0, 0.5], (M - 3, M / 2)),
        (-40, 70, [0.25, 0.0], (7, M - 1)),
        (0, 0, [0.0, 0.0], (1, 1)),
    ] {
        let place = Placement { col0, row0, shift };
        let (e_out, out) = finish_fixed_owned(&grid, 3, &place, size, &tw16);
        let (mut g, mut aux) = (grid.clone(), vec![0i32; fixed_aux_len(M)]);
        let mut block = vec![0i16; M * M];
        let e_block =
            finish_fixed_in_block(&mut g, &mut aux, &mut block, &at(3, place, size, &tw16))
                .unwrap();
        assert_eq!(e_block, e_out, "{place:?} {size:?}");
        assert_eq!(&block[..size.0 * size.1], &out[..], "{place:?} {size:?}");
    }
    let place = Placement {
        col0: 0,
        row0: 0,
        shift: [0.0, 0.0],
    };
    let (mut g, mut aux, mut block) = (grid.clone(), vec![0i32; M], vec![0i16; M * M]);
    for size in [(0, M), (M + 1, M)] {
        let mut aux4 = vec![0i32; fixed_aux_len(M)];
        assert!(
            finish_fixed_in_block(&mut g, &mut aux4, &mut block, &at(0, place, size, &tw16))
                .is_err()
        );
    }
    assert!(
        finish_fixed_in_block(&mut g, &mut aux, &mut block, &at(0, place, (M, M), &tw16)).is_err()
    );
}
