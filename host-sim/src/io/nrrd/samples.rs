//! Sample types, encodings and byte orders, and conversion of sample bytes
//! to and from numbers.

use std::str::FromStr;

use super::error::{excerpt, invalid_argument, IoError};

/// The type of one stored sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleType {
    /// Unsigned 8-bit integer (NRRD `uchar`).
    U8,
    /// Signed 8-bit integer (NRRD `signed char`, also spelled `char`).
    I8,
    /// Unsigned 16-bit integer (NRRD `ushort`).
    U16,
    /// Signed 16-bit integer (NRRD `short`).
    I16,
    /// Unsigned 32-bit integer (NRRD `uint`).
    U32,
    /// Signed 32-bit integer (NRRD `int`).
    I32,
    /// IEEE 754 single precision (NRRD `float`).
    F32,
    /// IEEE 754 double precision (NRRD `double`).
    F64,
}

/// How the sample bytes are stored after the header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// Uncompressed bytes (NRRD `raw`).
    Raw,
    /// A gzip stream, possibly of several members (NRRD `gzip` or `gz`).
    Gzip,
}

/// Byte order of multi-byte samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Endian {
    /// Least significant byte first.
    Little,
    /// Most significant byte first.
    Big,
}

/// NRRD type names and their standard synonyms (lowercase, single spaces).
const NRRD_TYPE_NAMES: &[(&str, SampleType)] = &[
    ("signed char", SampleType::I8),
    ("int8", SampleType::I8),
    ("int8_t", SampleType::I8),
    ("char", SampleType::I8),
    ("uchar", SampleType::U8),
    ("unsigned char", SampleType::U8),
    ("uint8", SampleType::U8),
    ("uint8_t", SampleType::U8),
    ("short", SampleType::I16),
    ("short int", SampleType::I16),
    ("signed short", SampleType::I16),
    ("signed short int", SampleType::I16),
    ("int16", SampleType::I16),
    ("int16_t", SampleType::I16),
    ("ushort", SampleType::U16),
    ("unsigned short", SampleType::U16),
    ("unsigned short int", SampleType::U16),
    ("uint16", SampleType::U16),
    ("uint16_t", SampleType::U16),
    ("int", SampleType::I32),
    ("signed int", SampleType::I32),
    ("int32", SampleType::I32),
    ("int32_t", SampleType::I32),
    ("uint", SampleType::U32),
    ("unsigned int", SampleType::U32),
    ("uint32", SampleType::U32),
    ("uint32_t", SampleType::U32),
    ("float", SampleType::F32),
    ("double", SampleType::F64),
];

/// Short forms accepted by [`SampleType::from_str`] in addition to the NRRD names.
const SHORT_TYPE_NAMES: &[(&str, SampleType)] = &[
    ("u8", SampleType::U8),
    ("i8", SampleType::I8),
    ("u16", SampleType::U16),
    ("i16", SampleType::I16),
    ("u32", SampleType::U32),
    ("i32", SampleType::I32),
    ("f32", SampleType::F32),
    ("f64", SampleType::F64),
];

/// NRRD types that exist but are not supported here.
const UNSUPPORTED_TYPE_NAMES: &[&str] = &[
    "longlong",
    "long long",
    "long long int",
    "signed long long",
    "signed long long int",
    "int64",
    "int64_t",
    "ulonglong",
    "unsigned long long",
    "unsigned long long int",
    "uint64",
    "uint64_t",
    "block",
];

/// Lowercase, trimmed, inner whitespace runs collapsed to one space.
fn normalize(name: &str) -> String {
    name.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_ascii_lowercase()
}

fn lookup(table: &[(&str, SampleType)], name: &str) -> Option<SampleType> {
    table.iter().find(|(n, _)| *n == name).map(|&(_, t)| t)
}

impl SampleType {
    /// Bytes per sample.
    pub fn size_bytes(self) -> usize {
        match self {
            SampleType::U8 | SampleType::I8 => 1,
            SampleType::U16 | SampleType::I16 => 2,
            SampleType::U32 | SampleType::I32 | SampleType::F32 => 4,
            SampleType::F64 => 8,
        }
    }

    /// The canonical NRRD name, as written in headers (`unsigned char`, `float`, ...).
    pub fn nrrd_name(self) -> &'static str {
        match self {
            SampleType::U8 => "unsigned char",
            SampleType::I8 => "signed char",
            SampleType::U16 => "unsigned short",
            SampleType::I16 => "short",
            SampleType::U32 => "unsigned int",
            SampleType::I32 => "int",
            SampleType::F32 => "float",
            SampleType::F64 => "double",
        }
    }

    /// Whether the type is floating point (and so can hold NaN or infinities).
    pub fn is_float(self) -> bool {
        matches!(self, SampleType::F32 | SampleType::F64)
    }

    /// Parse the value of a NRRD `type` field (NRRD names and synonyms only).
    pub(super) fn from_nrrd_field(value: &str) -> Result<Self, IoError> {
        let name = normalize(value);
        if let Some(t) = lookup(NRRD_TYPE_NAMES, &name) {
            return Ok(t);
        }
        let problem = if UNSUPPORTED_TYPE_NAMES.contains(&name.as_str()) {
            format!("sample type `{}` is not supported", excerpt(value))
        } else {
            format!("unknown sample type `{}`", excerpt(value))
        };
        Err(super::error::field_error("type", problem))
    }
}

impl FromStr for SampleType {
    type Err = IoError;

