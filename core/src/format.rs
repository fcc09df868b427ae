//! Storage formats beyond the IEEE types: bfloat16, minifloats of any
//! exponent width, and block floating point.
//!
//! Every format is a [`Sample`], so the one generic transform
//! ([`crate::dht::dht_3d`]), preparation ([`crate::spectrum::Spectrum`]) and
//! slice extraction serve them all; no kernel is written per format.
//!
//! # Minifloats
//! [`Minifloat16<E>`] has 1 sign bit, `E` exponent bits and `15 − E`
//! mantissa bits; [`Minifloat8<E>`] has `7 − E` mantissa bits. Both follow
//! IEEE 754 rules: bias `2^(E−1) − 1`, subnormals, infinities and NaN in the
//! top exponent, round to nearest with ties to even (one rounding from f32
//! or f64). `Minifloat16<5>` is bit for bit IEEE binary16 and
//! `Minifloat16<8>` is bfloat16; the tests prove it over all 65,536
//! patterns. The exponent width is a type parameter, checked at compile
//! time (`2 ≤ E ≤ 8` for 16 bits, `2 ≤ E ≤ 5` for 8 bits): wider exponents
//! would leave the range of the f32 arithmetic, which loads every value of
//! these formats exactly. A split read at run time is checked by
//! [`Format::minifloat`].
//!
//! # Block floating point
//! [`Q15`] and [`Q7`] are signed fractions `i/2^15` and `i/2^7` with a
//! symmetric range; the most negative integer is reserved to flag overflow
//! (it is this format's NaN). Stored alone they are fixed-point numbers
//! whose one exponent is the spectrum's scale. With a [`BlockLayout`] every
//! block (an x-line, or a `b³` brick) shares an exponent, as fixed-point
//! DSPs store FFTs: [`encode_blocks`] rounds a finished spectrum once,
//! picking per block the smallest power of two that keeps the block's
//! largest value in range, and [`LineBlocks`] lets the in-place transform
//! do the same line by line, pass by pass.

use crate::dht::{LineStore, Pass};
use crate::error::{Error, Result};
use crate::real::{Real, Sample};

pub use half::bf16;

impl Sample for bf16 {
    const NAME: &'static str = "bf16";
    const MAX_FINITE: f64 = 3.389_531_389_251_535_5e38;
    const BITS: u32 = 16;
    const SCALE_LOG2: i32 = 14;
    #[inline(always)]
    fn from_f32(v: f32) -> Self {
        bf16::from_f32(v)
    }
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        bf16::from_f64(v)
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        bf16::to_f32(self)
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        bf16::to_f64(self)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        bf16::is_finite(self)
    }
}

/// A sign–exponent–mantissa layout with IEEE 754 semantics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FloatLayout {
    /// Exponent bits.
    pub exponent: u32,
    /// Mantissa (fraction) bits.
    pub mantissa: u32,
}

impl FloatLayout {
    /// Exponent bias, `2^(E−1) − 1`.
    pub const fn bias(self) -> i32 {
        (1 << (self.exponent - 1)) - 1
    }

    /// Exponent of the smallest normal number, `1 − bias`.
    pub const fn min_exponent(self) -> i32 {
        1 - self.bias()
    }

    const fn exp_mask(self) -> u32 {
        (1 << self.exponent) - 1
    }

    /// Largest finite value, `(2 − 2^−M)·2^bias`.
    pub const fn max_finite(self) -> f64 {
        let top = ((1u64 << (self.mantissa + 1)) - 1) as f64;
        top * pow2(self.bias() - self.mantissa as i32)
    }

    /// The scaling exponent `t` (see [`Sample::SCALE_LOG2`]): 14, or less
    /// when the format's range needs it, so that `2^(t+1) ≤ max_finite`.
    pub const fn scale_log2(self) -> i32 {
        let t = self.bias() - 1;
        if t < 14 {
            t
        } else {
            14
        }
    }

