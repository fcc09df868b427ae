//! Adaptive filtering on the host (paper §4): marks built once per
//! spectrum for a tolerance in dB, then views that read the cheaper filters
//! wherever the marks allow, with statistics.

use crate::render::adaptive_view::{AdaptiveRenderer, Walked};
use crate::render::fast_dht::{dht_3d_real, half_spectrum_bytes, SparseCube};
use crate::render::fast_marks;
use crate::render::spectrum::OwnedSpectrum;
use fvr_core::dht::signed_index;
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::num::{Real, Sample};
use fvr_core::slice::adaptive::{
    marks_words, response_difference, threshold_for, AdaptiveStats, MAX_LEVELS,
};
use fvr_core::spectrum::Spectrum;
use rayon::prelude::*;

/// The cheaper filters tried, cheapest first, as the user names them.
pub fn parse_chain(s: &str) -> Result<Vec<FilterKind>, String> {
    let kinds: Vec<FilterKind> = s
        .split(',')
        .map(|name| {
            FilterKind::from_name(name.trim())
                .ok_or_else(|| format!("unknown filter `{name}` in the adaptive chain"))
        })
        .collect::<Result<_, _>>()?;
    if kinds.is_empty() || kinds.len() > MAX_LEVELS {
        return Err(format!(
            "an adaptive chain names 1 to {MAX_LEVELS} cheaper filters, got `{s}`"
        ));
    }
    Ok(kinds)
}

/// Parse a tolerance in dB: a finite number above 0.
pub fn parse_tolerance(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "adaptive tolerance must be a positive number of dB (e.g. 40), got `{s}`"
        )),
    }
}

/// How the magnitude threshold is derived from the tolerance.
///
/// Both keep the 3D error energy of the substitution (eq. 15) within
/// `10^(−dB/10)` of the volume's energy; they differ in how tightly they
/// measure it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// Eq. 16 as printed: `h_d² · Σ_{|F|<τ}|F|²` with `h_d` the largest
    /// response difference anywhere in the volume's extent. Cheap (one pass
    /// over a histogram) and loose: it charges every weak sample the
    /// worst-case difference, which occurs only at the extent's corners.
    Paper,
    /// The error field of eq. 15 itself, `f₂·(g·h₂ − h₁)`, computed by one 3D
    /// inverse transform of the weak samples per candidate `τ`, and its
    /// energy summed over the whole grid. Exact for the substitution of the
    /// weak set, so the largest `τ` it accepts is the largest the 3D energy
    /// criterion allows; it costs 3–4 FFT-based 3D transforms once per
    /// volume (one for the reference, then the search of
    /// `ErrorModel::threshold`).
    Exact,
}

impl Bound {
    /// Parse `paper` or `exact`.
    pub fn from_name(s: &str) -> Result<Self, String> {
        match s.trim() {
            "paper" => Ok(Self::Paper),
            "exact" => Ok(Self::Exact),
            other => Err(format!(
                "unknown adaptive bound `{other}`: use `exact` (the error field of eq. 15) or \
                 `paper` (eq. 16 with the worst-case response difference)"
            )),
        }
    }

    /// The name `from_name` accepts.
    pub fn name(self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::Exact => "exact",
        }
    }
}

/// The spectrum and grid the exact bound works on: the stored samples in
/// f32 and the large filter's response per signed grid index.
struct ErrorModel {
    n: usize,
    values: Vec<f32>,
    large_response: Vec<f64>,
    /// `Σ (f·h₁)²` over the grid: the energy the tolerance is relative to,
    /// in the same (unnormalized) units as the error energies.
    reference: f64,
    /// `Σ F²` of the samples in each ⅛-octave magnitude bin `b`
    /// (`2^((b−1)/8) ≤ |F| < 2^(b/8)`), from bin `lowest` up.
    bins: Vec<f64>,
    /// The bin of `bins[0]`.
    lowest: i64,
    /// `values[i]` is the spectrum's `value(i)` exactly (no block
    /// exponents, a format f32 holds), so the marks may test it.
    exact: bool,
    work: Vec<f32>,
    /// The inverse transform of every sample (the reference's field), kept
    /// when memory allows: the weak samples' field is then this minus the
    /// strong samples' ([`ErrorModel::probe`]).
    full: Option<Vec<f32>>,
    /// The largest `|F|` in each z-plane, and in each row `y` over all
    /// planes: the strong samples of a threshold lie on the planes and rows
    /// that reach it.
    plane_max: Vec<f32>,
    row_max: Vec<f32>,
}

