//! The stored 3D Hartley spectrum and its one-time preparation.
//!
//! # Layout
//! A cube of side `n` (a power of two), `x` fastest. Index `k` on an axis
//! holds the signed frequency `k` for `k < n/2` and `k − n` above (DC at
//! index 0). The spatial origin of the transform is the volume's centre: the
//! volume is stored circularly shifted so that voxel `⌊n_a/2⌋` lands at index
//! 0 on each axis. The fractional rest of the centre `c = n_a/2` (½ on odd
//! axes) is applied per view as an exact sub-pixel shift.
//!
//! # Scaling rule
//! Stored values are `s·H` with `s = 2^e` chosen so that `s·Σ|g|` lies in
//! `(2^(t−1), 2^t]`, where `g` is the premultiplied volume and `t` is the
//! format's [`Sample::SCALE_LOG2`] (`t = 14` for f16, as below; formats of
//! narrower range use a smaller `t`, so that `2^(t+1)` fits them). During the
//! transform every stored value is bounded by `2·Σ|g|` (x pass: `√2` times a
//! line sum; y pass: 2 times a plane sum; final: `√2·Σ|g|`, since
//! `|cas| ≤ √2`), so nothing exceeds `2^15 < 65504`, the f16 maximum, and the
//! largest coefficients sit within a factor 4 of it, keeping small ones as
//! far from underflow as the format allows. `s` is a power of two, so scaling
//! is exact. Renderers divide by `s` at the end.

use crate::dht::{dht_3d_scratch_len, dht_3d_store, Elements, LineStore, Pass, Rounding, Twiddles};
use crate::error::{mismatch, require_len, require_pow2, Error, Result};
use crate::filter::Filter;
use crate::format::{BlockExponents, BlockLayout, LineBlocks};
use crate::real::{Real, Sample};

/// A read-only source of voxels for preprocessing.
pub trait VoxelSource {
    /// Sizes `[nx, ny, nz]`.
    fn dims(&self) -> [usize; 3];
    /// Value of voxel `(i, j, k)`; indices are within `dims`.
    fn voxel(&self, i: usize, j: usize, k: usize) -> f64;
}

/// A dense volume borrowed from a slice, `i` fastest.
#[derive(Clone, Copy, Debug)]
pub struct DenseVolume<'a, V> {
    dims: [usize; 3],
    data: &'a [V],
}

impl<'a, V: Copy + Into<f64>> DenseVolume<'a, V> {
    /// Wrap `data` of shape `dims`.
    ///
    /// # Errors
    /// `data.len() != nx·ny·nz`, or a zero dimension.
    pub fn new(dims: [usize; 3], data: &'a [V]) -> Result<Self> {
        if dims.contains(&0) {
            return Err(Error::EmptyVolume);
        }
        let count = dims[0]
            .checked_mul(dims[1])
            .and_then(|v| v.checked_mul(dims[2]))
            .ok_or(Error::VolumeTooLarge { dims, grid: 0 })?;
        if count != data.len() {
            return Err(mismatch("volume data", count, data.len()));
        }
        Ok(Self { dims, data })
    }
}

impl<V: Copy + Into<f64>> VoxelSource for DenseVolume<'_, V> {
    fn dims(&self) -> [usize; 3] {
        self.dims
    }
    #[inline]
    fn voxel(&self, i: usize, j: usize, k: usize) -> f64 {
        self.data[i + self.dims[0] * (j + self.dims[1] * k)].into()
    }
}

/// Side of the padded cube for a volume: the smallest power of two at least
/// `oversample × max(nx, ny, nz)`.
///
/// # Errors
/// A zero dimension, or a size beyond `usize`.
pub fn padded_size(dims: [usize; 3], oversample: u32) -> Result<usize> {
    if dims.contains(&0) {
        return Err(Error::EmptyVolume);
    }
    let largest = dims.iter().copied().max().unwrap_or(1);
    largest
        .checked_mul(oversample as usize)
        .and_then(usize::checked_next_power_of_two)
        .ok_or(Error::VolumeTooLarge { dims, grid: 0 })
}

/// Scratch elements [`Spectrum::prepare`] needs for a padded side `n`:
/// `n` premultiplication factors plus the transform's `4n`.
pub const fn prepare_scratch_len(n: usize) -> usize {
    n + dht_3d_scratch_len([n, n, n])
}

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
    data: &'a [S],
    n: Z,
    scale: f64,
    filter: Filter,
    dims: [usize; 3],
    blocks: Option<BlockExponents<'a>>,
}

