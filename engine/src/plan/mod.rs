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

use std::f64::consts::PI;

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::volume::{padded_size, DenseVolume, GridOversampling};

use crate::plan::filter::{choose_filter, KbDesign};
use crate::spectrum::Precision;
use crate::volume::Volume;
use sums::ViewSums;

/// The weights' leak `|c − 1| + |s|` above which an axis position counts
/// towards the edge term (−40 dB), if it is also [`EDGE_OVER_CENTRE`] times
/// the leak at the centre (even-width kernels have one more tap on one side,
/// which alone errs by about 2% everywhere at oversampling 1).
pub const EDGE_LEAK: f64 = 0.01;

/// See [`EDGE_LEAK`].
pub const EDGE_OVER_CENTRE: f64 = 2.0;

/// Late roundings proportional to the image (`r_late`): the last pass's
/// store, and the two before it for the view along the axis transformed
/// first (measured: the x view is the noisiest, by up to 3 dB).
const LATE_ROUNDINGS: f64 = 3.0;

/// Roundings spread over the cube (`r_spread`): the premultiplied input and
/// the three passes' stores would make 4; fitted to the worst measured case
/// (a grid-filling volume whose faces premultiplication amplifies, where
/// 4 was 3.6 dB optimistic): 10.
const SPREAD_ROUNDINGS: f64 = 10.0;

/// The three axis views the prediction is made for.
pub const AXIS_VIEWS: [View; 3] = [
    View {
        dir: [1.0, 0.0, 0.0],
        up: [0.0, 0.0, 1.0],
    },
    View {
        dir: [0.0, 1.0, 0.0],
        up: [0.0, 0.0, 1.0],
    },
    View {
        dir: [0.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
    },
];

/// A configuration the planner can choose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// Interpolation filter.
    pub filter: FilterKind,
    /// The filter's integer oversampling, 1 or 2: with [`Prediction::grid`]
    /// σ = 1 or 2 the grid's, and 1 for the mixed-radix grids σ = 1.25
    /// and 1.5 ([`GridOversampling::integer`]).
    pub oversample: u32,
    /// Spectrum storage.
    pub precision: Precision,
}

/// The grids [`choose`] considers: the power-of-two ones.
pub const POW2_GRIDS: [GridOversampling; 2] = [GridOversampling::X1, GridOversampling::X2];

/// Every grid [`choose_among`] can consider, mixed radix included.
pub const ALL_GRIDS: [GridOversampling; 4] = GridOversampling::ALL;

/// The error term that limits a prediction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Term {
    /// Replicas leaking into content near the faces of the grid.
    Edge,
    /// The kernel's finite stopband on the rest of the volume.
    Kernel,
    /// Rounding of the stored spectrum.
    Storage,
}

impl Term {
    /// Short name, as `--stats-json` prints it.
    pub fn name(self) -> &'static str {
        match self {
            Term::Edge => "edge",
            Term::Kernel => "kernel",
            Term::Storage => "storage",
        }
    }

    /// Why this term limits the accuracy, in a few words.
    pub fn why(self) -> &'static str {
        match self {
            Term::Edge => {
                "content near the faces of the grid meets the neighbouring replica, or an \
                 oblique view's shadow or its band-limited tails wrap around the image"
            }
            Term::Kernel => "the kernel's stopband leaks on the volume's interior",
            Term::Storage => "rounding of the stored spectrum",
        }
    }
}

/// A predicted accuracy: SNR in dB against the exact projection of the
/// band-limited interpolant, worst of the three axis views and the oblique
/// views whose shadow wraps around the image (`wrap.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prediction {
    /// The configuration predicted.
    pub candidate: Candidate,
    /// The grid predicted ([`GridOversampling::side`]): what to prepare
    /// with [`super::spectrum::AnySpectrum::prepare_grid`] and the filter
    /// [`grid_filter`] makes.
    pub grid: GridOversampling,
    /// Kaiser–Bessel β of the fitted filter (0 for other kernels).
    pub beta: f64,
    /// SNR of the worst axis view, dB.
    pub db: f64,
    /// SNR of each axis view (x, y, z), dB.
    pub views_db: [f64; 3],
    /// Each term alone on the worst view, as an SNR in dB: edge, kernel,
    /// storage.
    pub parts_db: [f64; 3],
}

