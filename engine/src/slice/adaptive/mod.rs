//! Adaptive filtering on the host (paper §4): marks built once per
//! spectrum for a tolerance in dB, then views that read the cheaper filters
//! wherever the marks allow, with statistics.

pub mod marks;
pub mod spans;
pub mod summary;
pub mod walk;

mod bound;

use crate::slice::adaptive::summary::MarksSummary;
use crate::spectrum::prepare::PreparedEnergy;
use crate::spectrum::OwnedSpectrum;
use bound::{ErrorModel, Probes};
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::num::{Real, Sample};
use fvr_core::slice::adaptive::{
    marks_words, response_difference, threshold_for, AdaptiveLevel, AdaptiveStats, Marks,
    MAX_LEVELS,
};
use fvr_core::spectrum::Spectrum;

/// One link of an adaptive chain: what stands in for the large filter
/// where the spectrum is weak.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cheaper {
    /// The zero filter (`ĥ₂ = 0` in eq. 15): the point is left out, and
    /// reads nothing. Its error is the weak samples' own contribution.
    Zero,
    /// A narrower filter, its DC gain matched to the large one's.
    Filter(FilterKind),
}

impl Cheaper {
    /// Taps per axis: 0 for the zero filter.
    pub fn width(self) -> usize {
        match self {
            Self::Zero => 0,
            Self::Filter(kind) => kind.width(),
        }
    }

    /// The name [`parse_chain`] accepts.
    pub fn name(self) -> &'static str {
        match self {
            Self::Zero => "zero",
            Self::Filter(kind) => kind.name(),
        }
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
    /// The error energy bounded by Parseval's theorem with the weight's
    /// largest square, against the same reference as [`Bound::Exact`] (or
    /// a floor of it the preparation measured): a guarantee without a
    /// probe, and a smaller threshold than the exact one's. Tight for the
    /// zero filter, whose weight `−ĥ₁` peaks at 1. Then at most
    /// [`AdaptiveSettings::probes`] evaluations of the error field raise
    /// the threshold where the field allows.
    Parseval,
}

impl Bound {
    /// Parse `paper`, `exact` or `parseval`.
    pub fn from_name(s: &str) -> Result<Self, String> {
        match s.trim() {
            "paper" => Ok(Self::Paper),
            "exact" => Ok(Self::Exact),
            "parseval" => Ok(Self::Parseval),
            other => Err(format!(
                "unknown adaptive bound `{other}`: use `exact` (the error field of eq. 15), \
                 `parseval` (its energy bounded, one transform) or `paper` (eq. 16 with the \
                 worst-case response difference)"
            )),
        }
    }

    /// The name `from_name` accepts.
    pub fn name(self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::Exact => "exact",
            Self::Parseval => "parseval",
        }
    }
}

/// What the user asked of adaptive filtering.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptiveSettings {
    /// Tolerance in dB: the substitution's error energy stays
    /// `10^(−dB/10)` below the volume's.
    pub tolerance_db: f64,
    /// The cheaper filters, cheapest first ([`parse_chain`]).
    pub chain: Vec<Cheaper>,
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
    /// With [`Bound::Parseval`]: at most this many 3D transforms that
    /// evaluate the error field above Parseval's threshold and raise it
    /// where the field allows (0, [`DEFAULT_PROBES`], for Parseval's bound
    /// alone).
    pub probes: usize,
}

/// Probes that raise Parseval's threshold by default: none. Each is a 3D
/// transform of the error field, about one preparation's time, and on the
/// smooth benchmark volume one probe took the marks from about 1.2 to 2.2
/// preparations for a view 4% faster (docs/adaptive.md); a user rendering
/// many views asks for them.
pub const DEFAULT_PROBES: usize = 0;

/// The share of substituted samples below which the plain walk is faster
/// than the adaptive one: about 80% for kb6 and 97% for kb4 with the 1³
/// filter (`FVR_BENCH_BREAKEVEN=1 cargo bench -p fvr-host --bench
/// adaptive`; see docs/adaptive.md). Where the two walks are close, the
/// plain one is kept: its image is the full filter's.
pub const DEFAULT_PLAIN_BELOW: f64 = 0.9;

impl AdaptiveSettings {
    /// `tolerance_db` with the paper's 1³ filter and the exact bound (the
    /// defaults of `fvr adaptive-table`; `fvr render --adaptive` takes the
    /// zero filter and Parseval's bound).
    pub fn new(tolerance_db: f64) -> Self {
        Self {
            tolerance_db,
            chain: vec![Cheaper::Filter(FilterKind::Nearest)],
            h_d: None,
            bound: Bound::Exact,
            plain_below: DEFAULT_PLAIN_BELOW,
            probes: DEFAULT_PROBES,
        }
    }
}

