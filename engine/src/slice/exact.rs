//! The host's slice extraction for plain spectra, of power-of-two and of
//! even mixed-radix side: the core's phase-table extraction
//! (`fvr_core::slice`), point for point the same arithmetic in the same
//! order, so the slice is the same bit for bit, but walked for the host's
//! caches and cores. [`extract_reordered`] is the same walk with each
//! point's sum reordered into lanes: the core's values to within rounding.
//!
//! - **Mirror pairs stay together.** Row `p` and row `−p` share every
//!   point's setup (taps reflected through the origin, same weights), so
//!   the unit of work is a *band* of consecutive pairs `p = p0 … p0 + B − 1`
//!   with both of their rows, and the bands go to the threads by work
//!   stealing (rayon): rows near `ky = 0` have the longest intervals inside
//!   the Nyquist cube, and stealing evens that out, as well as a core taken
//!   by another process.
//! - **Tiles.** Inside a band the points are visited in chunks of `C`
//!   columns, every pair of the band per chunk, instead of whole rows, so
//!   that the lines a chunk's taps share between neighbouring rows are read
//!   while they are still close. On the 2-core AMD EPYC machine of
//!   docs/performance.md this measured within the run-to-run spread of
//!   whole rows (`cargo bench -p fvr-host --bench view_cpu`); the tiling is
//!   a tunable ([`Tiling`]).
//! - **Wide filters** (kb6) sum every plane of a point side by side.
//! - **Prefetch.** Each point asks for the runs of the point
//!   [`Tiling::ahead`] columns on ([`crate::slice::prefetch`]): on a plane
//!   along no axis a point's runs lie plane and line strides apart, which
//!   the hardware prefetchers do not follow. A hint, so the values are the
//!   same bits.
//!
//! A point's fixed-point position is the row's anchor plus `(k − anchor)`
//! steps, exactly the integer the core's running sum reaches, so the visit
//! order changes nothing in the values.
//!
//! Indices wrap around the cube as the core wraps them: by masks on a
//! power-of-two side, else by one remainder per axis and a conditional
//! subtraction per tap ([`Side`]); the sums are the same either way.

use fvr_core::filter::{KernelTable, PhaseTable};
use fvr_core::geometry::SliceAxes;
use fvr_core::num::{Real, Sample};
use fvr_core::spectrum::Spectrum;
use rayon::prelude::*;

use crate::slice::prefetch::prefetch;
pub(crate) use crate::slice::taps::tap_sum;
use crate::slice::taps::{run_starts, tap_sum_on, Side};
use crate::spectrum::bricks::Bricked;

/// How the host extraction walks the slice: `band` mirror pairs per unit
/// of work, `chunk` columns per tile, and how far ahead the strip and
/// column walks prefetch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tiling {
    /// Mirror pairs (rows `p` and `−p`) per unit of work (≥ 1).
    pub band: usize,
    /// Columns per tile inside a band (≥ 1).
    pub chunk: usize,
    /// Lines of cells the strip and column walks prefetch ahead of the one
    /// they reduce, and columns the exact walk prefetches ahead of the
    /// point it sums (0: none; [`crate::slice::prefetch`]).
    pub ahead: usize,
}

impl Tiling {
    /// `band` pairs by `chunk` columns, prefetching `ahead` lines.
    pub const fn new(band: usize, chunk: usize, ahead: usize) -> Self {
        Self { band, chunk, ahead }
    }
}

impl Default for Tiling {
    /// 8 pairs by 32 columns (`cargo bench -p fvr-host --bench view`),
    /// prefetching 8 lines ahead (`cargo bench -p fvr-host --bench
    /// view_cpu`, side 512).
    fn default() -> Self {
        Self::new(8, 32, 8)
    }
}

impl core::str::FromStr for Tiling {
    type Err = String;

    /// `band,chunk` or `band,chunk,ahead` (the benches' `FVR_BENCH_TILING`);
    /// `ahead` defaults to [`Tiling::default`]'s.
    fn from_str(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        let number = |i: usize| -> Result<usize, String> {
            parts[i]
                .parse()
                .map_err(|_| format!("tiling {s:?}: {:?} is not a whole number", parts[i]))
        };
        match parts.len() {
            2 | 3 => Ok(Self {
                band: number(0)?,
                chunk: number(1)?,
                ahead: if parts.len() == 3 {
                    number(2)?
                } else {
                    Self::default().ahead
                },
            }),
            _ => Err(format!("tiling {s:?}: give band,chunk or band,chunk,ahead")),
        }
    }
}

