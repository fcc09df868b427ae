//! NRRD and raw volume I/O.
//!
//! Reads NRRD files with an attached header (`.nrrd`) or a detached one
//! (`.nhdr` with `data file:`), raw or gzip encoded, of any of the common
//! integer and floating point sample types, into an `f32` [`Volume`] with
//! its voxel spacing (from `spacings`, or the lengths of the
//! `space directions` vectors); reads headerless raw files given their
//! layout; and writes `float` NRRD files.
//!
//! Input is untrusted: malformed headers, truncated or corrupt data and
//! NaN/Inf samples are reported as [`IoError`]s, never panics. Before
//! allocating, the memory a volume needs is checked against
//! [`crate::budget::limit_bytes`], and gzip data is never decompressed beyond the
//! expected size plus a small margin.
//!
//! Notes on the NRRD dialect accepted:
//! - `line skip` skips lines of the file after the header (before
//!   decompression); `byte skip` then skips bytes of the (decompressed) data,
//!   as in Teem. `byte skip: -1` is not supported.
//! - Field names are case-insensitive; unknown fields and `key:=value` pairs
//!   are ignored; a field given twice is an error.
//! - `data file` names one file, relative to the header's directory unless
//!   absolute; `line skip` and `byte skip` then apply to that file. The
//!   multi-file forms (`LIST`, format strings) are refused.
//! - `space directions` of an oblique or sheared grid keep only their
//!   lengths: the volume is rendered as an axis-aligned grid with those
//!   spacings. With a patient `space` (`right-anterior-superior`,
//!   `left-anterior-superior`, `left-posterior-superior` or their
//!   abbreviations) the vectors and `space origin` also become the volume's
//!   [`fvr_engine::volume::Orientation`] (in RAS), which `--view` and
//!   `fvr convert` use.
//! - Bytes after the expected data are ignored. For gzip, the last member
//!   read is decompressed to its end (within the margin) so that its CRC is
//!   verified.

use super::error;
mod header;
mod samples;
mod space;
#[cfg(test)]
mod tests;

use std::io::{self, BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use flate2::bufread::MultiGzDecoder;
use indicatif::ProgressBar;

use fvr_engine::volume::Volume;

pub use error::IoError;
pub use samples::{Encoding, Endian, SampleType};

pub(crate) use error::{excerpt, format_error};
pub(crate) use header::{geometry, Layout};

use error::invalid_argument;
use header::read_header;

/// Decompressed bytes read past the expected data, to reach the end of the
/// gzip member and check its CRC.
const GZIP_MARGIN: u64 = 4096;

/// Bytes converted per step when streaming samples (a multiple of 8).
const CHUNK_BYTES: usize = 1 << 16;

/// Samples reserved before any are read.
const INITIAL_SAMPLES: usize = 1 << 24;

/// Read buffer for files.
const FILE_BUFFER_BYTES: usize = 1 << 16;

/// Refuse volumes whose decoding would need more than `limit` bytes: the
/// `f32` output plus the raw samples.
///
/// First the whole job: the volume of `dims` with what the program plans to
/// build from it, against the process's limit ([`crate::budget::check_load`]).
pub(crate) fn check_memory(
    dims: [usize; 3],
    count: usize,
    ty: SampleType,
    limit: u64,
) -> Result<(), IoError> {
    crate::budget::check_load(dims, CHUNK_BYTES as u64)?;
    let per_sample = 4 + ty.size_bytes() as u64;
    let needed = (count as u64).saturating_mul(per_sample);
    if needed > limit {
        return Err(IoError::TooLarge { needed, limit });
    }
    Ok(())
}

/// Read a NRRD file (attached header `.nrrd`, or detached header `.nhdr`
/// with its data file) into a volume of `f32`.
///
/// Dimension 1 gives dims `[n0, 1, 1]`, dimension 2 gives `[n0, n1, 1]`;
/// dimension 4 or more is an error. Errors carry the path.
pub fn read_nrrd(path: &Path) -> Result<Volume, IoError> {
    read_nrrd_with_progress(path, &ProgressBar::hidden())
}

/// [`read_nrrd`], advancing `progress` by the bytes read from the file
/// that holds the samples (its length is set to that file's size).
pub fn read_nrrd_with_progress(path: &Path, progress: &ProgressBar) -> Result<Volume, IoError> {
    read_nrrd_limited(path, crate::budget::limit_bytes(), progress, None)
}

/// What an image file holds, from its `kinds` ([`read_nrrd_image_kind`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageKind {
    /// Scalar samples on spatial axes: an image `[W, H, 1]` (or a volume).
    Scalar,
    /// `kinds: RGB-color domain domain`: dims `[3, W, H]`.
    Colour,
    /// `kinds: space space list`, as `fvr project` writes: `[W, H, views]`.
    Stack,
}

