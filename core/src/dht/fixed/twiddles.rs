//! Fixed-point twiddle factors: one quarter-wave sine table in Q15 or Q31
//! for every power-of-two length up to its size.

use super::{twiddle_pair_bound, FixedSample};
use crate::dht::twiddles::{check_serves, fill_quarter, quarter_of};
use crate::error::{Error, Result};

/// Quarter-wave sine table for fixed-point transforms of length up to
/// `len`: `round(sin(2πk/len) · 2^F)` for `k = 0 ..= len/4` in a
/// caller-provided buffer, clamped to `2^F − 1` (the entry `k = len/4` is
/// 1, which the transform never reads, and cosines within half a unit of 1
/// clamp too). Any power-of-two length `n ≤ len` uses every `(len/n)`-th
/// entry.
///
/// # Provenance and accuracy
/// [`FixedTwiddles::new`] computes each entry once with `libm::sin` in f64
/// (error below 1 ulp of f64, so far below the `2^−F` step), then rounds to
/// nearest: each entry is within half a unit of the last place of the true
/// value, or a clamped unit below 1. On a device without an FPU this runs
/// once in soft float; a table stored in flash from the host's output is
/// loaded by [`FixedTwiddles::from_table`]. Both check what the overflow
/// proof of [`super`] relies on: entries in `[0, 2^F − 1]` and every pair
/// `cos + sin ≤ ⌊√2·2^F⌋ + 1`.
#[derive(Debug)]
pub struct FixedTwiddles<'a, S> {
    pub(super) len: usize,
    quarter: &'a [S],
}

impl<'a, S: FixedSample> FixedTwiddles<'a, S> {
    /// Entries a table for transforms of length up to `len` needs.
    pub const fn buffer_len(len: usize) -> usize {
        len / 4 + 1
    }

    /// Fill `buf` with the table for transform lengths up to `len`.
    ///
    /// # Errors
    /// `len` not a power of two, or `buf` shorter than
    /// [`FixedTwiddles::buffer_len`]`(len)`.
    pub fn new(buf: &'a mut [S], len: usize) -> Result<Self> {
        fill_quarter(buf, len, |_, angle| S::from_f64(libm::sin(angle)))?;
        Self::from_table(buf, len)
    }

    /// Wrap a table filled earlier by [`FixedTwiddles::new`] (or stored,
    /// e.g. in flash, from its output) for lengths up to `len`.
    ///
    /// # Errors
    /// `len` not a power of two, `table` shorter than
    /// [`FixedTwiddles::buffer_len`]`(len)`, or an entry out of range
    /// ([`Error::TableEntryOutOfRange`]).
    pub fn from_table(table: &'a [S], len: usize) -> Result<Self> {
        let quarter = quarter_of(table, len)?;
        let max = (1i64 << S::FRAC_BITS) - 1;
        let pair = twiddle_pair_bound(S::FRAC_BITS);
        let q = len / 4;
        for (k, v) in quarter.iter().enumerate() {
            let v = v.to_i64();
            let cos = quarter[q - k.min(q)].to_i64();
            if !(0..=max).contains(&v) || (0 < k && k < q && v + cos > pair) {
                return Err(Error::TableEntryOutOfRange {
                    what: "fixed-point twiddle table",
                    index: k,
                });
            }
        }
        Ok(Self { len, quarter })
    }

    /// Largest transform length this table serves.
    pub fn len(&self) -> usize {
        self.len
    }

    /// `false`: a table always serves at least length 1.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// `(cos, sin)` of `2πk/len` for `0 < k < len/4` (the only angles the
    /// radix-2 stages twiddle by), both in `[0, 2^F − 1]`.
    #[inline(always)]
    pub(super) fn cos_sin(&self, k: usize) -> (S::Wide, S::Wide) {
        let q = self.len / 4;
        (self.quarter[q - k].widen(), self.quarter[k].widen())
    }

    pub(super) fn check(&self, n: usize) -> Result<()> {
        check_serves(self.len, n)
    }
}
