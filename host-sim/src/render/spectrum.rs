//! The core pipeline with owned buffers, for the host.
//!
//! Three precisions share the one generic core:
//! - `f16`: spectrum stored as IEEE binary16 (2 bytes a voxel), f32 arithmetic;
//! - `f32`: spectrum and arithmetic in f32;
//! - `f64`: spectrum and arithmetic in f64 (the reference pipeline).

use std::fmt;
use std::str::FromStr;

use fvr_core::dht::Twiddles;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::{Sampling, View};
use fvr_core::real::{Real, Sample};
use fvr_core::render::{
    aux_len, check_image, extract_slice_rows, finish_projection, grid_len, placement_on_axes,
    render_sampled,
};
use fvr_core::spectrum::{padded_size, prepare_scratch_len, DenseVolume, Spectrum};
use half::f16;

use crate::volume::Volume;

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
}

impl<S: Sample> OwnedSpectrum<S> {
    /// Premultiply, pad and transform `volume` for `filter`, with arithmetic `T`.
    ///
    /// # Errors
    /// As [`Spectrum::prepare`]; also a volume whose padded cube would not fit
    /// in memory is refused before allocating.
    pub fn prepare<T: Real>(volume: &Volume, filter: Filter) -> Result<Self, PipelineError> {
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
        })
    }

    /// Borrow as a core spectrum.
    pub fn view(&self) -> Spectrum<'_, S> {
        Spectrum::from_parts(&self.data, self.n, self.scale, self.filter, self.dims)
            .expect("parts come from a prepared spectrum")
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
        let sum_sq: f64 = self
            .data
            .iter()
            .map(|v| {
                let x = v.to_f64() / self.scale;
                x * x
            })
            .sum();
        let g2 = sum_sq / n3;
        let signal = volume_sum * volume_sum / (self.n * self.n) as f64;
        let noise = 4.0 * unit_roundoff * unit_roundoff / 3.0 * g2;
        10.0 * (signal / noise).log10()
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

/// Reusable per-view buffers and tables for arithmetic `T`.
#[derive(Debug)]
pub struct ViewRenderer<T> {
    kernel: KernelTable<T>,
    tw: Vec<T>,
    grid: Vec<T>,
    aux: Vec<T>,
    n: usize,
    threads: usize,
}

impl<T: Real> ViewRenderer<T> {
    /// Buffers for spectra of side `n` and `filter`.
    pub fn new(n: usize, filter: Filter) -> Self {
        let mut tw = vec![T::ZERO; Twiddles::<T>::buffer_len(n)];
        Twiddles::new(&mut tw, n).expect("n is a power of two");
        Self {
            kernel: KernelTable::new(filter),
            tw,
            grid: vec![T::ZERO; grid_len(n)],
            aux: vec![T::ZERO; aux_len(n)],
            n,
            threads: 0,
        }
    }

