//! Rust errors as Python exceptions, with the one-line messages `fvr`
//! prints after `fvr: error: `:
//!
//! - `MemoryError`: a job beyond the memory limit (the engine's
//!   [`PipelineError::OutOfMemory`] and the budget's [`OverBudget`]);
//! - `FileNotFoundError`: a VOLUME that is no file and no known name;
//! - `OSError`: a file that could not be read or decoded;
//! - `TypeError`: an argument of the wrong kind (a complex array, a string
//!   where numbers belong);
//! - `ValueError`: every other bad argument or setting.

use fvr_engine::memory::OverBudget;
use fvr_engine::PipelineError;
use pyo3::exceptions::{PyFileNotFoundError, PyMemoryError, PyOSError, PyTypeError, PyValueError};
use pyo3::PyErr;

/// The message as the CLI prints it: long lines cut in the middle, at most
/// a few lines ([`fvr_host::text::bounded`]).
fn bounded(message: &str) -> String {
    fvr_host::text::bounded(message)
}

/// A bad argument.
pub(crate) fn value(message: impl AsRef<str>) -> PyErr {
    PyValueError::new_err(bounded(message.as_ref()))
}

/// An argument of the wrong type.
pub(crate) fn type_error(message: impl AsRef<str>) -> PyErr {
    PyTypeError::new_err(bounded(message.as_ref()))
}

/// A job beyond the memory limit.
pub(crate) fn over_budget(e: &OverBudget) -> PyErr {
    PyMemoryError::new_err(bounded(&e.to_string()))
}

/// An engine error: `MemoryError` for memory, else `ValueError` (the
/// engine refuses settings, views and data, never files).
pub(crate) fn pipeline(e: PipelineError) -> PyErr {
    match e {
        PipelineError::OutOfMemory { .. } => PyMemoryError::new_err(bounded(&e.to_string())),
        other => value(other.to_string()),
    }
}

/// A refusal of `fvr_host::sources::load_volume` for `spec`: memory,
/// a missing file or name, a file that could not be read, or a bad
/// phantom parameter (`gaussians@3`).
pub(crate) fn load(spec: &str, message: String) -> PyErr {
    let text = bounded(&message);
    if message.starts_with("this job needs about") {
        PyMemoryError::new_err(text)
    } else if message.starts_with("no such file or volume") {
        PyFileNotFoundError::new_err(text)
    } else if std::path::Path::new(spec).exists() || message.contains("FVR_") {
        // A file given, or a data set's file (its environment variable).
        PyOSError::new_err(text)
    } else {
        PyValueError::new_err(text)
    }
}
