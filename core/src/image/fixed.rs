//! Finishing a view in integers: the sub-pixel shift on the `i32` slice,
//! the slice to Q15 block floating point, the fixed-point inverse 2D DHT
//! ([`crate::dht::fixed::idht_2d`]) and the crop into a Q15 image with one
//! exponent.
//!
//! The same steps as [`super::finish`]; the image is
//! `out[i]·2^exponent` in the slice's units (the caller takes off the
//! spectrum's power-of-two scale).

use super::{check_image, Placement};
use crate::dht::fixed::{idht_2d, FixedTwiddles};
use crate::dht::{neg_mod, signed_index};
use crate::error::{check_len, require_len, Result};

#[cfg(test)]
#[path = "fixed_tests.rs"]
mod tests;

/// Auxiliary `i32` scratch [`finish_fixed`] needs for an `m × m` grid: `4m`
/// (the shift's cosines and sines per axis).
pub const fn fixed_aux_len(m: usize) -> usize {
    4 * m
}

/// Peak the `i32` slice is brought under before the shift, whose outputs
/// grow by at most `√2` (`|cos| + |sin|`).
const SHIFT_HEADROOM_LOG2: u32 = 29;

/// The caller's buffers of [`finish_fixed`].
#[derive(Debug)]
pub struct FixedBuffers<'a> {
    /// The `m × m` slice, `i32` values (shifted in place).
    pub grid: &'a mut [i32],
    /// Scratch of [`fixed_aux_len`]`(m)`.
    pub aux: &'a mut [i32],
    /// The slice as Q15 mantissas, `m²`, inverse-transformed in place.
    pub block: &'a mut [i16],
    /// The image, `width·height` Q15 mantissas.
    pub out: &'a mut [i16],
}

impl FixedBuffers<'_> {
    /// The same buffers, borrowed again for one call of [`finish_fixed`]
    /// (which takes them by value).
    pub fn reborrow(&mut self) -> FixedBuffers<'_> {
        FixedBuffers {
            grid: self.grid,
            aux: self.aux,
            block: self.block,
            out: self.out,
        }
    }
}

/// What [`finish_fixed`] turns into an image: the `m × m` slice grid holds
/// `grid·2^exponent`, and the `width × height` image sits at `place`.
#[derive(Clone, Copy, Debug)]
pub struct FixedSlice<'a> {
    /// The slice's exponent.
    pub exponent: i32,
    /// The grid's side.
    pub m: usize,
    /// Where the image sits on the grid.
    pub place: Placement,
    /// The image's `(width, height)`.
    pub size: (usize, usize),
    /// Q15 twiddles serving side `m`.
    pub tw: &'a FixedTwiddles<'a, i16>,
}

/// Turn the `m × m` slice `grid·2^exponent` into the `width × height`
/// image at `place`: sub-pixel shift (a phase ramp, as [`super::finish`],
/// with the cosines and sines in Q30), round to Q15 with one exponent
/// (half up, from the peak, so that no mantissa reaches −32768), inverse
/// 2D DHT in Q15 block floating point, and crop. Returns the image's
/// exponent: pixel `i` is `out[i]·2^e`.
///
/// # Errors
/// An image side of 0 or above `m`, buffers of the wrong size, or
/// twiddles too short.
pub fn finish_fixed(buffers: FixedBuffers<'_>, slice: &FixedSlice<'_>) -> Result<i32> {
    let FixedBuffers {
        grid,
        aux,
        block,
        out,
    } = buffers;
    let (m, place, (width, height)) = (slice.m, &slice.place, slice.size);
    check_len("fixed-point image", width * height, out.len())?;
    let exponent = to_block(grid, aux, block, slice)?;
    let mask = m - 1;
    let (row0, col0) = (place.row0 as usize, place.col0 as usize);
    for (row, line) in out.chunks_exact_mut(width).enumerate() {
        let gy = row0.wrapping_sub(row) & mask;
        let grid_row = &block[gy * m..(gy + 1) * m];
        for (col, o) in line.iter_mut().enumerate() {
            *o = grid_row[col0.wrapping_add(col) & mask];
        }
    }
    Ok(exponent)
}

/// [`finish_fixed`] with the image cut in place into `block`, so a device
/// needs no image buffer beside it: afterwards `block[..width·height]`
/// holds, bit for bit, what [`finish_fixed`] writes to its `out`.
///
/// As [`super::in_grid::finish_in_grid`]: image row `r` is block row
/// `σ(r) = (row0 − r) mod m`, an involution, so the rows are put in place
/// by swapping pairs; each row is then copied to `aux` and packed to
/// `width` values, which only writes at or before the row being read.
///
/// # Errors
/// As [`finish_fixed`].
pub fn finish_fixed_in_block(
    grid: &mut [i32],
    aux: &mut [i32],
    block: &mut [i16],
    slice: &FixedSlice<'_>,
) -> Result<i32> {
    let (m, place, (width, height)) = (slice.m, &slice.place, slice.size);
    let exponent = to_block(grid, aux, block, slice)?;
    let mask = m - 1;
    let (row0, col0) = (place.row0 as usize, place.col0 as usize);
    for r in 0..height {
        let s = row0.wrapping_sub(r) & mask;
        if s > r {
            let (head, tail) = block.split_at_mut(s * m);
            head[r * m..(r + 1) * m].swap_with_slice(&mut tail[..m]);
        }
    }
    let row = &mut aux[..m];
    for r in 0..height {
        for (a, b) in row.iter_mut().zip(&block[r * m..(r + 1) * m]) {
            *a = *b as i32;
        }
        for (col, o) in block[r * width..(r + 1) * width].iter_mut().enumerate() {
            *o = row[col0.wrapping_add(col) & mask] as i16;
        }
    }
    Ok(exponent)
}

