//! Per-view rendering: slice extraction and the 2D inverse transform.
//!
//! By the projection-slice theorem (paper §1, fig. 1), the 2D Hartley
//! transform of the projection along `d` equals the 3D spectrum on the plane
//! through the origin spanned by `r` and `u`. The slice sample at 2D
//! frequency index `(kx, ky)` is the spectrum interpolated at the 3D index
//! `kx·r + ky·u` (paper §2: `F * H`, with the volume premultiplied by
//! `1/h`). Slice points outside the spectrum's Nyquist cube `|q_a| ≤ n/2` are
//! zero: the band-limited interpolant has no energy there.
//!
//! The image grid is `n × n` with a pitch of one voxel. A `W × H` image is
//! cut from it around the centre; sub-pixel offsets (odd volume sides, odd
//! image sides) are applied exactly as a phase ramp on the slice:
//! in Hartley form, shifting by `t` maps `H(k)` to
//! `cos φ·H(k) + sin φ·H(−k)` with `φ = −2π k·t/n`.
//!
//! In physical units ([`Sampling`]: voxel spacing `Δ`, pixel size `p`, in
//! mm) the slice is spanned by [`Sampling::slice_axes`] `r'_a = r_a·Δ_a/p`,
//! `u'_a = u_a·Δ_a/p` instead, and the image is multiplied by
//! `Δx·Δy·Δz/p²` ([`render_sampled`]). The extraction needs no change: the
//! Nyquist-cube test is per index axis, the taps wrap modulo `n` as before,
//! and `r'`, `u'` need not be orthonormal.

use crate::dht::{dht_2d, neg_mod, Twiddles};
use crate::error::{require_len, Error, Result};
use crate::filter::{KernelTable, PhaseTable, MAX_WIDTH};
use crate::format::BlockLayout;
use crate::geometry::{dot, Frame, Sampling, SliceAxes, View};
use crate::real::{Real, Sample};
use crate::spectrum::{CubeSide, Spectrum};

/// Where a `W × H` image sits on the `m × m` projection grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Grid column (signed, modulo `m`) of image column 0.
    pub col0: i64,
    /// Grid row coordinate (signed, up positive) of image row 0.
    pub row0: i64,
    /// Sub-pixel shift `(ta, tb)` in `[0, 1)`, along `r` and `u`.
    pub shift: [f64; 2],
}

/// The placement of a `width × height` image of a volume of `dims` seen in
/// `frame`: image pixel `(col, row)` is the projection at grid offset
/// `(col0 + col + ta, row0 − row + tb)` from the transform origin.
///
/// The transform origin is voxel `⌊n_a/2⌋`, the centre is `n_a/2`; their
/// difference `δ` (0 or ½ per axis) projects to `(δ·r, δ·u)` on the image.
pub fn placement(dims: [usize; 3], frame: &Frame, width: usize, height: usize) -> Placement {
    placement_at_pitch(dims, frame, width, height, 1.0)
}

/// [`placement`] for pixels `pitch` voxels apart (progressive previews):
/// pixel `(col, row)` sits at `c + (col − W/2)·pitch·r + (H/2 − row)·pitch·u`.
pub fn placement_at_pitch(
    dims: [usize; 3],
    frame: &Frame,
    width: usize,
    height: usize,
    pitch: f64,
) -> Placement {
    placement_on_axes(dims, &frame.slice_axes(), width, height, pitch)
}

/// [`placement_at_pitch`] for slice axes `axes` (index units per pixel):
/// with [`Sampling::slice_axes`], `δ·r' = Σ δ_a·Δ_a·r_a/p` is the physical
/// offset `δ∘Δ` of the transform origin from the centre, in pixels of `p`
/// mm, as the physical contract needs.
pub fn placement_on_axes(
    dims: [usize; 3],
    axes: &SliceAxes,
    width: usize,
    height: usize,
    pitch: f64,
) -> Placement {
    let delta = dims.map(|d| (d % 2) as f64 * 0.5);
    let a0 = -(width as f64) / 2.0 + dot(delta, axes.right) / pitch;
    let b0 = height as f64 / 2.0 + dot(delta, axes.up) / pitch;
    let (col0, row0) = (libm::floor(a0), libm::floor(b0));
    Placement {
        col0: col0 as i64,
        row0: row0 as i64,
        shift: [a0 - col0, b0 - row0],
    }
}

