//! `fvr compare`: the SNR of one NRRD image against another, as a line or
//! as JSON, optionally gated by a least SNR (`--min-db`, exit 1 below it).

use crate::Error;
use std::path::PathBuf;

use clap::Args;

use fvr_host::io::nrrd::read_nrrd_image as read_nrrd;
use fvr_host::reference::{max_abs_error, snr_db};

#[derive(Args)]
pub(crate) struct CompareArgs {
    /// Reference image.
    pub(crate) a: PathBuf,
    /// Image to measure.
    pub(crate) b: PathBuf,
    /// Print one JSON object on stdout instead of the line: `a`, `b`,
    /// `width`, `height`, `dims`, `snr_db`, `identical`, `max_abs_error`,
    /// and `min_db` and `passed` with --min-db. Identical images have an
    /// infinite SNR, which JSON cannot hold: `snr_db` is then `null` and
    /// `identical` is `true`.
    #[arg(long)]
    pub(crate) json: bool,
    /// Exit with status 1 (and one line on stderr) when the SNR is below DB;
    /// identical images always pass. Errors still exit 2.
    #[arg(long, value_name = "DB", allow_negative_numbers = true)]
    pub(crate) min_db: Option<f64>,
}

/// The SNR fell below `--min-db`: `main` prints this and exits 1.
#[derive(Debug)]
pub(crate) struct BelowMinDb(pub(crate) String);

impl std::fmt::Display for BelowMinDb {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BelowMinDb {}

pub(crate) fn compare(args: &CompareArgs) -> Result<(), Error> {
    let (a, b) = (&args.a, &args.b);
    // While the first image is read, plan for a second of the same size,
    // so that a pair that cannot both fit is refused before any decoding.
    let first_read = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let done = first_read.clone();
    fvr_host::budget::set_plan("compare smaller images", move |dims| {
        let mut budget = fvr_host::budget::Budget::new();
        if !done.load(std::sync::atomic::Ordering::SeqCst) {
            let count = dims.iter().fold(1u64, |c, &d| c.saturating_mul(d as u64));
            budget.hold("second image", count, 4);
        }
        budget
    });
    let ia = read_nrrd(a)?;
    first_read.store(true, std::sync::atomic::Ordering::SeqCst);
    // The first image counts against the limit while the second is read.
    let _first = fvr_host::budget::hold(ia.data.len() as u64 * 4);
    let ib = read_nrrd(b)?;
    if ia.dims != ib.dims {
        return Err(format!("images differ in size: {:?} against {:?}", ia.dims, ib.dims).into());
    }
    let (ra, rb) = (&ia.data, &ib.data);
    if ra.iter().all(|&v| v == 0.0) {
        return Err(format!(
            "reference image `{}` is all zero: an SNR against it is undefined",
            a.display()
        )
        .into());
    }
    if let Some(min) = args.min_db {
        if !min.is_finite() {
            return Err(format!("--min-db must be a finite number of dB, not {min}").into());
        }
    }
    let db = snr_db(ra, rb);
    let err = max_abs_error(ra, rb);
    let identical = ra == rb;
    let passed = args.min_db.map(|min| identical || db >= min);
    if args.json {
        let [width, height, _] = ia.dims;
        let json = serde_json::json!({
            "a": a.display().to_string(),
            "b": b.display().to_string(),
            "width": width,
            "height": height,
            "dims": ia.dims,
            "snr_db": if db.is_finite() { Some(db) } else { None },
            "identical": identical,
            "max_abs_error": err,
            "min_db": args.min_db,
            "passed": passed,
        });
        let mut json = json;
        if args.min_db.is_none() {
            if let Some(o) = json.as_object_mut() {
                o.remove("min_db");
                o.remove("passed");
            }
        }
        say!("{json}");
    } else {
        say!(
            "SNR of {} against {}: {:.2} dB (max abs error {:.3e})",
            b.display(),
            a.display(),
            db,
            err
        );
    }
    if let (Some(min), Some(false)) = (args.min_db, passed) {
        return Err(Box::new(BelowMinDb(format!(
            "compare: {db:.2} dB is below --min-db {min}"
        ))));
    }
    Ok(())
}
