//! DICOM series: a directory of single-frame slices (CT, MR, …), read by
//! [`reader`] (explicit VR little and big endian, implicit VR, deflated)
//! and decoded with `dicom-pixeldata` (uncompressed, RLE and baseline JPEG
//! pixel data).
//!
//! How the slices become a volume:
//! - Files that are not DICOM (no `DICM` at byte 128), `DICOMDIR`, and
//!   objects without pixel data are skipped; a DICOM file that cannot be
//!   parsed is an error naming it.
//! - One series only: pointing at a file reads that file's series from its
//!   directory; a directory holding several series is an error that lists
//!   them.
//! - Slices are sorted by their position along the slice normal,
//!   `ImagePositionPatient · (row direction × column direction)` from
//!   `ImageOrientationPatient`. They must share `Rows`, `Columns`,
//!   `PixelSpacing` and orientation, and be evenly spaced (within 1 %):
//!   missing slices or variable spacing are refused rather than rendered
//!   distorted.
//! - `ImageOrientationPatient` (row, column directions; the slice normal
//!   their cross product) and the first slice's `ImagePositionPatient`,
//!   from LPS to RAS, are the volume's orientation (none when the
//!   attribute is absent).
//! - Voxel `(i, j, k)` is column `i`, row `j` of slice `k`. The spacing is
//!   `[column spacing, row spacing, slice step]` in mm (`PixelSpacing` is
//!   row spacing first). A lone slice gets `SliceThickness` (or 1 mm).
//! - Samples go through the modality LUT (`RescaleSlope`,
//!   `RescaleIntercept`): CT comes out in Hounsfield units.
//!
//! Not supported: multi-frame objects (enhanced CT/MR), colour images,
//! gantry tilt (it shows as a mismatch of orientation and position).
//!
//! Hostile input: files are read by a bounded reader of our own
//! ([`reader`]), not by `dicom-parser` (which allocates each value's
//! declared length before reading it): every declared length is checked
//! against the bytes left in the file and in the item or sequence holding
//! it before anything is allocated, so memory grows with the bytes present
//! (a deflated data set is inflated up to the memory limit). The reader
//! builds `dicom-object`'s in-memory object, from which `dicom-pixeldata`
//! decodes the pixels; image sizes the pixel data cannot hold are refused
//! before decoding, since the decoder allocates the decoded size first.
//! `parity.rs` checks that valid files read as `dicom-object` reads them.

mod encode;
#[cfg(test)]
mod parity;
mod reader;
mod values;

pub use encode::CtSlice;

use std::fs;
use std::path::{Path, PathBuf};

use dicom_dictionary_std::tags;
use dicom_object::DefaultDicomObject;
use dicom_pixeldata::{ConvertOptions, ModalityLutOption, PixelDecoder};
use indicatif::ProgressBar;

use crate::io::nrrd::{excerpt, format_error, IoError};
use fvr_engine::volume::{check_spacing, Volume};

/// Format name in error messages.
pub(crate) const FORMAT: &str = "DICOM";
/// Format name of the series in error messages.
const SERIES: &str = "DICOM series";

/// Relative tolerance on the slice step.
const STEP_TOLERANCE: f64 = 0.01;
/// Tolerance on direction cosines.
const COSINE_TOLERANCE: f64 = 1e-4;

/// Whether `head` is the start of a DICOM Part 10 file: `DICM` at 128.
pub fn has_magic(head: &[u8]) -> bool {
    head.get(128..132) == Some(b"DICM")
}

/// One decoded slice.
#[derive(Clone, Debug, PartialEq)]
pub struct Slice {
    /// `SeriesInstanceUID` (empty when absent).
    pub series: String,
    /// `Columns` (x) and `Rows` (y).
    pub size: [usize; 2],
    /// `PixelSpacing`: row spacing (y), then column spacing (x), in mm.
    pub pixel_spacing: [f64; 2],
    /// `ImagePositionPatient`, mm (zero when absent).
    pub position: [f64; 3],
    /// `ImageOrientationPatient`: row direction, then column direction
    /// (rows along x, columns along y when absent).
    pub orientation: [f64; 6],
    /// Whether `ImageOrientationPatient` was given.
    pub oriented: bool,
    /// `SliceThickness` in mm, if given.
    pub thickness: Option<f64>,
    /// Modality values, column fastest.
    pub pixels: Vec<f32>,
}

/// Parse one DICOM Part 10 file held in memory (preamble optional).
///
/// # Errors
/// Not DICOM, unreadable attributes, pixel data that is missing, colour,
/// multi-frame or cannot be decoded; each names the attribute.
pub fn parse_slice(bytes: &[u8]) -> Result<Slice, IoError> {
    let obj = open_bytes(bytes)?;
    slice_from(&obj)
}

