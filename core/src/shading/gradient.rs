//! The gradient-magnitude volume `|∇f|` for hemispherical shading (paper
//! eq. 10–11: the second spectrum `F{|∇f|·p_m}`).
//!
//! `∇f` is the exact gradient of the band-limited (trigonometric)
//! interpolant of the samples, taken at the sample points. That
//! interpolant is a tensor product, so at the grid points its partial
//! derivative along an axis is the 1D spectral derivative along that axis's
//! lines: `H{∂f}(k) = −(2πk/L)·H(−k)` (paper eq. 11, Hartley form), with
//! the Nyquist term dropped (its derivative vanishes at the samples). Each
//! line is zero-padded to `L = 2·next_pow2(n_a)` so the interpolant does not
//! wrap around the volume: data that does not fall to zero at the volume's
//! faces rings there as any band-limited interpolant must.
//!
//! Cost: three passes of 1D transforms, `O(N log N)` for `N` voxels, and one
//! accumulator the size of the volume. `|∇f|` is not band-limited where the
//! gradient vanishes (it has a cone-like kink), so its samples alias a
//! little; that is part of the shading model's error budget.

use crate::dht::{dht, neg_mod, Twiddles};
use crate::error::{require_len, Error, Result};
use crate::num::Real;
use crate::volume::{require_voxels, VoxelSource};

/// Line length used along axis `a` of size `len`: `2·next_pow2(len)`.
pub fn padded_line_len(len: usize) -> usize {
    len.next_power_of_two() * 2
}

/// Scratch (and twiddle length) [`gradient_magnitude`] needs for `dims`:
/// the longest padded line.
pub fn gradient_scratch_len(dims: [usize; 3]) -> usize {
    dims.iter().map(|&d| padded_line_len(d)).max().unwrap_or(2)
}

/// Write `|∇f|` at every voxel of `volume` into `out` (`i` fastest, the
/// volume's own dims).
///
/// `line` needs [`gradient_scratch_len`]`(dims)` elements and `tw` must
/// serve that length.
///
/// # Errors
/// A NaN or infinite voxel, short buffers, a twiddle table too short.
pub fn gradient_magnitude<V: VoxelSource, T: Real>(
    volume: &V,
    out: &mut [T],
    line: &mut [T],
    tw: &Twiddles<'_, T>,
) -> Result<()> {
    require_voxels("derivative volume", volume.dims(), out.len())?;
    out.fill(T::ZERO);
    for axis in 0..3 {
        for_each_derivative(volume, axis, line, tw, |index, d| out[index] += d * d)?;
    }
    for v in out.iter_mut() {
        *v = T::from_f64(libm::sqrt(v.to_f64()));
    }
    Ok(())
}

/// Write `∂f/∂x_axis` at every voxel into `out` (the same derivative
/// [`gradient_magnitude`] uses), for references and the firmware's tables.
///
/// # Errors
/// As [`gradient_magnitude`], and `axis > 2`.
pub fn partial_derivative<V: VoxelSource, T: Real>(
    volume: &V,
    axis: usize,
    out: &mut [T],
    line: &mut [T],
    tw: &Twiddles<'_, T>,
) -> Result<()> {
    require_voxels("derivative volume", volume.dims(), out.len())?;
    for_each_derivative(volume, axis, line, tw, |index, d| out[index] = d)
}

/// Call `sink(voxel index, ∂f/∂x_axis)` for every voxel.
fn for_each_derivative<V: VoxelSource, T: Real>(
    volume: &V,
    axis: usize,
    line: &mut [T],
    tw: &Twiddles<'_, T>,
    mut sink: impl FnMut(usize, T),
) -> Result<()> {
    let dims = volume.dims();
    if axis > 2 {
        return Err(Error::LengthMismatch {
            what: "axis index (0, 1 or 2)",
            expected: 2,
            got: axis,
        });
    }
    require_len(
        "gradient line scratch",
        gradient_scratch_len(dims),
        line.len(),
    )?;
    let stride = [1, dims[0], dims[0] * dims[1]];
    let len = dims[axis];
    let l = padded_line_len(len);
    let buf = &mut line[..l];
    let inv = T::from_f64(1.0 / l as f64);
    let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
    for b in 0..dims[o2] {
        for a in 0..dims[o1] {
            let base = a * stride[o1] + b * stride[o2];
            buf.fill(T::ZERO);
            for (i, v) in buf[..len].iter_mut().enumerate() {
                let mut p = [0usize; 3];
                p[axis] = i;
                p[o1] = a;
                p[o2] = b;
                let x = volume.voxel(p[0], p[1], p[2]);
                if !x.is_finite() {
                    return Err(Error::NonFiniteVoxel { index: p, value: x });
                }
                *v = T::from_f64(x);
            }
            dht(buf, tw)?;
            differentiate(buf);
            dht(buf, tw)?;
            for (i, v) in buf[..len].iter().enumerate() {
                sink(base + i * stride[axis], *v * inv);
            }
        }
    }
    Ok(())
}

/// `H(k) ← −(2πk/L)·H(−k)` for signed `k`, Nyquist to zero, in place.
fn differentiate<T: Real>(h: &mut [T]) {
    let l = h.len();
    let unit = 2.0 * core::f64::consts::PI / l as f64;
    h[0] = T::ZERO;
    if l >= 2 {
        h[l / 2] = T::ZERO;
    }
    for k in 1..l / 2 {
        let m = neg_mod(k, l);
        let c = T::from_f64(unit * k as f64);
        let (hk, hm) = (h[k], h[m]);
        // H'(k) = −ck·H(−k); H'(−k) = +ck·H(k).
        h[k] = -(c * hm);
        h[m] = c * hk;
    }
}