impl Prediction {
    /// The term with the most error power on the worst view.
    pub fn dominant(&self) -> Term {
        let [e, k, s] = self.parts_db;
        if e <= k && e <= s {
            Term::Edge
        } else if k <= s {
            Term::Kernel
        } else {
            Term::Storage
        }
    }
}

/// One axis of the padded grid: the interpolation weights at each grid index
/// (signed distance `x` from the transform origin, `x ∈ [−n/2, n/2)`).
struct AxisWeights {
    c: Vec<f64>,
    s: Vec<f64>,
    p: Vec<f64>,
    edge: Vec<bool>,
}

fn signed(idx: usize, n: usize) -> i64 {
    if idx < n / 2 || n == 1 {
        idx as i64
    } else {
        idx as i64 - n as i64
    }
}

fn axis_weights(filter: &Filter, n: usize) -> AxisWeights {
    let w = filter.width() as i64;
    // First tap of a sample at integer index q: j0 = ⌊q − W/2⌋ + 1; offsets q − j.
    let j0 = (-(w as f64) / 2.0).floor() as i64 + 1;
    let taps: Vec<(f64, f64)> = (0..w)
        .map(|m| {
            let t = (-j0 - m) as f64;
            (t, filter.kernel(t))
        })
        .collect();
    let mut out = AxisWeights {
        c: vec![0.0; n],
        s: vec![0.0; n],
        p: vec![0.0; n],
        edge: vec![false; n],
    };
    for idx in 0..n {
        let nu = signed(idx, n) as f64 / n as f64;
        let p = 1.0 / filter.response(nu);
        let (mut c, mut s) = (0.0, 0.0);
        for &(t, k) in &taps {
            c += k * (2.0 * PI * t * nu).cos();
            s += k * (2.0 * PI * t * nu).sin();
        }
        out.c[idx] = c * p;
        out.s[idx] = s * p;
        out.p[idx] = p;
    }
    let leak = |idx: usize| (out.c[idx] - 1.0).abs() + out.s[idx].abs();
    let threshold = EDGE_LEAK.max(EDGE_OVER_CENTRE * leak(0));
    for idx in 0..n {
        out.edge[idx] = leak(idx) > threshold;
    }
    out
}

/// What the interpolation of one filter does to one volume.
struct Interpolation {
    n: usize,
    /// Per view: `Σref²`, edge, kernel and total error energies.
    energies: [[f64; 4]; 3],
    /// `Σg²` of the premultiplied volume.
    g2: f64,
    /// `Σ_t k(t)²` and `Σ_t k(t)` of the taps of a sample on the grid.
    k2: f64,
    k1: f64,
    /// Image pixels `W·H`.
    pixels: f64,
}

/// The default image side on the grid of side `n`: the power of two the
/// volume fills at σ = 1 ([`padded_size`]`(dims, 1)`, `n/oversample` on the
/// power-of-two grids), at most `n`.
pub fn image_side(dims: [usize; 3], n: usize) -> Result<usize, fvr_core::Error> {
    Ok(padded_size(dims, 1)?.min(n))
}

/// The filter of kind `kind` for `grid`, fitted as `design` asks: on the
/// power-of-two grids as [`choose_filter`]; on the mixed-radix ones
/// [`Filter::fit_grid`] (or Beatty's β at the design given).
///
/// # Errors
/// As [`choose_filter`].
pub fn grid_filter(
    volume: &Volume,
    kind: FilterKind,
    grid: GridOversampling,
    design: KbDesign,
) -> Result<Filter, fvr_core::Error> {
    if grid.is_pow2() {
        return choose_filter(volume, kind, grid.integer(), design);
    }
    match design {
        KbDesign::Auto => {
            let src = DenseVolume::new(volume.dims, &volume.data)?;
            Ok(Filter::fit_grid(kind, grid, &src)?.0)
        }
        KbDesign::Sigma(s) => Filter::with_design_oversampling(kind, grid.integer(), s),
    }
}

