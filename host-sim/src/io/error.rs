//! The error type of volume I/O: NRRD, raw, and the other formats of
//! [`crate::io`].

use std::fmt;
use std::io;
use std::path::PathBuf;

/// What went wrong reading or writing a volume.
///
/// `Display` names the header field or the problem, e.g.
/// ``NRRD field `sizes`: expected 3 positive integers, got `12 x` ``, and the
/// file path when the error came from [`read_nrrd`](crate::io::nrrd::read_nrrd),
/// [`read_raw`](crate::io::nrrd::read_raw) or [`write_nrrd_f32`](crate::io::nrrd::write_nrrd_f32).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IoError {
    /// An operating-system error while opening, reading or writing.
    #[error("I/O error: {source}")]
    Io {
        /// The underlying error.
        #[from]
        source: io::Error,
    },
    /// The first line is not a NRRD magic `NRRD0001` to `NRRD0005`.
    #[error("{}", bad_magic(found))]
    BadMagic {
        /// The start of the first line (control characters escaped).
        found: String,
    },
    /// A header line that is not a comment, field or key/value pair, or a
    /// header that is too long or not terminated by a blank line.
    #[error("NRRD header line {line}: {problem}")]
    Header {
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        problem: String,
    },
    /// A required header field is absent.
    #[error("NRRD field `{field}`: required field is missing")]
    MissingField {
        /// The canonical field name, e.g. `sizes`.
        field: &'static str,
    },
    /// A header field has a malformed or unsupported value.
    #[error("NRRD field `{field}`: {problem}")]
    Field {
        /// The canonical field name, e.g. `sizes`.
        field: &'static str,
        /// What is wrong with the value.
        problem: String,
    },
    /// The header refers to a detached data file, but was parsed from memory
    /// without a path to resolve it against.
    #[error(
        "NRRD field `data file`: the samples are in the separate file `{file}`, which can only be found from the header's path (read the header as a file)"
    )]
    DetachedData {
        /// The value of the `data file` field.
        file: String,
    },
    /// Fewer data bytes than the sizes and sample type call for.
    #[error("truncated data: expected {expected} bytes of samples{}, found {found}", if *gzip { " after gzip decompression" } else { "" })]
    Truncated {
        /// Bytes of sample data needed.
        expected: u64,
        /// Bytes of sample data found.
        found: u64,
        /// Whether the counts are of gzip-decompressed data.
        gzip: bool,
    },
    /// Decoding would need more memory than allowed.
    #[error("volume too large: decoding would need {needed} bytes ({}) of memory, the limit is {limit} bytes ({})", Gib(*needed), Gib(*limit))]
    TooLarge {
        /// Bytes the decoded volume (plus its raw samples) would need.
        needed: u64,
        /// The memory limit in bytes.
        limit: u64,
    },
    /// The job (this volume and what will be built from it) would exceed
    /// the memory limit.
    #[error(transparent)]
    OverBudget(#[from] crate::budget::OverBudget),
    /// The gzip-encoded data could not be decompressed.
    #[error("corrupt or truncated gzip stream: {source}")]
    Gzip {
        /// The decompressor's error.
        source: io::Error,
    },
    /// A NaN or infinite sample, or a double too large for `f32`.
    #[error("{}", non_finite(*voxel, *value))]
    NonFinite {
        /// Voxel index `(i, j, k)` of the first offending sample.
        voxel: [usize; 3],
        /// Its value as stored in the file.
        value: f64,
    },
    /// Invalid arguments: raw dimensions, sizes for writing, type names.
    #[error("{problem}")]
    InvalidArgument {
        /// What is wrong.
        problem: String,
    },
    /// A malformed or unsupported field of a format other than NRRD.
    #[error("{format} field `{field}`: {problem}")]
    Format {
        /// The format and the part of the file, e.g. `NIfTI-1 header`.
        format: &'static str,
        /// The field, e.g. `pixdim`.
        field: &'static str,
        /// What is wrong with it.
        problem: String,
    },
    /// A file whose format could not be recognised.
    #[error("{problem}")]
    UnknownFormat {
        /// What was seen, and what is supported.
        problem: String,
    },
    /// Another error, while reading or writing the file at `path`.
    #[error("{}: {source}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: Box<IoError>,
    },
}

impl IoError {
    /// Attach a file path to this error.
    pub(crate) fn in_file(self, path: &std::path::Path) -> Self {
        IoError::File {
            path: path.to_path_buf(),
            source: Box::new(self),
        }
    }

    /// The innermost error, looking through [`IoError::File`].
    pub fn root(&self) -> &IoError {
        match self {
            IoError::File { source, .. } => source.root(),
            other => other,
        }
    }
}

/// The message of [`IoError::BadMagic`].
fn bad_magic(found: &str) -> String {
    if found.is_empty() {
        "not a NRRD file: empty first line (expected magic `NRRD0001` to `NRRD0005`)".into()
    } else {
        format!("not a NRRD file: magic line `{found}` (expected `NRRD0001` to `NRRD0005`)")
    }
}

/// The message of [`IoError::NonFinite`]: a double too large for `f32`, or
/// NaN/Inf.
fn non_finite([i, j, k]: [usize; 3], value: f64) -> String {
    if value.is_finite() {
        format!("sample {value:e} at voxel ({i}, {j}, {k}) does not fit in f32 (it would become infinite)")
    } else {
        format!("non-finite sample {value} at voxel ({i}, {j}, {k}); NaN/Inf data would corrupt the rendering")
    }
}

struct Gib(u64);

impl fmt::Display for Gib {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.2} GiB", self.0 as f64 / (1u64 << 30) as f64)
    }
}

/// A header value fit for an error message: at most 60 characters, all but
/// printable ASCII escaped.
pub(crate) fn excerpt(s: &str) -> String {
    const MAX_CHARS: usize = 60;
    let mut out = String::new();
    for (n, c) in s.chars().enumerate() {
        if n == MAX_CHARS {
            out.push('…');
            break;
        }
        // Only printable ASCII is echoed: a binary file (a PNG given as a
        // NRRD) must not put raw bytes or replacement characters on a
        // terminal, so anything else is escaped (`\r`, `\u{fffd}`).
        if !(c == ' ' || c.is_ascii_graphic()) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// A malformed or unsupported field of a non-NRRD format.
#[cold]
pub(crate) fn format_error(
    format: &'static str,
    field: &'static str,
    problem: impl Into<String>,
) -> IoError {
    IoError::Format {
        format,
        field,
        problem: problem.into(),
    }
}

/// The first `len` bytes of `bytes`, the fixed-size header of `format`;
/// a file too short for it is an error on `field`.
pub(crate) fn header<'a>(
    format: &'static str,
    field: &'static str,
    bytes: &'a [u8],
    len: usize,
) -> Result<&'a [u8], IoError> {
    bytes.get(..len).ok_or_else(|| {
        format_error(
            format,
            field,
            format!("the header needs {len} bytes, the file has {}", bytes.len()),
        )
    })
}

/// A malformed or unsupported field value.
#[cold]
pub(crate) fn field_error(field: &'static str, problem: impl Into<String>) -> IoError {
    IoError::Field {
        field,
        problem: problem.into(),
    }
}

/// A malformed header line.
#[cold]
pub(crate) fn header_error(line: usize, problem: impl Into<String>) -> IoError {
    IoError::Header {
        line,
        problem: problem.into(),
    }
}

/// Invalid caller-supplied arguments.
#[cold]
pub(crate) fn invalid_argument(problem: impl Into<String>) -> IoError {
    IoError::InvalidArgument {
        problem: problem.into(),
    }
}
