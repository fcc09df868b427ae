//! Volume files: format detection and the readers other than NRRD.
//!
//! [`read_volume`] recognises a file by its magic bytes, then by its
//! extension, and reads it into an `f32` [`Volume`] with its voxel spacing
//! in millimetres:
//!
//! | format | extensions | magic | spacing from |
//! |---|---|---|---|
//! | NRRD ([`crate::io::nrrd`]) | `.nrrd`, `.nhdr` | `NRRD000x` | `spacings` or `space directions` |
//! | NIfTI-1 ([`nifti`]) | `.nii`, `.nii.gz`, `.hdr` + `.img` | `sizeof_hdr` 348 and `n+1`/`ni1` | `pixdim`, in `xyzt_units` |
//! | VolPack density ([`den`]) | `.den`, `.den.gz` | version 1 (either byte order) | none (1 mm) |
//! | InVesalius project ([`inv3`]) | `.inv3` | gzip of a tar holding `main.plist` | `spacing` in `main.plist` |
//! | DICOM series ([`dicom`]) | a directory, or one `.dcm` file of the series | `DICM` at byte 128 | `PixelSpacing` and slice positions |
//!
//! Headerless raw files have no magic: read them with
//! [`crate::io::nrrd::read_raw`] and an explicit layout.
//!
//! Every reader treats its input as untrusted: sizes are checked for zero
//! and overflow, the memory needed is checked against
//! [`crate::budget::limit_bytes`] before allocating, gzip data is never
//! decompressed far beyond what the header calls for, and every problem is
//! an [`IoError`] that names the file and the field.

pub mod atomic;
pub mod c_array;
pub mod den;
pub mod dicom;
mod error;
pub mod fvrs;
pub mod inputs;
pub mod inv3;
pub mod nifti;
mod nifti_encode;
pub mod npy;
pub mod nrrd;
pub mod paths;
pub mod stack;

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

use flate2::bufread::MultiGzDecoder;
use indicatif::ProgressBar;

pub use error::IoError;
use fvr_engine::volume::Volume;

/// Read buffer for files.
const FILE_BUFFER_BYTES: usize = 1 << 16;

/// Decompressed bytes read past the expected data, to reach the end of a
/// gzip member and check its CRC.
const GZIP_MARGIN: u64 = 4096;

/// Bytes looked at to recognise a format (a tar header is 512 bytes).
const SNIFF_BYTES: usize = 512;

/// A volume file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// NRRD, attached (`.nrrd`) or detached (`.nhdr`) header.
    Nrrd,
    /// NIfTI-1, single file (`.nii`, `.nii.gz`) or pair (`.hdr` + `.img`).
    Nifti,
    /// VolPack density file (`.den`, `.den.gz`).
    Den,
    /// InVesalius 3 project (`.inv3`).
    Inv3,
    /// DICOM series (a directory, or one file of the series).
    Dicom,
}

impl Format {
    /// Human name.
    pub fn name(self) -> &'static str {
        match self {
            Format::Nrrd => "NRRD",
            Format::Nifti => "NIfTI-1",
            Format::Den => "VolPack .den",
            Format::Inv3 => "InVesalius .inv3",
            Format::Dicom => "DICOM series",
        }
    }

    /// The format a file name's extension suggests, if any.
    pub fn from_extension(path: &Path) -> Option<Format> {
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        let name = name.strip_suffix(".gz").unwrap_or(&name);
        let ext = name.rsplit_once('.')?.1;
        Some(match ext {
            "nrrd" | "nhdr" => Format::Nrrd,
            "nii" | "hdr" => Format::Nifti,
            "den" => Format::Den,
            "inv3" => Format::Inv3,
            "dcm" | "dicom" => Format::Dicom,
            _ => return None,
        })
    }

    /// The format the first bytes of a file show, if any. `head` is the
    /// start of the file, already decompressed if it was gzip.
    /// `gzip` says whether it was.
    pub fn from_magic(head: &[u8], gzip: bool) -> Option<Format> {
        if head.starts_with(b"NRRD000") {
            return Some(Format::Nrrd);
        }
        if nifti::has_magic(head) {
            return Some(Format::Nifti);
        }
        if !gzip && dicom::has_magic(head) {
            return Some(Format::Dicom);
        }
        if gzip && head.get(257..262) == Some(b"ustar") {
            return Some(Format::Inv3);
        }
        if den::has_magic(head) {
            return Some(Format::Den);
        }
        None
    }
}

