//! Batches of views: `B` views of one prepared volume rendered on all
//! cores into one caller-owned `f32` buffer, each frame the same bit for
//! bit as [`Renderer::render`]'s image of that view converted to `f32`
//! (what `fvr render` writes to NRRD).
//!
//! Plain X-ray views (the main path) are spread over rayon's pool one view
//! per task, each worker reusing one [`ViewRenderer`] with single-threaded
//! extraction: the views, not the rows of one slice, are what run in
//! parallel, so no thread waits on another's inverse transform. A batch of
//! fewer views than threads is drawn one view at a time with the slice
//! extracted on all threads, as [`Renderer::render`] draws one. Depth-cued,
//! shaded, adaptive and preview views go through [`Renderer::render`]
//! itself, still one view per task.

use std::time::{Duration, Instant};

use fvr_core::geometry::{Sampling, View};
use fvr_core::num::Real;
use fvr_core::shading::DepthCue;
use rayon::prelude::*;

use crate::error::PipelineError;
use crate::image::finite::check_frames;
use crate::render::view::{ViewRenderer, WalkCounts};
use crate::renderer::Renderer;
use crate::spectrum::{with_arithmetic, AnySpectrum};

/// The frames a batch wrote.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchShape {
    /// Views rendered.
    pub views: usize,
    /// Channels per pixel: 1 (grey), or 3 (RGB: lights or a coloured
    /// ambient), interleaved.
    pub channels: usize,
    /// Frame width in pixels.
    pub width: usize,
    /// Frame height in pixels.
    pub height: usize,
}

impl BatchShape {
    /// Values in one frame: `channels · width · height`.
    pub fn frame_len(&self) -> usize {
        self.channels * self.width * self.height
    }

    /// Values in the whole batch.
    pub fn len(&self) -> usize {
        self.views * self.frame_len()
    }

    /// Whether the batch holds no value.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// What a batch cost.
#[derive(Clone, Copy, Debug)]
pub struct BatchReport {
    /// The frames written.
    pub shape: BatchShape,
    /// Wall time of the whole batch.
    pub time: Duration,
    /// The walk that took each plain view's slice (none counted for views
    /// drawn through [`Renderer::render`]: scenes, previews, adaptive
    /// filtering).
    pub walks: WalkCounts,
}

impl Renderer {
    /// The shape of `views` frames at `size` ([`Renderer::image_size`]):
    /// at a preview level, the preview's smaller size, as
    /// [`Renderer::render`] returns it.
    ///
    /// # Errors
    /// A size beyond the grid.
    pub fn batch_shape(
        &self,
        views: usize,
        size: Option<(usize, usize)>,
    ) -> Result<BatchShape, PipelineError> {
        let (w, h) = self.image_size(size)?;
        let settings = self.settings();
        let (width, height) = match settings.preview_level {
            0 => (w, h),
            level => fvr_core::render::preview_size(w, h, level),
        };
        Ok(BatchShape {
            views,
            channels: settings.scene.channels(),
            width,
            height,
        })
    }

    /// Render every view of `views` at `size` into `out`, frame `b` at
    /// `out[b·L .. (b+1)·L]` with `L` = [`BatchShape::frame_len`] (row 0
    /// at the top, channels interleaved), on all cores of rayon's current
    /// pool. Each frame is [`Renderer::render`]'s image of its view, each
    /// value converted to `f32`, bit for bit.
    ///
    /// Views are checked in order before any is rendered, so a bad one is
    /// reported by its index (`view 3: ...`) and `out` is left untouched.
    ///
    /// # Errors
    /// `out` not of [`BatchShape::len`] values, a bad size or view, a
    /// view's own error (the adaptive marks', a refused sampling), or an
    /// image that overflows `f32` ([`PipelineError::Overflow`]; `out` is
    /// then zeroed).
    pub fn render_batch_into(
        &self,
        views: &[View],
        size: Option<(usize, usize)>,
        out: &mut [f32],
    ) -> Result<BatchReport, PipelineError> {
        let t0 = Instant::now();
        let shape = self.batch_shape(views.len(), size)?;
        if out.len() != shape.len() {
            return Err(PipelineError::Settings(format!(
                "the output holds {} values, but {} views of {}x{}x{} need {}",
                out.len(),
                shape.views,
                shape.width,
                shape.height,
                shape.channels,
                shape.len()
            )));
        }
        for (i, view) in views.iter().enumerate() {
            view.frame().map_err(|e| match views.len() {
                1 => PipelineError::Core(e),
                _ => PipelineError::Settings(format!("view {i}: {e}")),
            })?;
        }
        if shape.is_empty() {
            return Ok(BatchReport {
                shape,
                time: t0.elapsed(),
                walks: WalkCounts::default(),
            });
        }
        let size = self.image_size(size)?;
        let walks = match self.plain_grey() {
            Some((sampling, grey)) => self.plain_batch(views, &shape, &sampling, grey, out)?,
            None => {
                self.scene_batch(views, &shape, size, out)?;
                WalkCounts::default()
            }
        };
        if let Err(e) = check_frames(out, shape.frame_len(), &self.settings().scene) {
            // No frame of NaN or infinity is left for a caller to use.
            out.fill(0.0);
            return Err(e);
        }
        Ok(BatchReport {
            shape,
            time: t0.elapsed(),
            walks,
        })
    }

