//! SIGINT, SIGTERM and SIGHUP: stop at once, leaving the previous outputs
//! as they were.
//!
//! The handler (on the `ctrlc` crate's own thread) removes every temporary
//! output file still open and blocks any later rename
//! ([`fvr_host::io::atomic::remove_live`]), prints one line and exits with
//! status 130 (128 + SIGINT, the shells' convention for an interrupted
//! command; the same status for the other two, which the crate does not
//! tell apart).

use std::io::Write;

/// Exit status after a signal.
pub(crate) const INTERRUPTED: i32 = 130;

/// Install the handler; once per process (a second call changes nothing).
pub(crate) fn install() {
    let _ = ctrlc::set_handler(|| {
        fvr_host::io::atomic::remove_live();
        let _ = writeln!(
            std::io::stderr(),
            "fvr: interrupted; unfinished outputs removed, earlier files left as they were"
        );
        std::process::exit(INTERRUPTED);
    });
}