/// [`read_nrrd`] for an image `fvr render` or `fvr project` wrote: also a
/// colour image (`kinds: RGB-color domain domain`, `sizes: 3 W H`), as
/// dims `[3, W, H]`, and a stack of views (`kinds: space space list`).
///
/// # Errors
/// As [`read_nrrd`].
pub fn read_nrrd_image(path: &Path) -> Result<Volume, IoError> {
    read_nrrd_image_kind(path).map(|(image, _)| image)
}

/// [`read_nrrd_image`], and what the image is.
///
/// # Errors
/// As [`read_nrrd`].
pub fn read_nrrd_image_kind(path: &Path) -> Result<(Volume, ImageKind), IoError> {
    let mut kind = ImageKind::Scalar;
    let image = read_nrrd_limited(
        path,
        crate::budget::limit_bytes(),
        &ProgressBar::hidden(),
        Some(&mut kind),
    )?;
    Ok((image, kind))
}

/// Read `path`: a volume, or with `image` any image, whose kind is set.
fn read_nrrd_limited(
    path: &Path,
    limit: u64,
    progress: &ProgressBar,
    mut image: Option<&mut ImageKind>,
) -> Result<Volume, IoError> {
    let mut open = || -> Result<Volume, IoError> {
        let file = crate::io::open_file(path)?;
        progress.set_length(file.metadata().map(|m| m.len()).unwrap_or(0));
        let mut reader = BufReader::with_capacity(FILE_BUFFER_BYTES, progress.wrap_read(file));
        let layout = read_header(&mut reader)?;
        match image.as_deref_mut() {
            None => layout.check_volume()?,
            Some(kind) => {
                *kind = match (layout.colour, layout.stack) {
                    (true, _) => ImageKind::Colour,
                    (_, true) => ImageKind::Stack,
                    _ => ImageKind::Scalar,
                }
            }
        }
        check_memory(layout.dims, layout.count, layout.ty, limit)?;
        let Some(name) = &layout.data_file else {
            return read_data(&mut reader, &layout);
        };
        let data_path = match path.parent() {
            Some(dir) => dir.join(name),
            None => Path::new(name).to_path_buf(),
        };
        let read_detached = || -> Result<Volume, IoError> {
            let file = crate::io::open_file(&data_path)?;
            progress.set_position(0);
            progress.set_length(file.metadata().map(|m| m.len()).unwrap_or(0));
            let mut data = BufReader::with_capacity(FILE_BUFFER_BYTES, progress.wrap_read(file));
            read_data(&mut data, &layout)
        };
        read_detached().map_err(|e| e.in_file(&data_path))
    };
    open().map_err(|e| e.in_file(path))
}

/// The data file a detached NRRD header (`.nhdr`) names, resolved against
/// the header's directory; `None` for an attached header or a file whose
/// header cannot be read (the reader reports that). Reads the header only.
pub fn detached_data_file(path: &Path) -> Option<PathBuf> {
    let file = crate::io::open_file(path).ok()?;
    let mut reader = BufReader::with_capacity(FILE_BUFFER_BYTES, file);
    let name = read_header(&mut reader).ok()?.data_file?;
    Some(match path.parent() {
        Some(dir) => dir.join(name),
        None => PathBuf::from(name),
    })
}