fn interpolation(
    volume: &Volume,
    filter: &Filter,
    n: usize,
) -> Result<Interpolation, fvr_core::Error> {
    let dims = volume.dims;
    let weights = axis_weights(filter, n);
    let (sums, g2) = sums::view_sums(volume, &weights, n)?;
    let side = image_side(dims, n)?;
    let mut energies = [[0.0; 4]; 3];
    for (a, e) in energies.iter_mut().enumerate() {
        *e = view_energies(&sums[a], &weights, dims, n, a, side)?;
    }
    let taps = fvr_core::filter::KernelTable::<f64>::new(*filter);
    let mut w = [0.0; fvr_core::filter::MAX_WIDTH];
    taps.taps(0.0, &mut w);
    Ok(Interpolation {
        n,
        energies,
        g2,
        k2: w.iter().map(|x| x * x).sum(),
        k1: w.iter().sum(),
        pixels: (side * side) as f64,
    })
}

/// The in-plane axes of the view along axis `a`, lower first.
fn in_plane(a: usize) -> (usize, usize) {
    match a {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// `[Σref², Σe_edge², Σe_kernel², Σe²]` of the `side × side` image of the
/// view along axis `a` ([`AXIS_VIEWS`]).
fn view_energies(
    sums: &ViewSums,
    w: &AxisWeights,
    dims: [usize; 3],
    n: usize,
    a: usize,
    side: usize,
) -> Result<[f64; 4], fvr_core::Error> {
    let frame = AXIS_VIEWS[a].frame()?;
    let (pa, qa) = in_plane(a);
    // Image column/row steps along the in-plane axes: ±1 on one of them.
    let along = |v: [f64; 3]| {
        let ax = if v[pa].abs() > 0.5 { pa } else { qa };
        (ax, v[ax].signum())
    };
    let (ax_r, sign_r) = along(frame.right);
    let (ax_u, sign_u) = along(frame.up);
    let half = side as f64 / 2.0;
    let mut out = [0.0; 4];
    for row in 0..side {
        for col in 0..side {
            let mut rel = [0i64; 3];
            // Pixel offset from the centre dims/2, measured from the origin ⌊dims/2⌋.
            let offset = |ax: usize, t: f64| ((dims[ax] % 2) as f64 * 0.5 + t).floor() as i64;
            rel[ax_r] = offset(ax_r, sign_r * (col as f64 - half));
            rel[ax_u] = offset(ax_u, sign_u * (half - row as f64));
            let inside = [pa, qa]
                .iter()
                .all(|&ax| (0..dims[ax] as i64).contains(&(rel[ax] + (dims[ax] / 2) as i64)));
            let wrap = |r: i64| r.rem_euclid(n as i64) as usize;
            let (xp, xq) = (wrap(rel[pa]), wrap(rel[qa]));
            let (mp, mq) = (wrap(-rel[pa]), wrap(-rel[qa]));
            let at = xp + n * xq;
            let mirror = mp + n * mq;
            let aa = w.c[xp] * w.c[xq] - w.s[xp] * w.s[xq];
            let bb = w.s[xp] * w.c[xq] + w.c[xp] * w.s[xq];
            let mut e = [0.0; 2];
            let mut reference = 0.0;
            for (b, eb) in e.iter_mut().enumerate() {
                let image = aa * (sums.cos[b][at] - sums.sin[b][mirror])
                    + bb * (sums.cos[b][mirror] - sums.sin[b][at]);
                let r = if inside { sums.plain[b][at] } else { 0.0 };
                reference += r;
                *eb = image - r;
            }
            out[0] += reference * reference;
            out[1] += e[0] * e[0];
            out[2] += e[1] * e[1];
            out[3] += (e[0] + e[1]) * (e[0] + e[1]);
        }
    }
    Ok(out)
}

/// Unit roundoff of the stored spectrum.
fn storage_roundoff(p: Precision) -> f64 {
    match p {
        Precision::F16 => 2f64.powi(-11),
        Precision::F32 => 2f64.powi(-24),
        Precision::F64 => 2f64.powi(-53),
    }
}

fn db(signal: f64, noise: f64) -> f64 {
    if signal <= 0.0 {
        return f64::INFINITY;
    }
    10.0 * (signal / noise).log10()
}

fn combine(
    interp: &Interpolation,
    candidate: Candidate,
    grid: GridOversampling,
    beta: f64,
    wrap: f64,
) -> Prediction {
    let u = storage_roundoff(candidate.precision);
    // f32 arithmetic for f16 and f32 storage: log₂n roundings in each of the
    // five transform passes (three forward, two inverse).
    let ua = match candidate.precision {
        Precision::F64 => u,
        _ => 2f64.powi(-24),
    };
    let log_n = (interp.n.max(2) as f64).log2();
    let rho = (interp.k2 / (interp.k1 * interp.k1)).powf(1.5);
    let spread = interp.pixels / (interp.n * interp.n) as f64 * interp.k2.powi(3) * interp.g2;
    let mut views_db = [0.0; 3];
    let mut worst = (f64::INFINITY, [f64::INFINITY; 3]);
    let mut worst_energies = [0.0; 5];
    for (v, e) in interp.energies.iter().enumerate() {
        let [signal, edge, kernel, total] = *e;
        let late = LATE_ROUNDINGS * u * u + 5.0 * log_n * ua * ua;
        let storage = (late * rho * signal + SPREAD_ROUNDINGS * u * u * spread) / 3.0;
        views_db[v] = db(signal, total + storage);
        if views_db[v] < worst.0 || v == 0 {
            worst = (
                views_db[v],
                [db(signal, edge), db(signal, kernel), db(signal, storage)],
            );
            worst_energies = [signal, edge, kernel, total, storage];
        }
    }
    // The oblique views: the worst axis view's error with the wrapped
    // shadow added to its edge term.
    let [signal, edge, kernel, total, storage] = worst_energies;
    let oblique = db(signal, total + storage + wrap * signal);
    if wrap > 0.0 && oblique < worst.0 {
        worst = (
            oblique,
            [
                db(signal, edge + wrap * signal),
                db(signal, kernel),
                db(signal, storage),
            ],
        );
    }
    Prediction {
        candidate,
        grid,
        beta,
        db: worst.0,
        views_db,
        parts_db: worst.1,
    }
}

/// Predict the SNR of `candidate` on `volume` (filter fitted as `design`
/// asks, default image size `n/oversample`).
///
/// # Errors
/// As [`choose_filter`]; a NaN or infinite voxel.
pub fn predict(
    volume: &Volume,
    candidate: Candidate,
    design: KbDesign,
) -> Result<Prediction, fvr_core::Error> {
    let grid = GridOversampling::from_integer(candidate.oversample)?;
    predict_grid(volume, candidate, grid, design)
}

/// [`predict`] on the grid `grid` (whose [`GridOversampling::integer`] is
/// taken as the candidate's oversampling), filter from [`grid_filter`].
///
/// # Errors
/// As [`predict`].
pub fn predict_grid(
    volume: &Volume,
    candidate: Candidate,
    grid: GridOversampling,
    design: KbDesign,
) -> Result<Prediction, fvr_core::Error> {
    let candidate = Candidate {
        oversample: grid.integer(),
        ..candidate
    };
    let filter = grid_filter(volume, candidate.filter, grid, design)?;
    let n = grid.side(volume.dims)?;
    let interp = interpolation(volume, &filter, n)?;
    let wrap = wrap::Shadows::new(volume).worst_ratio(n, image_side(volume.dims, n)?);
    Ok(combine(&interp, candidate, grid, filter.beta(), wrap))
}

mod choose;
mod splat;
mod sums;
mod tails;
#[cfg(test)]
mod test_volume;
mod wrap;
pub use choose::{
    choose, choose_among, cost, cost_grid, Constraints, Plan, CANDIDATE_FILTERS, MARGIN_DB,
};