/// The supported formats, for error messages.
pub const FORMATS_HELP: &str = "NRRD (.nrrd, .nhdr), NIfTI-1 (.nii, .nii.gz, .hdr/.img), \
VolPack (.den, .den.gz), InVesalius (.inv3) or a DICOM series (a directory, or one of its files); \
headerless raw files need --raw-dims";

/// Recognise the format of the file at `path` by its magic bytes, then by
/// its extension.
///
/// # Errors
/// The file cannot be read, or neither its content nor its name is of a
/// supported format.
pub fn detect(path: &Path) -> Result<Format, IoError> {
    if path.is_dir() {
        return Ok(Format::Dicom);
    }
    let go = || -> Result<Format, IoError> {
        let mut reader = BufReader::new(open_file(path)?);
        let (head, gzip) = sniff(&mut reader)?;
        Format::from_magic(&head, gzip)
            .or_else(|| Format::from_extension(path))
            .ok_or_else(|| unknown_format(&head, gzip))
    };
    go().map_err(|e| e.in_file(path))
}

/// The first [`SNIFF_BYTES`] of `reader` (decompressed if it is gzip, as far
/// as the stream allows) and whether it was gzip.
fn sniff<R: BufRead>(reader: &mut R) -> Result<(Vec<u8>, bool), IoError> {
    let gzip = is_gzip(reader)?;
    let mut head = vec![0; SNIFF_BYTES];
    let got = if gzip {
        // A corrupt stream still has a format; its reader reports the damage.
        let mut gz = MultiGzDecoder::new(reader);
        read_up_to(&mut gz, &mut head).unwrap_or(0)
    } else {
        read_up_to(reader, &mut head)?
    };
    head.truncate(got);
    Ok((head, gzip))
}

/// Read until `buf` is full or the input ends; the bytes read.
fn read_up_to<R: Read>(reader: &mut R, buf: &mut [u8]) -> io::Result<usize> {
    nrrd::read_full(reader, buf)
}

#[cold]
fn unknown_format(head: &[u8], gzip: bool) -> IoError {
    let shown: String = head
        .iter()
        .take(8)
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ");
    let what = if gzip {
        "a gzip stream whose content"
    } else {
        "content that"
    };
    IoError::UnknownFormat {
        problem: format!(
            "unknown volume format: {what} starts with bytes [{shown}] and the file name has no known \
             extension; supported: {FORMATS_HELP}"
        ),
    }
}

/// Read the volume file at `path`, whatever its supported format.
///
/// # Errors
/// Unreadable, unrecognised, malformed or truncated files, with the path
/// and the field at fault.
pub fn read_volume(path: &Path) -> Result<Volume, IoError> {
    read_volume_with_progress(path, &ProgressBar::hidden())
}

/// [`read_volume`], advancing `progress` by the bytes read from disk (its
/// length is set to the file's size).
pub fn read_volume_with_progress(path: &Path, progress: &ProgressBar) -> Result<Volume, IoError> {
    match detect(path)? {
        Format::Nrrd => nrrd::read_nrrd_with_progress(path, progress),
        Format::Nifti => nifti::read_nifti_with_progress(path, progress),
        Format::Den => den::read_den_with_progress(path, progress),
        Format::Inv3 => inv3::read_inv3_with_progress(path, progress),
        Format::Dicom => dicom::read_dicom_with_progress(path, progress),
    }
}

/// Whether unit vectors (two or three) are far from linearly dependent: the
/// area or volume they span is at least 1e-3 of a unit square or cube.
pub(crate) fn spans_independent_axes(units: &[[f64; 3]]) -> bool {
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    match units {
        [a, b] => cross(*a, *b).iter().map(|c| c * c).sum::<f64>().sqrt() >= 1e-3,
        [a, b, c] => {
            let n = cross(*a, *b);
            (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]).abs() >= 1e-3
        }
        _ => true,
    }
}

