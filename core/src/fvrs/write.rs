//! Writing an image into a caller's buffer (the host wraps it with its
//! atomic file writer; a device could write one too).

use super::error::FvrsError;
use super::header::{Header, Layout, Section};
use super::{crc32, kernel_entries, twiddle_entries, HEADER_LEN};
use crate::error::mismatch;

/// Bytes of the image for `header` ([`Layout::file_len`]).
///
/// # Errors
/// As [`Header::layout`].
pub fn write_len(header: &Header) -> Result<usize, FvrsError> {
    let len = header.layout()?.file_len;
    usize::try_from(len).map_err(|_| FvrsError::Field {
        field: "image length (beyond this machine's address space)",
        value: len,
    })
}

/// Write the image of `header` with the spectrum's little-endian bytes
/// `spectrum` (`n³` values of the header's precision), the kernel table
/// `kernel` ([`crate::filter::KernelTable::values`] of the header's
/// filter) and the twiddles `twiddles`
/// ([`crate::dht::Twiddles::buffer_len`]`(n)` entries) into `out`, which
/// must be exactly [`write_len`] bytes. Padding is zeroed. Returns the
/// layout written.
///
/// # Errors
/// A header [`Header::layout`] refuses; a section or `out` of the wrong
/// length; a big-endian machine (the f32 tables are written as they lie
/// in memory).
pub fn write(
    header: &Header,
    spectrum: &[u8],
    kernel: &[f32],
    twiddles: &[f32],
    out: &mut [u8],
) -> Result<Layout, FvrsError> {
    if cfg!(target_endian = "big") {
        return Err(FvrsError::BigEndian);
    }
    let layout = header.layout()?;
    let n = header.n;
    let lengths = [
        ("spectrum bytes", layout.spectrum.len, spectrum.len()),
        (
            "kernel table",
            kernel_entries(&header.filter) as u64,
            kernel.len(),
        ),
        ("twiddle table", twiddle_entries(n) as u64, twiddles.len()),
        ("output image", layout.file_len, out.len()),
    ];
    for (what, expected, got) in lengths {
        if expected != got as u64 {
            return Err(FvrsError::Core(mismatch(what, expected as usize, got)));
        }
    }
    out.fill(0);
    let kernel: &[u8] = bytemuck::cast_slice(kernel);
    let twiddles: &[u8] = bytemuck::cast_slice(twiddles);
    let parts = [
        (layout.spectrum, spectrum),
        (layout.kernel, kernel),
        (layout.twiddles, twiddles),
    ];
    let mut crcs = [0u32; 3];
    for (crc, (section, bytes)) in crcs.iter_mut().zip(parts) {
        range(out, section).copy_from_slice(bytes);
        *crc = crc32(bytes);
    }
    out[..HEADER_LEN].copy_from_slice(&header.encode(&layout, crcs));
    Ok(layout)
}

fn range(out: &mut [u8], s: Section) -> &mut [u8] {
    &mut out[s.offset as usize..(s.offset + s.len) as usize]
}
