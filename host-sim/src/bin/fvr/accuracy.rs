//! `fvr accuracy`: the README's accuracy table.

use crate::Error;
use clap::Args;

#[derive(Args)]
pub(crate) struct AccuracyArgs {
    /// Phantom sides to test.
    #[arg(long, value_delimiter = ',', default_values_t = [64usize, 128])]
    pub(crate) sizes: Vec<usize>,
}

pub(crate) fn accuracy(args: &AccuracyArgs) -> Result<(), Error> {
    let rows = fvr_host::studies::accuracy::accuracy_table(&args.sizes)?;
    print!("{}", fvr_host::studies::accuracy::markdown(&rows));
    Ok(())
}
