//! The scene model: lights, depth cues, and their per-view plan.

use crate::error::{Error, Result};
use crate::filter::gauss_legendre_16;
use crate::geometry::{dot, Frame};
use heapless::Vec;

/// Capacity of [`Scene::lights`].
pub const MAX_LIGHTS: usize = 8;
/// Capacity of a depth profile's weights.
pub const MAX_PROFILE_POINTS: usize = 64;
/// Largest number of harmonics of a fitted depth profile.
pub const MAX_HARMONICS: usize = 16;

const PI: f64 = core::f64::consts::PI;

/// A directional light for hemispherical shading (eq. 8).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Direction towards the light (any length but zero).
    pub towards: [f64; 3],
    /// Linear RGB colour, each component finite and `≥ 0`.
    pub color: [f64; 3],
}

/// A depth-cueing function `w(t)`.
// The profile is held inline (no allocation in the core); a scene is built
// once per render, so the variant size costs nothing that matters.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum DepthCue {
    /// No depth cue: `w = 1`.
    None,
    /// `w(t) = C_avg + C_cue·t` with `w(−R) = front`, `w(R) = back` (eq. 3).
    Linear {
        /// Weight at the front, `t = −R`.
        front: f64,
        /// Weight at the back, `t = +R`.
        back: f64,
    },
    /// A DC-free sine through `front` and `back` (§3.1, after eq. 5).
    Sine {
        /// Weight at the front, `t = −R`.
        front: f64,
        /// Weight at the back, `t = +R`.
        back: f64,
    },
    /// A piecewise-linear profile fitted by a cosine series.
    Profile {
        /// Weights at equally spaced depths from `−R` to `+R` (at least 2).
        weights: Vec<f64, MAX_PROFILE_POINTS>,
        /// Harmonics `M` of the fit, `1 ≤ M ≤ MAX_HARMONICS`.
        harmonics: usize,
    },
}

/// Everything a view needs besides the spectra: cue, ambient and lights.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Depth cue.
    pub cue: DepthCue,
    /// Ambient colour `A_c` (eq. 7), each component finite and `≥ 0`.
    pub ambient: [f64; 3],
    /// Directional lights (eq. 8–11).
    pub lights: Vec<Light, MAX_LIGHTS>,
    /// Apply the eq. 14 correction when depth cueing and shading are
    /// combined (on by default; off reproduces the paper's uncorrected
    /// reversed order, for comparison).
    pub correct_cue_shading: bool,
}

impl Default for Scene {
    fn default() -> Self {
        Self::xray()
    }
}

impl Scene {
    /// The grey ambient term front ends use when none is given: 1 for a
    /// scene without lights (the plain projection, eq. 1), 0.2 with lights,
    /// so that the shading they add (eq. 8) shows against it.
    pub const fn default_ambient(lit: bool) -> f64 {
        if lit {
            0.2
        } else {
            1.0
        }
    }

    /// The plain X-ray projection: no cue, grey ambient 1, no lights.
    pub fn xray() -> Self {
        Self {
            cue: DepthCue::None,
            ambient: [1.0; 3],
            lights: Vec::new(),
            correct_cue_shading: true,
        }
    }

    /// Add a light.
    ///
    /// # Errors
    /// [`Error::TooMany`] beyond [`MAX_LIGHTS`].
    pub fn add_light(&mut self, light: Light) -> Result<()> {
        let given = self.lights.len() + 1;
        self.lights
            .push(light)
            .map_err(|_| too_many("lights", given, MAX_LIGHTS))
    }

