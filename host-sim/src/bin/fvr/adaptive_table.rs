//! `fvr adaptive-table`: the paper's Table 1 measured here.

use crate::args::{load_with_progress, parse_filter};
use crate::Error;

use clap::Args;
use fvr_host::options::parse_tolerance;

use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;
use fvr_engine::slice::adaptive::{AdaptiveSettings, Bound};

#[derive(Args)]
pub(crate) struct AdaptiveTableArgs {
    /// Tolerance in dB.
    #[arg(long, default_value_t = 40.0, value_parser = parse_tolerance)]
    pub(crate) tolerance: f64,
    /// How the tolerance becomes a threshold (see `render --adaptive-bound`).
    #[arg(long, default_value = "exact", value_parser = Bound::from_name)]
    pub(crate) bound: Bound,
    /// Large filter (the spectrum's).
    #[arg(long, value_parser = parse_filter, default_value = "kb3")]
    pub(crate) filter: FilterKind,
    /// Oversampling of the spectrum.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=2))]
    pub(crate) oversample: u32,
    /// Volumes (ct-head is resampled to 128).
    #[arg(long, value_delimiter = ',', default_values_t = ["ct-head".to_string(), "blobs@256".to_string(), "gaussians@128".to_string(), "shepp-logan@128".to_string()])]
    pub(crate) volumes: Vec<String>,
    /// Timed runs per measurement (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub(crate) runs: usize,
}

pub(crate) fn adaptive_table(args: &AdaptiveTableArgs) -> Result<(), Error> {
    let AdaptiveTableArgs {
        tolerance,
        bound,
        filter: kind,
        oversample,
        ref volumes,
        runs,
    } = *args;
    fvr_host::studies::check_repeats("--runs", runs)?;
    let filter = fvr_core::filter::Filter::new(kind, oversample)?;
    let view = View::along([1.0, 0.3, 0.2]);
    let mut rows = Vec::new();
    for name in volumes {
        let mut volume = load_with_progress(name, None)?;
        if name == "ct-head" {
            volume.subtract_background(-1024.0)?;
            volume = volume.resample_isotropic(128)?;
        }
        // The paper's table counts the taps the marks allow: always the
        // adaptive walk, never the plain walk's fallback.
        let settings = AdaptiveSettings {
            bound,
            plain_below: 0.0,
            ..AdaptiveSettings::new(tolerance)
        };
        rows.push(fvr_host::studies::adaptive_table::table1_row(
            name, &volume, filter, &settings, &view, runs,
        )?);
        eprintln!("fvr: measured {name}");
    }
    say_part!(
        "{}",
        fvr_host::studies::adaptive_table::table1_markdown(&rows, tolerance)
    );
    Ok(())
}
