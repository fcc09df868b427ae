//! The owned spectrum: the core pipeline's spectrum with its buffers, for
//! the host ([`crate::render::view::ViewRenderer`] renders views of it, [`crate::plan::filter`] chooses
//! its filter).
//!
//! Three precisions share the one generic core:
//! - `f16`: spectrum stored as IEEE binary16 (2 bytes a voxel), f32 arithmetic;
//! - `f32`: spectrum and arithmetic in f32;
//! - `f64`: spectrum and arithmetic in f64 (the reference pipeline).

pub mod bricks;
pub mod exchange;
pub mod prepare;
#[cfg(test)]
mod tests;

use std::fmt;
use std::str::FromStr;
use std::sync::OnceLock;

use fvr_core::dht::Twiddles;
use fvr_core::filter::Filter;
use fvr_core::num::{Real, Sample};
use fvr_core::spectrum::{prepare_scratch_len, Spectrum};
use fvr_core::volume::{padded_size, DenseVolume, GridOversampling};
use half::f16;

use crate::dht::real::FftReal;
use crate::dht::store::StoreFormat;
use crate::spectrum::exchange::exchange_xy;
use crate::spectrum::prepare::{prepare_fast_on, PreparedEnergy};
use crate::volume::Volume;

pub use crate::error::PipelineError;

/// Storage and arithmetic of a pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// f16 storage, f32 arithmetic (the product).
    F16,
    /// f32 storage and arithmetic.
    F32,
    /// f64 storage and arithmetic (reference).
    F64,
}

impl Precision {
    /// Every precision.
    pub const ALL: [Precision; 3] = [Precision::F16, Precision::F32, Precision::F64];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F16 => "f16",
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }

    /// Bytes per stored coefficient.
    pub fn bytes(self) -> usize {
        match self {
            Precision::F16 => 2,
            Precision::F32 => 4,
            Precision::F64 => 8,
        }
    }
}

impl fmt::Display for Precision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Precision {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Precision::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| format!("unknown precision `{s}`: expected f16, f32 or f64"))
    }
}

/// An owned, prepared spectrum in storage format `S`.
#[derive(Clone, Debug)]
pub struct OwnedSpectrum<S> {
    data: Vec<S>,
    n: usize,
    scale: f64,
    filter: Filter,
    dims: [usize; 3],
    /// The energy the FFT preparation measured; `None` from the core's
    /// in-place transform, which rounds after each pass.
    energy: Option<PreparedEnergy>,
    /// The samples with x and y exchanged, once a renderer asked for them
    /// ([`OwnedSpectrum::exchanged_xy`]); `None` inside when the memory
    /// budget did not hold them.
    exchanged: OnceLock<Option<Vec<S>>>,
}

impl<S: Sample> OwnedSpectrum<S> {
    /// Premultiply, pad and transform `volume` for `filter`, with arithmetic
    /// `T`, on all cores through FFTs ([`crate::spectrum::prepare`]): the core's
    /// input and scale, rounded to `S` once at the end.
    ///
    /// # Errors
    /// As [`Spectrum::prepare`]; also a volume whose padded cube and
    /// transient buffers would not fit in memory is refused before
    /// allocating.
    pub fn prepare<T: FftReal>(volume: &Volume, filter: Filter) -> Result<Self, PipelineError>
    where
        S: StoreFormat,
    {
        let n = padded_size(volume.dims, filter.oversample())?;
        if n < 2 {
            return Self::prepare_in_place::<T>(volume, filter);
        }
        Self::prepare_on::<T>(volume, filter, n)
    }

    /// [`OwnedSpectrum::prepare`] into a cube of side `n`: the power of two
    /// it picks, or a mixed-radix side such as
    /// [`fvr_core::volume::GridOversampling::side`] gives (the
    /// filter's integer oversampling must match,
    /// [`fvr_core::volume::check_side`]).
    ///
    /// # Errors
    /// As [`OwnedSpectrum::prepare`]; also a side the volume and filter do
    /// not allow.
    pub fn prepare_on<T: FftReal>(
        volume: &Volume,
        filter: Filter,
        n: usize,
    ) -> Result<Self, PipelineError>
    where
        S: StoreFormat,
    {
        let spec = prepare_fast_on::<T, S>(volume, filter, n)?;
        Ok(Self {
            data: spec.data,
            n: spec.n,
            scale: spec.scale,
            filter,
            dims: volume.dims,
            energy: Some(spec.energy),
            exchanged: OnceLock::new(),
        })
    }

