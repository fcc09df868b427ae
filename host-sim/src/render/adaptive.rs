//! Adaptive filtering on the host (paper §4): marks built once per
//! spectrum for a tolerance in dB, then views that read the cheaper filters
//! wherever the marks allow, with statistics.

use crate::render::spectrum::OwnedSpectrum;
use fvr_core::dht::signed_index;
use fvr_core::dht::{dht_3d, dht_3d_scratch_len, Twiddles};
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::View;
use fvr_core::image::{aux_len, check_image, finish, placement, Crop};
use fvr_core::num::{Real, Sample};
use fvr_core::slice::adaptive::{
    extract_slice_adaptive, mark, marks_words, response_difference, threshold_for, AdaptiveLevel,
    AdaptiveStats, Marks, MAX_LEVELS,
};
use fvr_core::spectrum::Spectrum;

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
    /// criterion allows; it costs about `log₂(bins)` 3D transforms once per
    /// volume.
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
    work: Vec<f32>,
    scratch: Vec<f32>,
    twiddles: Vec<f32>,
}

impl ErrorModel {
    fn new<S: Sample>(view: &Spectrum<'_, S>) -> Result<Self, String> {
        let n = view.n();
        let large = *view.filter();
        let values: Vec<f32> = (0..n * n * n).map(|i| view.value(i) as f32).collect();
        let large_response = Self::responses(&large, n);
        let mut model = Self {
            n,
            values,
            large_response,
            reference: 0.0,
            work: vec![0.0; n * n * n],
            scratch: vec![0.0; dht_3d_scratch_len([n; 3])],
            twiddles: vec![0.0; Twiddles::<f32>::buffer_len(n)],
        };
        let ones = model.large_response.clone();
        model.reference =
            model.field_energy(f64::INFINITY, |x| ones[x[0]] * ones[x[1]] * ones[x[2]])?;
        Ok(model)
    }

