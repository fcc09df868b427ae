//! The one PNG writer: raw samples of a given colour type and depth to a
//! file (through [`crate::io::atomic::Output`]: the previous file stays
//! whole until the new one is), with the path in every error.

use std::io::Write;
use std::path::Path;

use crate::io::atomic::Output;

/// `"cannot write PNG `path`: {e}"`.
pub(crate) fn png_error(path: &Path, e: &dyn std::fmt::Display) -> String {
    format!("cannot write PNG `{}`: {e}", path.display())
}

/// An encoder for a `width × height` image, refusing sizes a PNG cannot
/// hold.
pub(crate) fn encoder<W: Write>(
    w: W,
    width: usize,
    height: usize,
    color: png::ColorType,
    depth: png::BitDepth,
) -> Result<png::Encoder<'static, W>, String> {
    let (w32, h32) = match (u32::try_from(width), u32::try_from(height)) {
        (Ok(a), Ok(b)) if a > 0 && b > 0 => (a, b),
        _ => {
            return Err(format!(
                "image size {width}x{height} cannot be stored in a PNG"
            ))
        }
    };
    let mut enc = png::Encoder::new(w, w32, h32);
    enc.set_color(color);
    enc.set_depth(depth);
    Ok(enc)
}

/// Write `data` (rows top first, samples as `color` and `depth` lay them
/// out) as a PNG.
///
/// # Errors
/// File creation or encoding failure, with the path.
pub(crate) fn write(
    path: &Path,
    (width, height): (usize, usize),
    color: png::ColorType,
    depth: png::BitDepth,
    data: &[u8],
) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| png_error(path, e);
    let mut out = Output::create(path).map_err(|e| fail(&e))?;
    let enc = encoder(&mut out, width, height, color, depth).map_err(|e| fail(&e))?;
    let mut writer = enc.write_header().map_err(|e| fail(&e))?;
    writer.write_image_data(data).map_err(|e| fail(&e))?;
    writer.finish().map_err(|e| fail(&e))?;
    out.commit().map_err(|e| fail(&e))
}