    /// Check every value against its documented range.
    ///
    /// # Errors
    /// A negative or non-finite colour, weight or ambient term, a zero,
    /// too short ([`crate::geometry::too_short`]) or non-finite light
    /// direction, or a profile of the wrong size.
    pub fn validate(&self) -> Result<()> {
        for (c, &a) in self.ambient.iter().enumerate() {
            check_nonnegative("ambient colour component", c, a)?;
        }
        for (i, light) in self.lights.iter().enumerate() {
            for &v in light.towards.iter() {
                if !v.is_finite() {
                    return Err(Error::InvalidSceneValue {
                        what: "light direction component",
                        index: i,
                        value: v,
                    });
                }
            }
            if light.towards == [0.0; 3] {
                return Err(Error::ZeroLightVector { index: i });
            }
            if crate::geometry::too_short(light.towards) {
                return Err(Error::ShortLightVector { index: i });
            }
            for &v in light.color.iter() {
                check_nonnegative("light colour component of light", i, v)?;
            }
        }
        match &self.cue {
            DepthCue::None => {}
            DepthCue::Linear { front, back } | DepthCue::Sine { front, back } => {
                check_nonnegative("depth-cue weight (0 = front, 1 = back)", 0, *front)?;
                check_nonnegative("depth-cue weight (0 = front, 1 = back)", 1, *back)?;
            }
            DepthCue::Profile { weights, harmonics } => {
                if weights.len() < 2 {
                    return Err(Error::InvalidSceneValue {
                        what: "depth-profile point count (needs at least 2)",
                        index: 0,
                        value: weights.len() as f64,
                    });
                }
                for (i, &v) in weights.iter().enumerate() {
                    check_nonnegative("depth-profile weight", i, v)?;
                }
                if *harmonics == 0 || *harmonics > MAX_HARMONICS {
                    return Err(Error::TooMany {
                        what: "depth-profile harmonics (at least 1)",
                        given: *harmonics,
                        capacity: MAX_HARMONICS,
                    });
                }
            }
        }
        Ok(())
    }

    /// `true` if the scene reads the `|∇f|` spectrum: it has a light with a
    /// non-zero colour. Without one, the spectrum is never built or read.
    pub fn needs_gradient_spectrum(&self) -> bool {
        self.lights
            .iter()
            .any(|l| l.color.iter().any(|&c| c != 0.0))
    }

    /// `true` if the scene needs the kernel derivative table (linear cue).
    pub fn needs_kernel_derivative(&self) -> bool {
        matches!(self.cue, DepthCue::Linear { front, back } if front != back)
    }

    /// Output channels: 1 for a grey scene without lights, else 3 (RGB).
    pub fn channels(&self) -> usize {
        let a = self.ambient;
        if self.needs_gradient_spectrum() || a[0] != a[1] || a[1] != a[2] {
            3
        } else {
            1
        }
    }

    /// `true` if the cue has terms read at the partner point `−k` (any
    /// cue whose weight varies with depth); such scenes need a second
    /// accumulator per spectrum.
    pub fn has_partner_terms(&self) -> bool {
        match &self.cue {
            DepthCue::None => false,
            DepthCue::Linear { front, back } | DepthCue::Sine { front, back } => front != back,
            DepthCue::Profile { .. } => true,
        }
    }

    /// `true` if the eq. 14 correction needs its own accumulators: a
    /// depth-varying cue, lights, and the correction on.
    pub fn needs_cue_derivative_fields(&self) -> bool {
        self.correct_cue_shading && self.needs_gradient_spectrum() && self.has_partner_terms()
    }

    /// Slice-sized scratch grids the scene's render needs (see
    /// [`crate::shading::fields_len`]): 1 for a plain or cued grey
    /// image; otherwise one accumulator per spectrum term plus one output.
    pub fn field_count(&self) -> usize {
        field_count_of(
            self.has_partner_terms(),
            self.channels(),
            self.needs_gradient_spectrum(),
            self.needs_cue_derivative_fields(),
        )
    }
}

fn check_nonnegative(what: &'static str, index: usize, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(what, index, value))
    }
}

#[cold]
fn invalid(what: &'static str, index: usize, value: f64) -> Error {
    Error::InvalidSceneValue { what, index, value }
}

/// One sinusoidal term `amplitude·sin(2π·nu·τ + phase)` of a depth cue, in
/// the depth `τ = d·(x − o)` measured from the transform origin `o`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wave {
    /// Amplitude.
    pub amplitude: f64,
    /// Frequency, cycles per voxel, `≥ 0`.
    pub nu: f64,
    /// Phase, radians.
    pub phase: f64,
}

/// Per-channel shading coefficients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChannelPlan {
    /// Ambient `A_c`.
    pub ambient: f64,
    /// `K_c = Σ_l ½·D_{l,c}`, the weight of the `|∇f|` term.
    pub gradient: f64,
    /// `M_c = Σ_l ½·D_{l,c}·L_l` projected on the image's right and up axes.
    pub moment: [f64; 2],
    /// `d·M_c`, the moment along the view, which eq. 14 corrects.
    pub along_view: f64,
}

