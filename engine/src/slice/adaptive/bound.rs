//! The exact bound of adaptive filtering ([`super::Bound::Exact`]): the
//! error field of eq. 15 evaluated by 3D inverse transforms, and the search
//! for the largest threshold it accepts.

use crate::dht::real_fft::{dht_3d_real, half_spectrum_bytes, SparseCube};
use crate::spectrum::prepare::PreparedEnergy;
use fvr_core::dht::signed_index;
use fvr_core::filter::Filter;
use fvr_core::num::Sample;
use fvr_core::spectrum::Spectrum;
use rayon::prelude::*;

/// What a model is built for: [`Probes::None`], Parseval's bound alone
/// (no field held); [`Probes::Few`], Parseval's bound raised by a few
/// probes (one field held, the reference from the preparation when
/// known); [`Probes::Search`], the exact bound's search (the reference
/// transformed, and its field kept when memory allows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Probes {
    None,
    Few,
    Search,
}

/// A threshold and what backs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Found {
    /// The magnitude threshold.
    pub(super) tau: f64,
    /// The error energy relative to the reference: evaluated, or, when not
    /// `evaluated`, Parseval's bound on it.
    pub(super) ratio: f64,
    /// The probe transforms run.
    pub(super) probes: usize,
    /// Whether `ratio` was evaluated.
    pub(super) evaluated: bool,
}

