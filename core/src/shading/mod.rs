//! Shape cues in the frequency domain: depth cueing (paper §3.1, eq. 3–5),
//! hemispherical directional shading with coloured lights (§3.2, eq. 7–11)
//! and both together (§3.3, eq. 12–14).
//!
//! # The image model
//! For each colour channel `c` the image is
//!
//! `I_c = ∫ w(t)·[ A_c·f + Σ_l ½·D_{l,c}·(|∇f| − ∇f·L_l) ] dt`
//!
//! along the ray of each pixel, where
//! - `t = d·(x − c)` is the depth from the volume's centre `c` along the unit
//!   view direction `d` (voxel units), and `w(t)` the depth-cue weight;
//! - `A_c` is the ambient colour, `D_{l,c}` light `l`'s colour and `L_l` the
//!   unit vector *towards* light `l`;
//! - `N = −∇f/|∇f|` is the outward normal of structures denser than their
//!   surroundings, so `½·(|∇f| − ∇f·L) = ½·|∇f|·(1 + N·L)` is the
//!   hemispherical irradiance of eq. 8–10: a surface facing a light is
//!   bright, one facing away is dark, and the term is never negative.
//!
//! # Depth cues
//! - [`DepthCue::Linear`]: `w(t) = C_avg + C_cue·t` (eq. 3) through `FRONT`
//!   at `t = −R` and `BACK` at `t = +R`, `R` half the volume's largest
//!   dimension. Rendered with the composite filter `H' = C_avg·H −
//!   (C_cue/2π)·(d·∇H)` of eq. 5 (see [`mod@crate::render`] for its
//!   Hartley form).
//! - [`DepthCue::Sine`]: the paper's single-impulse form, `w(t) = A·sin(ωt +
//!   φ)` with no DC term, through `FRONT` and `BACK`, one end at the sine's
//!   crest. It is one shifted `H`. For `FRONT = 1, BACK = 0` it is
//!   `sin(π(R − t)/4R)`, which departs from the linear ramp by at most 0.21
//!   (at `t ≈ −0.12R`); for `1, 0.5` by 0.12.
//! - [`DepthCue::Profile`]: any profile, given as weights at equally spaced
//!   depths from `−R` (front) to `+R` (back), joined linearly, and fitted by
//!   the cosine series `w(u) = Σ_{m=0}^{M} c_m·cos(πmu)`, `u = (t + R)/2R`.
//!   Each harmonic is one more shifted `H` (the convolution `H * D` of eq. 5
//!   with `D` a sum of `2M + 1` impulses): the composite filter spans
//!   `W + 2M·n/(4R)` samples per axis, `W + 2M` at oversampling 2, and costs
//!   about `1 + 2M` times the plain extraction.
//!
//! Outside `[−R, R]` (the corners of the volume on oblique views) the linear
//! and sine weights are extrapolated and the profile repeats evenly. Weights
//! given below zero are refused ([`crate::Error::InvalidSceneValue`]): a negative
//! weight would subtract density and silently produce a wrong image.
//! Extrapolation into the corners can still go negative on oblique views;
//! [`ViewPlan::min_weight_in_box`] reports it so front ends can warn.
//!
//! # Hartley forms of the paper's operators
//! Let `X(k) = Σ_x g(x)·cas(2πk·x/n)` be a stored spectrum (index units,
//! `x` the signed position from the transform origin) and `X(q)` its
//! interpolation at a real 3D index `q`. Differentiating under the sum,
//! `∂X/∂q_a (q) = (2π/n)·Σ x_a·g·cas(−2πq·x/n)`, hence:
//!
//! - **Linear ramp (eq. 4–5).** `H{(d·x)·g}(k) = (n/2π)·(d·∇X)(−k)`: the
//!   gradient filter `d·∇H` applied at the *mirrored* point `−k`. (In
//!   Fourier terms `F{(d·x)g} = (i/2π)·d·∇F`; the factor `i` becomes the
//!   mirror.) For a slice point `k` the cued sample is
//!   `C_avg·X(k) + C_cue·(n/2π)·(d·∇X)(−k)`.
//! - **Sinusoid (after eq. 5).** For `a` a 3D index offset,
//!   `H{cos(2πa·x/n)·g}(k) = ½[X(k − a) + X(k + a)]` and
//!   `H{sin(2πa·x/n)·g}(k) = ½[X(a − k) − X(−a − k)]`. All four values come
//!   from the one neighbourhood of `k + a`: `U(k) = X(k + a)` read
//!   directly and `V(k) = X(−(k + a))` read at the mirrored indices `−j`
//!   with the same weights (the kernel is even). Then `X(k − a) = V(−k)`
//!   and `X(a − k) = U(−k)`. This is the paper's "shifted H"; the Hartley
//!   spectrum needs the mirrored read where a complex one holds `F` and
//!   `F*` in one sample, so a sinusoid costs two reads per tap.
//! - **First moment (eq. 11).** `H{∂_L f}(k) = −(2π/n)·(k·L)·X(−k)`.
//! - **Both (eq. 12–14).** `∫w·∂_L f = ∫∂_L(w·f) − (d·L)·∫w'·f`: shading
//!   the cued spectrum misses `−(d·L)` times the projection cued by `w'`.
//!   For linear cueing `w' = C_cue` and the correction is eq. 14,
//!   `½·C_cue·C_dif·L_dif·f·(V·L)`; for sinusoids `w'` is another sinusoid
//!   read from the same neighbourhood, so it costs no extra reads.
//!
//! Terms that need the partner point `−k` are accumulated in a second grid
//! `Q` and folded in at the end: `DC(k) = P(k) + Q(−k)`.
//!

pub mod gradient;
mod passes;
mod scene;

pub use scene::{
    field_count_of, ChannelPlan, CueTerms, DepthCue, Light, Scene, ViewPlan, Wave, MAX_HARMONICS,
    MAX_LIGHTS, MAX_PROFILE_POINTS,
};

pub(crate) use passes::{accumulate_cue, fold_partner, Accumulators, CueView, Tables};

/// Scratch elements a scene's render needs on a spectrum of side `n`:
/// [`Scene::field_count`] slice grids of `n²`.
pub fn fields_len(scene: &Scene, n: usize) -> usize {
    scene.field_count() * n * n
}
