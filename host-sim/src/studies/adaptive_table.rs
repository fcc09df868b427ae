//! The paper's Table 1 measured here (`fvr adaptive-table`): filter taps
//! and time per view with and without adaptive filtering, against the
//! spatial-domain ray caster.

use fvr_core::filter::Filter;
use fvr_core::geometry::View;

use crate::studies::timing::median_ms;
use fvr_engine::slice::adaptive::{AdaptiveMarks, AdaptiveSettings};
use fvr_engine::spectrum::OwnedSpectrum;

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
    /// Time to build the marks once, ms.
    pub mark_ms: f64,
}

/// Measure a Table 1 row for `volume`: `filter` (at its oversampling)
/// against adaptive filtering as `settings` ask, view along `view`, `runs`
/// timed runs.
///
/// # Errors
/// As [`AdaptiveMarks::build`] and the renderers.
pub fn table1_row(
    name: &str,
    volume: &fvr_engine::volume::Volume,
    filter: Filter,
    settings: &AdaptiveSettings,
    view: &View,
    runs: usize,
) -> Result<Table1Row, String> {
    let spec =
        OwnedSpectrum::<half::f16>::prepare::<f32>(volume, filter).map_err(|e| e.to_string())?;
    let n = spec.n();
    let side = n / filter.oversample() as usize;
    let any = fvr_engine::spectrum::AnySpectrum::F16(spec.clone());
    let t_marks = std::time::Instant::now();
    let marks = AdaptiveMarks::build(&spec, settings)?;
    let mark_ms = t_marks.elapsed().as_secs_f64() * 1e3;
    let full = any.render(view, side, side).map_err(|e| e.to_string())?;
    let (image, stats) = marks
        .render::<half::f16, f32>(&spec, view, side, side)
        .map_err(|e| e.to_string())?;
    let full_ms = median_ms(runs, || {
        any.render(view, side, side)
            .map(drop)
            .map_err(|e| e.to_string())
    })?;
    let adaptive_ms = median_ms(runs, || {
        marks
            .render::<half::f16, f32>(&spec, view, side, side)
            .map(drop)
            .map_err(|e| e.to_string())
    })?;
    let caster = crate::reference::raycast::RayCaster::new(volume);
    let spatial_ms = median_ms(runs, || caster.project(view, side, side, 1.0, 0).map(drop))?;
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
        mark_ms,
    })
}

/// Table 1 as Markdown.
pub fn table1_markdown(rows: &[Table1Row], tolerance_db: f64) -> String {
    let mut s = format!(
        "| volume | spectrum | taps, full filter | taps, adaptive ({tolerance_db} dB) | ratio | \
         adaptive vs full | view, full | view, adaptive | spatial ray caster | marks (once) |\n\
         |---|---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        s += &format!(
            "| {} ({}×{}×{}) | {}³ | {} | {} | {:.1}% | {:.1} dB | {:.2} ms | {:.2} ms | {:.2} ms | {:.2} s |\n",
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
            r.spatial_ms,
            r.mark_ms / 1e3
        );
    }
    s
}
