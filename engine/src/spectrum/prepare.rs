//! Preparation of a spectrum on the host through FFTs on all cores
//! ([`crate::dht::real_fft`]): the same premultiplication, padding, circular shift
//! and scale as the core's [`fvr_core::spectrum::Spectrum::prepare`], the
//! input bit for bit, with the transform rounded to `S` once at the end
//! instead of after each of its three passes.

use fvr_core::error::Error;
use fvr_core::filter::Filter;
use fvr_core::num::Real;
use fvr_core::spectrum::{check_scale, premultiplier_table, scale_for_target};
use fvr_core::volume::padded_size;
use rayon::prelude::*;

use crate::dht::real::FftReal;
use crate::dht::real_fft::{dht_3d_real, half_spectrum_bytes, tile_bytes, SparseCube};
use crate::dht::store::StoreFormat;
use crate::error::PipelineError;
use crate::memory::{self, Budget};
use crate::volume::Volume;

/// A spectrum prepared by [`prepare_fast`].
#[derive(Debug)]
pub struct FastSpectrum<S> {
    /// `n³` stored coefficients, x fastest.
    pub data: Vec<S>,
    /// Side of the padded cube.
    pub n: usize,
    /// Scale of the stored values.
    pub scale: f64,
    /// The scaled volume's energy and the roundings since.
    pub energy: PreparedEnergy,
}

/// What the preparation knows of the energy of its spectrum's inverse
/// transform, for the reference of the adaptive marks' bounds
/// (`render::adaptive`), which would otherwise take a 3D inverse transform.
///
/// With `g` the premultiplied, scaled cube, `F = DHT(g)` unnormalized and
/// `ĥ` the filter's response per grid index, `DHT(F)·ĥ = n³·g·ĥ = n³·s·v`
/// on the volume's voxels and 0 elsewhere. The stored spectrum differs
/// from `F` by the transform's and the storage's roundings, bounded here
/// relative to its norm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedEnergy {
    /// `s²·Σ v²` over the voxels, `s` the spectrum's scale (summed in f64).
    pub scaled: f64,
    /// Relative bound on `|g·ĥ − s·v|` per voxel and on the sum's rounding.
    pub input: f64,
    /// Relative bound on the transform's error in norm: ten times the
    /// classic `log₂(n³)·ε` of an FFT in the arithmetic `T`.
    pub transform: f64,
    /// Unit roundoff of the storage format.
    pub storage: f64,
    /// Half the spacing of the storage format's subnormals.
    pub floor: f64,
}

/// What [`prepare_fast`] holds at its peak for side `n`: the stored spectrum
/// (`n³` of `S`), the complex half spectrum in `T` (`(n/2+1)·n²` complex
/// values, about `4n³` bytes in f32) and each thread's tiles.
pub fn fast_budget<T, S>(n: usize) -> Budget {
    let n64 = n as u64;
    let threads = rayon::current_num_threads() as u64;
    let mut b = Budget::new();
    b.hold(
        "spectrum",
        n64.saturating_mul(n64).saturating_mul(n64),
        std::mem::size_of::<S>() as u64,
    )
    .hold("half spectrum (complex)", half_spectrum_bytes::<T>(n), 1)
    .hold("transform tiles", threads, tile_bytes::<T>(n));
    b
}

/// `(Σ |v_i|·p_i, Σ v_i²)` in f64, each over [`LANES`] interleaved
/// partial sums, so that the sums vectorize instead of waiting on one
/// addition after another.
fn row_sums(line: &[f32], p: &[f64]) -> (f64, f64) {
    let mut acc = [0.0f64; LANES];
    let mut sq = [0.0f64; LANES];
    let (lines, ps) = (line.chunks_exact(LANES), p.chunks_exact(LANES));
    let (rest, rest_p) = (lines.remainder(), ps.remainder());
    for (vs, ps) in lines.zip(ps) {
        for (((a, q), &v), &p) in acc.iter_mut().zip(&mut sq).zip(vs).zip(ps) {
            *a += (v as f64).abs() * p;
            *q += v as f64 * v as f64;
        }
    }
    let (tail, tail_sq) = rest
        .iter()
        .zip(rest_p)
        .fold((0.0, 0.0), |(a, q), (&v, &p)| {
            (a + (v as f64).abs() * p, q + v as f64 * v as f64)
        });
    (
        acc.iter().sum::<f64>() + tail,
        sq.iter().sum::<f64>() + tail_sq,
    )
}

/// Partial sums in [`row_sums`].
const LANES: usize = 8;

/// Premultiply `volume` for `filter`, zero-pad it into the cube of side
/// [`padded_size`]`(dims, filter.oversample())`, scale it by the core's rule
/// for `S` and take its 3D DHT with arithmetic `T`, on all cores.
///
/// # Errors
/// A NaN or infinite voxel (the first in storage order, as the core names
/// it), a volume beyond the memory limit (checked before allocating, with
/// [`fast_budget`]), or an overflow.
pub fn prepare_fast<T: FftReal, S: StoreFormat>(
    volume: &Volume,
    filter: Filter,
) -> Result<FastSpectrum<S>, PipelineError> {
    let n = padded_size(volume.dims, filter.oversample())?;
    prepare_fast_on::<T, S>(volume, filter, n)
}

