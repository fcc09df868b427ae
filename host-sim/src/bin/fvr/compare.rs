//! `fvr compare`: the SNR of one NRRD image against another, as a line or
//! as JSON, optionally gated by a least SNR (`--min-db`, exit 1 below it).
//! Stacks of views (`fvr project`'s, NRRD or `.npy`) are also compared
//! view by view, and gated on their worst view.

use crate::Error;
use std::path::PathBuf;

use clap::Args;

use fvr_host::io::npy::{is_npy, read_npy_image};
use fvr_host::io::nrrd::{read_nrrd_image_kind, ImageKind};
use fvr_host::io::IoError;
use fvr_host::reference::{max_abs_error, snr_db};

#[derive(Args)]
pub(crate) struct CompareArgs {
    /// Reference image.
    pub(crate) a: PathBuf,
    /// Image to measure.
    pub(crate) b: PathBuf,
    /// Print one JSON object on stdout instead of the line: `a`, `b`,
    /// `width`, `height`, `views`, `dims`, `snr_db`, `identical`,
    /// `max_abs_error`, for stacks of views also `worst_view` (from 0) and
    /// `worst_view_db`, and `min_db` and `passed` with --min-db. Identical
    /// images have an infinite SNR, which JSON cannot hold: `snr_db` is then
    /// `null` and `identical` is `true`.
    #[arg(long)]
    pub(crate) json: bool,
    /// Exit with status 1 (and one line on stderr) when the SNR is below DB
    /// (for a stack of views, `fvr project`'s, the worst view's); identical
    /// images always pass. Errors still exit 2.
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
    let (ia, kind) = read_image(a)?;
    first_read.store(true, std::sync::atomic::Ordering::SeqCst);
    // The first image counts against the limit while the second is read.
    let _first = fvr_host::budget::hold(ia.data.len() as u64 * 4);
    let (ib, _) = read_image(b)?;
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
    let (width, height, views) = match kind {
        ImageKind::Colour => (ia.dims[1], ia.dims[2], 1),
        ImageKind::Scalar | ImageKind::Stack => (ia.dims[0], ia.dims[1], ia.dims[2]),
    };
    let worst = (views > 1).then(|| worst_view(ra, rb, views)).flatten();
    // A stack is gated on its worst view.
    let gated = worst.map_or(db, |(_, view_db)| view_db);
    let passed = args.min_db.map(|min| identical || gated >= min);
    let finite = |db: f64| db.is_finite().then_some(db);
    if args.json {
        let mut json = serde_json::json!({
            "a": a.display().to_string(),
            "b": b.display().to_string(),
            "width": width,
            "height": height,
            "views": views,
            "dims": ia.dims,
            "snr_db": finite(db),
            "identical": identical,
            "max_abs_error": err,
        });
        if let Some(o) = json.as_object_mut() {
            if let Some((view, view_db)) = worst {
                o.insert("worst_view".into(), view.into());
                o.insert("worst_view_db".into(), finite(view_db).into());
            }
            if let (Some(min), Some(passed)) = (args.min_db, passed) {
                o.insert("min_db".into(), min.into());
                o.insert("passed".into(), passed.into());
            }
        }
        say!("{json}");
    } else {
        let worst = worst.map_or(String::new(), |(view, view_db)| {
            format!(", worst of {views} views: {view_db:.2} dB at view {view}")
        });
        say!(
            "SNR of {} against {}: {:.2} dB (max abs error {:.3e}){worst}",
            b.display(),
            a.display(),
            db,
            err
        );
    }
    if let (Some(min), Some(false)) = (args.min_db, passed) {
        let what = if views > 1 { "the worst view's " } else { "" };
        return Err(Box::new(BelowMinDb(format!(
            "compare: {what}{gated:.2} dB is below --min-db {min}"
        ))));
    }
    Ok(())
}

/// An image or stack: a `.npy` file (by its magic bytes) or a NRRD one.
fn read_image(path: &std::path::Path) -> Result<(fvr_engine::volume::Volume, ImageKind), IoError> {
    let mut lead = [0u8; 6];
    let npy = fvr_host::io::open_file(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut lead))
        .is_ok_and(|()| is_npy(&lead));
    match npy {
        true => read_npy_image(path),
        false => read_nrrd_image_kind(path),
    }
}

/// The view (from 0) with the lowest SNR among `views` equal slices, and
/// that SNR; views whose reference is all zero have none and are left out
/// (`None` when every view's is).
fn worst_view(reference: &[f32], test: &[f32], views: usize) -> Option<(usize, f64)> {
    let len = reference.len() / views;
    reference
        .chunks_exact(len)
        .zip(test.chunks_exact(len))
        .enumerate()
        .filter(|(_, (r, _))| r.iter().any(|&v| v != 0.0))
        .map(|(view, (r, t))| (view, snr_db(r, t)))
        .min_by(|x, y| x.1.total_cmp(&y.1))
}
