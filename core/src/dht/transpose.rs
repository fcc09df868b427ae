//! In-place transposes of square arrays for the 2D transform's row pass,
//! plain and fused with the radix-4 bit reversal.

use super::plane::{chunk_out_of_range, radix4_plain, rows_mut};
use crate::num::Real;

/// Side from which [`transpose_square`] works in tiles.
pub(super) const TILED_TRANSPOSE_FROM: usize = 128;

/// Transpose an `n × n` array in place: row by row below `n = 128`, in
/// tiles of 16 × 16 from there (a row-by-row transpose walks one side with
/// a stride of `n` and misses the cache on every element once rows outgrow
/// it; on a cacheless core the plain loop costs fewer instructions).
pub(super) fn transpose_square<T>(data: &mut [T], n: usize) {
    const TILE: usize = 16;
    if n < TILED_TRANSPOSE_FROM || n % TILE != 0 {
        swap_across_diagonal(data, n, |i| i);
        return;
    }
    for bi in (0..n).step_by(TILE) {
        for bj in (bi..n).step_by(TILE) {
            for i in bi..bi + TILE {
                let first = if bi == bj { i + 1 } else { bj };
                for j in first..bj + TILE {
                    data.swap(i * n + j, j * n + i);
                }
            }
        }
    }
}

/// `data[r][c] ← data[rev c][rev r]` in place for an `n × n` array (`n` a
/// power of two, at least 4, `rev` reversing `log₂n` bits), then the first
/// two (untwiddled) stages of [`dht_columns_stages`] on every group of
/// four rows `4t .. 4t+3`.
///
/// The permutation is a transpose that also puts rows and columns in
/// bit-reversed order. The groups of four rows are closed under it in
/// 4 × 4 tiles (`rev(4t + j) = rev(4t) + rev(j)` for `j < 4`), so each
/// value is loaded and stored once for both. Since `rev(4t) < n/4` and
/// `rev(j)` is a whole number of quarters, a tile's values sit at one
/// index of sixteen quarter rows, and one bounds check covers them all.
pub(super) fn transpose_square_bit_reversed_radix4<T: Real>(data: &mut [T], n: usize) {
    const B: usize = 4;
    // Quarter holding column rev(4t) + rev(j): rev(j) = QUARTER_OF[j]·n/4.
    const QUARTER_OF: [usize; B] = [0, 2, 1, 3];
    let quarter = n / B;
    let shift = usize::BITS - quarter.trailing_zeros();
    let rev4 = |t: usize| t.reverse_bits().checked_shr(shift).unwrap_or(0);
    for rt in 0..n / B {
        let (above, below) = data.split_at_mut(B * rt * n);
        let band = quarters(&mut below[..B * n], n);
        let pr = rev4(rt);
        if pr >= quarter {
            return;
        }
        let tile: [[T; B]; B] =
            core::array::from_fn(|i| core::array::from_fn(|j| band[i][QUARTER_OF[j]][pr]));
        for (j, column) in tile.iter().enumerate() {
            for (i, v) in radix4_plain(*column).into_iter().enumerate() {
                band[i][QUARTER_OF[j]][pr] = v;
            }
        }
        for (st, other) in above.chunks_exact_mut(B * n).enumerate() {
            let ps = rev4(st);
            if ps >= quarter {
                return;
            }
            let other = quarters(other, n);
            let saved: [[T; B]; B] =
                core::array::from_fn(|i| core::array::from_fn(|j| band[i][QUARTER_OF[j]][ps]));
            for j in 0..B {
                let theirs: [T; B] = core::array::from_fn(|i| other[j][QUARTER_OF[i]][pr]);
                for (i, v) in radix4_plain(theirs).into_iter().enumerate() {
                    band[i][QUARTER_OF[j]][ps] = v;
                }
            }
            for (i, row) in saved.iter().enumerate() {
                for (j, v) in radix4_plain(*row).into_iter().enumerate() {
                    other[j][QUARTER_OF[i]][pr] = v;
                }
            }
        }
    }
}