/// Parse a whole NRRD file held in memory; see [`read_nrrd`].
pub fn parse_nrrd(bytes: &[u8]) -> Result<Volume, IoError> {
    parse_nrrd_limited(bytes, crate::budget::limit_bytes())
}

/// [`parse_nrrd`] with an explicit memory limit in bytes.
fn parse_nrrd_limited(bytes: &[u8], limit: u64) -> Result<Volume, IoError> {
    let mut reader = bytes;
    read_nrrd_from(&mut reader, limit)
}

/// Read header and data from `reader`, refusing volumes over `limit` bytes
/// before reading any data.
fn read_nrrd_from<R: BufRead>(reader: &mut R, limit: u64) -> Result<Volume, IoError> {
    let layout = read_header(reader)?;
    layout.check_volume()?;
    check_memory(layout.dims, layout.count, layout.ty, limit)?;
    if let Some(file) = &layout.data_file {
        return Err(IoError::DetachedData {
            file: excerpt(file),
        });
    }
    read_data(reader, &layout)
}

/// Read the samples `layout` describes from `reader`, which is positioned
/// at the start of the data (after the header, or at the start of a
/// detached data file).
fn read_data<R: BufRead>(reader: &mut R, layout: &Layout) -> Result<Volume, IoError> {
    skip_lines(reader, layout.line_skip)?;
    let data = match layout.encoding {
        Encoding::Raw => read_raw_data(reader, layout)?,
        Encoding::Gzip => read_gzip_data(reader, layout)?,
    };
    let mut volume = Volume::new(layout.dims, data);
    volume.spacing = layout.spacing;
    volume.orientation = layout.orientation;
    Ok(volume)
}

fn read_raw_data<R: Read>(reader: &mut R, layout: &Layout) -> Result<Vec<f32>, IoError> {
    skip_bytes(reader, layout.byte_skip, Source::Raw)?;
    decode_stream(reader, layout, Source::Raw)
}

pub(crate) fn read_gzip_data<R: BufRead>(
    reader: &mut R,
    layout: &Layout,
) -> Result<Vec<f32>, IoError> {
    let bound = layout
        .byte_skip
        .saturating_add(layout.data_bytes as u64)
        .saturating_add(GZIP_MARGIN);
    let mut gz = MultiGzDecoder::new(reader).take(bound);
    skip_bytes(&mut gz, layout.byte_skip, Source::Gzip)?;
    let data = decode_stream(&mut gz, layout, Source::Gzip)?;
    drain(&mut gz).map_err(|source| IoError::Gzip { source })?;
    Ok(data)
}

/// Where sample bytes come from, for error reporting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Source {
    /// Uncompressed bytes.
    Raw,
    /// Decompressed gzip data.
    Gzip,
}

impl Source {
    #[cold]
    fn read_error(self, source: io::Error) -> IoError {
        match self {
            Source::Raw => IoError::Io { source },
            Source::Gzip => IoError::Gzip { source },
        }
    }

    #[cold]
    fn truncated(self, expected: usize, found: usize) -> IoError {
        IoError::Truncated {
            expected: expected as u64,
            found: found as u64,
            gzip: self == Source::Gzip,
        }
    }
}

/// Read until `buf` is full or the input ends; the number of bytes read.
pub(crate) fn read_full<R: Read>(reader: &mut R, buf: &mut [u8]) -> io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        let rest = buf.get_mut(filled..).unwrap_or_default();
        match reader.read(rest) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

/// Read and discard what is left of `reader`.
fn drain<R: Read>(reader: &mut R) -> io::Result<()> {
    io::copy(reader, &mut io::sink()).map(drop)
}

