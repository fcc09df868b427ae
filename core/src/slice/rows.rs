//! The rows of a slice and the walk over its points inside the
//! spectrum's Nyquist cube: row intervals, and mirror pairs.

use crate::filter::PhaseTable;
use crate::num::Real;

/// Which rows of the slice to fill, and its axes in index units.
pub(super) struct SliceRows<T> {
    pub(super) right: [T; 3],
    pub(super) up: [T; 3],
    pub(super) m: usize,
    pub(super) first_row: usize,
}

impl<T: Real> SliceRows<T> {
    /// [`walk_pairs`] over this slice's rows, with the positions in `T`.
    /// `POW2`: `m` is a power of two, and `k mod m` is a mask; otherwise a
    /// comparison (mixed-radix sides).
    #[inline(always)]
    pub(super) fn for_each_fixed_pair<const W: usize, const POW2: bool>(
        &self,
        n: usize,
        grid: &mut [T],
        pixel: impl FnMut([i64; 3], bool, bool) -> (T, T),
    ) {
        walk_pairs::<W, POW2, T, Self>(self, self.m, self.first_row, n, grid, pixel);
    }

    /// [`SliceRows::row_interval`] as the walks of filter width `W` call
    /// it: inlined for `W ≤ 3`, out of line above. Codegen only: with it
    /// inlined the M4F's kb3 extraction (the firmware's scene filter)
    /// compiles to 43 k fewer instructions (1,179 k → 1,137 k), while kb6's
    /// loop compiles worse inlined (+815 k), and kb4's a little (+9 k).
    #[inline(always)]
    fn row_interval_for<const W: usize>(&self, n: usize, c: [T; 3]) -> (i32, i32) {
        if W <= 3 {
            self.row_interval_inlined(n, c)
        } else {
            self.row_interval(n, c)
        }
    }

    /// The integers `kx` in `[low, high]` for which `|kx·r_a + c_a| ≤ n/2` on
    /// every axis (`c = ky·u`): the intersection of three intervals, each
    /// `(±n/2 − c_a)/r_a`, rounded inwards. Points within rounding of the
    /// cube's faces may fall on either side; their interpolated value is
    /// next to nothing there (the band-limited spectrum ends at the faces).
    /// Not inlined: see [`SliceRows::row_interval_for`].
    #[inline(never)]
    fn row_interval(&self, n: usize, c: [T; 3]) -> (i32, i32) {
        self.row_interval_inlined(n, c)
    }

    /// [`SliceRows::row_interval`], always inlined.
    #[inline(always)]
    fn row_interval_inlined(&self, n: usize, c: [T; 3]) -> (i32, i32) {
        row_interval(n, &self.right, c)
    }
}

/// The integers `kx` for which `|kx·r_a + c_a| ≤ n/2` on every axis `a`
/// (`r = right`, `c = ky·up`): the intersection of three intervals, each
/// `(±n/2 − c_a)/r_a`, rounded inwards; `(1, 0)` (empty) when an axis
/// the row does not move along lies outside. The host's walks call it too,
/// so that their rows cover the same points as the core's.
#[inline(always)]
pub fn row_interval<T: Real>(n: usize, right: &[T; 3], c: [T; 3]) -> (i32, i32) {
    let half = T::from_usize(n) * T::HALF;
    let (mut low, mut high) = (-T::from_usize(n), T::from_usize(n));
    for a in 0..3 {
        let (r, c) = (right[a], c[a]);
        if r == T::ZERO {
            if c > half || -c > half {
                return (1, 0);
            }
            continue;
        }
        let (t1, t2) = ((-half - c) / r, (half - c) / r);
        let (t_low, t_high) = if t1 < t2 { (t1, t2) } else { (t2, t1) };
        if t_low > low {
            low = t_low;
        }
        if t_high < high {
            high = t_high;
        }
    }
    (-((-low).floor_i64() as i32), high.floor_i64() as i32)
}

/// Where the rows of a slice run through the spectrum, in the 32.32
/// fixed-point phase positions of [`PhaseTable::fixed_position`]: what
/// [`walk_pairs`] needs from the slice's axes, computed in floating point
/// ([`SliceRows`]) or in integers (the fixed-point extraction).
pub(super) trait RowPositions<const W: usize> {
    /// What a row's positions are computed from (`ky·u`).
    type Row: Copy;
    /// The step of the position per unit of `kx` (`r` in fixed point).
    fn steps(&self) -> [i64; 3];
    /// The row of signed frequency `ky = p`: its context and the interval
    /// `[low, high]` of `kx` inside the cube `|q_a| ≤ n/2` (empty when
    /// `low > high`).
    fn row(&self, n: usize, p: usize) -> (Self::Row, i32, i32);
    /// The position of the point `kx` of `row`.
    fn position(&self, row: Self::Row, kx: i32) -> [i64; 3];
}

impl<T: Real, const W: usize> RowPositions<W> for SliceRows<T> {
    type Row = [T; 3];

    #[inline(always)]
    fn steps(&self) -> [i64; 3] {
        self.right.map(PhaseTable::<T, W>::fixed_step)
    }

