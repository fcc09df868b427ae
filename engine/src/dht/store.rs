//! Rounding a row of arithmetic values to a storage format, a row at a time
//! ([`StoreFormat`]); for f16 from f32 without branches, so that the loop
//! vectorizes on baseline x86-64 (which has no f32 → f16 instruction).

use fvr_core::num::{Real, Sample};
use half::f16;

use crate::dht::real::FftReal;

/// A storage format the fast preparation writes ([`crate::spectrum::prepare`]).
pub trait StoreFormat: Sample {
    /// Unit roundoff: a value rounded to `Self` in its normal range is within
    /// this share of it.
    const UNIT_ROUNDOFF: f64;
    /// Half the spacing of `Self`'s subnormals: the largest absolute error
    /// of a value rounded below the normal range.
    const SUBNORMAL_HALF_SPACING: f64;
    /// `dst[i] = src[i]` rounded to nearest even; `false` if a value is not
    /// finite in `Self`.
    fn store_row<T: FftReal>(src: &[T], dst: &mut [Self]) -> bool {
        let mut finite = true;
        for (d, &s) in dst.iter_mut().zip(src) {
            *d = s.store();
            finite &= d.is_finite();
        }
        finite
    }
}

impl StoreFormat for f32 {
    const UNIT_ROUNDOFF: f64 = f32::EPSILON as f64 / 2.0;
    // 2^−150.
    const SUBNORMAL_HALF_SPACING: f64 = f32::MIN_POSITIVE as f64 * f32::EPSILON as f64 / 2.0;
}

impl StoreFormat for f64 {
    const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;
    // The spacing itself (2^−1074): half of it is not an f64.
    const SUBNORMAL_HALF_SPACING: f64 = f64::MIN_POSITIVE * f64::EPSILON;
}

impl StoreFormat for f16 {
    const UNIT_ROUNDOFF: f64 = 1.0 / 2048.0;
    // 2^−25.
    const SUBNORMAL_HALF_SPACING: f64 = 1.0 / 33_554_432.0;
    fn store_row<T: FftReal>(src: &[T], dst: &mut [Self]) -> bool {
        if T::EPSILON_HALF != f32::EPSILON_HALF {
            // f64 → f16 must round once, from f64.
            let mut finite = true;
            for (d, &s) in dst.iter_mut().zip(src) {
                *d = s.store();
                finite &= d.is_finite();
            }
            return finite;
        }
        let mut bad = 0u16;
        for (d, &s) in dst.iter_mut().zip(src) {
            // Exact: T is f32 here.
            let bits = f16_bits(s.to_f64() as f32);
            bad |= u16::from(bits & 0x7c00 == 0x7c00);
            *d = f16::from_bits(bits);
        }
        bad == 0
    }
}

/// The binary16 bits of `x` rounded to nearest even (NaN to a quiet NaN).
#[inline(always)]
pub fn f16_bits(x: f32) -> u16 {
    let b = x.to_bits();
    let sign = (b >> 16) & 0x8000;
    let a = b & 0x7fff_ffff;
    // Normal results: rebias the exponent (127 − 15 = 112) and drop 13
    // mantissa bits, adding just under half an ulp plus the kept lsb so that
    // the shift rounds to nearest even (a carry moves into the exponent).
    let normal = (a + 0x0fff + ((a >> 13) & 1)).wrapping_sub(112 << 23) >> 13;
    // Subnormal results are multiples of 2^−24, the ulp of 0.5 in f32: the
    // f32 addition rounds to nearest even, and its low bits are the result.
    let sub = (f32::from_bits(a) + 0.5).to_bits() - 0x3f00_0000;
    let m = if a > 0x7f80_0000 {
        0x7e00
    } else if a >= 0x477f_f000 {
        // At least 65520: rounds to infinity.
        0x7c00
    } else if a >= 0x3880_0000 {
        normal
    } else {
        sub
    };
    (sign | m) as u16
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every f16 value, the f32s next to it, the midpoints to its
    /// neighbours and the f32s next to those: all the rounding boundaries.
    #[test]
    fn f16_bits_matches_half_at_every_boundary() {
        let mut checked = 0u32;
        for h in 0..=0xffffu16 {
            let v = f16::from_bits(h);
            if v.is_nan() {
                assert!(f16::from_bits(f16_bits(v.to_f32())).is_nan());
                continue;
            }
            let next = f16::from_bits(h.wrapping_add(1)).to_f32();
            let mut xs = vec![v.to_f32()];
            if next.is_finite() {
                xs.push((v.to_f32() + next) * 0.5);
            }
            for x in xs.clone() {
                let b = x.to_bits();
                xs.extend([b.wrapping_sub(1), b + 1].map(f32::from_bits));
            }
            for x in xs {
                if x.is_nan() {
                    continue;
                }
                let want = f16::from_f32(x).to_bits();
                assert_eq!(f16_bits(x), want, "{x:e} ({:#x})", x.to_bits());
                checked += 1;
            }
        }
        assert!(checked > 300_000);
        for x in [f32::INFINITY, f32::MAX, 65519.99, 65520.0, 1e-30, 0.0] {
            for s in [x, -x] {
                assert_eq!(f16_bits(s), f16::from_f32(s).to_bits(), "{s:e}");
            }
        }
    }

    #[test]
    fn rows_flag_overflow() {
        let mut out = [f16::ZERO; 3];
        assert!(f16::store_row(&[1.0f32, -2.5, 65504.0], &mut out));
        assert_eq!(out[1].to_f32(), -2.5);
        assert!(!f16::store_row(&[1.0f32, 70000.0, 0.0], &mut out));
        assert!(!f16::store_row(&[1.0f64, 1e6, 0.0], &mut out));
    }
}
