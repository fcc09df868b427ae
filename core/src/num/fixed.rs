//! Fixed-point fractions Q15 and Q7, the mantissas of block floating
//! point.

use super::Sample;

/// The 16-bit fraction `i/2^15`, `|i| ≤ 32767`; `i = −32768` flags overflow.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Q15(pub i16);

/// The 8-bit fraction `i/2^7`, `|i| ≤ 127`; `i = −128` flags overflow.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Q7(pub i8);

/// Round `v·2^frac` to nearest even, or `None` beyond `±limit` or NaN.
#[inline]
fn fixed_round(v: f64, frac: i32, limit: f64) -> Option<f64> {
    let r = libm::rint(libm::scalbn(v, frac));
    (libm::fabs(r) <= limit).then_some(r)
}

/// [`Sample`] for the fraction type `$ty`: `i/2^$frac` stored in the
/// signed integer `$int`, whose most negative value flags overflow.
macro_rules! fixed_sample {
    ($ty:ident, $int:ty, $name:literal, $frac:literal) => {
        impl Sample for $ty {
            const NAME: &'static str = $name;
            const MAX_FINITE: f64 = <$int>::MAX as f64 / (1u32 << $frac) as f64;
            const BITS: u32 = <$int>::BITS;
            // Values met during a transform stay within 2^(t+1) = 1/2 < MAX_FINITE.
            const SCALE_LOG2: i32 = -2;
            const BLOCK_MANTISSA: bool = true;
            #[inline]
            fn from_f32(v: f32) -> Self {
                Self::from_f64(v as f64)
            }
            #[inline]
            fn from_f64(v: f64) -> Self {
                Self(fixed_round(v, $frac, <$int>::MAX as f64).map_or(<$int>::MIN, |r| r as $int))
            }
            #[inline]
            fn to_f32(self) -> f32 {
                self.0 as f32 * (1.0 / (1u32 << $frac) as f32)
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self.0 as f64 / (1u32 << $frac) as f64
            }
            #[inline]
            fn is_finite(self) -> bool {
                self.0 != <$int>::MIN
            }
        }
    };
}

fixed_sample!(Q15, i16, "q15", 15);
fixed_sample!(Q7, i8, "q7", 7);
