//! What an adaptive render did (`fvr render --adaptive`), for --stats.

use crate::Error;
use serde::Serialize;
use std::time::Instant;

use fvr_core::geometry::View;
use fvr_engine::image::Image;
use fvr_engine::render::adaptive::Walked;
use fvr_engine::slice::adaptive::{AdaptiveMarks, Bound};
use fvr_engine::{AdaptiveView, Renderer, ViewReport};
use fvr_host::reference::snr_db;

/// An adaptive render with what it did.
pub(crate) struct AdaptiveReport<'a> {
    pub(crate) marks: &'a AdaptiveMarks,
    pub(crate) stats: fvr_core::slice::adaptive::AdaptiveStats,
    pub(crate) walked: Walked,
    pub(crate) mark_time: std::time::Duration,
    pub(crate) view_time: std::time::Duration,
    pub(crate) full_view_time: std::time::Duration,
    pub(crate) snr_vs_full: f64,
}

impl<'a> AdaptiveReport<'a> {
    /// The report of the adaptive view `image` of `view`, with the full
    /// filter's view rendered for comparison.
    pub(crate) fn new(
        renderer: &'a Renderer,
        adaptive: &AdaptiveView,
        view: &View,
        report: &ViewReport,
        image: &Image,
    ) -> Result<Self, Error> {
        let marks = renderer
            .marks()
            .ok_or("an adaptive view was rendered without marks")?;
        if let (Walked::Plain { share }, false) = (adaptive.walked, fvr_host::progress::quiet()) {
            eprintln!(
                "fvr: note: adaptive: the marks allow {:.1}% of the samples on the cheaper \
                 filters, below {:.1}% (--adaptive-plain-below): 0.0% of samples substituted, \
                 plain walk used",
                100.0 * share,
                100.0 * marks.plain_below
            );
        }
        // The full filter's view in the same units: voxel units, times the
        // gain the adaptive image carries.
        let gain = renderer.sampling().gain() * renderer.settings().scene.ambient[0];
        let t = Instant::now();
        let full = renderer
            .spectra()
            .density
            .render(view, image.width, image.height)?;
        let full_view_time = t.elapsed();
        let full: Vec<f64> = full.iter().map(|v| v * gain).collect();
        Ok(Self {
            snr_vs_full: snr_db(&full, &image.data),
            marks,
            stats: adaptive.stats,
            walked: adaptive.walked,
            mark_time: adaptive.mark_time.unwrap_or_default(),
            view_time: report.time,
            full_view_time,
        })
    }

    pub(crate) fn print_human(&self) {
        let s = &self.stats;
        let pct = |v: u64, of: u64| 100.0 * v as f64 / of.max(1) as f64;
        say!(
            "  adaptive      {} dB: {} of {} taps ({:.1}%), {:.2} ms per view against {:.2} ms \
             with the full filter; image {:.1} dB from the full-filter image",
            self.marks.tolerance_db,
            s.taps,
            s.full_taps,
            pct(s.taps, s.full_taps),
            self.view_time.as_secs_f64() * 1e3,
            self.full_view_time.as_secs_f64() * 1e3,
            self.snr_vs_full
        );
        say!(
            "  samples       {:.1}% on the full filter",
            pct(s.per_filter[0], s.samples)
        );
        if let Walked::Plain { share } = self.walked {
            say!(
                "  adaptive      0.0% of samples substituted, plain walk used (the marks allow \
                 {:.1}%, below --adaptive-plain-below {:.1}%)",
                100.0 * share,
                100.0 * self.marks.plain_below
            );
        }
        for (i, l) in self.marks.levels.iter().enumerate() {
            say!(
                "  samples       {:.1}% on {} (h_d {:.3}, threshold {:.3e}, {} of {} spectrum samples marked)",
                pct(s.per_filter[i + 1], s.samples),
                l.cheaper.name(),
                l.h_d,
                l.threshold,
                l.marked,
                l.words.len() * 32
            );
            match (l.error_ratio, self.marks.bound) {
                (Some(r), Bound::Parseval) if !l.evaluated => say!(
                    "  error field   at least {:.1} dB below the volume (Parseval's bound on \
                     eq. 15; {})",
                    -10.0 * r.log10(),
                    match l.probes.unwrap_or(0) {
                        0 => "no probe transforms".to_string(),
                        _ => format!("{}, none accepted", transforms(l.probes)),
                    }
                ),
                (Some(r), Bound::Parseval) => say!(
                    "  error field   {:.1} dB below the volume (Parseval's bound on eq. 15, \
                     raised by {})",
                    -10.0 * r.log10(),
                    transforms(l.probes)
                ),
                (Some(r), _) => say!(
                    "  error field   {:.1} dB below the volume (exact bound, eq. 15; {} probe \
                     transforms)",
                    -10.0 * r.log10(),
                    l.probes.unwrap_or(0)
                ),
                (None, _) => {}
            }
        }
        say!(
            "  marks         {} bytes (1 bit per voxel and 1 byte per 8^3 brick per level), built in {:.1} ms",
            self.marks.bytes(),
            self.mark_time.as_secs_f64() * 1e3
        );
        if let Some(note) = self.marks.note(s, self.walked) {
            say!("  note          {note}");
        }
    }