/// Scratch elements [`render`] needs: the `m × m` slice grid.
pub const fn grid_len(m: usize) -> usize {
    m * m
}

/// Auxiliary scratch elements [`render`] needs: `4m`.
pub const fn aux_len(m: usize) -> usize {
    4 * m
}

/// Render the X-ray projection of `spec` seen along `view` into `out`, a
/// `width × height` image, row 0 at the top, in voxel units of the input
/// volume (`∫ f dt`).
///
/// `grid` needs [`grid_len`]`(n)` and `aux` [`aux_len`]`(n)` elements, `out`
/// `width·height`, and `tw` must serve length `n` (the spectrum's side).
///
/// # Errors
/// Bad view vectors, an image side of 0 or above `n`, short buffers, or a
/// kernel for another filter than the spectrum was premultiplied for.
pub fn render<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    view: &View,
    width: usize,
    height: usize,
    tw: &Twiddles<'_, T>,
    grid: &mut [T],
    aux: &mut [T],
    out: &mut [T],
) -> Result<()> {
    render_sampled(
        spec,
        kernel,
        view,
        &Sampling::UNIT,
        width,
        height,
        tw,
        grid,
        aux,
        out,
    )
}

/// [`render`] in physical units: voxels `sampling.spacing()` mm apart,
/// pixels `sampling.pixel_size()` mm apart, values `∫ f dt` in mm × volume
/// units (the physical contract of [`crate::geometry`]).
/// [`Sampling::UNIT`] gives [`render`]'s image bit for bit.
///
/// # Errors
/// As [`render`].
pub fn render_sampled<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    view: &View,
    sampling: &Sampling,
    width: usize,
    height: usize,
    tw: &Twiddles<'_, T>,
    grid: &mut [T],
    aux: &mut [T],
    out: &mut [T],
) -> Result<()> {
    crate::progressive::render_level_sampled(
        spec, kernel, view, sampling, width, height, 0, tw, grid, aux, out,
    )
}

/// `Ok` if `1 ≤ width, height ≤ n`.
///
/// # Errors
/// [`Error::EmptyImage`] or [`Error::ImageTooLarge`].
pub fn check_image(width: usize, height: usize, n: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::EmptyImage);
    }
    if width > n || height > n {
        return Err(Error::ImageTooLarge {
            width,
            height,
            grid: n,
        });
    }
    Ok(())
}

/// Signed frequency of index `k` on an axis of length `m`.
#[inline(always)]
pub fn signed_index(k: usize, m: usize) -> i64 {
    if 2 * k < m {
        k as i64
    } else {
        k as i64 - m as i64
    }
}

/// Fill the `n × n` slice `grid` (`kx` fastest, natural DHT order) by
/// interpolating the spectrum with `kernel` on the plane spanned by the
/// frame's right and up vectors.
pub fn extract_slice<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    frame: &Frame,
    grid: &mut [T],
) {
    extract_central_slice(spec, kernel, frame, spec.n(), grid);
}

/// [`extract_slice`] restricted to the central `m × m` frequencies
/// (`m ≤ n`, a power of two): the slice of a preview at pitch `n/m`
/// ([`crate::progressive`]). `grid` holds `m²` values, `kx` fastest.
pub fn extract_central_slice<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    frame: &Frame,
    m: usize,
    grid: &mut [T],
) {
    extract_central_slice_on(spec, kernel, &frame.slice_axes(), m, grid);
}

/// [`extract_central_slice`] on the plane spanned by `axes` (the slice
/// sample at `(kx, ky)` is the spectrum at `kx·axes.right + ky·axes.up`,
/// zero outside the Nyquist cube): the physical-units slice with
/// [`Sampling::slice_axes`].
pub fn extract_central_slice_on<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    axes: &SliceAxes,
    m: usize,
    grid: &mut [T],
) {
    extract_rows(spec, kernel, axes, m, 0, &mut grid[..m * m]);
}

