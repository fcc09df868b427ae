//! The `.fvrs` file: a prepared spectrum with what renders it, in one
//! checked, aligned byte image (specification: `docs/fvrs.md`).
//!
//! A file is a 144-byte little-endian header followed by three sections,
//! each starting at a multiple of 64 bytes: the spectrum (`n³` f16 or f32,
//! `x` fastest), the filter's kernel table (f32, [`KernelTable::values`])
//! and the twiddles (f32, [`Twiddles::buffer_len`]`(n)` entries). The header
//! carries the format version, the grid, the filter, the precision, the
//! scale, the part it was prepared for, and CRC-32s of itself and of every
//! section. [`Fvrs::parse`] checks all of it, without allocating, and hands
//! out the sections as the core's types ([`Fvrs::spectrum_f16`],
//! [`Fvrs::kernel`], [`Fvrs::twiddles`]) borrowed from the image, so a
//! memory-mapped file or an array in flash is rendered in place. [`write`]
//! makes the image into a caller's buffer.
//!
//! A corrupt, truncated or mismatched image is an [`FvrsError`] naming the
//! field, never a panic or a wrong spectrum.

mod error;
mod header;
mod read;
#[cfg(test)]
mod tests;
mod write;

pub use error::FvrsError;
pub use header::{Header, Layout, Part, Precision, Section};
pub use read::Fvrs;
pub use write::{write, write_len};

use crate::dht::Twiddles;
use crate::filter::KernelTable;

/// The first 8 bytes: `FVRS`, CR LF, Ctrl-Z, LF (as PNG's, so that a text
/// transfer or a truncated copy breaks them).
pub const MAGIC: [u8; 8] = *b"FVRS\r\n\x1a\n";
/// The major version this reader reads; another major is refused.
pub const VERSION_MAJOR: u16 = 1;
/// The minor version this writer writes; a reader of the same major reads
/// any minor (later minors only append header fields).
pub const VERSION_MINOR: u16 = 0;
/// Bytes of a version-1.0 header.
pub const HEADER_LEN: usize = 144;
/// Every section starts at a multiple of this many bytes from the image's
/// start (a cache line; also what the C arrays are aligned to).
pub const SECTION_ALIGN: usize = 64;
/// The alignment the image's first byte must have in memory, so that the
/// f32 and f16 sections can be read in place.
pub const IMAGE_ALIGN: usize = 8;

/// Round `v` up to a multiple of [`SECTION_ALIGN`], `None` on overflow.
pub(crate) fn align_up(v: u64) -> Option<u64> {
    let a = SECTION_ALIGN as u64;
    v.checked_add(a - 1).map(|x| x / a * a)
}

/// The CRC-32 (IEEE 802.3, as zlib's `crc32`) of `bytes`.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(bytes);
    h.finalize()
}

/// Entries of the kernel-table section for the filter (f32 each).
pub(crate) fn kernel_entries(filter: &crate::filter::Filter) -> usize {
    KernelTable::<f32>::len_for(filter)
}

/// Entries of the twiddle section for side `n` (f32 each).
pub(crate) fn twiddle_entries(n: usize) -> usize {
    Twiddles::<f32>::buffer_len(n)
}