    /// [`OwnedSpectrum::prepare`] through the core's in-place transform on
    /// one core ([`Spectrum::prepare`]), rounding to `S` after each pass:
    /// the device's path, and the reference the fast path is tested against.
    ///
    /// # Errors
    /// As [`Spectrum::prepare`]; also a volume whose padded cube would not fit
    /// in memory is refused before allocating.
    pub fn prepare_in_place<T: Real>(
        volume: &Volume,
        filter: Filter,
    ) -> Result<Self, PipelineError> {
        let n = padded_size(volume.dims, filter.oversample())?;
        check_memory(n, std::mem::size_of::<S>())?;
        let source = DenseVolume::new(volume.dims, &volume.data)?;
        let mut data = vec![S::default(); n * n * n];
        let mut scratch = vec![T::ZERO; prepare_scratch_len(n)];
        let mut tw_buf = vec![T::ZERO; Twiddles::<T>::buffer_len(n)];
        let tw = Twiddles::new(&mut tw_buf, n)?;
        let spec = Spectrum::prepare(&source, filter, &mut data, &mut scratch, &tw)?;
        let (scale, dims) = (spec.scale(), spec.dims());
        Ok(Self {
            data,
            n,
            scale,
            filter,
            dims,
            energy: None,
            exchanged: OnceLock::new(),
        })
    }

    /// An owned copy of a plain core spectrum (one `fvr prepare` stored,
    /// read in place from its file): the same samples, side, scale, filter
    /// and dims, so it renders the same views bit for bit. `None` for a
    /// spectrum with block exponents, which the host walks do not read.
    pub fn from_view(spec: &Spectrum<'_, S>) -> Option<Self> {
        if spec.blocks().is_some() {
            return None;
        }
        Some(Self {
            data: spec.data().to_vec(),
            n: spec.n(),
            scale: spec.scale(),
            filter: *spec.filter(),
            dims: spec.dims(),
            energy: None,
            exchanged: OnceLock::new(),
        })
    }

    /// Borrow as a core spectrum.
    pub fn view(&self) -> Spectrum<'_, S> {
        Spectrum::from_parts(&self.data, self.n, self.scale, self.filter, self.dims)
            .expect("parts come from a prepared spectrum")
    }

    /// The scaled volume's energy and the roundings since, when the FFT
    /// preparation made this spectrum.
    pub fn prepared_energy(&self) -> Option<&PreparedEnergy> {
        self.energy.as_ref()
    }

    /// The spectrum with its x and y axes exchanged (y fastest in memory,
    /// [`crate::spectrum::exchange`]), for views whose strip rows run mostly
    /// along y. Built on the first call, on all cores, when the memory
    /// limit holds a second copy of the samples beside the first; `None`
    /// when it does not.
    pub fn exchanged_xy(&self) -> Option<Spectrum<'_, S>> {
        let data = self
            .exchanged
            .get_or_init(|| {
                let cells = (self.n as u64).pow(3);
                let size = std::mem::size_of::<S>() as u64;
                crate::memory::Budget::new()
                    .hold("spectrum", cells, size)
                    .hold("spectrum with x and y exchanged", cells, size)
                    .check(crate::memory::limit(), "")
                    .ok()?;
                exchange_xy(&self.data, self.n)
            })
            .as_ref()?;
        let [a, b, c] = self.dims;
        Spectrum::from_parts(data, self.n, self.scale, self.filter, [b, a, c]).ok()
    }

    /// Bytes of the exchanged copy held ([`OwnedSpectrum::exchanged_xy`]),
    /// 0 before it is built or when it was not.
    pub fn exchanged_bytes(&self) -> usize {
        match self.exchanged.get() {
            Some(Some(d)) => std::mem::size_of_val(d.as_slice()),
            _ => 0,
        }
    }

    /// Side of the padded cube.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Bytes of stored coefficients.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.data.as_slice())
    }

    /// The filter the volume was premultiplied for.
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// Estimated SNR (dB) of images against the same pipeline in f64, from
    /// the storage format's rounding alone:
    /// `(Σf)²/n² ÷ (r·u²/3 · Σg²)`.
    ///
    /// `g` is the premultiplied volume; `Σg² = Σ_k H_k²/n³` by Parseval,
    /// read off the stored spectrum. Each of the `r = 4` roundings (input and
    /// three passes) adds noise of relative variance `u²/3` (`u` the unit
    /// roundoff) to every coefficient, and a slice inherits it; the image
    /// energy is at least `(Σf)²/n²` by Cauchy–Schwarz. Premultiplication
    /// that amplifies the volume's edges (Kaiser–Bessel at σ = 1 on data that
    /// fills the grid) inflates `Σg²` and shows up here.
    pub fn storage_snr_estimate_db(&self, volume_sum: f64, unit_roundoff: f64) -> f64 {
        let n3 = (self.n * self.n * self.n) as f64;
        let g2 = self.stored_sum_of_squares() / (self.scale * self.scale) / n3;
        let signal = volume_sum * volume_sum / (self.n * self.n) as f64;
        let noise = 4.0 * unit_roundoff * unit_roundoff / 3.0 * g2;
        10.0 * (signal / noise).log10()
    }

    /// `Σ c²` over the stored values `c`, on all cores: each chunk of
    /// 2¹⁶ values summed in order, then the chunks' sums in order, so the
    /// result is the same bits on any number of threads. Formats up to 32
    /// bits are widened raw ([`Sample::to_f32_raw`], a loop the compiler
    /// vectorizes) and the power of two put back on the sum.
    fn stored_sum_of_squares(&self) -> f64 {
        use rayon::prelude::*;
        let raw = S::BITS <= 32;
        let chunk_sums: Vec<f64> = self
            .data
            .par_chunks(1 << 16)
            .map(|chunk| {
                chunk
                    .iter()
                    .map(|v| {
                        let x = if raw {
                            v.to_f32_raw() as f64
                        } else {
                            v.to_f64()
                        };
                        x * x
                    })
                    .sum::<f64>()
            })
            .collect();
        let sum: f64 = chunk_sums.iter().sum();
        if raw {
            sum * 4f64.powi(S::RAW_EXPONENT_F32)
        } else {
            sum
        }
    }

    /// Stored coefficients.
    pub fn data(&self) -> &[S] {
        &self.data
    }

    /// Scale of the stored values.
    pub fn scale(&self) -> f64 {
        self.scale
    }
}

