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
    let ia = read_nrrd(a)?;
    let ib = read_nrrd(b)?;
    if ia.dims != ib.dims {
        return Err(format!("images differ in size: {:?} against {:?}", ia.dims, ib.dims).into());
    }
    let ra: Vec<f64> = ia.data.iter().map(|&v| v as f64).collect();
    let rb: Vec<f64> = ib.data.iter().map(|&v| v as f64).collect();
    if ra.iter().all(|&v| v == 0.0) {
        return Err(format!(
            "reference image `{}` is all zero: an SNR against it is undefined",
            a.display()
        )
        .into());
    }
    println!(
        "SNR of {} against {}: {:.2} dB (max abs error {:.3e})",
        b.display(),
        a.display(),
        snr_db(&ra, &rb),
        max_abs_error(&ra, &rb)
    );
    Ok(())
}
