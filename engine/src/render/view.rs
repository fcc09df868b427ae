//! Reusable per-view buffers: one extraction and one 2D inverse transform
//! per view, no allocation after the first.

use fvr_core::dht::{mixed_table_len, MixedPlan, Twiddles};
use fvr_core::filter::{Filter, KernelTable};
use fvr_core::geometry::{Sampling, SliceAxes, View};
use fvr_core::image::{aux_len, check_image, finish_with, grid_len, placement_on_axes};
use fvr_core::image::{Crop, Inverse};
use fvr_core::num::{Real, Sample};
use fvr_core::render::{render, render_projection_with, Buffers, Request, Source};
use fvr_core::slice::extract_slice_rows;
use fvr_core::spectrum::Spectrum;

use crate::image::inverse::MixedFinish;
use crate::image::zoom::ZoomFinish;
use crate::slice::column;
use crate::slice::exact::{self, SliceJob, Tiling};
use crate::slice::strip;
use crate::spectrum::exchange;
use crate::spectrum::{with_arithmetic, AnySpectrum, OwnedSpectrum};

/// Reusable per-view buffers and tables for arithmetic `T`.
#[derive(Debug)]
pub struct ViewRenderer<T> {
    kernel: KernelTable<T>,
    tw: Vec<T>,
    grid: Vec<T>,
    aux: Vec<T>,
    /// The column walk's sums between its passes.
    along: Vec<T>,
    /// The threaded finish of a mixed-radix side.
    mixed: Option<MixedFinish<T>>,
    n: usize,
    threads: usize,
    pool: Option<rayon::ThreadPool>,
    tiling: Tiling,
    walk: Walk,
    /// Strip views with rows along y drawn so far ([`Self::exchanged`]).
    y_rows_views: usize,
    /// The zero-padded finish of a magnified image ([`Self::with_zoom`]).
    zoom: Option<ZoomFinish<T>>,
    /// The walk that took the last view's slice.
    walked: Option<WalkTaken>,
}

/// How a plain view's slice is summed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Walk {
    /// Factored along the axis the slice contains, where there is one
    /// ([`column::extract`]), else reduced along the axis the slice's rows
    /// hold, where there is one ([`strip::extract`]): the core's values to
    /// within rounding, with a third to a sixth of the products. Elsewhere
    /// point by point with the sums in lanes where the core has them
    /// ([`exact::extract_reordered`]: the core's values to within
    /// rounding), else as [`Walk::Exact`].
    #[default]
    Strip,
    /// Tap by tap in the core's order ([`exact::extract`]): the core's
    /// values bit for bit.
    Exact,
}

/// The walk that filled a view's slice: the first of the renderer's
/// [`Walk`] that takes it, in the order they are tried.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WalkTaken {
    /// Factored along the axis the slice contains ([`column::extract`]).
    Column,
    /// The strip walk on the spectrum with x and y exchanged
    /// ([`strip::extract_exchanged`]).
    Exchanged,
    /// Reduced along the axis the slice's rows hold ([`strip::extract`]).
    Strip,
    /// Point by point, each point's sum reordered in lanes
    /// ([`exact::extract_reordered`]).
    Reordered,
    /// Point by point in the core's order ([`exact::extract`]).
    Exact,
    /// The core's walk (a spectrum, grid or zoom the host's walks do not
    /// take), on blocks of rows or on this thread.
    Core,
}

impl WalkTaken {
    /// Every walk, in the order the renderer tries them.
    pub const ALL: [Self; 6] = [
        Self::Column,
        Self::Exchanged,
        Self::Strip,
        Self::Reordered,
        Self::Exact,
        Self::Core,
    ];

    /// The walk's name in reports: `column`, `exchanged`, `strip`,
    /// `reordered`, `exact` or `core`.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Column => "column",
            Self::Exchanged => "exchanged",
            Self::Strip => "strip",
            Self::Reordered => "reordered",
            Self::Exact => "exact",
            Self::Core => "core",
        }
    }
}

/// How many views each walk took ([`WalkTaken::ALL`]'s order).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WalkCounts(pub [usize; 6]);