impl ErrorModel {
    fn new<S: Sample>(view: &Spectrum<'_, S>) -> Result<Self, String> {
        let n = view.n();
        let cells = (n as u64).pow(3);
        crate::budget::Budget::new()
            .hold("adaptive samples and error field (f32)", 2 * cells, 4)
            .hold(
                "adaptive transform half spectrum",
                half_spectrum_bytes::<f32>(n),
                1,
            )
            .check(crate::budget::limit(), "use --adaptive-bound paper")
            .map_err(|e| e.to_string())?;
        let large = *view.filter();
        let mut values = vec![0f32; n * n * n];
        let (data, plain) = (view.data(), view.blocks().is_none());
        values
            .par_chunks_mut(n * n)
            .enumerate()
            .for_each(|(z, plane)| match plain {
                // Without block exponents a value is its stored sample.
                true => {
                    for (v, d) in plane.iter_mut().zip(&data[z * n * n..]) {
                        *v = d.to_f32();
                    }
                }
                false => {
                    for (i, v) in plane.iter_mut().enumerate() {
                        *v = view.value(z * n * n + i) as f32;
                    }
                }
            });
        let (bins, lowest) = magnitude_bins(&values);
        let (plane_max, row_max) = extents(&values, n);
        let large_response = Self::responses(&large, n);
        let mut model = Self {
            n,
            values,
            large_response,
            reference: 0.0,
            bins,
            lowest,
            exact: plain && (S::BITS <= 16 || S::NAME == "f32"),
            work: vec![0.0; n * n * n],
            full: None,
            plane_max,
            row_max,
        };
        let large = model.large_response.clone();
        let weight = Weight {
            gain: 0.0,
            small: &large,
            large: &large,
        };
        model.reference = model.field_energy(f64::INFINITY, &weight)?;
        // A third cube for the full field, if the budget allows it.
        let room = crate::budget::Budget::new()
            .hold("adaptive samples and fields (f32)", 3 * cells, 4)
            .hold(
                "adaptive transform half spectrum",
                half_spectrum_bytes::<f32>(n),
                1,
            )
            .check(crate::budget::limit(), "")
            .is_ok();
        if room {
            model.full = Some(std::mem::replace(&mut model.work, vec![0.0; n * n * n]));
        }
        Ok(model)
    }

    /// The error energy of the samples below `tau` with `weight`:
    /// [`ErrorModel::field_energy`], or, when the strong samples
    /// (`|F| ≥ tau`) lie on at most ¾ of the rows `(y, z)` and the
    /// budget is not below [`SUBTRACTION_BUDGET`], the full field minus the
    /// strong samples' field. The transform then skips the rows and planes
    /// without strong samples (its first two passes), and the weak field is
    /// the same up to f32 rounding relative to the whole field's energy.
    fn probe(&mut self, tau: f64, weight: &Weight<'_>, budget: f64) -> Result<f64, String> {
        let n = self.n;
        let t = tau as f32;
        let planes: Vec<bool> = self.plane_max.iter().map(|&m| m >= t).collect();
        let rows: Vec<bool> = self.row_max.iter().map(|&m| m >= t).collect();
        let occupied = planes.iter().filter(|&&p| p).count() * rows.iter().filter(|&&r| r).count();
        let full = match &self.full {
            Some(full) if budget >= SUBTRACTION_BUDGET && 4 * occupied <= 3 * n * n => full,
            _ => return self.field_energy(tau, weight),
        };
        let values = &self.values;
        let fill = move |y: usize, z: usize, line: &mut [f32]| {
            let row = &values[(z * n + y) * n..][..n];
            for (w, &v) in line.iter_mut().zip(row) {
                *w = if v.abs() < t { 0.0 } else { v };
            }
        };
        let cube = SparseCube {
            n,
            rows_y: &rows,
            planes_z: &planes,
            fill: &fill,
        };
        dht_3d_real::<f32, f32>(&cube, &mut self.work).map_err(|e| e.to_string())?;
        Ok(weight.energy(full, Some(&self.work), n))
    }

