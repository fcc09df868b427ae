//! VolPack density files (`.den`), the format of the Stanford volume
//! rendering group's data sets, optionally gzip-compressed (`.den.gz`).
//!
//! Layout (from VolPack's example `denfile.c`, facts only): a 62-byte
//! header of 16-bit integers, then `map_length` unsigned bytes, `x`
//! fastest.
//!
//! | offset | field | meaning |
//! |---|---|---|
//! | 0 | `map_version` | 1; read as `0x0100` the header is byte-swapped |
//! | 2, 8, 14 | `orig_min`, `orig_max`, `orig_len` | 3 × i16 each: the original scan |
//! | 20, 26, 32 | `extr_min`, `extr_max`, `extr_len` | 3 × i16 each: the extracted part |
//! | 38, 44, 50 | `map_min`, `map_max`, `map_len` | 3 × i16 each: this volume; `map_len` are its sizes x, y, z |
//! | 56 | `map_warps` | i16 |
//! | 58 | `map_length` | i32: number of samples, the product of `map_len` |
//!
//! The byte order is the one in which `map_version` reads 1. The format
//! stores no voxel spacing: volumes get 1 mm.

use std::path::Path;

use indicatif::ProgressBar;

use super::{decode_samples, open_counted, MaybeGzip};
use crate::io::nrrd::{format_error, Endian, IoError, SampleType};
use fvr_engine::volume::Volume;

/// Bytes of the header.
pub const HEADER_BYTES: usize = 62;

/// Format name in error messages.
const FORMAT: &str = "VolPack .den header";

/// Offset of `map_len` (3 × i16).
const MAP_LEN_OFFSET: usize = 50;
/// Offset of `map_length` (i32).
const MAP_LENGTH_OFFSET: usize = 58;

/// The decoded header fields a reader needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DenHeader {
    /// Byte order of the header.
    pub endian: Endian,
    /// Sizes `map_len`, x fastest.
    pub dims: [usize; 3],
}

/// Whether `head` starts like a `.den` file: `map_version` 1 in either byte
/// order, and a `map_length` equal to the product of positive `map_len`.
pub fn has_magic(head: &[u8]) -> bool {
    head.get(..HEADER_BYTES)
        .is_some_and(|h| parse_header(h).is_ok())
}

/// Decode and check the 62-byte header.
///
/// # Errors
/// A wrong `map_version` (not a `.den` file), a size that is zero or
/// negative, or a `map_length` that is not the product of the sizes.
pub fn parse_header(header: &[u8]) -> Result<DenHeader, IoError> {
    let header = crate::io::error::header(FORMAT, "map_version", header, HEADER_BYTES)?;
    let endian = match [header[0], header[1]] {
        [1, 0] => Endian::Little,
        [0, 1] => Endian::Big,
        found => {
            return Err(format_error(
                FORMAT,
                "map_version",
                format!(
                    "expected 1 (bytes `01 00` or `00 01`), found bytes `{:02x} {:02x}`: not a VolPack density file",
                    found[0], found[1]
                ),
            ))
        }
    };
    let i16_at = |off: usize| {
        let b = [header[off], header[off + 1]];
        match endian {
            Endian::Little => i16::from_le_bytes(b),
            Endian::Big => i16::from_be_bytes(b),
        }
    };
    let lens = [0, 1, 2].map(|a| i16_at(MAP_LEN_OFFSET + 2 * a));
    if let Some(axis) = lens.iter().position(|&n| n <= 0) {
        return Err(format_error(
            FORMAT,
            "map_len",
            format!(
                "size {axis} is {} in {lens:?}; every size must be at least 1",
                lens[axis]
            ),
        ));
    }
    let dims = lens.map(|n| n as usize);
    let word: [u8; 4] = [0, 1, 2, 3].map(|i| header[MAP_LENGTH_OFFSET + i]);
    let map_length = match endian {
        Endian::Little => i32::from_le_bytes(word),
        Endian::Big => i32::from_be_bytes(word),
    };
    let product = dims[0] as u64 * dims[1] as u64 * dims[2] as u64;
    if u64::try_from(map_length).ok() != Some(product) {
        return Err(format_error(
            FORMAT,
            "map_length",
            format!(
                "is {map_length} but the sizes `map_len` {dims:?} hold {product} samples: inconsistent header"
            ),
        ));
    }
    Ok(DenHeader { endian, dims })
}

/// Read a `.den` or `.den.gz` file, advancing `progress` by the bytes read
/// from disk. Errors carry the path.
pub fn read_den_with_progress(path: &Path, progress: &ProgressBar) -> Result<Volume, IoError> {
    let go = || read_den_from(open_counted(path, progress)?);
    go().map_err(|e| e.in_file(path))
}

/// Parse a whole `.den` file (optionally gzip-compressed) held in memory.
pub fn parse_den(bytes: &[u8]) -> Result<Volume, IoError> {
    read_den_from(bytes)
}

fn read_den_from<R: std::io::BufRead>(reader: R) -> Result<Volume, IoError> {
    let mut reader = MaybeGzip::new(reader)?;
    let mut header = [0u8; HEADER_BYTES];
    reader.read_exact_or(&mut header, FORMAT, "map_version")?;
    let h = parse_header(&header)?;
    decode_samples(
        reader,
        h.dims,
        SampleType::U8,
        Endian::Little,
        (FORMAT, "map_len"),
    )
}

/// Encode a `.den` file of `dims` (each at most `i16::MAX`) holding `data`,
/// with the header in `endian` order. A test and fixture helper.
///
/// # Panics
/// If a size exceeds `i16::MAX` or `data.len()` is not their product.
pub fn encode_den(dims: [usize; 3], data: &[u8], endian: Endian) -> Vec<u8> {
    let lens = dims.map(|d| i16::try_from(d).expect("den sizes fit in i16"));
    let count = dims.iter().product::<usize>();
    assert_eq!(data.len(), count, "encode_den: data length");
    let map_length = i32::try_from(count).expect("den sample count fits in i32");
    let put16 = |v: i16| match endian {
        Endian::Little => v.to_le_bytes(),
        Endian::Big => v.to_be_bytes(),
    };
    let mut out = Vec::with_capacity(HEADER_BYTES + count);
    out.extend(put16(1));
    // orig, extr and map: min 0, max len - 1, len.
    for _ in 0..3 {
        out.extend(lens.iter().flat_map(|_| put16(0)));
        out.extend(lens.iter().flat_map(|&l| put16(l - 1)));
        out.extend(lens.iter().flat_map(|&l| put16(l)));
    }
    out.extend(put16(0));
    out.extend(match endian {
        Endian::Little => map_length.to_le_bytes(),
        Endian::Big => map_length.to_be_bytes(),
    });
    out.extend_from_slice(data);
    out
}
