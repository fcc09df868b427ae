//! The one output writer: every file `fvr` writes goes through [`Output`].
//!
//! An output is written to a temporary file created exclusively
//! (`O_CREAT | O_EXCL`, so never through a planted link, never shared with
//! another job) under a short random name (`.fvr-XXXXXX.tmp`, well under
//! `NAME_MAX` whatever the output's name) in the output's own directory.
//! [`Output::commit`] flushes it, syncs it to the disk and renames it over
//! the output; until then the previous output is untouched. An output that
//! is dropped uncommitted (an error, a full disk) removes its temporary
//! file.
//!
//! On SIGINT, SIGTERM or SIGHUP the `fvr` program calls [`remove_live`]
//! before it exits: every temporary file still open is removed, and no
//! rename happens after it, so an interrupted job leaves the previous
//! outputs as they were and nothing beside them.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use tempfile::TempPath;

/// Buffer of the temporary file's writer.
const BUFFER_BYTES: usize = 1 << 20;

/// The temporary files not yet renamed or removed. Creating, renaming and
/// removing one hold this lock, so [`remove_live`] sees each file either
/// before it is renamed (and removes it) or not at all.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

fn forget(live: &mut Vec<PathBuf>, path: &Path) {
    live.retain(|p| p != path);
}

/// Remove every temporary file still open and block any later output from
/// being created or renamed into place. For a signal handler that exits
/// the process right after.
pub fn remove_live() {
    let guard = live();
    for path in guard.iter() {
        let _ = std::fs::remove_file(path);
    }
    // Held until the process exits: no output is created or renamed now.
    std::mem::forget(guard);
}

/// The directory an output is written in (`.` for a bare file name).
fn directory(target: &Path) -> &Path {
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

struct Inner {
    /// The open temporary file; `None` once committed.
    file: Option<BufWriter<File>>,
    /// Its name; removes the file when dropped.
    temp: Option<TempPath>,
    /// Its name, for the list of live files.
    name: PathBuf,
    target: PathBuf,
}

impl Drop for Inner {
    /// Uncommitted: the temporary file is removed.
    fn drop(&mut self) {
        if let Some(temp) = self.temp.take() {
            let mut live = live();
            drop(self.file.take());
            drop(temp);
            forget(&mut live, &self.name);
        }
    }
}

/// An output being written; see the module's documentation. Clones are
/// handles on the same file (for encoders that own their writer); the
/// temporary file is removed when the last handle of an uncommitted output
/// is dropped.
#[derive(Clone)]
pub struct Output {
    inner: Arc<Mutex<Inner>>,
}

impl Output {
    /// Start writing `target`: a new temporary file in its directory.
    ///
    /// # Errors
    /// The temporary file cannot be created (a missing or read-only
    /// directory, a full disk).
    pub fn create(target: &Path) -> io::Result<Self> {
        let mut live = live();
        let mut builder = tempfile::Builder::new();
        builder.prefix(".fvr-").suffix(".tmp");
        // The mode of a file made by `File::create` (0666 less the umask),
        // not tempfile's private 0600.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let (file, temp) = builder.tempfile_in(directory(target))?.into_parts();
        let name = temp.to_path_buf();
        live.push(name.clone());
        drop(live);
        Ok(Self {
            inner: Arc::new(Mutex::new(Inner {
                file: Some(BufWriter::with_capacity(BUFFER_BYTES, file)),
                temp: Some(temp),
                name,
                target: target.to_path_buf(),
            })),
        })
    }

    fn lock(&self) -> MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Flush, sync and rename the temporary file over the target.
    ///
    /// # Errors
    /// A write, sync or rename failure, or a target that is one of the
    /// job's inputs ([`super::inputs`]); the temporary file is then removed
    /// and the target left as it was.
    pub fn commit(self) -> io::Result<()> {
        let mut inner = self.lock();
        let (Some(file), Some(temp)) = (inner.file.take(), inner.temp.take()) else {
            return Err(io::Error::other("the output was already committed"));
        };
        let name = inner.name.clone();
        let target = inner.target.clone();
        // On any error `temp` is dropped, which removes the file.
        let renamed = file
            .into_inner()
            .map_err(io::IntoInnerError::into_error)
            .and_then(|file| file.sync_all())
            .and_then(|()| {
                let _live = live();
                // Never over a file this job read (checked before the render
                // too; this holds for every writer).
                super::inputs::check_output(&target).map_err(io::Error::other)?;
                temp.persist(&target).map_err(|e| e.error)
            });
        forget(&mut live(), &name);
        renamed?;
        // The rename itself reaches the disk with the directory (best effort:
        // not every file system lets a directory be synced).
        if let Ok(dir) = File::open(directory(&target)) {
            let _ = dir.sync_all();
        }
        Ok(())
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self.lock().file.as_mut() {
            Some(f) => f.write(buf),
            None => Err(io::Error::other("the output was already committed")),
        }
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        match self.lock().file.as_mut() {
            Some(f) => f.write_all(buf),
            None => Err(io::Error::other("the output was already committed")),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self.lock().file.as_mut() {
            Some(f) => f.flush(),
            None => Ok(()),
        }
    }
}

/// Write `bytes` to `target` through an [`Output`].
///
/// # Errors
/// As [`Output::create`] and [`Output::commit`].
pub fn write_bytes(target: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut out = Output::create(target)?;
    out.write_all(bytes)?;
    out.commit()
}

/// [`write_bytes`] with the error as one line naming `target`.
///
/// # Errors
/// As [`write_bytes`].
pub fn write_text(target: &Path, text: &str) -> Result<(), String> {
    write_bytes(target, text.as_bytes())
        .map_err(|e| format!("cannot write `{}`: {e}", target.display()))
}