/// Refuse a spectrum of side `n` whose storage and f32 working buffers would
/// exceed the memory available, before allocating it.
pub fn check_memory(n: usize, bytes_per_sample: usize) -> Result<(), PipelineError> {
    let needed = (n as u64)
        .checked_pow(3)
        .and_then(|c| c.checked_mul(bytes_per_sample as u64))
        .unwrap_or(u64::MAX);
    let limit = crate::memory::limit_bytes();
    if needed > limit {
        return Err(PipelineError::OutOfMemory { needed, limit, n });
    }
    Ok(())
}

/// A prepared spectrum in any of the three precisions.
#[derive(Clone, Debug)]
pub enum AnySpectrum {
    /// f16 storage.
    F16(OwnedSpectrum<f16>),
    /// f32 storage.
    F32(OwnedSpectrum<f32>),
    /// f64 storage.
    F64(OwnedSpectrum<f64>),
}

/// `body` with `$s` bound to the typed spectrum and `$t` to its
/// arithmetic: f32 for f16 and f32 storage, f64 for f64.
macro_rules! with_arithmetic {
    ($any:expr, $s:ident, $t:ident => $body:expr) => {
        match $any {
            AnySpectrum::F16($s) => {
                type $t = f32;
                $body
            }
            AnySpectrum::F32($s) => {
                type $t = f32;
                $body
            }
            AnySpectrum::F64($s) => {
                type $t = f64;
                $body
            }
        }
    };
}
pub(crate) use with_arithmetic;

/// Which host path prepares a spectrum.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Preparation {
    /// FFTs on all cores, rounded to the storage format once
    /// ([`OwnedSpectrum::prepare`]).
    #[default]
    Fast,
    /// The core's in-place transform on one core, rounding after each pass
    /// ([`OwnedSpectrum::prepare_in_place`]): the device's path, bit for bit.
    InPlace,
}

impl AnySpectrum {
    /// Prepare `volume` at `precision` for `filter` ([`Preparation::Fast`]).
    ///
    /// # Errors
    /// As [`OwnedSpectrum::prepare`].
    pub fn prepare(
        volume: &Volume,
        filter: Filter,
        precision: Precision,
    ) -> Result<Self, PipelineError> {
        Self::prepare_by(volume, filter, precision, Preparation::Fast)
    }