    /// Parse a NRRD type name or synonym (`uchar`, `unsigned short`, `int16`,
    /// `float`, ...) or a short form (`u8`, `i16`, `f32`, ...), ignoring case.
    fn from_str(s: &str) -> Result<Self, IoError> {
        let name = normalize(s);
        lookup(NRRD_TYPE_NAMES, &name)
            .or_else(|| lookup(SHORT_TYPE_NAMES, &name))
            .ok_or_else(|| {
                invalid_argument(format!(
                    "unknown sample type `{}` (expected u8, i8, u16, i16, u32, i32, f32, f64 \
                     or a NRRD type name such as `uchar`, `short`, `float`)",
                    excerpt(s)
                ))
            })
    }
}

impl Encoding {
    /// Parse the value of a NRRD `encoding` field.
    pub(super) fn from_nrrd_field(value: &str) -> Result<Self, IoError> {
        match normalize(value).as_str() {
            "raw" => Ok(Encoding::Raw),
            "gzip" | "gz" => Ok(Encoding::Gzip),
            _ => Err(super::error::field_error(
                "encoding",
                format!(
                    "encoding `{}` is not supported (supported: raw, gzip)",
                    excerpt(value)
                ),
            )),
        }
    }

    /// The NRRD name.
    pub(super) fn nrrd_name(self) -> &'static str {
        match self {
            Encoding::Raw => "raw",
            Encoding::Gzip => "gzip",
        }
    }
}

impl Endian {
    /// Parse the value of a NRRD `endian` field.
    pub(super) fn from_nrrd_field(value: &str) -> Result<Self, IoError> {
        match normalize(value).as_str() {
            "little" => Ok(Endian::Little),
            "big" => Ok(Endian::Big),
            _ => Err(super::error::field_error(
                "endian",
                format!("expected `little` or `big`, got `{}`", excerpt(value)),
            )),
        }
    }

    /// The NRRD name.
    pub(super) fn nrrd_name(self) -> &'static str {
        match self {
            Endian::Little => "little",
            Endian::Big => "big",
        }
    }
}

/// Append one `f32` per whole `N`-byte group of `bytes` to `out`.
fn push_samples<const N: usize>(bytes: &[u8], out: &mut Vec<f32>, f: impl Fn([u8; N]) -> f32) {
    out.extend(
        bytes
            .chunks_exact(N)
            .filter_map(|c| <[u8; N]>::try_from(c).ok())
            .map(f),
    );
}

/// Convert whole samples of `bytes` to `f32` and append them to `out`.
/// A trailing partial sample is ignored.
pub(super) fn decode_into(bytes: &[u8], ty: SampleType, endian: Endian, out: &mut Vec<f32>) {
    macro_rules! decode {
        ($t:ty, $to_f32:expr) => {{
            const N: usize = std::mem::size_of::<$t>();
            match endian {
                Endian::Little => {
                    push_samples::<N>(bytes, out, |a| $to_f32(<$t>::from_le_bytes(a)))
                }
                Endian::Big => push_samples::<N>(bytes, out, |a| $to_f32(<$t>::from_be_bytes(a))),
            }
        }};
    }
    match ty {
        SampleType::U8 => decode!(u8, f32::from),
        SampleType::I8 => decode!(i8, f32::from),
        SampleType::U16 => decode!(u16, f32::from),
        SampleType::I16 => decode!(i16, f32::from),
        SampleType::U32 => decode!(u32, |x: u32| x as f32),
        SampleType::I32 => decode!(i32, |x: i32| x as f32),
        SampleType::F32 => decode!(f32, |x: f32| x),
        SampleType::F64 => decode!(f64, |x: f64| x as f32),
    }
}

/// The value of the first sample in `bytes` at full precision, for floating
/// point types (used to report non-finite samples).
pub(super) fn float_value(bytes: &[u8], ty: SampleType, endian: Endian) -> Option<f64> {
    match (ty, endian) {
        (SampleType::F32, Endian::Little) => {
            bytes.first_chunk().map(|a| f32::from_le_bytes(*a) as f64)
        }
        (SampleType::F32, Endian::Big) => {
            bytes.first_chunk().map(|a| f32::from_be_bytes(*a) as f64)
        }
        (SampleType::F64, Endian::Little) => bytes.first_chunk().map(|a| f64::from_le_bytes(*a)),
        (SampleType::F64, Endian::Big) => bytes.first_chunk().map(|a| f64::from_be_bytes(*a)),
        _ => None,
    }
}

/// Encode `values` as samples of type `ty`: integers are rounded to nearest
/// and saturated to the type's range (NaN becomes 0), floats are cast.
pub(super) fn encode_values(values: &[f64], ty: SampleType, endian: Endian) -> Vec<u8> {
    let mut out = Vec::with_capacity(values.len().saturating_mul(ty.size_bytes()));
    macro_rules! encode {
        ($convert:expr) => {
            for &v in values {
                let x = $convert(v);
                match endian {
                    Endian::Little => out.extend_from_slice(&x.to_le_bytes()),
                    Endian::Big => out.extend_from_slice(&x.to_be_bytes()),
                }
            }
        };
    }
    match ty {
        SampleType::U8 => encode!(|v: f64| v.round() as u8),
        SampleType::I8 => encode!(|v: f64| v.round() as i8),
        SampleType::U16 => encode!(|v: f64| v.round() as u16),
        SampleType::I16 => encode!(|v: f64| v.round() as i16),
        SampleType::U32 => encode!(|v: f64| v.round() as u32),
        SampleType::I32 => encode!(|v: f64| v.round() as i32),
        SampleType::F32 => encode!(|v: f64| v as f32),
        SampleType::F64 => encode!(|v: f64| v),
    }
    out
}

/// Encode `f32` samples little endian.
pub(super) fn encode_f32_le(data: &[f32]) -> Vec<u8> {
    data.iter().flat_map(|v| v.to_le_bytes()).collect()
}