/// Open `path` for reading if it is a regular file, and record it as an
/// input of the job ([`inputs`]). A FIFO, a device such as `/dev/zero` or a
/// directory is refused before it is opened: reading one could block or
/// never end.
///
/// # Errors
/// The path does not exist, cannot be opened, or is not a regular file.
pub fn open_file(path: &Path) -> io::Result<File> {
    if !std::fs::metadata(path)?.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "not a regular file (a directory, FIFO or device cannot be read as data)",
        ));
    }
    let file = File::open(path)?;
    inputs::record(path);
    Ok(file)
}

/// The text of the small file `path` (a scene or a depth profile): a
/// regular file of at most `max` bytes.
///
/// # Errors
/// One line naming `what`, the path and the problem.
pub fn read_small_text(path: &Path, what: &str, max: u64) -> Result<String, String> {
    let fail = |e: &dyn std::fmt::Display| format!("cannot read {what} `{}`: {e}", path.display());
    let file = open_file(path).map_err(|e| fail(&e))?;
    let mut text = String::new();
    file.take(max + 1)
        .read_to_string(&mut text)
        .map_err(|e| fail(&e))?;
    if text.len() as u64 > max {
        return Err(fail(&format!("larger than {max} bytes")));
    }
    Ok(text)
}

/// Open `path` for reading, counting the bytes read into `progress`.
pub(crate) fn open_counted(
    path: &Path,
    progress: &ProgressBar,
) -> Result<BufReader<impl Read>, IoError> {
    let file = open_file(path)?;
    progress.set_length(file.metadata().map(|m| m.len()).unwrap_or(0));
    Ok(BufReader::with_capacity(
        FILE_BUFFER_BYTES,
        progress.wrap_read(file),
    ))
}

/// Whether `reader` starts with the gzip magic `1f 8b`; nothing is consumed.
pub(crate) fn is_gzip<R: BufRead>(reader: &mut R) -> Result<bool, IoError> {
    // `fill_buf` may return fewer than 2 bytes only at the end of input for
    // the readers used here (files and slices, buffers >= 2 bytes).
    let buf = reader.fill_buf()?;
    Ok(buf.starts_with(&[0x1f, 0x8b]))
}

/// A stream that is either plain or gzip-compressed (detected from its
/// magic), so that one reader serves `.den` and `.den.gz`, `.nii` and
/// `.nii.gz`.
pub(crate) enum MaybeGzip<R: BufRead> {
    /// Uncompressed.
    Plain(R),
    /// Gzip, decompressed on the fly (several members allowed); boxed, as
    /// zlib-rs's inflate state is a few hundred bytes.
    Gzip(Box<BufReader<MultiGzDecoder<R>>>),
}

impl<R: BufRead> MaybeGzip<R> {
    /// Wrap `reader`, looking at its first bytes.
    pub(crate) fn new(mut reader: R) -> Result<Self, IoError> {
        Ok(if is_gzip(&mut reader)? {
            MaybeGzip::Gzip(Box::new(BufReader::with_capacity(
                FILE_BUFFER_BYTES,
                MultiGzDecoder::new(reader),
            )))
        } else {
            MaybeGzip::Plain(reader)
        })
    }

    /// Whether the data is gzip-compressed.
    pub(crate) fn is_gzip(&self) -> bool {
        matches!(self, MaybeGzip::Gzip(_))
    }

    /// The source kind, for error messages from [`nrrd::decode_stream`].
    pub(crate) fn source(&self) -> nrrd::Source {
        if self.is_gzip() {
            nrrd::Source::Gzip
        } else {
            nrrd::Source::Raw
        }
    }

    /// Fill `buf` exactly, or explain what is missing: `what` names the
    /// part of the file (e.g. `NIfTI-1 header`).
    pub(crate) fn read_exact_or(
        &mut self,
        buf: &mut [u8],
        format: &'static str,
        what: &'static str,
    ) -> Result<(), IoError> {
        let got = nrrd::read_full(self, buf).map_err(|e| self.read_error(e))?;
        if got < buf.len() {
            let after = if self.is_gzip() {
                " after gzip decompression"
            } else {
                ""
            };
            return Err(nrrd::format_error(
                format,
                what,
                format!(
                    "the file ends after {got} bytes{after}; the {what} needs {}",
                    buf.len()
                ),
            ));
        }
        Ok(())
    }

