//! Adaptive filtering on the host (paper §4): marks built once per
//! spectrum for a tolerance in dB, then views that read the cheaper filters
//! wherever the marks allow, with statistics.

use crate::pipeline::OwnedSpectrum;
use fvr_core::adaptive::{
    extract_slice_adaptive, mark, marks_words, response_difference, threshold_for, AdaptiveLevel,
    AdaptiveStats, Marks, MAX_LEVELS,
};
use fvr_core::dht::Twiddles;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::View;
use fvr_core::real::{Real, Sample};
use fvr_core::render::{aux_len, check_image, finish_projection, placement};
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
}

/// Marks for adaptive filtering of one spectrum.
#[derive(Clone, Debug)]
pub struct AdaptiveMarks {
    /// The tolerance asked for, dB.
    pub tolerance_db: f64,
    /// The cheaper filters, cheapest first.
    pub levels: Vec<Level>,
    n: usize,
}

impl AdaptiveMarks {
    /// Mark `spec` for a tolerance of `tolerance_db` with the cheaper
    /// filters `chain` (cheapest first), with `h_d` from
    /// [`response_difference`] unless `h_d_override` sets it (the paper
    /// used 0.3; a smaller `h_d` than the filters' own voids the bound). The energy budget
    /// `10^(−dB/10)` is split evenly in amplitude between the levels, so
    /// their errors, added, stay within it.
    ///
    /// # Errors
    /// A tolerance that is not a positive number, a chain too long, or a
    /// filter whose response vanishes inside the volume.
    pub fn build<S: Sample>(
        spec: &OwnedSpectrum<S>,
        tolerance_db: f64,
        chain: &[FilterKind],
        h_d_override: Option<f64>,
    ) -> Result<Self, String> {
        Self::build_for(&spec.view(), tolerance_db, chain, h_d_override)
    }

    /// [`AdaptiveMarks::build`] for any core spectrum (every storage
    /// format, block exponents included).
    ///
    /// # Errors
    /// As [`AdaptiveMarks::build`].
    pub fn build_for<S: Sample>(
        view: &Spectrum<'_, S>,
        tolerance_db: f64,
        chain: &[FilterKind],
        h_d_override: Option<f64>,
    ) -> Result<Self, String> {
        parse_tolerance(&tolerance_db.to_string())?;
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
        for &kind in chain {
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
            let threshold = threshold_for(total, |i| view.value(i), h_d, budget);
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
                gain: large.response(0.0) / small.response(0.0),
            });
        }
        Ok(Self {
            tolerance_db,
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
        finish_projection(
            &mut grid,
            n,
            &place,
            1.0 / core_spec.scale(),
            width,
            height,
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

/// One row of the paper's Table 1, measured.
#[derive(Clone, Debug)]
pub struct Table1Row {
    /// Volume name.
    pub name: String,
    /// Volume dims after any resampling.
    pub dims: [usize; 3],
    /// Spectrum side.
    pub n: usize,
    /// Filter taps without adaptivity (per view).
    pub full_taps: u64,
    /// Filter taps with it.
    pub taps: u64,
    /// SNR of the adaptive image against the full-filter one, dB.
    pub snr_db: f64,
    /// Median time per view, full filter, ms.
    pub full_ms: f64,
    /// Median time per view, adaptive, ms.
    pub adaptive_ms: f64,
    /// Median time per view of the spatial-domain ray caster, ms.
    pub spatial_ms: f64,
}

fn median_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let t = std::time::Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// Measure a Table 1 row for `volume`: `filter` (at its oversampling)
/// against `chain` at `tolerance_db`, view along `view`, `runs` timed runs.
///
/// # Errors
/// As [`AdaptiveMarks::build`] and the renderers.
pub fn table1_row(
    name: &str,
    volume: &crate::volume::Volume,
    filter: Filter,
    chain: &[FilterKind],
    tolerance_db: f64,
    view: &View,
    runs: usize,
) -> Result<Table1Row, String> {
    let spec =
        OwnedSpectrum::<half::f16>::prepare::<f32>(volume, filter).map_err(|e| e.to_string())?;
    let n = spec.n();
    let side = n / filter.oversample() as usize;
    let any = crate::pipeline::AnySpectrum::F16(spec.clone());
    let marks = AdaptiveMarks::build(&spec, tolerance_db, chain, None)?;
    let full = any.render(view, side, side).map_err(|e| e.to_string())?;
    let (image, stats) = marks
        .render::<half::f16, f32>(&spec, view, side, side)
        .map_err(|e| e.to_string())?;
    let full_ms = median_ms(runs, || {
        let _ = any.render(view, side, side);
    });
    let adaptive_ms = median_ms(runs, || {
        let _ = marks.render::<half::f16, f32>(&spec, view, side, side);
    });
    let caster = crate::raycast::RayCaster::new(volume);
    let spatial_ms = median_ms(runs, || {
        let _ = caster.project(view, side, side, 1.0, 0);
    });
    Ok(Table1Row {
        name: name.to_string(),
        dims: volume.dims,
        n,
        full_taps: stats.full_taps,
        taps: stats.taps,
        snr_db: crate::reference::snr_db(&full, &image),
        full_ms,
        adaptive_ms,
        spatial_ms,
    })
}

/// Table 1 as Markdown.
pub fn table1_markdown(rows: &[Table1Row], tolerance_db: f64) -> String {
    let mut s = format!(
        "| volume | spectrum | taps, full filter | taps, adaptive ({tolerance_db} dB) | ratio | \
         adaptive vs full | view, full | view, adaptive | spatial ray caster |\n\
         |---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        s += &format!(
            "| {} ({}×{}×{}) | {}³ | {} | {} | {:.1}% | {:.1} dB | {:.2} ms | {:.2} ms | {:.2} ms |\n",
            r.name,
            r.dims[0],
            r.dims[1],
            r.dims[2],
            r.n,
            r.full_taps,
            r.taps,
            100.0 * r.taps as f64 / r.full_taps.max(1) as f64,
            r.snr_db,
            r.full_ms,
            r.adaptive_ms,
            r.spatial_ms
        );
    }
    s
}
