//! Finishing a view: from a filled slice to the image.
//!
//! The slice is shifted by the sub-pixel offsets of its [`Placement`]
//! (exactly, as a phase ramp: in Hartley form, shifting by `t` maps `H(k)`
//! to `cos φ·H(k) + sin φ·H(−k)` with `φ = −2π k·t/n`), inverse-transformed
//! by the 2D DHT, and the `W × H` image is cut from the grid around the
//! centre, times the gain.

pub mod fixed;
mod placement;

pub use placement::{placement, placement_at_pitch, placement_on_axes, Placement};

use crate::dht::{dht_2d, neg_mod, signed_index, Twiddles};
use crate::error::{require_len, Error, Result};
use crate::num::Real;

/// Elements of an `m × m` slice grid.
pub const fn grid_len(m: usize) -> usize {
    m * m
}

/// Auxiliary scratch elements [`finish`] needs for an `m × m` grid: `4m`.
pub const fn aux_len(m: usize) -> usize {
    4 * m
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

/// How the image is cut from the inverse-transformed `m × m` grid: at
/// `place`, `width × height` pixels multiplied by `gain` (the reciprocal of
/// the spectrum's scale, times any unit conversion), into channel
/// `channel` of an interleaved image of `channels` channels (channel
/// fastest: `out[(row·width + col)·channels + channel]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crop {
    /// Where the image sits on the grid.
    pub place: Placement,
    /// The factor every pixel is multiplied by.
    pub gain: f64,
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Channels of the interleaved image (1 for a projection).
    pub channels: usize,
    /// The channel written.
    pub channel: usize,
}

impl Crop {
    /// A one-channel image of `width × height` at `place`, times `gain`.
    pub fn new(place: Placement, gain: f64, width: usize, height: usize) -> Self {
        Self {
            place,
            gain,
            width,
            height,
            channels: 1,
            channel: 0,
        }
    }
}

/// Turn a filled `m × m` slice into the image: sub-pixel shift, 2D inverse
/// DHT, then the [`Crop`].
///
/// `grid` needs [`grid_len`]`(m)` elements, `aux` [`aux_len`]`(m)`, `out`
/// `width·height·channels`.
///
/// # Errors
/// An image side of 0 or above `m`, `channel ≥ channels`, short buffers, or
/// twiddles too short.
pub fn finish<T: Real>(
    grid: &mut [T],
    m: usize,
    crop: &Crop,
    tw: &Twiddles<'_, T>,
    aux: &mut [T],
    out: &mut [T],
) -> Result<()> {
    let Crop {
        place,
        gain,
        width,
        height,
        channels,
        channel,
    } = *crop;
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