/// Parse a whole file held in memory with the bounded reader.
fn open_bytes(bytes: &[u8]) -> Result<DefaultDicomObject, IoError> {
    reader::read(bytes)
}

fn has_pixel_data(obj: &DefaultDicomObject) -> bool {
    obj.get(tags::PIXEL_DATA).is_some()
}

fn slice_from(obj: &DefaultDicomObject) -> Result<Slice, IoError> {
    if !has_pixel_data(obj) {
        return Err(format_error(
            FORMAT,
            "PixelData",
            "is missing: not an image",
        ));
    }
    let series = text(obj, tags::SERIES_INSTANCE_UID, "SeriesInstanceUID")?.unwrap_or_default();
    let ps = floats(obj, tags::PIXEL_SPACING, "PixelSpacing", 2)?.unwrap_or(vec![1.0, 1.0]);
    let position = floats(obj, tags::IMAGE_POSITION_PATIENT, "ImagePositionPatient", 3)?
        .unwrap_or(vec![0.0; 3]);
    let orientation = floats(
        obj,
        tags::IMAGE_ORIENTATION_PATIENT,
        "ImageOrientationPatient",
        6,
    )?;
    let oriented = orientation.is_some();
    let orientation = orientation.unwrap_or(vec![1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let thickness = floats(obj, tags::SLICE_THICKNESS, "SliceThickness", 1)?.map(|v| v[0]);
    let slope = floats(obj, tags::RESCALE_SLOPE, "RescaleSlope", 1)?.map_or(1.0, |v| v[0]);
    let intercept =
        floats(obj, tags::RESCALE_INTERCEPT, "RescaleIntercept", 1)?.map_or(0.0, |v| v[0]);
    let bits = check_bits(obj)?;
    check_pixel_size(obj)?;
    let decoded = obj
        .decode_pixel_data()
        .map_err(|e| format_error(FORMAT, "PixelData", format!("cannot be decoded: {e}")))?;
    if decoded.number_of_frames() != 1 {
        return Err(format_error(
            FORMAT,
            "NumberOfFrames",
            format!(
                "is {}: multi-frame objects are not supported, only series of single slices",
                decoded.number_of_frames()
            ),
        ));
    }
    if decoded.samples_per_pixel() != 1 {
        return Err(format_error(
            FORMAT,
            "SamplesPerPixel",
            format!(
                "is {}: only greyscale images are supported",
                decoded.samples_per_pixel()
            ),
        ));
    }
    let size = [decoded.columns() as usize, decoded.rows() as usize];
    if size.contains(&0) {
        return Err(format_error(
            FORMAT,
            "Rows",
            format!("Columns x Rows is {size:?}; both must be at least 1"),
        ));
    }
    // The modality LUT is applied here rather than by `dicom-pixeldata`,
    // whose lookup table (2^BitsStored entries) panics on a BitsStored of 0
    // or above 32 (found by `cargo fuzz run dicom`).
    let raw: Vec<f64> = decoded
        .to_vec_with_options(&ConvertOptions::new().with_modality_lut(ModalityLutOption::None))
        .map_err(|e| format_error(FORMAT, "PixelData", format!("cannot be converted: {e}")))?;
    let pixels: Vec<f32> = raw
        .iter()
        .map(|&x| (slope * bits.value(x) + intercept) as f32)
        .collect();
    if pixels.len() != size[0] * size[1] {
        return Err(format_error(
            FORMAT,
            "PixelData",
            format!(
                "holds {} values for {} x {} pixels",
                pixels.len(),
                size[0],
                size[1]
            ),
        ));
    }
    if let Some(p) = pixels.iter().position(|v| !v.is_finite()) {
        return Err(IoError::NonFinite {
            voxel: [p % size[0], p / size[0], 0],
            value: pixels[p] as f64,
        });
    }
    Ok(Slice {
        series,
        size,
        pixel_spacing: [ps[0], ps[1]],
        position: [position[0], position[1], position[2]],
        orientation: [0, 1, 2, 3, 4, 5].map(|i| orientation[i]),
        oriented,
        thickness,
        pixels,
    })
}

/// The sample layout: `stored` significant bits (the low ones) of
/// `allocated`, signed (two's complement) or not.
#[derive(Clone, Copy, Debug)]
struct Bits {
    allocated: u32,
    stored: u32,
    signed: bool,
}

impl Bits {
    /// The value of a sample decoded as a whole `allocated`-bit integer
    /// `x`: its bits above `stored` (overlay bits or garbage) are masked
    /// off, and a signed value is sign-extended from bit `stored − 1`.
    /// E.g. 0xF123 with 12 bits stored reads 0x123 = 291.
    fn value(self, x: f64) -> f64 {
        if self.stored >= self.allocated {
            return x;
        }
        let pattern = (x as i64) & ((1i64 << self.allocated) - 1);
        let low = pattern & ((1i64 << self.stored) - 1);
        let v = if self.signed && low & (1i64 << (self.stored - 1)) != 0 {
            low - (1i64 << self.stored)
        } else {
            low
        };
        v as f64
    }
}

/// `BitsAllocated` 8 or 16, and `1 <= BitsStored <= BitsAllocated`, the
/// greyscale layouts decoded here.
fn check_bits(obj: &DefaultDicomObject) -> Result<Bits, IoError> {
    let int = |tag, name: &'static str| -> Result<Option<i64>, IoError> {
        match obj.get(tag) {
            None => Ok(None),
            Some(e) => e
                .to_int::<i64>()
                .map(Some)
                .map_err(|err| format_error(FORMAT, name, format!("is not an integer: {err}"))),
        }
    };
    let allocated = int(tags::BITS_ALLOCATED, "BitsAllocated")?
        .ok_or_else(|| format_error(FORMAT, "BitsAllocated", "is missing"))?;
    if allocated != 8 && allocated != 16 {
        return Err(format_error(
            FORMAT,
            "BitsAllocated",
            format!("is {allocated}: only 8- and 16-bit greyscale samples are supported"),
        ));
    }
    let stored = int(tags::BITS_STORED, "BitsStored")?.unwrap_or(allocated);
    if !(1..=allocated).contains(&stored) {
        return Err(format_error(
            FORMAT,
            "BitsStored",
            format!("is {stored}; it must be 1 to BitsAllocated ({allocated})"),
        ));
    }
    let signed = int(tags::PIXEL_REPRESENTATION, "PixelRepresentation")?.unwrap_or(0) == 1;
    Ok(Bits {
        allocated: allocated as u32,
        stored: stored as u32,
        signed,
    })
}

/// Largest ratio accepted between decoded and encapsulated (compressed)
/// pixel bytes; deflate's limit is about 1032.
const MAX_COMPRESSION_RATIO: u64 = 1024;

/// Refuse `Rows × Columns × NumberOfFrames × SamplesPerPixel ×
/// BitsAllocated/8` bytes that the pixel data cannot hold: more than its
/// length when native, or more than [`MAX_COMPRESSION_RATIO`] times its
/// bytes when encapsulated, or more than the memory limit. The decoder
/// allocates the decoded size up front, so a 1 kB file could otherwise
/// claim gigabytes.
fn check_pixel_size(obj: &DefaultDicomObject) -> Result<(), IoError> {
    let int = |tag, name: &'static str, default: i64| -> Result<i64, IoError> {
        match obj.get(tag) {
            None => Ok(default),
            Some(e) => e
                .to_int::<i64>()
                .map_err(|err| format_error(FORMAT, name, format!("is not an integer: {err}"))),
        }
    };
    let rows = int(tags::ROWS, "Rows", 0)?;
    let columns = int(tags::COLUMNS, "Columns", 0)?;
    let frames = int(tags::NUMBER_OF_FRAMES, "NumberOfFrames", 1)?;
    let samples = int(tags::SAMPLES_PER_PIXEL, "SamplesPerPixel", 1)?;
    let bytes = int(tags::BITS_ALLOCATED, "BitsAllocated", 16)? / 8;
    for (v, name) in [
        (rows, "Rows"),
        (columns, "Columns"),
        (frames, "NumberOfFrames"),
        (samples, "SamplesPerPixel"),
    ] {
        if v < 1 {
            return Err(format_error(
                FORMAT,
                name,
                format!("is {v}; it must be at least 1"),
            ));
        }
    }
    let needed = [rows, columns, frames, samples, bytes.max(1)]
        .iter()
        .try_fold(1u64, |acc, &v| acc.checked_mul(v as u64))
        .unwrap_or(u64::MAX);
    let Some(pixel_data) = obj.get(tags::PIXEL_DATA) else {
        return Ok(());
    };
    let (available, what) = match pixel_data.value().fragments() {
        Some(fragments) => (
            fragments
                .iter()
                .map(|f| f.len() as u64)
                .sum::<u64>()
                .saturating_mul(MAX_COMPRESSION_RATIO),
            "the compressed fragments can hold",
        ),
        None => (
            pixel_data
                .value()
                .primitive()
                .map_or(0, |p| p.calculate_byte_len() as u64),
            "the pixel data holds",
        ),
    };
    let limit = crate::budget::limit_bytes();
    if needed > available || needed > limit {
        return Err(format_error(
            FORMAT,
            "Rows",
            format!(
                "{rows} rows x {columns} columns x {frames} frames x {samples} samples x {bytes} bytes = {needed} bytes, more than {what} ({available}) or the memory limit ({limit})"
            ),
        ));
    }
    Ok(())
}