    /// Skip `count` bytes, or explain what is missing.
    pub(crate) fn skip(
        &mut self,
        count: u64,
        format: &'static str,
        field: &'static str,
    ) -> Result<(), IoError> {
        let skipped = io::copy(&mut self.by_ref().take(count), &mut io::sink())
            .map_err(|e| self.read_error(e))?;
        if skipped < count {
            return Err(nrrd::format_error(
                format,
                field,
                format!("points {count} bytes on, but the file ends after {skipped}"),
            ));
        }
        Ok(())
    }

    /// For gzip, decompress what is left of the member (at most
    /// [`GZIP_MARGIN`] bytes) so that its CRC is verified.
    pub(crate) fn finish(self) -> Result<(), IoError> {
        match self {
            MaybeGzip::Plain(_) => Ok(()),
            MaybeGzip::Gzip(mut gz) => {
                io::copy(&mut gz.by_ref().take(GZIP_MARGIN), &mut io::sink())
                    .map(drop)
                    .map_err(|source| IoError::Gzip { source })
            }
        }
    }

    #[cold]
    fn read_error(&self, source: io::Error) -> IoError {
        if self.is_gzip() {
            IoError::Gzip { source }
        } else {
            IoError::Io { source }
        }
    }
}

impl<R: BufRead> Read for MaybeGzip<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self {
            MaybeGzip::Plain(r) => r.read(buf),
            MaybeGzip::Gzip(r) => r.read(buf),
        }
    }
}

impl<R: BufRead> BufRead for MaybeGzip<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        match self {
            MaybeGzip::Plain(r) => r.fill_buf(),
            MaybeGzip::Gzip(r) => r.fill_buf(),
        }
    }
    fn consume(&mut self, amt: usize) {
        match self {
            MaybeGzip::Plain(r) => r.consume(amt),
            MaybeGzip::Gzip(r) => r.consume(amt),
        }
    }
}

/// Where the sizes of a volume come from, for error messages: the format
/// and the field, e.g. `("NIfTI-1 header", "dim")`.
pub(crate) type SizeField = (&'static str, &'static str);

/// `dims` if none is zero and the data size in bytes fits in `usize`:
/// the sample count and the byte count.
pub(crate) fn check_dims(
    dims: [usize; 3],
    ty: nrrd::SampleType,
    (format, field): SizeField,
) -> Result<(usize, usize), IoError> {
    if let Some(axis) = dims.iter().position(|&d| d == 0) {
        return Err(nrrd::format_error(
            format,
            field,
            format!("size {axis} is 0 in {dims:?}; every size must be at least 1"),
        ));
    }
    dims.iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .and_then(|count| Some((count, count.checked_mul(ty.size_bytes())?)))
        .ok_or_else(|| {
            nrrd::format_error(
                format,
                field,
                format!(
                    "sizes {dims:?} of {}-byte samples overflow the address space",
                    ty.size_bytes()
                ),
            )
        })
}

/// Decode the samples of a volume of `dims` (checked by [`check_dims`] and
/// against the memory limit first), of type `ty` in `endian` order, from
/// `reader`, then check the rest of a gzip member.
pub(crate) fn decode_samples<R: BufRead>(
    mut reader: MaybeGzip<R>,
    dims: [usize; 3],
    ty: nrrd::SampleType,
    endian: nrrd::Endian,
    sizes: SizeField,
) -> Result<Volume, IoError> {
    let (count, data_bytes) = check_dims(dims, ty, sizes)?;
    nrrd::check_memory(dims, count, ty, crate::budget::limit_bytes())?;
    let layout = nrrd::Layout::samples(dims, count, data_bytes, ty, endian);
    let source = reader.source();
    let data = nrrd::decode_stream(&mut reader, &layout, source)?;
    reader.finish()?;
    Ok(Volume::new(dims, data))
}