    /// Extract the slice on `threads` threads (0, the default: one per
    /// core). The image is the same bit for bit whatever the count.
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = threads;
        self
    }

    /// Render one view into `out` (`width × height`, row 0 at the top).
    ///
    /// The slice is extracted in blocks of rows on the renderer's threads
    /// ([`fvr_core::render::extract_slice_rows`]; the core stays
    /// single-threaded), then inverse-transformed on this one.
    ///
    /// # Errors
    /// As [`fvr_core::render::render`].
    pub fn render_into<S: Sample>(
        &mut self,
        spec: &OwnedSpectrum<S>,
        view: &View,
        width: usize,
        height: usize,
        out: &mut [T],
    ) -> Result<(), fvr_core::Error> {
        self.render_sampled_into(spec, view, &Sampling::UNIT, width, height, out)
    }

    /// [`ViewRenderer::render_into`] in physical units
    /// ([`fvr_core::render::render_sampled`]).
    ///
    /// # Errors
    /// As [`fvr_core::render::render_sampled`].
    pub fn render_sampled_into<S: Sample>(
        &mut self,
        spec: &OwnedSpectrum<S>,
        view: &View,
        sampling: &Sampling,
        width: usize,
        height: usize,
        out: &mut [T],
    ) -> Result<(), fvr_core::Error> {
        let tw = Twiddles::from_table(&self.tw, self.n)?;
        let spec = spec.view();
        let n = spec.n();
        let threads = match self.threads {
            0 => std::thread::available_parallelism().map_or(1, |t| t.get()),
            t => t,
        };
        // Blocks of at least 16 rows: below that a thread costs more than it saves.
        let blocks = threads.min(n / 16).max(1);
        if blocks == 1 || self.grid.len() != grid_len(n) || self.kernel.filter() != spec.filter() {
            return render_sampled(
                &spec,
                &self.kernel,
                view,
                sampling,
                width,
                height,
                &tw,
                &mut self.grid,
                &mut self.aux,
                out,
            );
        }
        let axes = sampling.slice_axes(&view.frame()?);
        check_image(width, height, n)?;
        let rows_per_block = n.div_ceil(blocks);
        let kernel = &self.kernel;
        let spec_ref = &spec;
        let axes_ref = &axes;
        std::thread::scope(|scope| {
            let workers: Vec<_> = self
                .grid
                .chunks_mut(rows_per_block * n)
                .enumerate()
                .map(|(block, rows)| {
                    scope.spawn(move || {
                        extract_slice_rows(spec_ref, kernel, axes_ref, block * rows_per_block, rows)
                    })
                })
                .collect();
            workers
                .into_iter()
                .try_for_each(|w| w.join().expect("an extraction thread panicked"))
        })?;
        let place = placement_on_axes(spec.dims(), &axes, width, height, 1.0);
        finish_projection(
            &mut self.grid,
            n,
            &place,
            sampling.gain() / spec.scale(),
            width,
            height,
            &tw,
            &mut self.aux,
            out,
        )
    }
}

/// Why a host pipeline could not run.
#[derive(Debug)]
pub enum PipelineError {
    /// The core refused (bad view, bad size, non-finite voxel, ...).
    Core(fvr_core::Error),
    /// The padded spectrum would need more memory than is available.
    OutOfMemory {
        /// Bytes the spectrum would need.
        needed: u64,
        /// Bytes available.
        limit: u64,
        /// Side of the padded cube.
        n: usize,
    },
}

impl fmt::Display for PipelineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PipelineError::Core(e) => e.fmt(f),
            PipelineError::OutOfMemory { needed, limit, n } => write!(
                f,
                "a {n}^3 spectrum needs {needed} bytes, more than the {limit} bytes available"
            ),
        }
    }
}

impl std::error::Error for PipelineError {}

impl From<fvr_core::Error> for PipelineError {
    fn from(e: fvr_core::Error) -> Self {
        PipelineError::Core(e)
    }
}

/// Refuse a spectrum of side `n` whose storage and f32 working buffers would
/// exceed the memory available, before allocating it.
pub(crate) fn check_memory(n: usize, bytes_per_sample: usize) -> Result<(), PipelineError> {
    let needed = (n as u64)
        .checked_pow(3)
        .and_then(|c| c.checked_mul(bytes_per_sample as u64))
        .unwrap_or(u64::MAX);
    let limit = crate::io::nrrd::memory_limit_bytes();
    if needed > limit {
        return Err(PipelineError::OutOfMemory { needed, limit, n });
    }
    Ok(())
}

/// How the Kaiser–Bessel shape parameter is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KbDesign {
    /// Fitted to the volume's energy distribution ([`Filter::fit`]).
    Auto,
    /// Beatty's β for this design oversampling.
    Sigma(f64),
}

impl FromStr for KbDesign {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(KbDesign::Auto);
        }
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 1.0 => Ok(KbDesign::Sigma(v)),
            _ => Err(format!(
                "kb design `{s}` must be `auto` or an oversampling factor >= 1"
            )),
        }
    }
}

/// Choose the filter for `volume`.
///
/// # Errors
/// As [`Filter::fit`].
pub fn choose_filter(
    volume: &Volume,
    kind: FilterKind,
    oversample: u32,
    design: KbDesign,
) -> Result<Filter, fvr_core::Error> {
    match design {
        KbDesign::Auto => {
            let src = DenseVolume::new(volume.dims, &volume.data)?;
            Ok(Filter::fit(kind, oversample, &src)?.0)
        }
        KbDesign::Sigma(s) => Filter::with_design_oversampling(kind, oversample, s),
    }
}