/// Skip `count` bytes of `reader` (the `byte skip` field).
fn skip_bytes<R: Read>(reader: &mut R, count: u64, source: Source) -> Result<(), IoError> {
    if count == 0 {
        return Ok(());
    }
    let skipped = io::copy(&mut reader.by_ref().take(count), &mut io::sink())
        .map_err(|e| source.read_error(e))?;
    if skipped < count {
        return Err(error::field_error(
            "byte skip",
            format!("skips {count} bytes but the data has only {skipped}"),
        ));
    }
    Ok(())
}

/// Skip `count` lines of `reader` (the `line skip` field).
fn skip_lines<R: BufRead>(reader: &mut R, count: u64) -> Result<(), IoError> {
    for skipped in 0..count {
        if !skip_line(reader)? {
            return Err(error::field_error(
                "line skip",
                format!("skips {count} lines but the data has only {skipped}"),
            ));
        }
    }
    Ok(())
}

/// Skip through the next `\n`; `false` if the input ended first.
fn skip_line<R: BufRead>(reader: &mut R) -> io::Result<bool> {
    loop {
        let (consumed, found) = match reader.fill_buf() {
            Ok([]) => return Ok(false),
            Ok(buf) => match buf.iter().position(|&b| b == b'\n') {
                Some(p) => (p + 1, true),
                None => (buf.len(), false),
            },
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        reader.consume(consumed);
        if found {
            return Ok(true);
        }
    }
}

/// Read `layout.data_bytes` bytes of samples from `reader` and convert them
/// to `f32`, checking that they are finite.
pub(crate) fn decode_stream<R: Read>(
    reader: &mut R,
    layout: &Layout,
    source: Source,
) -> Result<Vec<f32>, IoError> {
    let total = layout.data_bytes;
    // The first INITIAL_SAMPLES are reserved at once, so a short file that
    // claims a huge volume costs little; past them, the whole volume (within
    // the budget, checked before). Doubling instead would peak at twice the
    // volume during a reallocation; this peaks at the volume plus 64 MiB.
    let mut out = Vec::with_capacity(layout.count.min(INITIAL_SAMPLES));
    let mut buf = vec![0u8; CHUNK_BYTES.min(total)];
    let mut done = 0;
    while done < total {
        let want = (total - done).min(buf.len());
        let chunk = buf.get_mut(..want).unwrap_or_default();
        let got = read_full(reader, chunk).map_err(|e| source.read_error(e))?;
        if got < want {
            return Err(source.truncated(total, done + got));
        }
        let first = out.len();
        if first + want / layout.ty.size_bytes() > out.capacity() {
            out.reserve_exact(layout.count - first);
        }
        samples::decode_into(chunk, layout.ty, layout.endian, &mut out);
        check_finite(&out, first, chunk, layout)?;
        done += want;
    }
    Ok(out)
}

/// Fail on the first non-finite value in `out[first..]`, decoded from `chunk`.
fn check_finite(out: &[f32], first: usize, chunk: &[u8], layout: &Layout) -> Result<(), IoError> {
    if !layout.ty.is_float() {
        return Ok(());
    }
    let new = out.get(first..).unwrap_or_default();
    match new.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(p) => Err(non_finite(p, first, new, chunk, layout)),
    }
}

/// The error for the non-finite sample `p` of the chunk starting at sample `first`.
#[cold]
fn non_finite(p: usize, first: usize, new: &[f32], chunk: &[u8], layout: &Layout) -> IoError {
    let size = layout.ty.size_bytes();
    let value = chunk
        .get(p * size..)
        .and_then(|b| samples::float_value(b, layout.ty, layout.endian))
        .or_else(|| new.get(p).map(|&v| v as f64))
        .unwrap_or(f64::NAN);
    IoError::NonFinite {
        voxel: voxel_of(layout.dims, first + p),
        value,
    }
}

/// Voxel `(i, j, k)` of linear sample index `linear`.
fn voxel_of(dims: [usize; 3], linear: usize) -> [usize; 3] {
    let [nx, ny, _] = dims.map(|d| d.max(1));
    [
        linear % nx,
        (linear / nx) % ny,
        linear / nx.saturating_mul(ny),
    ]
}

