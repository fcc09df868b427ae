//! Progress bars on standard error for steps that can take seconds:
//! loading, preprocessing, turntable frames.
//!
//! Bars are drawn only when standard error is a terminal and the user has
//! not asked for quiet (`--quiet`, [`set_quiet`]); otherwise every bar is
//! [`ProgressBar::hidden`], which costs nothing. Finished bars are cleared,
//! so only results and errors stay on screen.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

static QUIET: AtomicBool = AtomicBool::new(false);

/// Turn every later bar off (`--quiet`).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Whether `--quiet` was given (notes on stderr are left out too).
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// Whether bars are drawn: stderr is a terminal and not quiet.
pub fn enabled() -> bool {
    !QUIET.load(Ordering::Relaxed) && std::io::stderr().is_terminal()
}

fn styled(bar: ProgressBar, template: &str, message: &str) -> ProgressBar {
    let style = ProgressStyle::with_template(template)
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    bar.set_style(style);
    bar.set_message(message.to_owned());
    bar
}

/// A bar counting bytes (its length is set by the reader).
pub fn bytes(message: &str) -> ProgressBar {
    if !enabled() {
        return ProgressBar::hidden();
    }
    styled(
        ProgressBar::new(0),
        "{msg:>12} [{bar:30}] {bytes}/{total_bytes} ({eta})",
        message,
    )
}

/// A bar counting `len` items, e.g. frames.
pub fn count(len: u64, message: &str) -> ProgressBar {
    if !enabled() {
        return ProgressBar::hidden();
    }
    styled(
        ProgressBar::new(len),
        "{msg:>12} [{bar:30}] {pos}/{len} ({eta})",
        message,
    )
}

/// A spinner with the elapsed time, for a step with no measurable parts
/// (the core's one-call preprocessing).
pub fn spinner(message: &str) -> ProgressBar {
    if !enabled() {
        return ProgressBar::hidden();
    }
    let bar = styled(
        ProgressBar::new_spinner(),
        "{msg:>12} {spinner} {elapsed}",
        message,
    );
    bar.enable_steady_tick(Duration::from_millis(100));
    bar
}
