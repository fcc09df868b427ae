//! `--accuracy DB` for render and turntable: the configuration chosen by
//! [`fvr_host::render::plan`], its warnings, and its lines in `--stats` and
//! `--stats-json`.

use crate::args::SpectrumArgs;
use crate::render::RenderArgs;
use crate::turntable::TurntableArgs;
use crate::Error;

use fvr_core::volume::GridOversampling;
use fvr_host::render::plan::{
    choose_among, predict_grid, Candidate, Constraints, Prediction, ALL_GRIDS, POW2_GRIDS,
};
use fvr_host::volume::Volume;
use serde::Serialize;

/// Below this prediction a render whose settings were given warns.
pub(crate) const PREDICTION_WARNING_DB: f64 = 40.0;

/// The target without `--accuracy` (or a scene's `accuracy`), in dB.
pub(crate) const DEFAULT_ACCURACY_DB: f64 = 50.0;

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

    /// Whether every setting the planner chooses was given.
    pub(crate) fn all(self) -> bool {
        self.filter && self.oversample && self.precision
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

/// Commands whose spectrum the planner may set.
pub(crate) trait Planned: Clone {
    fn spectrum_mut(&mut self) -> &mut SpectrumArgs;
}

impl Planned for RenderArgs {
    fn spectrum_mut(&mut self) -> &mut SpectrumArgs {
        &mut self.frame.spectrum
    }
}

impl Planned for TurntableArgs {
    fn spectrum_mut(&mut self) -> &mut SpectrumArgs {
        &mut self.frame.spectrum
    }
}

/// Which grids the planner may choose: every one for plain X-ray views, the
/// power-of-two ones for what needs them (cued and lit scenes, adaptive
/// filtering).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Grids {
    All,
    PowersOfTwo,
}

impl Grids {
    fn list(self) -> &'static [GridOversampling] {
        match self {
            Grids::All => &ALL_GRIDS,
            Grids::PowersOfTwo => &POW2_GRIDS,
        }
    }
}

/// `args` with the spectrum settings `--accuracy` chooses for `volume`
/// among `grids` (or as given, with a warning when they are predicted
/// below [`PREDICTION_WARNING_DB`]), the outcome recorded for `--stats`.
pub(crate) fn planned<A: Planned>(args: &A, volume: &Volume, grids: Grids) -> Result<A, Error> {
    let mut out = args.clone();
    apply(out.spectrum_mut(), volume, grids)?;
    Ok(out)
}

fn apply(s: &mut SpectrumArgs, volume: &Volume, grids: Grids) -> Result<(), Error> {
    if s.given.oversample && !s.oversample.is_pow2() && grids == Grids::PowersOfTwo {
        return Err(format!(
            "--oversample {} works on plain X-ray views: depth cues, lights and --adaptive \
             need --oversample 1 or 2",
            s.oversample.name()
        )
        .into());
    }
    // A volume too thin for the smallest grid allowed gets its own message
    // before any prediction.
    let least = if s.given.oversample {
        s.oversample
    } else {
        GridOversampling::X1
    };
    fvr_host::volume::check_padding(volume.dims, least.side(volume.dims)?)?;
    let explicit = s.accuracy.is_some();
    let target = s.accuracy.unwrap_or(DEFAULT_ACCURACY_DB);
    if !explicit && s.given.all() {
        // Everything fixed by the user: nothing to choose, only to predict.
        let candidate = Candidate {
            filter: s.filter,
            oversample: s.oversample.integer(),
            precision: s.precision,
        };
        let prediction = predict_grid(volume, candidate, s.oversample, s.kb_design)?;
        warn_low(&prediction);
        s.outcome = Some(Outcome {
            target_db: None,
            explicit: false,
            prediction,
        });
        return Ok(());
    }
    let constraints = Constraints {
        filter: s.given.filter.then_some(s.filter),
        oversample: s.given.oversample.then_some(s.oversample),
        precision: s.given.precision.then_some(s.precision),
    };
    let plan = choose_among(volume, s.kb_design, target, constraints, grids.list())?;
    let p = plan.prediction;
    if !explicit && constraints != Constraints::default() {
        // The default target with some settings given: they win, and only a
        // prediction below the warning level is worth a line.
        warn_low(&p);
    } else if !plan.met {
        eprintln!(
            "fvr: warning: no configuration is predicted to reach {target} dB{}; using the best, \
             {}, predicted at {:.1} dB ({}).",
            if constraints == Constraints::default() {
                ""
            } else {
                " with the settings given"
            },
            describe(&p),
            p.db,
            p.dominant().why()
        );
    }
    s.filter = p.candidate.filter;
    s.oversample = p.grid;
    s.precision = p.candidate.precision;
    s.outcome = Some(Outcome {
        target_db: Some(target),
        explicit,
        prediction: p,
    });
    Ok(())
}

/// The warning for settings the user gave that are predicted below
/// [`PREDICTION_WARNING_DB`].
fn warn_low(prediction: &Prediction) {
    if prediction.db < PREDICTION_WARNING_DB {
        eprintln!(
            "fvr: warning: {} is predicted to reach only {:.1} dB on this volume ({}); \
             --accuracy 50 chooses a configuration predicted to reach 50 dB.",
            describe(prediction),
            prediction.db,
            prediction.dominant().why()
        );
    }
}

fn describe(p: &Prediction) -> String {
    format!(
        "--filter {} --oversample {} --precision {}",
        p.candidate.filter.name(),
        p.grid.name(),
        p.candidate.precision
    )
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
