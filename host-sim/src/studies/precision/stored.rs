//! A spectrum held in any storage format, with block exponents for block
//! floating point: prepared in place or rounded once from f32.

use fvr_core::dht::{Rounding, Twiddles};
use fvr_core::filter::Filter;
use fvr_core::geometry::View;
use fvr_core::num::{encode_blocks, encode_elements, BlockExponents, BlockLayout, Blocking};
use fvr_core::num::{Real, Sample};
use fvr_core::render::Request;
use fvr_core::spectrum::{prepare_scratch_len, LineBlockStorage, Spectrum};
use fvr_core::volume::{padded_size, DenseVolume};
use fvr_engine::render::view::render_once;

use fvr_engine::spectrum::PipelineError;
use fvr_engine::volume::Volume;

/// A spectrum in storage format `S`, owned, with block exponents if any.
#[derive(Clone, Debug)]
pub struct StoredSpectrum<S> {
    pub(super) data: Vec<S>,
    blocks: Option<(BlockLayout, Vec<i8>)>,
    n: usize,
    scale: f64,
    filter: Filter,
    dims: [usize; 3],
}

impl<S: Sample> StoredSpectrum<S> {
    /// Premultiply, pad and transform `volume` in place in format `S`, with
    /// arithmetic `T` and the given rounding.
    ///
    /// # Errors
    /// As [`Spectrum::prepare_rounding`], or a spectrum beyond memory.
    pub fn prepare<T: Real>(
        volume: &Volume,
        filter: Filter,
        rounding: Rounding,
    ) -> Result<Self, PipelineError> {
        Self::prepare_in_place::<T>(volume, filter, rounding, false)
    }

    /// Premultiply, pad and transform `volume` in place in format `S`, with
    /// arithmetic `T` and the given rounding; with `line_blocks`, into block
    /// floating point with per-line exponents
    /// ([`Spectrum::prepare_line_blocks`]).
    ///
    /// # Errors
    /// As [`Spectrum::prepare_rounding`] or [`Spectrum::prepare_line_blocks`],
    /// or a spectrum beyond memory.
    pub fn prepare_in_place<T: Real>(
        volume: &Volume,
        filter: Filter,
        rounding: Rounding,
        line_blocks: bool,
    ) -> Result<Self, PipelineError> {
        let (n, mut data, mut scratch, mut tw_buf) = buffers::<S, T>(volume, filter)?;
        let source = DenseVolume::new(volume.dims, &volume.data)?;
        let tw = Twiddles::new(&mut tw_buf, n)?;
        let (scale, dims, blocks) = if line_blocks {
            let mut exps = vec![0i8; n * n];
            let mut exps_scratch = vec![0i8; n * n];
            let spec = Spectrum::prepare_line_blocks(
                &source,
                filter,
                LineBlockStorage {
                    mantissas: &mut data,
                    exponents: &mut exps,
                    exponent_scratch: &mut exps_scratch,
                },
                &mut scratch,
                &tw,
                rounding,
            )?;
            let (scale, dims) = (spec.scale(), spec.dims());
            (scale, dims, Some((BlockLayout::Line, exps)))
        } else {
            let spec = Spectrum::prepare_rounding(
                &source,
                filter,
                &mut data,
                &mut scratch,
                &tw,
                rounding,
            )?;
            (spec.scale(), spec.dims(), None)
        };
        Ok(Self {
            data,
            blocks,
            n,
            scale,
            filter,
            dims,
        })
    }

    /// Round a finished spectrum `src` to `S` once: element by element
    /// (rescaled by a power of two to `S`'s scaling exponent), or with block
    /// exponents.
    ///
    /// # Errors
    /// An overflow, or a block layout that does not fit.
    pub fn encode<U: Sample>(
        src: &StoredSpectrum<U>,
        blocking: Blocking,
    ) -> Result<Self, fvr_core::Error> {
        let n = src.n;
        let mut data = vec![S::default(); n * n * n];
        let values: Vec<f64> = src.data.iter().map(|v| v.to_f64()).collect();
        let (blocks, scale) = match blocking {
            Blocking::Volume => {
                let factor = 2f64.powi(S::SCALE_LOG2 - U::SCALE_LOG2);
                encode_elements(&values, factor, &mut data)?;
                (None, src.scale * factor)
            }
            Blocking::Blocks(layout) => {
                let mut exps = vec![0i8; layout.exponent_count(n)?];
                encode_blocks(&values, n, layout, &mut data, &mut exps)?;
                (Some((layout, exps)), src.scale)
            }
        };
        Ok(Self {
            data,
            blocks,
            n,
            scale,
            filter: src.filter,
            dims: src.dims,
        })
    }

    /// Borrow as a core spectrum.
    pub fn view(&self) -> Spectrum<'_, S> {
        let parts = match &self.blocks {
            None => Spectrum::from_parts(&self.data, self.n, self.scale, self.filter, self.dims),
            Some((layout, exps)) => BlockExponents::new(*layout, exps, self.n).and_then(|b| {
                Spectrum::from_blocks(&self.data, b, self.n, self.scale, self.filter, self.dims)
            }),
        };
        parts.expect("parts come from a prepared spectrum")
    }

    /// Side of the padded cube.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Bytes held, block exponents included.
    pub fn bytes(&self) -> usize {
        self.view().bytes()
    }

    /// `(Σ stored², count of non-finite)`, the stored values times their
    /// block's power of two.
    pub fn stored_stats(&self) -> (f64, usize) {
        let spec = self.view();
        let mut sum = 0.0;
        let mut bad = 0;
        for i in 0..self.data.len() {
            let v = spec.value(i);
            if v.is_finite() {
                sum += v * v;
            } else {
                bad += 1;
            }
        }
        (sum, bad)
    }

    /// Render one view with arithmetic `T`; the image comes back in f64.
    ///
    /// # Errors
    /// As [`fvr_core::render::render`].
    pub fn render<T: Real>(
        &self,
        view: &View,
        width: usize,
        height: usize,
    ) -> Result<Vec<f64>, fvr_core::Error> {
        render_once::<S, T>(&self.view(), &Request::new(*view, width, height))
    }
}

/// The side of a padded spectrum and the buffers of its in-place
/// preparation in `S` with arithmetic `T`: spectrum, scratch, twiddles.
type PrepareBuffers<S, T> = (usize, Vec<S>, Vec<T>, Vec<T>);

/// [`PrepareBuffers`] for `volume`, refusing a spectrum beyond memory first.
fn buffers<S: Sample, T: Real>(
    volume: &Volume,
    filter: Filter,
) -> Result<PrepareBuffers<S, T>, PipelineError> {
    let n = padded_size(volume.dims, filter.oversample())?;
    fvr_engine::spectrum::check_memory(n, std::mem::size_of::<S>())?;
    Ok((
        n,
        vec![S::default(); n * n * n],
        vec![T::ZERO; prepare_scratch_len(n)],
        vec![T::ZERO; Twiddles::<T>::buffer_len(n)],
    ))
}