impl WalkCounts {
    /// One more view taken by `walk`.
    pub fn add(&mut self, walk: WalkTaken) {
        self.0[walk as usize] += 1;
    }

    /// The walks that took views, each with its count, in
    /// [`WalkTaken::ALL`]'s order.
    pub fn taken(&self) -> impl Iterator<Item = (WalkTaken, usize)> + '_ {
        WalkTaken::ALL
            .into_iter()
            .zip(self.0)
            .filter(|&(_, count)| count > 0)
    }

    /// Both counts added.
    pub fn merged(self, other: Self) -> Self {
        Self(core::array::from_fn(|i| self.0[i] + other.0[i]))
    }
}

/// Fill `grid` with the slice of `job` by the first walk of `walk` that
/// takes it (`exchanged`: the job on the spectrum with x and y exchanged,
/// where the renderer holds it); `None` (grid untouched) when none does.
fn fill<S: Sample, T: Real>(
    walk: Walk,
    job: &SliceJob<'_, Spectrum<'_, S>, T>,
    exchanged: Option<&(Spectrum<'_, S>, SliceAxes)>,
    grid: &mut [T],
    along: &mut Vec<T>,
) -> Option<WalkTaken> {
    if walk == Walk::Strip {
        if column::extract(job, grid, along) {
            return Some(WalkTaken::Column);
        }
        if let Some((spec, axes)) = exchanged {
            if strip::extract_exchanged(&SliceJob { spec, axes, ..*job }, grid) {
                return Some(WalkTaken::Exchanged);
            }
        }
        if strip::extract(job, grid) {
            return Some(WalkTaken::Strip);
        }
        if exact::extract_reordered(job, grid) {
            return Some(WalkTaken::Reordered);
        }
    }
    exact::extract(job, grid).then_some(WalkTaken::Exact)
}

impl<T: Real> ViewRenderer<T> {
    /// Buffers for spectra of side `n` and `filter`: radix-2 twiddles for
    /// a power of two, else a mixed-radix plan's table.
    pub fn new(n: usize, filter: Filter) -> Self {
        let tw = inverse_table::<T>(n);
        Self {
            kernel: KernelTable::new(filter),
            tw,
            grid: vec![T::ZERO; grid_len(n)],
            aux: vec![T::ZERO; aux_len(n)],
            along: Vec::new(),
            mixed: (!n.is_power_of_two())
                .then(|| MixedFinish::new(n).ok())
                .flatten(),
            n,
            threads: 0,
            pool: None,
            tiling: Tiling::default(),
            walk: Walk::default(),
            y_rows_views: 0,
            zoom: None,
            walked: None,
        }
    }

    /// The spectrum with x and y exchanged and the axes to match
    /// ([`OwnedSpectrum::exchanged_xy`]), for a strip view whose rows run
    /// mostly along y ([`exchange::rows_along_y`]) and contain no
    /// axis: from the second such view this renderer draws (a single view
    /// would pay for the copy without using it again), or at once if the
    /// spectrum already holds the copy.
    fn exchanged<'s, S: Sample>(
        walk: Walk,
        seen: &mut usize,
        spec: &'s OwnedSpectrum<S>,
        axes: &SliceAxes,
    ) -> Option<(Spectrum<'s, S>, SliceAxes)> {
        if !Self::wants_exchanged(walk, axes) {
            return None;
        }
        *seen += 1;
        if *seen < 2 && spec.exchanged_bytes() == 0 {
            return None;
        }
        Some((spec.exchanged_xy()?, exchange::exchanged(axes)))
    }

    /// Whether a view of `axes` walked as `walk` reads the spectrum with
    /// x and y exchanged, once it is built.
    fn wants_exchanged(walk: Walk, axes: &SliceAxes) -> bool {
        walk == Walk::Strip && exchange::rows_along_y(axes) && column::column_axis(axes).is_none()
    }

    /// Build what a batch of `views` will share before its renderers start:
    /// the spectrum with x and y exchanged, when at least two of the views
    /// read it under the default walk. A renderer that drew the views in
    /// turn would build it at the second; the renderers of a batch's tasks
    /// each see only a few views, and without this most of them never
    /// reached it (measured on the CT head: a batch of views along
    /// (1, 0.45, 0.3) took 34 ms a view, 5 times the same views about y).
    pub fn share_for_batch<S: Sample>(
        spec: &OwnedSpectrum<S>,
        views: &[View],
        sampling: &Sampling,
    ) {
        let wanting = views
            .iter()
            .filter(|v| {
                v.frame()
                    .is_ok_and(|f| Self::wants_exchanged(Walk::default(), &sampling.slice_axes(&f)))
            })
            .take(2)
            .count();
        if wanting == 2 {
            let _ = spec.exchanged_xy();
        }
    }

    /// Bytes of per-view working memory (slice grid, auxiliary, tables),
    /// at its largest: with the column walk's buffer, which is allocated
    /// at the first view that takes that walk.
    pub fn bytes(&self) -> usize {
        // A mixed side's threaded finish: a table and a transposed grid.
        let mixed = match self.n.is_power_of_two() {
            true => 0,
            false => self.tw.len() + grid_len(self.n),
        };
        let along = match self.walk {
            Walk::Strip => column::along_len(self.n),
            Walk::Exact => 0,
        };
        (self.tw.len() + self.grid.len() + self.aux.len() + mixed + along)
            * std::mem::size_of::<T>()
            + std::mem::size_of::<KernelTable<T>>()
            + self.zoom.as_ref().map_or(0, ZoomFinish::bytes)
    }

    /// Extract the slice on `threads` threads (0, the default: one per
    /// core). The image is the same bit for bit whatever the count.
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = threads;
        self.pool = (threads > 1)
            .then(|| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .ok()
            })
            .flatten();
        self
    }

    /// Walk plain spectra (power-of-two and mixed-radix sides) with `tiling`
    /// ([`exact::extract`]; the image is the same whatever it is).
    pub fn with_tiling(mut self, tiling: Tiling) -> Self {
        self.tiling = tiling;
        self
    }

    /// Magnify every image `zoom` times ([`crate::image::zoom`]): the same
    /// field of view, `zoom·width × zoom·height` pixels in `out`. A zoom of
    /// 1 is the plain image.
    ///
    /// # Errors
    /// A factor [`crate::image::zoom::zoomed_side`] refuses.
    pub fn with_zoom(mut self, zoom: usize) -> Result<Self, fvr_core::Error> {
        self.zoom = match zoom {
            1 => None,
            _ => Some(ZoomFinish::new(self.n, zoom)?),
        };
        Ok(self)
    }

    /// Sum plain slices by `walk` ([`Walk`]).
    pub fn with_walk(mut self, walk: Walk) -> Self {
        self.walk = walk;
        self
    }

    /// The walk that took the last view's slice: `None` before the first
    /// view, or when the last one failed before its slice was walked.
    pub fn walked(&self) -> Option<WalkTaken> {
        self.walked
    }

    /// Render one view into `out` (`width × height`, row 0 at the top).
    ///
    /// The slice is extracted in blocks of rows on the renderer's threads
    /// ([`fvr_core::slice::extract_slice_rows`]; the core stays
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
        let (radix2, mixed);
        let inverse = if self.n.is_power_of_two() {
            radix2 = Twiddles::from_table(&self.tw, self.n)?;
            Inverse::Radix2(&radix2)
        } else {
            mixed = MixedPlan::from_table(&self.tw, self.n)?;
            Inverse::Mixed(&mixed)
        };
        self.walked = None;
        let owned = spec;
        let spec = spec.view();
        let n = spec.n();
        if self.grid.len() == grid_len(n) && exact::supports(&spec) {
            let axes = sampling.slice_axes(&view.frame()?);
            check_image(width, height, n)?;
            let exchanged = Self::exchanged(self.walk, &mut self.y_rows_views, owned, &axes);
            let (kernel, tiling, grid) = (&self.kernel, self.tiling, &mut self.grid);
            let (walk, along) = (self.walk, &mut self.along);
            let mut extract = |parallel: bool, grid: &mut [T]| {
                let job = SliceJob::new(&spec, kernel, &axes, tiling, parallel);
                fill(walk, &job, exchanged.as_ref(), grid, along)
            };
            let filled = match (&self.pool, self.threads) {
                (_, 1) => extract(false, grid),
                (Some(pool), _) => pool.install(|| extract(true, grid)),
                (None, _) => extract(true, grid),
            };
            if let Some(taken) = filled {
                self.walked = Some(taken);
                let place = placement_on_axes(spec.dims(), &axes, width, height, 1.0);
                let crop = Crop::new(place, sampling.gain() / spec.scale(), width, height);
                return self.finish(n, &crop, out);
            }
        }
        self.walked = Some(WalkTaken::Core);
        let threads = match self.threads {
            0 => std::thread::available_parallelism().map_or(1, |t| t.get()),
            t => t,
        };
        // Blocks of at least 16 rows: below that a thread costs more than it saves.
        let blocks = threads.min(n / 16).max(1);
        let own_grid = self.grid.len() == grid_len(n) && self.kernel.filter() == spec.filter();
        // The core's path below finishes at the slice's side only.
        if self.zoom.is_some() && self.grid.len() != grid_len(n) {
            return Err(fvr_core::Error::LengthMismatch {
                what: "spectrum side for the zoomed finish",
                expected: self.n,
                got: n,
            });
        }
        if self.zoom.is_some() && !own_grid {
            return Err(fvr_core::Error::FilterMismatch);
        }
        if (blocks == 1 && self.zoom.is_none()) || !own_grid {
            return render_projection_with(
                &spec,
                &self.kernel,
                inverse,
                &Request {
                    sampling: *sampling,
                    ..Request::new(*view, width, height)
                },
                Buffers {
                    grid: &mut self.grid,
                    aux: &mut self.aux,
                    out,
                },
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
        let crop = Crop::new(place, sampling.gain() / spec.scale(), width, height);
        self.finish(n, &crop, out)
    }

    /// Shift, inverse-transform and crop the filled grid: through
    /// [`MixedFinish`] on the renderer's threads for a mixed-radix
    /// side, else through the core's [`finish_with`] (the same image).
    fn finish(&mut self, n: usize, crop: &Crop, out: &mut [T]) -> Result<(), fvr_core::Error> {
        if let Some(zoom) = &mut self.zoom {
            let grid = &mut self.grid;
            return match &self.pool {
                Some(pool) => pool.install(|| zoom.finish(grid, crop, out)),
                None => zoom.finish(grid, crop, out),
            };
        }
        // The tables are for the renderer's side; the core checks `n` against it.
        if self.n.is_power_of_two() {
            let tw = Twiddles::from_table(&self.tw, self.n)?;
            return finish_with(
                &mut self.grid,
                n,
                crop,
                Inverse::Radix2(&tw),
                &mut self.aux,
                out,
            );
        }
        let (grid, mixed) = (&mut self.grid, &mut self.mixed);
        // One thread of its own: the core's single-threaded transform,
        // unless the renderer runs on a rayon worker (a batch's task), whose
        // pool the lanes' finish can share without taking a core from
        // anyone (measured on the CT head's 320 grid, 100 views about z: a
        // batch took 1.8 times the turntable's time a view with the core's
        // transform, and no more than the turntable's with the lanes').
        let single = self.threads == 1 && rayon::current_thread_index().is_none();
        match (single, mixed) {
            (true, _) | (_, None) => {
                let plan = MixedPlan::from_table(&self.tw, self.n)?;
                finish_with(grid, n, crop, Inverse::Mixed(&plan), &mut self.aux, out)
            }
            (_, Some(mixed)) => {
                let mut run = || mixed.finish(grid, crop, out);
                match &self.pool {
                    Some(pool) => pool.install(run),
                    None => run(),
                }
            }
        }
    }
}

