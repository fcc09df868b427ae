//! The marks of adaptive filtering (`fvr_core::slice::adaptive::mark`) on
//! all cores: the same words bit for bit.
//!
//! The core erodes the bitset line by line, one bit at a time. Here, for a
//! side that is a multiple of 32 (every row a whole number of words):
//!
//! - the threshold test runs plane by plane on the threads;
//! - the erosion along z keeps a bit when it is set in every plane within
//!   the radius, so a plane is the AND of `2r + 1` planes' words; along y
//!   the same with rows inside a plane; along x a row is the AND of its
//!   circular rotations by `−r … r` bits, word by word.
//!
//! Each pass reads the previous pass's bits, as the core's does (it copies
//! a line before rewriting it), so the order of the axes is the core's.
//! Other sides go to the core's function.

use fvr_core::slice::adaptive::{mark as core_mark, marks_words};
use rayon::prelude::*;

/// [`fvr_core::slice::adaptive::mark`]: mark the samples of a cube of side
/// `n` (values `value(i)`, x fastest) below `tau` together with every sample
/// within Chebyshev distance `radius`, circularly; the count marked.
///
/// # Errors
/// As the core's: `n` not a power of two, too few `words`.
pub fn mark(
    n: usize,
    value: impl Fn(usize) -> f64 + Sync,
    tau: f64,
    radius: usize,
    words: &mut [u32],
) -> Result<usize, fvr_core::Error> {
    if !n.is_power_of_two() || n % 32 != 0 || words.len() < marks_words(n) {
        let mut line = vec![false; n];
        return core_mark(n, value, tau, radius, words, &mut line);
    }
    let words = &mut words[..marks_words(n)];
    let (row_words, plane_words) = (n / 32, n * n / 32);
    words
        .par_chunks_mut(plane_words)
        .enumerate()
        .for_each(|(z, plane)| {
            for (w, word) in plane.iter_mut().enumerate() {
                let base = z * n * n + w * 32;
                *word = (0..32).fold(0u32, |bits, b| {
                    bits | (u32::from(value(base + b).abs() < tau) << b)
                });
            }
        });
    let r = radius.min(n / 2);
    let window = move |k: usize| (0..=2 * r).map(move |o| (k + n + o - r) % n);
    // x: each row against its rotations.
    words.par_chunks_mut(row_words).for_each(|row| {
        let old = row.to_vec();
        for (w, word) in row.iter_mut().enumerate() {
            *word = (0..=2 * r).fold(!0u32, |acc, o| acc & rotated(&old, w, n + o - r))
        }
    });
    let mut old = words.to_vec();
    // y: rows of words inside each plane.
    words
        .par_chunks_mut(plane_words)
        .zip(old.par_chunks(plane_words))
        .for_each(|(plane, before)| {
            for y in 0..n {
                for w in 0..row_words {
                    plane[y * row_words + w] =
                        window(y).fold(!0u32, |acc, yy| acc & before[yy * row_words + w]);
                }
            }
        });
    old.copy_from_slice(words);
    // z: whole planes of words.
    words
        .par_chunks_mut(plane_words)
        .enumerate()
        .for_each(|(z, plane)| {
            for (i, word) in plane.iter_mut().enumerate() {
                *word = window(z).fold(!0u32, |acc, zz| acc & old[zz * plane_words + i]);
            }
        });
    Ok(words.par_iter().map(|w| w.count_ones() as usize).sum())
}

/// Word `w` of the row `row` (`32·row.len()` bits, bit `k` in word `k/32`)
/// rotated so that bit `k` holds bit `(k + shift) mod 32·row.len()`.
#[inline(always)]
fn rotated(row: &[u32], w: usize, shift: usize) -> u32 {
    let len = row.len();
    let shift = shift % (32 * len);
    let (q, t) = (shift / 32, shift % 32);
    let low = row[(w + q) % len];
    if t == 0 {
        low
    } else {
        (low >> t) | (row[(w + q + 1) % len] << (32 - t))
    }
}
