//! The host's slice extraction for slices that contain a coordinate axis:
//! the same points and weights as [`crate::slice::exact`], summed in another
//! order, with a third to a fifth of the products and each stored sample
//! widened once per column block instead of once per tap.
//!
//! A slice point is `k·r + p·u` (`r` the right axis, `u` the up axis,
//! column `k`, row `p`). When `u` lies along axis `a` and `r` has no `a`
//! component (every turntable about an axis through views square to it,
//! which is the circular orbit of a CT gantry), column `k` sits at the same
//! point `k·r` of the other two axes `(u, w)` in every row, and row `p` at
//! the same `a = p·|u|` in every column. The `W³` taps of a point then
//! factor:
//!
//! 1. **Interpolate each plane along the line:** for every column `k` and
//!    every plane `a = z` of the cube,
//!    `L(k, z) = Σ_b ww_b Σ_t wu_t c[u₀ + t, w₀ + b, z]`, `W²` products.
//!    Eight planes go side by side: the cells the column block reaches
//!    are widened into a buffer with the plane fastest, so every product
//!    is an eight-lane multiply-add.
//! 2. **Filter along the axis:** `value(k, p) = Σ_c wz_c L(k, z₀(p) + c)`,
//!    `W` products.
//!
//! A point costs `W² + W` products against the strip walk's
//! `√2·W² + W²` ([`crate::slice::strip`]) and the core's `W³`, and the
//! spectrum is read once per block of columns, in runs along `x`.
//!
//! **Rounding.** Row `p ≥ 0` takes the core's taps. Row `−p` takes the
//! core's mirrored taps on `a`, but on `(u, w)` the taps of its own
//! column `k = −k'` where the core reflects those of `k'`: the same points
//! and the same exact weights, each interpolated from the phase table at
//! the reflected fraction, so each differs by the table interpolation's
//! rounding (two roundings of a weight). With the sums' `3W + 2`, a value
//! differs from the core's by at most `γ·Σ|wu·ww·wz·c|`, `γ = (3W + 8)·ε`
//! of `T` (tested in `tests/fast_strip.rs`).

use fvr_core::filter::{KernelTable, PhaseTable};
use fvr_core::geometry::SliceAxes;
use fvr_core::num::{Real, Sample};
use fvr_core::spectrum::Spectrum;
use rayon::prelude::*;

use crate::slice::exact::{phase_table, row_setup, Geometry, SliceJob};
use crate::slice::prefetch::prefetch;
use crate::slice::runs::{axes_and_strides, wrap, Runs};

/// Planes interpolated side by side (the multiply-adds' lanes).
const LANES: usize = 8;

/// The axis the slice contains (its up axis, with the right axis square
/// to it), if any: `up` zero on the two other axes and `right` zero on it.
pub fn column_axis(axes: &SliceAxes) -> Option<usize> {
    (0..3).find(|&a| axes.right[a] == 0.0 && (0..3).all(|b| b == a || axes.up[b] == 0.0))
}

/// Values the walk keeps between its passes for side `n`: two per cell of
/// the slice, for the columns whose mirror rows reach other cells.
pub const fn along_len(n: usize) -> usize {
    2 * n * n
}

/// Fill the `n × n` slice `grid` (`kx` fastest, natural DHT order) of
/// `job` as [`crate::slice::exact::extract`] does, to within rounding (see
/// the module's bound), `job.tiling.chunk` columns per unit of work.
/// `along` holds the planes' sums between the passes (`2n²` values; kept
/// by the caller, so that views after the first allocate nothing).
/// `false` (grid untouched) when the slice contains no axis
/// ([`column_axis`]) or [`SliceJob::geometry`] declines.
pub fn extract<S: Sample, T: Real + Send + Sync>(
    job: &SliceJob<'_, Spectrum<'_, S>, T>,
    grid: &mut [T],
    along: &mut Vec<T>,
) -> bool {
    let (Some(g), Some(axis)) = (job.geometry(grid), column_axis(job.axes)) else {
        return false;
    };
    let (data, kernel) = (job.spec.data(), job.kernel);
    for_width!(kernel.filter().width(), W => walk::<W, S, T>(data, kernel, &g, axis, grid, along))
}