    /// `ĥ(x/n)` for each grid index `x` in natural order (signed position).
    fn responses(filter: &Filter, n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| filter.response(signed_index(k, n) as f64 / n as f64))
            .collect()
    }

    /// `Σ_x (f_τ(x)·weight(x))²`, `f_τ` the inverse transform of the
    /// samples below `tau` (unnormalized: the transform is its own inverse
    /// up to `n³`, and every energy here carries the same factor), through
    /// the host's FFT-based transform on all cores.
    fn field_energy(&mut self, tau: f64, weight: &Weight<'_>) -> Result<f64, String> {
        let n = self.n;
        let tau = tau as f32;
        let (values, all) = (&self.values, vec![true; n]);
        let fill = move |y: usize, z: usize, line: &mut [f32]| {
            let row = &values[(z * n + y) * n..][..n];
            for (w, &v) in line.iter_mut().zip(row) {
                *w = if v.abs() < tau { v } else { 0.0 };
            }
        };
        let cube = SparseCube {
            n,
            rows_y: &all,
            planes_z: &all,
            fill: &fill,
        };
        dht_3d_real::<f32, f32>(&cube, &mut self.work).map_err(|e| e.to_string())?;
        Ok(weight.energy(&self.work, None, n))
    }

    /// The error energy of threshold bin `b` as if the weight were its mean
    /// square everywhere (Parseval: `n³·mean(w²)·Σ_{|F|<τ} F²`): exact for
    /// a constant weight, and a guide for where to start the exact search.
    fn estimate(&self, b: i64, mean_square_weight: f64) -> f64 {
        // Bins `k ≤ b` hold the samples below `2^(b/8)`.
        let below = (b - self.lowest + 1).clamp(0, self.bins.len() as i64) as usize;
        let sum: f64 = self.bins[..below].iter().sum();
        (self.n as f64).powi(3) * mean_square_weight * sum
    }

    /// The largest candidate threshold whose error energy for the pair
    /// (large, `small` with gain `gain`) stays within `budget` of the
    /// reference, and the relative energy it was verified at. Candidates are
    /// ⅛-octave steps `2^(b/8)`, and the answer is bracketed between an
    /// accepted step and a refused one (at first the empty weak set, which
    /// has no error, and "no limit"). Each probe is one exact evaluation of
    /// the error field. The first three probes go where the Parseval
    /// estimate ([`ErrorModel::estimate`]) puts the answer, rescaled by the
    /// ratio of exact to estimated energy at the last probe (the weight is
    /// far from constant, so the raw estimate is off by octaves, but the
    /// ratio varies slowly with `τ`); the rest bisect. It returns only
    /// thresholds it evaluated.
    fn threshold(
        &mut self,
        small: &Filter,
        gain: f64,
        budget: f64,
    ) -> Result<(f64, f64, usize), String> {
        let n = self.n;
        let hs = Self::responses(small, n);
        let hl = self.large_response.clone();
        let weight = Weight {
            gain,
            small: &hs,
            large: &hl,
        };
        if self.bins.is_empty() || self.reference <= 0.0 {
            return Ok((0.0, 0.0, 0));
        }
        // mean(w²) of the separable weight, from per-axis sums of products.
        let axis_mean = |f: &dyn Fn(usize) -> f64| (0..n).map(f).sum::<f64>() / n as f64;
        let mean_square = gain * gain * axis_mean(&|i| hs[i] * hs[i]).powi(3)
            - 2.0 * gain * axis_mean(&|i| hs[i] * hl[i]).powi(3)
            + axis_mean(&|i| hl[i] * hl[i]).powi(3);
        let tau_of = |b: i64| 2f64.powf(b as f64 / 8.0);
        let allowed = budget * self.reference;
        // Below step `lowest` no sample is weak: the empty set, accepted.
        let mut good: (i64, Option<f64>) = (self.lowest - 1, None);
        // From `top` on every sample is weak: no larger threshold changes the set.
        let top = self.lowest + self.bins.len() as i64 - 1;
        let mut bad = top + 1;
        let mut scale = 1.0;
        let mut probes = 0;
        while bad - good.0 > 1 {
            let b = if probes < 3 {
                (good.0 + 1..bad)
                    .rev()
                    .find(|&b| scale * self.estimate(b, mean_square) <= allowed)
                    .unwrap_or(good.0 + 1)
            } else {
                good.0 + (bad - good.0) / 2
            };
            let e = self.probe(tau_of(b), &weight, budget)?;
            probes += 1;
            let estimate = self.estimate(b, mean_square);
            if estimate > 0.0 && e > 0.0 {
                scale = e / estimate;
            }
            if e <= allowed {
                good = (b, Some(e / self.reference));
            } else {
                bad = b;
            }
        }
        Ok(match good.1 {
            Some(r) => (tau_of(good.0), r, probes),
            None => (0.0, 0.0, probes),
        })
    }
}

