//! The slice's axes in fixed point: the rows' positions and intervals of
//! the mirror-pair walk in integers.

use super::super::rows::RowPositions;
use crate::error::{Error, Result};
use crate::filter::TABLE_RESOLUTION;
use crate::geometry::SliceAxes;

/// One index unit in the 32.32 phase positions: `1024·2^32`.
const UNIT_LOG2: u32 = 32 + TABLE_RESOLUTION.trailing_zeros();

/// Largest axis component accepted, in index units per pixel (voxel-unit
/// axes are unit vectors; physical ones scale by `Δ_a/p`).
const MAX_COMPONENT: f64 = 16.0;

/// Largest cube side: positions `|q| ≤ n/2 + W` times `2^42` and the
/// row products `ky·u` stay far inside `i64`.
pub(super) const MAX_SIDE: usize = 4096;

/// The axes `r` and `u` rounded once (per view, in floating point) to
/// steps of the phase position: `R_a = round(r_a·2^42)`, the position's
/// change per unit of `kx` (as [`crate::filter::PhaseTable::fixed_step`]),
/// and `U_a` likewise. A point's position is then
/// `kx·R + ky·U − 512·W·2^32` exactly, and whether it lies in the Nyquist
/// cube `|q_a| ≤ n/2` is the integer test `|kx·R_a + ky·U_a| ≤ n·2^41`:
/// the walk's rows and intervals need no floating point. Rounding the axes
/// moves a point by at most `|k|·2^−43` index units.
#[derive(Clone, Copy, Debug)]
pub(super) struct FixedAxes<const W: usize> {
    right: [i64; 3],
    up: [i64; 3],
}

impl<const W: usize> FixedAxes<W> {
    /// The axes in fixed point.
    ///
    /// # Errors
    /// A component that is not finite or beyond ±16 index units
    /// ([`Error::FixedPointRange`]).
    pub(super) fn new(axes: &SliceAxes) -> Result<Self> {
        let unit = libm::scalbn(1.0, UNIT_LOG2 as i32);
        let fixed = |v: [f64; 3]| -> Result<[i64; 3]> {
            let mut out = [0i64; 3];
            for (o, c) in out.iter_mut().zip(v) {
                if !(c.is_finite() && libm::fabs(c) <= MAX_COMPONENT) {
                    return Err(Error::FixedPointRange {
                        what: "slice axis component (finite, at most 16 index units)",
                    });
                }
                *o = libm::round(c * unit) as i64;
            }
            Ok(out)
        };
        Ok(Self {
            right: fixed(axes.right)?,
            up: fixed(axes.up)?,
        })
    }
}

impl<const W: usize> RowPositions<W> for FixedAxes<W> {
    /// `ky·U`.
    type Row = [i64; 3];

    #[inline(always)]
    fn steps(&self) -> [i64; 3] {
        self.right
    }

    fn row(&self, n: usize, p: usize) -> ([i64; 3], i32, i32) {
        let ky = p as i64;
        let row = self.up.map(|u| ky * u);
        let half = (n as i64) << (UNIT_LOG2 - 1);
        let (mut low, mut high) = (-(n as i64), n as i64);
        for a in 0..3 {
            // |kx·r + c| = |kx·(−r) + (−c)|: make the step positive.
            let (r, c) = if self.right[a] < 0 {
                (-self.right[a], -row[a])
            } else {
                (self.right[a], row[a])
            };
            if r == 0 {
                if c.abs() > half {
                    return (row, 1, 0);
                }
                continue;
            }
            // kx·r + c ∈ [−half, half] ⟺ kx ∈ [⌈(−half − c)/r⌉, ⌊(half − c)/r⌋].
            low = low.max(-(half + c).div_euclid(r));
            high = high.min((half - c).div_euclid(r));
        }
        (row, low as i32, high as i32)
    }

    #[inline(always)]
    fn position(&self, c: [i64; 3], kx: i32) -> [i64; 3] {
        let origin = ((W * TABLE_RESOLUTION / 2) as i64) << 32;
        core::array::from_fn(|a| kx as i64 * self.right[a] + c[a] - origin)
    }
}