/// A scene resolved for one view: the depth cue as a constant, a slope and
/// sinusoids in the transform's coordinates, and per-channel coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewPlan {
    /// Constant part of `w`, at the transform origin.
    pub base: f64,
    /// Slope `C_cue` of `w` (per voxel of depth).
    pub slope: f64,
    /// Sinusoidal terms.
    pub waves: Waves,
    /// Channel coefficients (1 or 3).
    pub channels: Vec<ChannelPlan, 3>,
    /// The lowest value `w` takes inside the volume's box on this view.
    pub min_weight_in_box: f64,
}

impl ViewPlan {
    /// Resolve `scene` for a volume of `dims` seen in `frame`.
    ///
    /// # Errors
    /// As [`Scene::validate`].
    pub fn new(scene: &Scene, frame: &Frame, dims: [usize; 3]) -> Result<Self> {
        scene.validate()?;
        let d = frame.dir;
        let radius = dims.iter().copied().max().unwrap_or(1) as f64 / 2.0;
        let (mut base, slope, mut waves) = resolve_cue(&scene.cue, radius)?;
        let weight_at = |t: f64| evaluate_cue(base, slope, &waves, t);
        let extent: f64 = (0..3)
            .map(|a| libm::fabs(d[a]) * dims[a] as f64 / 2.0)
            .sum();
        let mut min_weight_in_box = f64::INFINITY;
        for i in 0..=256 {
            let t = -extent + 2.0 * extent * i as f64 / 256.0;
            min_weight_in_box = min_weight_in_box.min(weight_at(t));
        }
        // Move the origin of depth from the centre c = n/2 to the transform
        // origin o = ⌊n/2⌋: t = τ − d·δ with δ = c − o (½ on odd axes).
        let shift: f64 = (0..3).map(|a| d[a] * (dims[a] % 2) as f64 * 0.5).sum();
        base -= slope * shift;
        for wave in waves.iter_mut() {
            wave.phase -= 2.0 * PI * wave.nu * shift;
        }

        let mut channels: Vec<ChannelPlan, 3> = Vec::new();
        for c in 0..scene.channels() {
            let mut plan = ChannelPlan {
                ambient: scene.ambient[c],
                gradient: 0.0,
                moment: [0.0; 2],
                along_view: 0.0,
            };
            for light in scene.lights.iter() {
                // Scaled first, so that a direction like 1e-300 or 1e300
                // per component does not square to 0 or infinity.
                let l = crate::geometry::fit_range(light.towards);
                let len = libm::sqrt(dot(l, l));
                let l = [l[0] / len, l[1] / len, l[2] / len];
                let half = 0.5 * light.color[c];
                plan.gradient += half;
                plan.moment[0] += half * dot(frame.right, l);
                plan.moment[1] += half * dot(frame.up, l);
                plan.along_view += half * dot(d, l);
            }
            // Channels are at most 3, the capacity.
            channels
                .push(plan)
                .map_err(|_| too_many("channels", 4, 3))?;
        }
        Ok(Self {
            base,
            slope,
            waves,
            channels,
            min_weight_in_box,
        })
    }
}

/// The sinusoidal terms of a resolved depth cue.
pub type Waves = Vec<Wave, { MAX_HARMONICS + 1 }>;

/// A depth cue resolved for a volume: `w(t) = base + slope·t + Σ waves`,
/// `t` the depth from the volume's centre.
#[derive(Clone, Debug, PartialEq)]
pub struct CueTerms {
    /// Constant part.
    pub base: f64,
    /// Slope `C_cue`, per voxel.
    pub slope: f64,
    /// Sinusoidal terms.
    pub waves: Waves,
}

impl CueTerms {
    /// Resolve `cue` for a volume whose largest dimension is `2·radius`.
    ///
    /// # Errors
    /// As [`Scene::validate`].
    pub fn new(cue: &DepthCue, radius: f64) -> Result<Self> {
        let scene = Scene {
            cue: cue.clone(),
            ..Scene::xray()
        };
        scene.validate()?;
        let (base, slope, waves) = resolve_cue(cue, radius)?;
        Ok(Self { base, slope, waves })
    }

