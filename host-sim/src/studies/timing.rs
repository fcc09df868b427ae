//! Wall-clock timing for the measuring commands (`fvr adaptive-table`,
//! `fvr growth`). Criterion benches time the same work more carefully;
//! these give one-command tables, and ratios within one run are what to
//! compare.

use std::time::Instant;

/// The median of `runs` timed calls of `f`, in ms (the upper median for an
/// even count).
///
/// # Errors
/// The first error `f` returns; `runs` of 0.
pub fn median_ms(runs: usize, mut f: impl FnMut() -> Result<(), String>) -> Result<f64, String> {
    if runs == 0 {
        return Err("at least one timed run is needed".into());
    }
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs {
        let t = Instant::now();
        f()?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}