/// The weight of eq. 15, `w(x) = g·ĥ₂(x)ĥ₂(y)ĥ₂(z) − ĥ₁(x)ĥ₁(y)ĥ₁(z)`,
/// from the responses per grid index (`g = 0` gives `−ĥ₁`, the reference's
/// weight up to sign).
struct Weight<'a> {
    gain: f64,
    small: &'a [f64],
    large: &'a [f64],
}

impl Weight<'_> {
    /// `Σ_x ((field(x) − minus(x))·w(x))²` over the cube of side `n` (x
    /// fastest; `minus` zero if `None`), on all cores: per row,
    /// `w = a·ĥ₂(x) − b·ĥ₁(x)` with `a = g·ĥ₂(y)ĥ₂(z)` and `b = ĥ₁(y)ĥ₁(z)`,
    /// summed in f64 in four interleaved lanes.
    fn energy(&self, field: &[f32], minus: Option<&[f32]>, n: usize) -> f64 {
        let plane = n * n;
        field
            .par_chunks(plane)
            .enumerate()
            .map(|(z, f)| match minus {
                Some(m) => self.plane_energy(z, n, |i| f[i] - m[z * plane + i]),
                None => self.plane_energy(z, n, |i| f[i]),
            })
            .sum()
    }

    /// The energy of plane `z`, its values `value(i)` (`i = x + n·y`).
    #[inline(always)]
    fn plane_energy(&self, z: usize, n: usize, value: impl Fn(usize) -> f32) -> f64 {
        let (hs, hl) = (self.small, self.large);
        let mut energy = 0.0f64;
        for y in 0..n {
            let (a, b) = (self.gain * hs[y] * hs[z], hl[y] * hl[z]);
            let mut lanes = [0.0f64; 4];
            for x in 0..n {
                let e = value(x + n * y) as f64 * (a * hs[x] - b * hl[x]);
                lanes[x % 4] += e * e;
            }
            energy += (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
        }
        energy
    }
}

/// The smallest per-level budget (energy relative to the volume's) for which
/// [`ErrorModel::probe`] subtracts fields: f32 rounding of the full field is
/// about `10^-14` of its energy, far below.
const SUBTRACTION_BUDGET: f64 = 1e-9;

/// The largest `|v|` of each z-plane, and of each row `y` over all planes,
/// of the cube of side `n`.
fn extents(values: &[f32], n: usize) -> (Vec<f32>, Vec<f32>) {
    let per_plane: Vec<(f32, Vec<f32>)> = values
        .par_chunks(n * n)
        .map(|plane| {
            let rows: Vec<f32> = plane
                .chunks_exact(n)
                .map(|row| row.iter().fold(0.0f32, |m, v| m.max(v.abs())))
                .collect();
            (rows.iter().fold(0.0f32, |m, &v| m.max(v)), rows)
        })
        .collect();
    let planes = per_plane.iter().map(|p| p.0).collect();
    let rows = (0..n)
        .map(|y| per_plane.iter().fold(0.0f32, |m, p| m.max(p.1[y])))
        .collect();
    (planes, rows)
}

