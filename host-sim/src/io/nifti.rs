//! NIfTI-1 volumes: `.nii`, `.nii.gz`, and `.hdr` + `.img` pairs.
//!
//! The 348-byte header is parsed by the `nifti` crate (which also finds its
//! byte order); this module checks it and streams the samples itself, so
//! that truncated files, huge sizes and bad scaling get precise errors and
//! no allocation beyond what the file holds.
//!
//! What is used:
//! - `dim`: 1 to 3 spatial sizes; a 4th or higher dimension must be 1
//!   (a single 3D volume).
//! - `datatype`: uint8, int8, uint16, int16, uint32, int32, float32,
//!   float64. (`bitpix` is ignored, as most readers do.)
//! - `pixdim[1..=3]` in the spatial unit of `xyzt_units` (metre, mm or
//!   micron; unknown is taken as mm) become the spacing in mm.
//! - `scl_slope`, `scl_inter`: when the slope is non-zero and finite, every
//!   sample `x` becomes `slope·x + inter` (NIfTI-1 §scl_slope); a zero or
//!   NaN slope means no scaling.
//! - `vox_offset`: where the samples start (after the header extensions,
//!   which are skipped).
//!
//! - The orientation, from the sform (`sform_code > 0`), else the qform
//!   (`qform_code > 0`, quaternion `quatern_b/c/d` and `qfac = pixdim[0]`):
//!   the axes are permuted and flipped to the closest RAS order, as 3D
//!   Slicer and nibabel's `as_closest_canonical` do. The renderer's x, y, z
//!   then run to the subject's right, anterior and superior, so the default
//!   up hint `+z` shows a head upright. Each file axis goes to the world axis
//!   it runs closest to (greedily, largest direction cosine first). An
//!   oblique rotation is not resampled: the remaining rotation (at most 45°
//!   per axis) stays in the picture. With both codes 0 the index order is
//!   kept (NIfTI-1 "method 1").

use std::io::BufRead;
use std::path::{Path, PathBuf};

use ::nifti::{NiftiHeader, NiftiType, Unit};
use indicatif::ProgressBar;

use super::{decode_samples, open_counted, MaybeGzip};
use crate::io::nrrd::{format_error, Endian, IoError, SampleType};
use fvr_engine::volume::{check_spacing, Orientation, Volume};

/// Bytes of a NIfTI-1 header.
pub const HEADER_BYTES: usize = 348;

/// Offset of `dim[0]` in the header.
const DIM_OFFSET: usize = 40;

/// Format name in error messages.
const FORMAT: &str = "NIfTI-1 header";

/// `magic` of a single-file NIfTI-1 (`.nii`).
pub(crate) const MAGIC_SINGLE: &[u8; 4] = b"n+1\0";
/// `magic` of a header/image pair (`.hdr` + `.img`).
const MAGIC_PAIR: &[u8; 4] = b"ni1\0";
/// Offset of `magic`.
pub(crate) const MAGIC_OFFSET: usize = 344;

/// Whether `head` starts with a NIfTI-1 header: `sizeof_hdr` 348 in either
/// byte order and the magic `n+1` or `ni1`.
pub fn has_magic(head: &[u8]) -> bool {
    let sizeof = head.get(..4).map(|b| [b[0], b[1], b[2], b[3]]);
    let magic = head.get(MAGIC_OFFSET..MAGIC_OFFSET + 4);
    sizeof.is_some_and(|b| i32::from_le_bytes(b) == 348 || i32::from_be_bytes(b) == 348)
        && (magic == Some(MAGIC_SINGLE) || magic == Some(MAGIC_PAIR))
}

