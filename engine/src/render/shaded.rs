//! Depth-cued and shaded rendering on the host: the spectra a scene needs
//! (the `|∇f|` spectrum only when a light needs it) and a reusable renderer.

use crate::image::Image;
use crate::spectrum::{AnySpectrum, OwnedSpectrum, PipelineError, Precision, Preparation};
use crate::volume::Volume;
use fvr_core::dht::Twiddles;
use fvr_core::filter::{DerivativeTable, Filter, KernelTable};
use fvr_core::geometry::{Sampling, View};
use fvr_core::image::aux_len;
use fvr_core::num::{Real, Sample};
use fvr_core::render::{render, Buffers, Request, Source};
use fvr_core::shading::fields_len;
use fvr_core::shading::gradient::{gradient_magnitude, gradient_scratch_len};
use fvr_core::shading::{DepthCue, Light, Scene};
use fvr_core::volume::DenseVolume;

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
        spacing: volume.spacing,
        orientation: volume.orientation,
    })
}

/// The spectra a scene reads, in one storage type `S`: the density and,
/// for lights, `|∇f|`.
#[derive(Clone, Copy, Debug)]
pub struct TypedSpectra<'a, S> {
    /// The density spectrum.
    pub density: &'a OwnedSpectrum<S>,
    /// The `|∇f|` spectrum, if a light needs it.
    pub gradient: Option<&'a OwnedSpectrum<S>>,
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
        Self::prepare_by(volume, filter, precision, scene, Preparation::Fast)
    }

    /// [`SceneSpectra::prepare`] by the path `how`.
    ///
    /// # Errors
    /// As [`SceneSpectra::prepare`].
    pub fn prepare_by(
        volume: &Volume,
        filter: Filter,
        precision: Precision,
        scene: &Scene,
        how: Preparation,
    ) -> Result<Self, PipelineError> {
        let density = AnySpectrum::prepare_by(volume, filter, precision, how)?;
        let gradient = if scene.needs_gradient_spectrum() {
            // The density spectrum counts against the limit from here on.
            let _density = crate::memory::hold(density.bytes() as u64);
            let g = gradient_volume(volume)?;
            Some(AnySpectrum::prepare_by(&g, filter, precision, how)?)
        } else {
            None
        };
        Ok(Self { density, gradient })
    }

    /// Bytes of spectra held.
    pub fn bytes(&self) -> usize {
        self.density.bytes() + self.gradient.as_ref().map_or(0, AnySpectrum::bytes)
    }

    /// Render one view of `scene` in physical units (`fvr_core::geometry`'s
    /// physical contract: voxel spacing and pixel size from `sampling`).
    ///
    /// - A plain X-ray scene (one channel, no cue, no light) renders any
    ///   sampling ([`AnySpectrum::render_sampled`], times the ambient grey).
    /// - A cued or lit scene needs a *uniform pitch*: the three spacings
    ///   equal to the pixel size `Δ`. Then `t = Δ·t_index`, `R = Δ·R_index`
    ///   (the cue weights are unchanged), `∇ = ∇_index/Δ` and `dt = Δ·dt_index`,
    ///   so `I = ∫ w·[Δ·A·f + Σ ½D·(|∇f| − ∇f·L)]_index dt`: the voxel-unit
    ///   render with the ambient colour scaled by `Δ`, exactly.
    /// - Other samplings of cued or lit scenes are refused: the cue's ramp
    ///   (`d∘Δ` in index space), the light moments (`L_a/Δ_a`) and `|∇f|`
    ///   (per-axis `1/Δ_a`) are not carried through the core's scene path.
    ///
    /// [`Sampling::UNIT`] gives [`SceneSpectra::render`]'s image bit for bit.
    ///
    /// # Errors
    /// As [`SceneSpectra::render`], and a refused sampling (the message
    /// suggests `--resample` or `--ignore-spacing`).
    pub fn render_sampled(
        &self,
        scene: &Scene,
        view: &View,
        sampling: &Sampling,
        width: usize,
        height: usize,
    ) -> Result<Image, String> {
        let image = if *sampling == Sampling::UNIT {
            self.render(scene, view, width, height)
        } else if let Some(pitch) = sampling.uniform_pitch() {
            let scaled = Scene {
                ambient: scene.ambient.map(|a| a * pitch),
                ..scene.clone()
            };
            self.render(&scaled, view, width, height)
        } else if let Some(image) = self.plain_xray(scene, view, sampling, (width, height)) {
            image
        } else {
            let [x, y, z] = sampling.spacing();
            return Err(format!(
                "depth cueing and shading need cubic voxels imaged at their own size, but the \
                 voxels are {x} x {y} x {z} mm and the pixels {} mm: use --resample N (cubic \
                 voxels) or --ignore-spacing (voxel units), or render an X-ray view",
                sampling.pixel_size()
            ));
        };
        image.map_err(|e| e.to_string())
    }

    /// A plain X-ray scene (grey, no lights, no depth-varying cue) through
    /// the view renderer: its walk (strips where the rows hold a
    /// coordinate) and, on a mixed-radix side, its inverse, so the image is
    /// the plain projection's times the ambient grey and the cue's constant
    /// weight. `None` for any other scene.
    fn plain_xray(
        &self,
        scene: &Scene,
        view: &View,
        sampling: &Sampling,
        (width, height): (usize, usize),
    ) -> Option<Result<Image, fvr_core::Error>> {
        let grey = plain_grey(scene)?;
        Some(
            self.density
                .render_sampled(view, sampling, width, height)
                .map(|data| Image {
                    channels: 1,
                    width,
                    height,
                    data: data.into_iter().map(|v| v * grey).collect(),
                }),
        )
    }

    /// Render one view of `scene`; the image comes back in f64.
    ///
    /// # Errors
    /// As [`fvr_core::render::render`], and a scene that needs a `|∇f|` spectrum these
    /// spectra were not prepared with.
    pub fn render(
        &self,
        scene: &Scene,
        view: &View,
        width: usize,
        height: usize,
    ) -> Result<Image, fvr_core::Error> {
        if let Some(image) = self.plain_xray(scene, view, &Sampling::UNIT, (width, height)) {
            return image;
        }
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
            let spectra = TypedSpectra {
                density: d,
                gradient: g,
            };
            let channels = r.render_into(spectra, scene, view, w, h, &mut out)?;
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
    /// As [`fvr_core::render::render`]; a scene with more fields than this renderer was
    /// built for.
    pub fn render_into<S: Sample>(
        &mut self,
        spectra: TypedSpectra<'_, S>,
        scene: &Scene,
        view: &View,
        width: usize,
        height: usize,
        out: &mut [T],
    ) -> Result<usize, fvr_core::Error> {
        let TypedSpectra { density, gradient } = spectra;
        if self.derivative.is_none() && scene.needs_kernel_derivative() {
            self.derivative = Some(DerivativeTable::new(density.filter())?);
        }
        let needed = fields_len(scene, self.n);
        if self.fields.len() < needed {
            self.fields.resize(needed, T::ZERO);
        }
        let tw = Twiddles::from_table(&self.tw, self.n)?;
        let g = gradient.map(OwnedSpectrum::view);
        render(
            &Source {
                spectrum: &density.view(),
                gradient: g.as_ref(),
                kernel: &self.kernel,
                derivative: self.derivative.as_ref(),
                twiddles: &tw,
            },
            &Request {
                scene: Some(scene),
                ..Request::new(*view, width, height)
            },
            Buffers {
                grid: &mut self.fields,
                aux: &mut self.aux,
                out,
            },
        )
    }
}