/// Rows `first_row ..` of the `n × n` slice on `axes` ([`Frame::slice_axes`]
/// in voxel units, [`Sampling::slice_axes`] in physical units), as many as
/// `rows` holds (`rows.len()` a multiple of `n`): the unit of work of a
/// caller that spreads the extraction over threads. Every value equals the
/// one [`extract_central_slice_on`] computes, bit for bit, whatever the
/// split.
///
/// # Errors
/// `rows.len()` not a multiple of `n`, or rows beyond the grid
/// ([`Error::LengthMismatch`]).
pub fn extract_slice_rows<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    axes: &SliceAxes,
    first_row: usize,
    rows: &mut [T],
) -> Result<()> {
    let n = spec.n();
    let count = rows.len() / n;
    if count * n != rows.len() || first_row + count > n {
        return Err(Error::LengthMismatch {
            what: "slice rows (a whole number of rows within the grid)",
            expected: (n - first_row.min(n)) * n,
            got: rows.len(),
        });
    }
    extract_rows(spec, kernel, axes, n, first_row, rows);
    Ok(())
}

/// Rows `first_row ..` (as many as `grid` holds) of the central `m × m`
/// slice, by filter width.
fn extract_rows<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    axes: &SliceAxes,
    m: usize,
    first_row: usize,
    grid: &mut [T],
) {
    match kernel.filter().width() {
        1 => extract_width::<1, S, Z, T>(spec, kernel, axes, m, first_row, grid),
        2 => extract_width::<2, S, Z, T>(spec, kernel, axes, m, first_row, grid),
        3 => extract_width::<3, S, Z, T>(spec, kernel, axes, m, first_row, grid),
        4 => extract_width::<4, S, Z, T>(spec, kernel, axes, m, first_row, grid),
        5 => extract_width::<5, S, Z, T>(spec, kernel, axes, m, first_row, grid),
        _ => extract_width::<MAX_WIDTH, S, Z, T>(spec, kernel, axes, m, first_row, grid),
    }
}

/// How x-lines are read in the extraction's inner loops.
#[derive(Clone, Copy)]
pub(crate) enum LineReads<'a> {
    /// Plain coefficients.
    Plain,
    /// One block exponent per x-line.
    LineExponents(&'a [i8]),
    /// Anything else (bricks): through [`Spectrum::line_taps`].
    General,
}

impl<'a> LineReads<'a> {
    /// The reads for `spec`.
    pub(crate) fn of<S: Sample, Z: CubeSide>(spec: &Spectrum<'a, S, Z>) -> Self {
        match spec.blocks() {
            Some(b) if S::BLOCK_MANTISSA => match b.layout() {
                BlockLayout::Line => LineReads::LineExponents(b.exponents()),
                _ => LineReads::General,
            },
            _ => LineReads::Plain,
        }
    }

    /// Whether a run of `W` taps from `x0` can be read contiguously.
    #[inline(always)]
    pub(crate) fn contiguous<const W: usize>(self, x0: usize, n: usize) -> bool {
        x0 + W <= n && !matches!(self, LineReads::General)
    }