/// Whether [`extract`] serves `spec`: plain coefficients (no block
/// exponents), exactly `n³` of them, and a power-of-two or an even side
/// (the sides spectra take; the walk pairs rows as the core does on both).
pub fn supports<S: Sample>(spec: &Spectrum<'_, S>) -> bool {
    let n = spec.n();
    (n.is_power_of_two() || n % 2 == 0) && spec.blocks().is_none() && spec.data().len() == n * n * n
}

/// One slice for a walk to fill: the spectrum `spec` (a [`Spectrum`], or
/// a [`Bricked`] copy for [`extract_bricked`]), the table of its filter,
/// the plane spanned by `axes.right` and `axes.up`, the tiling, and
/// whether to run on the current rayon pool's threads (`parallel`) or on
/// this thread. Every walk of this module, [`crate::slice::strip`] and
/// [`crate::slice::column`] takes one and checks it the same way
/// ([`SliceJob::geometry`]).
#[derive(Clone, Copy)]
pub struct SliceJob<'a, Spec, T> {
    /// The stored spectrum.
    pub spec: &'a Spec,
    /// The table of the spectrum's filter.
    pub kernel: &'a KernelTable<T>,
    /// The slice's plane.
    pub axes: &'a SliceAxes,
    /// How the walk splits and tiles the slice.
    pub tiling: Tiling,
    /// On the current rayon pool's threads, else on this thread.
    pub parallel: bool,
}

impl<'a, Spec, T> SliceJob<'a, Spec, T> {
    /// The job of filling the slice of `spec` on `axes` with `kernel`.
    pub const fn new(
        spec: &'a Spec,
        kernel: &'a KernelTable<T>,
        axes: &'a SliceAxes,
        tiling: Tiling,
        parallel: bool,
    ) -> Self {
        Self {
            spec,
            kernel,
            axes,
            tiling,
            parallel,
        }
    }
}

impl<S: Sample, T: Real> SliceJob<'_, Spectrum<'_, S>, T> {
    /// The walk's geometry: `None` (the walk declines, grid untouched)
    /// when [`supports`] does not hold, `grid` is not `n²` or the kernel
    /// is not the spectrum's filter.
    #[inline]
    pub(crate) fn geometry(&self, grid: &[T]) -> Option<Geometry<T>> {
        let n = self.spec.n();
        (supports(self.spec) && grid.len() == n * n && self.kernel.filter() == self.spec.filter())
            .then(|| Geometry::new(self.axes, n, self.tiling, self.parallel))
    }
}

/// Fill the `n × n` slice `grid` (`kx` fastest, natural DHT order) of
/// `job`, as `fvr_core::slice::extract_slice_rows` over all rows would,
/// bit for bit. `false` (grid untouched) when [`SliceJob::geometry`]
/// declines.
pub fn extract<S: Sample, T: Real + Send + Sync>(
    job: &SliceJob<'_, Spectrum<'_, S>, T>,
    grid: &mut [T],
) -> bool {
    extract_summed(job, grid, false)
}

