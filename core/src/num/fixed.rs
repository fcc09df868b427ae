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

impl Sample for Q15 {
    const NAME: &'static str = "q15";
    const MAX_FINITE: f64 = 32767.0 / 32768.0;
    const BITS: u32 = 16;
    // Values met during a transform stay within 2^(t+1) = 1/2 < MAX_FINITE.
    const SCALE_LOG2: i32 = -2;
    const BLOCK_MANTISSA: bool = true;
    #[inline]
    fn from_f32(v: f32) -> Self {
        Self::from_f64(v as f64)
    }
    #[inline]
    fn from_f64(v: f64) -> Self {
        Self(fixed_round(v, 15, 32767.0).map_or(i16::MIN, |r| r as i16))
    }
    #[inline]
    fn to_f32(self) -> f32 {
        self.0 as f32 * (1.0 / 32768.0)
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self.0 as f64 / 32768.0
    }
    #[inline]
    fn is_finite(self) -> bool {
        self.0 != i16::MIN
    }
}

impl Sample for Q7 {
    const NAME: &'static str = "q7";
    const MAX_FINITE: f64 = 127.0 / 128.0;
    const BITS: u32 = 8;
    const SCALE_LOG2: i32 = -2;
    const BLOCK_MANTISSA: bool = true;
    #[inline]
    fn from_f32(v: f32) -> Self {
        Self::from_f64(v as f64)
    }
    #[inline]
    fn from_f64(v: f64) -> Self {
        Self(fixed_round(v, 7, 127.0).map_or(i8::MIN, |r| r as i8))
    }
    #[inline]
    fn to_f32(self) -> f32 {
        self.0 as f32 * (1.0 / 128.0)
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self.0 as f64 / 128.0
    }
    #[inline]
    fn is_finite(self) -> bool {
        self.0 != i8::MIN
    }
}