/// Default harmonics for `profile:` depth cues.
pub const DEFAULT_PROFILE_HARMONICS: usize = 8;

/// How much of the image a depth cue weights negatively on `view`: the
/// weights are given between `t = −R` and `+R`, and oblique views reach
/// beyond into the box's corners, where a linear cue can extrapolate below
/// zero. Returns `(lowest weight, share)` where `share` is
/// `Σ_{w<0} |w·f| / Σ |w·f|` over the voxels (0 when no voxel is weighted
/// negatively).
///
/// # Errors
/// Bad view vectors or scene values.
pub fn negative_cue_share(
    volume: &Volume,
    scene: &Scene,
    view: &View,
) -> Result<(f64, f64), fvr_core::Error> {
    let frame = view.frame()?;
    let d = frame.dir;
    let dims = volume.dims;
    let c = fvr_core::geometry::center(dims);
    let radius = dims.iter().copied().max().unwrap_or(1) as f64 / 2.0;
    let terms = fvr_core::shading::CueTerms::new(&scene.cue, radius)?;
    // The weight on a table over the box's depth range (it is smooth).
    let reach: f64 = (0..3)
        .map(|a| d[a].abs() * dims[a] as f64 / 2.0)
        .sum::<f64>()
        + 1.0;
    const STEPS: usize = 4096;
    let table: Vec<f64> = (0..=STEPS)
        .map(|s| terms.weight(-reach + 2.0 * reach * s as f64 / STEPS as f64))
        .collect();
    let lowest = table.iter().copied().fold(f64::INFINITY, f64::min);
    if lowest >= 0.0 {
        return Ok((lowest, 0.0));
    }
    let (mut negative, mut total) = (0.0f64, 0.0f64);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            let row = (j as f64 - c[1]) * d[1] + (k as f64 - c[2]) * d[2];
            for i in 0..dims[0] {
                let v = volume.data[i + dims[0] * (j + dims[1] * k)].abs() as f64;
                let t = row + (i as f64 - c[0]) * d[0];
                let s = ((t + reach) / (2.0 * reach) * STEPS as f64).round() as usize;
                let w = table[s.min(STEPS)];
                total += (w * v).abs();
                if w < 0.0 {
                    negative -= w * v;
                }
            }
        }
    }
    Ok((lowest, if total > 0.0 { negative / total } else { 0.0 }))
}

