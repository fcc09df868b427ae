//! Preparation, once per volume: premultiply by the filter's reciprocal
//! spatial response, pad, scale (the scaling rule of [`super`]) and take the
//! 3D DHT in place.

use super::Spectrum;
use crate::dht::{
    dht_3d_scratch_len, dht_3d_store, Elements, LineBlocks, LineStore, Pass, Rounding, Twiddles,
};
use crate::error::{require_len, Error, Result};
use crate::filter::Filter;
use crate::num::{BlockExponents, BlockLayout, Real, Sample};
use crate::volume::{padded_size, VoxelSource};

/// Scratch elements [`Spectrum::prepare`] needs for a padded side `n`:
/// `n` premultiplication factors plus the transform's `4n`.
pub const fn prepare_scratch_len(n: usize) -> usize {
    n + dht_3d_scratch_len([n, n, n])
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
        let (dims, n, cube) = cube_for(volume, &filter, storage.len())?;
        let storage = &mut storage[..cube];
        storage.fill(S::default());
        let scale = prepare_into::<S, _, _, _>(
            volume,
            &filter,
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
        storage: LineBlockStorage<'a, '_, S>,
        scratch: &mut [T],
        tw: &Twiddles<'_, T>,
        rounding: Rounding,
    ) -> Result<Self> {
        let LineBlockStorage {
            mantissas,
            exponents,
            exponent_scratch,
        } = storage;
        let (dims, n, cube) = cube_for(volume, &filter, mantissas.len())?;
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
        let scale =
            prepare_into::<S, _, _, _>(volume, &filter, &mut store, n, scratch, tw, rounding)?;
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
}

/// Where a spectrum in block floating point with one exponent per line is
/// prepared ([`Spectrum::prepare_line_blocks`]).
#[derive(Debug)]
pub struct LineBlockStorage<'a, 's, S> {
    /// The mantissas, `n³`.
    pub mantissas: &'a mut [S],
    /// The finished spectrum's per-x-line exponents, `n²`.
    pub exponents: &'a mut [i8],
    /// The transform's second exponent table, `n²`.
    pub exponent_scratch: &'s mut [i8],
}

/// The volume's dims, the padded side `n` and the cube's length `n³`,
/// checking that `storage` elements hold the cube.
pub(super) fn cube_for<V: VoxelSource>(
    volume: &V,
    filter: &Filter,
    storage: usize,
) -> Result<([usize; 3], usize, usize)> {
    let dims = volume.dims();
    let n = padded_size(dims, filter.oversample())?;
    let cube = n
        .checked_mul(n)
        .and_then(|v| v.checked_mul(n))
        .ok_or(Error::VolumeTooLarge { dims, grid: n })?;
    require_len("spectrum storage", cube, storage)?;
    Ok((dims, n, cube))
}

/// Premultiply `volume`, place it in `store` (x-line by x-line, circularly
/// shifted, scaled by the rule for `S::SCALE_LOG2`) and transform it. `store`
/// must hold zeros. Returns the scale.
fn prepare_into<S: Sample, T: Real, V: VoxelSource, L: LineStore<T>>(
    volume: &V,
    filter: &Filter,
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
                let v = volume.finite_voxel(i, j, k)?;
                bound += libm::fabs(v * pm(i, 0) * pyz);
            }
        }
    }
    if !bound.is_finite() {
        return Err(Error::Overflow {
            stage: "premultiplication (volume magnitude beyond f64)",
        });
    }
    let scale = scale_for_target(bound, S::SCALE_LOG2);

    // Pass 2: place the scaled, premultiplied volume, circularly shifted,
    // one x-line at a time (rows the volume does not reach stay zero).
    let sc = check_scale(&premul[..n], bound, scale)?;
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

/// `scale` in `T`, if `T` holds it exactly and the largest factor a voxel
/// meets in preparation, `premul³·scale`, stays finite in `T`; `bound` is
/// the `Σ|premultiplied voxel|` the scale was derived from.
///
/// # Errors
/// [`Error::MagnitudeOutOfRange`] (voxels near `1e-38` in f32, say).
pub fn check_scale<T: Real>(premul: &[T], bound: f64, scale: f64) -> Result<T> {
    let sc = T::from_f64(scale);
    let pmax = premul
        .iter()
        .fold(0.0f64, |m, p| libm::fmax(m, libm::fabs(p.to_f64())));
    if sc.to_f64() != scale || !T::from_f64(pmax * pmax * pmax * scale).is_finite() {
        return Err(Error::MagnitudeOutOfRange { sum: bound, scale });
    }
    Ok(sc)
}

/// Premultiplication factors `1/ĥ(x/n)` for signed positions
/// `x ∈ [−n/2, n/2)`, stored at index `x mod n` (the same on every axis).
pub fn premultiplier_table<T: Real>(filter: &Filter, n: usize, out: &mut [T]) {
    for (idx, v) in out[..n].iter_mut().enumerate() {
        *v = T::from_f64(premultiplier(filter, n, idx));
    }
}

/// Entry `idx` of [`premultiplier_table`] for side `n`, in f64.
pub(crate) fn premultiplier(filter: &Filter, n: usize, idx: usize) -> f64 {
    let half = (n / 2) as i64;
    let x = if (idx as i64) < half || n == 1 {
        idx as i64
    } else {
        idx as i64 - n as i64
    };
    1.0 / filter.response(x as f64 / n as f64)
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
