//! The stored spectrum: its coefficients, scale, filter and cube side.

use crate::error::{mismatch, require_pow2, Error, Result};
use crate::filter::Filter;
use crate::num::{BlockExponents, BlockLayout, Real, Sample};
use crate::volume::check_side;

/// The side `n` of a spectrum's cube: known at run time (`usize`, what
/// every constructor makes) or at compile time ([`Side`]).
///
/// A compile-time side is for targets with one volume shape, e.g. a table
/// in flash ([`Spectrum::with_side`]): the extraction's index arithmetic
/// then folds to constants and the compiler drops the bounds tests of its
/// tap reads (the 64³ kb3 view on a Cortex-M4F: about 200 k of 1.54 M
/// instructions). Results are the same bit for bit.
pub trait CubeSide: Copy + core::fmt::Debug {
    /// The side.
    fn get(self) -> usize;
}

impl CubeSide for usize {
    #[inline(always)]
    fn get(self) -> usize {
        self
    }
}

/// A cube side fixed at compile time ([`CubeSide`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Side<const N: usize>;

impl<const N: usize> CubeSide for Side<N> {
    #[inline(always)]
    fn get(self) -> usize {
        N
    }
}

/// A 3D Hartley spectrum in storage format `S`, ready to render from, with
/// its cube side held as `Z` ([`CubeSide`]: run time by default).
#[derive(Debug)]
pub struct Spectrum<'a, S, Z = usize> {
    pub(super) data: &'a [S],
    pub(super) n: Z,
    pub(super) scale: f64,
    pub(super) filter: Filter,
    pub(super) dims: [usize; 3],
    pub(super) blocks: Option<BlockExponents<'a>>,
}

impl<'a, S: Sample> Spectrum<'a, S> {
    /// Rebuild a spectrum from stored parts, e.g. a table in flash made at
    /// build time by [`Spectrum::prepare`].
    ///
    /// `n` is [`crate::volume::padded_size`] of the dims for the filter's
    /// oversampling (a power of two), or a mixed-radix side
    /// ([`crate::volume::check_side`], [`crate::volume::GridOversampling`]).
    ///
    /// # Errors
    /// A side that is neither, `data.len() != n³`, dims that do not fit, or
    /// a scale that is not a positive finite number.
    ///
    /// `data` is not scanned (this runs once per view on the host): it must
    /// hold finite values, as [`Spectrum::prepare`] guarantees. Data from
    /// elsewhere goes through [`Spectrum::check_finite`] once; the
    /// extraction's widening ([`Real::load_raw`]) turns an infinity or NaN
    /// into a finite wrong value.
    pub fn from_parts(
        data: &'a [S],
        n: usize,
        scale: f64,
        filter: Filter,
        dims: [usize; 3],
    ) -> Result<Self> {
        check_side(dims, filter.oversample(), n)?;
        if n * n * n != data.len() {
            return Err(mismatch("spectrum storage", n * n * n, data.len()));
        }
        if !(scale.is_finite() && scale > 0.0) {
            return Err(Error::Overflow {
                stage: "spectrum scale (not a positive finite number)",
            });
        }
        Ok(Self {
            data,
            n,
            scale,
            filter,
            dims,
            blocks: None,
        })
    }

    /// Rebuild a block-floating-point spectrum: coefficient
    /// `i` is `data[i]·2^e/s` with `e` its block's exponent (made by
    /// [`crate::num::encode_blocks`]).
    ///
    /// # Errors
    /// As [`Spectrum::from_parts`]; also a side that is not a power of two,
    /// `S` not a block mantissa format, or exponents that do not match `n`
    /// and their layout.
    pub fn from_blocks(
        data: &'a [S],
        blocks: BlockExponents<'a>,
        n: usize,
        scale: f64,
        filter: Filter,
        dims: [usize; 3],
    ) -> Result<Self> {
        // Block layouts and their tables are for power-of-two sides.
        require_pow2("block-floating-point spectrum side", n)?;
        if !S::BLOCK_MANTISSA {
            return Err(Error::UnsupportedFormat {
                format: S::NAME,
                reason: "block exponents need an integer mantissa format (q15 or q7)",
            });
        }
        let mut spec = Self::from_parts(data, n, scale, filter, dims)?;
        BlockExponents::new(blocks.layout(), blocks.exponents(), n)?;
        spec.blocks = Some(blocks);
        Ok(spec)
    }