    /// [`Renderer::render_batch_into`] into a new buffer.
    ///
    /// # Errors
    /// As [`Renderer::render_batch_into`].
    pub fn render_batch(
        &self,
        views: &[View],
        size: Option<(usize, usize)>,
    ) -> Result<(Vec<f32>, BatchReport), PipelineError> {
        let shape = self.batch_shape(views.len(), size)?;
        let mut out = vec![0.0f32; shape.len()];
        let report = self.render_batch_into(views, size, &mut out)?;
        Ok((out, report))
    }

    /// For views that [`Renderer::render`] draws as a plain projection
    /// times a grey factor (no preview, no adaptive filtering, one channel,
    /// no depth-varying cue): the sampling that projection is drawn at and
    /// the factor, as `SceneSpectra::render_sampled` and its `plain_xray`
    /// choose them. `None` for every other view.
    ///
    /// The three cases there: voxel units draw at [`Sampling::UNIT`] times
    /// the ambient grey and the cue's constant weight; cubic voxels imaged
    /// at their own size `Δ` draw at `UNIT` with the ambient scaled by `Δ`
    /// first; any other sampling draws at itself. The products are formed
    /// in the same order, so the values agree bit for bit (the batch tests
    /// hold each case to [`Renderer::render`]).
    fn plain_grey(&self) -> Option<(Sampling, f64)> {
        let settings = self.settings();
        if settings.preview_level > 0 || settings.adaptive.is_some() || !settings.plain() {
            return None;
        }
        let scene = &settings.scene;
        let cue = match scene.cue {
            DepthCue::Linear { front, .. } | DepthCue::Sine { front, .. } => front,
            DepthCue::None | DepthCue::Profile { .. } => 1.0,
        };
        let ambient = scene.ambient[0];
        let sampling = *self.sampling();
        Some(if sampling == Sampling::UNIT {
            (Sampling::UNIT, ambient * cue)
        } else if let Some(pitch) = sampling.uniform_pitch() {
            (Sampling::UNIT, (ambient * pitch) * cue)
        } else {
            (sampling, ambient * cue)
        })
    }

    /// Plain views: with at least as many views as threads, one
    /// [`ViewRenderer`] per piece rayon splits the batch into (a few per
    /// thread), extraction on the task's own thread; with fewer, one
    /// renderer drawing the views in turn, extraction on all threads. The
    /// image is the same bit for bit whatever the thread count (see
    /// [`ViewRenderer::with_threads`]).
    fn plain_batch(
        &self,
        views: &[View],
        shape: &BatchShape,
        sampling: &Sampling,
        grey: f64,
        out: &mut [f32],
    ) -> Result<WalkCounts, PipelineError> {
        let (w, h) = (shape.width, shape.height);
        let density = &self.spectra().density;
        // Fewer views than threads: one view at a time, each slice
        // extracted on all of them (as `render` does), rather than cores
        // left idle.
        let one_at_a_time = views.len() < rayon::current_num_threads();
        with_arithmetic!(density, s, T => {
            ViewRenderer::<T>::share_for_batch(s, views, sampling);
            let count = |walks: &mut WalkCounts, renderer: &ViewRenderer<T>| {
                if let Some(walk) = renderer.walked() {
                    walks.add(walk);
                }
            };
            if one_at_a_time {
                let mut renderer = ViewRenderer::<T>::new(s.n(), s.filter());
                let mut frame = vec![<T as Real>::ZERO; w * h];
                let mut walks = WalkCounts::default();
                for (dst, view) in out.chunks_mut(shape.frame_len()).zip(views) {
                    renderer.render_sampled_into(s, view, sampling, w, h, &mut frame)?;
                    count(&mut walks, &renderer);
                    to_f32(dst, &frame, grey);
                }
                return Ok(walks);
            }
            out.par_chunks_mut(shape.frame_len())
                .zip(views.par_iter())
                .map_init(
                    || {
                        let r = ViewRenderer::<T>::new(s.n(), s.filter()).with_threads(1);
                        (r, vec![<T as Real>::ZERO; w * h])
                    },
                    |(renderer, frame), (dst, view)| {
                        renderer.render_sampled_into(s, view, sampling, w, h, frame)?;
                        to_f32(dst, frame, grey);
                        let mut walks = WalkCounts::default();
                        count(&mut walks, renderer);
                        Ok::<WalkCounts, PipelineError>(walks)
                    },
                )
                .try_reduce(WalkCounts::default, |a, b| Ok(a.merged(b)))
        })
    }

    /// Every other view through [`Renderer::render`], one per task. The
    /// first view runs alone, so that adaptive marks are built once (by
    /// it) rather than raced for by every thread.
    fn scene_batch(
        &self,
        views: &[View],
        shape: &BatchShape,
        size: (usize, usize),
        out: &mut [f32],
    ) -> Result<(), PipelineError> {
        let one = |dst: &mut [f32], view: &View| -> Result<(), PipelineError> {
            let (image, _) = self.render(view, Some(size))?;
            for (d, v) in dst.iter_mut().zip(&image.data) {
                *d = *v as f32;
            }
            Ok(())
        };
        let (first, rest) = out.split_at_mut(shape.frame_len());
        one(first, &views[0])?;
        rest.par_chunks_mut(shape.frame_len())
            .zip(views[1..].par_iter())
            .try_for_each(|(dst, view)| one(dst, view))
    }
}

/// A frame as `Renderer::render` then the NRRD writer make it: each value
/// to f64, times the grey factor, rounded to f32.
fn to_f32<T: Real>(dst: &mut [f32], frame: &[T], grey: f64) {
    for (d, v) in dst.iter_mut().zip(frame) {
        *d = (v.to_f64() * grey) as f32;
    }
}