/// A checked NIfTI-1 header: everything needed to read the samples.
#[derive(Clone, Debug, PartialEq)]
pub struct NiftiLayout {
    /// Sizes `dim[1..=3]`, padded with 1.
    pub dims: [usize; 3],
    /// Sample type from `datatype`.
    pub ty: SampleType,
    /// Byte order of header and data.
    pub endian: Endian,
    /// Spacing in mm from `pixdim` and `xyzt_units`.
    pub spacing: [f64; 3],
    /// `(slope, inter)` to apply, or `None`.
    pub scaling: Option<(f32, f32)>,
    /// Byte offset of the samples in their file.
    pub vox_offset: u64,
    /// Whether the samples are in a separate `.img` file (magic `ni1`).
    pub pair: bool,
    /// The permutation and flips to the closest RAS order.
    pub to_ras: AxisMap,
    /// The file's axes and origin in RAS (from the sform, else the qform),
    /// before that reordering; `None` with both codes 0.
    pub orientation: Option<Orientation>,
}

/// A permutation and flips of the three axes: file axis `a` becomes axis
/// `world[a]` of the result, reversed when `flip[a]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisMap {
    /// The result's axis for each file axis.
    pub world: [usize; 3],
    /// Whether each file axis runs against its result axis.
    pub flip: [bool; 3],
    /// Which header field gave it: `"sform"`, `"qform"` or `"none"`.
    pub source: &'static str,
}

impl AxisMap {
    /// Keep the file's order.
    pub const IDENTITY: Self = Self {
        world: [0, 1, 2],
        flip: [false; 3],
        source: "none",
    };

    /// The closest axis order to a direction-cosine matrix `m` (`m[w][a]`:
    /// world component `w` of file axis `a`), greedily by the largest
    /// normalized cosine. `None` when a column is zero or not finite.
    pub fn closest(m: [[f64; 3]; 3], source: &'static str) -> Option<Self> {
        let mut cos = [[0.0f64; 3]; 3];
        for a in 0..3 {
            let norm = (0..3).map(|w| m[w][a] * m[w][a]).sum::<f64>().sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                return None;
            }
            for w in 0..3 {
                cos[w][a] = m[w][a] / norm;
            }
        }
        let (mut world, mut flip) = ([usize::MAX; 3], [false; 3]);
        let mut row_used = [false; 3];
        for _ in 0..3 {
            let mut best = (0usize, 0usize, -1.0f64);
            for (w, row) in cos.iter().enumerate() {
                for (a, &c) in row.iter().enumerate() {
                    if !row_used[w] && world[a] == usize::MAX && c.abs() > best.2 {
                        best = (w, a, c.abs());
                    }
                }
            }
            let (w, a, _) = best;
            row_used[w] = true;
            world[a] = w;
            flip[a] = cos[w][a] < 0.0;
        }
        Some(Self {
            world,
            flip,
            source,
        })
    }

    /// Reorder `volume` (samples and spacing) by this map.
    pub fn apply(&self, volume: &mut Volume) {
        if self.world == [0, 1, 2] && self.flip == [false; 3] {
            return;
        }
        let old = volume.dims;
        let mut dims = [0usize; 3];
        let mut spacing = [0.0f64; 3];
        for a in 0..3 {
            dims[self.world[a]] = old[a];
            spacing[self.world[a]] = volume.spacing[a];
        }
        let mut data = Vec::with_capacity(volume.data.len());
        let mut p = [0usize; 3];
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let q = [x, y, z];
                    for a in 0..3 {
                        let c = q[self.world[a]];
                        p[a] = if self.flip[a] { old[a] - 1 - c } else { c };
                    }
                    data.push(volume.data[p[0] + old[0] * (p[1] + old[1] * p[2])]);
                }
            }
        }
        volume.dims = dims;
        volume.data = data;
        volume.spacing = spacing;
    }
}

