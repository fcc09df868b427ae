//! `--accuracy DB` for render and turntable: the configuration chosen by
//! [`fvr_engine::Plan`], its warnings, and its lines in `--stats` and
//! `--stats-json`.

use crate::args::SpectrumArgs;

use fvr_core::volume::GridOversampling;
use fvr_engine::plan::Prediction;
use fvr_engine::{describe, Plan, Settings};
use serde::Serialize;

/// Which spectrum settings were given on the command line (they win over
/// the planner's choice).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Given {
    pub(crate) filter: bool,
    pub(crate) oversample: bool,
    pub(crate) precision: bool,
}

impl Given {
    /// From `given(id)`: whether the flag `id` was on the command line.
    pub(crate) fn from_flags(given: &dyn Fn(&str) -> bool) -> Self {
        Self {
            filter: given("filter"),
            oversample: given("oversample"),
            precision: given("precision"),
        }
    }
}

/// What the planner decided, for `--stats`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Outcome {
    /// The target the configuration was chosen for (none when every
    /// setting was given).
    pub(crate) target_db: Option<f64>,
    /// Whether the target was given (`--accuracy` or the scene's
    /// `accuracy`) rather than the default.
    pub(crate) explicit: bool,
    /// The prediction for the configuration used.
    pub(crate) prediction: Prediction,
}

/// The engine's settings for the spectrum flags: those given are fixed,
/// the rest are the planner's to choose.
pub(crate) fn settings(s: &SpectrumArgs) -> Settings {
    Settings {
        accuracy_db: s.accuracy,
        filter: s.given.filter.then_some(s.filter),
        oversample: s.given.oversample.then_some(s.oversample),
        precision: s.given.precision.then_some(s.precision),
        kb_design: s.kb_design,
        ..Settings::default()
    }
}

/// Print the plan's warnings and record its choice in `s`: the spectrum
/// settings used, and the outcome for `--stats`.
pub(crate) fn apply(s: &mut SpectrumArgs, plan: &Plan) {
    for w in &plan.warnings {
        eprintln!("fvr: warning: {w}");
    }
    s.filter = plan.filter;
    s.oversample = plan.grid;
    s.precision = plan.precision;
    s.outcome = Some(Outcome {
        target_db: plan.target_db,
        explicit: plan.explicit,
        prediction: plan.prediction,
    });
}

/// The `--stats` line: the configuration, its prediction and the term
/// that limits it.
pub(crate) fn print_human(s: &SpectrumArgs) {
    if let Some(o) = s.outcome {
        let p = o.prediction;
        let how = match o.target_db {
            Some(t) if o.explicit => format!("chosen for --accuracy {t}"),
            Some(t) => format!("chosen for the default --accuracy {t}"),
            None => "as given".to_string(),
        };
        say!(
            "  accuracy      {:.1} dB predicted for {} ({how}; limited by the {} term: {})",
            p.db,
            describe(&p),
            p.dominant().name(),
            p.dominant().why()
        );
    }
}

/// `--stats-json`: `accuracy` object.
#[derive(Serialize)]
pub(crate) struct AccuracyJson {
    target_db: Option<f64>,
    target_is_default: bool,
    predicted_db: Option<f64>,
    predicted_views_db: [Option<f64>; 3],
    filter: &'static str,
    oversample: serde_json::Value,
    precision: &'static str,
    limited_by: &'static str,
    edge_db: Option<f64>,
    kernel_db: Option<f64>,
    storage_db: Option<f64>,
}

/// The `accuracy` object of `--stats-json`, if a prediction was made; a
/// term with no error at all (infinite dB) is `null`.
pub(crate) fn json(s: &SpectrumArgs) -> Option<AccuracyJson> {
    s.outcome.map(|o| {
        let p = o.prediction;
        let finite = |v: f64| v.is_finite().then_some(v);
        AccuracyJson {
            target_db: o.target_db,
            target_is_default: o.target_db.is_some() && !o.explicit,
            predicted_db: finite(p.db),
            predicted_views_db: p.views_db.map(finite),
            filter: p.candidate.filter.name(),
            oversample: oversample_json(p.grid),
            precision: p.candidate.precision.name(),
            limited_by: p.dominant().name(),
            edge_db: finite(p.parts_db[0]),
            kernel_db: finite(p.parts_db[1]),
            storage_db: finite(p.parts_db[2]),
        }
    })
}

/// σ in `--stats-json`: an integer for 1 and 2, else a float.
pub(crate) fn oversample_json(grid: GridOversampling) -> serde_json::Value {
    if grid.is_pow2() {
        grid.integer().into()
    } else {
        grid.factor().into()
    }
}