/// `2^(j/8)` for `j = 1 … 7` in f32: a mantissa in `[1, 2)` is in eighth
/// `j` when it reaches the `j`-th entry (the estimate only guides the
/// search, so the last bit of these does not matter).
const EIGHTH_OCTAVES: [f32; 7] = [
    1.090_507_8,
    1.189_207_1,
    1.296_839_6,
    core::f32::consts::SQRT_2,
    1.542_210_8,
    1.681_792_9,
    1.834_008_1,
];

/// `Σ F²` per ⅛-octave magnitude bin (`2^((b−1)/8) ≤ |F| < 2^(b/8)` in bin
/// `b`), from the lowest occupied bin, and that bin; zeros are left out
/// (they add nothing to any energy).
fn magnitude_bins(values: &[f32]) -> (Vec<f64>, i64) {
    let bin = |v: f32| {
        // ⌊8·log₂|v|⌋ + 1 from the exponent and mantissa bits (normal
        // numbers; subnormals through log₂).
        let bits = v.abs().to_bits();
        let exponent = (bits >> 23) as i64;
        if exponent == 0 {
            return ((v.abs() as f64).log2() * 8.0).floor() as i64 + 1;
        }
        let mantissa = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
        let eighths = EIGHTH_OCTAVES.iter().filter(|t| mantissa >= **t).count() as i64;
        8 * (exponent - 127) + eighths + 1
    };
    // Every bin an f32 can fall in (subnormals down to 2^−149), in one pass.
    const FIRST: i64 = -8 * 150;
    const BINS: usize = 8 * 280;
    let all = values
        .par_chunks(1 << 16)
        .fold(
            || vec![0f64; BINS],
            |mut acc, chunk| {
                for &v in chunk.iter().filter(|v| **v != 0.0) {
                    acc[(bin(v) - FIRST) as usize] += v as f64 * v as f64;
                }
                acc
            },
        )
        .reduce(
            || vec![0f64; BINS],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    *x += y;
                }
                a
            },
        );
    // A nonzero f32 squared is a positive f64: occupied bins are positive.
    let (lo, hi) = match (
        all.iter().position(|&e| e > 0.0),
        all.iter().rposition(|&e| e > 0.0),
    ) {
        (Some(lo), Some(hi)) => (lo, hi),
        _ => return (Vec::new(), 0),
    };
    let bins = all[lo..=hi].to_vec();
    let lo = lo as i64 + FIRST;
    (bins, lo)
}

/// What the user asked of adaptive filtering.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptiveSettings {
    /// Tolerance in dB: the substitution's error energy stays
    /// `10^(−dB/10)` below the volume's.
    pub tolerance_db: f64,
    /// The cheaper filters, cheapest first ([`parse_chain`]).
    pub chain: Vec<FilterKind>,
    /// With [`Bound::Paper`], an `h_d` to use instead of the filter pair's
    /// own (the paper used 0.3; a smaller value than the pair's voids the
    /// bound).
    pub h_d: Option<f64>,
    /// How the thresholds are derived.
    pub bound: Bound,
    /// A view whose marks would move less than this share of its slice
    /// samples (0 to 1) to the cheaper filters is rendered by the plain
    /// walk with the full filter instead, which is then faster
    /// ([`DEFAULT_PLAIN_BELOW`]; 0 always walks adaptively).
    pub plain_below: f64,
}

/// The share of substituted samples below which the plain walk is faster
/// than the adaptive one (`cargo bench -p fvr-host --bench adaptive --
/// breakeven`; see docs/adaptive.md).
pub const DEFAULT_PLAIN_BELOW: f64 = 0.5;

/// Parse a share in percent (0 to 100) into a fraction.
pub fn parse_percent(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if (0.0..=100.0).contains(&v) => Ok(v / 100.0),
        _ => Err(format!("expected a percentage from 0 to 100, got `{s}`")),
    }
}

