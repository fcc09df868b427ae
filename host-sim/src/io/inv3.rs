//! InVesalius 3 projects (`.inv3`): a gzip-compressed tar archive whose
//! `main.plist` (an XML property list) describes the image matrix:
//!
//! - `matrix.dtype`: a NumPy type name (`int16` for CT), little endian;
//! - `matrix.filename`: the archive member holding the samples (`matrix.dat`);
//! - `matrix.shape`: `[z, y, x]` (NumPy C order, so `x` is fastest);
//! - `spacing`: `[x, y, z]` in mm.
//!
//! The samples are read straight from the archive as it is decompressed.
//! The rest of the archive is then read through (not kept) so that a
//! truncated or corrupt archive is reported even when the damage lies
//! after the matrix: the gzip CRC covers the whole file.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use indicatif::ProgressBar;

use plist::{Dictionary, Value};

use super::{decode_samples, open_counted, MaybeGzip};
use crate::io::nrrd::{excerpt, format_error, Endian, IoError, SampleType};
use fvr_engine::volume::{check_spacing, Volume};

/// Format name of the archive in error messages.
const ARCHIVE: &str = "InVesalius .inv3 archive";
/// Format name of the metadata in error messages.
const PLIST: &str = "InVesalius main.plist";

/// The member holding the metadata.
pub const MAIN_PLIST: &str = "main.plist";

/// Largest `main.plist` accepted, in bytes.
const MAX_PLIST_BYTES: u64 = 1 << 20;

/// The image matrix `main.plist` describes.
#[derive(Clone, Debug, PartialEq)]
pub struct MatrixInfo {
    /// Archive member holding the samples.
    pub filename: String,
    /// Sample type.
    pub ty: SampleType,
    /// Sizes `[x, y, z]` (the plist's shape reversed).
    pub dims: [usize; 3],
    /// Spacing `[x, y, z]` in mm.
    pub spacing: [f64; 3],
}

/// Read the matrix description from the text of `main.plist`.
///
/// # Errors
/// Malformed XML, or a missing or malformed `matrix.dtype`,
/// `matrix.filename`, `matrix.shape` or `spacing`.
pub fn parse_main_plist(text: &str) -> Result<MatrixInfo, IoError> {
    let root = parse_plist(text).map_err(|e| format_error(PLIST, "xml", e))?;
    let root = root.as_dictionary();
    let matrix = get(root, "matrix").ok_or_else(|| missing("matrix"))?;
    let matrix = matrix.as_dictionary();
    let dtype = get(matrix, "dtype")
        .ok_or_else(|| missing("matrix.dtype"))?
        .as_string()
        .ok_or_else(|| format_error(PLIST, "matrix.dtype", "is not a string"))?;
    let ty = numpy_type(dtype)?;
    let filename = get(matrix, "filename")
        .ok_or_else(|| missing("matrix.filename"))?
        .as_string()
        .filter(|s| !s.is_empty())
        .ok_or_else(|| format_error(PLIST, "matrix.filename", "is not a non-empty string"))?
        .to_owned();
    let shape = numbers(get(matrix, "shape"), "matrix.shape")?;
    let mut dims = [0usize; 3];
    for (axis, &n) in shape.iter().rev().enumerate() {
        if !(n >= 1.0 && n.fract() == 0.0 && n <= i64::MAX as f64) {
            return Err(format_error(
                PLIST,
                "matrix.shape",
                format!("{shape:?} has size {n}; sizes must be whole numbers of at least 1"),
            ));
        }
        dims[axis] = n as usize;
    }
    let spacing = numbers(get(root, "spacing"), "spacing")?;
    let spacing =
        check_spacing(spacing).map_err(|e| format_error(PLIST, "spacing", e.to_string()))?;
    Ok(MatrixInfo {
        filename,
        ty,
        dims,
        spacing,
    })
}

