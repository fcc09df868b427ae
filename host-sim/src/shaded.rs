//! Depth-cued and shaded rendering on the host: the spectra a scene needs
//! (the `|∇f|` spectrum only when a light needs it) and a reusable renderer.

use crate::pipeline::{AnySpectrum, OwnedSpectrum, PipelineError, Precision};
use crate::volume::Volume;
use fvr_core::dht::Twiddles;
use fvr_core::filter::{DerivativeTable, Filter, KernelTable};
use fvr_core::geometry::View;
use fvr_core::gradient::{gradient_magnitude, gradient_scratch_len};
use fvr_core::real::{Real, Sample};
use fvr_core::render::aux_len;
use fvr_core::scene::Scene;
use fvr_core::scene_render::{fields_len, render_scene};
use fvr_core::spectrum::DenseVolume;

/// An image of 1 (grey) or 3 (RGB) interleaved channels, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Channels per pixel.
    pub channels: usize,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `data[(row·width + col)·channels + c]`.
    pub data: Vec<f64>,
}

impl Image {
    /// Channel `c` as its own `width × height` image.
    pub fn channel(&self, c: usize) -> Vec<f64> {
        self.data
            .iter()
            .skip(c)
            .step_by(self.channels)
            .copied()
            .collect()
    }
}

/// `|∇f|` at every voxel (spectral gradient, [`fvr_core::gradient`]),
/// computed in f64.
///
/// # Errors
/// A non-finite voxel.
pub fn gradient_volume(volume: &Volume) -> Result<Volume, fvr_core::Error> {
    let source = DenseVolume::new(volume.dims, &volume.data)?;
    let len = gradient_scratch_len(volume.dims);
    let mut tw_buf = vec![0.0f64; Twiddles::<f64>::buffer_len(len)];
    let tw = Twiddles::new(&mut tw_buf, len)?;
    let mut line = vec![0.0f64; len];
    let mut out = vec![0.0f64; volume.data.len()];
    gradient_magnitude(&source, &mut out, &mut line, &tw)?;
    Ok(Volume {
        dims: volume.dims,
        data: out.into_iter().map(|v| v as f32).collect(),
    })
}

/// The spectra of one volume prepared for a scene.
#[derive(Clone, Debug)]
pub struct SceneSpectra {
    /// The density spectrum.
    pub density: AnySpectrum,
    /// The `|∇f|` spectrum, present only if the scene has a light.
    pub gradient: Option<AnySpectrum>,
}

impl SceneSpectra {
    /// Prepare `volume` for `scene`: the density spectrum always, the
    /// `|∇f|` spectrum only if [`Scene::needs_gradient_spectrum`].
    ///
    /// # Errors
    /// As [`AnySpectrum::prepare`] and [`gradient_volume`].
    pub fn prepare(
        volume: &Volume,
        filter: Filter,
        precision: Precision,
        scene: &Scene,
    ) -> Result<Self, PipelineError> {
        let density = AnySpectrum::prepare(volume, filter, precision)?;
        let gradient = if scene.needs_gradient_spectrum() {
            let g = gradient_volume(volume)?;
            Some(AnySpectrum::prepare(&g, filter, precision)?)
        } else {
            None
        };
        Ok(Self { density, gradient })
    }

    /// Bytes of spectra held.
    pub fn bytes(&self) -> usize {
        self.density.bytes() + self.gradient.as_ref().map_or(0, AnySpectrum::bytes)
    }