/// [`prepare_fast`] into a cube of side `n`: a power of two as there, or a
/// mixed-radix side ([`fvr_core::volume::check_side`]) such as
/// [`fvr_core::volume::GridOversampling::side`] gives.
///
/// # Errors
/// As [`prepare_fast`]; also a side `n` the volume and filter do not allow.
pub fn prepare_fast_on<T: FftReal, S: StoreFormat>(
    volume: &Volume,
    filter: Filter,
    n: usize,
) -> Result<FastSpectrum<S>, PipelineError> {
    let dims = volume.dims;
    fvr_core::volume::check_side(dims, filter.oversample(), n)?;
    fvr_core::volume::DenseVolume::new(dims, &volume.data)?;
    if let Err(e) = fast_budget::<T, S>(n).check(memory::limit(), "use a smaller --resample") {
        return Err(PipelineError::OutOfMemory {
            needed: e.needed,
            limit: e.limit.bytes,
            n,
        });
    }
    let mut premul = vec![<T as Real>::ZERO; n];
    premultiplier_table(&filter, n, &mut premul);
    let offs = dims.map(|d| d / 2);
    let shifted = |idx: usize, axis: usize| (idx + n - offs[axis]) % n;
    let [nx, ny, nz] = dims;

    // Σ|g| in f64 (in another order than the core's, which can change the
    // scale only for a sum within an ulp of a power of two), and the first
    // non-finite voxel. `pmx[i]` is |p| at volume index i along x.
    let pmx: Vec<f64> = (0..nx)
        .map(|i| premul[shifted(i, 0)].to_f64().abs())
        .collect();
    let sums: Vec<Result<(f64, f64), Error>> = volume
        .data
        .par_chunks_exact(nx * ny)
        .enumerate()
        .map(|(k, plane)| {
            let pz = premul[shifted(k, 2)].to_f64();
            let (mut sum, mut energy) = (0.0f64, 0.0f64);
            for (j, line) in plane.chunks_exact(nx).enumerate() {
                if !line.iter().fold(true, |ok, v| ok & v.is_finite()) {
                    let i = line.iter().position(|v| !v.is_finite()).unwrap_or(0);
                    return Err(Error::NonFiniteVoxel {
                        index: [i, j, k],
                        value: line[i] as f64,
                    });
                }
                let pyz = (premul[shifted(j, 1)].to_f64() * pz).abs();
                let (magnitude, squares) = row_sums(line, &pmx);
                sum += magnitude * pyz;
                energy += squares;
            }
            Ok((sum, energy))
        })
        .collect();
    let (mut bound, mut energy) = (0.0f64, 0.0f64);
    for s in sums {
        let (b, e) = s?;
        bound += b;
        energy += e;
    }
    if !bound.is_finite() {
        return Err(Error::Overflow {
            stage: "premultiplication (volume magnitude beyond f64)",
        }
        .into());
    }
    let scale = scale_for_target(bound, S::SCALE_LOG2);
    let sc = check_scale(&premul, bound, scale)?;

    // Shifted row (y, z) holds volume row ((y + offs) mod n, (z + offs) mod n).
    let mut rows_y = vec![false; n];
    let mut planes_z = vec![false; n];
    for j in 0..ny {
        rows_y[shifted(j, 1)] = true;
    }
    for k in 0..nz {
        planes_z[shifted(k, 2)] = true;
    }
    let premul = &premul;
    let fill = move |py: usize, pz: usize, line: &mut [T]| {
        let (j, k) = ((py + offs[1]) % n, (pz + offs[2]) % n);
        let src = &volume.data[nx * (j + ny * k)..][..nx];
        line.fill(<T as Real>::ZERO);
        // The core's products, in its order: v·p(x)·(p(y)·p(z)·s).
        let pyz = premul[py] * premul[pz] * sc;
        // x index i lands at (i − offs) mod n: two contiguous runs.
        let (head, tail) = src.split_at(offs[0]);
        let (front, back) = line.split_at_mut(n - offs[0]);
        let runs = [(tail, &mut front[..nx - offs[0]]), (head, &mut back[..])];
        for (from, to) in runs {
            for (o, &v) in to.iter_mut().zip(from) {
                *o = <T as Real>::from_f64(v as f64);
            }
        }
        for (o, &p) in line.iter_mut().zip(premul) {
            *o = *o * p * pyz;
        }
    };
    let cube = SparseCube {
        n,
        rows_y: &rows_y,
        planes_z: &planes_z,
        fill: &fill,
    };
    let mut data = Vec::new();
    // Zeroed on all cores: the first touch of the pages is a large part.
    data.par_extend(rayon::iter::repeat_n(S::default(), n * n * n));
    dht_3d_real(&cube, &mut data)?;
    let cells = (n as f64).powi(3);
    let energy = PreparedEnergy {
        scaled: energy * scale * scale,
        // Seven roundings of T in `g = v·p(x)·(p(y)·p(z)·s)` with each
        // `p = 1/ĥ` rounded, and the f64 sum of squares.
        input: 8.0 * T::EPSILON_HALF.to_f64() + (nx * ny * nz) as f64 * f64::EPSILON / 2.0,
        transform: 10.0 * cells.log2() * T::EPSILON_HALF.to_f64(),
        storage: S::UNIT_ROUNDOFF,
        floor: S::SUBNORMAL_HALF_SPACING,
    };
    Ok(FastSpectrum {
        data,
        n,
        scale,
        energy,
    })
}