/// Four rows of `n` as four quarter rows each.
#[inline(always)]
fn quarters<T>(rows: &mut [T], n: usize) -> [[&mut [T]; 4]; 4] {
    rows_mut(rows, n, [0, 1, 2, 3]).map(|row| rows_mut(row, n / 4, [0, 1, 2, 3]))
}

/// [`transpose_square_bit_reversed_radix4`] without the bit reversal: the
/// plain transpose, then the two untwiddled stages on every group of four
/// rows. Written over row segments of four, which the M4F addresses with
/// immediate offsets from one pointer per segment.
pub(super) fn transpose_square_plain_radix4<T: Real>(data: &mut [T], n: usize) {
    const B: usize = 4;
    for rt in 0..n / B {
        let (above, below) = data.split_at_mut(B * rt * n);
        let band = &mut below[..B * n];
        let c = B * rt;
        let tile: [[T; B]; B] = core::array::from_fn(|i| *segment(band, i * n + c));
        for (j, column) in tile.iter().enumerate() {
            for (i, v) in radix4_plain(*column).into_iter().enumerate() {
                segment(band, i * n + c)[j] = v;
            }
        }
        for (st, other) in above.chunks_exact_mut(B * n).enumerate() {
            let cs = B * st;
            let [b0, b1, b2, b3] = rows_mut(band, n, [0, 1, 2, 3]);
            let mine = [b0, b1, b2, b3].map(|row| segment(row, cs));
            let [o0, o1, o2, o3] = rows_mut(other, n, [0, 1, 2, 3]);
            let theirs = [o0, o1, o2, o3].map(|row| segment(row, c));
            let saved: [[T; B]; B] = core::array::from_fn(|i| *mine[i]);
            for (j, row) in theirs.iter().enumerate() {
                for (i, v) in radix4_plain(**row).into_iter().enumerate() {
                    mine[i][j] = v;
                }
            }
            for (i, row) in saved.iter().enumerate() {
                for (j, v) in radix4_plain(*row).into_iter().enumerate() {
                    theirs[j][i] = v;
                }
            }
        }
    }
}

/// The four values of `row` from `start` on, as an array.
#[inline(always)]
fn segment<T>(row: &mut [T], start: usize) -> &mut [T; 4] {
    let (_, tail) = row.split_at_mut(start);
    match tail.first_chunk_mut::<4>() {
        Some(s) => s,
        None => chunk_out_of_range(),
    }
}

/// Swap `data[r·n + p(s)]` with `data[s·n + p(r)]` for all `s < r < n`,
/// `p` a permutation of `0..n` with `p(4t + j) = p(4t) + p(j)` for `j < 4`
/// (an involution of the array: the identity gives the transpose).
///
/// Works in 4 × 4 tiles, so that one tile's sixteen swaps share their
/// row and column offsets.
#[inline(always)]
fn swap_across_diagonal<T, P: Fn(usize) -> usize>(data: &mut [T], n: usize, p: P) {
    const B: usize = 4;
    if n % B != 0 {
        for r in 1..n {
            for s in 0..r {
                data.swap(r * n + p(s), s * n + p(r));
            }
        }
        return;
    }
    let q: [usize; B] = core::array::from_fn(&p);
    for rt in 0..n / B {
        let (above, below) = data.split_at_mut(B * rt * n);
        let band = &mut below[..B * n];
        let pr = p(B * rt);
        for i in 1..B {
            for j in 0..i {
                band.swap(i * n + pr + q[j], j * n + pr + q[i]);
            }
        }
        for (st, other) in above.chunks_exact_mut(B * n).enumerate() {
            let ps = p(B * st);
            for i in 0..B {
                for j in 0..B {
                    core::mem::swap(&mut band[i * n + ps + q[j]], &mut other[j * n + pr + q[i]]);
                }
            }
        }
    }
}