    /// The `W` coefficients from `line + x0` as one run, when `contiguous`
    /// (one bounds check for the run).
    #[inline(always)]
    fn run<'s, const W: usize, S: Sample, Z: CubeSide>(
        spec: &Spectrum<'s, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
    ) -> Option<&'s [S; W]> {
        if !contiguous {
            return None;
        }
        let start = line + x0;
        // As in `extract_lines`: for W ≤ 4 the tail's first chunk (no
        // overflow test of `start + W`).
        if W <= 4 {
            spec.data()
                .get(start..)
                .and_then(|rest| rest.first_chunk::<W>())
        } else {
            spec.data()
                .get(start..start + W)
                .and_then(|s| <&[S; W]>::try_from(s).ok())
        }
    }

    /// The block exponent's power of two for `line`, if lines carry one.
    #[inline(always)]
    fn line_scale<S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
    ) -> Option<T> {
        match self {
            LineReads::LineExponents(e) => Some(T::exp2i(e[line / spec.n()] as i32)),
            _ => None,
        }
    }

    /// `Σ_t w[t]·c[line + xs[t]]` with block exponents applied: one
    /// contiguous run from `x0` when `contiguous`, else through
    /// [`Spectrum::line_taps`] at the wrapped indices `xs`.
    #[inline(always)]
    pub(crate) fn sum<const W: usize, S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        weights: &[T; W],
    ) -> T {
        let Some(run) = Self::run::<W, S, Z>(spec, line, x0, contiguous) else {
            return spec.line_taps(line, xs, weights);
        };
        let mut sum = T::ZERO;
        for (wt, v) in weights.iter().zip(run) {
            sum += *wt * T::load(*v);
        }
        match self.line_scale::<S, Z, T>(spec, line) {
            Some(scale) => sum * scale,
            None => sum,
        }
    }

    /// [`LineReads::sum`] with raw widening ([`Real::load_raw`]): the
    /// weights must carry the `2^e` of [`Real::raw_exponent`]. Plain and
    /// per-line-exponent reads only (never [`LineReads::General`], whose
    /// per-tap exponents this does not apply).
    #[inline(always)]
    pub(crate) fn sum_raw<const W: usize, S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        weights: &[T; W],
    ) -> T {
        let mut sum = T::ZERO;
        match Self::run::<W, S, Z>(spec, line, x0, contiguous) {
            Some(run) => {
                for t in 0..W {
                    sum += weights[t] * T::load_raw(run[t]);
                }
            }
            None => {
                let data = spec.data();
                for t in 0..W {
                    let v = data.get(line + xs[t]).copied().unwrap_or_default();
                    sum += weights[t] * T::load_raw(v);
                }
            }
        }
        match self.line_scale::<S, Z, T>(spec, line) {
            Some(scale) => sum * scale,
            None => sum,
        }
    }

    /// [`LineReads::sum2`] with raw widening, as [`LineReads::sum_raw`]
    /// (both weight sets carry the `2^e`).
    #[inline(always)]
    pub(crate) fn sum2_raw<const W: usize, S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        first: &[T; W],
        second: &[T; W],
    ) -> (T, T) {
        let (mut a, mut b) = (T::ZERO, T::ZERO);
        match Self::run::<W, S, Z>(spec, line, x0, contiguous) {
            Some(run) => {
                for t in 0..W {
                    let v = T::load_raw(run[t]);
                    a += first[t] * v;
                    b += second[t] * v;
                }
            }
            None => {
                let data = spec.data();
                for t in 0..W {
                    let v = T::load_raw(data.get(line + xs[t]).copied().unwrap_or_default());
                    a += first[t] * v;
                    b += second[t] * v;
                }
            }
        }
        match self.line_scale::<S, Z, T>(spec, line) {
            Some(scale) => (a * scale, b * scale),
            None => (a, b),
        }
    }

    /// Two weighted sums over the same taps, each coefficient read once
    /// (the value and a derivative of [`LineReads::sum`]).
    #[inline(always)]
    pub(crate) fn sum2<const W: usize, S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        first: &[T; W],
        second: &[T; W],
    ) -> (T, T) {
        let Some(run) = Self::run::<W, S, Z>(spec, line, x0, contiguous) else {
            return (
                spec.line_taps(line, xs, first),
                spec.line_taps(line, xs, second),
            );
        };
        let (mut a, mut b) = (T::ZERO, T::ZERO);
        for t in 0..W {
            let v = T::load(run[t]);
            a += first[t] * v;
            b += second[t] * v;
        }
        match self.line_scale::<S, Z, T>(spec, line) {
            Some(scale) => (a * scale, b * scale),
            None => (a, b),
        }
    }
}

/// [`extract_rows`] for filter width `W`: the phase-table path for plain
/// and per-line-exponent spectra, the general one for the rest. Not
/// inlined, so that only one width's phase table is on the stack.
#[inline(never)]
fn extract_width<const W: usize, S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    axes: &SliceAxes,
    m: usize,
    first_row: usize,
    grid: &mut [T],
) {
    let geometry = SliceRows {
        right: axes.right.map(T::from_f64),
        up: axes.up.map(T::from_f64),
        m,
        first_row,
    };
    let mut phases = PhaseTable::<T, W>::zeroed();
    match (phases.fill(kernel), LineReads::of(spec)) {
        (Ok(()), LineReads::Plain) => {
            extract_lines::<W, false, S, Z, T>(spec, &phases, &geometry, &[], grid)
        }
        (Ok(()), LineReads::LineExponents(e)) => {
            extract_lines::<W, true, S, Z, T>(spec, &phases, &geometry, e, grid)
        }
        _ => extract_general::<W, S, Z, T>(spec, kernel, &geometry, grid),
    }
}