/// The steps of [`finish_fixed`] before the crop: the checks, the shift,
/// the slice to Q15 in `block` and its inverse 2D DHT in place; returns
/// the block's exponent.
fn to_block(
    grid: &mut [i32],
    aux: &mut [i32],
    block: &mut [i16],
    slice: &FixedSlice<'_>,
) -> Result<i32> {
    let FixedSlice {
        mut exponent,
        m,
        place,
        size: (width, height),
        tw,
    } = *slice;
    check_image(width, height, m)?;
    check_len("fixed-point slice grid", m * m, grid.len())?;
    check_len("Q15 slice block", m * m, block.len())?;
    require_len("fixed-point auxiliary scratch", fixed_aux_len(m), aux.len())?;
    if place.shift != [0.0, 0.0] {
        exponent += bring_under(grid, SHIFT_HEADROOM_LOG2);
        apply_shift(grid, m, place.shift, aux);
    }
    exponent += to_q15(grid, block);
    exponent += idht_2d(block, m, m, tw)?;
    Ok(exponent)
}

/// `v / 2^s` rounded half up, for `s ≤ 31`.
#[inline(always)]
fn shift_round(v: i32, s: u32) -> i32 {
    if s == 0 {
        v
    } else {
        ((v as i64 + (1i64 << (s - 1))) >> s) as i32
    }
}

/// The right shift that brings `peak` (rounded half up) to at most
/// `2^bits − 1`.
fn shift_for(peak: i64, bits: u32) -> u32 {
    let limit = (1i64 << bits) - 1;
    let mut s = 0;
    while s < 32 && (peak + ((1i64 << s) >> 1)) >> s > limit {
        s += 1;
    }
    s
}

/// Shift `grid` right (rounded) until its peak is below `2^bits`; returns
/// the shift.
fn bring_under(grid: &mut [i32], bits: u32) -> i32 {
    let peak = grid.iter().map(|v| (*v as i64).abs()).max().unwrap_or(0);
    let s = shift_for(peak, bits);
    if s > 0 {
        for v in grid.iter_mut() {
            *v = shift_round(*v, s);
        }
    }
    s as i32
}

/// The slice as Q15 mantissas with one exponent, rounded half up from the
/// peak (every mantissa within ±32767); returns the shift.
fn to_q15(grid: &[i32], block: &mut [i16]) -> i32 {
    let peak = grid.iter().map(|v| (*v as i64).abs()).max().unwrap_or(0);
    let s = shift_for(peak, 15);
    for (b, v) in block.iter_mut().zip(grid) {
        *b = shift_round(*v, s) as i16;
    }
    s as i32
}

/// `(cos, sin)(k·θ)` in Q30 for `k = 0 … m/2 − 1` by the recurrence
/// `z_k = z_{k−1}·z_1` (each product rounded: the error grows by at most
/// a unit of Q30 a step), then `k ≥ m/2` as the conjugates of `m − k`,
/// Nyquist (`k = m/2`) with no phase. `θ = −2π·t/m`: two soft-float
/// calls per axis and view.
fn phase_ramp(t: f64, m: usize, cos: &mut [i32], sin: &mut [i32]) {
    let one = (1i64 << 30) as f64;
    let theta = -2.0 * core::f64::consts::PI * t / m as f64;
    let z1 = (
        libm::round(libm::cos(theta) * one) as i64,
        libm::round(libm::sin(theta) * one) as i64,
    );
    let mut z = (1i64 << 30, 0i64);
    let half = 1i64 << 29;
    for k in 0..m {
        if 2 * k == m {
            (cos[k], sin[k]) = (1 << 30, 0);
        } else if signed_index(k, m) < 0 {
            let j = m - k;
            (cos[k], sin[k]) = (cos[j], -sin[j]);
        } else {
            (cos[k], sin[k]) = (z.0 as i32, z.1 as i32);
            z = (
                (z.0 * z1.0 - z.1 * z1.1 + half) >> 30,
                (z.0 * z1.1 + z.1 * z1.0 + half) >> 30,
            );
        }
    }
}

/// The phase ramp of [`super::finish`]'s shift on the integer slice:
/// `H'(k) = cos φ·H(k) + sin φ·H(−k)`, `φ = −2π k·t/m`, in Q30, for a
/// slice whose peak is below `2^29` (outputs below `2^29.6`).
fn apply_shift(grid: &mut [i32], m: usize, t: [f64; 2], aux: &mut [i32]) {
    let (cx, rest) = aux.split_at_mut(m);
    let (sx, rest) = rest.split_at_mut(m);
    let (cy, sy) = rest.split_at_mut(m);
    phase_ramp(t[0], m, cx, sx);
    phase_ramp(t[1], m, cy, sy);
    let product = |a: i32, b: i32, c: i32, d: i32| -> i64 {
        (a as i64 * b as i64 + c as i64 * d as i64 + (1 << 29)) >> 30
    };
    for iy in 0..m {
        let my = neg_mod(iy, m);
        for ix in 0..m {
            let (a, b) = (iy * m + ix, my * m + neg_mod(ix, m));
            if a >= b {
                continue;
            }
            // |cos|, |sin| ≤ 2^30 (+ rounding): c and s are Q30 too.
            let c = product(cx[ix], cy[iy], -sx[ix], sy[iy]) as i32;
            let s = product(sx[ix], cy[iy], cx[ix], sy[iy]) as i32;
            let (h, hm) = (grid[a], grid[b]);
            grid[a] = product(c, h, s, hm) as i32;
            grid[b] = product(c, hm, -s, h) as i32;
        }
    }
}
