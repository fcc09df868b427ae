//! Minifloats: IEEE 754 rules in 16 or 8 bits with any exponent width.

use super::Sample;

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

/// [`Sample`] for the minifloat `$ty<E>` stored in `$bits` (`$width` bits,
/// named from `$names`), by its [`FloatLayout`].
macro_rules! minifloat_sample {
    ($ty:ident, $bits:ty, $width:literal, $names:ident) => {
        impl<const E: u32> Sample for $ty<E> {
            const NAME: &'static str = $names[E as usize];
            const MAX_FINITE: f64 = Self::LAYOUT.max_finite();
            const BITS: u32 = $width;
            const SCALE_LOG2: i32 = Self::LAYOUT.scale_log2();
            #[inline]
            fn from_f32(v: f32) -> Self {
                Self(Self::LAYOUT.encode(v as f64) as $bits)
            }
            #[inline]
            fn from_f64(v: f64) -> Self {
                Self(Self::LAYOUT.encode(v) as $bits)
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
    };
}

minifloat_sample!(Minifloat16, u16, 16, MINIFLOAT16_NAMES);
minifloat_sample!(Minifloat8, u8, 8, MINIFLOAT8_NAMES);