/// Which rows of the slice to fill, and its axes in index units.
struct SliceRows<T> {
    right: [T; 3],
    up: [T; 3],
    m: usize,
    first_row: usize,
}

impl<T: Real> SliceRows<T> {
    /// Calls `pixel(slot, q)` for every slice point of the rows inside
    /// the spectrum's Nyquist cube, with `q = kx·r + ky·u` (`ky·u` once per
    /// row), and zeroes the points outside. The cube `|q_a| ≤ n/2` cuts each
    /// row to one interval of `kx`, found once per row
    /// ([`SliceRows::row_interval`]).
    #[inline(always)]
    fn for_each(&self, n: usize, grid: &mut [T], mut pixel: impl FnMut(&mut T, [T; 3])) {
        let m = self.m;
        for (row_offset, row) in grid.chunks_exact_mut(m).enumerate() {
            let ky = T::from_i32(signed_index(self.first_row + row_offset, m) as i32);
            let kyu = self.up.map(|c| ky * c);
            let (low, high) = self.row_interval(n, kyu);
            for (ix, g) in row.iter_mut().enumerate() {
                let k = signed_index(ix, m) as i32;
                if k < low || k > high {
                    *g = T::ZERO;
                    continue;
                }
                let kx = T::from_i32(k);
                pixel(g, core::array::from_fn(|a| kx * self.right[a] + kyu[a]));
            }
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
    /// Along a row, one point is placed from `q = kx·r + ky·u` in `T`;
    /// `q` then advances by `r`, so each next `y` is the last plus
    /// [`PhaseTable::fixed_step`]`(r)`: two integer additions an axis
    /// instead of a product, a sum and a floor in floating point.
    #[inline(always)]
    fn for_each_fixed_pair<const W: usize>(
        &self,
        n: usize,
        grid: &mut [T],
        mut pixel: impl FnMut([i64; 3], bool, bool) -> (T, T),
    ) {
        let m = self.m;
        grid.fill(T::ZERO);
        let rows = grid.len() / m;
        let step = self.right.map(PhaseTable::<T, W>::fixed_step);
        // Signed frequencies of a row: −⌊m/2⌋ … ⌈m/2⌉ − 1 (`signed_index`).
        let (half, k_max) = ((m / 2) as i32, ((m - 1) / 2) as i32);
        let mask = m.wrapping_sub(1);
        // Row `r` of the grid as a slot in this call's rows, if there.
        let local = |r: usize| r.checked_sub(self.first_row).filter(|&i| i < rows);
        for p in 0..=m / 2 {
            let plus_row = if p as i32 <= k_max { local(p) } else { None };
            let minus_row = local((m - p) & mask);
            if plus_row.is_none() && minus_row.is_none() {
                continue;
            }
            let ky = T::from_usize(p);
            let kyu = self.up.map(|c| ky * c);
            let (low, high) = self.row_interval(n, kyu);
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
            let kx = T::from_i32(anchor);
            let mut y: [i64; 3] = core::array::from_fn(|a| {
                PhaseTable::<T, W>::fixed_position(kx * self.right[a] + kyu[a])
                    + (low - anchor) as i64 * step[a]
            });
            for k in low..=high {
                // The point `(k, p)` is on the grid for `k ≤ k_max`, its
                // mirror `(−k, −p)` for `−k ≤ k_max` (and `−k ≥ −m/2`, the
                // loop's bound), on row 0 only for `k > 0` (`k = 0` is its
                // own mirror).
                let plus = plus_row.is_some() && k <= k_max;
                let minus = minus_row.is_some() && -k <= k_max && (p > 0 || k > 0);
                if plus || minus {
                    let (value, mirror) = pixel(y, plus, minus);
                    // `m` is a power of two: `k mod m` by a mask.
                    if let (true, Some(r)) = (plus, plus_row) {
                        if let Some(g) = grid.get_mut(r * m + (k as usize & mask)) {
                            *g = value;
                        }
                    }
                    if let (true, Some(r)) = (minus, minus_row) {
                        if let Some(g) = grid.get_mut(r * m + (k.wrapping_neg() as usize & mask)) {
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

    /// The integers `kx` in `[low, high]` for which `|kx·r_a + c_a| ≤ n/2` on
    /// every axis (`c = ky·u`): the intersection of three intervals, each
    /// `(±n/2 − c_a)/r_a`, rounded inwards. Points within rounding of the
    /// cube's faces may fall on either side; their interpolated value is
    /// next to nothing there (the band-limited spectrum ends at the faces).
    fn row_interval(&self, n: usize, c: [T; 3]) -> (i32, i32) {
        let half = T::from_usize(n) * T::HALF;
        let (mut low, mut high) = (-T::from_usize(n), T::from_usize(n));
        for a in 0..3 {
            let (r, c) = (self.right[a], c[a]);
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
}

/// The tap reads of [`extract_lines`]: a spectrum of side `n` stored as
/// `data` (exactly `n³` values), with one block exponent per x-line in
/// `exponents` when `LINE_EXP`.
struct TapSums<'a, const W: usize, const LINE_EXP: bool, S> {
    data: &'a [S],
    n: usize,
    exponents: &'a [i8],
}

impl<const W: usize, const LINE_EXP: bool, S: Sample> TapSums<'_, W, LINE_EXP, S> {
    /// An x-line's sum `acc_x` times the line's power of two, if lines
    /// carry one.
    #[inline(always)]
    fn line_sum<T: Real>(&self, line: usize, acc_x: T) -> T {
        if LINE_EXP {
            let e = self.exponents.get(line / self.n).copied().unwrap_or(0);
            acc_x * T::exp2i(e as i32)
        } else {
            acc_x
        }
    }

    /// The value at the taps `j + t` of each axis (`t < W`, wrapping
    /// around the cube) with weights `w[t]`; the x-weights carry the raw
    /// gain of [`Real::load_raw`].
    #[inline(always)]
    fn value<T: Real>(
        &self,
        jx: i32,
        wx: &[T; W],
        jy: i32,
        wy: &[T; W],
        jz: i32,
        wz: &[T; W],
    ) -> T {
        let (data, n) = (self.data, self.n);
        let (nn, mask) = (n * n, n - 1);
        // `((j + b) mod n)·n` as `(j·n + b·n) mod n²`, in wrapping usize:
        // the offsets of the taps' lines and planes with one product an axis.
        let (y0, z0) = (
            (jy as usize).wrapping_mul(n),
            (jz as usize).wrapping_mul(nn),
        );
        let lines: [usize; W] = core::array::from_fn(|b| y0.wrapping_add(b * n) & (nn - n));
        let planes: [usize; W] = core::array::from_fn(|c| z0.wrapping_add(c * nn) & (nn * n - nn));
        let x0 = jx as usize & mask;
        let mut acc = T::ZERO;
        if x0 + W <= n {
            for c in 0..W {
                let mut acc_y = T::ZERO;
                for b in 0..W {
                    let start = planes[c] + lines[b] + x0;
                    // The run of W taps from `start`. For W ≤ 4, as the tail
                    // from `start` and its first chunk: two length tests and
                    // no overflow test of `start + W` (plain kb3 −32 k, kb4
                    // −55 k instructions on the M4F); kb6's loop compiles
                    // worse that way (+690 k), so it keeps the range.
                    let run = if W <= 4 {
                        data.get(start..).and_then(|rest| rest.first_chunk::<W>())
                    } else {
                        data.get(start..start + W)
                            .and_then(|s| <&[S; W]>::try_from(s).ok())
                    };
                    let acc_x = match run {
                        Some(run) => {
                            let mut sum = T::ZERO;
                            for t in 0..W {
                                sum += wx[t] * T::load_raw(run[t]);
                            }
                            sum
                        }
                        None => T::ZERO,
                    };
                    acc_y += wy[b] * self.line_sum(start, acc_x);
                }
                acc += wz[c] * acc_y;
            }
        } else {
            let xs: [usize; W] = core::array::from_fn(|t| (jx + t as i32) as usize & mask);
            for c in 0..W {
                let mut acc_y = T::ZERO;
                for b in 0..W {
                    let line = planes[c] + lines[b];
                    let mut acc_x = T::ZERO;
                    for t in 0..W {
                        let v = data.get(line + xs[t]).copied().unwrap_or_default();
                        acc_x += wx[t] * T::load_raw(v);
                    }
                    acc_y += wy[b] * self.line_sum(line, acc_x);
                }
                acc += wz[c] * acc_y;
            }
        }
        acc
    }
}

/// The extraction's hot loop: per slice point, three phase-table lookups
/// for the weights, then `W²` x-lines of `W` taps, each line one
/// contiguous run with one bounds check unless its taps wrap around the
/// cube. The `W` x-weights carry the `2^e` of [`Real::load_raw`], so a tap
/// costs a load, its raw widening, a multiplication and an addition; the
/// products are the same numbers as with the full widening (a power of two
/// moved between factors is exact). `LINE_EXP`: multiply each line's sum
/// by its block exponent's power of two (`exponents`, one per x-line).
fn extract_lines<const W: usize, const LINE_EXP: bool, S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    phases: &PhaseTable<T, W>,
    geometry: &SliceRows<T>,
    exponents: &[i8],
    grid: &mut [T],
) {
    let n = spec.n();
    let nn = n * n;
    // Exactly `n³` (as `Spectrum` guarantees): with a compile-time side
    // ([`CubeSide`]) the compiler then proves every masked tap index in
    // range and drops the bounds tests.
    let Some(data) = spec.data().get(..nn * n) else {
        grid.fill(T::ZERO);
        return;
    };
    let raw_gain = T::exp2i(T::raw_exponent::<S>());
    let taps = TapSums::<W, LINE_EXP, S> { data, n, exponents };
    // The mirror `−q` of a point: taps `−j − t`, i.e. the run from
    // `−j − (W − 1)` with the weights reversed.
    let mirror = |j: i32| -j - (W as i32 - 1);
    let reversed = |w: &[T; W]| -> [T; W] { core::array::from_fn(|t| w[W - 1 - t]) };
    geometry.for_each_fixed_pair::<W>(n, grid, |y, plus, minus| {
        let (jx, wx) = phases.taps_fixed_point(y[0]);
        let (jy, wy) = phases.taps_fixed_point(y[1]);
        let (jz, wz) = phases.taps_fixed_point(y[2]);
        let wx = wx.map(|w| w * raw_gain);
        let value = if plus {
            taps.value(jx, &wx, jy, &wy, jz, &wz)
        } else {
            T::ZERO
        };
        let mirrored = if minus {
            let (rx, ry, rz) = (reversed(&wx), reversed(&wy), reversed(&wz));
            taps.value(mirror(jx), &rx, mirror(jy), &ry, mirror(jz), &rz)
        } else {
            T::ZERO
        };
        (value, mirrored)
    });
}

/// The extraction for any storage (e.g. bricked block exponents): taps
/// through [`LineReads::sum`], weights from the kernel table.
fn extract_general<const W: usize, S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    geometry: &SliceRows<T>,
    grid: &mut [T],
) {
    let n = spec.n();
    let nn = n * n;
    let reads = LineReads::of(spec);
    let mask = n - 1;
    geometry.for_each(n, grid, |g, q| {
        let (mut wx, mut wy, mut wz) = ([T::ZERO; W], [T::ZERO; W], [T::ZERO; W]);
        let jx = kernel.taps_fixed(q[0], &mut wx);
        let jy = kernel.taps_fixed(q[1], &mut wy);
        let jz = kernel.taps_fixed(q[2], &mut wz);
        let x0 = jx as usize & mask;
        let contiguous = reads.contiguous::<W>(x0, n);
        let xs: [usize; W] = core::array::from_fn(|t| (jx + t as i64) as usize & mask);
        let mut acc = T::ZERO;
        for (c, wzc) in wz.iter().enumerate() {
            let z = ((jz + c as i64) as usize & mask) * nn;
            let mut acc_y = T::ZERO;
            for (b, wyb) in wy.iter().enumerate() {
                let line = z + ((jy + b as i64) as usize & mask) * n;
                let acc_x = reads.sum(spec, line, x0, contiguous, &xs, &wx);
                acc_y += *wyb * acc_x;
            }
            acc += *wzc * acc_y;
        }
        *g = acc;
    });
}

/// Turn a filled `m × m` slice into the image: sub-pixel shift, 2D inverse
/// DHT, then cut the `width × height` image at `place`, multiplied by `gain`
/// (the reciprocal of the spectrum's scale).
///
/// `aux` needs [`aux_len`]`(m)` elements.
///
/// # Errors
/// As [`render`].
pub fn finish_projection<T: Real>(
    grid: &mut [T],
    m: usize,
    place: &Placement,
    gain: f64,
    width: usize,
    height: usize,
    tw: &Twiddles<'_, T>,
    aux: &mut [T],
    out: &mut [T],
) -> Result<()> {
    finish_channel(grid, m, place, gain, width, height, tw, aux, out, 1, 0)
}

/// [`finish_projection`] into channel `channel` of an interleaved image of
/// `channels` channels (channel fastest: `out[(row·width + col)·channels +
/// channel]`).
///
/// # Errors
/// As [`render`], and `channel ≥ channels`.
pub fn finish_channel<T: Real>(
    grid: &mut [T],
    m: usize,
    place: &Placement,
    gain: f64,
    width: usize,
    height: usize,
    tw: &Twiddles<'_, T>,
    aux: &mut [T],
    out: &mut [T],
    channels: usize,
    channel: usize,
) -> Result<()> {
    check_image(width, height, m)?;
    if channel >= channels {
        return Err(Error::LengthMismatch {
            what: "channel index",
            expected: channels,
            got: channel,
        });
    }
    require_len("slice grid", grid_len(m), grid.len())?;
    require_len("auxiliary scratch", aux_len(m), aux.len())?;
    require_len("output image", width * height * channels, out.len())?;
    apply_shift(grid, m, place.shift, aux);
    dht_2d(grid, m, m, &mut aux[..m], tw)?;
    let g = T::from_f64(gain / (m * m) as f64);
    // Grid indices modulo m (a power of two), in wrapping usize arithmetic:
    // the same residues as the signed i64 ones, without 64-bit adds on a
    // 32-bit core, and the row is sliced once.
    let mask = m - 1;
    let (row0, col0) = (place.row0 as usize, place.col0 as usize);
    for (row, line) in out
        .chunks_exact_mut(width * channels)
        .take(height)
        .enumerate()
    {
        let gy = row0.wrapping_sub(row) & mask;
        let grid_row = &grid[gy * m..(gy + 1) * m];
        if channels == 1 {
            // One channel (plain and cued frames): a plain loop over the
            // row, without the per-pixel chunking of interleaved ones.
            for (col, o) in line.iter_mut().enumerate() {
                *o = grid_row[col0.wrapping_add(col) & mask] * g;
            }
        } else {
            for (col, o) in line.chunks_exact_mut(channels).enumerate() {
                o[channel] = grid_row[col0.wrapping_add(col) & mask] * g;
            }
        }
    }
    Ok(())
}

/// Shift the projection by `t = (ta, tb)` pixels (`R(x) = Q(x + t)`) on its
/// Hartley slice: `H'(k) = cos φ·H(k) + sin φ·H(−k)`, `φ = −2π k·t/m`.
/// Nyquist components get no phase (a real signal cannot hold a shifted
/// Nyquist cosine), which keeps `φ(−k) = −φ(k)` for every pair.
fn apply_shift<T: Real>(grid: &mut [T], m: usize, t: [f64; 2], aux: &mut [T]) {
    if t == [0.0, 0.0] {
        return;
    }
    let (cx, rest) = aux.split_at_mut(m);
    let (sx, rest) = rest.split_at_mut(m);
    let (cy, sy) = rest.split_at_mut(m);
    let tau = -2.0 * core::f64::consts::PI / m as f64;
    for k in 0..m {
        let nyq = 2 * k == m;
        let ks = signed_index(k, m) as f64;
        let (phx, phy) = if nyq {
            (0.0, 0.0)
        } else {
            (tau * ks * t[0], tau * ks * t[1])
        };
        cx[k] = T::from_f64(libm::cos(phx));
        sx[k] = T::from_f64(libm::sin(phx));
        cy[k] = T::from_f64(libm::cos(phy));
        sy[k] = T::from_f64(libm::sin(phy));
    }
    for iy in 0..m {
        let my = neg_mod(iy, m);
        for ix in 0..m {
            let (a, b) = (iy * m + ix, my * m + neg_mod(ix, m));
            if a >= b {
                continue;
            }
            let c = cx[ix] * cy[iy] - sx[ix] * sy[iy];
            let s = sx[ix] * cy[iy] + cx[ix] * sy[iy];
            let (h, hm) = (grid[a], grid[b]);
            grid[a] = c * h + s * hm;
            grid[b] = c * hm - s * h;
        }
    }
}
