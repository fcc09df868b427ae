//! The accuracy experiment of the README: the Gaussian-mixture phantom,
//! three views, against exact line integrals and against the f64 pipeline.

use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;

use crate::reference::{exact_projection, snr_db};
use crate::sources::{DEFAULT_SEED, GAUSSIAN_COUNT};
use fvr_engine::plan::filter::{choose_filter, KbDesign};
use fvr_engine::spectrum::{AnySpectrum, PipelineError, Precision};
use fvr_engine::volume::phantom::{sample, GaussianMixture};

/// The three views: along an axis, along (1, 0.3, 0.2) and along (1, 1, 1).
pub const VIEWS: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [1.0, 0.3, 0.2], [1.0, 1.0, 1.0]];

/// One configuration of the experiment.
#[derive(Clone, Copy, Debug)]
pub struct Config {
    /// Interpolation filter.
    pub filter: FilterKind,
    /// Grid oversampling.
    pub oversample: u32,
    /// Pipeline precision.
    pub precision: Precision,
    /// Compare against the f64 pipeline with the same filter instead of
    /// against exact line integrals.
    pub against_f64: bool,
}

/// The configurations reported, with the floor each must reach (dB).
pub const CONFIGS: [(Config, f64); 9] = [
    (
        cfg(FilterKind::Linear, 1, Precision::F32, false),
        f64::NEG_INFINITY,
    ),
    (
        cfg(FilterKind::Cubic, 1, Precision::F32, false),
        f64::NEG_INFINITY,
    ),
    (cfg(FilterKind::Kb3, 1, Precision::F16, false), 40.0),
    (cfg(FilterKind::Kb4, 1, Precision::F16, false), 50.0),
    (cfg(FilterKind::Kb6, 1, Precision::F16, false), 65.0),
    (cfg(FilterKind::Kb6, 2, Precision::F32, false), 85.0),
    (cfg(FilterKind::Kb4, 1, Precision::F16, true), 70.0),
    (cfg(FilterKind::Kb6, 1, Precision::F16, true), 70.0),
    (cfg(FilterKind::Kb6, 2, Precision::F16, true), 70.0),
];

const fn cfg(
    filter: FilterKind,
    oversample: u32,
    precision: Precision,
    against_f64: bool,
) -> Config {
    Config {
        filter,
        oversample,
        precision,
        against_f64,
    }
}

/// A measured row.
#[derive(Clone, Debug)]
pub struct Row {
    /// What was measured.
    pub config: Config,
    /// Phantom side.
    pub n: usize,
    /// SNR for each of [`VIEWS`], dB.
    pub snr: [f64; 3],
    /// Required floor, dB.
    pub floor: f64,
}

/// Measure one configuration on the `n³` phantom.
///
/// # Errors
/// As the pipeline.
pub fn measure(config: Config, n: usize) -> Result<[f64; 3], PipelineError> {
    let dims = [n, n, n];
    let phantom = GaussianMixture::random(DEFAULT_SEED, n, GAUSSIAN_COUNT);
    let volume = sample(&phantom, dims);
    let filter = choose_filter(&volume, config.filter, config.oversample, KbDesign::Auto)?;
    let spec = AnySpectrum::prepare(&volume, filter, config.precision)?;
    let reference_spec = if config.against_f64 {
        Some(AnySpectrum::prepare(&volume, filter, Precision::F64)?)
    } else {
        None
    };
    let mut snr = [0.0; 3];
    for (s, dir) in snr.iter_mut().zip(VIEWS) {
        let view = View::along(dir);
        let image = spec.render(&view, n, n)?;
        let reference = match &reference_spec {
            Some(r) => r.render(&view, n, n)?,
            None => exact_projection(&phantom, dims, &view, n, n)?,
        };
        *s = snr_db(&reference, &image);
    }
    Ok(snr)
}

/// Measure every configuration at every size.
///
/// # Errors
/// As the pipeline.
pub fn accuracy_table(sizes: &[usize]) -> Result<Vec<Row>, PipelineError> {
    let mut rows = Vec::new();
    for &n in sizes {
        for (config, floor) in CONFIGS {
            let snr = measure(config, n)?;
            rows.push(Row {
                config,
                n,
                snr,
                floor,
            });
        }
    }
    Ok(rows)
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| n | filter | oversample | precision | reference | axis | (1,0.3,0.2) | (1,1,1) | floor |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let c = r.config;
        let floor = if r.floor.is_finite() {
            format!("≥ {:.0} dB", r.floor)
        } else {
            "—".into()
        };
        s += &format!(
            "| {} | {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {} |\n",
            r.n,
            c.filter.name(),
            c.oversample,
            c.precision,
            if c.against_f64 {
                "f64 pipeline"
            } else {
                "exact"
            },
            r.snr[0],
            r.snr[1],
            r.snr[2],
            floor
        );
    }
    s
}
