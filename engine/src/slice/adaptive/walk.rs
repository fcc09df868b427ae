//! The host's adaptive slice extraction (paper §4): the core's
//! `fvr_core::slice::adaptive::extract_slice_adaptive`, point for point
//! the same arithmetic in the same order, so the slice and the statistics
//! are the same bit for bit, but walked as the plain host extraction
//! ([`crate::slice::exact`]) walks:
//!
//! - **Bands of mirror pairs on rayon threads.** Rows `p` and `−p` cut the
//!   Nyquist cube to intervals of the same length, so a band of consecutive
//!   pairs is a balanced unit of work, and the bands go to the threads by
//!   work stealing.
//! - **Row intervals.** Each row is walked only over its interval of `kx`
//!   inside the cube (the plain path's, one column wider on each side),
//!   and every point in it is tested as the core tests it, so the points
//!   within rounding of the faces fall on the core's side.
//! - **Tiles** of columns across the band's rows, as in the plain path.
//! - **Tap loops per filter width**, unrolled, the wide ones with every
//!   plane summed side by side (the plain path's [`crate::slice::exact`]
//!   loop).
//!
//! What stays the core's: each point's position `q = kx·r + ky·u` in `T`,
//! the spectrum sample nearest to it looked up in the marks, and the
//! weights from the kernel table ([`KernelTable::taps_fixed`]). The plain
//! path's fixed-point stepping and phase tables would move the nearest
//! sample at half-integers (so a point could change filter) and the weights
//! in their last bits, for little: where the marks hold, a point reads a
//! handful of taps, and its cost is the position, the lookup and one
//! sample; the wide filter's weights are looked up only where the marks do
//! not hold.

use fvr_core::filter::{KernelTable, MAX_WIDTH};
use fvr_core::geometry::Frame;
use fvr_core::num::{Real, Sample};
use fvr_core::slice::adaptive::{AdaptiveLevel, AdaptiveStats, Marks, MAX_LEVELS};
use fvr_core::spectrum::Spectrum;
use rayon::prelude::*;

use crate::slice::adaptive::spans::PartialSpans;
use crate::slice::adaptive::summary::MarksSummary;
use crate::slice::exact::{supports, tap_sum, SliceJob, Tiling};
use crate::slice::strip;
use fvr_core::slice::row_interval;

/// One filter of the chain as the walk applies it.
#[derive(Clone, Copy)]
struct Applied<'k, T> {
    table: &'k KernelTable<T>,
    width: usize,
    /// Taps a point reads, `W³`.
    taps: u64,
    /// The level's DC gain (one for the large filter, as in the core).
    gain: T,
}

/// `table` with `gain`, if its width is one the walk unrolls. Gain 0 is
/// the zero filter, which reads no taps.
fn applied<T: Real>(table: &KernelTable<T>, gain: T) -> Option<Applied<'_, T>> {
    let width = table.filter().width();
    let taps = match gain == T::ZERO {
        true => 0,
        false => (width * width * width) as u64,
    };
    (width <= MAX_WIDTH).then_some(Applied {
        table,
        width,
        taps,
        gain,
    })
}

/// Everything a band reads.
struct Walk<'a, S, T> {
    data: &'a [S],
    n: usize,
    right: [T; 3],
    /// `filters[0]` the large filter, then the levels in order.
    filters: [Option<Applied<'a, T>>; 1 + MAX_LEVELS],
    marks: [Option<Marks<'a>>; MAX_LEVELS],
    /// The bricks the first level's marks hold whole.
    whole: Option<&'a MarksSummary>,
    /// When the first level is the zero filter, the parts of each row
    /// that may reach the bricks its marks do not hold whole: the rest of
    /// the row is counted without settling its points.
    spans: Option<PartialSpans>,
    raw_gain: T,
    chunk: i32,
    /// Points on the large filter are left at zero for the strip walk
    /// ([`extract_with_strip`]), their columns noted in [`Row::strong`].
    defer: bool,
}

/// One row of the slice: its points, `ky·u` for its signed frequency `ky`,
/// and the interval of `kx` walked.
struct Row<'g, T> {
    cells: &'g mut [T],
    /// The row's index in the grid.
    index: usize,
    kyu: [T; 3],
    low: i32,
    high: i32,
    /// The least and greatest `kx` of the points left to the strip walk
    /// ([`Walk::defer`]); [`EMPTY`] when there are none.
    strong: (i32, i32),
}