    /// `ĥ(x/n)` for each grid index `x` in natural order (signed position).
    fn responses(filter: &Filter, n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| filter.response(signed_index(k, n) as f64 / n as f64))
            .collect()
    }

    /// `Σ_x (f_τ(x)·weight(x))²`, `f_τ` the inverse transform of the
    /// samples below `tau` (unnormalized: the transform is its own inverse
    /// up to `n³`, and every energy here carries the same factor).
    fn field_energy(
        &mut self,
        tau: f64,
        weight: impl Fn([usize; 3]) -> f64,
    ) -> Result<f64, String> {
        let n = self.n;
        let tau = tau as f32;
        for (w, &v) in self.work.iter_mut().zip(&self.values) {
            *w = if v.abs() < tau { v } else { 0.0 };
        }
        let tw = Twiddles::new(&mut self.twiddles, n).map_err(|e| e.to_string())?;
        dht_3d::<f32, f32>(&mut self.work, [n; 3], &mut self.scratch, &tw)
            .map_err(|e| e.to_string())?;
        let mut energy = 0.0f64;
        for z in 0..n {
            for y in 0..n {
                let row = &self.work[(z * n + y) * n..][..n];
                let mut line = 0.0f64;
                for (x, &f) in row.iter().enumerate() {
                    let e = f as f64 * weight([x, y, z]);
                    line += e * e;
                }
                energy += line;
            }
        }
        Ok(energy)
    }

    /// The largest candidate threshold whose error energy for the pair
    /// (large, `small` with gain `gain`) stays within `budget` of the
    /// reference, and the relative energy it was verified at. Candidates are
    /// ⅛-octave steps `2^(b/8)`; the search starts at `start` (the paper's
    /// threshold, usually 1–2 octaves below the answer), gallops by whole
    /// octaves until it brackets the answer, then bisects, about 6
    /// transforms in all. It returns only thresholds it evaluated.
    fn threshold(
        &mut self,
        small: &Filter,
        gain: f64,
        budget: f64,
        start: f64,
    ) -> Result<(f64, f64), String> {
        let hs = Self::responses(small, self.n);
        let hl = self.large_response.clone();
        let weight =
            |x: [usize; 3]| gain * hs[x[0]] * hs[x[1]] * hs[x[2]] - hl[x[0]] * hl[x[1]] * hl[x[2]];
        let hi_mag = self
            .values
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs() as f64));
        if hi_mag == 0.0 || self.reference <= 0.0 {
            return Ok((0.0, 0.0));
        }
        let tau_of = |b: i64| 2f64.powf(b as f64 / 8.0);
        // Above `top` every sample is weak: no larger threshold changes the set.
        let top = (hi_mag.log2() * 8.0).ceil() as i64 + 1;
        let allowed = budget * self.reference;
        let mut probe = |b: i64| -> Result<Option<f64>, String> {
            let e = self.field_energy(tau_of(b), weight)?;
            Ok((e <= allowed).then_some(e / self.reference))
        };
        let first = if start > 0.0 {
            ((start.log2() * 8.0).round() as i64).min(top)
        } else {
            top - 8
        };
        // Invariant: `good` is accepted (`None` is the empty set, always
        // accepted), `bad` is not (`top + 1` stands for "no limit found").
        let (mut good, mut bad): ((i64, Option<f64>), i64);
        match probe(first)? {
            Some(r) => {
                good = (first, Some(r));
                bad = top + 1;
                let mut step = 8;
                while good.0 < top {
                    let b = (good.0 + step).min(top);
                    match probe(b)? {
                        Some(r) => good = (b, Some(r)),
                        None => {
                            bad = b;
                            break;
                        }
                    }
                    step *= 2;
                }
            }
            None => {
                bad = first;
                let mut step = 8;
                loop {
                    let b = first - step;
                    if b < first - 8 * 64 {
                        // 64 octaves below the paper's threshold: nothing fits.
                        good = (b, None);
                        break;
                    }
                    match probe(b)? {
                        Some(r) => {
                            good = (b, Some(r));
                            break;
                        }
                        None => bad = b,
                    }
                    step *= 2;
                }
            }
        }
        while bad - good.0 > 1 && good.1.is_some() {
            let mid = good.0 + (bad - good.0) / 2;
            match probe(mid)? {
                Some(r) => good = (mid, Some(r)),
                None => bad = mid,
            }
        }
        Ok(match good.1 {
            Some(r) => (tau_of(good.0), r),
            None => (0.0, 0.0),
        })
    }
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
        } = *settings;
        parse_tolerance(&tolerance_db.to_string())?;
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
        let mut line = vec![false; n];
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
            let (threshold, error_ratio) = match model.as_mut() {
                Some(model) => {
                    let start = threshold_for(total, |i| view.value(i), h_d, budget);
                    let (tau, ratio) = model.threshold(&small, gain, budget, start)?;
                    (tau, Some(ratio))
                }
                None => (threshold_for(total, |i| view.value(i), h_d, budget), None),
            };
            let mut words = vec![0u32; marks_words(n)];
            let marked = mark(
                n,
                |i| view.value(i),
                threshold,
                radius,
                &mut words,
                &mut line,
            )
            .map_err(|e| e.to_string())?;
            levels.push(Level {
                filter: small,
                h_d,
                threshold,
                words,
                marked,
                gain,
                error_ratio,
            });
        }
        Ok(Self {
            tolerance_db,
            bound,
            levels,
            n,
        })
    }

    /// Bytes of marks held (1 bit per voxel per level).
    pub fn bytes(&self) -> usize {
        self.levels.iter().map(|l| l.words.len() * 4).sum()
    }

    /// Render one view adaptively; returns the image (f64) and statistics.
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
        let n = spec.n();
        let frame = view.frame()?;
        check_image(width, height, n)?;
        let kernel = KernelTable::<T>::new(spec.filter());
        let tables: Vec<KernelTable<T>> = self
            .levels
            .iter()
            .map(|l| KernelTable::new(l.filter))
            .collect();
        let levels: Vec<AdaptiveLevel<'_, '_, T>> = self
            .levels
            .iter()
            .zip(&tables)
            .map(|(l, t)| {
                Ok(AdaptiveLevel {
                    kernel: t,
                    marks: Marks::new(&l.words, self.n)?,
                    gain: T::from_f64(l.gain),
                })
            })
            .collect::<Result<_, fvr_core::Error>>()?;
        let core_spec = spec.view();
        let mut grid = vec![T::ZERO; n * n];
        let stats = extract_slice_adaptive(&core_spec, &kernel, &levels, &frame, &mut grid)?;
        let mut tw_buf = vec![T::ZERO; Twiddles::<T>::buffer_len(n)];
        let tw = Twiddles::new(&mut tw_buf, n)?;
        let mut aux = vec![T::ZERO; aux_len(n)];
        let mut out = vec![T::ZERO; width * height];
        let place = placement(core_spec.dims(), &frame, width, height);
        finish(
            &mut grid,
            n,
            &Crop::new(place, 1.0 / core_spec.scale(), width, height),
            &tw,
            &mut aux,
            &mut out,
        )?;
        Ok((out.into_iter().map(T::to_f64).collect(), stats))
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
