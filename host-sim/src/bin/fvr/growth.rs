//! `fvr growth`: time per view against the volume's side, both methods.

use crate::Error;
use std::path::PathBuf;

use clap::Args;

#[derive(Args)]
pub(crate) struct GrowthArgs {
    /// Volume sides: powers of two from 16 to 256 (512 with --large).
    #[arg(long, value_delimiter = ',', default_values_t = [64usize, 128, 256])]
    pub(crate) sizes: Vec<usize>,
    /// Timed views per size and method (after one warm-up view), the
    /// sizes in turn in each round.
    #[arg(long, default_value_t = 15)]
    pub(crate) runs: usize,
    /// Allow 512 (a 256 MiB spectrum, its 256 MiB copy with x and y
    /// exchanged and a 512 MiB volume, held beside the smaller sizes').
    #[arg(long)]
    pub(crate) large: bool,
    /// Where to write the files.
    #[arg(long, default_value = "growth")]
    pub(crate) out_dir: PathBuf,
}

pub(crate) fn run(args: &GrowthArgs) -> Result<(), Error> {
    fvr_host::studies::growth::run(&args.sizes, args.runs, args.large, &args.out_dir, |r| {
        eprintln!(
            "fvr: {}³: {:.3} ms against {:.2} ms",
            r.n, r.frequency_ms, r.raycast_ms
        )
    })
    .map(|md| say_part!("{md}"))?;
    Ok(())
}