/// Collections nested deeper than this are refused before the value is
/// built (building recurses once per level).
pub const MAX_PLIST_DEPTH: usize = 64;

/// Parse an XML property list with the `plist` crate, refusing nesting
/// deeper than [`MAX_PLIST_DEPTH`] first.
///
/// # Errors
/// Malformed XML or property list, or nesting too deep, as text.
pub fn parse_plist(text: &str) -> Result<Value, String> {
    // Text cannot hold a raw `<`, so every `<` opens markup; a comment that
    // mentions a collection can only make this count stricter.
    // The XML reader matches elements by their local name, so a prefixed
    // `<x:array>` is an array too: the prefix is dropped before comparing.
    let mut depth = 0usize;
    for (i, _) in text.match_indices('<') {
        let tag = &text[i + 1..];
        let end = tag.find('>').map_or(tag.len(), |e| e);
        let self_closing = tag[..end].ends_with('/');
        let (closing, tag) = match tag.strip_prefix('/') {
            Some(t) => (true, t),
            None => (false, tag),
        };
        let name_end = tag
            .find(|c: char| c.is_whitespace() || c == '>' || c == '/')
            .unwrap_or(tag.len());
        let name = &tag[..name_end];
        let local = name.rsplit(':').next().unwrap_or(name);
        if local != "array" && local != "dict" {
            continue;
        }
        if closing {
            depth = depth.saturating_sub(1);
        } else if !self_closing {
            depth += 1;
            if depth > MAX_PLIST_DEPTH {
                return Err(format!("nested deeper than {MAX_PLIST_DEPTH}"));
            }
        }
    }
    Value::from_reader_xml(text.as_bytes()).map_err(|e| e.to_string())
}

/// `key` of a dictionary value, if it is one.
fn get<'a>(dict: Option<&'a Dictionary>, key: &str) -> Option<&'a Value> {
    dict.and_then(|d| d.get(key))
}

/// An integer or real as `f64`.
fn as_f64(v: &Value) -> Option<f64> {
    match v {
        Value::Integer(i) => i
            .as_signed()
            .map(|i| i as f64)
            .or_else(|| i.as_unsigned().map(|u| u as f64)),
        Value::Real(r) => Some(*r),
        _ => None,
    }
}

#[cold]
fn missing(field: &'static str) -> IoError {
    format_error(PLIST, field, "is missing")
}

/// Three numbers from an array value.
fn numbers(value: Option<&Value>, field: &'static str) -> Result<[f64; 3], IoError> {
    let items = value
        .ok_or_else(|| missing(field))?
        .as_array()
        .ok_or_else(|| format_error(PLIST, field, "is not an array"))?;
    let values: Option<Vec<f64>> = items.iter().map(as_f64).collect();
    match values.as_deref() {
        Some(&[a, b, c]) => Ok([a, b, c]),
        _ => Err(format_error(
            PLIST,
            field,
            format!("expected an array of 3 numbers, got {} items", items.len()),
        )),
    }
}

fn numpy_type(dtype: &str) -> Result<SampleType, IoError> {
    Ok(match dtype {
        "uint8" => SampleType::U8,
        "int8" => SampleType::I8,
        "uint16" => SampleType::U16,
        "int16" => SampleType::I16,
        "uint32" => SampleType::U32,
        "int32" => SampleType::I32,
        "float32" => SampleType::F32,
        "float64" => SampleType::F64,
        other => {
            return Err(format_error(
                PLIST,
                "matrix.dtype",
                format!(
                    "`{}` is not supported; expected uint8, int8, uint16, int16, uint32, int32, float32 or float64",
                    excerpt(other)
                ),
            ))
        }
    })
}

/// Read an `.inv3` project's image matrix, advancing `progress` by the bytes
/// read from disk. Errors carry the path.
pub fn read_inv3_with_progress(path: &Path, progress: &ProgressBar) -> Result<Volume, IoError> {
    let go = || read_inv3_from(|| open_counted(path, progress));
    go().map_err(|e| e.in_file(path))
}