/// Render `request` from `spec` once, allocating the kernel table, the
/// twiddles and the buffers for the request's level; the image as `f64`.
///
/// # Errors
/// As [`fvr_core::render::render`].
pub fn render_once<S: Sample, T: Real>(
    spec: &Spectrum<'_, S>,
    request: &Request<'_>,
) -> Result<Vec<f64>, fvr_core::Error> {
    let n = spec.n();
    let m = (n >> request.level.min(usize::BITS - 1)).max(1);
    let kernel = KernelTable::<T>::new(*spec.filter());
    let mut grid = vec![T::ZERO; grid_len(m)];
    let mut aux = vec![T::ZERO; aux_len(m)];
    let mut out = vec![T::ZERO; request.width * request.height];
    let buffers = Buffers::new(&mut grid, &mut aux, &mut out);
    if n.is_power_of_two() {
        let mut tw_buf = vec![T::ZERO; Twiddles::<T>::buffer_len(n)];
        let tw = Twiddles::new(&mut tw_buf, n)?;
        render(&Source::new(spec, &kernel, &tw), request, buffers)?;
    } else {
        // A mixed-radix side: a plan for the slice's side (X-ray only).
        let mut table = vec![T::ZERO; mixed_table_len(m)];
        let plan = MixedPlan::new(&mut table, m)?;
        render_projection_with(spec, &kernel, Inverse::Mixed(&plan), request, buffers)?;
    }
    Ok(out.into_iter().map(T::to_f64).collect())
}

