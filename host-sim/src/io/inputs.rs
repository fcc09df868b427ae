//! The job's inputs: every file the process opens to read (a volume, the
//! data file a detached NRRD header names, a named data set, a DICOM
//! series' files, a scene, a depth profile) is recorded by file identity
//! (device and inode on Unix), and no output may be one of them.
//!
//! [`crate::io::open_file`] records each file it opens. The commands check
//! their outputs with [`check_output`] once the inputs are read, before the
//! render; [`crate::io::atomic::Output::commit`] checks again before it
//! renames, so no path can replace an input.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

use super::paths::PathError;

/// A file's identity: (device, inode) on Unix, its canonical path elsewhere.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Id {
    #[cfg(unix)]
    Inode(u64, u64),
    #[cfg(not(unix))]
    Path(PathBuf),
}

impl Id {
    fn of(path: &Path) -> Option<Self> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let m = std::fs::metadata(path).ok()?;
            Some(Id::Inode(m.dev(), m.ino()))
        }
        #[cfg(not(unix))]
        {
            path.canonicalize().ok().map(Id::Path)
        }
    }
}

/// The inputs recorded so far, with the path each was opened by.
static INPUTS: Mutex<Vec<(Id, PathBuf)>> = Mutex::new(Vec::new());

/// Record `path` (an existing file) as an input of this job.
pub fn record(path: &Path) {
    if let Some(id) = Id::of(path) {
        let mut inputs = INPUTS.lock().unwrap_or_else(PoisonError::into_inner);
        if !inputs.iter().any(|(i, _)| *i == id) {
            inputs.push((id, path.to_path_buf()));
        }
    }
}

/// The input that `output` names, if it names one (following links, so a
/// link to an input or a hard link to it is that input).
pub fn input_named_by(output: &Path) -> Option<PathBuf> {
    let id = Id::of(output)?;
    let inputs = INPUTS.lock().unwrap_or_else(PoisonError::into_inner);
    inputs
        .iter()
        .find(|(i, _)| *i == id)
        .map(|(_, p)| p.clone())
}

/// Refuse `output` if it is one of the inputs recorded so far.
///
/// # Errors
/// [`PathError::SameAsInput`], naming the output and the input.
pub fn check_output(output: &Path) -> Result<(), PathError> {
    match input_named_by(output) {
        Some(input) => Err(PathError::SameAsInput {
            output: output.to_path_buf(),
            input,
        }),
        None => Ok(()),
    }
}
