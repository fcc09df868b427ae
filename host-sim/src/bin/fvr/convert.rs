//! `fvr convert`: write a loaded volume (any input `fvr` reads, with
//! `--background` applied) as a `float` NRRD file with its voxel spacing, for
//! tools that cannot read the original format.

use std::path::PathBuf;

use clap::Args;

use crate::args::{volume_help, InputArgs};
use crate::Error;

#[derive(Args)]
pub(crate) struct ConvertArgs {
    /// A volume file, a raw file with --raw-dims, a data set, or a built-in phantom.
    #[arg(help = volume_help())]
    pub(crate) volume: String,
    /// Output file (.nrrd): f32 samples, raw, little endian, with `spacings`.
    #[arg(long, value_name = "FILE.nrrd")]
    pub(crate) out: PathBuf,
    #[command(flatten)]
    pub(crate) input: InputArgs,
}

pub(crate) fn convert(args: &ConvertArgs) -> Result<(), Error> {
    crate::checks::check_output(&args.out, &["nrrd"], &args.volume, &[])?;
    let volume = args.input.load(&args.volume)?;
    crate::checks::check_not_input(&args.out)?;
    fvr_host::io::nrrd::write_volume_nrrd(&args.out, &volume)?;
    Ok(())
}