/// Above this [`premultiplication_gain_db`], [`choose_oversampling`] pads the
/// grid to oversampling 2.
///
/// Why 20 dB: the f16 spectrum of compact data sits 75–84 dB from f64
/// (README); a gain of 20 dB would leave about 55–64 dB, the most the
/// default format can give away and still stay above the paper's 50 dB.
pub const CONDITIONING_LIMIT_DB: f64 = 20.0;

/// How much premultiplication amplifies storage rounding noise relative to
/// the image, in dB: `10·log10(Σg² / (p₀⁶·Σf²))`, where `g = f·p(x)p(y)p(z)`
/// is the premultiplied volume, `p` the per-axis factor `1/ĥ` on the padded
/// grid and `p₀ = p(0)` its value at the centre.
///
/// Rounding adds noise proportional to each stored coefficient, so the noise
/// energy of an image is proportional to `Σg²` (Parseval), while its signal
/// is that of `p₀³·f`. A volume confined to the middle of its grid has a gain
/// near 0 dB. One that fills the grid at oversampling 1 has its faces and
/// corners multiplied by `p(n/2)/p₀` per axis (about 200 for kb4, so up to
/// 10⁷ at a corner), which no 16-bit format can absorb: the gain is then
/// 60–90 dB. Returns 0 for an all-zero volume.
///
/// # Errors
/// A NaN or infinite voxel, or an empty volume.
pub fn premultiplication_gain_db(volume: &Volume, filter: Filter) -> Result<f64, fvr_core::Error> {
    let n = padded_size(volume.dims, filter.oversample())?;
    let mut table = vec![0.0f64; n];
    fvr_core::spectrum::premultiplier_table(&filter, n, &mut table);
    let p0 = table[0];
    let dims = volume.dims;
    let factor = |i: usize, a: usize| table[(i + n - dims[a] / 2) & (n - 1)] / p0;
    let (mut g2, mut f2) = (0.0f64, 0.0f64);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            let pyz = factor(j, 1) * factor(k, 2);
            for i in 0..dims[0] {
                let v = volume.get(i, j, k) as f64;
                if !v.is_finite() {
                    return Err(fvr_core::Error::NonFiniteVoxel {
                        index: [i, j, k],
                        value: v,
                    });
                }
                let g = v * factor(i, 0) * pyz;
                g2 += g * g;
                f2 += v * v;
            }
        }
    }
    Ok(if f2 > 0.0 {
        10.0 * (g2 / f2).log10()
    } else {
        0.0
    })
}