/// One stretch of a grid row: its signed columns `lo ..= hi` and its taps
/// on the contained axis (the stored samples' gain folded in).
struct RowTaps<const W: usize, T> {
    row: usize,
    /// Row `−p`'s mirrors (the core reflects the taps of column `−k`).
    mirror: bool,
    lo: i32,
    hi: i32,
    planes: [usize; W],
    weights: [T; W],
}

/// One column of a block: its first taps and weights on `u` and `w`.
#[derive(Clone, Copy)]
struct Column<const W: usize, T> {
    ju: i32,
    jw: i32,
    wu: [T; W],
    ww: [T; W],
}

/// A thread's buffers for one block of columns.
struct Scratch<const W: usize, T> {
    /// The block's tap sets and where their runs go.
    columns: Vec<(Column<W, T>, usize)>,
    runs: Runs,
    cells: Vec<[T; LANES]>,
}

/// The spectrum, its strides and the tables the columns need.
struct Line<'a, const W: usize, S, T> {
    data: &'a [S],
    n: usize,
    /// Element strides of the contained axis, `u` and `w` (`u` before `w`
    /// in memory order).
    strides: [usize; 3],
    phases: &'a PhaseTable<T, W>,
    /// Fixed-point position of column 0 and step per column on `u`, `w`.
    origin: [i64; 2],
    step: [i64; 2],
    /// Lines prefetched ahead ([`Tiling::ahead`]).
    ahead: usize,
}

/// The signed frequency of grid column `c` (`c` for `c ≤ (n − 1)/2`, else
/// `c − n`).
#[inline(always)]
fn signed(n: usize, c: usize) -> i32 {
    if c <= (n - 1) / 2 {
        c as i32
    } else {
        c as i32 - n as i32
    }
}

/// The rows' stretches and taps as the core sets its rows up
/// ([`crate::slice::exact::set_up_pair`]), and the columns' common origin on
/// `u` and `w`; `None` when the rows do not share one (never for a slice
/// [`column_axis`] accepts, whose rows all anchor at column 0).
fn rows<const W: usize, T: Real>(
    g: &Geometry<T>,
    phases: &PhaseTable<T, W>,
    [a, u, w]: [usize; 3],
    gain: T,
) -> Option<(Vec<RowTaps<W, T>>, [i64; 2])> {
    let n = g.n;
    let k_max = ((n - 1) / 2) as i32;
    let step = g.right.map(PhaseTable::<T, W>::fixed_step);
    let mut origin = None;
    let mut list = Vec::with_capacity(n + 1);
    let planes = |j: i32| -> [usize; W] { core::array::from_fn(|c| wrap(n, j as i64 + c as i64)) };
    for p in 0..=n / 2 {
        let Some((low, high, anchor, base)) = row_setup::<W, T>(g, p) else {
            continue;
        };
        let here = [u, w].map(|b| base[b] - anchor as i64 * step[b]);
        if *origin.get_or_insert(here) != here {
            return None;
        }
        let (jz, wz) = phases.taps_fixed_point(base[a]);
        let wz = wz.map(|x| x * gain);
        if p as i32 <= k_max {
            list.push(RowTaps {
                row: p,
                mirror: false,
                lo: low,
                hi: high.min(k_max),
                planes: planes(jz),
                weights: wz,
            });
        }
        // Row −p holds the mirrors −k of k = low ..= high (row 0's own
        // mirrors, k > 0, in row 0).
        let (row, first) = if p == 0 {
            (0, low.max(1))
        } else {
            ((n - p) % n, low)
        };
        if first <= high {
            list.push(RowTaps {
                row,
                mirror: true,
                lo: -high,
                hi: (-first).min(k_max),
                planes: planes(-jz - (W as i32 - 1)),
                weights: core::array::from_fn(|t| wz[W - 1 - t]),
            });
        }
    }
    Some((list, origin.unwrap_or([0; 2])))
}

