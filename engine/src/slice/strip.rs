//! The host's slice extraction for views whose rows hold one coordinate:
//! the same points and weights as [`crate::slice::exact`], summed in another
//! order, with a third to a sixth of the multiplications.
//!
//! A slice point is `k·r + p·u` (`r` the slice's right axis, `u` its up
//! axis, row `p`, column `k`). When `r` has a zero component on axis `h`,
//! every point of row `p` sits at the same `h`, so it shares its `h`-taps
//! and their weights with the whole row. The row then costs two passes
//! instead of `W³` taps a point:
//!
//! 1. **Reduce along `h`:** for every cell `(u, w)` of the other two axes
//!    that some point of the row reaches, `R(u, w) = Σ_c wh_c·c[h₀ + c, u, w]`.
//!    The cells a row reaches form a strip about its line, about `W·√2` cells
//!    wide, kept as one run of `u` per line `w`; on `h = y` or `z` the runs
//!    are contiguous in memory (`u = x`) and the loop vectorizes.
//! 2. **Interpolate in 2D:** each point is `Σ_b ww_b Σ_t wu_t R(u₀ + t, w₀ + b)`,
//!    `W²` products read from a strip that stays in L1.
//!
//! With `W` taps a side and a strip of about `√2·W` cells per point, a
//! point costs about `√2·W² + W²` products against `W³`: 2.4× fewer on
//! kb6 and 1.7× fewer on kb4, and the spectrum is read in runs.
//!
//! The default view frame (`right = up_hint × dir`, up hint on an axis)
//! and every turntable about an axis have such a zero.
//!
//! **Rounding.** Each value is the core's sum of the same `W³` products
//! `wx·wy·wz·c`, added in another order, so it differs from the core's
//! (and [`crate::slice::exact`]'s) by rounding only: at most
//! `γ·Σ|wx·wy·wz·c|` with `γ = (3W + 2)·ε` of `T` (the two passes each add
//! `W` terms and the interpolation `W²` in two levels; tested in
//! `tests/fast_strip.rs`).

use fvr_core::filter::{KernelTable, PhaseTable};
use fvr_core::geometry::SliceAxes;
use fvr_core::num::{Real, Sample};
use fvr_core::spectrum::Spectrum;
use rayon::prelude::*;

use crate::slice::exact::{bands_of_pairs, phase_table, set_up_pair, Geometry, Pair, SliceJob};
use crate::slice::prefetch::prefetch;
use crate::slice::runs::{axes_and_strides, wrap, Runs};

/// The axis whose coordinate the rows of a slice on `axes` hold (a zero
/// component of the right axis: z first, then y, then x), if any.
pub fn held_axis(axes: &SliceAxes) -> Option<usize> {
    [2, 1, 0].into_iter().find(|&a| axes.right[a] == 0.0)
}

/// Fill the `n × n` slice `grid` (`kx` fastest, natural DHT order) of
/// `job` as [`crate::slice::exact::extract`] does, to within rounding (see
/// the module's bound). `false` (grid untouched) when the rows hold no
/// coordinate ([`held_axis`]) or [`SliceJob::geometry`] declines.
pub fn extract<S: Sample, T: Real + Send + Sync>(job: &Job<'_, '_, S, T>, grid: &mut [T]) -> bool {
    extract_nested(job, grid, false, None)
}

/// [`extract`] on the points `k = within[p].0 ..= within[p].1` of each
/// mirror pair `p = 0 … n/2` (row `p` at `kx = k`, row `−p` at `kx = −k`;
/// `within` shorter than `n/2 + 1` leaves the pairs beyond it out), each
/// point's value the same bit for bit as [`extract`]'s: a strip's cells do
/// not depend on which of the row's points are summed from them. The rows
/// of the pairs walked are zeroed first; the others are left as they are.
pub fn extract_within<S: Sample, T: Real + Send + Sync>(
    job: &Job<'_, '_, S, T>,
    grid: &mut [T],
    within: &[(i32, i32)],
) -> bool {
    extract_nested(job, grid, false, Some(within))
}

