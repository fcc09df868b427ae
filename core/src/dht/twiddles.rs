//! Twiddle factors: one quarter-wave sine table for every power-of-two
//! length up to its size.

use crate::error::{require_len, require_pow2, Error, Result};
use crate::num::Real;

/// Quarter-wave sine table for transforms of length up to `len`.
///
/// Holds `sin(2πk/len)` for `k = 0 ..= len/4` in a caller-provided buffer.
/// Any power-of-two length `n ≤ len` uses every `(len/n)`-th entry, so one
/// table built for the largest size serves all smaller ones.
///
/// # Provenance and accuracy
/// Entries are computed once by `libm::sin` in f64 (error below 1 ulp of
/// f64), then rounded to `T`: each entry is within 0.5 ulp of `T` of the true
/// value (plus < 1e-16 absolute). Cosines come from the same table by
/// quarter-wave symmetry, so `sin² + cos²` is 1 to that accuracy.
#[derive(Debug)]
pub struct Twiddles<'a, T> {
    pub(super) len: usize,
    quarter: &'a [T],
}

impl<'a, T: Real> Twiddles<'a, T> {
    /// Entries a table for transforms of length up to `len` needs.
    pub const fn buffer_len(len: usize) -> usize {
        len / 4 + 1
    }

    /// Fill `buf` with the table for transform lengths up to `len`.
    ///
    /// # Errors
    /// `len` not a power of two, or `buf` shorter than
    /// [`Twiddles::buffer_len`]`(len)`.
    pub fn new(buf: &'a mut [T], len: usize) -> Result<Self> {
        fill_quarter(buf, len, |k, angle| {
            // Exact symmetric values where the quarter-wave table is tight.
            if 4 * k == len {
                T::ONE
            } else {
                T::from_f64(libm::sin(angle))
            }
        })?;
        Self::from_table(buf, len)
    }

    /// Wrap a table filled earlier by [`Twiddles::new`] (or stored, e.g. in
    /// flash, from its output) for lengths up to `len`.
    ///
    /// # Errors
    /// `len` not a power of two, or `table` shorter than
    /// [`Twiddles::buffer_len`]`(len)`.
    pub fn from_table(table: &'a [T], len: usize) -> Result<Self> {
        let quarter = quarter_of(table, len)?;
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

    /// `(cos, sin)` of `2πk/len` for `k < len/2`.
    #[inline(always)]
    pub(super) fn cos_sin(&self, k: usize) -> (T, T) {
        let q = self.len / 4;
        if k <= q {
            (self.quarter[q - k], self.quarter[k])
        } else {
            (-self.quarter[k - q], self.quarter[2 * q - k])
        }
    }

    pub(crate) fn check(&self, n: usize) -> Result<()> {
        check_serves(self.len, n)
    }
}

/// Fill the first `len/4 + 1` entries of `buf`, a quarter-wave table for
/// lengths up to `len`, with `value(k, 2πk/len)`.
///
/// # Errors
/// `len` not a power of two, or `buf` too short.
pub(super) fn fill_quarter<E>(
    buf: &mut [E],
    len: usize,
    value: impl Fn(usize, f64) -> E,
) -> Result<()> {
    require_pow2("twiddle table length", len)?;
    let entries = len / 4 + 1;
    require_len("twiddle buffer", entries, buf.len())?;
    let step = 2.0 * core::f64::consts::PI / len as f64;
    for (k, slot) in buf[..entries].iter_mut().enumerate() {
        *slot = value(k, step * k as f64);
    }
    Ok(())
}

/// The `len/4 + 1` entries of a quarter-wave `table` for lengths up to
/// `len`.
///
/// # Errors
/// `len` not a power of two, or `table` too short.
pub(super) fn quarter_of<E>(table: &[E], len: usize) -> Result<&[E]> {
    require_pow2("twiddle table length", len)?;
    let entries = len / 4 + 1;
    require_len("twiddle table", entries, table.len())?;
    Ok(&table[..entries])
}

/// A table for lengths up to `table_len` serves a transform of length `n`.
///
/// # Errors
/// `n` not a power of two, or longer than `table_len`.
pub(super) fn check_serves(table_len: usize, n: usize) -> Result<()> {
    require_pow2("transform length", n)?;
    if n > table_len {
        return Err(Error::TwiddlesTooShort {
            table_len,
            needed: n,
        });
    }
    Ok(())
}
