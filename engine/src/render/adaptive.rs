//! Adaptive views with reusable buffers: the kernel tables of the chain,
//! the twiddles and the slice built once, then one adaptive extraction
//! ([`crate::slice::adaptive::walk`], the core's for spectra it does not serve) and
//! one 2D inverse transform per view.
//!
//! The adaptive walk computes every point's position in floating point and
//! its weights from the kernel tables (the core's adaptive arithmetic), so
//! a point on the large filter costs more than in the plain walk
//! ([`crate::slice::exact`]). When the marks move too small a share of a
//! view's samples to the cheaper filters ([`AdaptiveMarks::plain_below`]),
//! the view is rendered by the plain walk instead: the full filter's image
//! bit for bit, which meets any tolerance. The share is the adaptive walk's
//! own count, taken once every point's filter is settled and before the
//! large filter's points are summed
//! ([`walk::extract_with_strip_if`]; [`walk::tally`]
//! first for the exact walk).

use fvr_core::dht::{dht_2d_sparse_len, Twiddles};
use fvr_core::filter::KernelTable;
use fvr_core::geometry::{Sampling, View};
use fvr_core::image::{aux_len, check_image, finish, placement, placement_on_axes, Crop};
use fvr_core::num::{Real, Sample};
use fvr_core::slice::adaptive::{extract_slice_adaptive, AdaptiveStats};

use crate::render::view::Walk;
use crate::slice::adaptive::walk::{self, AdaptiveJob, Settled};
use crate::slice::adaptive::AdaptiveMarks;
use crate::slice::column;
use crate::slice::exact::{self, SliceJob, Tiling};
use crate::slice::strip;
use crate::spectrum::OwnedSpectrum;

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
    /// ([`walk::extract_with_strip`]), allocated at the first
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
            // Room for the 2D inverse to batch the row pass of a slice
            // whose strong samples lie on few rows.
            aux: vec![T::ZERO; aux_len(n).max(dht_2d_sparse_len(n))],
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
        let below = self.marks.plain_below;
        // Whether the plain walk may take the view: not when the core's
        // walk is asked for, nor with no threshold.
        let decide = !self.core && below > 0.0 && self.grid.len() == n * n;
        let adaptive = |stats: &AdaptiveStats| {
            let cheap = stats.samples - stats.per_filter[0];
            !decide || cheap as f64 >= below * stats.samples as f64
        };
        let whole = self.marks.summary();
        let (kernel, tiling, parallel) = (&self.kernel, self.tiling, self.parallel);
        let job = AdaptiveJob::new(&core_spec, kernel, &levels, whole, &frame, tiling, parallel);
        let host = match (self.core, self.walk) {
            (true, _) => None,
            (false, Walk::Exact) => {
                let counted = match decide {
                    true => walk::tally(&job),
                    false => None,
                };
                match counted.filter(|stats| !adaptive(stats)) {
                    Some(stats) => Some(Settled::Declined(stats)),
                    None => walk::extract(&job, &mut self.grid).map(Settled::Extracted),
                }
            }
            (false, Walk::Strip) => {
                self.strong.resize(n * n, T::ZERO);
                walk::extract_with_strip_if(&job, &mut self.grid, &mut self.strong, adaptive)
            }
        };
        let stats = match host {
            Some(Settled::Extracted(stats)) => stats,
            Some(Settled::Declined(stats)) => {
                let (kernel, grid, along) = (&self.kernel, &mut self.grid, &mut self.along);
                if let Some(axes) =
                    plain(&core_spec, &frame, kernel, (tiling, parallel), grid, along)
                {
                    let share = 1.0 - stats.per_filter[0] as f64 / stats.samples.max(1) as f64;
                    self.last = Walked::Plain { share };
                    let place = placement_on_axes(core_spec.dims(), &axes, width, height, 1.0);
                    let gain = Sampling::UNIT.gain() / core_spec.scale();
                    self.finish(n, &Crop::new(place, gain, width, height), out)?;
                    return Ok(AdaptiveStats {
                        samples: stats.samples,
                        per_filter: core::array::from_fn(|i| match i {
                            0 => stats.samples,
                            _ => 0,
                        }),
                        taps: stats.full_taps,
                        full_taps: stats.full_taps,
                    });
                }
                // No plain walk serves the spectrum: the adaptive one does.
                let grid = &mut self.grid;
                match walk::extract(&job, grid) {
                    Some(stats) => stats,
                    None => extract_slice_adaptive(&core_spec, kernel, &levels, &frame, grid)?,
                }
            }
            None => {
                extract_slice_adaptive(&core_spec, &self.kernel, &levels, &frame, &mut self.grid)?
            }
        };
        let place = placement(core_spec.dims(), &frame, width, height);
        let crop = Crop::new(place, 1.0 / core_spec.scale(), width, height);
        self.finish(n, &crop, out)?;
        Ok(stats)
    }

    /// Shift, inverse-transform and crop the slice into `out` on this
    /// thread: at side 256 the core's finish was faster than the threaded
    /// one ([`crate::image::inverse::finish_threaded`]) on the two shared
    /// cores it was measured on (docs/adaptive.md).
    fn finish(&mut self, n: usize, crop: &Crop, out: &mut [T]) -> Result<(), fvr_core::Error> {
        let tw = Twiddles::from_table(&self.tw, n)?;
        finish(&mut self.grid, n, crop, &tw, &mut self.aux, out)
    }
}

/// The slice of `spec` along `frame` by the plain renderer's walk with the
/// full filter ([`crate::render::view::Walk::Strip`]) into `grid`, and its axes;
/// `None` when no plain walk serves the spectrum.
fn plain<S: Sample, T: Real>(
    spec: &fvr_core::spectrum::Spectrum<'_, S>,
    frame: &fvr_core::geometry::Frame,
    kernel: &KernelTable<T>,
    (tiling, parallel): (Tiling, bool),
    grid: &mut [T],
    along: &mut Vec<T>,
) -> Option<fvr_core::geometry::SliceAxes> {
    let axes = Sampling::UNIT.slice_axes(frame);
    let job = SliceJob::new(spec, kernel, &axes, tiling, parallel);
    let walked = column::extract(&job, grid, along)
        || strip::extract(&job, grid)
        || exact::extract(&job, grid);
    walked.then_some(axes)
}

impl AdaptiveMarks {
    /// Render one view adaptively; returns the image (f64) and statistics.
    /// For many views, keep an [`AdaptiveRenderer`] instead.
    ///
    /// # Errors
    /// As [`fvr_core::render::render`].
    pub fn render<S: Sample, T: Real>(
        &self,
        spec: &OwnedSpectrum<S>,
        view: &View,
        width: usize,
        height: usize,
    ) -> Result<(Vec<f64>, AdaptiveStats), fvr_core::Error> {
        let mut out = vec![T::ZERO; width * height];
        let stats = AdaptiveRenderer::<T>::new(self, spec)?
            .render_into(spec, view, width, height, &mut out)?;
        Ok((out.into_iter().map(T::to_f64).collect(), stats))
    }

    /// A sentence on how a view was walked and whether adaptivity had any
    /// effect in its `stats`.
    pub fn note(&self, stats: &AdaptiveStats, walked: Walked) -> Option<String> {
        match walked {
            Walked::Plain { share } => Some(format!(
                "the marks allow {:.1}% of this view's samples on the cheaper filters, below \
                 the {:.1}% at which the adaptive walk pays: 0.0% of samples substituted, plain \
                 walk used (the full filter's image)",
                100.0 * share,
                100.0 * self.plain_below
            )),
            Walked::Adaptive => self.effect(stats),
        }
    }
}