    /// Decode a bit pattern (the low `1 + E + M` bits of `bits`) exactly.
    #[inline]
    pub fn decode(self, bits: u32) -> f32 {
        let m = self.mantissa;
        let field = (bits >> m) & self.exp_mask();
        let frac = bits & ((1 << m) - 1);
        let negative = (bits >> (m + self.exponent)) & 1 == 1;
        let magnitude = if field == 0 {
            // Subnormal: frac·2^(emin − M), exact in f32 for E ≤ 8.
            frac as f32 * libm::scalbnf(1.0, self.min_exponent() - m as i32)
        } else if field == self.exp_mask() {
            if frac == 0 {
                f32::INFINITY
            } else {
                f32::NAN
            }
        } else {
            let exp = field as i32 - self.bias() + 127;
            f32::from_bits(((exp as u32) << 23) | (frac << (23 - m)))
        };
        if negative {
            -magnitude
        } else {
            magnitude
        }
    }

    /// Round `v` to this layout, to nearest with ties to even, in one
    /// rounding. Values at or beyond `max_finite` plus half an ulp become
    /// infinite; NaN stays NaN.
    #[inline]
    pub fn encode(self, v: f64) -> u32 {
        let m = self.mantissa;
        let sign = if v.is_sign_negative() {
            1 << (m + self.exponent)
        } else {
            0
        };
        let inf = sign | (self.exp_mask() << m);
        if v.is_nan() {
            return inf | (1 << (m - 1));
        }
        let a = libm::fabs(v);
        if a == f64::INFINITY {
            return inf;
        }
        if a == 0.0 {
            return sign;
        }
        // Unbiased exponent of `a` (f64 subnormals give −1023 and round to 0).
        let ea = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
        let mut quantum = ea.max(self.min_exponent()) - m as i32;
        // a·2^−quantum < 2^(M+1) is exact in f64; rint rounds it to nearest even.
        let mut r = libm::rint(libm::scalbn(a, -quantum)) as u32;
        if r == 1 << (m + 1) {
            r >>= 1;
            quantum += 1;
        }
        if r < 1 << m {
            return sign | r;
        }
        let field = quantum + m as i32 + self.bias();
        if field >= self.exp_mask() as i32 {
            return inf;
        }
        sign | ((field as u32) << m) | (r - (1 << m))
    }
}

const fn pow2(k: i32) -> f64 {
    let mut v = 1.0;
    let mut i = 0;
    if k >= 0 {
        while i < k {
            v *= 2.0;
            i += 1;
        }
    } else {
        while i < -k {
            v *= 0.5;
            i += 1;
        }
    }
    v
}

const MINIFLOAT16_NAMES: [&str; 9] = [
    "", "", "e2m13", "e3m12", "e4m11", "e5m10", "e6m9", "e7m8", "e8m7",
];
const MINIFLOAT8_NAMES: [&str; 6] = ["", "", "e2m5", "e3m4", "e4m3", "e5m2"];

/// A 16-bit float with `E` exponent bits and `15 − E` mantissa bits (module
/// docs). `2 ≤ E ≤ 8`, checked at compile time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Minifloat16<const E: u32>(pub u16);

impl<const E: u32> Minifloat16<E> {
    /// The bit layout.
    pub const LAYOUT: FloatLayout = {
        assert!(
            E >= 2 && E <= 8,
            "16-bit minifloats need 2 to 8 exponent bits"
        );
        FloatLayout {
            exponent: E,
            mantissa: 15 - E,
        }
    };

    /// The value with these bits.
    pub const fn from_bits(bits: u16) -> Self {
        Self(bits)
    }

    /// The bit pattern.
    pub const fn to_bits(self) -> u16 {
        self.0
    }
}

