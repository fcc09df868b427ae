//! Output paths checked before any work: the right extension, a directory
//! that exists, never an input file, and (for paths from scene files) inside
//! the scene's directory.

use std::path::{Path, PathBuf};

/// Why an output path is refused. `Display` is one line naming the path.
#[derive(Debug, PartialEq, Eq)]
pub enum PathError {
    /// The extension is not one the command writes.
    Extension {
        /// The path.
        path: PathBuf,
        /// The extensions allowed.
        allowed: &'static [&'static str],
    },
    /// The output would replace an input.
    SameAsInput {
        /// The output path.
        output: PathBuf,
        /// The input it names.
        input: PathBuf,
    },
    /// The output's directory does not exist.
    NoDirectory {
        /// The path.
        path: PathBuf,
    },
    /// The output exists and is not a regular file.
    NotAFile {
        /// The path.
        path: PathBuf,
    },
}

impl std::fmt::Display for PathError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PathError::Extension { path, allowed } => write!(
                f,
                "output {}: the extension must be one of {}",
                path.display(),
                allowed
                    .iter()
                    .map(|e| format!(".{e}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            PathError::SameAsInput { output, input } => write!(
                f,
                "output {} is the input {}: refusing to overwrite an input",
                output.display(),
                input.display()
            ),
            PathError::NoDirectory { path } => {
                write!(f, "output {}: its directory does not exist", path.display())
            }
            PathError::NotAFile { path } => {
                write!(
                    f,
                    "output {} exists and is not a regular file",
                    path.display()
                )
            }
        }
    }
}

impl std::error::Error for PathError {}

/// Check `output` before any work: its extension is in `allowed`
/// (case-insensitive), its directory exists, it is not an existing
/// non-file, and it is none of `inputs` (compared by file identity, so links
/// and `..` do not hide an input).
///
/// # Errors
/// The first [`PathError`] found.
pub fn check_output(
    output: &Path,
    allowed: &'static [&'static str],
    inputs: &[&Path],
) -> Result<(), PathError> {
    let ext_ok = output
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| allowed.iter().any(|a| a.eq_ignore_ascii_case(e)));
    if !ext_ok {
        return Err(PathError::Extension {
            path: output.to_path_buf(),
            allowed,
        });
    }
    let dir = match output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(PathError::NoDirectory {
            path: output.to_path_buf(),
        });
    }
    if let Ok(meta) = std::fs::metadata(output) {
        if !meta.is_file() {
            return Err(PathError::NotAFile {
                path: output.to_path_buf(),
            });
        }
        for input in inputs {
            if same_file(output, input) {
                return Err(PathError::SameAsInput {
                    output: output.to_path_buf(),
                    input: input.to_path_buf(),
                });
            }
        }
    }
    Ok(())
}

/// Whether two paths name one existing file (device and inode on Unix,
/// canonical paths elsewhere).
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (a.canonicalize(), b.canonicalize()) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

/// `written` joined to `base` if it stays inside `base`: relative, and no
/// `..` that climbs above it. `None` otherwise.
pub fn inside(base: &Path, written: &Path) -> Option<PathBuf> {
    use std::path::Component;
    let mut depth = 0usize;
    for c in written.components() {
        match c {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir if depth > 0 => depth -= 1,
            _ => return None,
        }
    }
    Some(base.join(written))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_inputs_and_scene_paths() {
        let dir = std::env::temp_dir().join(format!("fvr-paths-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let vol = dir.join("vol.nrrd");
        std::fs::write(&vol, b"x").unwrap();
        const OUT: &[&str] = &["png", "nrrd"];
        assert!(check_output(&dir.join("a.png"), OUT, &[&vol]).is_ok());
        assert!(check_output(&dir.join("a.PNG"), OUT, &[&vol]).is_ok());
        assert!(matches!(
            check_output(&dir.join("a.txt"), OUT, &[]),
            Err(PathError::Extension { .. })
        ));
        let sneaky = dir.join(".").join("vol.nrrd");
        assert!(matches!(
            check_output(&sneaky, OUT, &[&vol]),
            Err(PathError::SameAsInput { .. })
        ));
        assert!(matches!(
            check_output(&dir.join("missing/a.png"), OUT, &[]),
            Err(PathError::NoDirectory { .. })
        ));
        let out = Some(dir.join("out/a.png"));
        assert_eq!(inside(&dir, Path::new("out/a.png")), out);
        assert!(inside(&dir, Path::new("a/../b.png")).is_some());
        assert!(inside(&dir, Path::new("a/../../victim.txt")).is_none());
        assert!(inside(&dir, Path::new("/etc/passwd")).is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