/// [`extract`] on the spectrum with x and y exchanged
/// ([`crate::spectrum::exchange`]) and `job.axes` exchanged to match, for
/// rows that hold z: the interpolation's inner sum runs over the exchanged
/// spectrum's y (the original x), so that every value is summed as
/// [`extract`] sums it on the original spectrum, bit for bit.
pub fn extract_exchanged<S: Sample, T: Real + Send + Sync>(
    job: &Job<'_, '_, S, T>,
    grid: &mut [T],
) -> bool {
    held_axis(job.axes) == Some(2) && extract_nested(job, grid, true, None)
}

/// A walk of a plain spectrum.
type Job<'a, 's, S, T> = SliceJob<'a, Spectrum<'s, S>, T>;

/// [`extract`], the interpolation's inner sum over the strip's `w` axis
/// when `inner_w`, else over its `u` axis.
fn extract_nested<S: Sample, T: Real + Send + Sync>(
    job: &Job<'_, '_, S, T>,
    grid: &mut [T],
    inner_w: bool,
    within: Option<&[(i32, i32)]>,
) -> bool {
    let (Some(g), Some(held)) = (job.geometry(grid), held_axis(job.axes)) else {
        return false;
    };
    let (data, kernel) = (job.spec.data(), job.kernel);
    for_width!(kernel.filter().width(), W => {
        walk::<W, S, T>(data, kernel, &g, held, inner_w, within, grid)
    })
}

/// One point of a row: its column in the grid row, its first taps and
/// weights on the two axes other than the held one.
#[derive(Clone, Copy)]
struct Point<const W: usize, T> {
    col: usize,
    ju: i32,
    jw: i32,
    wu: [T; W],
    ww: [T; W],
}

/// A thread's buffers for one band: the points of a row and of its
/// mirror, the strip's runs and cells, and the values.
struct Scratch<const W: usize, T> {
    plus: Vec<Point<W, T>>,
    minus: Vec<Point<W, T>>,
    runs: Runs,
    cells: Vec<T>,
    values: Vec<T>,
}

impl<const W: usize, T> Scratch<W, T> {
    fn new() -> Self {
        Self {
            plus: Vec::new(),
            minus: Vec::new(),
            runs: Runs::default(),
            cells: Vec::new(),
            values: Vec::new(),
        }
    }
}

/// The spectrum, its strides and the tables a row needs.
struct Strip<'a, const W: usize, S, T> {
    data: &'a [S],
    n: usize,
    /// The held axis and the other two, `u` before `w` in memory order.
    axes: [usize; 3],
    /// Element strides of the held axis, `u` and `w`.
    strides: [usize; 3],
    phases: &'a PhaseTable<T, W>,
    raw_gain: T,
    step: [i64; 3],
    /// The interpolation's inner sum over `w` instead of `u`.
    inner_w: bool,
    /// Lines prefetched ahead ([`Tiling::ahead`]).
    ahead: usize,
    /// Whether [`crate::slice::f16c::scale_add`] reduces the planes
    /// (binary16 in `f32` on a core with F16C).
    f16c: bool,
}