impl<const E: u32> Sample for Minifloat16<E> {
    const NAME: &'static str = MINIFLOAT16_NAMES[E as usize];
    const MAX_FINITE: f64 = Self::LAYOUT.max_finite();
    const BITS: u32 = 16;
    const SCALE_LOG2: i32 = Self::LAYOUT.scale_log2();
    #[inline]
    fn from_f32(v: f32) -> Self {
        Self(Self::LAYOUT.encode(v as f64) as u16)
    }
    #[inline]
    fn from_f64(v: f64) -> Self {
        Self(Self::LAYOUT.encode(v) as u16)
    }
    #[inline]
    fn to_f32(self) -> f32 {
        Self::LAYOUT.decode(self.0 as u32)
    }
    #[inline]
    fn to_f64(self) -> f64 {
        Self::LAYOUT.decode(self.0 as u32) as f64
    }
    #[inline]
    fn is_finite(self) -> bool {
        (self.0 >> Self::LAYOUT.mantissa) as u32 & ((1 << E) - 1) != (1 << E) - 1
    }
}

/// An 8-bit float with `E` exponent bits and `7 − E` mantissa bits (module
/// docs). `2 ≤ E ≤ 5`, checked at compile time. `Minifloat8<4>` is the
/// e4m3 layout with IEEE rules (largest value 240).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Minifloat8<const E: u32>(pub u8);

impl<const E: u32> Minifloat8<E> {
    /// The bit layout.
    pub const LAYOUT: FloatLayout = {
        assert!(
            E >= 2 && E <= 5,
            "8-bit minifloats need 2 to 5 exponent bits"
        );
        FloatLayout {
            exponent: E,
            mantissa: 7 - E,
        }
    };
}

impl<const E: u32> Sample for Minifloat8<E> {
    const NAME: &'static str = MINIFLOAT8_NAMES[E as usize];
    const MAX_FINITE: f64 = Self::LAYOUT.max_finite();
    const BITS: u32 = 8;
    const SCALE_LOG2: i32 = Self::LAYOUT.scale_log2();
    #[inline]
    fn from_f32(v: f32) -> Self {
        Self(Self::LAYOUT.encode(v as f64) as u8)
    }
    #[inline]
    fn from_f64(v: f64) -> Self {
        Self(Self::LAYOUT.encode(v) as u8)
    }
    #[inline]
    fn to_f32(self) -> f32 {
        Self::LAYOUT.decode(self.0 as u32)
    }
    #[inline]
    fn to_f64(self) -> f64 {
        Self::LAYOUT.decode(self.0 as u32) as f64
    }
    #[inline]
    fn is_finite(self) -> bool {
        (self.0 >> Self::LAYOUT.mantissa) as u32 & ((1 << E) - 1) != (1 << E) - 1
    }
}

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

/// Which values of a cube of side `n` share a block exponent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockLayout {
    /// One exponent per x-line of `n` values (`n²` exponents).
    Line,
    /// One exponent per `b × b × b` brick (`(n/b)³` exponents).
    Brick(usize),
}

impl BlockLayout {
    /// Exponents needed for a cube of side `n`.
    ///
    /// # Errors
    /// A brick side of 0, or one that does not divide `n`
    /// ([`Error::BlockSizeMismatch`]).
    pub fn exponent_count(self, n: usize) -> Result<usize> {
        match self {
            BlockLayout::Line => Ok(n * n),
            BlockLayout::Brick(b) => {
                if b == 0 || n % b != 0 {
                    return Err(block_mismatch(b, n));
                }
                let m = n / b;
                Ok(m * m * m)
            }
        }
    }

    /// Index of the block holding `(x, y, z)` in a cube of side `n`.
    #[inline(always)]
    pub fn block_of(self, n: usize, x: usize, y: usize, z: usize) -> usize {
        match self {
            BlockLayout::Line => y + n * z,
            BlockLayout::Brick(b) => {
                let m = n / b;
                x / b + m * (y / b + m * (z / b))
            }
        }
    }
}

#[cold]
fn block_mismatch(block: usize, line: usize) -> Error {
    Error::BlockSizeMismatch { block, line }
}

