//! Slice extraction in integers, for cores without an FPU: Q15 kernel
//! weights, Q15 block-floating-point spectra and 32-bit sums widened to
//! 64 bits where they multiply.
//!
//! # Format
//! The spectrum is [`crate::num::Q15`] mantissas with one exponent per
//! x-line ([`crate::num::BlockLayout::Line`]), or none: coefficient `c` is
//! `m·2^(e − 15)` in the stored units `s·H`. The slice comes out as `i32`
//! values with one exponent for the grid: sample = `v·2^exponent`, in the
//! same units. Between, everything is integer; the per-view set-up
//! ([`FixedAxes`], the axes rounded to fixed point) is the only floating
//! point, six roundings.
//!
//! # Sums
//! A slice point takes `W` x-weights, `W` y-weights and `W` z-weights of
//! `F ≤ 15` fraction bits ([`FixedPhases`]), each triple's magnitudes
//! summing to at most `2^16 − 1`. With `E` the largest line exponent:
//! - each x-line sum `X = Σ_t w_t·m_t` in `i32`
//!   (`|X| ≤ (2^16 − 1)·2^15 < 2^31`), aligned to `E` by an arithmetic
//!   shift right by `E − e` (at most 31: lines below `E − 31` hold under
//!   one unit of the sum and give 0 or −1);
//! - each y-sum `Σ_b w_b·X_b` in `i64` (one multiply-accumulate of two
//!   32-bit values on a Cortex-M3), shifted right by 16 back to `i32`
//!   (`|·| < 2^31` by the same bound);
//! - the z-sum likewise, shifted right by 16 into the grid.
//!
//! So the grid's exponent is `E − 15 − 3F + 32`; with `F = 15`, `E − 28`,
//! and a point's value keeps about 30 bits while the stored mantissas have
//! 16. The shifts round down: a bias of half a unit of the last place,
//! far below the Q15 rounding the finish applies to the slice, whose peak
//! (at or near the DC term every slice passes through) is about the
//! spectrum's largest coefficient, `2^28` units. Nothing
//! can overflow, whatever the mantissas (the overflow flag −32768 reads as
//! −1) and exponents (−128 … 127), so the extraction never panics on data.
//!
//! # Structure shared with the float path
//! The walk over mirror pairs, rows and their intervals is the float
//! path's ([`super::rows::walk_pairs`]), fed by integer positions
//! ([`FixedAxes`] implements [`super::rows::RowPositions`]); the weights
//! are gathered from the same kernel entries as
//! [`crate::filter::PhaseTable`]'s; the tap addressing is
//! [`super::taps`]'s. The tap sums differ: block exponents are applied by
//! shifts instead of products.

mod axes;
mod phases;
#[cfg(test)]
mod tests;

pub use phases::FixedPhases;

use super::rows::walk_pairs;
use crate::error::{check_len, Error, Result};
use crate::geometry::SliceAxes;
use crate::num::{BlockLayout, Q15};
use crate::spectrum::{CubeSide, Spectrum};
use axes::{FixedAxes, MAX_SIDE};

/// Fill the `n × n` slice `grid` (`kx` fastest, natural DHT order) of the
/// Q15 spectrum `spec` on the plane spanned by `axes` (index units per
/// pixel: [`crate::geometry::Frame::slice_axes`]) with the weights of
/// `phases`; returns the grid's exponent (module docs). Points outside
/// the Nyquist cube are zero, as in [`super::extract_slice`].
///
/// # Errors
/// A `grid` of other than `n²` values; `phases` for another filter than
/// the spectrum was premultiplied for; brick exponents
/// ([`Error::UnsupportedFormat`]: only per-line exponents are read); a
/// side above 4096 or an axis component beyond ±16
/// ([`Error::FixedPointRange`]).
pub fn extract_slice_fixed<const W: usize, Z: CubeSide>(
    spec: &Spectrum<'_, Q15, Z>,
    phases: &FixedPhases<W>,
    axes: &SliceAxes,
    grid: &mut [i32],
) -> Result<i32> {
    let n = spec.n();
    check_len("fixed-point slice grid", n * n, grid.len())?;
    if phases.filter().as_ref() != Some(spec.filter()) {
        return Err(Error::FilterMismatch);
    }
    if n > MAX_SIDE {
        return Err(Error::FixedPointRange {
            what: "spectrum side (at most 4096)",
        });
    }
    let axes = FixedAxes::<W>::new(axes)?;
    let exponents = match spec.blocks() {
        None => &[][..],
        Some(b) if b.layout() == BlockLayout::Line => b.exponents(),
        Some(_) => {
            return Err(Error::UnsupportedFormat {
                format: "q15",
                reason: "the fixed-point extraction reads per-line block exponents only",
            })
        }
    };
    // The largest exponent, which every line is aligned to.
    let top = exponents.iter().copied().max().map_or(0, i32::from);
    let f = phases.fraction_bits() as i32;
    let exponent = top - 15 - 3 * f + 32;
    let Some(data) = spec.data().get(..n * n * n) else {
        grid.fill(0);
        return Ok(exponent);
    };
    if exponents.is_empty() {
        walk::<W, false>(data, n, &[], top, phases, &axes, grid);
    } else {
        walk::<W, true>(data, n, exponents, top, phases, &axes, grid);
    }
    Ok(exponent)
}