    /// This spectrum with its side fixed at compile time ([`Side`]), for
    /// the faster extraction [`CubeSide`] describes.
    ///
    /// # Errors
    /// A side other than `N` ([`Error::LengthMismatch`]).
    pub fn with_side<const N: usize>(self) -> Result<Spectrum<'a, S, Side<N>>> {
        if self.n != N {
            return Err(mismatch("spectrum side (compile-time Side<N>)", N, self.n));
        }
        Ok(Spectrum {
            data: self.data,
            n: Side,
            scale: self.scale,
            filter: self.filter,
            dims: self.dims,
            blocks: self.blocks,
        })
    }
}

impl<'a, S: Sample, Z: CubeSide> Spectrum<'a, S, Z> {
    /// `Σ_t w[t]·c[line + x[t]]`: the weighted sum of taps on one x-line
    /// starting at index `line` (a multiple of `n`), with each coefficient's
    /// block exponent applied. Per-line exponents are applied once, to the
    /// sum.
    #[inline(always)]
    pub fn line_taps<T: Real>(&self, line: usize, xs: &[usize], weights: &[T]) -> T {
        let data = self.data;
        let mut acc = T::ZERO;
        let blocks = match self.blocks {
            Some(b) if S::BLOCK_MANTISSA => b,
            _ => {
                for (x, w) in xs.iter().zip(weights) {
                    acc += *w * T::load(data[line + x]);
                }
                return acc;
            }
        };
        let n = self.n.get();
        match blocks.layout() {
            BlockLayout::Line => {
                for (x, w) in xs.iter().zip(weights) {
                    acc += *w * T::load(data[line + x]);
                }
                acc * T::exp2i(blocks.exponents()[line / n] as i32)
            }
            layout => {
                let (y, z) = ((line / n) % n, line / (n * n));
                for (x, w) in xs.iter().zip(weights) {
                    let e = blocks.exponents()[layout.block_of(n, *x, y, z)];
                    acc += *w * T::load(data[line + x]) * T::exp2i(e as i32);
                }
                acc
            }
        }
    }

    /// `Ok` if every stored coefficient is finite: the check for spectra
    /// rebuilt by [`Spectrum::from_parts`] from data that did not come
    /// straight from [`Spectrum::prepare`] (O(n³); once per load, not per
    /// view).
    ///
    /// # Errors
    /// [`Error::NonFiniteTableEntry`] naming the first bad coefficient.
    pub fn check_finite(&self) -> Result<()> {
        match self.data.iter().position(|v| !v.is_finite()) {
            None => Ok(()),
            Some(index) => Err(Error::NonFiniteTableEntry {
                what: "spectrum coefficient",
                index,
            }),
        }
    }

    /// The block exponents, for block floating point.
    pub fn blocks(&self) -> Option<BlockExponents<'a>> {
        self.blocks
    }

    /// Coefficient `i` as stored times its block's power of two (`s·H`).
    pub fn value(&self, i: usize) -> f64 {
        let v = self.data[i].to_f64();
        match self.blocks {
            None => v,
            Some(b) => {
                let n = self.n.get();
                let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
                let e = b.exponents()[b.layout().block_of(n, x, y, z)];
                v * libm::scalbn(1.0, e as i32)
            }
        }
    }

    /// The stored coefficients, `s·H`, `x` fastest.
    pub fn data(&self) -> &'a [S] {
        self.data
    }

    /// Side of the cube.
    #[inline(always)]
    pub fn n(&self) -> usize {
        self.n.get()
    }

    /// The scale `s` of the stored values (a power of two).
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The filter the volume was premultiplied for.
    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// Dimensions of the original volume.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Bytes of coefficient storage held, block exponents included.
    pub fn bytes(&self) -> usize {
        core::mem::size_of_val(self.data) + self.blocks.map_or(0, |b| b.exponents().len())
    }
}