impl<'a, S: Sample> Spectrum<'a, S> {
    /// Premultiply `volume` for `filter`, zero-pad it into the cube of side
    /// [`padded_size`]`(dims, filter.oversample())`, scale it (module docs)
    /// and take its 3D DHT in place in `storage`, with arithmetic in `T`.
    ///
    /// `storage` needs `n³` elements, `scratch` [`prepare_scratch_len`]`(n)`,
    /// and `tw` must serve length `n`.
    ///
    /// # Errors
    /// A NaN or infinite voxel (named), short buffers, a twiddle table too
    /// short, or an overflow (impossible under the scaling rule unless the
    /// volume's magnitude exceeds f64's range).
    pub fn prepare<T: Real, V: VoxelSource>(
        volume: &V,
        filter: Filter,
        storage: &'a mut [S],
        scratch: &mut [T],
        tw: &Twiddles<'_, T>,
    ) -> Result<Self> {
        Self::prepare_rounding(volume, filter, storage, scratch, tw, Rounding::PerPass)
    }

    /// [`Spectrum::prepare`] with a choice of where the transform rounds to
    /// `S` ([`Rounding`]).
    ///
    /// # Errors
    /// As [`Spectrum::prepare`]; also a scale factor that the arithmetic type
    /// `T` cannot hold exactly (a volume whose magnitude is beyond about
    /// `10^±30` for f32).
    pub fn prepare_rounding<T: Real, V: VoxelSource>(
        volume: &V,
        filter: Filter,
        storage: &'a mut [S],
        scratch: &mut [T],
        tw: &Twiddles<'_, T>,
        rounding: Rounding,
    ) -> Result<Self> {
        let dims = volume.dims();
        let n = padded_size(dims, filter.oversample())?;
        let cube = cube_len(dims, n)?;
        require_len("spectrum storage", cube, storage.len())?;
        let storage = &mut storage[..cube];
        storage.fill(S::default());
        let scale = prepare_into(
            volume,
            &filter,
            S::SCALE_LOG2,
            &mut Elements(&mut *storage),
            n,
            scratch,
            tw,
            rounding,
        )?;
        Ok(Self {
            data: storage,
            n,
            scale,
            filter,
            dims,
            blocks: None,
        })
    }

    /// [`Spectrum::prepare_rounding`] into block floating point with one
    /// exponent per line, in place ([`LineBlocks`]): `mantissas` needs `n³`
    /// elements, `exponents` and `exponent_scratch` `n²` each; the finished
    /// spectrum has per-x-line exponents ([`BlockLayout::Line`]) in
    /// `exponents`.
    ///
    /// # Errors
    /// As [`Spectrum::prepare_rounding`]; also `S` not a block mantissa.
    pub fn prepare_line_blocks<T: Real, V: VoxelSource>(
        volume: &V,
        filter: Filter,
        mantissas: &'a mut [S],
        exponents: &'a mut [i8],
        exponent_scratch: &mut [i8],
        scratch: &mut [T],
        tw: &Twiddles<'_, T>,
        rounding: Rounding,
    ) -> Result<Self> {
        let dims = volume.dims();
        let n = padded_size(dims, filter.oversample())?;
        let cube = cube_len(dims, n)?;
        require_len("spectrum storage", cube, mantissas.len())?;
        require_len("block exponents", n * n, exponents.len())?;
        require_len("block exponent scratch", n * n, exponent_scratch.len())?;
        let mantissas = &mut mantissas[..cube];
        mantissas.fill(S::default());
        exponents[..n * n].fill(0);
        exponent_scratch[..n * n].fill(0);
        // Table `a` holds the input's and the passes' lines; `b` ends up with
        // the spectrum's x-lines.
        let mut store = LineBlocks::new(
            &mut *mantissas,
            &mut exponent_scratch[..n * n],
            &mut exponents[..n * n],
            n,
        )?;
        let scale = prepare_into(
            volume,
            &filter,
            S::SCALE_LOG2,
            &mut store,
            n,
            scratch,
            tw,
            rounding,
        )?;
        store.finish(&mut scratch[n..2 * n])?;
        let exponents: &'a [i8] = exponents;
        let blocks = BlockExponents::new(BlockLayout::Line, &exponents[..n * n], n)?;
        Ok(Self {
            data: mantissas,
            n,
            scale,
            filter,
            dims,
            blocks: Some(blocks),
        })
    }