/// Parse an `.inv3` archive (gzip-compressed or plain tar) held in memory.
pub fn parse_inv3(bytes: &[u8]) -> Result<Volume, IoError> {
    read_inv3_from(|| Ok(bytes))
}

#[cold]
fn tar_error(e: std::io::Error) -> IoError {
    format_error(
        ARCHIVE,
        "tar",
        format!("cannot read the archive (corrupt or truncated gzip or tar data): {e}"),
    )
}

/// Read the archive that `open` yields. The samples are decoded as they
/// stream past: when their member comes before `main.plist` (which says how
/// to read them), the archive is opened again for a second pass rather than
/// buffering the member, so memory is the decoded volume alone.
fn read_inv3_from<R: BufRead>(open: impl Fn() -> Result<R, IoError>) -> Result<Volume, IoError> {
    let (info, volume) = scan(open()?, None)?;
    let volume = match (volume, info) {
        (Some(volume), _) => volume,
        (None, None) => {
            return Err(format_error(
                ARCHIVE,
                MAIN_PLIST,
                "the archive has no main.plist: not an InVesalius project",
            ))
        }
        (None, Some(info)) => match scan(open()?, Some(&info))? {
            (_, Some(volume)) => volume,
            (_, None) => {
                return Err(format_error(
                    ARCHIVE,
                    "matrix.filename",
                    format!(
                        "main.plist names `{}`, which is not in the archive",
                        excerpt(&info.filename)
                    ),
                ))
            }
        },
    };
    Ok(volume)
}

/// One pass over the archive: `main.plist` (unless `known` already) and
/// the samples, if their member comes after it. Reads the archive to its
/// end (the end-of-archive padding and the gzip trailer), so that damage
/// anywhere is reported.
fn scan<R: BufRead>(
    reader: R,
    known: Option<&MatrixInfo>,
) -> Result<(Option<MatrixInfo>, Option<Volume>), IoError> {
    let mut archive = tar::Archive::new(MaybeGzip::new(reader)?);
    let mut info: Option<MatrixInfo> = None;
    let mut volume: Option<Volume> = None;
    for entry in archive.entries().map_err(tar_error)? {
        let entry = entry.map_err(tar_error)?;
        if volume.is_some() {
            continue;
        }
        let name = member_name(&entry);
        if known.is_none() && name == MAIN_PLIST {
            info = Some(parse_main_plist(&read_plist(entry)?)?);
        } else if let Some(info) = known.or(info.as_ref()) {
            if name == info.filename {
                let size = entry.size();
                volume = Some(decode_matrix(info, entry, size)?);
            }
        }
    }
    let mut rest = archive.into_inner();
    std::io::copy(&mut rest, &mut std::io::sink()).map_err(tar_error)?;
    rest.finish()?;
    Ok((info, volume))
}

/// The last component of a member's path (`tmpXYZ/main.plist` → `main.plist`).
fn member_name<R: Read>(entry: &tar::Entry<'_, R>) -> String {
    let path = entry.path_bytes();
    let last = path.rsplit(|&b| b == b'/').next().unwrap_or(&path);
    String::from_utf8_lossy(last).into_owned()
}

fn read_plist<R: Read>(entry: tar::Entry<'_, R>) -> Result<String, IoError> {
    if entry.size() > MAX_PLIST_BYTES {
        return Err(format_error(
            ARCHIVE,
            MAIN_PLIST,
            format!(
                "is {} bytes, more than the {MAX_PLIST_BYTES} accepted",
                entry.size()
            ),
        ));
    }
    let mut bytes = Vec::new();
    entry
        .take(MAX_PLIST_BYTES)
        .read_to_end(&mut bytes)
        .map_err(tar_error)?;
    String::from_utf8(bytes)
        .map_err(|e| format_error(PLIST, "xml", format!("is not UTF-8 text: {e}")))
}

