//! The IEEE storage types (binary16, bfloat16, binary32, binary64) as
//! [`Sample`]s, and the fast binary16 widening the extraction uses.

use half::{bf16, f16};

use super::Sample;

/// IEEE binary16 bits to the binary32 of the same value, exactly, by
/// exponent rebias: the 15 magnitude bits shifted into binary32 position
/// read as `2^-112` times the value (a binary16 subnormal lands on a
/// binary32 subnormal), so one multiplication by `2^112` rebiases normals
/// and normalizes subnormals, exactly because it is a power of two. Infinity
/// and NaN (exponent all ones) take `half`'s path, which quiets NaNs.
///
/// Bit-identical to `half::f16::to_f32` for all 65,536 patterns (tested
/// exhaustively on the host and, in the firmware, on the Cortex-M4F). It
/// needs subnormal f32 arithmetic: a flush-to-zero FPU mode (FPSCR.FZ on
/// Arm, off at reset) would zero binary16 subnormals.
///
/// Why: `half` converts in software on targets without F16C or FP16
/// (Cortex-M4F, x86-64 without `target-feature=+f16c`) through a branchy
/// path of about 25 instructions; this is about 8, and slice extraction does
/// one per filter tap.
///
/// Off Arm the finite patterns take [`f16_bits_to_f32_finite`] instead,
/// which never forms a binary32 subnormal.
#[inline(always)]
pub fn f16_bits_to_f32(bits: u16) -> f32 {
    const TWO_POW_112: f32 = f32::from_bits((127 + 112) << 23);
    let magnitude = (bits & 0x7FFF) as u32;
    if magnitude >= 0x7C00 {
        return f16::from_bits(bits).to_f32();
    }
    if cfg!(not(target_arch = "arm")) {
        return f16_bits_to_f32_finite(bits);
    }
    let value = f32::from_bits(magnitude << 13) * TWO_POW_112;
    f32::from_bits(value.to_bits() | ((bits as u32 & 0x8000) << 16))
}

/// The finite binary16 `bits` as the binary32 of the same value, exactly,
/// without branches and without forming a binary32 subnormal: normals by
/// rebiasing the exponent in the integer field (`+112`), subnormals (and
/// zero) as their 10-bit mantissa times `2^−24`, an exact integer-to-float
/// conversion and product; a select picks one. Exponent-all-ones patterns
/// come out finite and wrong, which is why it is only for data known to
/// be finite.
///
/// Why: x86-64 cores (Intel's in particular) take a microcode assist of
/// the order of a hundred cycles for each floating-point operation with a
/// subnormal operand, so [`f16_bits_to_f32_raw`], whose binary16
/// subnormals become binary32 subnormals, slows the slice walk several
/// times on smooth volumes whose spectra are mostly small values. The
/// Cortex-M4F's FPU takes subnormals at full speed and keeps the raw path.
#[inline(always)]
pub fn f16_bits_to_f32_finite(bits: u16) -> f32 {
    const TWO_POW_MINUS_24: f32 = f32::from_bits((127 - 24) << 23);
    let magnitude = (bits & 0x7FFF) as u32;
    let normal = f32::from_bits((magnitude << 13) + (112 << 23));
    let subnormal = magnitude as f32 * TWO_POW_MINUS_24;
    let value = if magnitude < 0x0400 {
        subnormal
    } else {
        normal
    };
    f32::from_bits(value.to_bits() | ((bits as u32 & 0x8000) << 16))
}

/// The finite binary16 `bits` as binary32 times `2^−112`, exactly: the
/// rebias of [`f16_bits_to_f32`] without its multiplication by `2^112` and
/// without its infinity/NaN branch. The sign-extending read puts copies of
/// the sign in bits 28–31 after the shift; clearing bits 28–30 leaves the
/// sign in bit 31 over the 15 magnitude bits. Three integer instructions
/// on a Cortex-M4F; exponent-all-ones patterns come out finite and wrong,
/// which is why it is only for data known to be finite.
#[inline(always)]
pub fn f16_bits_to_f32_raw(bits: u16) -> f32 {
    f32::from_bits((((bits as i16 as i32) << 13) as u32) & 0x8FFF_FFFF)
}

/// [`Sample`] for a 16-bit type of `half`: its bit pattern and `half`'s
/// conversions; `$extra` holds the items that differ (the widening to f32,
/// and for binary16 its raw form).
macro_rules! impl_sample_half {
    ($t:ident, $name:literal, $max_finite:expr, { $($extra:tt)* }) => {
        impl Sample for $t {
            const NAME: &'static str = $name;
            const BITS: u32 = 16;
            const SCALE_LOG2: i32 = 14;
            const MAX_FINITE: f64 = $max_finite;
            $($extra)*
            #[inline(always)]
            fn pattern16(self) -> Option<u16> {
                Some(self.to_bits())
            }
            #[inline(always)]
            fn from_pattern16(p: u16) -> Option<Self> {
                Some($t::from_bits(p))
            }
            #[inline(always)]
            fn from_f32(v: f32) -> Self {
                $t::from_f32(v)
            }
            #[inline(always)]
            fn from_f64(v: f64) -> Self {
                $t::from_f64(v)
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                $t::to_f64(self)
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                $t::is_finite(self)
            }
        }
    };
}

impl_sample_half!(f16, "f16", 65504.0, {
    /// The raw rebias ([`f16_bits_to_f32_raw`]) on Arm; elsewhere the value
    /// itself ([`f16_bits_to_f32_finite`]), whose operands are never
    /// subnormal. Either way the products of the hot loops are the same
    /// bits: a power of two moved between the factors of an exact product.
    const RAW_EXPONENT_F32: i32 = if cfg!(target_arch = "arm") { 112 } else { 0 };
    #[inline(always)]
    fn to_f32_raw(self) -> f32 {
        if cfg!(target_arch = "arm") {
            f16_bits_to_f32_raw(self.to_bits())
        } else {
            f16_bits_to_f32_finite(self.to_bits())
        }
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        f16_bits_to_f32(self.to_bits())
    }
});

impl Sample for f32 {
    const NAME: &'static str = "f32";
    const BITS: u32 = 32;
    const SCALE_LOG2: i32 = 14;
    const MAX_FINITE: f64 = f32::MAX as f64;
    #[inline(always)]
    fn from_f32(v: f32) -> Self {
        v
    }
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}

impl Sample for f64 {
    const NAME: &'static str = "f64";
    const BITS: u32 = 64;
    const SCALE_LOG2: i32 = 14;
    const MAX_FINITE: f64 = f64::MAX;
    #[inline(always)]
    fn from_f32(v: f32) -> Self {
        v as f64
    }
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

impl_sample_half!(bf16, "bf16", 3.389_531_389_251_535_5e38, {
    #[inline(always)]
    fn to_f32(self) -> f32 {
        bf16::to_f32(self)
    }
});
