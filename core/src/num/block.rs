//! Block floating point: one shared exponent per x-line or per brick.

use super::{Real, Sample};
use crate::error::{Error, Result};

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
pub(crate) fn block_exponent<M: Sample>(max: f64) -> Result<i8> {
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