/// Block exponents of a block-floating-point spectrum.
#[derive(Clone, Copy, Debug)]
pub struct BlockExponents<'a> {
    layout: BlockLayout,
    exponents: &'a [i8],
}

impl<'a> BlockExponents<'a> {
    /// Wrap `exponents` for a cube of side `n`.
    ///
    /// # Errors
    /// A brick that does not divide `n`, or a table of the wrong length.
    pub fn new(layout: BlockLayout, exponents: &'a [i8], n: usize) -> Result<Self> {
        let count = layout.exponent_count(n)?;
        if exponents.len() != count {
            return Err(crate::error::mismatch(
                "block exponents",
                count,
                exponents.len(),
            ));
        }
        Ok(Self { layout, exponents })
    }

    /// How values are grouped.
    pub fn layout(&self) -> BlockLayout {
        self.layout
    }

    /// The exponents, one per block.
    pub fn exponents(&self) -> &'a [i8] {
        self.exponents
    }
}

/// Round the spectrum `src` (a cube of side `n`, `x` fastest) to block
/// floating point: per block, the exponent `e` is the smallest that keeps
/// `max|v|·2^−e` within the mantissa's range, and each value is stored as the
/// mantissa nearest `v·2^−e` (one rounding). Exponents are clamped to
/// `[−128, 127]`; a block whose largest value is below `2^−128` (all of it
/// under the mantissa's last bit then) rounds towards zero.
///
/// # Errors
/// `M` is not a block mantissa, buffer lengths do not match `n` and `layout`,
/// or a value is NaN, infinite or beyond `2^127` ([`Error::Overflow`]).
pub fn encode_blocks<T: Real, M: Sample>(
    src: &[T],
    n: usize,
    layout: BlockLayout,
    mantissas: &mut [M],
    exponents: &mut [i8],
) -> Result<()> {
    if !M::BLOCK_MANTISSA {
        return Err(Error::UnsupportedFormat {
            format: M::NAME,
            reason: "block exponents need an integer mantissa format (q15 or q7)",
        });
    }
    let cube = n * n * n;
    let blocks = layout.exponent_count(n)?;
    for (what, len) in [
        ("block source", src.len()),
        ("block mantissas", mantissas.len()),
    ] {
        if len != cube {
            return Err(crate::error::mismatch(what, cube, len));
        }
    }
    if exponents.len() != blocks {
        return Err(crate::error::mismatch(
            "block exponents",
            blocks,
            exponents.len(),
        ));
    }
    match layout {
        BlockLayout::Line => {
            for ((line, out), e) in src
                .chunks_exact(n)
                .zip(mantissas.chunks_exact_mut(n))
                .zip(exponents.iter_mut())
            {
                let max = line
                    .iter()
                    .fold(0.0f64, |a, v| a.max(libm::fabs(v.to_f64())));
                *e = block_exponent::<M>(max)?;
                let k = libm::scalbn(1.0, -(*e as i32));
                for (o, v) in out.iter_mut().zip(line) {
                    *o = M::from_f64(v.to_f64() * k);
                }
            }
        }
        BlockLayout::Brick(b) => {
            let m = n / b;
            for bz in 0..m {
                for by in 0..m {
                    for bx in 0..m {
                        let cells = |f: &mut dyn FnMut(usize)| {
                            for z in bz * b..(bz + 1) * b {
                                for y in by * b..(by + 1) * b {
                                    let row = n * (y + n * z);
                                    for x in bx * b..(bx + 1) * b {
                                        f(row + x);
                                    }
                                }
                            }
                        };
                        let mut max = 0.0f64;
                        cells(&mut |i| max = max.max(libm::fabs(src[i].to_f64())));
                        let e = block_exponent::<M>(max)?;
                        exponents[bx + m * (by + m * bz)] = e;
                        let k = libm::scalbn(1.0, -(e as i32));
                        cells(&mut |i| mantissas[i] = M::from_f64(src[i].to_f64() * k));
                    }
                }
            }
        }
    }
    Ok(())
}