/// One slice for the adaptive walk to fill: the spectrum, the table of
/// its filter (the large one), the cheaper filters' levels, the summary of
/// the first level's marks (`whole`: it settles the points in its whole
/// bricks without reading the marks), the view's frame, the tiling, and
/// whether to run on the current rayon pool's threads (`parallel`) or on
/// this thread.
#[derive(Clone, Copy)]
pub struct AdaptiveJob<'a, S, T> {
    /// The stored spectrum.
    pub spec: &'a Spectrum<'a, S>,
    /// The table of the spectrum's filter.
    pub kernel: &'a KernelTable<T>,
    /// The cheaper filters and their marks.
    pub levels: &'a [AdaptiveLevel<'a, 'a, T>],
    /// The summary of the first level's marks, if any.
    pub whole: Option<&'a MarksSummary>,
    /// The view's frame.
    pub frame: &'a Frame,
    /// How the walk splits and tiles the slice.
    pub tiling: Tiling,
    /// On the current rayon pool's threads, else on this thread.
    pub parallel: bool,
}

impl<'a, S, T> AdaptiveJob<'a, S, T> {
    /// The job of filling the slice of `spec` on `frame` with `kernel` and
    /// `levels`.
    pub const fn new(
        spec: &'a Spectrum<'a, S>,
        kernel: &'a KernelTable<T>,
        levels: &'a [AdaptiveLevel<'a, 'a, T>],
        whole: Option<&'a MarksSummary>,
        frame: &'a Frame,
        tiling: Tiling,
        parallel: bool,
    ) -> Self {
        Self {
            spec,
            kernel,
            levels,
            whole,
            frame,
            tiling,
            parallel,
        }
    }
}

/// Fill the `n × n` slice `grid` (`kx` fastest, natural DHT order) as
/// `extract_slice_adaptive(spec, kernel, levels, frame, grid)` would, bit
/// for bit, with the same statistics. `None` (grid untouched) when
/// [`supports`] does not hold for the spectrum or its side is not a power
/// of two, the grid is not `n²`, the kernel is not the spectrum's filter,
/// or the levels are more than [`MAX_LEVELS`] or have marks of another
/// side: the core's function reports those.
pub fn extract<S: Sample, T: Real>(
    job: &AdaptiveJob<'_, S, T>,
    grid: &mut [T],
) -> Option<AdaptiveStats> {
    let n = job.spec.n();
    if grid.len() != n * n {
        return None;
    }
    let walk = Walk::new(job)?;
    let up = job.frame.up.map(T::from_f64);
    let mut bands = walk.bands(grid, up, job.tiling.band.max(1));
    Some(walk.fill_bands(&mut bands, job.parallel))
}

/// [`extract`] with the points on the large filter summed by the plain
/// strip walk ([`strip::extract_within`], its row intervals, phase
/// tables and fixed-point stepping) over the intervals of each row that
/// hold them, into `strong` (`n²` values of scratch), where the slice's
/// rows hold a coordinate ([`strip::held_axis`]); elsewhere as
/// [`extract`]. The statistics and every point on a cheaper filter are
/// [`extract`]'s bit for bit; each point on the large filter is the plain
/// strip walk's value there, bit for bit, which is the core's to within
/// the strip's rounding bound (`host-sim/tests/fast_adaptive.rs`).
pub fn extract_with_strip<S: Sample, T: Real + Send + Sync>(
    job: &AdaptiveJob<'_, S, T>,
    grid: &mut [T],
    strong: &mut [T],
) -> Option<AdaptiveStats> {
    let walked = extract_with_strip_if(job, grid, strong, |_| true);
    walked.map(|walked| match walked {
        Settled::Extracted(stats) | Settled::Declined(stats) => stats,
    })
}

/// What [`extract_with_strip_if`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Settled {
    /// The slice is extracted, with these statistics.
    Extracted(AdaptiveStats),
    /// The walk's statistics (exactly [`extract`]'s) did not satisfy the
    /// condition, and the grid holds no finished slice.
    Declined(AdaptiveStats),
}

