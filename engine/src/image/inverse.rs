//! Finishing a view on all cores: the core's [`finish_with`] (sub-pixel
//! shift, true 2D inverse DHT, crop) with every pass split over rayon
//! threads, bit for bit the core's image.
//!
//! The core transforms rows in place, gathers each column into scratch and
//! transforms it, then applies the Hao–Bracewell correction. Here:
//! 1. rows `y` and `−y` go together to a thread, which shifts them (the
//!    shift pairs `(x, y)` with `(−x, −y)`);
//! 2. the rows are transformed: in strips of [`LANES`] rows, each strip's
//!    rows as the lanes of one transform ([`MixedFinish`], even mixed-radix
//!    sides, [`crate::dht::lanes`]), or a pair of rows at a time with the
//!    core's 1D DHT ([`finish_threaded`], any side);
//! 3. a blocked transpose makes every column a contiguous row of `trans`,
//!    and its rows are transformed the same way;
//! 4. rows `u` and `−u` of `trans` go together to a thread, which applies
//!    the correction to their groups of four;
//! 5. the crop reads `trans` in blocks of image rows.
//!
//! Each value meets the same operations on the same operands in the same
//! order as in the core, so the image is identical whatever the number of
//! threads (`host-sim/tests/fast_inverse.rs`).
//!
//! [`finish_with`]: fvr_core::image::finish_with

use fvr_core::dht::{dht, dht_mixed, mixed_scratch_len, mixed_table_len, MixedPlan};
use fvr_core::error::{Error, Result};
use fvr_core::image::{check_image, grid_len, shift_pair, shift_phasors, Crop, Inverse};
use fvr_core::num::Real;
use rayon::prelude::*;

use crate::dht::lanes::{Lanes, LANES};

/// The threaded finish for one mixed-radix side: its plan's table and the
/// transposed grid, kept between views.
#[derive(Debug)]
pub struct MixedFinish<T> {
    n: usize,
    table: Vec<T>,
    trans: Vec<T>,
}

impl<T: Real> MixedFinish<T> {
    /// The table and buffer for side `n` (`2^a·3^b·5^c`, odd too).
    ///
    /// # Errors
    /// A side the mixed-radix transform does not serve.
    pub fn new(n: usize) -> Result<Self> {
        let mut table = vec![T::ZERO; mixed_table_len(n)];
        MixedPlan::new(&mut table, n)?;
        Ok(Self {
            n,
            table,
            trans: vec![T::ZERO; grid_len(n)],
        })
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        (self.table.len() + self.trans.len()) * std::mem::size_of::<T>()
    }

    /// [`fvr_core::image::finish_with`] with [`Inverse::Mixed`] for this
    /// side, on the current rayon pool: the same image bit for bit.
    ///
    /// # Errors
    /// As [`fvr_core::image::finish_with`].
    pub fn finish(&mut self, grid: &mut [T], crop: &Crop, out: &mut [T]) -> Result<()> {
        let n = self.n;
        let plan = MixedPlan::from_table(&self.table, n)?;
        if n % 2 == 1 {
            return finish_threaded(grid, n, crop, Inverse::Mixed(&plan), &mut self.trans, out);
        }
        check(grid, n, crop, &self.trans, out)?;
        let (grid, trans, table) = (&mut grid[..n * n], &mut self.trans[..], &self.table[..]);
        if let Some(t) = shift_tables(n, crop.place.shift) {
            for_row_pairs(grid, n, |y, row, mirror, _| t.shift_rows(y, row, mirror));
        }
        let strips = |data: &mut [T]| {
            data.par_chunks_mut(LANES * n).for_each_init(
                || Lanes::new(n, table),
                |lanes, strip| lanes.dht_rows(strip),
            )
        };
        strips(grid);
        transpose(grid, trans, n);
        strips(trans);
        for_row_pairs(trans, n, |_, row, mirror, _| {
            if let Some(mirror) = mirror {
                hao_bracewell_pair(row, mirror);
            }
        });
        let g = T::from_f64(crop.gain / (n * n) as f64);
        crop_transposed(trans, n, crop, g, out);
        Ok(())
    }
}

/// The checks of [`fvr_core::image::finish_with`] on the buffers.
fn check<T>(grid: &[T], m: usize, crop: &Crop, trans: &[T], out: &[T]) -> Result<()> {
    check_image(crop.width, crop.height, m)?;
    if crop.channel >= crop.channels {
        return Err(Error::LengthMismatch {
            what: "channel index",
            expected: crop.channels,
            got: crop.channel,
        });
    }
    require_len("slice grid", grid_len(m), grid.len())?;
    require_len("transposed grid", grid_len(m), trans.len())?;
    require_len(
        "output image",
        crop.width * crop.height * crop.channels,
        out.len(),
    )
}