pub(crate) fn text(
    obj: &DefaultDicomObject,
    tag: dicom_object::Tag,
    name: &'static str,
) -> Result<Option<String>, IoError> {
    match obj.get(tag) {
        None => Ok(None),
        Some(e) => e
            .to_str()
            .map(|s| Some(s.trim_end_matches(['\0', ' ']).to_owned()))
            .map_err(|e| format_error(FORMAT, name, format!("is not text: {e}"))),
    }
}

/// `count` finite numbers of a decimal-string attribute, or `None` if absent.
pub(crate) fn floats(
    obj: &DefaultDicomObject,
    tag: dicom_object::Tag,
    name: &'static str,
    count: usize,
) -> Result<Option<Vec<f64>>, IoError> {
    let Some(e) = obj.get(tag) else {
        return Ok(None);
    };
    let v = e
        .to_multi_float64()
        .map_err(|err| format_error(FORMAT, name, format!("is not a list of numbers: {err}")))?;
    if v.len() < count || v.iter().take(count).any(|x| !x.is_finite()) {
        return Err(format_error(
            FORMAT,
            name,
            format!("expected {count} finite numbers, got {v:?}"),
        ));
    }
    Ok(Some(v))
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Stack slices of one series into a volume (see the module docs).
///
/// # Errors
/// No slices, several series, slices that disagree in size, spacing or
/// orientation, duplicate positions, uneven spacing, or a spacing that is
/// zero, negative or not finite.
pub fn assemble(mut slices: Vec<Slice>) -> Result<Volume, IoError> {
    let Some(first) = slices.first().cloned() else {
        return Err(format_error(
            SERIES,
            "PixelData",
            "no DICOM image was found",
        ));
    };
    let mut series: Vec<&str> = slices.iter().map(|s| s.series.as_str()).collect();
    series.sort_unstable();
    series.dedup();
    if series.len() > 1 {
        return Err(format_error(
            SERIES,
            "SeriesInstanceUID",
            format!(
                "the directory holds {} series ({}); point at one file of the series to read, or give each series its own directory",
                series.len(),
                series.iter().map(|s| excerpt(s)).collect::<Vec<_>>().join(", ")
            ),
        ));
    }
    for s in &slices {
        if s.size != first.size {
            return Err(format_error(
                SERIES,
                "Rows",
                format!(
                    "slices of {:?} and {:?} pixels (Columns x Rows) in one series",
                    first.size, s.size
                ),
            ));
        }
        if s.pixel_spacing != first.pixel_spacing {
            return Err(format_error(
                SERIES,
                "PixelSpacing",
                format!(
                    "slices with {:?} and {:?} mm in one series",
                    first.pixel_spacing, s.pixel_spacing
                ),
            ));
        }
        if s.orientation
            .iter()
            .zip(first.orientation)
            .any(|(a, b)| (a - b).abs() > COSINE_TOLERANCE)
        {
            return Err(format_error(
                SERIES,
                "ImageOrientationPatient",
                format!(
                    "slices with orientations {:?} and {:?} in one series",
                    first.orientation, s.orientation
                ),
            ));
        }
    }
    let row = [0, 1, 2].map(|i| first.orientation[i]);
    let col = [3, 4, 5].map(|i| first.orientation[i]);
    let normal = cross(row, col);
    let norm = dot(normal, normal).sqrt();
    let unit = |v: [f64; 3]| (dot(v, v).sqrt() - 1.0).abs() < 1e-2;
    if !(unit(row) && unit(col) && dot(row, col).abs() < 1e-3) {
        return Err(format_error(
            SERIES,
            "ImageOrientationPatient",
            format!(
                "{:?} does not give two orthogonal unit directions",
                first.orientation
            ),
        ));
    }
    let normal = normal.map(|c| c / norm);
    let depth = |s: &Slice| dot(s.position, normal);
    slices.sort_by(|a, b| depth(a).total_cmp(&depth(b)));
    let step = if slices.len() > 1 {
        let depths: Vec<f64> = slices.iter().map(depth).collect();
        let steps: Vec<f64> = depths.windows(2).map(|w| w[1] - w[0]).collect();
        let mean = (depths[depths.len() - 1] - depths[0]) / steps.len() as f64;
        let (lo, hi) = steps
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &s| {
                (lo.min(s), hi.max(s))
            });
        if lo <= 0.0 {
            return Err(format_error(SERIES, "ImagePositionPatient", "two slices share a position along the slice normal (duplicates, or a localizer in the series)"));
        }
        if hi - lo > STEP_TOLERANCE * mean {
            return Err(format_error(
                SERIES,
                "ImagePositionPatient",
                format!("slice steps vary from {lo:.4} to {hi:.4} mm: missing slices or variable spacing, which would render distorted"),
            ));
        }
        mean
    } else {
        first.thickness.unwrap_or(1.0)
    };
    let spacing = check_spacing([first.pixel_spacing[1], first.pixel_spacing[0], step])
        .map_err(|e| format_error(SERIES, "PixelSpacing", e.to_string()))?;
    let dims = [first.size[0], first.size[1], slices.len()];
    // Patient LPS to RAS; voxel k runs along the normal (slices sorted so).
    let ras = fvr_engine::volume::Orientation::flip_lps;
    let orientation = match first.oriented {
        true => fvr_engine::volume::Orientation::from_columns(
            std::array::from_fn(|w| [ras(row)[w], ras(col)[w], ras(normal)[w]]),
            ras(slices[0].position),
        ),
        false => None,
    };
    let mut data = Vec::with_capacity(dims.iter().product());
    for s in slices {
        data.extend(s.pixels);
    }
    let mut volume = Volume::new(dims, data);
    volume.spacing = spacing;
    volume.orientation = orientation;
    Ok(volume)
}