/// Points in a view's spans ([`PartialSpans::points`]) from which
/// [`extract_with_strip_if`] settles them on the pool. On the 2 shared
/// cores these were set on, a kb6 view at 40 dB on a 256³ volume (below
/// both thresholds) was extracted in 0.24 ms on the calling thread against
/// 0.30–0.37 ms with both passes on the pool, the wakes costing more than
/// they saved; a view whose every point is settled (a spectrum with no
/// zero level, or marks that hold little) keeps both cores.
pub const SETTLE_ON_POOL_FROM: usize = 16_384;

/// Taps of the large filter's points from which [`extract_with_strip_if`]
/// sums them on the pool (the view above has about 270,000; a full kb6
/// view at 256, 14 million).
pub const SUM_ON_POOL_FROM: u64 = 1 << 20;

/// [`extract_with_strip`] once `proceed` accepts the walk's statistics,
/// which are known when every point's filter is settled and before the
/// strip walk sums the large filter's points: a caller that would rather
/// render the view another way decides without a separate count
/// ([`tally`]). Where the strip walk does not serve, the statistics come
/// from [`tally`] and the slice, if accepted, from [`extract`].
pub fn extract_with_strip_if<S: Sample, T: Real + Send + Sync>(
    job: &AdaptiveJob<'_, S, T>,
    grid: &mut [T],
    strong: &mut [T],
    proceed: impl FnOnce(&AdaptiveStats) -> bool,
) -> Option<Settled> {
    let AdaptiveJob {
        spec,
        kernel,
        frame,
        tiling,
        parallel,
        ..
    } = *job;
    let n = spec.n();
    let axes = frame.slice_axes();
    if grid.len() != n * n || strong.len() != n * n || strip::held_axis(&axes).is_none() {
        let stats = tally(job)?;
        if !proceed(&stats) {
            return Some(Settled::Declined(stats));
        }
        return extract(job, grid).map(Settled::Extracted);
    }
    let mut walk = Walk::new(job)?;
    walk.defer = true;
    let up = frame.up.map(T::from_f64);
    let mut bands = walk.bands(grid, up, tiling.band.max(1));
    // Each pass on the pool only when it holds enough work to repay waking
    // it (the values are the same either way).
    let settle = walk
        .spans
        .as_ref()
        .is_none_or(|s| s.points() >= SETTLE_ON_POOL_FROM);
    let stats = walk.fill_bands(&mut bands, parallel && settle);
    if !proceed(&stats) {
        return Some(Settled::Declined(stats));
    }
    let large = walk.filters[0].map_or(0, |f| f.taps);
    let sum = stats.per_filter[0].saturating_mul(large) >= SUM_ON_POOL_FROM;
    // Pair `p` walks row `p` at `kx = k` and row `−p` at `kx = −k`.
    let mut within = vec![EMPTY; n / 2 + 1];
    for row in bands.iter().flatten() {
        let (low, high) = row.strong;
        if low > high {
            continue;
        }
        let ky = signed(row.index, n);
        let (p, from, to) = match ky >= 0 {
            true => (ky as usize, low, high),
            false => (ky.unsigned_abs() as usize, -high, -low),
        };
        within[p] = widened(within[p], from, to);
    }
    // Row 0 holds its own mirrors: `kx < 0` are pair 0's `k > 0`.
    if let Some(w) = within.first_mut().filter(|w| w.0 <= w.1) {
        *w = (w.0.min(-w.1), w.1.max(-w.0));
    }
    let strip_job = SliceJob::new(spec, kernel, &axes, tiling, parallel && sum);
    if !strip::extract_within(&strip_job, strong, &within) {
        drop(bands);
        return extract(job, grid).map(Settled::Extracted);
    }
    // On this thread: the strong points are few (about 1,400 on a kb6
    // view at 40 dB on a 256³ volume), and waking the pool for them cost
    // more than copying them.
    for row in bands.iter_mut().flatten() {
        let at = row.index * n;
        walk.copy_strong(row, &strong[at..at + n]);
    }
    Some(Settled::Extracted(stats))
}