/// `Ok` if `got ≥ needed`, else [`Error::BufferTooSmall`] (as the core).
fn require_len(what: &'static str, needed: usize, got: usize) -> Result<()> {
    if got >= needed {
        Ok(())
    } else {
        Err(Error::BufferTooSmall { what, needed, got })
    }
}

/// Rows and columns of the tiles the transpose and the crop move at a time.
const BLOCK: usize = 16;

/// [`fvr_core::image::finish_with`] on the current rayon pool, a pair of
/// lines at a time through the core's 1D transforms: the same image, bit
/// for bit, from the filled `m × m` slice `grid` (overwritten)
/// through `trans` ([`grid_len`]`(m)` elements of scratch) into `out`
/// (`width·height·channels`). Needs no `aux`; any side the transform
/// serves, odd ones too. Rows that are `+0` after the shift take the
/// transform of such a row, computed once.
///
/// # Errors
/// As [`fvr_core::image::finish_with`].
pub fn finish_threaded<T: Real>(
    grid: &mut [T],
    m: usize,
    crop: &Crop,
    inverse: Inverse<'_, T>,
    trans: &mut [T],
    out: &mut [T],
) -> Result<()> {
    check(grid, m, crop, trans, out)?;
    inverse.check(m)?;
    let grid = &mut grid[..m * m];
    let trans = &mut trans[..m * m];
    let tables = shift_tables(m, crop.place.shift);
    // A row of +0 (rows of a weak slice outside its strong disc) transforms
    // to the same bits every time: copied, not transformed.
    let mut zero = vec![T::ZERO; m];
    line(&mut zero, &mut vec![T::ZERO; mixed_scratch_len(m)], inverse);
    let row_pass =
        |row: &mut [T], scratch: &mut [T]| match row.iter().all(|v| v.to_f64().to_bits() == 0) {
            true => row.copy_from_slice(&zero),
            false => line(row, scratch, inverse),
        };
    for_row_pairs(grid, m, |y, row, mut mirror, scratch| {
        if let Some(t) = &tables {
            t.shift_rows(y, row, mirror.as_deref_mut());
        }
        row_pass(row, scratch);
        if let Some(mirror) = mirror {
            row_pass(mirror, scratch);
        }
    });
    transpose(grid, trans, m);
    for_row_pairs(trans, m, |_, row, mirror, scratch| {
        line(row, scratch, inverse);
        if let Some(mirror) = mirror {
            line(mirror, scratch, inverse);
            hao_bracewell_pair(row, mirror);
        }
    });
    let g = T::from_f64(crop.gain / (m * m) as f64);
    crop_transposed(trans, m, crop, g, out);
    Ok(())
}

/// The 1D forward DHT of one line by the core's transform.
fn line<T: Real>(data: &mut [T], scratch: &mut [T], inverse: Inverse<'_, T>) {
    // The plan was checked against the side; lines have that length.
    let done = match inverse {
        Inverse::Radix2(tw) => dht(data, tw),
        Inverse::Mixed(plan) => dht_mixed(data, scratch, plan),
    };
    debug_assert!(done.is_ok());
}

/// `job(y, row y, row −y, scratch)` for `y = 0 ..= m/2` on rayon threads,
/// `row −y` `None` where `y ≡ −y`; `scratch` holds a 1D transform's
/// scratch ([`mixed_scratch_len`]`(m)`).
pub(super) fn for_row_pairs<T: Real>(
    data: &mut [T],
    m: usize,
    job: impl Fn(usize, &mut [T], Option<&mut [T]>, &mut [T]) + Sync,
) {
    let mut rows: Vec<Option<&mut [T]>> = data.chunks_exact_mut(m).map(Some).collect();
    let mut pairs = Vec::with_capacity(m / 2 + 1);
    for y in 0..=m / 2 {
        let ym = (m - y) % m;
        let row = rows[y].take();
        let mirror = if ym == y { None } else { rows[ym].take() };
        if let Some(row) = row {
            pairs.push((y, row, mirror));
        }
    }
    pairs.into_par_iter().for_each_init(
        || vec![T::ZERO; mixed_scratch_len(m)],
        |scratch, (y, row, mirror)| job(y, row, mirror, scratch),
    );
}

/// The shift's phase factors per axis: `cos φ`, `sin φ` of
/// `φ = −2π k·t/m` for every `k`, Nyquist without phase, in `libm` as the
/// core computes them.
pub(super) struct ShiftTables<T> {
    m: usize,
    /// `[cx | sx | cy | sy]`, `m` each (`fvr_core::image::shift_phasors`).
    table: Vec<T>,
}

