//! A copy of a spectrum with its x and y axes exchanged (y fastest in
//! memory), for the strip walk ([`crate::slice::strip`]) on rows that run
//! mostly along y.
//!
//! The strip walk reads, for each line of its strip, a run of the fastest
//! axis. On rows that hold z and run mostly along x the runs are long and
//! contiguous; on rows that run mostly along y each y-line contributes a
//! run of about `W + 1` cells, so every cell read costs most of a cache
//! line. The same slice from the exchanged copy, with the slice's axes
//! exchanged too, reads long runs again. The values are the same numbers,
//! and [`crate::slice::strip::extract_exchanged`] nests its sums as on the
//! original, so the slice is the same bit for bit.

use fvr_core::geometry::SliceAxes;
use fvr_core::num::Sample;
use rayon::prelude::*;

/// Side of the square tiles the exchange copies, so that both the reads
/// and the writes of a tile stay in L1.
const TILE: usize = 32;

/// `out[y + n·x + n²·z] = data[x + n·y + n²·z]` for the cube of side `n`,
/// on all cores; `None` unless `data` holds `n³` values.
pub fn exchange_xy<S: Sample>(data: &[S], n: usize) -> Option<Vec<S>> {
    let plane = n.checked_mul(n)?;
    if plane.checked_mul(n)? != data.len() {
        return None;
    }
    let mut out = Vec::new();
    out.par_extend(rayon::iter::repeat_n(S::default(), data.len()));
    out.par_chunks_mut(plane.max(1))
        .zip(data.par_chunks(plane.max(1)))
        .for_each(|(to, from)| {
            for y0 in (0..n).step_by(TILE) {
                for x0 in (0..n).step_by(TILE) {
                    for y in y0..(y0 + TILE).min(n) {
                        for x in x0..(x0 + TILE).min(n) {
                            to[y + n * x] = from[x + n * y];
                        }
                    }
                }
            }
        });
    Some(out)
}

/// The slice axes for the exchanged copy: x and y components swapped.
pub fn exchanged(axes: &SliceAxes) -> SliceAxes {
    let swap = |v: [f64; 3]| [v[1], v[0], v[2]];
    SliceAxes {
        right: swap(axes.right),
        up: swap(axes.up),
    }
}

/// `true` when the strip walk would hold z on rows that run mostly along
/// y: the exchanged copy then reads long runs where the spectrum reads
/// short ones.
pub fn rows_along_y(axes: &SliceAxes) -> bool {
    axes.right[2] == 0.0 && axes.right[1].abs() > axes.right[0].abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cell lands where the exchange puts it, on sides below, at and
    /// above the tile and not multiples of it; wrong lengths are refused.
    #[test]
    fn every_cell_moves_to_its_exchanged_place() {
        for n in [1, 2, 5, 32, 40, 66] {
            let data: Vec<f32> = (0..n * n * n).map(|i| i as f32).collect();
            let out = exchange_xy(&data, n).unwrap();
            for z in 0..n {
                for y in 0..n {
                    for x in 0..n {
                        assert_eq!(out[y + n * (x + n * z)], data[x + n * (y + n * z)]);
                    }
                }
            }
            assert_eq!(exchange_xy(&out, n).unwrap(), data, "twice is the identity");
        }
        assert!(exchange_xy(&[0f32; 7], 2).is_none());
        assert!(exchange_xy(&[0f32; 8], usize::MAX).is_none());
    }

    #[test]
    fn rows_along_y_hold_z_and_lean_to_y() {
        let axes = |right| SliceAxes {
            right,
            up: [0.0, 0.0, 1.0],
        };
        assert!(rows_along_y(&axes([-0.29, 0.96, 0.0])));
        assert!(!rows_along_y(&axes([0.96, -0.29, 0.0])));
        assert!(!rows_along_y(&axes([0.1, 0.9, 0.1])));
        let e = exchanged(&axes([0.2, 0.7, 0.0]));
        assert_eq!(e.right, [0.7, 0.2, 0.0]);
        assert_eq!(e.up, [0.0, 0.0, 1.0]);
    }
}