/// The statistics [`extract`] would return for the same job, without
/// interpolating: each point's position, its test against the cube and its
/// nearest sample's marks, as the walk computes them, so the counts are
/// the walk's exactly (whatever the job's tiling). `None` where [`extract`]
/// would return `None`.
pub fn tally<S: Sample, T: Real>(job: &AdaptiveJob<'_, S, T>) -> Option<AdaptiveStats> {
    let n = job.spec.n();
    let walk = Walk::new(&AdaptiveJob {
        tiling: Tiling::default(),
        ..*job
    })?;
    let up = job.frame.up.map(T::from_f64);
    let count = |p: usize| {
        let mut stats = AdaptiveStats::default();
        let ky = signed(p, n);
        let mut row = walk.row(&mut [], p, up, ky);
        let (low, high) = (row.low, row.high);
        walk.fill_row(&mut row, low, high, &mut stats);
        stats
    };
    Some(match job.parallel {
        true => (0..n)
            .into_par_iter()
            .map(count)
            .reduce(AdaptiveStats::default, merged),
        false => (0..n).map(count).fold(AdaptiveStats::default(), merged),
    })
}

/// The signed frequency of grid row `p` as the walk numbers it: `p` for
/// `p ≤ (n − 1)/2`, else `p − n`.
fn signed(p: usize, n: usize) -> i32 {
    match p as i32 <= ((n - 1) / 2) as i32 {
        true => p as i32,
        false => p as i32 - n as i32,
    }
}

/// `ky·u` for the row of signed frequency `ky` and its interval of `kx`
/// walked: one column beyond the plain path's interval on each side, so
/// the points within rounding of the faces are tested point by point, as
/// the core tests them.
fn walked<T: Real>(n: usize, right: &[T; 3], up: [T; 3], ky: i32) -> ([T; 3], i32, i32) {
    let (half, k_max) = ((n / 2) as i32, ((n - 1) / 2) as i32);
    let k = T::from_i32(ky);
    let kyu = up.map(|c| k * c);
    let (low, high) = row_interval(n, right, kyu);
    (
        kyu,
        low.saturating_sub(1).max(-half),
        high.saturating_add(1).min(k_max),
    )
}

/// An interval of `kx` holding nothing (`low > high`).
const EMPTY: (i32, i32) = (i32::MAX, i32::MIN);

/// The least interval holding `span` and `from … to`.
fn widened(span: (i32, i32), from: i32, to: i32) -> (i32, i32) {
    (span.0.min(from), span.1.max(to))
}

/// The sums of two statistics.
fn merged(a: AdaptiveStats, b: AdaptiveStats) -> AdaptiveStats {
    AdaptiveStats {
        samples: a.samples + b.samples,
        per_filter: core::array::from_fn(|i| a.per_filter[i] + b.per_filter[i]),
        taps: a.taps + b.taps,
        full_taps: a.full_taps + b.full_taps,
    }
}

impl<'a, S: Sample, T: Real> Walk<'a, S, T> {
    /// The walk of the job's levels over its spectrum on its frame, or
    /// `None` where [`extract`] declines.
    fn new(job: &AdaptiveJob<'a, S, T>) -> Option<Self> {
        let (spec, kernel, levels, whole) = (job.spec, job.kernel, job.levels, job.whole);
        let n = spec.n();
        // Its walk wraps by masks: power-of-two sides only.
        if !supports(spec)
            || !n.is_power_of_two()
            || kernel.filter() != spec.filter()
            || levels.len() > MAX_LEVELS
            || levels.iter().any(|l| l.marks.n() != n)
        {
            return None;
        }
        let mut filters = [None; 1 + MAX_LEVELS];
        let mut marks = [None; MAX_LEVELS];
        filters[0] = Some(applied(kernel, T::ONE)?);
        for (i, level) in levels.iter().enumerate() {
            filters[i + 1] = Some(applied(level.kernel, level.gain)?);
            marks[i] = Some(level.marks);
        }
        Some(Self {
            data: spec.data(),
            n,
            right: job.frame.right.map(T::from_f64),
            filters,
            marks,
            whole: whole.filter(|_| !levels.is_empty()),
            spans: whole
                .filter(|_| levels.first().is_some_and(|l| l.gain == T::ZERO))
                .and_then(|summary| {
                    let rounded = |v: [f64; 3]| v.map(|c| T::from_f64(c).to_f64());
                    let frame = job.frame;
                    PartialSpans::new(summary, n, rounded(frame.right), rounded(frame.up))
                }),
            raw_gain: T::exp2i(T::raw_exponent::<S>()),
            chunk: job.tiling.chunk.clamp(1, n) as i32,
            defer: false,
        })
    }