/// Read a headerless raw file of `dims` samples of type `ty`, `i` fastest.
/// Bytes after the expected data are ignored. Errors carry the path.
pub fn read_raw(
    path: &Path,
    dims: [usize; 3],
    ty: SampleType,
    endian: Endian,
) -> Result<Volume, IoError> {
    let limit = crate::budget::limit_bytes();
    let open = || -> Result<Volume, IoError> {
        let mut reader = BufReader::with_capacity(FILE_BUFFER_BYTES, crate::io::open_file(path)?);
        read_raw_from(&mut reader, dims, ty, endian, limit)
    };
    open().map_err(|e| e.in_file(path))
}

/// Parse headerless raw samples held in memory; see [`read_raw`].
pub fn parse_raw(
    bytes: &[u8],
    dims: [usize; 3],
    ty: SampleType,
    endian: Endian,
) -> Result<Volume, IoError> {
    let mut reader = bytes;
    read_raw_from(&mut reader, dims, ty, endian, crate::budget::limit_bytes())
}

fn read_raw_from<R: Read>(
    reader: &mut R,
    dims: [usize; 3],
    ty: SampleType,
    endian: Endian,
    limit: u64,
) -> Result<Volume, IoError> {
    if dims.contains(&0) {
        return Err(invalid_argument(format!(
            "raw volume dimensions must be positive, got {dims:?}"
        )));
    }
    let (dims, count, data_bytes) = geometry(&dims, ty).map_err(|_| {
        invalid_argument(format!(
            "--raw-dims {}x{}x{} of {} samples: the byte count overflows",
            dims[0],
            dims[1],
            dims[2],
            ty.nrrd_name()
        ))
    })?;
    check_memory(dims, count, ty, limit)?;
    let layout = Layout::samples(dims, count, data_bytes, ty, endian);
    let data = decode_stream(reader, &layout, Source::Raw)?;
    // A file longer than the dimensions say is refused like a shorter one:
    // the dimensions are wrong, and the image would be skewed.
    let mut extra = [0u8; 1];
    let more = loop {
        match reader.read(&mut extra) {
            Ok(n) => break n > 0,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(source) => return Err(IoError::Io { source }),
        }
    };
    if more {
        return Err(invalid_argument(format!(
            "--raw-dims {}x{}x{} of {} samples make {data_bytes} bytes, but the file holds more; \
             give the file's own dimensions",
            dims[0],
            dims[1],
            dims[2],
            ty.nrrd_name()
        )));
    }
    Ok(Volume::new(dims, data))
}

/// Check that `sizes` (1 to 3 positive sizes) describe `len` samples.
fn check_sizes(sizes: &[usize], len: usize) -> Result<(), IoError> {
    if !(1..=3).contains(&sizes.len()) || sizes.contains(&0) {
        return Err(invalid_argument(format!(
            "NRRD sizes must be 1 to 3 positive integers, got {sizes:?}"
        )));
    }
    let count = sizes.iter().try_fold(1usize, |acc, &n| acc.checked_mul(n));
    if count != Some(len) {
        return Err(invalid_argument(format!(
            "NRRD sizes {sizes:?} do not match the {len} samples given"
        )));
    }
    Ok(())
}

/// The header text for the given layout, blank line included.
fn header_text(sizes: &[usize], ty: SampleType, encoding: Encoding, endian: Endian) -> String {
    let sizes: Vec<String> = sizes.iter().map(usize::to_string).collect();
    let mut text = format!(
        "NRRD0004\n# Complete NRRD file format specification at:\n\
         # http://teem.sourceforge.net/nrrd/format.html\n\
         type: {}\ndimension: {}\nsizes: {}\n",
        ty.nrrd_name(),
        sizes.len(),
        sizes.join(" "),
    );
    if ty.size_bytes() > 1 {
        text.push_str(&format!("endian: {}\n", endian.nrrd_name()));
    }
    text.push_str(&format!("encoding: {}\n\n", encoding.nrrd_name()));
    text
}

