//! Finishing a view: from a filled slice to the image.
//!
//! The slice is shifted by the sub-pixel offsets of its [`Placement`]
//! (exactly, as a phase ramp: in Hartley form, shifting by `t` maps `H(k)`
//! to `cos φ·H(k) + sin φ·H(−k)` with `φ = −2π k·t/n`), inverse-transformed
//! by the 2D DHT (radix 2, or mixed radix for sides `2^a·3^b·5^c`:
//! [`Inverse`]), and the `W × H` image is cut from the grid around the
//! centre, times the gain.

pub mod fixed;
mod in_grid;
mod placement;

pub use in_grid::finish_in_grid;
pub use placement::{placement, placement_at_pitch, placement_on_axes, Placement};

use crate::dht::{dht_2d, dht_2d_mixed, dht_2d_mixed_scratch_len, neg_mod, signed_index};
use crate::dht::{MixedPlan, Twiddles};
use crate::error::{require_len, Error, Result};
use crate::num::Real;

/// Elements of an `m × m` slice grid.
pub const fn grid_len(m: usize) -> usize {
    m * m
}

/// Auxiliary scratch elements [`finish`] needs for an `m × m` grid: `4m`
/// (also enough for [`Inverse::Mixed`] on even `m`).
pub const fn aux_len(m: usize) -> usize {
    4 * m
}

/// The 2D inverse transform a view is finished with.
#[derive(Clone, Copy, Debug)]
pub enum Inverse<'a, T> {
    /// Radix 2, for power-of-two sides (the device's).
    Radix2(&'a Twiddles<'a, T>),
    /// Mixed radix, for sides `2^a·3^b·5^c`: a plan for the grid's side.
    Mixed(&'a MixedPlan<'a, T>),
}

impl<T: Real> Inverse<'_, T> {
    /// `Ok` if this transform serves side `m`.
    ///
    /// # Errors
    /// Twiddles too short or not a power of two side, or a plan for
    /// another length ([`Error::LengthMismatch`]).
    pub fn check(&self, m: usize) -> Result<()> {
        match self {
            Inverse::Radix2(tw) => tw.check(m),
            Inverse::Mixed(plan) => crate::error::check_len("mixed-radix plan", plan.len(), m),
        }
    }

    /// The unnormalized 2D DHT of the `m × m` grid in place.
    fn transform(&self, grid: &mut [T], m: usize, aux: &mut [T]) -> Result<()> {
        match self {
            Inverse::Radix2(tw) => dht_2d(grid, m, m, aux, tw),
            Inverse::Mixed(plan) => {
                let need = dht_2d_mixed_scratch_len(m, m);
                require_len("auxiliary scratch (mixed radix)", need, aux.len())?;
                dht_2d_mixed(grid, m, m, &mut aux[..need], [plan, plan])
            }
        }
    }
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
/// `width·height·channels`. An `aux` of [`crate::dht::dht_2d_sparse_len`]`(m)` or more
/// lets a slice with few nonzero rows (an adaptive view's) batch the row
/// pass of its transform ([`dht_2d`]); the image is the same.
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
    finish_with(grid, m, crop, Inverse::Radix2(tw), aux, out)
}

/// [`finish`] with the 2D inverse transform `inverse`: [`Inverse::Mixed`]
/// for a grid whose side `m` is not a power of two (the crop then wraps by
/// comparison instead of masks).
///
/// # Errors
/// As [`finish`]; also a transform for another side.
pub fn finish_with<T: Real>(
    grid: &mut [T],
    m: usize,
    crop: &Crop,
    inverse: Inverse<'_, T>,
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
    let pow2 = m.is_power_of_two();
    if pow2 {
        apply_shift::<true, T>(grid, m, place.shift, aux);
    } else {
        apply_shift::<false, T>(grid, m, place.shift, aux);
    }
    inverse.transform(grid, m, aux)?;
    let g = T::from_f64(gain / (m * m) as f64);
    if !pow2 {
        crop_any(grid, m, crop, g, out);
        return Ok(());
    }
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
            // One channel (plain and cued frames): the row in at most two
            // runs of the grid row (the second wrapped round to its
            // start), each a loop that vectorizes.
            let start = col0 & mask;
            let (head, tail) = line.split_at_mut(width.min(m - start));
            let runs = [(head, &grid_row[start..]), (tail, grid_row)];
            for (run, from) in runs {
                for (o, &v) in run.iter_mut().zip(from) {
                    *o = v * g;
                }
            }
        } else {
            for (col, o) in line.chunks_exact_mut(channels).enumerate() {
                o[channel] = grid_row[col0.wrapping_add(col) & mask] * g;
            }
        }
    }
    Ok(())
}