/// `count` lights evenly spaced around the view axis, as in the paper's
/// figure 8, starting at the top of the image and going counter-clockwise,
/// each tilted `tilt_degrees` from the image plane towards the eye, with
/// fully saturated colours evenly spaced in hue (3 lights: red, green,
/// blue).
///
/// # Errors
/// Bad view vectors.
pub fn light_ring(
    view: &View,
    count: usize,
    tilt_degrees: f64,
) -> Result<Vec<Light>, fvr_core::Error> {
    let frame = view.frame()?;
    let tilt = tilt_degrees.to_radians();
    Ok((0..count)
        .map(|i| {
            let frac = i as f64 / count as f64;
            let theta = std::f64::consts::FRAC_PI_2 + 2.0 * std::f64::consts::PI * frac;
            let towards: [f64; 3] = std::array::from_fn(|a| {
                tilt.cos() * (frame.right[a] * theta.cos() + frame.up[a] * theta.sin())
                    - tilt.sin() * frame.dir[a]
            });
            Light {
                towards,
                color: hue(frac),
            }
        })
        .collect())
}

/// A saturated colour at `frac` of the hue circle (0 red, ⅓ green, ⅔ blue).
fn hue(frac: f64) -> [f64; 3] {
    std::array::from_fn(|c| {
        let d = (frac * 3.0 - c as f64).rem_euclid(3.0);
        let d = d.min(3.0 - d);
        (1.0 - d).max(0.0)
    })
}

/// The factor a plain X-ray scene (grey, no lights, no depth-varying cue)
/// multiplies the plain projection by: the ambient grey times the cue's
/// constant weight. `None` for any other scene.
pub(crate) fn plain_grey(scene: &Scene) -> Option<f64> {
    if scene.channels() != 1 || scene.has_partner_terms() {
        return None;
    }
    // A cue with equal ends weighs every depth alike.
    let cue = match scene.cue {
        DepthCue::Linear { front, .. } | DepthCue::Sine { front, .. } => front,
        DepthCue::None | DepthCue::Profile { .. } => 1.0,
    };
    Some(scene.ambient[0] * cue)
}
