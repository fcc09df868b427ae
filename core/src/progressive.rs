//! Progressive previews (the paper's conclusion): a low-resolution image
//! from the centre of the spectrum only.
//!
//! Level `L` renders a `(W/2^L) × (H/2^L)` image at a pitch of `2^L`
//! voxels. Its slice is the central `m × m` block of the full slice,
//! `m = n/2^L`, so extraction reads `4^L` times fewer points and the 2D
//! inverse transform is `m × m`. The image is the full-resolution
//! projection low-passed to `|k| < m/2` and sampled every `2^L` voxels:
//! `P_L(x) = (1/n²)·Σ_{|k|<m/2} S(k)·cas(2πk·x/m)`, which is the `m`-point
//! inverse transform scaled by `(m/n)² = 4^−L`.

use crate::dht::Twiddles;
use crate::error::{require_len, Error, Result};
use crate::filter::KernelTable;
use crate::geometry::{Sampling, View};
use crate::real::{Real, Sample};
use crate::render::{
    aux_len, check_image, extract_central_slice_on, finish_projection, placement_on_axes,
};
use crate::spectrum::{CubeSide, Spectrum};

/// Deepest level: the preview grid keeps at least 2 samples a side.
pub fn max_level(n: usize) -> u32 {
    n.max(2).trailing_zeros().saturating_sub(1)
}

/// The preview size of a `width × height` image at `level` (each side
/// divided by `2^level`, at least 1).
pub fn preview_size(width: usize, height: usize, level: u32) -> (usize, usize) {
    let shrink = |v: usize| (v >> level.min(usize::BITS - 1)).max(1);
    (shrink(width), shrink(height))
}

/// Render the level-`level` preview of `spec` along `view` into `out`, a
/// `width × height` image at pitch `2^level` (row 0 at the top). `grid`
/// needs `(n/2^level)²` elements, `aux` [`aux_len`] of that side. Level 0
/// is [`crate::render::render`].
///
/// # Errors
/// As [`crate::render::render`], and a level beyond [`max_level`].
pub fn render_level<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    view: &View,
    width: usize,
    height: usize,
    level: u32,
    tw: &Twiddles<'_, T>,
    grid: &mut [T],
    aux: &mut [T],
    out: &mut [T],
) -> Result<()> {
    render_level_sampled(
        spec,
        kernel,
        view,
        &Sampling::UNIT,
        width,
        height,
        level,
        tw,
        grid,
        aux,
        out,
    )
}

/// [`render_level`] in physical units ([`crate::render::render_sampled`]):
/// pixels `2^level·p` mm apart. The slice axes are the full view's
/// [`Sampling::slice_axes`] (level `L` samples the same plane `2^L` times
/// more coarsely in frequency, and `m = n/2^L` makes `n/(m·2^L·p) = 1/p`),
/// and the gain is `Δx·Δy·Δz/(2^L·p)²`. [`Sampling::UNIT`] gives
/// [`render_level`]'s image bit for bit.
///
/// # Errors
/// As [`render_level`].
pub fn render_level_sampled<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    view: &View,
    sampling: &Sampling,
    width: usize,
    height: usize,
    level: u32,
    tw: &Twiddles<'_, T>,
    grid: &mut [T],
    aux: &mut [T],
    out: &mut [T],
) -> Result<()> {
    let n = spec.n();
    if level > max_level(n) {
        return Err(Error::TooMany {
            what: "progressive levels (the preview grid needs 2 samples a side)",
            given: level as usize,
            capacity: max_level(n) as usize,
        });
    }
    let axes = sampling.slice_axes(&view.frame()?);
    let m = n >> level;
    check_image(width, height, m)?;
    if kernel.filter() != spec.filter() {
        return Err(Error::FilterMismatch);
    }
    require_len("slice grid", m * m, grid.len())?;
    require_len("auxiliary scratch", aux_len(m), aux.len())?;
    require_len("output image", width * height, out.len())?;
    // Checked before the extraction, which is the bulk of the work.
    tw.check(m)?;
    let pitch = (1u64 << level) as f64;
    extract_central_slice_on(spec, kernel, &axes, m, grid);
    let place = placement_on_axes(spec.dims(), &axes, width, height, pitch);
    let gain = sampling.gain() / (spec.scale() * pitch * pitch);
    finish_projection(
        &mut grid[..m * m],
        m,
        &place,
        gain,
        width,
        height,
        tw,
        aux,
        out,
    )
}