/// Check the 348 header bytes and decode the fields a reader needs.
///
/// # Errors
/// Not a NIfTI-1 header (size or magic), a NIfTI-2 header, bad or
/// unsupported `dim`, `datatype`, `pixdim`, `xyzt_units`, `vox_offset` or
/// scaling; each names the field.
pub fn parse_header(bytes: &[u8]) -> Result<NiftiLayout, IoError> {
    let bytes = crate::io::error::header(FORMAT, "sizeof_hdr", bytes, HEADER_BYTES)?;
    let sizeof = [bytes[0], bytes[1], bytes[2], bytes[3]];
    if i32::from_le_bytes(sizeof) == 540 || i32::from_be_bytes(sizeof) == 540 {
        return Err(format_error(
            FORMAT,
            "sizeof_hdr",
            "is 540: this is a NIfTI-2 file, and only NIfTI-1 is supported",
        ));
    }
    if !has_magic(bytes) {
        return Err(format_error(
            FORMAT,
            "magic",
            format!(
                "expected `sizeof_hdr` 348 and magic `n+1` or `ni1`, found `sizeof_hdr` bytes {} and magic {}: not a NIfTI-1 file",
                hex(&sizeof),
                hex(&bytes[MAGIC_OFFSET..MAGIC_OFFSET + 4])
            ),
        ));
    }
    // The nifti crate guesses the byte order from `dim[0]`, so a bad
    // `dim[0]` would be reported byte-swapped; `sizeof_hdr` tells the order.
    let dim0 = [bytes[DIM_OFFSET], bytes[DIM_OFFSET + 1]];
    let dim0 = if i32::from_le_bytes(sizeof) == 348 {
        i16::from_le_bytes(dim0)
    } else {
        i16::from_be_bytes(dim0)
    };
    check_rank(dim0)?;
    let h = NiftiHeader::from_reader(bytes).map_err(|e| {
        format_error(
            FORMAT,
            "magic",
            format!("the nifti crate refused the header: {e}"),
        )
    })?;
    let endian = match h.endianness {
        ::nifti::Endianness::Little => Endian::Little,
        ::nifti::Endianness::Big => Endian::Big,
    };
    let dims = parse_dim(&h.dim)?;
    let ty = sample_type(h.datatype)?;
    let spacing = parse_spacing(&h)?;
    let scaling = parse_scaling(h.scl_slope, h.scl_inter)?;
    let pair = &h.magic == MAGIC_PAIR;
    let vox_offset = parse_vox_offset(h.vox_offset, pair)?;
    let (to_ras, orientation) = parse_orientation(&h)?;
    Ok(NiftiLayout {
        dims,
        ty,
        endian,
        spacing,
        scaling,
        vox_offset,
        pair,
        to_ras,
        orientation,
    })
}

/// The axis map from the sform, else the qform, else the identity, and the
/// orientation it was read from.
fn parse_orientation(h: &NiftiHeader) -> Result<(AxisMap, Option<Orientation>), IoError> {
    if h.sform_code > 0 {
        let rows = [h.srow_x, h.srow_y, h.srow_z];
        let m: [[f64; 3]; 3] =
            core::array::from_fn(|w| core::array::from_fn(|a| rows[w][a] as f64));
        let columns: [[f64; 3]; 3] = core::array::from_fn(|a| {
            let c: [f64; 3] = core::array::from_fn(|w| m[w][a]);
            let norm = c.iter().map(|v| v * v).sum::<f64>().sqrt();
            c.map(|v| v / norm)
        });
        if columns.iter().flatten().all(|v| v.is_finite())
            && !crate::io::spans_independent_axes(&columns)
        {
            return Err(format_error(
                FORMAT,
                "srow_x",
                format!(
                    "sform_code is {} but the sform's 3×3 part is singular (its axes are \
                     parallel or nearly so): srow_x {:?}, srow_y {:?}, srow_z {:?}",
                    h.sform_code, h.srow_x, h.srow_y, h.srow_z
                ),
            ));
        }
        let origin = [h.srow_x[3], h.srow_y[3], h.srow_z[3]].map(|v| v as f64);
        let orientation = Orientation::from_columns(m, origin);
        let map = AxisMap::closest(m, "sform").ok_or_else(|| {
            format_error(
                FORMAT,
                "srow_x",
                format!(
                    "sform_code is {} but the sform's 3×3 part has a zero or non-finite column: \
                     srow_x {:?}, srow_y {:?}, srow_z {:?}",
                    h.sform_code, h.srow_x, h.srow_y, h.srow_z
                ),
            )
        })?;
        return Ok((map, orientation));
    }
    if h.qform_code > 0 {
        let (b, c, d) = (h.quatern_b as f64, h.quatern_c as f64, h.quatern_d as f64);
        let bcd = b * b + c * c + d * d;
        // NIfTI-1 allows rounding to push b²+c²+d² a little above 1.
        if !bcd.is_finite() || bcd > 1.0 + 1e-4 {
            return Err(format_error(
                FORMAT,
                "quatern_b",
                format!(
                    "qform_code is {} but quatern_b/c/d = {b}, {c}, {d} is not a unit quaternion's \
                     vector part (b²+c²+d² = {bcd})",
                    h.qform_code
                ),
            ));
        }
        let a = (1.0 - bcd).max(0.0).sqrt();
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let m = [
            [
                a * a + b * b - c * c - d * d,
                2.0 * (b * c - a * d),
                qfac * 2.0 * (b * d + a * c),
            ],
            [
                2.0 * (b * c + a * d),
                a * a + c * c - b * b - d * d,
                qfac * 2.0 * (c * d - a * b),
            ],
            [
                2.0 * (b * d - a * c),
                2.0 * (c * d + a * b),
                qfac * (a * a + d * d - c * c - b * b),
            ],
        ];
        let origin = [h.quatern_x, h.quatern_y, h.quatern_z].map(|v| v as f64);
        let orientation = Orientation::from_columns(m, origin);
        return Ok((
            AxisMap::closest(m, "qform").unwrap_or(AxisMap::IDENTITY),
            orientation,
        ));
    }
    Ok((AxisMap::IDENTITY, None))
}

