//! The kernel weights of the fixed-point extraction: a phase table in Q15
//! (or fewer fraction bits), read with an integer interpolation.

use crate::error::{mismatch, Error, Result};
use crate::filter::{
    fill_rows, phase_entry, Filter, FilterKind, KernelTable, MAX_WIDTH, TABLE_RESOLUTION,
};
use crate::num::Real;

/// Entries of the widest kernel table: `MAX_WIDTH·1024/2 + 1`.
const ENTRIES_CAP: usize = MAX_WIDTH * TABLE_RESOLUTION / 2 + 1;

/// Bits of the phase fraction the weights are interpolated with.
const FRACTION_BITS: u32 = 14;

/// The largest `Σ_m |w_m|` a weight triple may have: with mantissas of
/// magnitude at most `2^15`, an x-line sum `Σ w·c` stays below `2^31`.
pub(super) const MAX_ABS_SUM: i64 = (1 << 16) - 1;

/// The weights of the `W` taps at every phase `i/1024` in fixed point, as
/// [`crate::filter::PhaseTable`] holds them in floating point: row `i` has
/// `round(k(p + W/2 − 1 − m)·2^F)` for `m = 0 … W−1` and the differences to
/// row `i + 1`, where `k` is the kernel table's entry (the same entries,
/// gathered the same way) and `F` the weight fraction bits
/// ([`FixedPhases::fraction_bits`]): 15, or fewer if a row's weights would
/// sum to more than [`MAX_ABS_SUM`] in magnitude (never for the kernels
/// here; the bound keeps the extraction's overflow proof independent of
/// the kernel).
///
/// A weight at a sample is row `i`'s plus the difference times the
/// position's fraction in 14 bits, rounded down: it lies between the two
/// rows' weights, so its magnitude sum obeys the same bound.
///
/// Built once per filter: the kernel's `W·1024/2 + 1` entries are rounded
/// in `T` (soft float on a core without an FPU), the rest is integer.
#[derive(Clone, Debug)]
pub struct FixedPhases<const W: usize> {
    /// The filter's parts, `oversample` 0 until the table is filled: all
    /// zero bits, so a `static` table starts in `.bss`.
    kind: FilterKind,
    oversample: u32,
    beta: f64,
    fraction_bits: u32,
    rows: [[[i32; W]; 2]; TABLE_RESOLUTION],
}

impl<const W: usize> Default for FixedPhases<W> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const W: usize> FixedPhases<W> {
    /// An empty table (no filter, all weights zero), to be
    /// [`FixedPhases::fill`]ed in place: 24 KiB for `W = 3`, so a device
    /// keeps it in a `static` (this is a `const fn`, and the value is all
    /// zero bits) rather than building it on the stack.
    pub const fn new() -> Self {
        Self {
            kind: FilterKind::Nearest,
            oversample: 0,
            beta: 0.0,
            fraction_bits: 0,
            rows: [[[0; W]; 2]; TABLE_RESOLUTION],
        }
    }

    /// Gather the rows from `kernel` (whose filter becomes this table's),
    /// rounded to the widest fraction that keeps every row within
    /// [`MAX_ABS_SUM`].
    ///
    /// # Errors
    /// As [`FixedPhases::fill_from`].
    pub fn fill<T: Real>(&mut self, kernel: &KernelTable<T>) -> Result<()> {
        self.fill_from(*kernel.filter(), kernel.values())
    }