#[inline(never)]
fn walk<const W: usize, S: Sample, T: Real + Send + Sync>(
    data: &[S],
    kernel: &KernelTable<T>,
    g: &Geometry<T>,
    held: usize,
    inner_w: bool,
    within: Option<&[(i32, i32)]>,
    grid: &mut [T],
) -> bool {
    let Some(phases) = phase_table::<W, T>(kernel) else {
        return false;
    };
    let n = g.n;
    let (axes, strides) = axes_and_strides(held, n);
    let strip = Strip::<W, S, T> {
        data,
        n,
        axes,
        strides,
        phases: &phases,
        raw_gain: T::exp2i(T::raw_exponent::<S>()),
        step: g.right.map(PhaseTable::<T, W>::fixed_step),
        inner_w,
        ahead: g.tiling.ahead,
        f16c: crate::slice::f16c_available::<S, T>(),
    };
    let mut bands = bands_of_pairs(grid, n, g.tiling.band);
    let fill = |band: &mut Vec<Pair<'_, T>>| {
        let mut scratch = Scratch::new();
        for pair in band.iter_mut() {
            let (from, to) = match within {
                None => (i32::MIN, i32::MAX),
                Some(w) => match w.get(pair.p) {
                    Some(&(from, to)) if from <= to => (from, to),
                    _ => continue,
                },
            };
            if set_up_pair::<W, T>(g, pair) {
                (pair.low, pair.high) = (pair.low.max(from), pair.high.min(to));
                if pair.low <= pair.high {
                    strip.fill_pair(pair, &mut scratch);
                }
            }
        }
    };
    if g.parallel {
        bands.par_iter_mut().for_each(fill);
    } else {
        bands.iter_mut().for_each(fill);
    }
    true
}