    /// Rebuild a spectrum from stored parts, e.g. a table in flash made at
    /// build time by [`Spectrum::prepare`].
    ///
    /// # Errors
    /// `n` not a power of two, `data.len() != n³`, dims that do not fit, or
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
        require_pow2("spectrum side", n)?;
        let expected = padded_size(dims, filter.oversample())?;
        if expected != n {
            return Err(Error::VolumeTooLarge { dims, grid: n });
        }
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
    /// [`crate::format::encode_blocks`]).
    ///
    /// # Errors
    /// As [`Spectrum::from_parts`]; also `S` not a block mantissa format, or
    /// exponents that do not match `n` and their layout.
    pub fn from_blocks(
        data: &'a [S],
        blocks: BlockExponents<'a>,
        n: usize,
        scale: f64,
        filter: Filter,
        dims: [usize; 3],
    ) -> Result<Self> {
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

fn cube_len(dims: [usize; 3], n: usize) -> Result<usize> {
    n.checked_mul(n)
        .and_then(|v| v.checked_mul(n))
        .ok_or(Error::VolumeTooLarge { dims, grid: n })
}

/// Premultiply `volume`, place it in `store` (x-line by x-line, circularly
/// shifted, scaled by the rule for `scale_log2`) and transform it. `store`
/// must hold zeros. Returns the scale.
fn prepare_into<T: Real, V: VoxelSource, L: LineStore<T>>(
    volume: &V,
    filter: &Filter,
    scale_log2: i32,
    store: &mut L,
    n: usize,
    scratch: &mut [T],
    tw: &Twiddles<'_, T>,
    rounding: Rounding,
) -> Result<f64> {
    let dims = volume.dims();
    require_len("preparation scratch", prepare_scratch_len(n), scratch.len())?;
    let (premul, rest) = scratch.split_at_mut(n);
    premultiplier_table(filter, n, premul);

    // Pass 1: check finiteness and sum |g| exactly (in f64).
    let mask = n - 1;
    let offs = dims.map(|d| d / 2);
    let pm = |idx: usize, axis: usize| premul[(idx + n - offs[axis]) & mask].to_f64();
    let mut bound = 0.0f64;
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            let pyz = pm(j, 1) * pm(k, 2);
            for i in 0..dims[0] {
                let v = volume.voxel(i, j, k);
                if !v.is_finite() {
                    return Err(Error::NonFiniteVoxel {
                        index: [i, j, k],
                        value: v,
                    });
                }
                bound += libm::fabs(v * pm(i, 0) * pyz);
            }
        }
    }
    if !bound.is_finite() {
        return Err(Error::Overflow {
            stage: "premultiplication (volume magnitude beyond f64)",
        });
    }
    let scale = scale_for_target(bound, scale_log2);

    // Pass 2: place the scaled, premultiplied volume, circularly shifted,
    // one x-line at a time (rows the volume does not reach stay zero).
    let sc = T::from_f64(scale);
    if sc.to_f64() != scale {
        return Err(Error::Overflow {
            stage: "scaling (the volume's magnitude is beyond the arithmetic type's range)",
        });
    }
    let mut finite = true;
    for k in 0..dims[2] {
        let pz = (k + n - offs[2]) & mask;
        for j in 0..dims[1] {
            let py = (j + n - offs[1]) & mask;
            let pyz = premul[py] * premul[pz] * sc;
            let line = &mut rest[..n];
            line.fill(T::ZERO);
            for i in 0..dims[0] {
                let px = (i + n - offs[0]) & mask;
                line[px] = T::from_f64(volume.voxel(i, j, k)) * premul[px] * pyz;
            }
            finite &= store.store(Pass::X, n * (py + n * pz), 1, line);
        }
    }
    if !finite {
        return Err(Error::Overflow {
            stage: "placement of the premultiplied volume",
        });
    }
    dht_3d_store(store, [n, n, n], rest, tw, rounding)?;
    Ok(scale)
}

/// Premultiplication factors `1/ĥ(x/n)` for signed positions
/// `x ∈ [−n/2, n/2)`, stored at index `x mod n` (the same on every axis).
pub fn premultiplier_table<T: Real>(filter: &Filter, n: usize, out: &mut [T]) {
    let half = (n / 2) as i64;
    for (idx, v) in out[..n].iter_mut().enumerate() {
        let x = if (idx as i64) < half || n == 1 {
            idx as i64
        } else {
            idx as i64 - n as i64
        };
        *v = T::from_f64(1.0 / filter.response(x as f64 / n as f64));
    }
}

/// The power of two `s` with `s·bound ∈ (2^13, 2^14]` (1 when `bound` is 0):
/// the rule for f16.
pub fn scale_for(bound: f64) -> f64 {
    scale_for_target(bound, 14)
}

/// The power of two `s` with `s·bound ∈ (2^(t−1), 2^t]` (1 when `bound` is 0
/// or not finite), for `t = log2_target`.
pub fn scale_for_target(bound: f64, log2_target: i32) -> f64 {
    if !(bound > 0.0 && bound.is_finite()) {
        return 1.0;
    }
    let target = libm::scalbn(1.0, log2_target);
    let e = libm::floor(libm::log2(target / bound)) as i32;
    let mut s = libm::scalbn(1.0, e);
    // Guard against log2 rounding at exact powers of two.
    while s * bound > target {
        s *= 0.5;
    }
    while s * bound * 2.0 <= target {
        s *= 2.0;
    }
    s
}