impl AdaptiveSettings {
    /// `tolerance_db` with the 1³ filter and the exact bound: the defaults
    /// of `fvr render --adaptive`.
    pub fn new(tolerance_db: f64) -> Self {
        Self {
            tolerance_db,
            chain: vec![FilterKind::Nearest],
            h_d: None,
            bound: Bound::Exact,
            plain_below: DEFAULT_PLAIN_BELOW,
        }
    }
}

/// One cheaper filter with its marks.
#[derive(Clone, Debug)]
pub struct Level {
    /// The filter.
    pub filter: Filter,
    /// `h_d = max|g·ĥ_small/ĥ_large − 1|` over the volume.
    pub h_d: f64,
    /// The magnitude threshold from eq. 16.
    pub threshold: f64,
    /// The marks' words.
    pub words: Vec<u32>,
    /// Samples marked.
    pub marked: usize,
    /// DC gain correction `ĥ_large(0)/ĥ_small(0)`.
    pub gain: f64,
    /// With [`Bound::Exact`]: the 3D error energy of this level's
    /// substitution relative to the volume's, as verified for `threshold`.
    pub error_ratio: Option<f64>,
    /// With [`Bound::Exact`]: the 3D inverse transforms the threshold
    /// search ran for this level (the reference's not counted).
    pub probes: Option<usize>,
}

/// Marks for adaptive filtering of one spectrum.
#[derive(Clone, Debug)]
pub struct AdaptiveMarks {
    /// The tolerance asked for, dB.
    pub tolerance_db: f64,
    /// How the thresholds were derived.
    pub bound: Bound,
    /// The cheaper filters, cheapest first.
    pub levels: Vec<Level>,
    /// [`AdaptiveSettings::plain_below`]: views whose marks would move a
    /// smaller share of their samples to the cheaper filters are walked
    /// plainly with the full filter.
    pub plain_below: f64,
    n: usize,
}

impl AdaptiveMarks {
    /// Mark `spec` as `settings` ask: for each cheaper filter of the chain
    /// (cheapest first), the largest magnitude threshold that `settings.bound`
    /// accepts. The energy budget `10^(−dB/10)` is split evenly in amplitude
    /// between the levels, so their errors, added, stay within it.
    ///
    /// # Errors
    /// A tolerance that is not a positive number, a chain too long or with a
    /// filter no cheaper than the spectrum's, `h_d` given with the exact
    /// bound, or a filter whose response vanishes inside the volume.
    pub fn build<S: Sample>(
        spec: &OwnedSpectrum<S>,
        settings: &AdaptiveSettings,
    ) -> Result<Self, String> {
        Self::build_for(&spec.view(), settings)
    }

