//! A float NRRD image without allocation: the header in a fixed buffer,
//! the samples as little-endian bytes in chunks.

use core::fmt::{self, Write};

/// Header bytes this writer can hold.
pub const HEADER_CAP: usize = 256;

/// A NRRD header in a fixed buffer.
#[derive(Clone, Debug)]
pub struct Header(heapless::String<HEADER_CAP>);

impl Header {
    /// The header of a `float` image of `width × height` pixels of
    /// `channels` values, raw encoding, little endian, with one comment
    /// line: `sizes: W H` for one channel, `sizes: C W H` (channel fastest,
    /// as the host's `fvr render` writes RGB) otherwise.
    ///
    /// # Errors
    /// `fmt::Error` if the header would exceed [`HEADER_CAP`] bytes.
    pub fn image_f32(
        channels: usize,
        width: usize,
        height: usize,
        comment: fmt::Arguments<'_>,
    ) -> Result<Self, fmt::Error> {
        let mut h = heapless::String::<HEADER_CAP>::new();
        write!(h, "NRRD0004\n# {comment}\ntype: float\n")?;
        if channels == 1 {
            write!(h, "dimension: 2\nsizes: {width} {height}\n")?;
        } else {
            write!(h, "dimension: 3\nsizes: {channels} {width} {height}\n")?;
        }
        write!(h, "endian: little\nencoding: raw\n\n")?;
        Ok(Self(h))
    }

    /// The header's bytes.
    pub fn as_bytes(&self) -> &[u8] {
        self.0.as_bytes()
    }
}

/// Pass the samples to `put` as little-endian bytes, up to 256 bytes at a
/// time.
///
/// # Errors
/// The first error of `put`.
pub fn write_samples_le<E>(
    samples: &[f32],
    mut put: impl FnMut(&[u8]) -> Result<(), E>,
) -> Result<(), E> {
    let mut chunk = [0u8; 256];
    for group in samples.chunks(64) {
        for (v, out) in group.iter().zip(chunk.chunks_exact_mut(4)) {
            out.copy_from_slice(&v.to_le_bytes());
        }
        put(&chunk[..4 * group.len()])?;
    }
    Ok(())
}