#[inline(never)]
fn walk<const W: usize, S: Sample, T: Real + Send + Sync>(
    data: &[S],
    kernel: &KernelTable<T>,
    g: &Geometry<T>,
    axis: usize,
    grid: &mut [T],
    along: &mut Vec<T>,
) -> bool {
    let Some(phases) = phase_table::<W, T>(kernel) else {
        return false;
    };
    let n = g.n;
    let (axes @ [_, u, w], strides) = axes_and_strides(axis, n);
    let gain = T::exp2i(T::raw_exponent::<S>());
    let Some((rows, origin)) = rows(g, &phases, axes, gain) else {
        return false;
    };
    let line = Line::<W, S, T> {
        data,
        n,
        strides,
        phases: &phases,
        origin,
        step: [u, w].map(|b| PhaseTable::<T, W>::fixed_step(g.right[b])),
        ahead: g.tiling.ahead,
    };
    let columns = line.columns();
    // Pass 1: `L(k, z)` for every column (and its mirrored taps where
    // they differ), z fastest, by blocks of columns.
    let block = g.tiling.chunk.clamp(1, n);
    // Every value is written before it is read: no clearing.
    along.resize(along_len(n), T::ZERO);
    let fill = |scratch: &mut Scratch<W, T>, (b, chunk): (usize, &mut [T])| {
        let first = b * block;
        let last = (first + block).min(n);
        line.fill_block(&columns[first..last], chunk, scratch);
    };
    let new_scratch = || Scratch::<W, T> {
        columns: Vec::new(),
        runs: Runs::default(),
        cells: Vec::new(),
    };
    if g.parallel {
        along
            .par_chunks_mut(2 * block * n)
            .enumerate()
            .for_each_init(new_scratch, fill);
    } else {
        let mut scratch = new_scratch();
        along
            .chunks_mut(2 * block * n)
            .enumerate()
            .for_each(|item| fill(&mut scratch, item));
    }
    // Pass 2: each row's stretches filtered along the axis.
    let mut by_row: Vec<Vec<&RowTaps<W, T>>> = (0..n).map(|_| Vec::new()).collect();
    for r in &rows {
        by_row[r.row].push(r);
    }
    let along = &*along;
    let finish = |(row, out): (usize, &mut [T])| {
        out.fill(T::ZERO);
        for r in &by_row[row] {
            for (c, o) in out.iter_mut().enumerate() {
                let k = signed(n, c);
                if k < r.lo || k > r.hi {
                    continue;
                }
                let i = (k + (n / 2) as i32) as usize;
                let mirrored = r.mirror && columns.get(i).is_some_and(|c| c.1.is_some());
                let at = 2 * i * n + if mirrored { n } else { 0 };
                let Some(run) = along.get(at..at + n) else {
                    continue;
                };
                let mut acc = T::ZERO;
                for (&z, &wz) in r.planes.iter().zip(&r.weights) {
                    acc += wz * run.get(z).copied().unwrap_or(T::ZERO);
                }
                *o = acc;
            }
        }
    };
    if g.parallel {
        grid.par_chunks_mut(n).enumerate().for_each(finish);
    } else {
        grid.chunks_mut(n).enumerate().for_each(finish);
    }
    true
}

