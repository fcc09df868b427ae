//! The clock the renderer times its stages with.
//!
//! `std::time::Instant` panics on `wasm32-unknown-unknown` (the target has
//! no clock without JavaScript), where the browser viewer (`web/`) runs this
//! engine. There every duration reads zero and the page times its views
//! itself with `performance.now()`; everywhere else this is `std`'s clock.

#[cfg(not(all(target_arch = "wasm32", target_os = "unknown")))]
pub(crate) use std::time::Instant;

/// A clock that never advances: every [`Instant::elapsed`] is zero.
#[cfg(all(target_arch = "wasm32", target_os = "unknown"))]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Instant;

#[cfg(all(target_arch = "wasm32", target_os = "unknown"))]
impl Instant {
    /// The (only) instant.
    pub(crate) fn now() -> Self {
        Self
    }

    /// Zero: there is no clock to read.
    pub(crate) fn elapsed(&self) -> std::time::Duration {
        std::time::Duration::ZERO
    }
}