fn hex(bytes: &[u8]) -> String {
    let parts: Vec<String> = bytes.iter().map(|b| format!("{b:02x}")).collect();
    format!("`{}`", parts.join(" "))
}

/// `dim[0]` (the number of dimensions) as a rank from 1 to 7.
fn check_rank(dim0: i16) -> Result<usize, IoError> {
    if !(1..=7).contains(&dim0) {
        return Err(format_error(
            FORMAT,
            "dim",
            format!("dim[0] (the number of dimensions) is {dim0}; it must be 1 to 7"),
        ));
    }
    Ok(dim0 as usize)
}

/// `dim[0]` spatial rank 1 to 3 (higher ranks only with sizes of 1), and
/// `dim[1..=3]` positive.
fn parse_dim(dim: &[u16; 8]) -> Result<[usize; 3], IoError> {
    // The header stores `dim` as i16; the crate reads it as u16.
    let signed = dim.map(|d| d as i16);
    let rank = check_rank(signed[0])?;
    let mut dims = [1usize; 3];
    for (axis, &n) in signed.iter().enumerate().take(rank + 1).skip(1) {
        if n <= 0 {
            return Err(format_error(
                FORMAT,
                "dim",
                format!(
                    "dim[{axis}] is {n} in {:?}; every size must be at least 1",
                    &signed[1..=rank]
                ),
            ));
        }
        match dims.get_mut(axis - 1) {
            Some(d) => *d = n as usize,
            None if n == 1 => {}
            None => {
                return Err(format_error(
                    FORMAT,
                    "dim",
                    format!(
                        "dim[{axis}] is {n}: this file holds {} volumes of {:?} ({}D data), but fvr renders a single 3D volume; extract one first (e.g. `fslroi in out 0 1`)",
                        signed[4..=rank].iter().map(|&v| v as i64).product::<i64>(),
                        &signed[1..=3.min(rank)],
                        rank
                    ),
                ));
            }
        }
    }
    Ok(dims)
}

fn sample_type(datatype: i16) -> Result<SampleType, IoError> {
    let kind: Option<NiftiType> = num_from_i16(datatype);
    Ok(match kind {
        Some(NiftiType::Uint8) => SampleType::U8,
        Some(NiftiType::Int8) => SampleType::I8,
        Some(NiftiType::Uint16) => SampleType::U16,
        Some(NiftiType::Int16) => SampleType::I16,
        Some(NiftiType::Uint32) => SampleType::U32,
        Some(NiftiType::Int32) => SampleType::I32,
        Some(NiftiType::Float32) => SampleType::F32,
        Some(NiftiType::Float64) => SampleType::F64,
        Some(other) => {
            return Err(format_error(
                FORMAT,
                "datatype",
                format!(
                    "{datatype} ({other:?}) is not supported; expected a scalar type: uint8, int8, uint16, int16, uint32, int32, float32 or float64"
                ),
            ))
        }
        None => {
            return Err(format_error(
                FORMAT,
                "datatype",
                format!("{datatype} is not a NIfTI-1 data type code"),
            ))
        }
    })
}

