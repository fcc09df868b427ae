//! Adaptive views with reusable buffers: the kernel tables of the chain,
//! the twiddles and the slice built once, then one adaptive extraction
//! ([`super::fast_adaptive`], the core's for spectra it does not serve) and
//! one 2D inverse transform per view.
//!
//! The adaptive walk computes every point's position in floating point and
//! its weights from the kernel tables (the core's adaptive arithmetic), so
//! a point on the large filter costs more than in the plain walk
//! ([`super::fast_slice`]). When the marks move too small a share of a
//! view's samples to the cheaper filters ([`AdaptiveMarks::plain_below`],
//! counted first by [`fast_adaptive::tally`]), the view is rendered by the
//! plain walk instead: the full filter's image bit for bit, which meets any
//! tolerance.

use fvr_core::dht::Twiddles;
use fvr_core::filter::KernelTable;
use fvr_core::geometry::{Sampling, View};
use fvr_core::image::{aux_len, check_image, finish, placement, placement_on_axes, Crop};
use fvr_core::num::{Real, Sample};
use fvr_core::slice::adaptive::{extract_slice_adaptive, AdaptiveLevel, AdaptiveStats};

use super::adaptive::AdaptiveMarks;
use super::fast_adaptive;
use super::fast_slice::{self, Tiling};
use super::spectrum::OwnedSpectrum;
use super::view::Walk;
use super::{fast_column, fast_strip};

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
    /// The column walk's sums between its passes.
    along: Vec<T>,
    /// The strip walk's values of the large filter's points
    /// ([`fast_adaptive::extract_with_strip`]), allocated at the first
    /// view that takes it.
    strong: Vec<T>,
    walk: Walk,
    parallel: bool,
    core: bool,
    tiling: Tiling,
    last: Walked,
}