impl<const W: usize, S: Sample, T: Real> Strip<'_, W, S, T> {
    /// Row `p` and row `−p` of `pair`, each through its own strip.
    fn fill_pair(&self, pair: &mut Pair<'_, T>, s: &mut Scratch<W, T>) {
        let n = self.n;
        let k_max = ((n - 1) / 2) as i32;
        let p = pair.p;
        let has_plus = pair.plus.is_some();
        // Row 0's mirrors land in row 0 itself.
        let has_minus = pair.minus.is_some() || p == 0;
        let [h, au, aw] = self.axes;
        let mirror = |j: i32| -j - (W as i32 - 1);
        let reversed = |w: &[T; W]| -> [T; W] { core::array::from_fn(|t| w[W - 1 - t]) };
        let col = |k: i32| wrap(self.n, k as i64);
        // The held coordinate does not move along the row (`step[h] = 0`).
        let (jh, wh) = self.phases.taps_fixed_point(pair.base[h]);
        let wh = wh.map(|w| w * self.raw_gain);
        s.plus.clear();
        s.minus.clear();
        for k in pair.low..=pair.high {
            let plus = has_plus && k <= k_max;
            let minus = has_minus && -k <= k_max && (p > 0 || k > 0);
            if !(plus || minus) {
                continue;
            }
            let steps = (k - pair.anchor) as i64;
            let at = |a: usize| pair.base[a] + steps * self.step[a];
            let (ju, wu) = self.phases.taps_fixed_point(at(au));
            let (jw, ww) = self.phases.taps_fixed_point(at(aw));
            if plus {
                s.plus.push(Point {
                    col: col(k),
                    ju,
                    jw,
                    wu,
                    ww,
                });
            }
            if minus {
                s.minus.push(Point {
                    col: col(k.wrapping_neg()),
                    ju: mirror(ju),
                    jw: mirror(jw),
                    wu: reversed(&wu),
                    ww: reversed(&ww),
                });
            }
        }
        let mut plus = core::mem::take(&mut s.plus);
        self.row_values(jh, &wh, &plus, s);
        if let Some(row) = pair.plus.as_deref_mut() {
            for (q, &v) in plus.iter().zip(&s.values) {
                if let Some(g) = row.get_mut(q.col) {
                    *g = v;
                }
            }
        }
        plus.clear();
        s.plus = plus;
        let minus = core::mem::take(&mut s.minus);
        self.row_values(mirror(jh), &reversed(&wh), &minus, s);
        let row = match pair.minus.as_deref_mut() {
            Some(r) => Some(r),
            None => pair.plus.as_deref_mut(),
        };
        if let Some(row) = row {
            for (q, &v) in minus.iter().zip(&s.values) {
                if let Some(g) = row.get_mut(q.col) {
                    *g = v;
                }
            }
        }
        s.minus = minus;
    }

    /// The values of `points` (one row, held taps from `jh` with weights
    /// `wh`) into `s.values`: the strip reduced along the held axis, then
    /// each point interpolated on it.
    fn row_values(&self, jh: i32, wh: &[T; W], points: &[Point<W, T>], s: &mut Scratch<W, T>) {
        s.values.clear();
        let runs = &mut s.runs;
        if !runs.cover::<W>(points.iter().map(|q| (q.ju, q.jw))) {
            return;
        }
        s.cells.clear();
        s.cells.resize(runs.total(), T::ZERO);
        let planes: [usize; W] =
            core::array::from_fn(|c| wrap(self.n, jh as i64 + c as i64) * self.strides[0]);
        let [_, su, sw] = self.strides;
        for l in 0..runs.lines() {
            if self.ahead > 0 {
                if let Some((first, last)) = runs.ends(self.n, su, sw, l + self.ahead) {
                    for &plane in &planes {
                        prefetch(self.data, plane + first);
                        prefetch(self.data, plane + last);
                    }
                }
            }
            let w = wrap(self.n, runs.w_min as i64 + l as i64);
            let cells = &mut s.cells[runs.off[l]..runs.off[l + 1]];
            self.reduce(&planes, wh, w, runs.lo[l], cells);
        }
        if self.inner_w {
            for q in points {
                let starts: [usize; W] = core::array::from_fn(|b| runs.start(q.ju, q.jw, b));
                let mut acc = T::ZERO;
                for t in 0..W {
                    let mut acc_w = T::ZERO;
                    for b in 0..W {
                        let cell = s.cells.get(starts[b] + t).copied();
                        acc_w += q.ww[b] * cell.unwrap_or(T::ZERO);
                    }
                    acc += q.wu[t] * acc_w;
                }
                s.values.push(acc);
            }
            return;
        }
        for q in points {
            let mut acc = T::ZERO;
            for b in 0..W {
                let start = runs.start(q.ju, q.jw, b);
                let mut acc_u = T::ZERO;
                if let Some(run) = s.cells.get(start..start + W) {
                    for t in 0..W {
                        acc_u += q.wu[t] * run[t];
                    }
                }
                acc += q.ww[b] * acc_u;
            }
            s.values.push(acc);
        }
    }

    /// `cells[i] = Σ_c wh_c·c[h = planes[c], u = lo + i, w]` (`planes`:
    /// the held taps' offsets), indices wrapping around the cube.
    #[inline(always)]
    fn reduce(&self, planes: &[usize; W], wh: &[T; W], w: usize, lo: i32, cells: &mut [T]) {
        let n = self.n;
        let [_, su, sw] = self.strides;
        let len = cells.len();
        let line = w * sw;
        let u0 = wrap(self.n, lo as i64);
        if su == 1 && u0 + len <= n {
            let start = line + u0;
            // Plane by plane, short runs too: on rows along y (runs of about
            // W + 1 cells) 15–25% less CPU than summing each cell's planes in
            // turn (`view_cpu`, side 320, kb5).
            for (c, &weight) in wh.iter().enumerate() {
                let Some(src) = self.data.get(planes[c] + start..planes[c] + start + len) else {
                    return;
                };
                if self.f16c {
                    // SAFETY: `f16c` is set only where F16C and AVX were
                    // detected on this core, the features `scale_add` enables.
                    #[cfg(target_arch = "x86_64")]
                    #[allow(unsafe_code)]
                    unsafe {
                        crate::slice::f16c::scale_add(weight, src, cells, c == 0)
                    };
                    #[cfg(target_arch = "x86_64")]
                    continue;
                }
                if c == 0 {
                    for (o, &v) in cells.iter_mut().zip(src) {
                        *o = weight * T::load_raw(v);
                    }
                } else {
                    for (o, &v) in cells.iter_mut().zip(src) {
                        *o += weight * T::load_raw(v);
                    }
                }
            }
            return;
        }
        for (i, o) in cells.iter_mut().enumerate() {
            let u = wrap(self.n, lo as i64 + i as i64);
            let mut acc = T::ZERO;
            for c in 0..W {
                let v = self.data.get(planes[c] + line + u * su).copied();
                acc += wh[c] * T::load_raw(v.unwrap_or_default());
            }
            *o = acc;
        }
    }
}