    pub(crate) fn json(&self) -> AdaptiveJson {
        let s = &self.stats;
        let levels = self
            .marks
            .levels
            .iter()
            .enumerate()
            .map(|(i, l)| LevelJson {
                filter: l.cheaper.name(),
                h_d: l.h_d,
                threshold: l.threshold,
                marked: l.marked,
                samples: s.per_filter[i + 1],
                error_field_db: l.error_ratio.map(|r| -10.0 * r.log10()),
                error_field_evaluated: l.evaluated,
                probes: l.probes,
            })
            .collect();
        AdaptiveJson {
            tolerance_db: self.marks.tolerance_db,
            bound: self.marks.bound.name(),
            taps: s.taps,
            full_taps: s.full_taps,
            taps_ratio: s.taps as f64 / s.full_taps.max(1) as f64,
            samples: s.samples,
            full_filter_samples: s.per_filter[0],
            levels,
            marks_bytes: self.marks.bytes(),
            mark_ms: self.mark_time.as_secs_f64() * 1e3,
            view_ms: self.view_time.as_secs_f64() * 1e3,
            full_view_ms: self.full_view_time.as_secs_f64() * 1e3,
            snr_vs_full_db: self.snr_vs_full,
            plain_walk: matches!(self.walked, Walked::Plain { .. }),
            allowed_share: match self.walked {
                Walked::Plain { share } => share,
                Walked::Adaptive => 1.0 - s.per_filter[0] as f64 / s.samples.max(1) as f64,
            },
            plain_below: self.marks.plain_below,
            note: self.marks.note(s, self.walked),
        }
    }
}

/// The `adaptive` member of `fvr render --stats-json`.
#[derive(Serialize)]
pub(crate) struct AdaptiveJson {
    tolerance_db: f64,
    bound: &'static str,
    taps: u64,
    full_taps: u64,
    taps_ratio: f64,
    samples: u64,
    full_filter_samples: u64,
    levels: Vec<LevelJson>,
    marks_bytes: usize,
    mark_ms: f64,
    view_ms: f64,
    full_view_ms: f64,
    snr_vs_full_db: f64,
    /// The view was walked plainly with the full filter: the marks allowed
    /// fewer than `plain_below` of its samples on the cheaper filters.
    plain_walk: bool,
    /// Share of the view's samples the marks allow on the cheaper filters.
    allowed_share: f64,
    plain_below: f64,
    note: Option<String>,
}

/// "1 probe transform", "3 probe transforms".
fn transforms(probes: Option<usize>) -> String {
    match probes.unwrap_or(0) {
        1 => "1 probe transform".into(),
        k => format!("{k} probe transforms"),
    }
}

/// One cheaper filter of [`AdaptiveJson`].
#[derive(Serialize)]
struct LevelJson {
    filter: &'static str,
    h_d: f64,
    threshold: f64,
    marked: usize,
    samples: u64,
    error_field_db: Option<f64>,
    /// Whether `error_field_db` was evaluated (else it is a bound: the
    /// field is at least that far below the volume).
    error_field_evaluated: bool,
    probes: Option<usize>,
}