    /// `w(t)`.
    pub fn weight(&self, t: f64) -> f64 {
        evaluate_cue(self.base, self.slope, &self.waves, t)
    }
}

fn resolve_cue(cue: &DepthCue, radius: f64) -> Result<(f64, f64, Waves)> {
    let (mut base, mut slope) = (1.0, 0.0);
    let mut waves = Waves::new();
    match cue {
        DepthCue::None => {}
        DepthCue::Linear { front, back } => {
            base = 0.5 * (front + back);
            slope = (back - front) / (2.0 * radius);
        }
        DepthCue::Sine { front, back } => {
            let (hi, lo) = (front.max(*back), front.min(*back));
            if front == back || hi == 0.0 {
                base = *front;
            } else {
                base = 0.0;
                // The crest (θ = π/2) sits at the brighter end; the other
                // end reaches asin(lo/hi) ∈ [0, π/2).
                let omega = (0.5 * PI - libm::asin(lo / hi)) / (2.0 * radius);
                // Front brighter: θ(t) = π/2 − ω(t + R), and sin θ =
                // sin(π − θ) = sin(ωt + π/2 + ωR). Back brighter:
                // θ(t) = ωt + π/2 − ωR.
                let phase = if front > back {
                    0.5 * PI + omega * radius
                } else {
                    0.5 * PI - omega * radius
                };
                push_wave(&mut waves, hi, omega / (2.0 * PI), phase)?;
            }
        }
        DepthCue::Profile { weights, harmonics } => {
            base = cosine_coefficient(weights, 0);
            for m in 1..=*harmonics {
                let c = cosine_coefficient(weights, m);
                // c·cos(πm(t + R)/2R) = c·sin(2π·(m/4R)·t + πm/2 + π/2).
                push_wave(
                    &mut waves,
                    c,
                    m as f64 / (4.0 * radius),
                    0.5 * PI * m as f64 + 0.5 * PI,
                )?;
            }
        }
    }
    Ok((base, slope, waves))
}

fn evaluate_cue(base: f64, slope: f64, waves: &[Wave], t: f64) -> f64 {
    let mut w = base + slope * t;
    for wave in waves {
        w += wave.amplitude * libm::sin(2.0 * PI * wave.nu * t + wave.phase);
    }
    w
}

fn push_wave(waves: &mut Waves, amplitude: f64, nu: f64, phase: f64) -> Result<()> {
    waves
        .push(Wave {
            amplitude,
            nu,
            phase,
        })
        .map_err(|_| too_many("depth-cue terms", MAX_HARMONICS + 2, MAX_HARMONICS + 1))
}

#[cold]
fn too_many(what: &'static str, given: usize, capacity: usize) -> Error {
    Error::TooMany {
        what,
        given,
        capacity,
    }
}

/// Coefficient `c_m` of the cosine series of the piecewise-linear profile
/// through `weights` on `u ∈ [0, 1]`: `c_0 = ∫w`, `c_m = 2∫w·cos(πmu)`.
/// 16-point Gauss–Legendre per segment: the integrand is smooth there.
fn cosine_coefficient(weights: &[f64], m: usize) -> f64 {
    let segments = weights.len() - 1;
    let h = 1.0 / segments as f64;
    let mut sum = 0.0;
    for s in 0..segments {
        let (u0, w0, w1) = (s as f64 * h, weights[s], weights[s + 1]);
        sum += gauss_legendre_16(u0, u0 + h, |u| {
            let w = w0 + (w1 - w0) * (u - u0) / h;
            w * libm::cos(PI * m as f64 * u)
        });
    }
    if m == 0 {
        sum
    } else {
        2.0 * sum
    }
}

/// [`Scene::field_count`] from what the scene needs: terms at the partner
/// point `−k` (a depth-varying cue), its channels, the gradient spectrum
/// and the cue-derivative fields. A `const fn`, so that a device sizes its
/// buffers at compile time.
pub const fn field_count_of(
    partner_terms: bool,
    channels: usize,
    gradient: bool,
    cue_derivative: bool,
) -> usize {
    let pair = if partner_terms { 2 } else { 1 };
    if channels == 1 {
        return pair;
    }
    let mut count = pair + 1;
    if gradient {
        count += pair;
    }
    if cue_derivative {
        count += pair;
    }
    count
}