/// Whether [`extract_reordered`] serves spectra of `S` summed in `T` on
/// this core: binary16 in `f32` on an x86-64 core with F16C, AVX and FMA.
pub fn reorders<S: Sample, T: Real>() -> bool {
    #[cfg(target_arch = "x86_64")]
    return crate::slice::f16c::fused_available::<S, T>();
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// [`extract`] with each point's taps summed in lanes by fused
/// multiply-adds (`crate::slice::f16c::fused_sum`): the core's slice to
/// within `(5W + 5)·u·Σ|w·c|` at every point (`u = ε/2`), in about half
/// the time of the core's order on views whose rows hold no axis. `false`
/// (grid untouched) where [`reorders`] does not hold or [`extract`]
/// declines.
pub fn extract_reordered<S: Sample, T: Real + Send + Sync>(
    job: &SliceJob<'_, Spectrum<'_, S>, T>,
    grid: &mut [T],
) -> bool {
    reorders::<S, T>() && extract_summed(job, grid, true)
}

/// [`extract`], the sums reordered when `reorder` ([`extract_reordered`]).
fn extract_summed<S: Sample, T: Real + Send + Sync>(
    job: &SliceJob<'_, Spectrum<'_, S>, T>,
    grid: &mut [T],
    reorder: bool,
) -> bool {
    let Some(geometry) = job.geometry(grid) else {
        return false;
    };
    let (data, n, kernel) = (job.spec.data(), job.spec.n(), job.kernel);
    if n.is_power_of_two() {
        let source = Linear::<S, true>::new::<T>(data, n, reorder);
        by_width::<true, S, T, _>(&source, kernel, &geometry, grid)
    } else {
        let source = Linear::<S, false>::new::<T>(data, n, reorder);
        by_width::<false, S, T, _>(&source, kernel, &geometry, grid)
    }
}

/// [`extract`] from a bricked copy of the spectrum: the same slice, bit
/// for bit. `false` (grid untouched) when the grid is not `n²` or the
/// kernel is not the spectrum's filter.
pub fn extract_bricked<S: Sample + Sync, T: Real + Send + Sync>(
    job: &SliceJob<'_, Bricked<S>, T>,
    grid: &mut [T],
) -> bool {
    let SliceJob { spec, kernel, .. } = *job;
    let n = spec.n();
    if grid.len() != n * n || *kernel.filter() != spec.filter() {
        return false;
    }
    let geometry = Geometry::new(job.axes, n, job.tiling, job.parallel);
    // The bricked sums need no wrapping; `POW2` only picks how grid rows
    // are indexed.
    if n.is_power_of_two() {
        by_width::<true, S, T, _>(spec, kernel, &geometry, grid)
    } else {
        by_width::<false, S, T, _>(spec, kernel, &geometry, grid)
    }
}

/// Where a walk reads a point's tap sum from.
trait TapSource<S>: Sync {
    /// `Σ_c wz_c Σ_b wy_b Σ_t wx_t·c[z + c, y + b, x + t]` in the core's
    /// order ([`tap_sum_on`]).
    fn sum<const W: usize, T: Real>(&self, taps: [i32; 3], weights: [&[T; W]; 3]) -> T;

    /// Ask the caches for the runs [`TapSource::sum`] will read at `taps`
    /// (a hint: nothing is read into the program).
    #[inline(always)]
    fn prefetch<const W: usize>(&self, _taps: [i32; 3]) {}
}

/// The linear layout (x fastest, then y, then z).
struct Linear<'a, S, const POW2: bool> {
    data: &'a [S],
    side: Side<POW2>,
    /// Whether [`crate::slice::f16c::tap_sum`] serves the sums (binary16
    /// in `f32` on a core with F16C).
    f16c: bool,
    /// Whether [`crate::slice::f16c::fused_sum`] serves them instead
    /// ([`extract_reordered`]; set only where [`reorders`] holds).
    fused: bool,
}

impl<'a, S: Sample, const POW2: bool> Linear<'a, S, POW2> {
    fn new<T: Real>(data: &'a [S], n: usize, reorder: bool) -> Self {
        Self {
            data,
            side: Side { n },
            f16c: crate::slice::f16c_available::<S, T>(),
            fused: reorder && reorders::<S, T>(),
        }
    }
}

impl<S: Sample + Sync, const POW2: bool> TapSource<S> for Linear<'_, S, POW2> {
    #[inline(always)]
    fn sum<const W: usize, T: Real>(&self, taps: [i32; 3], weights: [&[T; W]; 3]) -> T {
        if self.fused {
            // SAFETY: `fused` is set only where `f16c::fused_available`
            // detected F16C, AVX and FMA on this core, the features
            // `fused_sum` enables.
            #[cfg(target_arch = "x86_64")]
            #[allow(unsafe_code)]
            return unsafe { crate::slice::f16c::fused_sum(self.data, self.side, taps, weights) };
        }
        if self.f16c {
            // SAFETY: `f16c` is set only where `f16c::available` detected
            // F16C and AVX on this core, the features `tap_sum` enables.
            #[cfg(target_arch = "x86_64")]
            #[allow(unsafe_code)]
            return unsafe { crate::slice::f16c::tap_sum(self.data, self.side, taps, weights) };
        }
        tap_sum_on(self.data, self.side, taps, weights)
    }

    #[inline(always)]
    fn prefetch<const W: usize>(&self, taps: [i32; 3]) {
        let (lines, planes, x0) = run_starts::<W, POW2>(self.side, taps);
        for plane in planes {
            for line in lines {
                prefetch(self.data, plane + line + x0);
            }
        }
    }
}