/// How a view was extracted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Walked {
    /// By the adaptive walk (the host's or the core's).
    Adaptive,
    /// By the plain walk with the full filter, because the marks would have
    /// moved only `share` of the view's samples to the cheaper filters,
    /// below [`AdaptiveMarks::plain_below`].
    Plain {
        /// Share of the slice samples the marks allowed on the cheaper
        /// filters.
        share: f64,
    },
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
            tables: marks.tables(),
            tw,
            grid: vec![T::ZERO; n * n],
            aux: vec![T::ZERO; aux_len(n)],
            along: Vec::new(),
            strong: Vec::new(),
            walk: Walk::default(),
            parallel: true,
            core: false,
            tiling: Tiling::default(),
            last: Walked::Adaptive,
        })
    }

    /// Extract and finish on the current rayon pool's threads (`true`, the
    /// default) or on this one. The image is the same bit for bit either
    /// way.
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = parallel;
        self
    }

    /// Sum the points on the large filter by the plain strip walk
    /// ([`Walk::Strip`], the default, where the slice's rows hold a
    /// coordinate: its values, within rounding of the core's) or point by
    /// point in the core's arithmetic ([`Walk::Exact`]: the core's image
    /// bit for bit). The points on the cheaper filters are the core's bit
    /// for bit either way.
    pub fn with_walk(mut self, walk: Walk) -> Self {
        self.walk = walk;
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

    /// How the last view [`AdaptiveRenderer::render_into`] rendered was
    /// extracted.
    pub fn walked(&self) -> Walked {
        self.last
    }

    /// Render one view into `out` (`width × height`, row 0 at the top); the
    /// extraction's statistics. With the plain walk ([`Walked::Plain`]),
    /// every sample is counted on the full filter.
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
        let levels = self.marks.core_levels(&self.tables)?;
        let core_spec = spec.view();
        self.last = Walked::Adaptive;
        if let Some(stats) = self.plain_instead(&core_spec, &levels, &frame) {
            let axes = Sampling::UNIT.slice_axes(&frame);
            let (kernel, grid, along) = (&self.kernel, &mut self.grid, &mut self.along);
            // The plain renderer's walk ([`super::view::Walk::Strip`]).
            let (tiling, parallel) = (self.tiling, self.parallel);
            if fast_column::extract(&core_spec, kernel, &axes, tiling, parallel, grid, along)
                || fast_strip::extract(&core_spec, kernel, &axes, tiling, parallel, grid)
                || fast_slice::extract(&core_spec, kernel, &axes, tiling, parallel, grid)
            {
                let share = 1.0 - stats.per_filter[0] as f64 / stats.samples.max(1) as f64;
                self.last = Walked::Plain { share };
                let place = placement_on_axes(core_spec.dims(), &axes, width, height, 1.0);
                let crop = Crop::new(
                    place,
                    Sampling::UNIT.gain() / core_spec.scale(),
                    width,
                    height,
                );
                self.finish(n, &crop, out)?;
                return Ok(AdaptiveStats {
                    samples: stats.samples,
                    per_filter: core::array::from_fn(|i| if i == 0 { stats.samples } else { 0 }),
                    taps: stats.full_taps,
                    full_taps: stats.full_taps,
                });
            }
        }
        let whole = self.marks.summary();
        let (kernel, tiling, parallel) = (&self.kernel, self.tiling, self.parallel);
        let host = match (self.core, self.walk) {
            (true, _) => None,
            (false, Walk::Exact) => fast_adaptive::extract(
                &core_spec,
                kernel,
                &levels,
                whole,
                &frame,
                tiling,
                parallel,
                &mut self.grid,
            ),
            (false, Walk::Strip) => {
                self.strong.resize(n * n, T::ZERO);
                fast_adaptive::extract_with_strip(
                    &core_spec,
                    kernel,
                    &levels,
                    whole,
                    &frame,
                    tiling,
                    parallel,
                    &mut self.grid,
                    &mut self.strong,
                )
            }
        };
        let stats = match host {
            Some(stats) => stats,
            None => {
                extract_slice_adaptive(&core_spec, &self.kernel, &levels, &frame, &mut self.grid)?
            }
        };
        let place = placement(core_spec.dims(), &frame, width, height);
        let crop = Crop::new(place, 1.0 / core_spec.scale(), width, height);
        self.finish(n, &crop, out)?;
        Ok(stats)
    }

    /// The statistics of the adaptive walk when it would move less than
    /// [`AdaptiveMarks::plain_below`] of the samples to the cheaper
    /// filters (the plain walk is then faster); `None` when the adaptive
    /// walk is to be used (the core's walk asked for, no threshold, or a
    /// spectrum the host's walks do not serve).
    fn plain_instead<S: Sample>(
        &self,
        spec: &fvr_core::spectrum::Spectrum<'_, S>,
        levels: &[AdaptiveLevel<'_, '_, T>],
        frame: &fvr_core::geometry::Frame,
    ) -> Option<AdaptiveStats> {
        let below = self.marks.plain_below;
        if self.core || below <= 0.0 || self.grid.len() != spec.n() * spec.n() {
            return None;
        }
        let whole = self.marks.summary();
        let stats = fast_adaptive::tally(spec, &self.kernel, levels, whole, frame, self.parallel)?;
        let cheap = stats.samples - stats.per_filter[0];
        ((cheap as f64) < below * stats.samples as f64).then_some(stats)
    }

    /// Shift, inverse-transform and crop the slice into `out` on this
    /// thread: at side 256 the core's finish was faster than the threaded
    /// one ([`super::fast_inverse::finish_threaded`]) on the two shared
    /// cores it was measured on (docs/adaptive.md).
    fn finish(&mut self, n: usize, crop: &Crop, out: &mut [T]) -> Result<(), fvr_core::Error> {
        let tw = Twiddles::from_table(&self.tw, n)?;
        finish(&mut self.grid, n, crop, &tw, &mut self.aux, out)
    }
}