/// `NiftiType` from its code, through the crate's own validation.
fn num_from_i16(code: i16) -> Option<NiftiType> {
    let header = NiftiHeader {
        datatype: code,
        ..NiftiHeader::default()
    };
    header.data_type().ok()
}

/// `pixdim[1..=3]` in mm. Axes beyond the rank keep 1 mm.
fn parse_spacing(h: &NiftiHeader) -> Result<[f64; 3], IoError> {
    let rank = (h.dim[0] as usize).min(3);
    let to_mm = match h.xyzt_to_space() {
        Ok(Unit::Meter) => 1000.0,
        Ok(Unit::Micron) => 1e-3,
        Ok(Unit::Mm) | Ok(Unit::Unknown) => 1.0,
        _ => {
            return Err(format_error(
                FORMAT,
                "xyzt_units",
                format!(
                    "spatial unit code {} is not metre (1), mm (2), micron (3) or unknown (0)",
                    h.xyzt_units & 7
                ),
            ))
        }
    };
    let mut spacing = fvr_engine::volume::DEFAULT_SPACING;
    for axis in 0..rank {
        spacing[axis] = h.pixdim[axis + 1] as f64 * to_mm;
    }
    check_spacing(spacing).map_err(|e| {
        format_error(
            FORMAT,
            "pixdim",
            format!("pixdim[{}] = {}: {e}", e.axis + 1, h.pixdim[e.axis + 1]),
        )
    })
}

/// `(slope, inter)` when scaling applies (non-zero finite slope).
fn parse_scaling(slope: f32, inter: f32) -> Result<Option<(f32, f32)>, IoError> {
    if slope == 0.0 || slope.is_nan() {
        return Ok(None);
    }
    if !slope.is_finite() {
        return Err(format_error(
            FORMAT,
            "scl_slope",
            format!("is {slope}; it must be finite (or 0 for no scaling)"),
        ));
    }
    if !inter.is_finite() {
        return Err(format_error(
            FORMAT,
            "scl_inter",
            format!("is {inter} while scl_slope is {slope}; it must be finite"),
        ));
    }
    if slope == 1.0 && inter == 0.0 {
        return Ok(None);
    }
    Ok(Some((slope, inter)))
}

/// The data offset: at least 348 in a single file, and a whole number.
fn parse_vox_offset(value: f32, pair: bool) -> Result<u64, IoError> {
    let min = if pair { 0.0 } else { HEADER_BYTES as f32 };
    if !(value.is_finite() && value >= min && value.fract() == 0.0 && value < 1e15) {
        return Err(format_error(
            FORMAT,
            "vox_offset",
            format!(
                "is {value}; it must be a whole number of bytes, at least {min} {}",
                if pair { "" } else { "(after the header)" }
            ),
        ));
    }
    Ok(value as u64)
}

/// Read a NIfTI-1 file. Errors carry the path.
pub fn read_nifti(path: &Path) -> Result<Volume, IoError> {
    read_nifti_with_progress(path, &ProgressBar::hidden())
}

/// [`read_nifti`], advancing `progress` by the bytes read from disk.
pub fn read_nifti_with_progress(path: &Path, progress: &ProgressBar) -> Result<Volume, IoError> {
    let go = || -> Result<Volume, IoError> {
        let mut reader = MaybeGzip::new(open_counted(path, progress)?)?;
        let layout = read_layout(&mut reader)?;
        if !layout.pair {
            return read_samples(reader, &layout, HEADER_BYTES as u64);
        }
        let img = image_path(path).ok_or_else(|| missing_image(path))?;
        let read_img = || {
            let data = MaybeGzip::new(open_counted(&img, progress)?)?;
            read_samples(data, &layout, 0)
        };
        read_img().map_err(|e| e.in_file(&img))
    };
    go().map_err(|e| e.in_file(path))
}

