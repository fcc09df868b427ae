//! Arithmetic and storage number types.
//!
//! [`Real`] is the arithmetic type of a pipeline (f32 on targets, f64 for
//! the host reference). [`Sample`] is the storage type of a spectrum
//! (IEEE binary16 by default). Conversions between them round to nearest,
//! ties to even.
//!
//! Besides the IEEE types there are bfloat16, minifloats of any exponent
//! width, and block floating point. Every format is a [`Sample`], so the
//! one generic transform ([`crate::dht::dht_3d`]), preparation
//! ([`crate::spectrum::Spectrum`]) and slice extraction serve them all; no
//! kernel is written per format.
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
//! largest value in range, and [`crate::dht::LineBlocks`] lets the in-place transform
//! do the same line by line, pass by pass.

mod block;
mod fixed;
mod format;
mod ieee;
mod minifloat;
mod real;
mod sample;

pub use block::{encode_blocks, BlockExponents, BlockLayout};
pub use fixed::{Q15, Q7};
pub use format::{encode_elements, Arithmetic, Blocking, Format, FormatName};
pub use half::{bf16, f16};
pub use ieee::{f16_bits_to_f32, f16_bits_to_f32_finite, f16_bits_to_f32_raw};
pub use minifloat::{FloatLayout, Minifloat16, Minifloat8};
pub use real::Real;
pub use sample::Sample;

pub(crate) use block::block_exponent;