/// The tables for shift `t`, `None` for no shift (the core then leaves the
/// grid as it is).
pub(super) fn shift_tables<T: Real>(m: usize, t: [f64; 2]) -> Option<ShiftTables<T>> {
    if t == [0.0, 0.0] {
        return None;
    }
    let mut table = vec![T::ZERO; 4 * m];
    shift_phasors(m, t, &mut table, |ph| {
        (T::from_f64(libm::cos(ph)), T::from_f64(libm::sin(ph)))
    });
    Some(ShiftTables { m, table })
}

impl<T: Real> ShiftTables<T> {
    /// The Hartley shift `H'(k) = cos φ·H(k) + sin φ·H(−k)` on rows `y`
    /// and `−y` (`mirror`; `None` where they coincide, and the pairs then
    /// lie within the row): the point `(x, y)` of each pair `(x, y)`,
    /// `(−x, −y)` that comes first in the grid carries the phase.
    pub(super) fn shift_rows(&self, y: usize, row: &mut [T], mirror: Option<&mut [T]>) {
        let m = self.m;
        let neg = |k: usize| if k == 0 { 0 } else { m - k };
        let (cx, rest) = self.table.split_at(m);
        let (sx, rest) = rest.split_at(m);
        let (cy, sy) = rest.split_at(m);
        let y_phase = [cy[y], sy[y]];
        let rotate = |x: usize, h: &mut T, hm: &mut T| {
            (*h, *hm) = shift_pair([cx[x], sx[x]], y_phase, (*h, *hm));
        };
        match mirror {
            // y < −y: every point of row y comes first.
            Some(mirror) => {
                for x in 0..m {
                    rotate(x, &mut row[x], &mut mirror[neg(x)]);
                }
            }
            None => {
                for x in 1..m.div_ceil(2) {
                    let (lo, hi) = row.split_at_mut(m - x);
                    rotate(x, &mut lo[x], &mut hi[0]);
                }
            }
        }
    }
}

/// The Hao–Bracewell correction on transposed rows `u` and `−u`
/// (`row[v] = T(u, v)`, `mirror[v] = T(−u, v)`): for each `v` with
/// `v ≢ −v`, the group `a, b, c, d` at `(u, v)`, `(−u, v)`, `(u, −v)`,
/// `(−u, −v)` shares `S = ½[(a + b) + (c + d)]` and each point becomes `S`
/// minus the point diagonally opposite, as in the core.
fn hao_bracewell_pair<T: Real>(row: &mut [T], mirror: &mut [T]) {
    let m = row.len();
    for v in 1..m.div_ceil(2) {
        let vm = m - v;
        let (a, b, c, d) = (row[v], mirror[v], row[vm], mirror[vm]);
        let s = T::HALF * ((a + b) + (c + d));
        row[v] = s - d;
        mirror[v] = s - c;
        row[vm] = s - b;
        mirror[vm] = s - a;
    }
}

/// `dst[c·m + r] = src[r·m + c]` for an `m × m` array, bands of
/// [`BLOCK`] destination rows on rayon threads, in `BLOCK × BLOCK` tiles.
fn transpose<T: Real>(src: &[T], dst: &mut [T], m: usize) {
    dst.par_chunks_mut(BLOCK * m)
        .enumerate()
        .for_each(|(band, rows)| {
            let c0 = band * BLOCK;
            let cols = rows.len() / m;
            for r0 in (0..m).step_by(BLOCK) {
                let r1 = (r0 + BLOCK).min(m);
                for r in r0..r1 {
                    let line = &src[r * m + c0..r * m + c0 + cols];
                    for (c, &v) in line.iter().enumerate() {
                        rows[c * m + r] = v;
                    }
                }
            }
        });
}

/// The core's crop from the transposed grid: image pixel `(col, row)` is
/// grid `(row0 − row, col0 + col)` modulo `m`, `trans[gx·m + gy]`, times
/// `g`; bands of [`BLOCK`] image rows on rayon threads.
fn crop_transposed<T: Real>(trans: &[T], m: usize, crop: &Crop, g: T, out: &mut [T]) {
    let (width, channels, channel) = (crop.width, crop.channels, crop.channel);
    let modulo = |v: i64| v.rem_euclid(m as i64) as usize;
    let col0 = modulo(crop.place.col0);
    let stride = width * channels;
    out[..stride * crop.height]
        .par_chunks_mut(BLOCK * stride)
        .enumerate()
        .for_each(|(band, lines)| {
            let first = band * BLOCK;
            let gys: Vec<usize> = (first..first + lines.len() / stride)
                .map(|row| modulo(crop.place.row0 - row as i64))
                .collect();
            let mut gx = col0;
            for col in 0..width {
                let column = &trans[gx * m..(gx + 1) * m];
                for (r, &gy) in gys.iter().enumerate() {
                    lines[r * stride + col * channels + channel] = column[gy] * g;
                }
                gx += 1;
                if gx == m {
                    gx = 0;
                }
            }
        });
}