/// The smallest exponent `e ∈ [−128, 127]` with `M::from_f64(max·2^−e)` finite.
fn block_exponent<M: Sample>(max: f64) -> Result<i8> {
    if !max.is_finite() {
        return Err(Error::Overflow {
            stage: "block encoding (a non-finite coefficient)",
        });
    }
    if max == 0.0 {
        return Ok(i8::MIN);
    }
    // Start one below the estimate and step up: the estimate may be off by
    // one at powers of two, and rounding may carry into the next binade.
    let guess = libm::ceil(libm::log2(max / M::MAX_FINITE)) as i32 - 1;
    let mut e = guess.clamp(i8::MIN as i32, i8::MAX as i32);
    while !M::from_f64(libm::scalbn(max, -e)).is_finite() {
        if e >= i8::MAX as i32 {
            return Err(Error::Overflow {
                stage: "block encoding (a coefficient beyond 2^127)",
            });
        }
        e += 1;
    }
    Ok(e as i8)
}

/// Round every value of `src`, multiplied by `factor` (exactly, in f64), to
/// the format `S` in one rounding.
///
/// # Errors
/// Lengths differ, or a value overflows `S` ([`Error::Overflow`]).
pub fn encode_elements<T: Real, S: Sample>(src: &[T], factor: f64, dst: &mut [S]) -> Result<()> {
    if src.len() != dst.len() {
        return Err(crate::error::mismatch(
            "encoded values",
            src.len(),
            dst.len(),
        ));
    }
    let mut finite = true;
    for (d, v) in dst.iter_mut().zip(src) {
        *d = S::from_f64(v.to_f64() * factor);
        finite &= d.is_finite();
    }
    if finite {
        Ok(())
    } else {
        Err(Error::Overflow {
            stage: "final rounding to the storage format",
        })
    }
}

/// How the values of a spectrum share exponents.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blocking {
    /// One exponent for the whole spectrum: its power-of-two scale.
    /// For Q15/Q7 this is plain fixed point.
    Volume,
    /// Block floating point with this layout.
    Blocks(BlockLayout),
}

/// How the 3D transform rounds to the storage format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arithmetic {
    /// In place over the storage, with f32 line buffers, rounding once per
    /// pass (x, y, and z fused with the Hao–Bracewell correction).
    PerPass,
    /// As `PerPass`, and also rounding every line to the storage format
    /// after every radix-2 butterfly stage.
    PerStage,
    /// On the host: transform in f32 storage (rounding per pass to f32),
    /// then round once to the storage format, to ship to a target.
    HostOnce,
}

impl Arithmetic {
    /// Every mode.
    pub const ALL: [Arithmetic; 3] = [
        Arithmetic::PerPass,
        Arithmetic::PerStage,
        Arithmetic::HostOnce,
    ];

    /// Short name: `per-pass`, `per-stage`, `host-once`.
    pub const fn name(self) -> &'static str {
        match self {
            Arithmetic::PerPass => "per-pass",
            Arithmetic::PerStage => "per-stage",
            Arithmetic::HostOnce => "host-once",
        }
    }
}

/// A storage format chosen at run time (e.g. on a command line); the host
/// dispatches it to the matching [`Sample`] type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// IEEE binary16 ([`half::f16`]), the default.
    F16,
    /// bfloat16 ([`bf16`]).
    Bf16,
    /// [`Minifloat16<E>`] with this `E` (other than 5 and 8, which are
    /// [`Format::F16`] and [`Format::Bf16`]).
    Minifloat16(u32),
    /// [`Minifloat8<E>`] with this `E`.
    Minifloat8(u32),
    /// [`Q15`] mantissas.
    Q15(Blocking),
    /// [`Q7`] mantissas.
    Q7(Blocking),
    /// IEEE binary32.
    F32,
    /// IEEE binary64 (the reference).
    F64,
}