impl<S: Sample + Sync> TapSource<S> for Bricked<S> {
    #[inline(always)]
    fn sum<const W: usize, T: Real>(&self, taps: [i32; 3], weights: [&[T; W]; 3]) -> T {
        self.tap_sum(taps, weights)
    }
}

/// [`walk`] for the kernel's width.
fn by_width<const POW2: bool, S: Sample, T: Real + Send + Sync, Src: TapSource<S>>(
    source: &Src,
    kernel: &KernelTable<T>,
    geometry: &Geometry<T>,
    grid: &mut [T],
) -> bool {
    for_width!(kernel.filter().width(), W => {
        walk::<W, POW2, S, T, Src>(source, kernel, geometry, grid)
    })
}

/// The slice's axes in `T`, the cube side and the walk.
pub(crate) struct Geometry<T> {
    pub(crate) right: [T; 3],
    pub(crate) up: [T; 3],
    pub(crate) n: usize,
    pub(crate) tiling: Tiling,
    pub(crate) parallel: bool,
}

impl<T: Real> Geometry<T> {
    pub(crate) fn new(axes: &SliceAxes, n: usize, tiling: Tiling, parallel: bool) -> Self {
        Self {
            right: axes.right.map(T::from_f64),
            up: axes.up.map(T::from_f64),
            n,
            tiling: Tiling {
                band: tiling.band.max(1),
                chunk: tiling.chunk.max(1),
                ahead: tiling.ahead,
            },
            parallel,
        }
    }
}

/// One mirror pair of a band: row `p` (`plus`, absent for `p = n/2`) and
/// row `−p` (`minus`; row 0 is its own mirror and holds both halves), the
/// pair's interval of `kx` inside the Nyquist cube and its anchor's
/// fixed-point position.
pub(crate) struct Pair<'g, T> {
    pub(crate) p: usize,
    pub(crate) plus: Option<&'g mut [T]>,
    pub(crate) minus: Option<&'g mut [T]>,
    pub(crate) low: i32,
    pub(crate) high: i32,
    pub(crate) anchor: i32,
    pub(crate) base: [i64; 3],
}

/// The walk for filter width `W`: rows split into bands of pairs, each
/// band set up, then filled tile by tile.
#[inline(never)]
fn walk<const W: usize, const POW2: bool, S: Sample, T: Real + Send + Sync, Src: TapSource<S>>(
    source: &Src,
    kernel: &KernelTable<T>,
    g: &Geometry<T>,
    grid: &mut [T],
) -> bool {
    let Some(phases) = phase_table::<W, T>(kernel) else {
        return false;
    };
    let n = g.n;
    let side = Side::<POW2> { n };
    let mut bands = bands_of_pairs(grid, n, g.tiling.band);
    let taps = Taps::<W, POW2, S, T, Src> {
        source,
        _sample: core::marker::PhantomData,
        side,
        phases: &phases,
        raw_gain: T::exp2i(T::raw_exponent::<S>()),
        step: g.right.map(PhaseTable::<T, W>::fixed_step),
        ahead: g.tiling.ahead,
    };
    let fill = |band: &mut Vec<Pair<'_, T>>| fill_band(&taps, g, band);
    if g.parallel {
        bands.par_iter_mut().for_each(fill);
    } else {
        bands.iter_mut().for_each(fill);
    }
    true
}

/// The phase table of `kernel` for width `W`, on the heap (it is large);
/// `None` where it cannot be filled (a kernel wider than `W`), and the
/// walk declines.
pub(crate) fn phase_table<const W: usize, T: Real>(
    kernel: &KernelTable<T>,
) -> Option<Box<PhaseTable<T, W>>> {
    let mut phases = Box::new(PhaseTable::<T, W>::zeroed());
    phases.fill(kernel).ok()?;
    Some(phases)
}

