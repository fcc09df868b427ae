//! What can be wrong with a `.fvrs` image: one variant per kind of fault,
//! each naming the field and the numbers.

use core::fmt;

use crate::error::Error;

/// A `.fvrs` image that cannot be used, and why. `Display` is one line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FvrsError {
    /// Fewer bytes than the header or its `file_len` says.
    Truncated {
        /// What is cut off ("header", "file").
        what: &'static str,
        /// Bytes needed.
        needed: u64,
        /// Bytes given.
        got: u64,
    },
    /// More bytes than the header's `file_len`.
    TrailingBytes {
        /// `file_len` in the header.
        file_len: u64,
        /// Bytes given.
        got: u64,
    },
    /// The first 8 bytes are not [`super::MAGIC`].
    BadMagic,
    /// A major version this reader does not read.
    Version {
        /// Major version found.
        major: u16,
        /// Minor version found.
        minor: u16,
    },
    /// An integer field with a value the format does not allow.
    Field {
        /// Which field, and what it must be.
        field: &'static str,
        /// The value found.
        value: u64,
    },
    /// A floating-point field with a value the format does not allow.
    Number {
        /// Which field, and what it must be.
        field: &'static str,
        /// The value found.
        value: f64,
    },
    /// A section's place in the image is not the one the header implies.
    Section {
        /// Which section.
        what: &'static str,
        /// "offset" or "length".
        field: &'static str,
        /// What the header's other fields imply.
        expected: u64,
        /// What the section table says.
        got: u64,
    },
    /// A stored CRC-32 differs from the bytes' own.
    Checksum {
        /// What was summed ("header", "spectrum section", ...).
        what: &'static str,
        /// The CRC stored in the header.
        stored: u32,
        /// The CRC of the bytes.
        computed: u32,
    },
    /// A byte the format requires to be zero is not (padding, reserved).
    NonZero {
        /// Where.
        what: &'static str,
        /// Offset of the first non-zero byte.
        offset: u64,
    },
    /// The image does not start at a multiple of [`super::IMAGE_ALIGN`]
    /// bytes in memory.
    Misaligned {
        /// The image's address modulo the alignment.
        remainder: usize,
    },
    /// The file holds another precision than the caller reads.
    PrecisionMismatch {
        /// Precision in the file.
        file: &'static str,
        /// Precision asked for.
        asked: &'static str,
    },
    /// The platform is big-endian; the format's sections are read in place
    /// as little-endian values.
    BigEndian,
    /// The core refused the fields (dims, side, filter) or a section's
    /// values (a NaN coefficient, a non-finite kernel entry).
    Core(Error),
}

impl fmt::Display for FvrsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FvrsError::Truncated { what, needed, got } => write!(
                f,
                "truncated .fvrs image: the {what} needs {needed} bytes, {got} given"
            ),
            FvrsError::TrailingBytes { file_len, got } => write!(
                f,
                ".fvrs image of {got} bytes, but its header says {file_len} (trailing bytes)"
            ),
            FvrsError::BadMagic => f.write_str(
                "not a .fvrs image: the first 8 bytes are not the FVRS magic (FVRS\\r\\n\\x1a\\n)",
            ),
            FvrsError::Version { major, minor } => write!(
                f,
                ".fvrs version {major}.{minor} is not readable here (this reader reads {}.x)",
                super::VERSION_MAJOR
            ),
            FvrsError::Field { field, value } => {
                write!(f, ".fvrs header: {field} is {value}")
            }
            FvrsError::Number { field, value } => {
                write!(f, ".fvrs header: {field} is {value}")
            }
            FvrsError::Section {
                what,
                field,
                expected,
                got,
            } => write!(
                f,
                ".fvrs header: the {what} section's {field} is {got}, the header's fields imply {expected}"
            ),
            FvrsError::Checksum {
                what,
                stored,
                computed,
            } => write!(
                f,
                ".fvrs checksum mismatch in the {what}: stored CRC-32 {stored:08x}, computed {computed:08x} (the file is corrupt)"
            ),
            FvrsError::NonZero { what, offset } => {
                write!(f, ".fvrs image: {what} byte at offset {offset} is not zero")
            }
            FvrsError::Misaligned { remainder } => write!(
                f,
                ".fvrs image starts {remainder} bytes past a multiple of {} in memory; it must be {}-byte aligned",
                super::IMAGE_ALIGN,
                super::IMAGE_ALIGN
            ),
            FvrsError::PrecisionMismatch { file, asked } => write!(
                f,
                ".fvrs spectrum is stored in {file}, but {asked} was asked for"
            ),
            FvrsError::BigEndian => {
                f.write_str(".fvrs images are read in place on little-endian machines only")
            }
            FvrsError::Core(e) => write!(f, ".fvrs contents refused: {e}"),
        }
    }
}

impl core::error::Error for FvrsError {}

impl From<Error> for FvrsError {
    fn from(e: Error) -> Self {
        FvrsError::Core(e)
    }
}
