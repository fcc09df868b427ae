//! The storage formats by name: what a spectrum is stored in and how
//! blocked, for callers that pick a format at run time.

use super::{BlockLayout, Real, Sample};
use crate::error::{Error, Result};

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
    /// bfloat16 ([`super::bf16`]).
    Bf16,
    /// [`super::Minifloat16<E>`] with this `E` (other than 5 and 8, which are
    /// [`Format::F16`] and [`Format::Bf16`]).
    Minifloat16(u32),
    /// [`super::Minifloat8<E>`] with this `E`.
    Minifloat8(u32),
    /// [`super::Q15`] mantissas.
    Q15(Blocking),
    /// [`super::Q7`] mantissas.
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
    /// transform's passes in place (per-line exponents can: [`crate::dht::LineBlocks`]),
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
