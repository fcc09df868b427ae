//! The arithmetic type of a pipeline: `f32` on targets, `f64` for the
//! host reference.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

use super::Sample;

/// Arithmetic type of a pipeline: `f32` or `f64`.
pub trait Real:
    Copy
    + Send
    + Sync
    + Default
    + Debug
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// 0.5.
    const HALF: Self;
    /// Unit roundoff, 2^-24 for f32 and 2^-53 for f64.
    const EPSILON_HALF: f64;
    /// Nearest value to `v`.
    fn from_f64(v: f64) -> Self;
    /// Widen to f64 (exact).
    fn to_f64(self) -> f64;
    /// Load a stored sample (exact for formats no wider than `Self`).
    fn load<S: Sample>(s: S) -> Self;
    /// Round to a storage sample, to nearest even.
    fn store<S: Sample>(self) -> S;
    /// `true` unless NaN or infinite.
    fn is_finite(self) -> bool;
    /// Nearest value to `n`.
    fn from_usize(n: usize) -> Self;
    /// Nearest value to `n` (exact for |n| ≤ 2^24 in f32), by the hardware
    /// int → float conversion where there is one; `from_f64(n as f64)`
    /// costs two soft-float calls on a target with no 64-bit FPU.
    fn from_i32(n: i32) -> Self;
    /// Largest integer not above `self`, saturating at the i64 range.
    fn floor_i64(self) -> i64;
    /// Integer part of a non-negative value, saturating.
    fn trunc_usize(self) -> usize;
    /// Integer part (toward zero), saturating at the i32 range, NaN to 0:
    /// one hardware conversion on a Cortex-M4F.
    fn trunc_i32(self) -> i32;
    /// `2^e`, exact for `e` in `[-149, 127]` (f32) or `[-1074, 1023]` (f64).
    fn exp2i(e: i32) -> Self;
    /// A stored *finite* sample as its value times `2^−e`, `e` being
    /// [`Real::raw_exponent`]`::<S>()`: the cheapest exact widening (for f16
    /// into f32 on Arm, the bits moved into place without the rebias
    /// multiplication of [`super::f16_bits_to_f32`]; elsewhere a widening
    /// without subnormal results, [`super::f16_bits_to_f32_finite`]). Hot loops fold `2^e` into a
    /// weight once instead of paying for it per sample. Not meaningful for
    /// infinities and NaNs (spectra hold neither: [`crate::spectrum`]).
    fn load_raw<S: Sample>(s: S) -> Self;
    /// The power of two `e` that turns [`super::Real::load_raw`] into the value.
    fn raw_exponent<S: Sample>() -> i32;
}

/// [`Real`] for the float type `$t` (`v as $t` conversions, which round to
/// nearest even), with its own `EPSILON_HALF` and the methods that differ
/// between the types.
macro_rules! impl_real {
    ($t:ty, $epsilon_half:expr, { $($specific:item)* }) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const HALF: Self = 0.5;
            const EPSILON_HALF: f64 = $epsilon_half;
            #[inline(always)]
            fn from_f64(v: f64) -> Self {
                v as $t
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
            #[inline(always)]
            fn from_usize(n: usize) -> Self {
                n as $t
            }
            #[inline(always)]
            fn from_i32(n: i32) -> Self {
                n as $t
            }
            #[inline(always)]
            fn trunc_usize(self) -> usize {
                self as usize
            }
            #[inline(always)]
            fn trunc_i32(self) -> i32 {
                self as i32
            }
            $($specific)*
        }
    };
}

impl_real!(f32, 5.960_464_477_539_063e-8, {
    #[inline(always)]
    fn load<S: Sample>(s: S) -> Self {
        s.to_f32()
    }
    #[inline(always)]
    fn store<S: Sample>(self) -> S {
        S::from_f32(self)
    }
    /// In the i32 range, by the hardware float → int conversion (a
    /// truncation) and one correction for negative non-integers; `libm`
    /// beyond it and for NaN. Targets without 64-bit float conversions
    /// (Cortex-M4F) would otherwise call `floorf` and a software f32 → i64.
    #[inline(always)]
    fn floor_i64(self) -> i64 {
        const TWO_POW_31: f32 = 2_147_483_648.0;
        if self.abs() < TWO_POW_31 {
            let t = self as i32;
            (t - ((t as f32) > self) as i32) as i64
        } else {
            libm::floorf(self) as i64
        }
    }
    #[inline(always)]
    fn exp2i(e: i32) -> Self {
        libm::scalbnf(1.0, e)
    }
    #[inline(always)]
    fn load_raw<S: Sample>(s: S) -> Self {
        s.to_f32_raw()
    }
    #[inline(always)]
    fn raw_exponent<S: Sample>() -> i32 {
        S::RAW_EXPONENT_F32
    }
});

impl_real!(f64, 1.110_223_024_625_156_5e-16, {
    #[inline(always)]
    fn load<S: Sample>(s: S) -> Self {
        s.to_f64()
    }
    #[inline(always)]
    fn store<S: Sample>(self) -> S {
        S::from_f64(self)
    }
    #[inline(always)]
    fn floor_i64(self) -> i64 {
        libm::floor(self) as i64
    }
    #[inline(always)]
    fn exp2i(e: i32) -> Self {
        libm::scalbn(1.0, e)
    }
    #[inline(always)]
    fn load_raw<S: Sample>(s: S) -> Self {
        s.to_f64()
    }
    #[inline(always)]
    fn raw_exponent<S: Sample>() -> i32 {
        0
    }
});
