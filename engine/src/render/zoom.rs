//! Magnified plain X-ray views ([`crate::image::zoom`]): the same field of
//! view, `F` times as many pixels per side, from the same slice.

use fvr_core::geometry::{Sampling, View};
use fvr_core::num::Real;

use crate::clock::Instant;
use crate::error::PipelineError;
use crate::image::Image;
use crate::render::shaded::plain_grey;
use crate::render::view::ViewRenderer;
use crate::spectrum::{with_arithmetic, AnySpectrum};
use crate::{Renderer, ViewReport};

impl AnySpectrum {
    /// [`AnySpectrum::render_sampled`] magnified `zoom` times: the field of
    /// view of a `width × height` image, as `zoom·width × zoom·height`
    /// pixels `sampling.pixel_size() / zoom` apart. Zoom 1 is the plain
    /// image.
    ///
    /// # Errors
    /// As [`AnySpectrum::render_sampled`], and a zoom
    /// [`crate::image::zoom::zoomed_side`] refuses.
    pub fn render_zoomed(
        &self,
        view: &View,
        sampling: &Sampling,
        (width, height): (usize, usize),
        zoom: usize,
    ) -> Result<Vec<f64>, fvr_core::Error> {
        with_arithmetic!(self, s, T => {
            let mut r = ViewRenderer::<T>::new(s.n(), s.filter()).with_zoom(zoom)?;
            let pixels = (width * zoom).saturating_mul(height * zoom);
            let mut out = vec![<T as Real>::ZERO; pixels];
            r.render_sampled_into(s, view, sampling, width, height, &mut out)?;
            Ok(out.into_iter().map(<T as Real>::to_f64).collect())
        })
    }
}

impl Renderer {
    /// [`Renderer::render`] magnified `zoom` times: the field of view of
    /// `size` ([`Renderer::image_size`]) as an image `zoom` times as wide
    /// and high, its pixels [`Renderer::zoomed_sampling`] apart. Zoom 1 is
    /// [`Renderer::render`].
    ///
    /// # Errors
    /// As [`Renderer::render`] (an image that overflows `f32` included); a
    /// zoom the transforms do not serve; a
    /// zoom with a preview level, adaptive filtering, a varying depth cue
    /// or lights (plain X-ray views only).
    pub fn render_zoomed(
        &self,
        view: &View,
        size: Option<(usize, usize)>,
        zoom: usize,
    ) -> Result<(Image, ViewReport), PipelineError> {
        if zoom == 1 {
            return self.render(view, size);
        }
        let settings = self.settings();
        let refuse = |what: &str| {
            PipelineError::Settings(format!(
                "--zoom renders plain X-ray views at full resolution, not {what}"
            ))
        };
        if settings.preview_level > 0 {
            return Err(refuse("progressive previews (--preview-level)"));
        }
        if settings.adaptive.is_some() {
            return Err(refuse("adaptive views (--adaptive)"));
        }
        let grey = plain_grey(&settings.scene).ok_or_else(|| refuse("depth-cued or lit scenes"))?;
        let (w, h) = self.image_size(size)?;
        crate::image::zoom::zoomed_side(self.n(), zoom).map_err(|_| {
            PipelineError::Settings(format!(
                "--zoom {zoom}: expected a whole factor from 1 to {} with no prime factor \
                 above 5 (2, 3, 4, 5, 6, 8, ...)",
                crate::image::zoom::MAX_ZOOM
            ))
        })?;
        let t0 = Instant::now();
        let data = self
            .spectra()
            .density
            .render_zoomed(view, self.sampling(), (w, h), zoom)?;
        let image = Image {
            channels: 1,
            width: w * zoom,
            height: h * zoom,
            data: data.into_iter().map(|v| v * grey).collect(),
        };
        let report = ViewReport {
            time: t0.elapsed(),
            adaptive: None,
        };
        crate::image::finite::check_image(&image.data, &settings.scene)?;
        Ok((image, report))
    }

    /// The sampling of an image magnified `zoom` times: the volume's
    /// spacing, pixels [`Sampling::pixel_size`]` / zoom` apart.
    ///
    /// # Errors
    /// A zoom of 0, or a pixel size the core refuses.
    pub fn zoomed_sampling(&self, zoom: usize) -> Result<Sampling, PipelineError> {
        let s = self.sampling();
        if zoom == 1 {
            return Ok(*s);
        }
        Ok(Sampling::new(s.spacing(), s.pixel_size() / zoom as f64)?)
    }
}