    /// [`AnySpectrum::prepare`] on the grid oversampled by `grid`: the cube
    /// of side [`GridOversampling::side`] (mixed radix for σ = 1.25 and
    /// 1.5), for a filter made for that grid ([`Filter::for_grid`],
    /// [`Filter::fit_grid`]).
    ///
    /// # Errors
    /// As [`OwnedSpectrum::prepare_on`].
    pub fn prepare_grid(
        volume: &Volume,
        filter: Filter,
        precision: Precision,
        grid: GridOversampling,
    ) -> Result<Self, PipelineError> {
        let n = grid.side(volume.dims)?;
        if n < 2 {
            return Self::prepare(volume, filter, precision);
        }
        Ok(match precision {
            Precision::F16 => {
                AnySpectrum::F16(OwnedSpectrum::prepare_on::<f32>(volume, filter, n)?)
            }
            Precision::F32 => {
                AnySpectrum::F32(OwnedSpectrum::prepare_on::<f32>(volume, filter, n)?)
            }
            Precision::F64 => {
                AnySpectrum::F64(OwnedSpectrum::prepare_on::<f64>(volume, filter, n)?)
            }
        })
    }

    /// [`AnySpectrum::prepare`] by the path `how`.
    ///
    /// # Errors
    /// As [`OwnedSpectrum::prepare`] or [`OwnedSpectrum::prepare_in_place`].
    pub fn prepare_by(
        volume: &Volume,
        filter: Filter,
        precision: Precision,
        how: Preparation,
    ) -> Result<Self, PipelineError> {
        /// One spectrum of storage `S` in arithmetic `T` by the path `how`.
        fn by<S: StoreFormat, T: FftReal>(
            volume: &Volume,
            filter: Filter,
            how: Preparation,
        ) -> Result<OwnedSpectrum<S>, PipelineError> {
            match how {
                Preparation::Fast => OwnedSpectrum::prepare::<T>(volume, filter),
                Preparation::InPlace => OwnedSpectrum::prepare_in_place::<T>(volume, filter),
            }
        }
        Ok(match precision {
            Precision::F16 => AnySpectrum::F16(by::<f16, f32>(volume, filter, how)?),
            Precision::F32 => AnySpectrum::F32(by::<f32, f32>(volume, filter, how)?),
            Precision::F64 => AnySpectrum::F64(by::<f64, f64>(volume, filter, how)?),
        })
    }

    /// Side of the padded cube.
    pub fn n(&self) -> usize {
        match self {
            AnySpectrum::F16(s) => s.n(),
            AnySpectrum::F32(s) => s.n(),
            AnySpectrum::F64(s) => s.n(),
        }
    }

    /// Bytes of stored coefficients.
    pub fn bytes(&self) -> usize {
        match self {
            AnySpectrum::F16(s) => s.bytes(),
            AnySpectrum::F32(s) => s.bytes(),
            AnySpectrum::F64(s) => s.bytes(),
        }
    }

    /// Bytes of the copy with x and y exchanged held
    /// ([`OwnedSpectrum::exchanged_bytes`]).
    pub fn exchanged_bytes(&self) -> usize {
        match self {
            AnySpectrum::F16(s) => s.exchanged_bytes(),
            AnySpectrum::F32(s) => s.exchanged_bytes(),
            AnySpectrum::F64(s) => s.exchanged_bytes(),
        }
    }

    /// The filter the spectrum was premultiplied for.
    pub fn filter(&self) -> Filter {
        match self {
            AnySpectrum::F16(s) => s.filter(),
            AnySpectrum::F32(s) => s.filter(),
            AnySpectrum::F64(s) => s.filter(),
        }
    }

    /// [`OwnedSpectrum::storage_snr_estimate_db`] for this precision's unit
    /// roundoff (`+∞` for f64, the reference).
    pub fn storage_snr_estimate_db(&self, volume_sum: f64) -> f64 {
        match self {
            AnySpectrum::F16(s) => s.storage_snr_estimate_db(volume_sum, 2f64.powi(-11)),
            AnySpectrum::F32(s) => s.storage_snr_estimate_db(volume_sum, 2f64.powi(-24)),
            AnySpectrum::F64(_) => f64::INFINITY,
        }
    }
}