/// One cheaper filter with its marks.
#[derive(Clone, Debug)]
pub struct Level {
    /// What stands in for the large filter.
    pub cheaper: Cheaper,
    /// Its filter (for [`Cheaper::Zero`], the 1³ filter, never read).
    pub filter: Filter,
    /// `h_d = max|g·ĥ_small/ĥ_large − 1|` over the volume.
    pub h_d: f64,
    /// The magnitude threshold from eq. 16.
    pub threshold: f64,
    /// The marks' words.
    pub words: Vec<u32>,
    /// The bricks the marks hold whole.
    pub summary: MarksSummary,
    /// Samples marked.
    pub marked: usize,
    /// DC gain correction `ĥ_large(0)/ĥ_small(0)`.
    pub gain: f64,
    /// With [`Bound::Exact`]: the 3D error energy of this level's
    /// substitution relative to the volume's, as verified for `threshold`;
    /// with [`Bound::Parseval`], as verified by a probe or else the bound
    /// on it ([`Level::evaluated`]).
    pub error_ratio: Option<f64>,
    /// Whether [`Level::error_ratio`] was evaluated (an inverse transform
    /// of the error field) rather than bounded.
    pub evaluated: bool,
    /// With [`Bound::Exact`] or [`Bound::Parseval`]: the 3D inverse
    /// transforms the threshold search ran for this level (the
    /// reference's not counted).
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
        Self::build_with(&spec.view(), settings, spec.prepared_energy())
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
        Self::build_with(view, settings, None)
    }

    /// [`AdaptiveMarks::build_for`], with the energy the preparation of
    /// `view`'s spectrum measured, if known: Parseval's bound then takes
    /// its reference from it instead of an inverse transform.
    fn build_with<S: Sample>(
        view: &Spectrum<'_, S>,
        settings: &AdaptiveSettings,
        prepared: Option<&PreparedEnergy>,
    ) -> Result<Self, String> {
        let AdaptiveSettings {
            tolerance_db,
            ref chain,
            h_d: h_d_override,
            bound,
            plain_below,
            probes: parseval_probes,
        } = *settings;
        if !(tolerance_db.is_finite() && tolerance_db > 0.0) {
            return Err(format!(
                "adaptive tolerance must be a positive number of dB (e.g. 40), got `{tolerance_db}`"
            ));
        }
        if !(0.0..=1.0).contains(&plain_below) {
            return Err(format!(
                "the share below which views walk plainly is 0 to 1, got {plain_below}"
            ));
        }
        if bound != Bound::Paper && h_d_override.is_some() {
            return Err(
                "--adaptive-hd sets the h_d of the paper's bound; the exact and parseval bounds \
                 use the error field of eq. 15 instead: use --adaptive-bound paper with it"
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
            Bound::Exact => Some(ErrorModel::new(view, prepared, Probes::Search)?),
            Bound::Parseval => {
                let probes = match parseval_probes {
                    0 => Probes::None,
                    _ => Probes::Few,
                };
                Some(ErrorModel::new(view, prepared, probes)?)
            }
            Bound::Paper => None,
        };
        for &cheaper in chain.iter() {
            let (small, h_d, gain) = match cheaper {
                // `|0·ĥ₂/ĥ₁ − 1| = 1` everywhere: no override applies.
                Cheaper::Zero => (
                    Filter::new(FilterKind::Nearest, large.oversample())
                        .map_err(|e| e.to_string())?,
                    1.0,
                    0.0,
                ),
                Cheaper::Filter(kind) => {
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
                    (small, h_d, large.response(0.0) / small.response(0.0))
                }
            };
            let found = match model.as_mut() {
                Some(model) if bound == Bound::Parseval => {
                    Some(model.raised(&small, gain, budget, parseval_probes)?)
                }
                Some(model) => Some(model.threshold(&small, gain, budget, None)?),
                None => None,
            };
            let threshold = match found {
                Some(found) => found.tau,
                None => threshold_for(total, |i| view.value(i), h_d, budget),
            };
            let (error_ratio, probes) = (found.map(|f| f.ratio), found.map(|f| f.probes));
            let evaluated = found.is_some_and(|f| f.evaluated);
            let mut words = vec![0u32; marks_words(n)];
            let exact = model.as_ref().filter(|m| m.exact).map(|m| &m.values[..]);
            let marked = match exact {
                Some(values) => marks::mark(n, |i| values[i] as f64, threshold, radius, &mut words),
                None => marks::mark(n, |i| view.value(i), threshold, radius, &mut words),
            }
            .map_err(|e| e.to_string())?;
            levels.push(Level {
                cheaper,
                filter: small,
                summary: MarksSummary::new(&words, n),
                h_d,
                threshold,
                words,
                marked,
                gain,
                error_ratio,
                evaluated,
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

    /// The levels as the core's extraction takes them, over `tables` (one
    /// kernel table per level, in order).
    ///
    /// # Errors
    /// Marks of the wrong length for their side.
    pub fn core_levels<'a, T: Real>(
        &'a self,
        tables: &'a [KernelTable<T>],
    ) -> Result<Vec<AdaptiveLevel<'a, 'a, T>>, fvr_core::Error> {
        self.levels
            .iter()
            .zip(tables)
            .map(|(l, t)| {
                Ok(AdaptiveLevel {
                    kernel: t,
                    marks: Marks::new(&l.words, self.n)?,
                    gain: T::from_f64(l.gain),
                })
            })
            .collect()
    }

    /// The kernel tables of the levels, in order.
    pub fn tables<T: Real>(&self) -> Vec<KernelTable<T>> {
        self.levels
            .iter()
            .map(|l| KernelTable::new(l.filter))
            .collect()
    }

    /// The summary of the first level's marks, which the host's walk reads
    /// before the marks themselves.
    pub fn summary(&self) -> Option<&MarksSummary> {
        self.levels.first().map(|l| &l.summary)
    }

    /// Bytes of marks held (1 bit per voxel per level, and in the summaries
    /// 1 byte per brick of 512 voxels and 6 per brick not held whole).
    pub fn bytes(&self) -> usize {
        self.levels
            .iter()
            .map(|l| l.words.len() * 4 + l.summary.bytes())
            .sum()
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
