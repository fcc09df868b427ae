//! The storage type of one spectrum coefficient.

use core::fmt::Debug;

/// Storage format of one spectrum coefficient.
///
/// Besides the IEEE types here, [`crate::num`] has bfloat16, 16-bit and
/// 8-bit minifloats of any exponent width, and the Q15/Q7 mantissas of block
/// floating point.
pub trait Sample: Copy + Default + Debug + PartialEq + Send + Sync {
    /// Short name, e.g. `"f16"`.
    const NAME: &'static str;
    /// Largest finite value.
    const MAX_FINITE: f64;
    /// Bits per stored value.
    const BITS: u32;
    /// `t` of the scaling rule ([`crate::spectrum`]): spectra are stored as
    /// `s·H` with `s·Σ|g| ∈ (2^(t−1), 2^t]`. Every value met during the
    /// transform is then at most `2^(t+1)`, which the format must hold:
    /// `2^(t+1) ≤ MAX_FINITE`. 14 for f16 (whose maximum is 65504).
    const SCALE_LOG2: i32;
    /// `true` for the integer mantissas of block floating point, whose value
    /// is multiplied by a power of two shared by a block
    /// ([`crate::num::BlockLayout`]). Without block exponents they are
    /// fixed-point numbers.
    const BLOCK_MANTISSA: bool = false;
    /// `e` of [`Sample::to_f32_raw`]: 0 unless the format has a cheaper
    /// scaled widening.
    const RAW_EXPONENT_F32: i32 = 0;
    /// A finite value as an f32 times `2^−RAW_EXPONENT_F32`, exactly (see
    /// [`super::Real::load_raw`]); by default [`Sample::to_f32`].
    #[inline(always)]
    fn to_f32_raw(self) -> f32 {
        self.to_f32()
    }
    /// The stored bits of a 16-bit IEEE-style format, for tables indexed by
    /// them (a histogram of a spectrum's values); `None` for the others.
    #[inline(always)]
    fn pattern16(self) -> Option<u16> {
        None
    }
    /// The value whose stored bits are `p` ([`Sample::pattern16`]'s
    /// inverse); `None` for formats without 16-bit patterns.
    #[inline(always)]
    fn from_pattern16(_p: u16) -> Option<Self> {
        None
    }
    /// Round an f32 to this format, to nearest even.
    fn from_f32(v: f32) -> Self;
    /// Round an f64 to this format, to nearest even (one rounding).
    fn from_f64(v: f64) -> Self;
    /// Widen to f32 (may round for formats wider than f32).
    fn to_f32(self) -> f32;
    /// Widen to f64 (exact).
    fn to_f64(self) -> f64;
    /// `true` unless NaN or infinite.
    fn is_finite(self) -> bool;
}
