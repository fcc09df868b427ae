//! Finishing a view into its own slice grid: the one-channel image of
//! [`super::finish_with`] cut in place, so a device needs no image buffer
//! beside the grid.

use super::{apply_shift, check_image, Crop, Inverse};
use crate::error::{require_len, Error, Result};
use crate::num::Real;

/// [`super::finish_with`] for a one-channel image written into `grid`
/// itself: afterwards `grid[..width·height]` holds the image, row 0 at the
/// top, bit for bit the values [`super::finish_with`] writes to its `out`.
///
/// The crop reads grid row `σ(r) = (row0 − r) mod m` for image row `r`, an
/// involution, so the rows are put in place by swapping pairs; each row is
/// then rotated by `col0` through `aux` and packed to `width` values, which
/// only ever writes at or before the row being read.
///
/// # Errors
/// As [`super::finish_with`]; a crop of more than one channel.
pub fn finish_in_grid<T: Real>(
    grid: &mut [T],
    m: usize,
    crop: &Crop,
    inverse: Inverse<'_, T>,
    aux: &mut [T],
) -> Result<()> {
    let Crop {
        place,
        gain,
        width,
        height,
        channels,
        ..
    } = *crop;
    check_image(width, height, m)?;
    if channels != 1 {
        return Err(Error::LengthMismatch {
            what: "channels of an image cut into its grid",
            expected: 1,
            got: channels,
        });
    }
    require_len("slice grid", super::grid_len(m), grid.len())?;
    require_len("auxiliary scratch", super::aux_len(m), aux.len())?;
    if m.is_power_of_two() {
        apply_shift::<true, T>(grid, m, place.shift, aux);
    } else {
        apply_shift::<false, T>(grid, m, place.shift, aux);
    }
    inverse.transform(grid, m, aux)?;
    let g = T::from_f64(gain / (m * m) as f64);
    let modulo = |v: i64| v.rem_euclid(m as i64) as usize;
    let (row0, col0) = (modulo(place.row0), modulo(place.col0));
    for r in 0..height {
        let s = (row0 + m - r) % m;
        if s > r {
            let (head, tail) = grid.split_at_mut(s * m);
            head[r * m..(r + 1) * m].swap_with_slice(&mut tail[..m]);
        }
    }
    let row = &mut aux[..m];
    for r in 0..height {
        row.copy_from_slice(&grid[r * m..(r + 1) * m]);
        let mut gx = col0;
        for o in &mut grid[r * width..(r + 1) * width] {
            *o = row[gx] * g;
            gx += 1;
            if gx == m {
                gx = 0;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
#[path = "in_grid_tests.rs"]
mod tests;