/// The grid's rows as mirror pairs (`p`, `−p`) for `p = 0 … n/2`, in
/// bands of `band` consecutive pairs.
pub(crate) fn bands_of_pairs<T>(grid: &mut [T], n: usize, band: usize) -> Vec<Vec<Pair<'_, T>>> {
    let side = Side::<false> { n };
    let mut rows: Vec<Option<&mut [T]>> = grid.chunks_exact_mut(n).map(Some).collect();
    // Signed frequencies of a row: −n/2 … n/2 − 1; row `p` holds `ky = p`
    // for `p ≤ k_max`, row `(n − p) mod n` holds `ky = −p`.
    let k_max = (n - 1) / 2;
    let pairs: Vec<Pair<'_, T>> = (0..=n / 2)
        .map(|p| {
            let plus = if p <= k_max { rows[p].take() } else { None };
            let minus = if p == 0 {
                None
            } else {
                rows[side.signed(-(p as i32))].take()
            };
            Pair {
                p,
                plus,
                minus,
                low: 1,
                high: 0,
                anchor: 0,
                base: [0; 3],
            }
        })
        .collect();
    let mut bands: Vec<Vec<Pair<'_, T>>> = Vec::new();
    let mut pairs = pairs.into_iter().peekable();
    while pairs.peek().is_some() {
        bands.push(pairs.by_ref().take(band.max(1)).collect());
    }
    bands
}

/// Row `p`'s interval of `kx` inside the Nyquist cube (`kx ≥ 0` on row 0,
/// whose mirrors hold the rest), its anchor and the anchor's fixed-point
/// position, as the core sets its rows up; `None` when the interval is
/// empty.
pub(crate) fn row_setup<const W: usize, T: Real>(
    g: &Geometry<T>,
    p: usize,
) -> Option<(i32, i32, i32, [i64; 3])> {
    let half = (g.n / 2) as i32;
    let ky = T::from_usize(p);
    let kyu = g.up.map(|c| ky * c);
    let (low, high) = fvr_core::slice::row_interval(g.n, &g.right, kyu);
    let k_low = if p == 0 { 0 } else { -half };
    let (low, high) = (low.max(k_low), high.min(half));
    if low > high {
        return None;
    }
    let anchor = 0.clamp(low, high);
    let kx = T::from_i32(anchor);
    let base =
        core::array::from_fn(|a| PhaseTable::<T, W>::fixed_position(kx * g.right[a] + kyu[a]));
    Some((low, high, anchor, base))
}

/// Zero the pair's rows and set its interval inside the Nyquist cube,
/// anchor and anchor position ([`row_setup`]); `false` when the interval
/// is empty.
pub(crate) fn set_up_pair<const W: usize, T: Real>(
    g: &Geometry<T>,
    pair: &mut Pair<'_, T>,
) -> bool {
    for row in [&mut pair.plus, &mut pair.minus].into_iter().flatten() {
        row.fill(T::ZERO);
    }
    let Some((low, high, anchor, base)) = row_setup::<W, T>(g, pair.p) else {
        return false;
    };
    (pair.low, pair.high, pair.anchor, pair.base) = (low, high, anchor, base);
    true
}