/// The inverse transform's table for side `n`: radix-2 twiddles for a
/// power of two, else a mixed-radix plan's table (empty for a side
/// neither serves; rendering then reports the error).
fn inverse_table<T: Real>(n: usize) -> Vec<T> {
    if n.is_power_of_two() {
        let mut tw = vec![T::ZERO; Twiddles::<T>::buffer_len(n)];
        match Twiddles::new(&mut tw, n) {
            Ok(_) => tw,
            Err(_) => Vec::new(),
        }
    } else {
        let mut table = vec![T::ZERO; mixed_table_len(n)];
        match MixedPlan::new(&mut table, n) {
            Ok(_) => table,
            Err(_) => Vec::new(),
        }
    }
}

impl AnySpectrum {
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
        with_arithmetic!(self, s, T => {
            let mut r = ViewRenderer::<T>::new(s.n(), s.filter());
            let mut out = vec![<T as Real>::ZERO; width * height];
            r.render_sampled_into(s, view, sampling, width, height, &mut out)?;
            Ok(out.into_iter().map(<T as Real>::to_f64).collect())
        })
    }

    /// The progressive preview at `level` ([`fvr_core::progressive`]):
    /// a `width × height` image at pitch `2^level` voxels.
    ///
    /// # Errors
    /// As [`fvr_core::render::render_level`].
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
    /// As [`fvr_core::render::render_level_sampled`].
    pub fn render_level_sampled(
        &self,
        view: &View,
        sampling: &Sampling,
        width: usize,
        height: usize,
        level: u32,
    ) -> Result<Vec<f64>, fvr_core::Error> {
        let request = Request {
            sampling: *sampling,
            level,
            ..Request::new(*view, width, height)
        };
        with_arithmetic!(self, s, T => crate::render::view::render_once::<_, T>(&s.view(), &request))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::phantom::{sample, GaussianMixture};
    use fvr_core::filter::FilterKind;

    /// The count a memory budget is planned with holds every buffer a
    /// view leaves allocated, the column walk's among them.
    #[test]
    fn bytes_hold_what_views_allocate() {
        let volume = sample(&GaussianMixture::random(3, 32, 2), [32; 3]);
        for n in [32, 40] {
            let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
            let spec = OwnedSpectrum::<half::f16>::prepare_on::<f32>(&volume, filter, n).unwrap();
            let mut r = ViewRenderer::<f32>::new(n, filter).with_threads(1);
            let mut out = vec![0.0f32; n * n];
            // About z (the column walk), then tilted (strip walk).
            for dir in [[1.0, 0.3, 0.0], [1.0, 0.3, 0.2]] {
                r.render_into(&spec, &View::along(dir), n, n, &mut out)
                    .unwrap();
            }
            assert_eq!(r.along.len(), column::along_len(n));
            let held = (r.tw.capacity() + r.grid.capacity() + r.aux.capacity())
                + r.along.capacity()
                + r.mixed.as_ref().map_or(0, |m| m.bytes() / 4);
            assert!(held * 4 <= r.bytes(), "{n}: {} > {}", held * 4, r.bytes());
        }
    }
}
