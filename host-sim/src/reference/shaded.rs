//! f64 references for depth-cued and shaded images (the model in
//! [`fvr_core::scene`]):
//!
//! `I_c = ∫ w(t)·[A_c·f + K_c·|∇f| − M_c·∇f] dt`, `K_c = Σ_l ½D_{l,c}`,
//! `M_c = Σ_l ½D_{l,c}·L_l`.
//!
//! - [`exact_scene_projection`]: analytic Gaussian mixtures. Along a ray a
//!   Gaussian is `G(t) = exp(−½(at² + 2bt + c))`, and `w·f` and `w·(∇f·M)`
//!   are polynomials (degree ≤ 2) and sinusoids times `G`, integrated in
//!   closed form through the complex moments
//!   `M_k(ω) = ∫ t^k·G·e^{iωt} dt`: `M_0 = √(2π/a)·e^{a z²/2 − c/2}`,
//!   `M_1 = z·M_0`, `M_2 = (1/a + z²)·M_0`, `z = (iω − b)/a`. `|∇f|` has no
//!   closed form and is integrated with Simpson's rule at a fine step.
//! - [`spatial_scene_projection`]: a sampled volume, ray-marched in f64
//!   with trilinear interpolation of `f`, of the spectral partial
//!   derivatives and of `|∇f|` (the same samples the frequency-domain path
//!   transforms).

use crate::image::Image;
use crate::reference::trilinear;
use fvr_core::dht::Twiddles;
use fvr_core::geometry::{center, Sampling, View};
use fvr_core::shading::gradient::{gradient_scratch_len, partial_derivative};
use fvr_core::shading::{CueTerms, Scene};
use fvr_core::volume::DenseVolume;
use fvr_engine::volume::phantom::{Gaussian, GaussianMixture};
use fvr_engine::volume::Volume;

/// Per-channel coefficients `(A_c, K_c, M_c)`.
fn channel_terms(scene: &Scene) -> Vec<(f64, f64, [f64; 3])> {
    (0..scene.channels())
        .map(|c| {
            let mut k = 0.0;
            let mut m = [0.0; 3];
            for light in scene.lights.iter() {
                let l = light.towards;
                let len = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
                let half = 0.5 * light.color[c];
                k += half;
                for a in 0..3 {
                    m[a] += half * l[a] / len;
                }
            }
            (scene.ambient[c], k, m)
        })
        .collect()
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `(re, im)` complex helpers.
type C = (f64, f64);
fn cmul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}

/// A Gaussian along the ray `p + t·d`, in whitened coordinates.
struct RayGaussian {
    amplitude: f64,
    a: f64,
    b: f64,
    /// `c − b²/a ≥ 0`, computed as a residual norm.
    rest: f64,
    /// `S(p − μ)` and `S·d` whitened, for moments against a vector.
    w: [f64; 3],
    v: [f64; 3],
}

impl RayGaussian {
    fn new(g: &Gaussian, p: [f64; 3], d: [f64; 3]) -> Self {
        let w = g.whiten([p[0] - g.center[0], p[1] - g.center[1], p[2] - g.center[2]]);
        let v = g.whiten(d);
        let a = dot(v, v);
        let s = dot(w, v) / a;
        let r = [w[0] - s * v[0], w[1] - s * v[1], w[2] - s * v[2]];
        Self {
            amplitude: g.amplitude,
            a,
            b: dot(w, v),
            rest: dot(r, r),
            w,
            v,
        }
    }

    /// `(M_0, M_1, M_2)` at angular frequency `omega`.
    fn moments(&self, omega: f64) -> [C; 3] {
        let z: C = (-self.b / self.a, omega / self.a);
        // a·z²/2 − c/2 = −rest/2 − ω²/(2a) − i·ωb/a.
        let re = -0.5 * self.rest - 0.5 * omega * omega / self.a;
        let im = -omega * self.b / self.a;
        let mag = (2.0 * std::f64::consts::PI / self.a).sqrt() * re.exp();
        let m0: C = (mag * im.cos(), mag * im.sin());
        let m1 = cmul(z, m0);
        let z2 = cmul(z, z);
        let m2 = cmul((1.0 / self.a + z2.0, z2.1), m0);
        [m0, m1, m2]
    }

