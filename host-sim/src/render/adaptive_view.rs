//! Adaptive views with reusable buffers: the kernel tables of the chain,
//! the twiddles and the slice built once, then one adaptive extraction
//! ([`super::fast_adaptive`], the core's for spectra it does not serve) and
//! one 2D inverse transform per view.

use fvr_core::dht::Twiddles;
use fvr_core::filter::KernelTable;
use fvr_core::geometry::View;
use fvr_core::image::{aux_len, check_image, finish, grid_len, placement, Crop, Inverse};
use fvr_core::num::{Real, Sample};
use fvr_core::slice::adaptive::{extract_slice_adaptive, AdaptiveLevel, AdaptiveStats, Marks};

use super::adaptive::AdaptiveMarks;
use super::fast_adaptive;
use super::fast_inverse::finish_threaded;
use super::fast_slice::Tiling;
use super::spectrum::OwnedSpectrum;

/// Reusable per-view buffers and tables for adaptive views of one
/// spectrum's marks, in arithmetic `T`.
#[derive(Debug)]
pub struct AdaptiveRenderer<'m, T> {
    marks: &'m AdaptiveMarks,
    kernel: KernelTable<T>,
    tables: Vec<KernelTable<T>>,
    tw: Vec<T>,
    grid: Vec<T>,
    aux: Vec<T>,
    /// The transposed grid of the threaded finish.
    trans: Vec<T>,
    parallel: bool,
    core: bool,
    tiling: Tiling,
}

impl<'m, T: Real> AdaptiveRenderer<'m, T> {
    /// Tables and buffers for views of `spec` with `marks` (built for it).
    ///
    /// # Errors
    /// A side the radix-2 twiddles do not serve.
    pub fn new<S: Sample>(
        marks: &'m AdaptiveMarks,
        spec: &OwnedSpectrum<S>,
    ) -> Result<Self, fvr_core::Error> {
        let n = spec.n();
        let mut tw = vec![T::ZERO; Twiddles::<T>::buffer_len(n)];
        Twiddles::new(&mut tw, n)?;
        Ok(Self {
            marks,
            kernel: KernelTable::new(spec.filter()),
            tables: marks
                .levels
                .iter()
                .map(|l| KernelTable::new(l.filter))
                .collect(),
            tw,
            grid: vec![T::ZERO; n * n],
            aux: vec![T::ZERO; aux_len(n)],
            trans: vec![T::ZERO; grid_len(n)],
            parallel: true,
            core: false,
            tiling: Tiling::default(),
        })
    }

    /// Extract and finish on the current rayon pool's threads (`true`, the
    /// default) or on this one. The image is the same bit for bit either
    /// way.
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = parallel;
        self
    }

    /// Extract with the core's single-threaded walk
    /// (`fvr_core::slice::adaptive::extract_slice_adaptive`) when `core`:
    /// the reference the host's walk is measured against. The image is the
    /// same bit for bit either way.
    pub fn with_core(mut self, core: bool) -> Self {
        self.core = core;
        self
    }

    /// Render one view into `out` (`width × height`, row 0 at the top); the
    /// extraction's statistics.
    ///
    /// # Errors
    /// As [`fvr_core::render::render`]; a spectrum of another side than the
    /// renderer's (a length mismatch).
    pub fn render_into<S: Sample>(
        &mut self,
        spec: &OwnedSpectrum<S>,
        view: &View,
        width: usize,
        height: usize,
        out: &mut [T],
    ) -> Result<AdaptiveStats, fvr_core::Error> {
        // Of another side than the renderer's, the grid and twiddles do
        // not fit, and the core's checks report it.
        let n = spec.n();
        let frame = view.frame()?;
        check_image(width, height, n)?;
        let levels: Vec<AdaptiveLevel<'_, '_, T>> = self
            .marks
            .levels
            .iter()
            .zip(&self.tables)
            .map(|(l, t)| {
                Ok(AdaptiveLevel {
                    kernel: t,
                    marks: Marks::new(&l.words, self.marks.n())?,
                    gain: T::from_f64(l.gain),
                })
            })
            .collect::<Result<_, fvr_core::Error>>()?;
        let core_spec = spec.view();
        let host = match self.core {
            true => None,
            false => fast_adaptive::extract(
                &core_spec,
                &self.kernel,
                &levels,
                &frame,
                self.tiling,
                self.parallel,
                &mut self.grid,
            ),
        };
        let stats = match host {
            Some(stats) => stats,
            None => {
                extract_slice_adaptive(&core_spec, &self.kernel, &levels, &frame, &mut self.grid)?
            }
        };
        let tw = Twiddles::from_table(&self.tw, n)?;
        let place = placement(core_spec.dims(), &frame, width, height);
        let crop = Crop::new(place, 1.0 / core_spec.scale(), width, height);
        // At a few % of the taps the view is bound by its finish as much
        // as by the walk: the 2D inverse on the threads too when the walk
        // is (`fast_inverse`, the core's image bit for bit).
        if self.parallel && !self.core {
            let inverse = Inverse::Radix2(&tw);
            finish_threaded(&mut self.grid, n, &crop, inverse, &mut self.trans, out)?;
        } else {
            finish(&mut self.grid, n, &crop, &tw, &mut self.aux, out)?;
        }
        Ok(stats)
    }
}