/// The oversampling for `volume`: 1, unless premultiplying for `kind` at
/// oversampling 1 would amplify storage noise by more than
/// [`CONDITIONING_LIMIT_DB`] ([`premultiplication_gain_db`]); then 2, where
/// the data fills only the middle half of each axis and the gain is a few dB.
///
/// This is the remedy for the ill-conditioning of Kaiser–Bessel
/// premultiplication on data that fills its grid (a constant volume, or CT
/// in Hounsfield units, whose air is −1000): the f64 image there is itself
/// wrong at the faces (the kernel's first alias is as strong as its main
/// lobe at ν = ½), and the amplified faces swamp every 16-bit format.
///
/// # Errors
/// As [`choose_filter`] and [`premultiplication_gain_db`].
pub fn choose_oversampling(
    volume: &Volume,
    kind: FilterKind,
    design: KbDesign,
) -> Result<u32, fvr_core::Error> {
    let filter = choose_filter(volume, kind, 1, design)?;
    let gain = premultiplication_gain_db(volume, filter)?;
    Ok(if gain > CONDITIONING_LIMIT_DB { 2 } else { 1 })
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

impl AnySpectrum {
    /// Prepare `volume` at `precision` for `filter`.
    ///
    /// # Errors
    /// As [`OwnedSpectrum::prepare`].
    pub fn prepare(
        volume: &Volume,
        filter: Filter,
        precision: Precision,
    ) -> Result<Self, PipelineError> {
        Ok(match precision {
            Precision::F16 => AnySpectrum::F16(OwnedSpectrum::prepare::<f32>(volume, filter)?),
            Precision::F32 => AnySpectrum::F32(OwnedSpectrum::prepare::<f32>(volume, filter)?),
            Precision::F64 => AnySpectrum::F64(OwnedSpectrum::prepare::<f64>(volume, filter)?),
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

    /// Render one view; the image comes back in f64 whatever the precision.
    ///
    /// # Errors
    /// As [`fvr_core::render::render`].
    pub fn render(
        &self,
        view: &View,
        width: usize,
        height: usize,
    ) -> Result<Vec<f64>, fvr_core::Error> {
        self.render_sampled(view, &Sampling::UNIT, width, height)
    }

    /// [`AnySpectrum::render`] in physical units: voxel spacing and pixel
    /// size from `sampling`, values in mm × volume units.
    ///
    /// # Errors
    /// As [`fvr_core::render::render_sampled`].
    pub fn render_sampled(
        &self,
        view: &View,
        sampling: &Sampling,
        width: usize,
        height: usize,
    ) -> Result<Vec<f64>, fvr_core::Error> {
        fn go<S: Sample, T: Real>(
            s: &OwnedSpectrum<S>,
            view: &View,
            sampling: &Sampling,
            w: usize,
            h: usize,
        ) -> Result<Vec<f64>, fvr_core::Error> {
            let mut r = ViewRenderer::<T>::new(s.n(), s.filter());
            let mut out = vec![T::ZERO; w * h];
            r.render_sampled_into(s, view, sampling, w, h, &mut out)?;
            Ok(out.into_iter().map(T::to_f64).collect())
        }
        match self {
            AnySpectrum::F16(s) => go::<_, f32>(s, view, sampling, width, height),
            AnySpectrum::F32(s) => go::<_, f32>(s, view, sampling, width, height),
            AnySpectrum::F64(s) => go::<_, f64>(s, view, sampling, width, height),
        }
    }

    /// The progressive preview at `level` ([`fvr_core::progressive`]):
    /// a `width × height` image at pitch `2^level` voxels.
    ///
    /// # Errors
    /// As [`fvr_core::progressive::render_level`].
    pub fn render_level(
        &self,
        view: &View,
        width: usize,
        height: usize,
        level: u32,
    ) -> Result<Vec<f64>, fvr_core::Error> {
        self.render_level_sampled(view, &Sampling::UNIT, width, height, level)
    }

    /// [`AnySpectrum::render_level`] in physical units: pixels
    /// `2^level·sampling.pixel_size()` mm apart.
    ///
    /// # Errors
    /// As [`fvr_core::progressive::render_level_sampled`].
    pub fn render_level_sampled(
        &self,
        view: &View,
        sampling: &Sampling,
        width: usize,
        height: usize,
        level: u32,
    ) -> Result<Vec<f64>, fvr_core::Error> {
        fn go<S: Sample, T: Real>(
            s: &OwnedSpectrum<S>,
            view: &View,
            sampling: &Sampling,
            w: usize,
            h: usize,
            level: u32,
        ) -> Result<Vec<f64>, fvr_core::Error> {
            let n = s.n();
            let m = (n >> level.min(usize::BITS - 1)).max(1);
            let mut tw_buf = vec![T::ZERO; Twiddles::<T>::buffer_len(n)];
            let tw = Twiddles::new(&mut tw_buf, n)?;
            let kernel = KernelTable::<T>::new(s.filter());
            let mut grid = vec![T::ZERO; m * m];
            let mut aux = vec![T::ZERO; aux_len(m)];
            let mut out = vec![T::ZERO; w * h];
            fvr_core::progressive::render_level_sampled(
                &s.view(),
                &kernel,
                view,
                sampling,
                w,
                h,
                level,
                &tw,
                &mut grid,
                &mut aux,
                &mut out,
            )?;
            Ok(out.into_iter().map(T::to_f64).collect())
        }
        match self {
            AnySpectrum::F16(s) => go::<_, f32>(s, view, sampling, width, height, level),
            AnySpectrum::F32(s) => go::<_, f32>(s, view, sampling, width, height, level),
            AnySpectrum::F64(s) => go::<_, f64>(s, view, sampling, width, height, level),
        }
    }
}