    /// `∫ w(t)·(α + β·t)·G(t) dt` for the cue `terms`.
    fn weighted(&self, terms: &CueTerms, alpha: f64, beta: f64) -> f64 {
        let [m0, m1, m2] = self.moments(0.0);
        let mut sum =
            terms.base * (alpha * m0.0 + beta * m1.0) + terms.slope * (alpha * m1.0 + beta * m2.0);
        for wave in terms.waves.iter() {
            let omega = 2.0 * std::f64::consts::PI * wave.nu;
            let [m0, m1, _] = self.moments(omega);
            let lin = (alpha * m0.0 + beta * m1.0, alpha * m0.1 + beta * m1.1);
            let rot = cmul((wave.phase.cos(), wave.phase.sin()), lin);
            sum += wave.amplitude * rot.1;
        }
        sum
    }
}

/// `∇f` of a mixture at `x`.
fn mixture_gradient(mixture: &GaussianMixture, x: [f64; 3]) -> [f64; 3] {
    let mut grad = [0.0; 3];
    for g in &mixture.components {
        let w = g.whiten([x[0] - g.center[0], x[1] - g.center[1], x[2] - g.center[2]]);
        let f = g.amplitude * (-0.5 * dot(w, w)).exp();
        // ∇f = −f·S(x − μ) = −f·R·diag(1/σ)·w.
        let y = [w[0] / g.sigmas[0], w[1] / g.sigmas[1], w[2] / g.sigmas[2]];
        for a in 0..3 {
            let ry = g.rotation[a][0] * y[0] + g.rotation[a][1] * y[1] + g.rotation[a][2] * y[2];
            grad[a] -= f * ry;
        }
    }
    grad
}

/// Exact shaded, depth-cued image of a Gaussian mixture sampled on a grid
/// of `dims` (geometry contract of [`fvr_core::geometry`]), on an image of
/// `size = (width, height)` pixels. `step` is the Simpson step for the
/// `|∇f|` term (e.g. 0.05 voxels).
///
/// # Errors
/// Bad view vectors or scene values.
pub fn exact_scene_projection(
    mixture: &GaussianMixture,
    dims: [usize; 3],
    scene: &Scene,
    view: &View,
    size: (usize, usize),
    step: f64,
) -> Result<Image, fvr_core::Error> {
    exact_scene_projection_sampled(mixture, dims, &Sampling::UNIT, scene, view, size, step)
}

/// [`exact_scene_projection`] in physical units, for a mixture given in mm
/// and a volume of `dims` sampled at `sampling.spacing()`: pixels at
/// `sampling.pixel_position`, depth `t = d·(x − C)` in mm with the cue's `R`
/// half the longest physical side `max_a n_a·Δ_a`, gradients per mm, and
/// `∫ … dt` with `t` in mm, on an image of `(width, height)` pixels. `step`
/// is in mm. [`Sampling::UNIT`] gives [`exact_scene_projection`].
///
/// # Errors
/// As [`exact_scene_projection`].
pub fn exact_scene_projection_sampled(
    mixture: &GaussianMixture,
    dims: [usize; 3],
    sampling: &Sampling,
    scene: &Scene,
    view: &View,
    (width, height): (usize, usize),
    step: f64,
) -> Result<Image, fvr_core::Error> {
    scene.validate()?;
    let frame = view.frame()?;
    let spacing = sampling.spacing();
    let sides: [f64; 3] = std::array::from_fn(|a| dims[a] as f64 * spacing[a]);
    let radius = sides.iter().copied().fold(0.0, f64::max).max(spacing[0]) / 2.0;
    let terms = CueTerms::new(&scene.cue, radius)?;
    let channels = channel_terms(scene);
    let needs_gradient = scene.needs_gradient_spectrum();
    let reach = 0.5 * sides.iter().map(|&d| d * d).sum::<f64>().sqrt()
        + 2.0 * spacing.iter().copied().fold(0.0, f64::max);
    let steps = 2 * (reach / step).ceil() as usize;
    let h = 2.0 * reach / steps as f64;
    let mut data = Vec::with_capacity(channels.len() * width * height);
    for row in 0..height {
        for col in 0..width {
            let p = sampling.pixel_position(&frame, dims, width, height, col as f64, row as f64);
            let rays: Vec<RayGaussian> = mixture
                .components
                .iter()
                .map(|g| RayGaussian::new(g, p, frame.dir))
                .collect();
            let density: f64 = rays
                .iter()
                .map(|r| r.weighted(&terms, r.amplitude, 0.0))
                .sum();
            let gradient_term = if needs_gradient {
                let mut sum = 0.0;
                for s in 0..=steps {
                    let t = -reach + s as f64 * h;
                    let x = [
                        p[0] + t * frame.dir[0],
                        p[1] + t * frame.dir[1],
                        p[2] + t * frame.dir[2],
                    ];
                    let g = mixture_gradient(mixture, x);
                    let simpson = if s == 0 || s == steps {
                        1.0
                    } else if s % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    sum += simpson * terms.weight(t) * dot(g, g).sqrt();
                }
                sum * h / 3.0
            } else {
                0.0
            };
            for &(ambient, k, m) in &channels {
                // −M·∇f = A·(w·S(p−μ)·M + t·(S d)·M)·G per component.
                let moment: f64 = rays
                    .iter()
                    .zip(&mixture.components)
                    .map(|(r, g)| {
                        let wm = g.whiten(m);
                        r.weighted(
                            &terms,
                            r.amplitude * dot(r.w, wm),
                            r.amplitude * dot(r.v, wm),
                        )
                    })
                    .sum();
                data.push(ambient * density + k * gradient_term + moment);
            }
        }
    }
    Ok(Image {
        channels: channels.len(),
        width,
        height,
        data,
    })
}

