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
    if let Some(&bad) = args
        .sizes
        .iter()
        .find(|&&n| !(8..=512).contains(&n) || !n.is_power_of_two())
    {
        return Err(format!("--sizes: {bad} is not a power of two from 8 to 512").into());
    }
    let rows = fvr_host::studies::accuracy::accuracy_table(&args.sizes)?;
    say_part!("{}", fvr_host::studies::accuracy::markdown(&rows));
    Ok(())
}