    /// Render one view of `scene`; the image comes back in f64.
    ///
    /// # Errors
    /// As [`render_scene`], and a scene that needs a `|∇f|` spectrum these
    /// spectra were not prepared with.
    pub fn render(
        &self,
        scene: &Scene,
        view: &View,
        width: usize,
        height: usize,
    ) -> Result<Image, fvr_core::Error> {
        fn go<S: Sample, T: Real>(
            d: &OwnedSpectrum<S>,
            g: Option<&OwnedSpectrum<S>>,
            scene: &Scene,
            view: &View,
            w: usize,
            h: usize,
        ) -> Result<Image, fvr_core::Error> {
            let mut r = SceneRenderer::<T>::new(d.n(), d.filter(), scene)?;
            let mut out = vec![T::ZERO; scene.channels() * w * h];
            let channels = r.render_into(d, g, scene, view, w, h, &mut out)?;
            Ok(Image {
                channels,
                width: w,
                height: h,
                data: out.into_iter().map(T::to_f64).collect(),
            })
        }
        let mismatch = || fvr_core::Error::GradientSpectrum {
            problem: "its precision differs from the density spectrum's",
        };
        match (&self.density, &self.gradient) {
            (AnySpectrum::F16(d), None) => go::<_, f32>(d, None, scene, view, width, height),
            (AnySpectrum::F16(d), Some(AnySpectrum::F16(g))) => {
                go::<_, f32>(d, Some(g), scene, view, width, height)
            }
            (AnySpectrum::F32(d), None) => go::<_, f32>(d, None, scene, view, width, height),
            (AnySpectrum::F32(d), Some(AnySpectrum::F32(g))) => {
                go::<_, f32>(d, Some(g), scene, view, width, height)
            }
            (AnySpectrum::F64(d), None) => go::<_, f64>(d, None, scene, view, width, height),
            (AnySpectrum::F64(d), Some(AnySpectrum::F64(g))) => {
                go::<_, f64>(d, Some(g), scene, view, width, height)
            }
            _ => Err(mismatch()),
        }
    }
}

/// Reusable per-view buffers and tables for a scene, arithmetic `T`. Holds
/// the kernel-derivative table only if the scene's cue needs it.
#[derive(Debug)]
pub struct SceneRenderer<T> {
    kernel: KernelTable<T>,
    derivative: Option<DerivativeTable<T>>,
    tw: Vec<T>,
    fields: Vec<T>,
    aux: Vec<T>,
    n: usize,
}

impl<T: Real> SceneRenderer<T> {
    /// Buffers for `scene` on spectra of side `n` and `filter`.
    ///
    /// # Errors
    /// A linear cue with the nearest-neighbour filter; `n` not a power of
    /// two.
    pub fn new(n: usize, filter: Filter, scene: &Scene) -> Result<Self, fvr_core::Error> {
        let mut tw = vec![T::ZERO; Twiddles::<T>::buffer_len(n)];
        Twiddles::new(&mut tw, n)?;
        let derivative = if scene.needs_kernel_derivative() {
            Some(DerivativeTable::new(filter)?)
        } else {
            None
        };
        Ok(Self {
            kernel: KernelTable::new(filter),
            derivative,
            tw,
            fields: vec![T::ZERO; fields_len(scene, n)],
            aux: vec![T::ZERO; aux_len(n)],
            n,
        })
    }

    /// Bytes of per-view working memory (fields, auxiliary, tables).
    pub fn bytes(&self) -> usize {
        let table = std::mem::size_of::<KernelTable<T>>();
        let derivative = self
            .derivative
            .as_ref()
            .map_or(0, |_| std::mem::size_of::<DerivativeTable<T>>());
        (self.fields.len() + self.aux.len() + self.tw.len()) * std::mem::size_of::<T>()
            + table
            + derivative
    }

    /// Render one view into `out` (`channels·width·height`, interleaved);
    /// returns the channel count.
    ///
    /// # Errors
    /// As [`render_scene`]; a scene with more fields than this renderer was
    /// built for.
    #[allow(clippy::too_many_arguments)]
    pub fn render_into<S: Sample>(
        &mut self,
        density: &OwnedSpectrum<S>,
        gradient: Option<&OwnedSpectrum<S>>,
        scene: &Scene,
        view: &View,
        width: usize,
        height: usize,
        out: &mut [T],
    ) -> Result<usize, fvr_core::Error> {
        if self.derivative.is_none() && scene.needs_kernel_derivative() {
            self.derivative = Some(DerivativeTable::new(density.filter())?);
        }
        let needed = fields_len(scene, self.n);
        if self.fields.len() < needed {
            self.fields.resize(needed, T::ZERO);
        }
        let tw = Twiddles::from_table(&self.tw, self.n)?;
        let g = gradient.map(OwnedSpectrum::view);
        render_scene(
            &density.view(),
            g.as_ref(),
            &self.kernel,
            self.derivative.as_ref(),
            scene,
            view,
            width,
            height,
            &tw,
            &mut self.fields,
            &mut self.aux,
            out,
        )
    }
}
