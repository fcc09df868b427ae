//! The accuracy model: the predicted dB of a configuration from the volume's
//! per-view sums ([`super`] explains the terms).

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::volume::{padded_size, DenseVolume, GridOversampling};

use super::sums::{self, PixelSums};
use super::weights::{axis_weights, in_plane, AxisWeights};
use super::wrap;
use crate::plan::filter::{choose_filter, KbDesign};
use crate::spectrum::Precision;
use crate::volume::Volume;

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

/// What the interpolation of one filter does to one volume.
pub(super) struct Interpolation {
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

pub(super) fn interpolation(
    volume: &Volume,
    filter: &Filter,
    n: usize,
) -> Result<Interpolation, fvr_core::Error> {
    let dims = volume.dims;
    let weights = axis_weights(filter, n);
    let (sums, g2) = sums::pixel_sums(volume, &weights, n)?;
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

/// `[Σref², Σe_edge², Σe_kernel², Σe²]` of the `side × side` image of the
/// view along axis `a` ([`AXIS_VIEWS`]).
fn view_energies(
    sums: &PixelSums,
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
            let (at, mirror) = (sums.pixel(xp, xq), sums.pixel(mp, mq));
            let aa = w.c[xp] * w.c[xq] - w.s[xp] * w.s[xq];
            let bb = w.s[xp] * w.c[xq] + w.c[xp] * w.s[xq];
            let mut e = [0.0; 2];
            let mut reference = 0.0;
            for (b, eb) in e.iter_mut().enumerate() {
                let image = aa * (at[b][1] - mirror[b][2]) + bb * (mirror[b][1] - at[b][2]);
                let r = if inside { at[b][0] } else { 0.0 };
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

pub(super) fn combine(
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
