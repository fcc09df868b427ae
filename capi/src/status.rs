//! Status codes and their text (`fvr_status_str`).
#![forbid(unsafe_code)]

use fvr_core::fvrs::FvrsError;
use fvr_core::Error;

/// What a call did: `FVR_OK` or why not. `fvr_status_str` gives the text.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum fvr_status {
    /// Success.
    FVR_OK = 0,
    /// A pointer argument is null.
    FVR_ERR_NULL = 1,
    /// A buffer or the image is not aligned (4 bytes for floats, 8 for the image).
    FVR_ERR_MISALIGNED = 2,
    /// Two buffers overlap, or a buffer overlaps the image.
    FVR_ERR_OVERLAP = 3,
    /// A buffer is shorter than `fvr_buffer_lens` says.
    FVR_ERR_BUFFER_TOO_SMALL = 4,
    /// The handle was not opened by `fvr_source_open` (or its open failed).
    FVR_ERR_NOT_OPEN = 5,
    /// The image is not a .fvrs image (magic).
    FVR_ERR_NOT_FVRS = 6,
    /// The image's major version is not readable by this library.
    FVR_ERR_VERSION = 7,
    /// The image is shorter or longer than its header says.
    FVR_ERR_LENGTH = 8,
    /// A header field is invalid or inconsistent.
    FVR_ERR_HEADER = 9,
    /// A CRC-32 (header or section) does not match: the image is corrupt.
    FVR_ERR_CHECKSUM = 10,
    /// A stored value is NaN, infinite or out of range.
    FVR_ERR_VALUE = 11,
    /// The view's direction or up vector is zero, parallel or not finite.
    FVR_ERR_VIEW = 12,
    /// The image size is zero or larger than the spectrum's grid, or the
    /// level is too deep.
    FVR_ERR_SIZE = 13,
    /// The platform cannot read the image in place (big-endian).
    FVR_ERR_UNSUPPORTED = 14,
    /// Any other refusal of the core.
    FVR_ERR_OTHER = 15,
}

impl fvr_status {
    /// Every status, in code order (a function, not a constant, so that
    /// cbindgen leaves it out of the header).
    pub const fn all() -> [fvr_status; 16] {
        [
            fvr_status::FVR_OK,
            fvr_status::FVR_ERR_NULL,
            fvr_status::FVR_ERR_MISALIGNED,
            fvr_status::FVR_ERR_OVERLAP,
            fvr_status::FVR_ERR_BUFFER_TOO_SMALL,
            fvr_status::FVR_ERR_NOT_OPEN,
            fvr_status::FVR_ERR_NOT_FVRS,
            fvr_status::FVR_ERR_VERSION,
            fvr_status::FVR_ERR_LENGTH,
            fvr_status::FVR_ERR_HEADER,
            fvr_status::FVR_ERR_CHECKSUM,
            fvr_status::FVR_ERR_VALUE,
            fvr_status::FVR_ERR_VIEW,
            fvr_status::FVR_ERR_SIZE,
            fvr_status::FVR_ERR_UNSUPPORTED,
            fvr_status::FVR_ERR_OTHER,
        ]
    }

    /// The text of the status, NUL-terminated for C.
    pub const fn text(self) -> &'static str {
        match self {
            fvr_status::FVR_OK => "ok\0",
            fvr_status::FVR_ERR_NULL => "a pointer argument is null\0",
            fvr_status::FVR_ERR_MISALIGNED => {
                "a buffer is misaligned (floats need 4 bytes, the .fvrs image 8)\0"
            }
            fvr_status::FVR_ERR_OVERLAP => "buffers overlap each other or the image\0",
            fvr_status::FVR_ERR_BUFFER_TOO_SMALL => {
                "a buffer is shorter than fvr_buffer_lens says\0"
            }
            fvr_status::FVR_ERR_NOT_OPEN => "the source was not opened by fvr_source_open\0",
            fvr_status::FVR_ERR_NOT_FVRS => "not a .fvrs image (bad magic)\0",
            fvr_status::FVR_ERR_VERSION => "unsupported .fvrs major version\0",
            fvr_status::FVR_ERR_LENGTH => {
                "the .fvrs image is truncated or longer than its header says\0"
            }
            fvr_status::FVR_ERR_HEADER => "invalid .fvrs header field\0",
            fvr_status::FVR_ERR_CHECKSUM => "checksum mismatch: the .fvrs image is corrupt\0",
            fvr_status::FVR_ERR_VALUE => {
                "the .fvrs image holds a NaN, infinite or out-of-range value\0"
            }
            fvr_status::FVR_ERR_VIEW => {
                "view direction or up vector is zero, parallel or not finite\0"
            }
            fvr_status::FVR_ERR_SIZE => {
                "image size is zero or beyond the spectrum's grid, or the level is too deep\0"
            }
            fvr_status::FVR_ERR_UNSUPPORTED => "this platform cannot read .fvrs images in place\0",
            fvr_status::FVR_ERR_OTHER => "the renderer refused the request\0",
        }
    }

    /// The status of a code from C, which may be any integer.
    pub fn from_code(code: i32) -> Option<Self> {
        Self::all().into_iter().find(|s| *s as i32 == code)
    }
}

/// Text for a code that is no status.
pub const UNKNOWN: &str = "unknown fvr_status code\0";

impl From<FvrsError> for fvr_status {
    fn from(e: FvrsError) -> Self {
        match e {
            FvrsError::Truncated { .. } | FvrsError::TrailingBytes { .. } => {
                fvr_status::FVR_ERR_LENGTH
            }
            FvrsError::BadMagic => fvr_status::FVR_ERR_NOT_FVRS,
            FvrsError::Version { .. } => fvr_status::FVR_ERR_VERSION,
            FvrsError::Field { .. }
            | FvrsError::Number { .. }
            | FvrsError::Section { .. }
            | FvrsError::NonZero { .. }
            | FvrsError::PrecisionMismatch { .. } => fvr_status::FVR_ERR_HEADER,
            FvrsError::Checksum { .. } => fvr_status::FVR_ERR_CHECKSUM,
            FvrsError::Misaligned { .. } => fvr_status::FVR_ERR_MISALIGNED,
            FvrsError::BigEndian => fvr_status::FVR_ERR_UNSUPPORTED,
            FvrsError::Core(e) => match e {
                Error::NonFiniteTableEntry { .. } | Error::TableEntryOutOfRange { .. } => {
                    fvr_status::FVR_ERR_VALUE
                }
                _ => fvr_status::FVR_ERR_HEADER,
            },
        }
    }
}

impl From<Error> for fvr_status {
    fn from(e: Error) -> Self {
        match e {
            Error::BufferTooSmall { .. } => fvr_status::FVR_ERR_BUFFER_TOO_SMALL,
            Error::ZeroViewVector { .. }
            | Error::ShortViewVector { .. }
            | Error::ParallelViewVectors { .. }
            | Error::NonFiniteViewVector { .. } => fvr_status::FVR_ERR_VIEW,
            Error::ImageTooLarge { .. } | Error::EmptyImage | Error::TooMany { .. } => {
                fvr_status::FVR_ERR_SIZE
            }
            Error::NonFiniteTableEntry { .. } => fvr_status::FVR_ERR_VALUE,
            _ => fvr_status::FVR_ERR_OTHER,
        }
    }
}