/// Decode the member `reader` of `size` bytes as `info` describes.
fn decode_matrix<R: Read>(info: &MatrixInfo, reader: R, size: u64) -> Result<Volume, IoError> {
    let (_, data_bytes) = super::check_dims(info.dims, info.ty, (PLIST, "matrix.shape"))?;
    if size != data_bytes as u64 {
        return Err(format_error(
            ARCHIVE,
            "matrix.filename",
            format!(
                "member `{}` holds {size} bytes, but a matrix of shape {:?} ({}) needs {data_bytes}",
                excerpt(&info.filename),
                [info.dims[2], info.dims[1], info.dims[0]],
                info.ty.nrrd_name()
            ),
        ));
    }
    let reader = MaybeGzip::Plain(BufReader::new(reader));
    let volume = decode_samples(
        reader,
        info.dims,
        info.ty,
        Endian::Little,
        (PLIST, "matrix.shape"),
    )?;
    Ok(Volume {
        spacing: info.spacing,
        ..volume
    })
}

/// The text of a `main.plist` for a matrix of `dims` `[x, y, z]`, `dtype`
/// and `spacing`, in the layout InVesalius writes. A test and fixture helper.
pub fn main_plist_text(dims: [usize; 3], dtype: &str, spacing: [f64; 3]) -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <!DOCTYPE plist PUBLIC \"-//Apple Computer//DTD PLIST 1.0//EN\" \"http://www.apple.com/DTDs/PropertyList-1.0.dtd\">\n\
         <plist version=\"1.0\">\n<dict>\n\
         \t<key>matrix</key>\n\t<dict>\n\
         \t\t<key>dtype</key>\n\t\t<string>{dtype}</string>\n\
         \t\t<key>filename</key>\n\t\t<string>matrix.dat</string>\n\
         \t\t<key>shape</key>\n\t\t<array>\n\
         \t\t\t<integer>{}</integer>\n\t\t\t<integer>{}</integer>\n\t\t\t<integer>{}</integer>\n\
         \t\t</array>\n\t</dict>\n\
         \t<key>modality</key>\n\t<string>CT</string>\n\
         \t<key>spacing</key>\n\t<array>\n\
         \t\t<real>{:?}</real>\n\t\t<real>{:?}</real>\n\t\t<real>{:?}</real>\n\
         \t</array>\n</dict>\n</plist>\n",
        dims[2], dims[1], dims[0], spacing[0], spacing[1], spacing[2]
    )
}

/// A gzip-compressed tar holding the members `(name, bytes)` in order, each
/// under a `project/` folder as InVesalius writes them. A test and fixture
/// helper.
pub fn encode_archive(members: &[(&str, &[u8])]) -> Vec<u8> {
    let gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    let mut builder = tar::Builder::new(gz);
    for (name, bytes) in members {
        let mut header = tar::Header::new_gnu();
        header.set_size(bytes.len() as u64);
        header.set_mode(0o644);
        header.set_cksum();
        builder
            .append_data(&mut header, format!("project/{name}"), *bytes)
            .expect("writing a tar into a Vec cannot fail");
    }
    builder
        .into_inner()
        .and_then(|gz| gz.finish())
        .expect("writing a tar into a Vec cannot fail")
}

/// A whole `.inv3` archive of an int16 matrix of `dims` `[x, y, z]`,
/// `x` fastest, with `spacing` in mm. A test and fixture helper.
///
/// # Panics
/// If `data.len()` is not the product of `dims`.
pub fn encode_inv3_i16(dims: [usize; 3], spacing: [f64; 3], data: &[i16]) -> Vec<u8> {
    assert_eq!(
        data.len(),
        dims.iter().product::<usize>(),
        "encode_inv3_i16"
    );
    let plist = main_plist_text(dims, "int16", spacing);
    let matrix: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    encode_archive(&[(MAIN_PLIST, plist.as_bytes()), ("matrix.dat", &matrix)])
}
