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
use crate::filter::{KernelTable, MAX_WIDTH};
use crate::format::BlockLayout;
use crate::geometry::{dot, Frame, Sampling, SliceAxes, View};
use crate::real::{Real, Sample};
use crate::spectrum::Spectrum;

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
pub fn render<S: Sample, T: Real>(
    spec: &Spectrum<'_, S>,
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
pub fn render_sampled<S: Sample, T: Real>(
    spec: &Spectrum<'_, S>,
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
    let axes = sampling.slice_axes(&view.frame()?);
    let n = spec.n();
    check_image(width, height, n)?;
    if kernel.filter() != spec.filter() {
        return Err(Error::FilterMismatch);
    }
    require_len("slice grid", grid_len(n), grid.len())?;
    require_len("auxiliary scratch", aux_len(n), aux.len())?;
    require_len("output image", width * height, out.len())?;
    if n > tw.len() {
        return Err(Error::TwiddlesTooShort {
            table_len: tw.len(),
            needed: n,
        });
    }
    extract_central_slice_on(spec, kernel, &axes, n, &mut grid[..n * n]);
    let place = placement_on_axes(spec.dims(), &axes, width, height, 1.0);
    finish_projection(
        &mut grid[..n * n],
        n,
        &place,
        sampling.gain() / spec.scale(),
        width,
        height,
        tw,
        aux,
        out,
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
pub fn extract_slice<S: Sample, T: Real>(
    spec: &Spectrum<'_, S>,
    kernel: &KernelTable<T>,
    frame: &Frame,
    grid: &mut [T],
) {
    extract_central_slice(spec, kernel, frame, spec.n(), grid);
}

/// [`extract_slice`] restricted to the central `m × m` frequencies
/// (`m ≤ n`, a power of two): the slice of a preview at pitch `n/m`
/// ([`crate::progressive`]). `grid` holds `m²` values, `kx` fastest.
pub fn extract_central_slice<S: Sample, T: Real>(
    spec: &Spectrum<'_, S>,
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
pub fn extract_central_slice_on<S: Sample, T: Real>(
    spec: &Spectrum<'_, S>,
    kernel: &KernelTable<T>,
    axes: &SliceAxes,
    m: usize,
    grid: &mut [T],
) {
    let grid = &mut grid[..m * m];
    match kernel.filter().width() {
        1 => extract_width::<1, S, T>(spec, kernel, axes, m, grid),
        2 => extract_width::<2, S, T>(spec, kernel, axes, m, grid),
        3 => extract_width::<3, S, T>(spec, kernel, axes, m, grid),
        4 => extract_width::<4, S, T>(spec, kernel, axes, m, grid),
        5 => extract_width::<5, S, T>(spec, kernel, axes, m, grid),
        _ => extract_width::<MAX_WIDTH, S, T>(spec, kernel, axes, m, grid),
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
    pub(crate) fn of<S: Sample>(spec: &Spectrum<'a, S>) -> Self {
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
    fn run<'s, const W: usize, S: Sample>(
        spec: &Spectrum<'s, S>,
        line: usize,
        x0: usize,
        contiguous: bool,
    ) -> Option<&'s [S; W]> {
        if !contiguous {
            return None;
        }
        spec.data()
            .get(line + x0..line + x0 + W)
            .and_then(|s| <&[S; W]>::try_from(s).ok())
    }

    /// The block exponent's power of two for `line`, if lines carry one.
    #[inline(always)]
    fn line_scale<S: Sample, T: Real>(self, spec: &Spectrum<'_, S>, line: usize) -> Option<T> {
        match self {
            LineReads::LineExponents(e) => Some(T::exp2i(e[line / spec.n()] as i32)),
            _ => None,
        }
    }

    /// `Σ_t w[t]·c[line + xs[t]]` with block exponents applied: one
    /// contiguous run from `x0` when `contiguous`, else through
    /// [`Spectrum::line_taps`] at the wrapped indices `xs`.
    #[inline(always)]
    pub(crate) fn sum<const W: usize, S: Sample, T: Real>(
        self,
        spec: &Spectrum<'_, S>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        weights: &[T; W],
    ) -> T {
        let Some(run) = Self::run::<W, S>(spec, line, x0, contiguous) else {
            return spec.line_taps(line, xs, weights);
        };
        let mut sum = T::ZERO;
        for (wt, v) in weights.iter().zip(run) {
            sum += *wt * T::load(*v);
        }
        match self.line_scale::<S, T>(spec, line) {
            Some(scale) => sum * scale,
            None => sum,
        }
    }

    /// Two weighted sums over the same taps, each coefficient read once
    /// (the value and a derivative of [`LineReads::sum`]).
    #[inline(always)]
    pub(crate) fn sum2<const W: usize, S: Sample, T: Real>(
        self,
        spec: &Spectrum<'_, S>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        first: &[T; W],
        second: &[T; W],
    ) -> (T, T) {
        let Some(run) = Self::run::<W, S>(spec, line, x0, contiguous) else {
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
        match self.line_scale::<S, T>(spec, line) {
            Some(scale) => (a * scale, b * scale),
            None => (a, b),
        }
    }
}

/// [`extract_slice`] for filter width `W`. The inner loop reads the `W`
/// x-taps of a line as one contiguous run when they do not wrap around the
/// cube (all but the outermost slice samples), with the loops unrolled;
/// sums are taken in the same order as the general path, so results are
/// bit-identical to it.
fn extract_width<const W: usize, S: Sample, T: Real>(
    spec: &Spectrum<'_, S>,
    kernel: &KernelTable<T>,
    axes: &SliceAxes,
    m: usize,
    grid: &mut [T],
) {
    let n = spec.n();
    let nn = n * n;
    let reads = LineReads::of(spec);
    let r = axes.right.map(T::from_f64);
    let u = axes.up.map(T::from_f64);
    let nyquist = T::from_usize(n) * T::HALF;
    let mask = n - 1;
    for (iy, row) in grid.chunks_exact_mut(m).enumerate() {
        let ky = T::from_i32(signed_index(iy, m) as i32);
        for (ix, g) in row.iter_mut().enumerate() {
            let kx = T::from_i32(signed_index(ix, m) as i32);
            let q: [T; 3] = core::array::from_fn(|a| kx * r[a] + ky * u[a]);
            if q.iter().any(|&c| c > nyquist || -c > nyquist) {
                *g = T::ZERO;
                continue;
            }
            let (mut wx, mut wy, mut wz) = ([T::ZERO; W], [T::ZERO; W], [T::ZERO; W]);
            let jx = kernel.taps_fixed(q[0], &mut wx);
            let jy = kernel.taps_fixed(q[1], &mut wy);
            let jz = kernel.taps_fixed(q[2], &mut wz);
            let x0 = jx as usize & mask;
            let contiguous = reads.contiguous::<W>(x0, n);
            let mut xs = [0usize; W];
            for (t, x) in xs.iter_mut().enumerate() {
                *x = (jx + t as i64) as usize & mask;
            }
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
        }
    }
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
    let mask = (m - 1) as i64;
    for (row, line) in out
        .chunks_exact_mut(width * channels)
        .take(height)
        .enumerate()
    {
        let gy = ((place.row0 - row as i64) & mask) as usize;
        for (col, o) in line.chunks_exact_mut(channels).enumerate() {
            let gx = ((place.col0 + col as i64) & mask) as usize;
            o[channel] = grid[gy * m + gx] * g;
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