/// The crop of [`finish_with`] for any side `m`: grid indices `i mod m`
/// by a remainder per row and a comparison per pixel.
fn crop_any<T: Real>(grid: &[T], m: usize, crop: &Crop, g: T, out: &mut [T]) {
    let (width, channels, channel) = (crop.width, crop.channels, crop.channel);
    let modulo = |v: i64| v.rem_euclid(m as i64) as usize;
    let col0 = modulo(crop.place.col0);
    for (row, line) in out
        .chunks_exact_mut(width * channels)
        .take(crop.height)
        .enumerate()
    {
        let gy = modulo(crop.place.row0 - row as i64);
        let grid_row = &grid[gy * m..(gy + 1) * m];
        let mut gx = col0;
        for o in line.chunks_exact_mut(channels) {
            o[channel] = grid_row[gx] * g;
            gx += 1;
            if gx == m {
                gx = 0;
            }
        }
    }
}

/// Shift the projection by `t = (ta, tb)` pixels (`R(x) = Q(x + t)`) on its
/// Hartley slice: `H'(k) = cos φ·H(k) + sin φ·H(−k)`, `φ = −2π k·t/m`.
/// Nyquist components get no phase (a real signal cannot hold a shifted
/// Nyquist cosine), which keeps `φ(−k) = −φ(k)` for every pair.
///
/// `POW2`: `m` is a power of two (`−k mod m` by a mask).
fn apply_shift<const POW2: bool, T: Real>(grid: &mut [T], m: usize, t: [f64; 2], aux: &mut [T]) {
    if t == [0.0, 0.0] {
        return;
    }
    shift_phasors(m, t, aux, |ph| {
        (T::from_f64(libm::cos(ph)), T::from_f64(libm::sin(ph)))
    });
    apply_phasors_by::<POW2, T>(grid, m, aux);
}

/// The phase factors of the shift by `t` into `table`, as
/// `[cx | sx | cy | sy]` (`m` each): `(cos φ, sin φ) = phasor(φ)` of
/// `φ = −2π k·t/m` on each axis for every index `k`, Nyquist (`2k = m`)
/// with phase 0.
///
/// # Panics
/// If `table` is shorter than `4·m`.
#[inline]
pub fn shift_phasors<T>(m: usize, t: [f64; 2], table: &mut [T], phasor: impl Fn(f64) -> (T, T)) {
    let (cx, rest) = table.split_at_mut(m);
    let (sx, rest) = rest.split_at_mut(m);
    let (cy, sy) = rest.split_at_mut(m);
    let tau = -2.0 * core::f64::consts::PI / m as f64;
    for k in 0..m {
        let ks = signed_index(k, m) as f64;
        let (phx, phy) = if 2 * k == m {
            (0.0, 0.0)
        } else {
            (tau * ks * t[0], tau * ks * t[1])
        };
        (cx[k], sx[k]) = phasor(phx);
        (cy[k], sy[k]) = phasor(phy);
    }
}

/// The shift of one pair of points `k`, `−k`: with the phase factors
/// `(cos, sin)` of `k`'s two axes, `(H'(k), H'(−k))` from `(H(k), H(−k))`.
#[inline(always)]
pub fn shift_pair<T: Real>([cx, sx]: [T; 2], [cy, sy]: [T; 2], (h, hm): (T, T)) -> (T, T) {
    let c = cx * cy - sx * sy;
    let s = sx * cy + cx * sy;
    (c * h + s * hm, c * hm - s * h)
}

/// Shift the Hartley slice `grid` (`m × m`, a power of two) by the phase
/// factors `table` of [`shift_phasors`].
///
/// # Panics
/// If `grid` is shorter than `m²` or `table` than `4·m`.
#[inline]
pub fn apply_phasors<T: Real>(grid: &mut [T], m: usize, table: &[T]) {
    apply_phasors_by::<true, T>(grid, m, table);
}

/// [`apply_phasors`] for any `m` (`POW2`: `m` is a power of two, `−k mod m`
/// by a mask): the point of each pair that comes first in `grid` carries
/// the phase.
#[inline(always)]
fn apply_phasors_by<const POW2: bool, T: Real>(grid: &mut [T], m: usize, table: &[T]) {
    let neg = |k: usize| {
        if POW2 {
            neg_mod(k, m)
        } else if k == 0 {
            0
        } else {
            m - k
        }
    };
    let (cx, rest) = table.split_at(m);
    let (sx, rest) = rest.split_at(m);
    let (cy, sy) = rest.split_at(m);
    for iy in 0..m {
        let my = neg(iy);
        for ix in 0..m {
            let (a, b) = (iy * m + ix, my * m + neg(ix));
            if a >= b {
                continue;
            }
            (grid[a], grid[b]) = shift_pair([cx[ix], sx[ix]], [cy[iy], sy[iy]], (grid[a], grid[b]));
        }
    }
}
