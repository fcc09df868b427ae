//! Arithmetic and storage number types.
//!
//! [`Real`] is the arithmetic type of a pipeline (f32 on targets, f64 for
//! the host reference). [`Sample`] is the storage type of a spectrum
//! (IEEE binary16 by default). Conversions between them round to nearest,
//! ties to even.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};
use half::f16;

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
    /// into f32, the bits moved into place without the rebias
    /// multiplication of [`f16_bits_to_f32`]). Hot loops fold `2^e` into a
    /// weight once instead of paying for it per sample. Not meaningful for
    /// infinities and NaNs (spectra hold neither: [`crate::spectrum`]).
    fn load_raw<S: Sample>(s: S) -> Self;
    /// The power of two `e` that turns [`Real::load_raw`] into the value.
    fn raw_exponent<S: Sample>() -> i32;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const HALF: Self = 0.5;
    const EPSILON_HALF: f64 = 5.960_464_477_539_063e-8;
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn load<S: Sample>(s: S) -> Self {
        s.to_f32()
    }
    #[inline(always)]
    fn store<S: Sample>(self) -> S {
        S::from_f32(self)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline(always)]
    fn from_usize(n: usize) -> Self {
        n as f32
    }
    #[inline(always)]
    fn from_i32(n: i32) -> Self {
        n as f32
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
    fn trunc_usize(self) -> usize {
        self as usize
    }
    #[inline(always)]
    fn trunc_i32(self) -> i32 {
        self as i32
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
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const HALF: Self = 0.5;
    const EPSILON_HALF: f64 = 1.110_223_024_625_156_5e-16;
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn load<S: Sample>(s: S) -> Self {
        s.to_f64()
    }
    #[inline(always)]
    fn store<S: Sample>(self) -> S {
        S::from_f64(self)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline(always)]
    fn from_usize(n: usize) -> Self {
        n as f64
    }
    #[inline(always)]
    fn from_i32(n: i32) -> Self {
        n as f64
    }
    #[inline(always)]
    fn floor_i64(self) -> i64 {
        libm::floor(self) as i64
    }
    #[inline(always)]
    fn trunc_usize(self) -> usize {
        self as usize
    }
    #[inline(always)]
    fn trunc_i32(self) -> i32 {
        self as i32
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
}

/// Storage format of one spectrum coefficient.
///
/// Besides the IEEE types here, [`crate::format`] has bfloat16, 16-bit and
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
    /// ([`crate::format::BlockLayout`]). Without block exponents they are
    /// fixed-point numbers.
    const BLOCK_MANTISSA: bool = false;
    /// `e` of [`Sample::to_f32_raw`]: 0 unless the format has a cheaper
    /// scaled widening.
    const RAW_EXPONENT_F32: i32 = 0;
    /// A finite value as an f32 times `2^−RAW_EXPONENT_F32`, exactly (see
    /// [`Real::load_raw`]); by default [`Sample::to_f32`].
    #[inline(always)]
    fn to_f32_raw(self) -> f32 {
        self.to_f32()
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
#[inline(always)]
pub fn f16_bits_to_f32(bits: u16) -> f32 {
    const TWO_POW_112: f32 = f32::from_bits((127 + 112) << 23);
    let magnitude = (bits & 0x7FFF) as u32;
    if magnitude >= 0x7C00 {
        return f16::from_bits(bits).to_f32();
    }
    let value = f32::from_bits(magnitude << 13) * TWO_POW_112;
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

impl Sample for f16 {
    const NAME: &'static str = "f16";
    const BITS: u32 = 16;
    const SCALE_LOG2: i32 = 14;
    const MAX_FINITE: f64 = 65504.0;
    const RAW_EXPONENT_F32: i32 = 112;
    #[inline(always)]
    fn to_f32_raw(self) -> f32 {
        f16_bits_to_f32_raw(self.to_bits())
    }
    #[inline(always)]
    fn from_f32(v: f32) -> Self {
        f16::from_f32(v)
    }
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        f16::from_f64(v)
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        f16_bits_to_f32(self.to_bits())
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        f16::to_f64(self)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f16::is_finite(self)
    }
}

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
