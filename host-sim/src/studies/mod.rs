//! The measuring commands: accuracy against exact line integrals, storage
//! precision, growth with the volume's side and the speed–accuracy trade.

pub mod accuracy;
pub mod adaptive_table;
pub mod growth;
pub mod precision;
pub mod timing;
pub mod trade;

/// The most timed repetitions a study takes per measurement (`--runs`,
/// `--repeats`): more would only hold memory for times no median needs.
pub const MAX_REPEATS: usize = 1000;

/// Refuse a repetition count `n` of `option` outside 1 to [`MAX_REPEATS`],
/// before any measurement or allocation.
///
/// # Errors
/// One line naming the option and the range.
pub fn check_repeats(option: &str, n: usize) -> Result<(), String> {
    if (1..=MAX_REPEATS).contains(&n) {
        Ok(())
    } else {
        Err(format!(
            "{option} {n}: must be at least 1 and at most {MAX_REPEATS}"
        ))
    }
}

/// Create the study's output directory if needed and make sure a file can
/// be written in it, before any measurement.
///
/// # Errors
/// One line naming the directory and the problem.
pub fn prepare_out_dir(dir: &std::path::Path) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| format!("--out-dir `{}`: {e}", dir.display());
    std::fs::create_dir_all(dir).map_err(|e| fail(&e))?;
    // A temporary file, removed at once: the directory is writable.
    crate::io::atomic::Output::create(&dir.join("probe")).map_err(|e| fail(&e))?;
    Ok(())
}