/// Spectral partial derivatives and `|∇f|` of a sampled volume, in f64.
///
/// # Errors
/// A non-finite voxel.
pub fn spectral_gradient(volume: &Volume) -> Result<[Vec<f64>; 3], fvr_core::Error> {
    let source = DenseVolume::new(volume.dims, &volume.data)?;
    let len = gradient_scratch_len(volume.dims);
    let mut tw_buf = vec![0.0f64; Twiddles::<f64>::buffer_len(len)];
    let tw = Twiddles::new(&mut tw_buf, len)?;
    let mut line = vec![0.0f64; len];
    let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; volume.data.len()]);
    for (axis, o) in out.iter_mut().enumerate() {
        partial_derivative(&source, axis, o, &mut line, &tw)?;
    }
    Ok(out)
}

/// Spatial-domain f64 image of `scene` on a sampled volume: each ray is
/// integrated with the midpoint rule at `step` voxels, `f`, `∂f/∂x_a` and
/// `|∇f|` being trilinear interpolations of their samples (zero outside).
///
/// # Errors
/// Bad view vectors, scene values, or a non-finite voxel.
pub fn spatial_scene_projection(
    volume: &Volume,
    scene: &Scene,
    view: &View,
    width: usize,
    height: usize,
    step: f64,
) -> Result<Image, fvr_core::Error> {
    scene.validate()?;
    let frame = view.frame()?;
    let dims = volume.dims;
    let c = center(dims);
    let radius = dims.iter().copied().max().unwrap_or(1) as f64 / 2.0;
    let terms = CueTerms::new(&scene.cue, radius)?;
    let channels = channel_terms(scene);
    let lit = scene.needs_gradient_spectrum();
    let to_volume = |data: Vec<f64>| Volume {
        dims,
        data: data.into_iter().map(|v| v as f32).collect(),
        spacing: volume.spacing,
        orientation: volume.orientation,
    };
    let (partials, magnitude) = if lit {
        let g = spectral_gradient(volume)?;
        let mag: Vec<f64> = (0..volume.data.len())
            .map(|i| (g[0][i] * g[0][i] + g[1][i] * g[1][i] + g[2][i] * g[2][i]).sqrt())
            .collect();
        let [gx, gy, gz] = g;
        (
            Some([to_volume(gx), to_volume(gy), to_volume(gz)]),
            Some(to_volume(mag)),
        )
    } else {
        (None, None)
    };
    let reach =
        0.5 * ((dims[0] * dims[0] + dims[1] * dims[1] + dims[2] * dims[2]) as f64).sqrt() + 1.0;
    let steps = (2.0 * reach / step).ceil() as usize;
    let mut data = Vec::with_capacity(channels.len() * width * height);
    let mut acc = vec![0.0f64; channels.len()];
    for row in 0..height {
        for col in 0..width {
            let p = frame.pixel_position(c, width, height, col as f64, row as f64);
            acc.iter_mut().for_each(|a| *a = 0.0);
            for s in 0..steps {
                let t = -reach + (s as f64 + 0.5) * step;
                let q: [f64; 3] = std::array::from_fn(|a| p[a] + t * frame.dir[a]);
                let w = terms.weight(t);
                let f = trilinear(volume, q);
                let (grad, mag) = match (&partials, &magnitude) {
                    (Some(g), Some(m)) => (
                        [
                            trilinear(&g[0], q),
                            trilinear(&g[1], q),
                            trilinear(&g[2], q),
                        ],
                        trilinear(m, q),
                    ),
                    _ => ([0.0; 3], 0.0),
                };
                for (a, &(ambient, k, m)) in acc.iter_mut().zip(&channels) {
                    *a += w * (ambient * f + k * mag - dot(m, grad));
                }
            }
            data.extend(acc.iter().map(|a| a * step));
        }
    }
    Ok(Image {
        channels: channels.len(),
        width,
        height,
        data,
    })
}
