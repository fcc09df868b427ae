//! `fvr compare`: the SNR of one NRRD image against another.

use crate::Error;
use std::path::PathBuf;

use clap::Args;

use fvr_host::io::nrrd::read_nrrd;
use fvr_host::reference::{max_abs_error, snr_db};

#[derive(Args)]
pub(crate) struct CompareArgs {
    /// Reference image.
    pub(crate) a: PathBuf,
    /// Image to measure.
    pub(crate) b: PathBuf,
}

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
    say!(
        "SNR of {} against {}: {:.2} dB (max abs error {:.3e})",
        b.display(),
        a.display(),
        snr_db(ra, rb),
        max_abs_error(ra, rb)
    );
    Ok(())
}