    /// The rows of `grid` in bands of `band` mirror pairs (`p` and `−p`,
    /// `p = 0 … n/2`).
    fn bands<'g>(&self, grid: &'g mut [T], up: [T; 3], band: usize) -> Vec<Vec<Row<'g, T>>> {
        let n = self.n;
        let mask = n - 1;
        let k_max = ((n - 1) / 2) as i32;
        let mut rows: Vec<Option<&'g mut [T]>> = grid.chunks_exact_mut(n).map(Some).collect();
        let mut row = |index: usize, ky: i32| Some(self.row(rows[index].take()?, index, up, ky));
        let mut bands = Vec::new();
        for first in (0..=n / 2).step_by(band) {
            let mut rows = Vec::with_capacity(2 * band);
            for p in first..(first + band).min(n / 2 + 1) {
                if p as i32 <= k_max {
                    rows.extend(row(p, p as i32));
                }
                if p > 0 {
                    rows.extend(row((n - p) & mask, -(p as i32)));
                }
            }
            bands.push(rows);
        }
        bands
    }

    /// The row of signed frequency `ky` over `cells`, row `index` of the
    /// grid.
    fn row<'g>(&self, cells: &'g mut [T], index: usize, up: [T; 3], ky: i32) -> Row<'g, T> {
        let (kyu, low, high) = walked(self.n, &self.right, up, ky);
        Row {
            cells,
            index,
            kyu,
            low,
            high,
            strong: EMPTY,
        }
    }

    /// Every band filled ([`Walk::fill_band`]), on the current rayon pool's
    /// threads when `parallel`; the sum of their statistics.
    fn fill_bands(&self, bands: &mut [Vec<Row<'_, T>>], parallel: bool) -> AdaptiveStats {
        let fill = |band: &mut Vec<Row<'_, T>>| self.fill_band(band);
        match parallel {
            true => bands
                .par_iter_mut()
                .map(fill)
                .reduce(AdaptiveStats::default, merged),
            false => bands
                .iter_mut()
                .map(fill)
                .fold(AdaptiveStats::default(), merged),
        }
    }

    /// Zero one band's rows, then fill their points inside the cube tile by
    /// tile; its statistics.
    fn fill_band(&self, band: &mut [Row<'_, T>]) -> AdaptiveStats {
        let mut stats = AdaptiveStats::default();
        let (mut first, mut last) = (i32::MAX, i32::MIN);
        for row in band.iter_mut() {
            row.cells.fill(T::ZERO);
            if row.low <= row.high {
                first = first.min(row.low);
                last = last.max(row.high);
            }
        }
        let mut start = first;
        while start <= last {
            let end = start.saturating_add(self.chunk - 1).min(last);
            for row in band.iter_mut() {
                self.fill_row(row, start.max(row.low), end.min(row.high), &mut stats);
            }
            start = end.saturating_add(1);
        }
        stats
    }

    /// Points `kx = from … to` of `row`, each as the core computes it. With
    /// a zero first level, only the points in the row's spans (those that
    /// may reach a brick not held whole) are settled one by one; the others
    /// are only counted (cells already zero, no taps).
    #[inline(always)]
    fn fill_row(&self, row: &mut Row<'_, T>, from: i32, to: i32, stats: &mut AdaptiveStats) {
        let spans = match &self.spans {
            Some(spans) => spans.row(row.index),
            None => return self.fill_points(row, from, to, stats),
        };
        let mut k = from;
        for &(low, high) in spans {
            if high < k {
                continue;
            }
            if low > to {
                break;
            }
            self.count_zero(row.kyu, k, low - 1, stats);
            let end = high.min(to);
            self.fill_points(row, low.max(k), end, stats);
            k = end + 1;
        }
        self.count_zero(row.kyu, k, to, stats);
    }

    /// The position `q = kx·right + kyu` of point `kx = k`, in `T` as the
    /// core computes it.
    #[inline(always)]
    fn position(&self, k: i32, kyu: [T; 3]) -> [T; 3] {
        let kx = T::from_i32(k);
        core::array::from_fn(|a| kx * self.right[a] + kyu[a])
    }

    /// Count points `kx = from … to` of the row at `kyu` inside the cube
    /// (the core's test) as the first level's, the zero filter. Each
    /// coordinate is monotonic in `kx` (rounding is), so when both ends
    /// are inside, every point between is.
    #[inline(always)]
    fn count_zero(&self, kyu: [T; 3], from: i32, to: i32, stats: &mut AdaptiveStats) {
        let large = match self.filters[0] {
            Some(f) if from <= to => f,
            _ => return,
        };
        let nyquist = T::from_usize(self.n) * T::HALF;
        let inside = |k: i32| {
            let q = self.position(k, kyu);
            !q.iter().any(|&c| c > nyquist || -c > nyquist)
        };
        let count = match inside(from) && inside(to) {
            true => (to - from) as u64 + 1,
            false => (from..=to).map(|k| u64::from(inside(k))).sum(),
        };
        stats.samples += count;
        stats.full_taps += large.taps * count;
        stats.per_filter[1] += count;
    }

    /// The chain's slot of the point at `q` (0 the large filter, `i + 1`
    /// level `i`): the first level whose marks hold its nearest sample, as
    /// the core finds it; `None` outside the cube of half-side `nyquist`.
    #[inline(always)]
    fn slot(&self, q: [T; 3], nyquist: T) -> Option<usize> {
        if q.iter().any(|&c| c > nyquist || -c > nyquist) {
            return None;
        }
        let (n, mask) = (self.n, self.n - 1);
        let nearest: [usize; 3] =
            core::array::from_fn(|a| (q[a] + T::HALF).floor_i64() as usize & mask);
        let index = nearest[0] + n * (nearest[1] + n * nearest[2]);
        Some(match self.whole.is_some_and(|w| w.holds(nearest)) {
            true => 1,
            false => self
                .marks
                .iter()
                .position(|m| m.is_some_and(|m| m.get(index)))
                .map_or(0, |i| i + 1),
        })
    }

    /// The large filter's points of `row`, left by [`Walk::fill_points`]
    /// when deferring, from `strong`, the strip walk's row of the grid.
    fn copy_strong(&self, row: &mut Row<'_, T>, strong: &[T]) {
        let nyquist = T::from_usize(self.n) * T::HALF;
        let mask = self.n - 1;
        for k in row.strong.0..=row.strong.1 {
            let q = self.position(k, row.kyu);
            if self.slot(q, nyquist) == Some(0) {
                let col = k as usize & mask;
                if let (Some(cell), Some(&v)) = (row.cells.get_mut(col), strong.get(col)) {
                    *cell = v;
                }
            }
        }
    }

    /// [`Walk::fill_row`] point by point.
    #[inline(always)]
    fn fill_points(&self, row: &mut Row<'_, T>, from: i32, to: i32, stats: &mut AdaptiveStats) {
        let n = self.n;
        let mask = n - 1;
        let nyquist = T::from_usize(n) * T::HALF;
        let large = match self.filters[0] {
            Some(f) => f,
            None => return,
        };
        for k in from..=to {
            let q = self.position(k, row.kyu);
            let Some(slot) = self.slot(q, nyquist) else {
                continue;
            };
            stats.samples += 1;
            stats.full_taps += large.taps;
            let filter = self.filters[slot].unwrap_or(large);
            stats.per_filter[slot] += 1;
            stats.taps += filter.taps;
            if slot == 0 && self.defer {
                row.strong = widened(row.strong, k, k);
                continue;
            }
            if let Some(cell) = row.cells.get_mut(k as usize & mask) {
                *cell = match filter.taps {
                    0 => T::ZERO,
                    _ => filter.gain * self.value(&filter, q),
                };
            }
        }
    }

    /// The interpolation of the spectrum at `q` with `filter`, unrolled for
    /// its width.
    #[inline(always)]
    fn value(&self, filter: &Applied<'_, T>, q: [T; 3]) -> T {
        for_width!(filter.width, W => self.interpolate::<W>(filter.table, q))
    }

    /// The core's separable interpolation for width `W` (the table's):
    /// weights `k(q_a − j0 − m)` from the kernel table, summed x-lines
    /// first.
    #[inline(always)]
    fn interpolate<const W: usize>(&self, table: &KernelTable<T>, q: [T; 3]) -> T {
        let mut weights = [[T::ZERO; W]; 3];
        let mut first = [0i32; 3];
        for a in 0..3 {
            first[a] = table.taps_fixed::<W>(q[a], &mut weights[a]) as i32;
        }
        let [wx, wy, wz] = weights;
        let wx = wx.map(|w| w * self.raw_gain);
        tap_sum::<W, S, T>(self.data, self.n, first, [&wx, &wy, &wz])
    }
}
