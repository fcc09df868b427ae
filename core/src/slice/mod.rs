//! Slice extraction: the 2D slice through the origin of the 3D spectrum.
//!
//! By the projection-slice theorem (paper §1, fig. 1), the 2D Hartley
//! transform of the projection along `d` equals the 3D spectrum on the plane
//! through the origin spanned by `r` and `u`. The slice sample at 2D
//! frequency index `(kx, ky)` is the spectrum interpolated at the 3D index
//! `kx·r + ky·u` (paper §2: `F * H`, with the volume premultiplied by
//! `1/h`). Slice points outside the spectrum's Nyquist cube `|q_a| ≤ n/2` are
//! zero: the band-limited interpolant has no energy there.
//!
//!
//! In physical units ([`crate::geometry::Sampling`]) the slice is spanned by
//! [`crate::geometry::Sampling::slice_axes`] `r'_a = r_a·Δ_a/p`, `u'_a = u_a·Δ_a/p` instead.
//! The extraction needs no change: the Nyquist-cube test is per index axis,
//! the taps wrap modulo `n` as before, and `r'`, `u'` need not be
//! orthonormal.

pub mod adaptive;
pub mod fixed;
mod reads;
mod rows;
mod taps;

pub(crate) use reads::{scaled, LineReads, XRun};
pub use rows::row_interval;
pub use taps::{wrapped_tap_sum, LineSum, Unscaled};

use crate::error::{Error, Result};
use crate::filter::{KernelTable, PhaseTable, MAX_WIDTH};
use crate::geometry::{Frame, SliceAxes};
use crate::num::{Real, Sample};
use crate::spectrum::{CubeSide, Spectrum};
use rows::SliceRows;
use taps::{extract_general, extract_lines};

/// Fill the `n × n` slice `grid` (`kx` fastest, natural DHT order) by
/// interpolating the spectrum with `kernel` on the plane spanned by the
/// frame's right and up vectors.
pub fn extract_slice<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    frame: &Frame,
    grid: &mut [T],
) {
    extract_central_slice_on(spec, kernel, &frame.slice_axes(), spec.n(), grid);
}

/// [`extract_slice`] restricted to the central `m × m` frequencies
/// (`m ≤ n`, a power of two: the slice of a preview at pitch `n/m`,
/// [`mod@crate::render`]) on the plane spanned by `axes` (the slice sample
/// at `(kx, ky)` is the spectrum at `kx·axes.right + ky·axes.up`, zero
/// outside the Nyquist cube): with [`crate::geometry::Sampling::slice_axes`]
/// the physical-units slice. `grid` holds `m²` values, `kx` fastest.
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
/// in voxel units, [`crate::geometry::Sampling::slice_axes`] in physical units), as many as
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
    let filled = phases.fill(kernel);
    // Selected once per view; a compile-time side folds it away.
    // `fill` fails only for a kernel wider than MAX_WIDTH, and no filter
    // is: the general arm then reads an all-zero table (a zero slice).
    if !spec.n().is_power_of_two() {
        return match (filled, LineReads::of(spec)) {
            (Ok(()), LineReads::Plain) => {
                extract_lines::<W, false, false, S, Z, T>(spec, &phases, &geometry, &[], grid)
            }
            _ => extract_general::<W, false, S, Z, T>(spec, &phases, &geometry, grid),
        };
    }
    match (filled, LineReads::of(spec)) {
        (Ok(()), LineReads::Plain) => {
            extract_lines::<W, false, true, S, Z, T>(spec, &phases, &geometry, &[], grid)
        }
        (Ok(()), LineReads::LineExponents(e)) => {
            extract_lines::<W, true, true, S, Z, T>(spec, &phases, &geometry, e, grid)
        }
        _ => extract_general::<W, true, S, Z, T>(spec, &phases, &geometry, grid),
    }
}
