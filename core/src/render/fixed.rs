//! A view in integers, for cores without an FPU: the X-ray projection of
//! a Q15 block-floating-point spectrum as a Q15 image with one exponent.
//!
//! Per view, only the set-up is floating point: the camera frame
//! ([`View::frame`]), the image's placement, the axes rounded to fixed
//! point, and, when the image has a sub-pixel shift, two cosines and two
//! sines. Extraction ([`crate::slice::fixed`]) and finish
//! ([`crate::image::fixed`]) are integer.

use crate::dht::fixed::FixedTwiddles;
use crate::error::{Error, Result};
use crate::geometry::View;
use crate::image::fixed::{finish_fixed, finish_fixed_in_block, FixedBuffers, FixedSlice};
use crate::image::placement;
use crate::num::Q15;
use crate::slice::fixed::{extract_slice_fixed, FixedPhases};
use crate::spectrum::{CubeSide, Spectrum};

/// What a fixed-point view is rendered from.
#[derive(Clone, Copy, Debug)]
pub struct FixedSource<'a, Z, const W: usize> {
    /// The Q15 spectrum, with per-line block exponents or none.
    pub spectrum: &'a Spectrum<'a, Q15, Z>,
    /// The kernel weights of the spectrum's filter.
    pub phases: &'a FixedPhases<W>,
    /// Q15 twiddles serving the spectrum's side.
    pub twiddles: &'a FixedTwiddles<'a, i16>,
}

/// Render the `size = (width, height)` X-ray projection along `view` (voxel units,
/// level 0) into `buffers.out`; returns the exponent `e`: pixel `i` is
/// `out[i]·2^e`, `∫ f dt` in voxel units of the input volume. The buffers
/// are those of [`finish_fixed`] for the spectrum's side.
///
/// # Errors
/// Bad view vectors, and those of [`extract_slice_fixed`] and
/// [`finish_fixed`]; a spectrum scale that is not a power of two within
/// ±2^30 ([`Error::FixedPointRange`]).
pub fn render_fixed<Z: CubeSide, const W: usize>(
    source: &FixedSource<'_, Z, W>,
    view: &View,
    size: (usize, usize),
    buffers: FixedBuffers<'_>,
) -> Result<i32> {
    let (slice, scale) = extract(source, view, size, buffers.grid)?;
    Ok(finish_fixed(buffers, &slice)? - scale)
}

/// [`render_fixed`] with the image cut into the Q15 block
/// ([`finish_fixed_in_block`]): afterwards `block[..width·height]` holds
/// the image [`render_fixed`] writes to its `out`, bit for bit, and no
/// image buffer is needed. `grid`, `aux` and `block` are those of
/// [`FixedBuffers`].
///
/// # Errors
/// As [`render_fixed`].
pub fn render_fixed_in_block<Z: CubeSide, const W: usize>(
    source: &FixedSource<'_, Z, W>,
    view: &View,
    size: (usize, usize),
    grid: &mut [i32],
    aux: &mut [i32],
    block: &mut [i16],
) -> Result<i32> {
    let (slice, scale) = extract(source, view, size, grid)?;
    Ok(finish_fixed_in_block(grid, aux, block, &slice)? - scale)
}

/// The set-up and the extraction of a fixed-point view: the slice in
/// `grid`, what the finish needs of it (its exponent, the image's
/// placement and size, the twiddles), and the spectrum's scale exponent.
fn extract<'a, Z: CubeSide, const W: usize>(
    source: &FixedSource<'a, Z, W>,
    view: &View,
    size: (usize, usize),
    grid: &mut [i32],
) -> Result<(FixedSlice<'a>, i32)> {
    let spec = source.spectrum;
    let frame = view.frame()?;
    let axes = frame.slice_axes();
    let place = placement(spec.dims(), &frame, size.0, size.1);
    let scale = scale_exponent(spec.scale())?;
    let exponent = extract_slice_fixed(spec, source.phases, &axes, grid)?;
    let slice = FixedSlice {
        exponent,
        m: spec.n(),
        place,
        size,
        tw: source.twiddles,
    };
    Ok((slice, scale))
}

/// `k` for a scale `2^k` (the spectrum's scale is a power of two).
///
/// # Errors
/// Not a power of two within ±2^30 ([`Error::FixedPointRange`]).
pub fn scale_exponent(scale: f64) -> Result<i32> {
    let (mantissa, k) = libm::frexp(scale);
    if mantissa != 0.5 || !(-30..=32).contains(&k) {
        return Err(Error::FixedPointRange {
            what: "spectrum scale (a power of two within 2^±30)",
        });
    }
    Ok(k - 1)
}