impl Format {
    /// The minifloat with `exponent` and `mantissa` bits plus a sign bit,
    /// 16 or 8 bits in all. `e5m10` is [`Format::F16`], `e8m7` [`Format::Bf16`].
    ///
    /// # Errors
    /// [`Error::BadMinifloatSplit`] if `1 + exponent + mantissa` is neither
    /// 16 nor 8; [`Error::UnsupportedFormat`] for fewer than 2 exponent bits
    /// (no room for both normal numbers and infinities) or for more than the
    /// target's f32 arithmetic can load exactly (8 for 16 bits; 5 for 8 bits,
    /// which must keep 2 mantissa bits for NaN and rounding).
    pub fn minifloat(exponent: u32, mantissa: u32) -> Result<Self> {
        let bits = 1 + exponent as u64 + mantissa as u64;
        if bits != 16 && bits != 8 {
            return Err(Error::BadMinifloatSplit { exponent, mantissa });
        }
        if exponent < 2 {
            return Err(Error::UnsupportedFormat {
                format: "minifloat",
                reason: "a minifloat needs at least 2 exponent bits",
            });
        }
        match (bits, exponent) {
            (16, 5) => Ok(Format::F16),
            (16, 8) => Ok(Format::Bf16),
            (16, e) if e <= 8 => Ok(Format::Minifloat16(e)),
            (16, _) => Err(Error::UnsupportedFormat {
                format: "minifloat",
                reason: "more than 8 exponent bits exceed the range of the target's f32 arithmetic",
            }),
            (_, e) if e <= 5 => Ok(Format::Minifloat8(e)),
            _ => Err(Error::UnsupportedFormat {
                format: "minifloat",
                reason:
                    "an 8-bit minifloat keeps at least 2 mantissa bits (at most 5 exponent bits)",
            }),
        }
    }

    /// Check that this format can be prepared with `arithmetic` for a
    /// target computing in f32, before any work is done.
    ///
    /// # Errors
    /// [`Error::UnsupportedFormat`]: brick exponents cannot follow the
    /// transform's passes in place (per-line exponents can: [`LineBlocks`]),
    /// so bricks are rounded once from a host spectrum
    /// ([`Arithmetic::HostOnce`]); f64 storage cannot be loaded by f32
    /// arithmetic, so it has no target modes; a brick that does not divide the
    /// grid side `n` is [`Error::BlockSizeMismatch`].
    pub fn check(self, arithmetic: Arithmetic, n: usize) -> Result<()> {
        match self {
            Format::Q15(Blocking::Blocks(layout)) | Format::Q7(Blocking::Blocks(layout)) => {
                layout.exponent_count(n)?;
                if matches!(layout, BlockLayout::Brick(_)) && arithmetic != Arithmetic::HostOnce {
                    return Err(Error::UnsupportedFormat {
                        format: "block floating point per brick",
                        reason: "brick exponents are chosen once, from a host spectrum (host-once)",
                    });
                }
            }
            Format::F64 if arithmetic != Arithmetic::PerPass => {
                return Err(Error::UnsupportedFormat {
                    format: "f64",
                    reason: "f64 is the host reference; a target's f32 arithmetic cannot load it",
                });
            }
            _ => {}
        }
        Ok(())
    }

    /// Bytes per voxel of a spectrum of side `n`, block exponents included
    /// (one byte each).
    pub fn bytes_per_voxel(self, n: usize) -> f64 {
        let (bits, blocking) = match self {
            Format::F16 | Format::Bf16 | Format::Minifloat16(_) => (16, Blocking::Volume),
            Format::Minifloat8(_) => (8, Blocking::Volume),
            Format::Q15(b) => (16, b),
            Format::Q7(b) => (8, b),
            Format::F32 => (32, Blocking::Volume),
            Format::F64 => (64, Blocking::Volume),
        };
        let extra = match blocking {
            Blocking::Volume => 0.0,
            Blocking::Blocks(l) => l.exponent_count(n).unwrap_or(0) as f64 / (n * n * n) as f64,
        };
        bits as f64 / 8.0 + extra
    }