/// Set up and fill one band of pairs.
fn fill_band<const W: usize, const POW2: bool, S: Sample, T: Real, Src: TapSource<S>>(
    taps: &Taps<'_, W, POW2, S, T, Src>,
    g: &Geometry<T>,
    band: &mut [Pair<'_, T>],
) {
    let n = g.n;
    let (mut first, mut last) = (i32::MAX, i32::MIN);
    for pair in band.iter_mut() {
        if set_up_pair::<W, T>(g, pair) {
            first = first.min(pair.low);
            last = last.max(pair.high);
        }
    }
    let chunk = g.tiling.chunk.min(n) as i32;
    let mut start = first;
    while start <= last {
        let end = start.saturating_add(chunk - 1).min(last);
        for pair in band.iter_mut() {
            fill_pair(taps, pair, start.max(pair.low), end.min(pair.high), n);
        }
        start = end.saturating_add(1);
    }
}

/// Points `k = from … to` of one pair, with their mirrors.
#[inline(always)]
fn fill_pair<const W: usize, const POW2: bool, S: Sample, T: Real, Src: TapSource<S>>(
    taps: &Taps<'_, W, POW2, S, T, Src>,
    pair: &mut Pair<'_, T>,
    from: i32,
    to: i32,
    n: usize,
) {
    let k_max = ((n - 1) / 2) as i32;
    let side = taps.side;
    let p = pair.p;
    let has_plus = pair.plus.is_some();
    // Row 0's mirrors land in row 0 itself.
    let has_minus = pair.minus.is_some() || p == 0;
    for k in from..=to {
        let plus = has_plus && k <= k_max;
        let minus = has_minus && -k <= k_max && (p > 0 || k > 0);
        if !(plus || minus) {
            continue;
        }
        let steps = (k - pair.anchor) as i64;
        let y: [i64; 3] = core::array::from_fn(|a| pair.base[a] + steps * taps.step[a]);
        if taps.ahead > 0 {
            // The point `ahead` columns on: on a plane that runs along no
            // axis, its runs lie a plane or a line stride from this one's,
            // where the hardware prefetchers do not look.
            let ahead = taps.ahead as i64;
            let y: [i64; 3] = core::array::from_fn(|a| y[a] + ahead * taps.step[a]);
            taps.prefetch(y, plus, minus);
        }
        let (value, mirror) = taps.point(y, plus, minus);
        if plus {
            if let Some(g) = pair
                .plus
                .as_deref_mut()
                .and_then(|r| r.get_mut(side.signed(k)))
            {
                *g = value;
            }
        }
        if minus {
            let row = match pair.minus.as_deref_mut() {
                Some(r) => Some(r),
                None => pair.plus.as_deref_mut(),
            };
            if let Some(g) = row.and_then(|r| r.get_mut(side.signed(k.wrapping_neg()))) {
                *g = mirror;
            }
        }
    }
}

/// The tap sums of one point and its mirror from the phase table.
struct Taps<'a, const W: usize, const POW2: bool, S, T, Src> {
    source: &'a Src,
    _sample: core::marker::PhantomData<S>,
    side: Side<POW2>,
    phases: &'a PhaseTable<T, W>,
    raw_gain: T,
    step: [i64; 3],
    /// Columns ahead whose runs are prefetched ([`Tiling::ahead`]).
    ahead: usize,
}

impl<const W: usize, const POW2: bool, S: Sample, T: Real, Src: TapSource<S>>
    Taps<'_, W, POW2, S, T, Src>
{
    /// The value at fixed-point position `y` (when `plus`) and at its
    /// mirror `−q` (when `minus`): taps `−j − t`, the run from
    /// `−j − (W − 1)` with the weights reversed.
    #[inline(always)]
    fn point(&self, y: [i64; 3], plus: bool, minus: bool) -> (T, T) {
        let (jx, wx) = self.phases.taps_fixed_point(y[0]);
        let (jy, wy) = self.phases.taps_fixed_point(y[1]);
        let (jz, wz) = self.phases.taps_fixed_point(y[2]);
        let wx = wx.map(|w| w * self.raw_gain);
        let value = if plus {
            self.value(jx, &wx, jy, &wy, jz, &wz)
        } else {
            T::ZERO
        };
        let mirrored = if minus {
            let mirror = |j: i32| -j - (W as i32 - 1);
            let reversed = |w: &[T; W]| -> [T; W] { core::array::from_fn(|t| w[W - 1 - t]) };
            let (rx, ry, rz) = (reversed(&wx), reversed(&wy), reversed(&wz));
            self.value(mirror(jx), &rx, mirror(jy), &ry, mirror(jz), &rz)
        } else {
            T::ZERO
        };
        (value, mirrored)
    }

    /// Prefetch the runs of the point at fixed-point position `y` (when
    /// `plus`) and of its mirror (when `minus`), as [`Taps::point`] will
    /// read them.
    #[inline(always)]
    fn prefetch(&self, y: [i64; 3], plus: bool, minus: bool) {
        let j = y.map(|c| self.phases.taps_fixed_point(c).0);
        if plus {
            self.source.prefetch::<W>(j);
        }
        if minus {
            self.source.prefetch::<W>(j.map(|j| -j - (W as i32 - 1)));
        }
    }

    /// [`tap_sum`] on this spectrum.
    #[inline(always)]
    fn value(&self, jx: i32, wx: &[T; W], jy: i32, wy: &[T; W], jz: i32, wz: &[T; W]) -> T {
        self.source.sum([jx, jy, jz], [wx, wy, wz])
    }
}
