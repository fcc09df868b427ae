//! The row pass of a square 2D DHT whose values lie on few rows (an
//! adaptive view's slice): only those rows transformed, as the lanes of
//! one batched column transform when the caller gives the scratch.

use super::line::dht_unchecked;
#[cfg(doc)]
use super::plane::dht_2d;
use super::plane::dht_columns;
use super::Twiddles;
use crate::num::Real;

/// At most one row in this many holding a nonzero value, [`dht_2d`]'s
/// row pass of a square array from side 128 transforms only those rows.
pub(super) const SPARSE_ROWS: usize = 4;

/// Scratch elements (`column`) with which [`dht_2d`] batches the row pass
/// of an `n × n` array with few nonzero rows: its nonzero rows, at most
/// `n / 4`, as the lanes of one `n`-point column transform.
pub const fn dht_2d_sparse_len(n: usize) -> usize {
    n * (n / SPARSE_ROWS)
}

/// The row pass of an `n × n` array whose nonzero values lie on at most
/// `n / SPARSE_ROWS` rows (an adaptive view's slice, whose weak samples are
/// left at zero): those rows transformed, the others left as they are
/// (the transform of zeros is zero, up to the sign of zero), instead of
/// every row between two transposes. With `n·k` elements of `scratch` for
/// the `k` rows, they go there as the lanes of an `n × k` array for the
/// batched column transform, and back; else each is transformed on its
/// own. `false`, and nothing done, for more rows. The values are the
/// batched pass's bit for bit, as [`dht_2d`] says.
#[inline]
pub(super) fn sparse_rows<T: Real>(
    data: &mut [T],
    n: usize,
    scratch: &mut [T],
    tw: &Twiddles<'_, T>,
) -> bool {
    // A whole-row test without early exit: the compare and OR vectorize.
    let nonzero = |row: &[T]| row.iter().fold(false, |any, &v| any | (v != T::ZERO));
    let k = data.chunks_exact(n).filter(|row| nonzero(row));
    let k = k.take(n / SPARSE_ROWS + 1).count();
    if k > n / SPARSE_ROWS {
        return false;
    }
    let Some(lanes) = scratch.get_mut(..n * k).filter(|_| k > 1) else {
        for row in data.chunks_exact_mut(n).filter(|row| nonzero(row)) {
            dht_unchecked(row, tw);
        }
        return true;
    };
    // Rows go to lanes and back a tile at a time, so each lane row (`k`
    // values) is written in runs of `TILE`, not one value per cache line.
    const TILE: usize = 8;
    let mut rows = data.chunks_exact_mut(n).filter(|row| nonzero(row));
    for j in (0..k).step_by(TILE) {
        let mut tile: heapless::Vec<&mut [T], TILE> = rows.by_ref().take(TILE).collect();
        for (x, lane) in lanes.chunks_exact_mut(k).enumerate() {
            for (v, row) in lane[j..].iter_mut().zip(&tile) {
                *v = row[x];
            }
        }
        // Row 0 marks the rows taken (their values are in `lanes`), so
        // the way back finds them without testing whole rows again.
        for row in &mut tile {
            row[0] = T::ONE;
        }
    }
    dht_columns(lanes, k, n, tw);
    let mut rows = data.chunks_exact_mut(n).filter(|row| row[0] != T::ZERO);
    for j in (0..k).step_by(TILE) {
        let mut tile: heapless::Vec<&mut [T], TILE> = rows.by_ref().take(TILE).collect();
        for (x, lane) in lanes.chunks_exact(k).enumerate() {
            for (v, row) in lane[j..].iter().zip(&mut tile) {
                row[x] = *v;
            }
        }
    }
    true
}