/// Parse a single-file NIfTI-1 (`.nii`, or `.nii.gz` bytes) held in memory.
pub fn parse_nifti(bytes: &[u8]) -> Result<Volume, IoError> {
    let mut reader = MaybeGzip::new(bytes)?;
    let layout = read_layout(&mut reader)?;
    if layout.pair {
        return Err(format_error(
            FORMAT,
            "magic",
            "is `ni1`: the samples are in a separate .img file, which can only be found from the header's path",
        ));
    }
    read_samples(reader, &layout, HEADER_BYTES as u64)
}

fn read_layout<R: BufRead>(reader: &mut MaybeGzip<R>) -> Result<NiftiLayout, IoError> {
    let mut header = [0u8; HEADER_BYTES];
    reader.read_exact_or(&mut header, FORMAT, "sizeof_hdr")?;
    parse_header(&header)
}

/// Skip to `vox_offset` (from byte `at`), decode, scale.
fn read_samples<R: BufRead>(
    mut reader: MaybeGzip<R>,
    layout: &NiftiLayout,
    at: u64,
) -> Result<Volume, IoError> {
    reader.skip(layout.vox_offset.saturating_sub(at), FORMAT, "vox_offset")?;
    let mut volume = decode_samples(
        reader,
        layout.dims,
        layout.ty,
        layout.endian,
        (FORMAT, "dim"),
    )?;
    volume.spacing = layout.spacing;
    if let Some((slope, inter)) = layout.scaling {
        apply_scaling(&mut volume, slope, inter)?;
    }
    let (dims, spacing) = (volume.dims, volume.spacing);
    layout.to_ras.apply(&mut volume);
    volume.orientation = layout.orientation.map(|o| {
        let map = &layout.to_ras;
        o.permuted(map.world, map.flip, dims, spacing)
    });
    Ok(volume)
}

/// `x ← slope·x + inter` in f64, refusing results beyond f32.
fn apply_scaling(volume: &mut Volume, slope: f32, inter: f32) -> Result<(), IoError> {
    let (slope, inter) = (slope as f64, inter as f64);
    for (n, v) in volume.data.iter_mut().enumerate() {
        let y = slope * *v as f64 + inter;
        let y32 = y as f32;
        if !y32.is_finite() {
            let [nx, ny, _] = volume.dims;
            return Err(format_error(
                FORMAT,
                "scl_slope",
                format!(
                    "scaling sample {} at voxel ({}, {}, {}) by {slope} and {inter} gives {y:e}, beyond f32",
                    *v,
                    n % nx,
                    (n / nx) % ny,
                    n / (nx * ny)
                ),
            ));
        }
        *v = y32;
    }
    Ok(())
}

/// The `.img` (or `.img.gz`) next to a `.hdr` (or `.hdr.gz`).
fn image_path(hdr: &Path) -> Option<PathBuf> {
    let name = hdr.file_name()?.to_str()?;
    let lower = name.to_ascii_lowercase();
    let stem_len = if lower.ends_with(".hdr.gz") {
        name.len() - 7
    } else if lower.ends_with(".hdr") {
        name.len() - 4
    } else {
        return None;
    };
    let stem = &name[..stem_len];
    let candidates = [".img", ".img.gz", ".IMG", ".IMG.GZ"];
    candidates
        .iter()
        .map(|ext| hdr.with_file_name(format!("{stem}{ext}")))
        .find(|p| p.exists())
}

#[cold]
fn missing_image(hdr: &Path) -> IoError {
    format_error(
        FORMAT,
        "magic",
        format!(
            "is `ni1`: the samples are in a separate .img file, but no .img or .img.gz sits next to `{}`",
            hdr.display()
        ),
    )
}

pub use super::nifti_encode::{encode_nifti_f32, offsets};
