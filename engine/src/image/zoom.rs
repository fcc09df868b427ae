//! A magnified image of the same view: the slice spectrum zero-padded from
//! `n × n` to `m × m` (`m = F·n`) before the 2D inverse transform, which
//! then samples the same band-limited projection `F` times as densely
//! (sinc interpolation at the cost of one `m × m` transform).
//!
//! Geometry. The engine places image pixel `(col, row)` of a `W × H` image
//! at `(col0 + col + ta, row0 − row + tb)` grid pixels from the transform
//! origin ([`fvr_core::image::Placement`]): pixel `W/2` is the volume's
//! centre. The zoomed image keeps that convention at pitch `1/F`: its
//! pixel `(c', r')` sits at `(col0 + ta + c'/F, row0 + tb − r'/F)`, so it is
//! `F·W × F·H` pixels, its pixel `F·W/2` is the centre, and its pixel
//! `(F·col, F·row)` is the same point as the unzoomed `(col, row)`.
//! No half-pixel shift is introduced; the pixels beyond the last coinciding
//! one (`F − 1` of them on the right and bottom edges) continue the grid.
//!
//! Arithmetic. The sub-pixel shift `(ta, tb)` is applied to the `n × n`
//! slice exactly as the unzoomed finish applies it; the shifted slice is
//! copied into the `m × m` grid at the same signed frequencies; an even
//! side's Nyquist line `k = n/2` (a cosine at the `n` grid's pixels) is
//! split in halves between `+n/2` and `−n/2` (a quarter each at the
//! corner), which keeps its value at every coinciding pixel and interpolates
//! it as a cosine between them. The `m × m` DHT over the same nonzero
//! coefficients at the coinciding pixels is then the `n × n` DHT's sum,
//! term for term; only the rounding of the twiddles and the order of the
//! additions differ. The gain is multiplied by `F²` since the finish divides
//! by `m²`.

use fvr_core::dht::{mixed_table_len, MixedPlan, Twiddles};
use fvr_core::error::{Error, Result};
use fvr_core::image::{grid_len, Crop, Inverse, Placement};
use fvr_core::num::Real;

use super::inverse::{finish_threaded, for_row_pairs, shift_tables};

/// The largest zoom factor accepted: beyond it a 128³ volume's image alone
/// would pass 64 M pixels.
pub const MAX_ZOOM: usize = 64;

/// `Ok(m)`, the zoomed grid's side `zoom·n`, if `zoom` is a factor the
/// transforms serve: `1 ..= MAX_ZOOM` with no prime factor above 5 (so
/// `m` stays a radix-2 or mixed-radix side when `n` is one).
///
/// # Errors
/// [`Error::UnsupportedLength`] naming the zoom for any other factor.
pub fn zoomed_side(n: usize, zoom: usize) -> Result<usize> {
    let mut rest = zoom;
    for p in [2, 3, 5] {
        while rest > 1 && rest % p == 0 {
            rest /= p;
        }
    }
    if zoom == 0 || zoom > MAX_ZOOM || rest != 1 {
        return Err(Error::UnsupportedLength { len: zoom });
    }
    n.checked_mul(zoom)
        .ok_or(Error::UnsupportedLength { len: zoom })
}

/// The zoomed finish for one slice side and factor: the `m × m` padded
/// grid, its transposed copy and the transform's table, kept between views.
#[derive(Debug)]
pub struct ZoomFinish<T> {
    n: usize,
    zoom: usize,
    m: usize,
    table: Vec<T>,
    padded: Vec<T>,
    trans: Vec<T>,
}

impl<T: Real> ZoomFinish<T> {
    /// Buffers for slices of side `n` magnified `zoom` times.
    ///
    /// # Errors
    /// A factor [`zoomed_side`] refuses, or a side `zoom·n` no transform
    /// serves.
    pub fn new(n: usize, zoom: usize) -> Result<Self> {
        let m = zoomed_side(n, zoom)?;
        let table = if m.is_power_of_two() {
            let mut tw = vec![T::ZERO; Twiddles::<T>::buffer_len(m)];
            Twiddles::new(&mut tw, m)?;
            tw
        } else {
            let mut table = vec![T::ZERO; mixed_table_len(m)];
            MixedPlan::new(&mut table, m)?;
            table
        };
        Ok(Self {
            n,
            zoom,
            m,
            table,
            padded: vec![T::ZERO; grid_len(m)],
            trans: vec![T::ZERO; grid_len(m)],
        })
    }

    /// The slice side and zoom these buffers serve.
    pub fn serves(&self, n: usize, zoom: usize) -> bool {
        self.n == n && self.zoom == zoom
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        (self.table.len() + self.padded.len() + self.trans.len()) * std::mem::size_of::<T>()
    }