impl<const W: usize, S: Sample, T: Real> Line<'_, W, S, T> {
    /// In order of the signed column `k = −n/2 … (n − 1)/2`, so that
    /// neighbours in a block are neighbours on the line: the taps of
    /// column `k` at `k·r` on `u` and `w`, and the core's
    /// for row `−p`'s point there (the reflection of column `−k`'s) where
    /// those take other cells: at phase zero a width-`W` window of an even
    /// `W` reaches `W/2` to one side, the reflected one to the other.
    fn columns(&self) -> Vec<(Column<W, T>, Option<Column<W, T>>)> {
        let n = self.n;
        let taps = |k: i64| {
            let (ju, wu) = self
                .phases
                .taps_fixed_point(self.origin[0] + k * self.step[0]);
            let (jw, ww) = self
                .phases
                .taps_fixed_point(self.origin[1] + k * self.step[1]);
            Column { ju, jw, wu, ww }
        };
        let mirror = |j: i32| -j - (W as i32 - 1);
        let reversed = |w: [T; W]| -> [T; W] { core::array::from_fn(|t| w[W - 1 - t]) };
        (0..n)
            .map(|i| {
                let k = i as i64 - (n / 2) as i64;
                let direct = taps(k);
                let other = taps(-k);
                let reflected = Column {
                    ju: mirror(other.ju),
                    jw: mirror(other.jw),
                    wu: reversed(other.wu),
                    ww: reversed(other.ww),
                };
                let differs = reflected.ju != direct.ju || reflected.jw != direct.jw;
                (direct, differs.then_some(reflected))
            })
            .collect()
    }

    /// `L(k, ·)` of a block of columns into `out`, two runs of `n` planes
    /// a column: its own taps', then its reflected taps' where
    /// [`Line::columns`] has them.
    fn fill_block(
        &self,
        block: &[(Column<W, T>, Option<Column<W, T>>)],
        out: &mut [T],
        s: &mut Scratch<W, T>,
    ) {
        let n = self.n;
        s.columns.clear();
        for (i, (direct, reflected)) in block.iter().enumerate() {
            s.columns.push((*direct, 2 * i * n));
            if let Some(r) = reflected {
                s.columns.push((*r, 2 * i * n + n));
            }
        }
        // The cells the block reaches: one run of `u` per line `w`.
        let runs = &mut s.runs;
        if !runs.cover::<W>(s.columns.iter().map(|(q, _)| (q.ju, q.jw))) {
            return;
        }
        s.cells.clear();
        s.cells.resize(runs.total(), [T::ZERO; LANES]);
        let [sa, su, sw] = self.strides;
        let lines = runs.lines();
        for z0 in (0..n).step_by(LANES) {
            let m = LANES.min(n - z0);
            for l in 0..lines {
                // The line `ahead` further on, in this group of planes or
                // the next.
                let (la, za) = match l + self.ahead {
                    la if la < lines => (la, z0),
                    la => (la - lines, z0 + LANES),
                };
                if self.ahead > 0 && za < n {
                    if let Some((first, last)) = runs.ends(n, su, sw, la) {
                        for plane in (za..n.min(za + LANES)).map(|z| z * sa) {
                            prefetch(self.data, plane + first);
                            prefetch(self.data, plane + last);
                        }
                    }
                }
                let w = wrap(n, runs.w_min as i64 + l as i64);
                let cells = &mut s.cells[runs.off[l]..runs.off[l + 1]];
                self.widen(z0, m, w, runs.lo[l], cells);
            }
            for (q, dst) in &s.columns {
                let mut acc = [T::ZERO; LANES];
                for b in 0..W {
                    let start = runs.start(q.ju, q.jw, b);
                    let Some(run) = s.cells.get(start..start + W) else {
                        continue;
                    };
                    let mut inner = [T::ZERO; LANES];
                    for (t, cell) in run.iter().enumerate() {
                        for (x, &v) in inner.iter_mut().zip(cell) {
                            *x += q.wu[t] * v;
                        }
                    }
                    for (x, &v) in acc.iter_mut().zip(&inner) {
                        *x += q.ww[b] * v;
                    }
                }
                if let Some(dst) = out.get_mut(dst + z0..dst + z0 + m) {
                    dst.copy_from_slice(&acc[..m]);
                }
            }
        }
    }

    /// `cells[i][j] = c[a = z0 + j, u = lo + i, w]` for `j < m` (raw
    /// widening), indices wrapping around the cube.
    #[inline(always)]
    fn widen(&self, z0: usize, m: usize, w: usize, lo: i32, cells: &mut [[T; LANES]]) {
        let n = self.n;
        let [sa, su, sw] = self.strides;
        let line = w * sw;
        let u0 = wrap(n, lo as i64);
        let len = cells.len();
        if su == 1 && u0 + len <= n {
            for j in 0..m {
                let start = (z0 + j) * sa + line + u0;
                let Some(src) = self.data.get(start..start + len) else {
                    return;
                };
                for (o, &v) in cells.iter_mut().zip(src) {
                    o[j] = T::load_raw(v);
                }
            }
            return;
        }
        for (i, o) in cells.iter_mut().enumerate() {
            let u = wrap(n, lo as i64 + i as i64);
            for (j, x) in o.iter_mut().enumerate().take(m) {
                let v = self.data.get((z0 + j) * sa + line + u * su).copied();
                *x = T::load_raw(v.unwrap_or_default());
            }
        }
    }
}
