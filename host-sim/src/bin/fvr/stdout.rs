//! Standard output that a closed pipe cannot crash.
//!
//! `println!` panics when standard output is a pipe whose reader has gone
//! (`fvr render … --stats | head -1`). Every line `fvr` prints goes through
//! [`say!`] and [`say_part!`] instead: on a broken pipe the rest of the
//! printed text is dropped quietly, the job goes on, its output files are
//! written whole, and the exit status is the job's own (0 on success).

use std::fmt::Arguments;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once standard output is found closed; nothing is printed after.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// Write `args` to standard output, dropping it (and everything after)
/// once the reader has gone (`EPIPE`). Other write errors (a full disk
/// behind a redirection) are dropped the same way: printed text is a
/// report, never the job's result.
pub(crate) fn write(args: Arguments<'_>) {
    if CLOSED.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    if out.write_fmt(args).and_then(|()| out.flush()).is_err() {
        CLOSED.store(true, Ordering::Relaxed);
    }
}

/// `println!` that a closed pipe cannot crash.
macro_rules! say {
    ($($t:tt)*) => {
        $crate::stdout::write(format_args!("{}\n", format_args!($($t)*)))
    };
}

/// `print!` that a closed pipe cannot crash.
macro_rules! say_part {
    ($($t:tt)*) => {
        $crate::stdout::write(format_args!($($t)*))
    };
}
