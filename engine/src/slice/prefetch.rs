//! Software prefetch of spectrum cells for the strip, column and exact
//! walks ([`crate::slice::strip`], [`crate::slice::column`],
//! [`crate::slice::exact`]).
//!
//! Those walks reduce the cells of one line `w` at a time, a run of a few
//! to a few dozen cells per plane. On a spectrum larger than the last-level
//! cache, each line's first read of a plane the walk has not visited yet
//! misses to DRAM, and the reduction of that line cannot start before it
//! arrives; the lines lie a plane stride or a row stride apart, a pattern
//! the hardware prefetchers do not follow. Asking for the lines a few ahead
//! overlaps those misses with the reduction of the current one.
//!
//! The prefetch is a hint: it reads nothing into the program, so the walks'
//! values are the same bits with or without it (`tests/fast_strip.rs`).
//! `safe_arch` wraps the instruction safely on x86 and x86-64; other
//! targets go without it.

/// Ask the cache hierarchy for the cache line that holds `data[index]`:
/// nothing when `index` is out of bounds or the target has no prefetch.
#[inline(always)]
pub(crate) fn prefetch<S>(data: &[S], index: usize) {
    #[cfg(all(
        any(target_arch = "x86", target_arch = "x86_64"),
        target_feature = "sse"
    ))]
    if let Some(cell) = data.get(index) {
        safe_arch::prefetch_t0(cell);
    }
    #[cfg(not(all(
        any(target_arch = "x86", target_arch = "x86_64"),
        target_feature = "sse"
    )))]
    let _ = (data, index);
}