    #[inline(always)]
    fn row(&self, n: usize, p: usize) -> ([T; 3], i32, i32) {
        let ky = T::from_usize(p);
        let kyu = self.up.map(|c| ky * c);
        let (low, high) = self.row_interval_for::<W>(n, kyu);
        (kyu, low, high)
    }

    #[inline(always)]
    fn position(&self, kyu: [T; 3], kx: i32) -> [i64; 3] {
        let kx = T::from_i32(kx);
        core::array::from_fn(|a| PhaseTable::<T, W>::fixed_position(kx * self.right[a] + kyu[a]))
    }
}

/// Fills the rows inside the Nyquist cube from `pixel(y, plus, minus)`
/// and zeroes the points outside. `y` is a slice point's per-axis
/// phase-table position in fixed point
/// ([`PhaseTable::fixed_position`]); `pixel` returns the value there
/// (when `plus`) and the value at the mirrored point `−q` (when
/// `minus`), which has the same taps reflected through the origin with
/// the same weights: the setup of a point (positions, phase rows,
/// weights) serves both `(kx, ky)` and `(−kx, −ky)`.
///
/// Points are placed per *mirror pair*: row `p = 0 … m/2` (signed
/// `ky = p`) is walked once for `kx` in its interval, writing the
/// point into row `p` and its mirror into row `−p` (row 0 pairs `kx`
/// with `−kx`). Row `−m/2` and column `−m/2`, whose mirrors are off the
/// grid, are the mirrors of `ky = m/2` and `kx = m/2`. So the value of
/// every point depends only on its pair, never on which rows the
/// caller asked for (threads get the same bits), and a point with its
/// mirror in the same call costs one setup for two.
///
/// Along a row, one point is placed by [`RowPositions::position`]; the
/// position then advances by [`RowPositions::steps`] (the fixed-point
/// step of `r`): two integer additions an axis instead of a product, a sum
/// and a floor in floating point. The grid holds `m` columns and
/// `grid.len()/m` rows from row `first_row`.
#[inline(always)]
pub(super) fn walk_pairs<
    const W: usize,
    const POW2: bool,
    G: Copy + Default,
    P: RowPositions<W>,
>(
    positions: &P,
    m: usize,
    first_row: usize,
    n: usize,
    grid: &mut [G],
    mut pixel: impl FnMut([i64; 3], bool, bool) -> (G, G),
) {
    grid.fill(G::default());
    let rows = grid.len() / m;
    let step = positions.steps();
    // Signed frequencies of a row: −⌊m/2⌋ … ⌈m/2⌉ − 1 (`signed_index`).
    let (half, k_max) = ((m / 2) as i32, ((m - 1) / 2) as i32);
    let mask = m.wrapping_sub(1);
    // Row `r` of the grid as a slot in this call's rows, if there.
    let local = |r: usize| r.checked_sub(first_row).filter(|&i| i < rows);
    for p in 0..=m / 2 {
        let plus_row = if p as i32 <= k_max { local(p) } else { None };
        let minus_row = local(if POW2 { (m - p) & mask } else { (m - p) % m });
        if plus_row.is_none() && minus_row.is_none() {
            continue;
        }
        let (row, low, high) = positions.row(n, p);
        // Row 0 is its own mirror: `kx ≥ 0` places both halves.
        let k_low = if p == 0 { 0 } else { -half };
        let (low, high) = (low.max(k_low), high.min(half));
        if low > high {
            continue;
        }
        // The row is anchored at `kx = 0` (or the nearest point of its
        // interval), where `q = ky·u` is as exact as `T` makes it: the
        // low frequencies, which carry most of the energy, then get
        // the least rounding (the steps are exact multiples of `r`).
        let anchor = 0.clamp(low, high);
        let at_anchor = positions.position(row, anchor);
        let mut y: [i64; 3] =
            core::array::from_fn(|a| at_anchor[a] + (low - anchor) as i64 * step[a]);
        for k in low..=high {
            // The point `(k, p)` is on the grid for `k ≤ k_max`, its
            // mirror `(−k, −p)` for `−k ≤ k_max` (and `−k ≥ −m/2`, the
            // loop's bound), on row 0 only for `k > 0` (`k = 0` is its
            // own mirror).
            let plus = plus_row.is_some() && k <= k_max;
            let minus = minus_row.is_some() && -k <= k_max && (p > 0 || k > 0);
            if plus || minus {
                let (value, mirror) = pixel(y, plus, minus);
                // `k mod m`: by a mask for a power of two, else `k + m` for
                // negative `k` (`|k| ≤ m/2`).
                let modulo = |k: i32| {
                    if POW2 {
                        k as usize & mask
                    } else if k < 0 {
                        (k + m as i32) as usize
                    } else {
                        k as usize
                    }
                };
                if let (true, Some(r)) = (plus, plus_row) {
                    if let Some(g) = grid.get_mut(r * m + modulo(k)) {
                        *g = value;
                    }
                }
                if let (true, Some(r)) = (minus, minus_row) {
                    if let Some(g) = grid.get_mut(r * m + modulo(k.wrapping_neg())) {
                        *g = mirror;
                    }
                }
            }
            for a in 0..3 {
                y[a] += step[a];
            }
        }
    }
}