    /// Unit roundoff `u` of an element format (half an ulp relative to the
    /// value); `None` for fixed-point and block formats, whose error is
    /// absolute within a block.
    pub fn unit_roundoff(self) -> Option<f64> {
        let m = match self {
            Format::F16 => 10,
            Format::Bf16 => 7,
            Format::Minifloat16(e) => 15 - e,
            Format::Minifloat8(e) => 7 - e,
            Format::F32 => 23,
            Format::F64 => 52,
            Format::Q15(_) | Format::Q7(_) => return None,
        };
        Some(libm::scalbn(1.0, -(m as i32) - 1))
    }
}

/// Names of the formats, for messages: `f16`, `bf16`, `e4m11`, `e4m3`,
/// `q15`, `q15-line`, `q15-brick8`, `q7-line`, …
pub struct FormatName(pub Format);

impl core::fmt::Display for FormatName {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let blocking = |f: &mut core::fmt::Formatter<'_>, b: Blocking| match b {
            Blocking::Volume => Ok(()),
            Blocking::Blocks(BlockLayout::Line) => f.write_str("-line"),
            Blocking::Blocks(BlockLayout::Brick(s)) => write!(f, "-brick{s}"),
        };
        match self.0 {
            Format::F16 => f.write_str("f16"),
            Format::Bf16 => f.write_str("bf16"),
            Format::Minifloat16(e) => write!(f, "e{e}m{}", 15 - e),
            Format::Minifloat8(e) => write!(f, "e{e}m{}", 7 - e),
            Format::Q15(b) => {
                f.write_str("q15")?;
                blocking(f, b)
            }
            Format::Q7(b) => {
                f.write_str("q7")?;
                blocking(f, b)
            }
            Format::F32 => f.write_str("f32"),
            Format::F64 => f.write_str("f64"),
        }
    }
}

/// Block floating point with one exponent per line, for the in-place 3D
/// transform ([`crate::dht::dht_3d_store`]), as fixed-point DSPs run FFTs.
///
/// Every stored line is one block: its exponent is chosen from the line's
/// largest value when it is stored (as in [`encode_blocks`]). The transform's
/// passes run along x, y and z in turn, so the blocks follow them: two
/// tables of `n²` exponents alternate — x-lines (and the input) in `a`,
/// y-lines in `b`, z-lines in `a` again — and [`LineBlocks::finish`]
/// re-blocks the spectrum into x-lines in `b`, the layout slice extraction
/// reads ([`BlockLayout::Line`]). Each value is read once and written once
/// per pass, so a pass never mixes exponents of two layouts. The cost is
/// one more rounding (the re-blocking) than element formats have.
#[derive(Debug)]
pub struct LineBlocks<'a, M> {
    mantissas: &'a mut [M],
    a: &'a mut [i8],
    b: &'a mut [i8],
    n: usize,
    reblocking: bool,
}

impl<'a, M: Sample> LineBlocks<'a, M> {
    /// Wrap zeroed mantissas (`n³`) and two exponent tables (`n²` each).
    ///
    /// # Errors
    /// `M` is not a block mantissa, or a length does not match `n`.
    pub fn new(mantissas: &'a mut [M], a: &'a mut [i8], b: &'a mut [i8], n: usize) -> Result<Self> {
        if !M::BLOCK_MANTISSA {
            return Err(Error::UnsupportedFormat {
                format: M::NAME,
                reason: "block exponents need an integer mantissa format (q15 or q7)",
            });
        }
        let plane = n.checked_mul(n).ok_or(Error::VolumeTooLarge {
            dims: [n; 3],
            grid: n,
        })?;
        let cube = plane.checked_mul(n).ok_or(Error::VolumeTooLarge {
            dims: [n; 3],
            grid: n,
        })?;
        crate::error::require_len("block mantissas", cube, mantissas.len())?;
        crate::error::require_len("block exponents", plane, a.len())?;
        crate::error::require_len("block exponent scratch", plane, b.len())?;
        Ok(Self {
            mantissas: &mut mantissas[..cube],
            a: &mut a[..plane],
            b: &mut b[..plane],
            n,
            reblocking: false,
        })
    }