/// The spectrum and grid the exact bound works on: the stored samples in
/// f32 and the large filter's response per signed grid index.
pub(super) struct ErrorModel {
    n: usize,
    pub(super) values: Vec<f32>,
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
    pub(super) exact: bool,
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
    /// The model of `view`'s samples. With `prepared` (the FFT
    /// preparation's energy, for the spectrum `view` shows) and no exact
    /// `probes` to come, the reference is [`reference_floor`] and no field
    /// is transformed or held; otherwise the reference is the field's
    /// energy, through one 3D inverse transform.
    pub(super) fn new<S: Sample>(
        view: &Spectrum<'_, S>,
        prepared: Option<&PreparedEnergy>,
        probes: Probes,
    ) -> Result<Self, String> {
        let n = view.n();
        let cells = (n as u64).pow(3);
        let fields = |cubes: u64| {
            let mut budget = crate::memory::Budget::new();
            budget.hold("adaptive samples and fields (f32)", cubes * cells, 4);
            if cubes > 1 {
                budget.hold(
                    "adaptive transform half spectrum",
                    half_spectrum_bytes::<f32>(n),
                    1,
                );
            }
            budget
        };
        let floor_only = prepared.is_some() && probes != Probes::Search;
        fields(if floor_only { 1 } else { 2 })
            .check(crate::memory::limit(), "use --adaptive-bound paper")
            .map_err(|e| e.to_string())?;
        let large = *view.filter();
        let mut values = vec![0f32; n * n * n];
        let Scan {
            bins,
            lowest,
            plane_max,
            row_max,
        } = scan(view, &mut values);
        let plain = view.blocks().is_none();
        let large_response = Self::responses(&large, n);
        let mut model = Self {
            n,
            values,
            large_response,
            reference: 0.0,
            bins,
            lowest,
            exact: plain && (S::BITS <= 16 || S::NAME == "f32"),
            work: Vec::new(),
            full: None,
            plane_max,
            row_max,
        };
        let stored: f64 = model.bins.iter().sum();
        let peak = model
            .large_response
            .iter()
            .fold(0.0f64, |m, h| m.max(h.abs()))
            .powi(3);
        let floor = prepared
            .filter(|_| plain)
            .and_then(|p| reference_floor(p, n, stored, peak));
        if let (true, Some(floor)) = (floor_only, floor) {
            model.reference = floor;
            // Room for the probes' field, if the budget allows it; else
            // Parseval's bound stands alone.
            if probes == Probes::Few && fields(2).check(crate::memory::limit(), "").is_ok() {
                model.work = vec![0.0; n * n * n];
            }
            return Ok(model);
        }
        fields(2)
            .check(crate::memory::limit(), "use --adaptive-bound paper")
            .map_err(|e| e.to_string())?;
        model.work = vec![0.0; n * n * n];
        let large = model.large_response.clone();
        let weight = Weight {
            gain: 0.0,
            small: &large,
            large: &large,
        };
        model.reference = model.field_energy(f64::INFINITY, &weight)?;
        // A third cube for the full field, if the budget allows it.
        if fields(3).check(crate::memory::limit(), "").is_ok() {
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

    /// The largest ⅛-octave step whose error energy for `weight` Parseval's
    /// theorem with the weight's largest square, `(|g|·max|ĥ₂|³ +
    /// max|ĥ₁|³)²` (exact for the zero filter), bounds within `allowed`
    /// (unnormalized), with that bound; the bin above is summed, as a
    /// sample on a bin's edge may be binned one up ([`bin`]).
    fn peak_bin(&self, weight: &Weight<'_>, allowed: f64) -> Option<(i64, f64)> {
        let max_square = weight.peak_square();
        let top = self.lowest + self.bins.len() as i64 - 1;
        (self.lowest..=top)
            .rev()
            .map(|b| (b, self.estimate(b + 1, max_square)))
            .find(|&(_, e)| e <= allowed)
    }

    /// [`super::Bound::Parseval`]: the threshold [`ErrorModel::peak_bin`]
    /// accepts for the pair (large, `small` with gain `gain`) within
    /// `budget`, and the bound on its relative error energy; `(0, 0)` when
    /// no step is accepted.
    pub(super) fn peak_threshold(&self, small: &Filter, gain: f64, budget: f64) -> (f64, f64) {
        let hs = Self::responses(small, self.n);
        let weight = Weight {
            gain,
            small: &hs,
            large: &self.large_response,
        };
        if self.bins.is_empty() || self.reference <= 0.0 {
            return (0.0, 0.0);
        }
        match self.peak_bin(&weight, budget * self.reference) {
            Some((b, e)) => (2f64.powf(b as f64 / 8.0), e / self.reference),
            None => (0.0, 0.0),
        }
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
    /// ratio varies slowly with `τ`); the rest bisect. The search starts
    /// from the largest step that Parseval's bound with the weight's peak
    /// accepts without a probe; the energy it returns is always evaluated.
    ///
    /// With a `limit` on the probes ([`ErrorModel::raised`]), the search
    /// stops after that many, and a seed never beaten keeps Parseval's
    /// bound on its energy instead of an evaluation.
    pub(super) fn threshold(
        &mut self,
        small: &Filter,
        gain: f64,
        budget: f64,
        limit: Option<usize>,
    ) -> Result<Found, String> {
        let n = self.n;
        let hs = Self::responses(small, n);
        let hl = self.large_response.clone();
        let weight = Weight {
            gain,
            small: &hs,
            large: &hl,
        };
        if self.bins.is_empty() || self.reference <= 0.0 {
            return Ok(Found {
                tau: 0.0,
                ratio: 0.0,
                probes: 0,
                evaluated: limit.is_none(),
            });
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
        // Accepted without a probe.
        let seed = self.peak_bin(&weight, allowed);
        if let Some((b, _)) = seed {
            good = (b, None);
        }
        // Limited, the first probe takes its scale from the every-sample-
        // weak error energy, which for the zero filter (w = −ĥ₁) is the
        // reference itself: a guess at where the first probe lands, no
        // part of the guarantee. The full search starts from the raw
        // estimate.
        let mut scale = match limit {
            Some(_) => self.reference / self.estimate(top, mean_square).max(f64::MIN_POSITIVE),
            None => 1.0,
        };
        let mut probes = 0;
        while bad - good.0 > 1 && limit.is_none_or(|l| probes < l) {
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
        let found = |tau: f64, ratio: f64, probes: usize, evaluated: bool| Found {
            tau,
            ratio,
            probes,
            evaluated,
        };
        Ok(match (good.1, seed) {
            (Some(r), _) => found(tau_of(good.0), r, probes, true),
            // The seed, never beaten: Parseval's bound on its energy when
            // the probes are limited, else its energy, evaluated once.
            (None, Some((b, e))) if limit.is_some() => {
                found(tau_of(b), e / self.reference, probes, false)
            }
            (None, Some(_)) => {
                let e = self.probe(tau_of(good.0), &weight, budget)?;
                found(tau_of(good.0), e / self.reference, probes + 1, true)
            }
            (None, None) => found(0.0, 0.0, probes, limit.is_none()),
        })
    }

    /// [`super::Bound::Parseval`] raised by at most `probes` evaluations
    /// of the error field above Parseval's threshold ([`ErrorModel::threshold`]
    /// with a limit), when the model holds room for a field; else
    /// [`ErrorModel::peak_threshold`].
    pub(super) fn raised(
        &mut self,
        small: &Filter,
        gain: f64,
        budget: f64,
        probes: usize,
    ) -> Result<Found, String> {
        if probes == 0 || self.work.len() != self.n * self.n * self.n {
            let (tau, ratio) = self.peak_threshold(small, gain, budget);
            return Ok(Found {
                tau,
                ratio,
                probes: 0,
                evaluated: false,
            });
        }
        self.threshold(small, gain, budget, Some(probes))
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
    /// `(|g|·max|ĥ₂|³ + max|ĥ₁|³)²`: at least `w(x)²` everywhere.
    fn peak_square(&self) -> f64 {
        let peak = |h: &[f64]| h.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        (self.gain.abs() * peak(self.small).powi(3) + peak(self.large).powi(3)).powi(2)
    }

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

/// A lower bound on the reference `Σ_x (DHT(F)(x)·ĥ(x))²` of a spectrum
/// whose preparation measured `p`, from `stored = Σ F²` of its samples and
/// `peak = max|ĥ(x)ĥ(y)ĥ(z)|`; `None` when the roundings could reach it.
///
/// With `N = n³`, `F_e = DHT(g)` the exact transform of the premultiplied
/// cube, `F_c` the computed one and `F` the stored one:
/// `‖DHT(F_e)·ĥ‖ = N‖g·ĥ‖ ≥ N·√scaled·(1 − input)`, and
/// `‖DHT(F − F_e)·ĥ‖ ≤ peak·√N·‖F − F_e‖` (the unnormalized DHT scales
/// norms by `√N`), where `‖F − F_c‖ ≤ (u‖F‖ + √N·a)/(1 − u)` (storage
/// roundoff `u`, subnormal floor `a`) and
/// `‖F_c − F_e‖ ≤ κ(‖F‖ + ‖F − F_c‖)/(1 − κ)` (transform bound `κ`).
pub(super) fn reference_floor(p: &PreparedEnergy, n: usize, stored: f64, peak: f64) -> Option<f64> {
    let cells = (n as f64).powi(3);
    let norm = stored.sqrt();
    let storage = (p.storage * norm + cells.sqrt() * p.floor) / (1.0 - p.storage);
    let transform = p.transform * (norm + storage) / (1.0 - p.transform);
    let exact = cells * p.scaled.sqrt() * (1.0 - p.input);
    let lower = exact - peak * cells.sqrt() * (storage + transform);
    (lower.is_finite() && lower > 0.0).then_some(lower * lower)
}

/// The smallest per-level budget (energy relative to the volume's) for which
/// [`ErrorModel::probe`] subtracts fields: f32 rounding of the full field is
/// about `10^-14` of its energy, far below.
const SUBTRACTION_BUDGET: f64 = 1e-9;

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

/// What one pass over the samples gathers ([`scan`]).
struct Scan {
    /// `Σ F²` per ⅛-octave magnitude bin (`2^((b−1)/8) ≤ |F| < 2^(b/8)` in
    /// bin `b`), from the lowest occupied bin; zeros are left out (they
    /// add nothing to any energy).
    bins: Vec<f64>,
    /// The bin of `bins[0]`.
    lowest: i64,
    /// The largest `|F|` of each z-plane.
    plane_max: Vec<f32>,
    /// The largest `|F|` of each row `y`, over all planes.
    row_max: Vec<f32>,
}

/// Every bin an f32 can fall in (subnormals down to 2^−149): bin `FIRST`
/// first.
const FIRST: i64 = -8 * 150;
const BINS: usize = 8 * 280;

/// The ⅛-octave bin of a nonzero `v`: `⌊8·log₂|v|⌋ + 1`, from the exponent
/// and mantissa bits for normal numbers (the mantissa compared with
/// [`EIGHTH_OCTAVES`] as integers: the same order as the floats), through
/// `log₂` for subnormals.
#[inline(always)]
fn bin(v: f32) -> i64 {
    let bits = v.abs().to_bits();
    let exponent = (bits >> 23) as i64;
    if exponent == 0 {
        return ((v.abs() as f64).log2() * 8.0).floor() as i64 + 1;
    }
    let mantissa = bits & 0x007f_ffff;
    let eighths: u32 = EIGHTH_OCTAVES
        .iter()
        .map(|t| u32::from(mantissa >= (t.to_bits() & 0x007f_ffff)))
        .sum();
    8 * (exponent - 127) + eighths as i64 + 1
}

/// `Σ F²` per bin ([`bin`]) of samples with 16-bit patterns
/// ([`Sample::pattern16`]), from a count of each pattern on all cores: each
/// value squared once, times its count (exact in f64), then summed.
fn pattern_bins<S: Sample>(data: &[S]) -> Vec<f64> {
    const PATTERNS: usize = 1 << 16;
    let counts = data
        .par_chunks(1 << 16)
        .fold(
            || vec![0u64; PATTERNS],
            |mut counts, chunk| {
                for d in chunk {
                    counts[usize::from(d.pattern16().unwrap_or(0))] += 1;
                }
                counts
            },
        )
        .reduce(
            || vec![0u64; PATTERNS],
            |mut a, b| {
                a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
                a
            },
        );
    let mut bins = vec![0f64; BINS];
    for (p, &count) in counts.iter().enumerate() {
        let v = S::from_pattern16(p as u16).map_or(0.0, |s| s.to_f32());
        if count > 0 && v != 0.0 {
            bins[(bin(v) - FIRST) as usize] += count as f64 * (v as f64 * v as f64);
        }
    }
    bins
}

/// Fill `values` with the spectrum's samples in f32, plane by plane on
/// all cores, and gather their magnitude bins and extents in the same pass.
fn scan<S: Sample>(view: &Spectrum<'_, S>, values: &mut [f32]) -> Scan {
    let n = view.n();
    let (data, plain) = (view.data(), view.blocks().is_none());
    // A 16-bit format's samples take at most 65,536 values: count them,
    // then bin each value once.
    let patterns = plain && data.first().is_some_and(|d| d.pattern16().is_some());
    let planes: Vec<(Vec<f64>, f32, Vec<f32>)> = values
        .par_chunks_mut(n * n)
        .enumerate()
        .map(|(z, plane)| {
            match plain {
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
            }
            let mut bins = vec![0f64; BINS];
            let rows: Vec<f32> = plane
                .chunks_exact(n)
                .map(|row| {
                    let mut largest = 0f32;
                    for &v in row {
                        largest = largest.max(v.abs());
                        if v != 0.0 && !patterns {
                            bins[(bin(v) - FIRST) as usize] += v as f64 * v as f64;
                        }
                    }
                    largest
                })
                .collect();
            (bins, rows.iter().fold(0f32, |m, &r| m.max(r)), rows)
        })
        .collect();
    let mut all = match patterns {
        true => pattern_bins(data),
        false => vec![0f64; BINS],
    };
    let mut row_max = vec![0f32; n];
    for (bins, _, rows) in &planes {
        for (a, b) in all.iter_mut().zip(bins) {
            *a += b;
        }
        for (m, &r) in row_max.iter_mut().zip(rows) {
            *m = m.max(r);
        }
    }
    let plane_max = planes.iter().map(|p| p.1).collect();
    // A nonzero f32 squared is a positive f64: occupied bins are positive.
    let (bins, lowest) = match (
        all.iter().position(|&e| e > 0.0),
        all.iter().rposition(|&e| e > 0.0),
    ) {
        (Some(lo), Some(hi)) => (all[lo..=hi].to_vec(), lo as i64 + FIRST),
        _ => (Vec::new(), 0),
    };
    Scan {
        bins,
        lowest,
        plane_max,
        row_max,
    }
}

#[cfg(test)]
mod tests;