/// Read the series at `path`: a directory holding one series, or one file
/// of a series (its directory is read, keeping that file's series).
/// Errors carry the path.
pub fn read_dicom(path: &Path) -> Result<Volume, IoError> {
    read_dicom_with_progress(path, &ProgressBar::hidden())
}

/// [`read_dicom`], advancing `progress` by the bytes of each file read.
pub fn read_dicom_with_progress(path: &Path, progress: &ProgressBar) -> Result<Volume, IoError> {
    let go = || -> Result<Volume, IoError> {
        let (dir, wanted) = if path.is_dir() {
            (path.to_path_buf(), None)
        } else {
            let bytes = fs::read(path)?;
            crate::io::inputs::record(path);
            let obj = open_bytes(&bytes)?;
            let uid =
                text(&obj, tags::SERIES_INSTANCE_UID, "SeriesInstanceUID")?.unwrap_or_default();
            let dir = path
                .parent()
                .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
            (dir, Some(uid))
        };
        let mut files: Vec<PathBuf> = fs::read_dir(&dir)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_file())
            .filter(|p| {
                let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
                !name.starts_with('.') && !name.eq_ignore_ascii_case("DICOMDIR")
            })
            .collect();
        files.sort();
        let candidates = files.len();
        let size = |p: &PathBuf| fs::metadata(p).map_or(0, |m| m.len());
        progress.set_length(files.iter().map(size).sum());
        let mut slices = Vec::new();
        for file in files {
            progress.inc(size(&file));
            let read_one = || -> Result<Option<Slice>, IoError> {
                let mut head = [0u8; 132];
                let mut f = fs::File::open(&file)?;
                let got = crate::io::nrrd::read_full(&mut f, &mut head)?;
                if !has_magic(&head[..got]) {
                    return Ok(None);
                }
                let bytes = fs::read(&file)?;
                crate::io::inputs::record(&file);
                let obj = open_bytes(&bytes)?;
                if !has_pixel_data(&obj) {
                    return Ok(None);
                }
                if let Some(uid) = &wanted {
                    let series = text(&obj, tags::SERIES_INSTANCE_UID, "SeriesInstanceUID")?
                        .unwrap_or_default();
                    if &series != uid {
                        return Ok(None);
                    }
                }
                slice_from(&obj).map(Some)
            };
            if let Some(s) = read_one().map_err(|e| e.in_file(&file))? {
                if slices.is_empty() {
                    // At most one slice a file; assembling copies the
                    // slices' samples into the volume, so both are held.
                    let dims = [s.size[0], s.size[1], candidates];
                    let count = dims.iter().fold(1u64, |a, &d| a.saturating_mul(d as u64));
                    crate::budget::check_load(dims, count.saturating_mul(4))?;
                }
                slices.push(s);
            }
        }
        assemble(slices)
    };
    go().map_err(|e| e.in_file(path))
}