    /// [`AdaptiveMarks::build`] for any core spectrum (every storage
    /// format, block exponents included).
    ///
    /// # Errors
    /// As [`AdaptiveMarks::build`].
    pub fn build_for<S: Sample>(
        view: &Spectrum<'_, S>,
        settings: &AdaptiveSettings,
    ) -> Result<Self, String> {
        let AdaptiveSettings {
            tolerance_db,
            ref chain,
            h_d: h_d_override,
            bound,
            plain_below,
        } = *settings;
        parse_tolerance(&tolerance_db.to_string())?;
        if !(0.0..=1.0).contains(&plain_below) {
            return Err(format!(
                "the share below which views walk plainly is 0 to 1, got {plain_below}"
            ));
        }
        if bound == Bound::Exact && h_d_override.is_some() {
            return Err(
                "--adaptive-hd sets the h_d of the paper's bound; the exact bound measures the \
                 error field instead: use --adaptive-bound paper with it"
                    .into(),
            );
        }
        if chain.is_empty() || chain.len() > MAX_LEVELS {
            return Err(format!(
                "an adaptive chain names 1 to {MAX_LEVELS} cheaper filters"
            ));
        }
        let n = view.n();
        let large = *view.filter();
        let total = n * n * n;
        let budget = 10f64.powf(-tolerance_db / 10.0) / (chain.len() * chain.len()) as f64;
        let radius = large.width().div_ceil(2);
        let mut levels = Vec::with_capacity(chain.len());
        let mut model = match bound {
            Bound::Exact => Some(ErrorModel::new(view)?),
            Bound::Paper => None,
        };
        for &kind in chain.iter() {
            let small = Filter::new(kind, large.oversample()).map_err(|e| e.to_string())?;
            if small.width() >= large.width() {
                return Err(format!(
                    "adaptive filter {} is not cheaper than the spectrum's {}",
                    kind.name(),
                    large.kind().name()
                ));
            }
            let h_d = match h_d_override {
                Some(h) if h.is_finite() && h > 0.0 => h,
                Some(h) => return Err(format!("h_d must be a positive number, got {h}")),
                None => response_difference(&large, &small, view.dims(), n)
                    .map_err(|e| e.to_string())?,
            };
            let gain = large.response(0.0) / small.response(0.0);
            let (threshold, error_ratio, probes) = match model.as_mut() {
                Some(model) => {
                    let (tau, ratio, probes) = model.threshold(&small, gain, budget)?;
                    (tau, Some(ratio), Some(probes))
                }
                None => (
                    threshold_for(total, |i| view.value(i), h_d, budget),
                    None,
                    None,
                ),
            };
            let mut words = vec![0u32; marks_words(n)];
            let exact = model.as_ref().filter(|m| m.exact).map(|m| &m.values[..]);
            let marked = match exact {
                Some(values) => {
                    fast_marks::mark(n, |i| values[i] as f64, threshold, radius, &mut words)
                }
                None => fast_marks::mark(n, |i| view.value(i), threshold, radius, &mut words),
            }
            .map_err(|e| e.to_string())?;
            levels.push(Level {
                filter: small,
                h_d,
                threshold,
                words,
                marked,
                gain,
                error_ratio,
                probes,
            });
        }
        Ok(Self {
            tolerance_db,
            bound,
            levels,
            plain_below,
            n,
        })
    }

    /// Side of the spectrum the marks were built for.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Bytes of marks held (1 bit per voxel per level).
    pub fn bytes(&self) -> usize {
        self.levels.iter().map(|l| l.words.len() * 4).sum()
    }

    /// Render one view adaptively; returns the image (f64) and statistics.
    /// For many views, keep an [`AdaptiveRenderer`] instead.
    ///
    /// # Errors
    /// As [`fvr_core::render::render`].
    pub fn render<S: Sample, T: Real>(
        &self,
        spec: &OwnedSpectrum<S>,
        view: &View,
        width: usize,
        height: usize,
    ) -> Result<(Vec<f64>, AdaptiveStats), fvr_core::Error> {
        let mut out = vec![T::ZERO; width * height];
        let stats = AdaptiveRenderer::<T>::new(self, spec)?
            .render_into(spec, view, width, height, &mut out)?;
        Ok((out.into_iter().map(T::to_f64).collect(), stats))
    }

    /// A sentence on how a view was walked and whether adaptivity had any
    /// effect in its `stats`.
    pub fn note(&self, stats: &AdaptiveStats, walked: Walked) -> Option<String> {
        match walked {
            Walked::Plain { share } => Some(format!(
                "the marks allow {:.1}% of this view's samples on the cheaper filters, below \
                 the {:.1}% at which the adaptive walk pays: 0.0% of samples substituted, plain \
                 walk used (the full filter's image)",
                100.0 * share,
                100.0 * self.plain_below
            )),
            Walked::Adaptive => self.effect(stats),
        }
    }

    /// A sentence on whether adaptivity had any effect in `stats`.
    pub fn effect(&self, stats: &AdaptiveStats) -> Option<String> {
        let cheap: u64 = stats.per_filter[1..].iter().sum();
        if self.levels.iter().all(|l| l.marked == 0) {
            Some(format!(
                "no sample is weak enough for a {} dB tolerance: adaptivity has no effect \
                 (every sample uses the full filter)",
                self.tolerance_db
            ))
        } else if cheap == 0 {
            Some("no slice sample fell on marked spectrum samples: adaptivity had no effect on this view".into())
        } else if stats.per_filter[0] == 0 {
            Some(format!(
                "every slice sample used a cheaper filter: a {} dB tolerance is so loose that the \
                 full filter is never needed",
                self.tolerance_db
            ))
        } else {
            None
        }
    }
}