/// Gzip-compress `bytes`.
fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    encoder
        .write_all(bytes)
        .and_then(|()| encoder.finish())
        .expect("gzip-compressing into a Vec cannot fail")
}

/// Write `data` as a `float` NRRD file: raw encoding, little endian, with
/// `sizes` (1 to 3 of them, e.g. `[w, h]` for an image) whose product must
/// equal `data.len()`. Errors carry the path.
pub fn write_nrrd_f32(path: &Path, sizes: &[usize], data: &[f32]) -> Result<(), IoError> {
    check_sizes(sizes, data.len())
        .and_then(|()| {
            Ok(super::atomic::write_bytes(
                path,
                &encode_nrrd_f32(sizes, data),
            )?)
        })
        .map_err(|e| e.in_file(path))
}

/// Write `volume` as a 3D `float` NRRD file (raw, little endian) with its
/// voxel spacing as `spacings`, which [`read_nrrd`] reads back exactly (the
/// numbers are written in Rust's shortest round-trip form); a volume with
/// an orientation gets `space: right-anterior-superior`, `space
/// directions` and `space origin` instead (read back to rounding). The samples are
/// streamed, so no second copy of the volume is held. Errors carry the path.
pub fn write_volume_nrrd(path: &Path, volume: &Volume) -> Result<(), IoError> {
    use std::io::Write;
    let write = || -> Result<(), IoError> {
        check_sizes(&volume.dims, volume.data.len())?;
        fvr_engine::volume::check_spacing(volume.spacing)
            .map_err(|e| invalid_argument(e.to_string()))?;
        let mut text = header_text(&volume.dims, SampleType::F32, Encoding::Raw, Endian::Little);
        // The header ends with its blank line: the spacing goes before it.
        text.truncate(text.len() - 1);
        let [sx, sy, sz] = volume.spacing;
        match &volume.orientation {
            // The format forbids `spacings` beside `space directions`,
            // whose lengths are the spacing.
            Some(o) => text.push_str(&space::header_lines(o, volume.spacing)),
            None => text.push_str(&format!("spacings: {sx} {sy} {sz}\n")),
        }
        text.push('\n');
        let mut out = super::atomic::Output::create(path)?;
        out.write_all(text.as_bytes())?;
        for chunk in volume.data.chunks(CHUNK_BYTES / 4) {
            out.write_all(&samples::encode_f32_le(chunk))?;
        }
        out.commit()?;
        Ok(())
    };
    write().map_err(|e| e.in_file(path))
}

/// Encode `data` as a `float` NRRD file, raw encoding, little endian; see
/// [`write_nrrd_f32`].
///
/// # Panics
/// If `sizes` is not 1 to 3 positive sizes whose product is `data.len()`.
pub fn encode_nrrd_f32(sizes: &[usize], data: &[f32]) -> Vec<u8> {
    if let Err(e) = check_sizes(sizes, data.len()) {
        panic!("encode_nrrd_f32: {e}");
    }
    let mut out = header_text(sizes, SampleType::F32, Encoding::Raw, Endian::Little).into_bytes();
    out.extend(samples::encode_f32_le(data));
    out
}

/// Encode a NRRD file of any supported sample type, encoding and byte order
/// from `f64` values (rounded to nearest and saturated for integer types,
/// cast for floating point types). A test and fixture helper.
///
/// # Panics
/// If `sizes` is not 1 to 3 positive sizes whose product is `values.len()`.
pub fn encode_nrrd(
    sizes: &[usize],
    ty: SampleType,
    encoding: Encoding,
    endian: Endian,
    values: &[f64],
) -> Vec<u8> {
    if let Err(e) = check_sizes(sizes, values.len()) {
        panic!("encode_nrrd: {e}");
    }
    let mut out = header_text(sizes, ty, encoding, endian).into_bytes();
    let payload = samples::encode_values(values, ty, endian);
    match encoding {
        Encoding::Raw => out.extend(payload),
        Encoding::Gzip => out.extend(gzip(&payload)),
    }
    out
}