    /// The exponent a value at index `p` is read with during `pass`.
    #[inline(always)]
    fn read_exponent(&self, pass: Pass, p: usize) -> i8 {
        let n = self.n;
        let (x, y, z) = (p % n, (p / n) % n, p / (n * n));
        match (pass, self.reblocking) {
            (_, true) => self.a[x + n * y],
            (Pass::X | Pass::Y, false) => self.a[y + n * z],
            (Pass::Z, false) => self.b[x + n * z],
        }
    }

    /// Re-block the finished spectrum into x-lines: each x-line is read with
    /// its z-line exponents and stored with a new one in the second table.
    /// `line` is scratch of `n` values. The final exponents are then in the
    /// second table (`b` of [`LineBlocks::new`]).
    ///
    /// # Errors
    /// [`Error::Overflow`] beyond the exponent range.
    pub fn finish<T: Real>(mut self, line: &mut [T]) -> Result<()> {
        let n = self.n;
        crate::error::require_len("re-blocking scratch", n, line.len())?;
        let line = &mut line[..n];
        self.reblocking = true;
        let mut finite = true;
        for row in 0..n * n {
            LineStore::<T>::load(&self, Pass::X, row * n, 1, line);
            finite &= self.store(Pass::X, row * n, 1, line);
        }
        if !finite {
            return Err(Error::Overflow {
                stage: "re-blocking the spectrum into x-lines",
            });
        }
        Ok(())
    }
}

impl<M: Sample, T: Real> LineStore<T> for LineBlocks<'_, M> {
    #[inline]
    fn load(&self, pass: Pass, base: usize, stride: usize, out: &mut [T]) {
        for (i, o) in out.iter_mut().enumerate() {
            let p = base + i * stride;
            let e = self.read_exponent(pass, p);
            *o = T::load(self.mantissas[p]) * T::exp2i(e as i32);
        }
    }

    fn store(&mut self, pass: Pass, base: usize, stride: usize, line: &[T]) -> bool {
        let n = self.n;
        let max = line
            .iter()
            .fold(0.0f64, |m, v| m.max(libm::fabs(v.to_f64())));
        let Ok(e) = block_exponent::<M>(max) else {
            return false;
        };
        let (x, y, z) = (base % n, (base / n) % n, base / (n * n));
        match (pass, self.reblocking) {
            (_, true) => self.b[y + n * z] = e,
            (Pass::X, false) => self.a[y + n * z] = e,
            (Pass::Y, false) => self.b[x + n * z] = e,
            (Pass::Z, false) => self.a[x + n * y] = e,
        }
        let k = libm::scalbn(1.0, -(e as i32));
        let mut finite = true;
        for (i, v) in line.iter().enumerate() {
            let m = M::from_f64(v.to_f64() * k);
            finite &= m.is_finite();
            self.mantissas[base + i * stride] = m;
        }
        finite
    }

    fn round(&self, line: &mut [T]) {
        let max = line
            .iter()
            .fold(0.0f64, |m, v| m.max(libm::fabs(v.to_f64())));
        let e = block_exponent::<M>(max).unwrap_or(i8::MAX) as i32;
        let (down, up) = (libm::scalbn(1.0, -e), libm::scalbn(1.0, e));
        for v in line.iter_mut() {
            let m = M::from_f64(v.to_f64() * down);
            // Keep an overflow visible: the reserved pattern decodes as −1.
            *v = T::from_f64(if m.is_finite() {
                m.to_f64() * up
            } else {
                f64::NAN
            });
        }
    }
}