    /// [`FixedPhases::fill`] from the values [`KernelTable::values`] gives
    /// for `filter` (e.g. a table in flash, read where it is: no copy).
    ///
    /// # Errors
    /// A filter whose width is not `W`, or a number of values other than
    /// [`KernelTable::len_for`] ([`Error::LengthMismatch`]); a NaN or
    /// infinite value ([`Error::NonFiniteTableEntry`]); weights that would
    /// need fewer than 8 fraction bits ([`Error::TableEntryOutOfRange`]).
    /// After an error the table has no filter (the extraction refuses it).
    pub fn fill_from<T: Real>(&mut self, filter: Filter, values: &[T]) -> Result<()> {
        self.oversample = 0;
        let width = filter.width();
        if width != W {
            return Err(mismatch("fixed-point phase table width", width, W));
        }
        let len = KernelTable::<T>::len_for(&filter);
        if values.len() != len {
            return Err(mismatch(
                "fixed-point phase table's kernel",
                len,
                values.len(),
            ));
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFiniteTableEntry {
                what: "fixed-point phase table's kernel",
                index,
            });
        }
        // The kernel's entries rounded once per try (half up, in `T`: the
        // product by a power of two is exact and the entries are at most 1
        // in magnitude here, so `floor(x + ½)` is the rounding of x), then
        // gathered in integers.
        let mut rounded = [0i32; ENTRIES_CAP];
        for bits in (8..=15).rev() {
            let scale = T::from_f64((1u32 << bits) as f64);
            for (r, v) in rounded.iter_mut().zip(values) {
                // Saturates (never wraps) for entries beyond 2^15 (none
                // here): the bound check below then asks for fewer bits.
                *r = (*v * scale + T::HALF)
                    .floor_i64()
                    .clamp(-(1 << 29), 1 << 29) as i32;
            }
            let entry = |i: usize, m: usize| {
                let index = phase_entry::<W>(i, m).unsigned_abs() as usize;
                if index < values.len() {
                    rounded.get(index).copied().unwrap_or(0)
                } else {
                    0
                }
            };
            let mut worst = 0i64;
            fill_rows(&mut self.rows, entry);
            for [weights, differences] in &self.rows {
                let sum: i64 = (0..W)
                    .map(|m| {
                        let (a, b) = (weights[m] as i64, (weights[m] + differences[m]) as i64);
                        a.abs().max(b.abs())
                    })
                    .sum();
                worst = worst.max(sum);
            }
            if worst <= MAX_ABS_SUM {
                self.fraction_bits = bits;
                (self.kind, self.oversample, self.beta) =
                    (filter.kind(), filter.oversample(), filter.beta());
                return Ok(());
            }
        }
        self.rows = [[[0; W]; 2]; TABLE_RESOLUTION];
        Err(Error::TableEntryOutOfRange {
            what: "fixed-point phase table (weights too large for 8 fraction bits)",
            index: 0,
        })
    }

    /// The filter the table was gathered for; `None` until it is filled.
    pub fn filter(&self) -> Option<Filter> {
        if self.oversample == 0 {
            return None;
        }
        Filter::from_parts(self.kind, self.oversample, self.beta).ok()
    }

    /// `F`: a weight `w` stands for `w/2^F`.
    pub fn fraction_bits(&self) -> u32 {
        self.fraction_bits
    }

    /// Taps of the sample at fixed-point position `y`
    /// ([`crate::filter::PhaseTable::fixed_position`]'s 32.32 format): the
    /// first tap's index `j0` and the `W` weights, interpolated between phase
    /// rows `⌊y⌋ mod 1024` and the next by the top 14 bits of the fraction.
    #[inline(always)]
    pub(super) fn taps(&self, y: i64) -> (i32, [i32; W]) {
        let floor = (y >> 32) as i32;
        let f = ((y as u32) >> (32 - FRACTION_BITS)) as i32;
        let row = (floor & (TABLE_RESOLUTION as i32 - 1)) as usize;
        let [p0, dp] = &self.rows[row];
        // |dp·f| < 2^31: weights are below 2^16 in magnitude (so at most
        // 2^17 apart), f below 2^14.
        let weights = core::array::from_fn(|m| p0[m] + ((dp[m] * f) >> FRACTION_BITS));
        ((floor >> TABLE_RESOLUTION.trailing_zeros()) + 1, weights)
    }
}
