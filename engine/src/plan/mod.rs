//! Planning a render for an accuracy target: the SNR a configuration is
//! predicted to reach on a volume, computed from the volume itself without
//! preparing a spectrum, and the cheapest configuration predicted to meet a
//! target.
//!
//! # The model
//!
//! For a view along a grid axis with pixels on the grid, the pipeline's
//! image is known in closed form. Interpolating the Hartley spectrum at an
//! integer index `q` reads `V(q) = Σ_t k(t)·H(q − t)` over the filter's taps
//! `t` (for an even width `W` they are `W/2, …, 1 − W/2`: one more on one
//! side). A shift of a Hartley spectrum is, in space,
//! `H(q − t) ↔ cos(2πtx/n)·g(x) + sin(2πtx/n)·g(−x)`, so each axis `a`
//! turns the premultiplied volume `g = f·Π p_a` (`p_a = 1/ĥ(x_a/n)`) into
//! `C_a·g + S_a·g(−x)` with `C_a(x) = Σ_t k(t)cos(2πtx_a/n)` (even) and
//! `S_a(x) = Σ_t k(t)sin(2πtx_a/n)` (odd, zero for odd widths). Composing the
//! three axes and summing along the view's axis `z` gives, with
//! `c_a = C_a·p_a`, `s_a = S_a·p_a`, `I = Σ_z c_z f`, `J = Σ_z s_z f`:
//!
//! `image(x, y) = A·(I(x, y) − J(−x, −y)) + B·(I(−x, −y) − J(x, y))`,
//! `A = c_x c_y − s_x s_y`, `B = s_x c_y + c_x s_y`,
//!
//! on the periodic `n × n` grid, where positions are signed distances from
//! the transform origin `⌊dims/2⌋` taken modulo `n`. The exact image of the
//! band-limited interpolant is the voxel sum `Σ_z f` where the pixel lies on
//! the volume, and 0 elsewhere (a pixel beyond the volume that wraps onto it
//! on the periodic grid is an error too). Ideal weights are `c = 1`, `s = 0`;
//! at oversampling 1 the first replica `ĥ(ν − 1)` is as strong as the main
//! lobe at `ν = ½`, so `c` reaches 2 there: content at the faces of the box
//! is imaged at double strength.
//!
//! The interpolation error is therefore computed, not estimated, in one pass
//! over the volume per filter and oversampling (about 10 multiply-adds per
//! voxel, against the `3·log₂n` passes and premultiplication of a spectrum).
//! It is split by where the content sits: the **edge** term comes from
//! voxels where some axis's weights leak more than [`EDGE_LEAK`] (`|c − 1| +
//! |s|`) and more than twice as much as at the centre, the **kernel** term from the rest (the kernel's finite stopband
//! everywhere else). The total is the energy of their sum.
//!
//! Storage rounding adds independent noise: each of `r` roundings of the
//! spectrum to unit roundoff `u` adds relative variance `u²/3` to the
//! coefficients, and the interpolation passes it to the slice with the
//! weights' gain `ρ = (Σk²/(Σk)²)^{3/2}` (the cube `(Σk²/(Σk)²)³` of
//! independent noise on a smooth spectrum measured up to 7 dB optimistic:
//! the slice's few large coefficients near the origin dominate). Roundings late in the transform stay
//! proportional to the slice's own values (the image energy `Σref²`); early
//! ones are spread over the whole cube, whose energy `Σg²` premultiplication
//! inflates at the faces ([`super::filter::premultiplication_gain_db`]):
//!
//! `noise = u²/3·(r_late·ρ·Σref² + r_spread·(W·H/n²)·(Σk²)³·Σg²)`
//!
//! with `r_late = 3` and `r_spread = 10` (see the constants: fitted so that
//! no measured case falls more than 3 dB below its prediction, from the
//! nominal 1 and 4),
//! plus `log₂n` f32 roundings per pass of arithmetic. The SNR of a view is
//! `Σref² / (Σ(image − ref)² + noise)`; a configuration's prediction is the
//! worst of the views along x, y and z.
//!
//! Odd sizes put the pixels half a voxel off the grid; they are predicted
//! as if on it. Oblique views and physical units are predicted by the axis views: the
//! weights then vary with the sub-voxel phase of each slice sample, but the
//! edge leak, which dominates real data, has the same size (measured: f64
//! kb5 and kb6 agree to 0.2 dB off axis). What oblique views add is in
//! `wrap.rs`: the shadow wider than the grid, and the band-limited tails of
//! points projected between pixels, which the image folds with the grid's
//! period instead of the ideal's.

pub mod filter;

mod choose;
mod model;
mod splat;
mod sums;
mod tails;
#[cfg(test)]
mod test_volume;
mod weights;
mod wrap;
pub use choose::{
    choose, choose_among, cost, cost_grid, Constraints, Plan, CANDIDATE_FILTERS, MARGIN_DB,
};
pub use model::{
    grid_filter, image_side, predict, predict_grid, Candidate, Prediction, Term, ALL_GRIDS,
    AXIS_VIEWS, POW2_GRIDS,
};
pub use weights::{EDGE_LEAK, EDGE_OVER_CENTRE};