/// The walk with the tap sums of [`FixedTaps`].
#[inline(always)]
fn walk<const W: usize, const LINE_EXP: bool>(
    data: &[Q15],
    n: usize,
    exponents: &[i8],
    top: i32,
    phases: &FixedPhases<W>,
    axes: &FixedAxes<W>,
    grid: &mut [i32],
) {
    let taps = FixedTaps::<W, LINE_EXP> {
        data,
        n,
        exponents,
        top,
    };
    let mirror = |j: i32| -j - (W as i32 - 1);
    let reversed = |w: &[i32; W]| -> [i32; W] { core::array::from_fn(|t| w[W - 1 - t]) };
    walk_pairs::<W, true, i32, _>(axes, n, 0, n, grid, |y, plus, minus| {
        let (jx, wx) = phases.taps(y[0]);
        let (jy, wy) = phases.taps(y[1]);
        let (jz, wz) = phases.taps(y[2]);
        let value = if plus {
            taps.value(jx, &wx, jy, &wy, jz, &wz)
        } else {
            0
        };
        let mirrored = if minus {
            let (rx, ry, rz) = (reversed(&wx), reversed(&wy), reversed(&wz));
            taps.value(mirror(jx), &rx, mirror(jy), &ry, mirror(jz), &rz)
        } else {
            0
        };
        (value, mirrored)
    });
}

/// The tap reads of the fixed-point extraction: `data` exactly `n³`
/// mantissas, with one exponent per x-line in `exponents` when `LINE_EXP`,
/// aligned to `top`.
struct FixedTaps<'a, const W: usize, const LINE_EXP: bool> {
    data: &'a [Q15],
    n: usize,
    exponents: &'a [i8],
    top: i32,
}

impl<const W: usize, const LINE_EXP: bool> FixedTaps<'_, W, LINE_EXP> {
    /// An x-line's sum aligned to the top exponent.
    #[inline(always)]
    fn aligned(&self, line: usize, x: i32) -> i32 {
        if LINE_EXP {
            let e = self
                .exponents
                .get(line / self.n)
                .copied()
                .unwrap_or(i8::MIN);
            // `top` is the largest exponent, so the shift is not negative.
            x >> ((self.top - e as i32) as u32).min(31)
        } else {
            x
        }
    }

    /// The `W` taps of one x-line from `start`, as one run (`x0 + W ≤ n`)
    /// or at the wrapped indices `xs` of `line`.
    #[inline(always)]
    fn line_sum(&self, run: Option<&[Q15; W]>, wx: &[i32; W]) -> i32 {
        let mut sum = 0i32;
        if let Some(run) = run {
            for t in 0..W {
                sum += wx[t] * run[t].0 as i32;
            }
        }
        sum
    }

    /// The value at the taps `j + t` of each axis (`t < W`, wrapping around
    /// the cube) with weights `w[t]` (module docs for the sums).
    #[inline(always)]
    fn value(&self, jx: i32, wx: &[i32; W], jy: i32, wy: &[i32; W], jz: i32, wz: &[i32; W]) -> i32 {
        let (data, n) = (self.data, self.n);
        let (nn, mask) = (n * n, n - 1);
        // The tap addressing of `super::taps`: line and plane offsets in
        // wrapping usize, one product an axis.
        let (y0, z0) = (
            (jy as usize).wrapping_mul(n),
            (jz as usize).wrapping_mul(nn),
        );
        let lines: [usize; W] = core::array::from_fn(|b| y0.wrapping_add(b * n) & (nn - n));
        let planes: [usize; W] = core::array::from_fn(|c| z0.wrapping_add(c * nn) & (nn * n - nn));
        let x0 = jx as usize & mask;
        let contiguous = x0 + W <= n;
        let xs: [usize; W] = core::array::from_fn(|t| (jx + t as i32) as usize & mask);
        let mut acc = 0i64;
        for c in 0..W {
            let mut acc_y = 0i64;
            for b in 0..W {
                let line = planes[c] + lines[b];
                let x = if contiguous {
                    let run = data
                        .get(line + x0..)
                        .and_then(|rest| rest.first_chunk::<W>());
                    self.line_sum(run, wx)
                } else {
                    let mut sum = 0i32;
                    for t in 0..W {
                        let v = data.get(line + xs[t]).map_or(0, |q| q.0 as i32);
                        sum += wx[t] * v;
                    }
                    sum
                };
                acc_y += wy[b] as i64 * self.aligned(line, x) as i64;
            }
            // |acc_y| < 2^47: its top 32 bits are exact as an i32.
            acc += wz[c] as i64 * ((acc_y >> 16) as i32) as i64;
        }
        (acc >> 16) as i32
    }
}