    /// Finish the filled `n × n` slice `grid` (overwritten) as a zoomed
    /// image into `out`: `crop` is the unzoomed image's (its placement,
    /// gain and `width × height`, the field of view), `out` holds
    /// `zoom·width × zoom·height` pixels of `crop.channels`.
    ///
    /// # Errors
    /// Short buffers, or a crop [`fvr_core::image::check_image`] refuses.
    pub fn finish(&mut self, grid: &mut [T], crop: &Crop, out: &mut [T]) -> Result<()> {
        let (n, f, m) = (self.n, self.zoom, self.m);
        fvr_core::image::check_image(crop.width, crop.height, n)?;
        if grid.len() < grid_len(n) {
            return Err(Error::BufferTooSmall {
                what: "slice grid",
                needed: grid_len(n),
                got: grid.len(),
            });
        }
        let grid = &mut grid[..n * n];
        if let Some(t) = shift_tables::<T>(n, crop.place.shift) {
            for_row_pairs(grid, n, |y, row, mirror, _| t.shift_rows(y, row, mirror));
        }
        pad(grid, n, m, &mut self.padded);
        let zoomed = Crop {
            place: Placement {
                col0: crop.place.col0 * f as i64,
                row0: crop.place.row0 * f as i64,
                shift: [0.0, 0.0],
            },
            gain: crop.gain * (f * f) as f64,
            width: crop.width * f,
            height: crop.height * f,
            ..*crop
        };
        let (radix2, mixed);
        let inverse = if m.is_power_of_two() {
            radix2 = Twiddles::from_table(&self.table, m)?;
            Inverse::Radix2(&radix2)
        } else {
            mixed = MixedPlan::from_table(&self.table, m)?;
            Inverse::Mixed(&mixed)
        };
        finish_threaded(&mut self.padded, m, &zoomed, inverse, &mut self.trans, out)
    }
}

/// Where signed frequency index `k` of side `n` lands on side `m ≥ n`, and
/// with what weight: `[(index, weight); 2]`, the second weight 0 unless
/// `k` is an even side's Nyquist index, which is split in halves.
fn targets(k: usize, n: usize, m: usize) -> [(usize, f64); 2] {
    if 2 * k == n {
        return [(k, 0.5), (m - k, 0.5)];
    }
    let to = if 2 * k < n { k } else { m - (n - k) };
    [(to, 1.0), (0, 0.0)]
}

/// Copy the `n × n` Hartley slice `grid` into the zeroed `m × m` `padded`
/// at the same signed frequencies (Nyquist lines split, [`targets`]).
fn pad<T: Real>(grid: &[T], n: usize, m: usize, padded: &mut [T]) {
    padded.fill(T::ZERO);
    for ky in 0..n {
        for (my, wy) in targets(ky, n, m) {
            if wy == 0.0 {
                continue;
            }
            for kx in 0..n {
                for (mx, wx) in targets(kx, n, m) {
                    if wx == 0.0 {
                        continue;
                    }
                    let v = grid[ky * n + kx];
                    // Halves and quarters are exact.
                    padded[my * m + mx] += if wx * wy == 1.0 {
                        v
                    } else {
                        v * T::from_f64(wx * wy)
                    };
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_the_transforms_serve() {
        assert_eq!(zoomed_side(128, 1).unwrap(), 128);
        assert_eq!(zoomed_side(128, 4).unwrap(), 512);
        assert_eq!(zoomed_side(160, 3).unwrap(), 480);
        for bad in [0, 7, 11, MAX_ZOOM + 1] {
            assert!(zoomed_side(128, bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn nyquist_lines_split_in_halves() {
        assert_eq!(targets(2, 4, 8), [(2, 0.5), (6, 0.5)]);
        assert_eq!(targets(3, 4, 8), [(7, 1.0), (0, 0.0)]);
        assert_eq!(targets(1, 3, 6), [(1, 1.0), (0, 0.0)]);
        assert_eq!(targets(2, 3, 6), [(5, 1.0), (0, 0.0)]);
        let grid: Vec<f64> = (0..16).map(|v| v as f64).collect();
        let mut padded = vec![0.0; 64];
        pad(&grid, 4, 8, &mut padded);
        let sum: f64 = padded.iter().sum();
        assert_eq!(sum, grid.iter().sum::<f64>());
        // The corner (2, 2) = 10 in quarters at (±2, ±2).
        for (y, x) in [(2, 2), (2, 6), (6, 2), (6, 6)] {
            assert_eq!(padded[y * 8 + x], 2.5);
        }
    }
}
