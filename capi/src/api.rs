//! The calls on safe slices: open (check an image once), describe it, size
//! a view's buffers, render. [`crate::ffi`] reaches these after turning
//! the C pointers into slices.
#![forbid(unsafe_code)]

use fvr_core::fvrs::{Fvrs, Precision};
use fvr_core::geometry::View;
use fvr_core::image::Inverse;
use fvr_core::image::{aux_len, grid_len};
use fvr_core::render::{max_level, render_projection_with};
use fvr_core::{Buffers, Request};

use crate::status::fvr_status;
use crate::types::{fvr_info, fvr_lens, fvr_request};

/// Check `image` in full: every field, length, CRC and value (once, at
/// open).
///
/// # Errors
/// The image's first fault as a status.
pub fn open(image: &[u8]) -> Result<(), fvr_status> {
    Fvrs::parse(image).map(drop).map_err(fvr_status::from)
}

/// An opened image again, header checks only (O(1)).
fn reopen(image: &[u8]) -> Result<Fvrs<'_>, fvr_status> {
    Fvrs::parse_trusting_sections(image).map_err(fvr_status::from)
}

/// What an opened `image` holds.
///
/// # Errors
/// A header that no longer checks (the image changed since it was opened).
pub fn info(image: &[u8]) -> Result<fvr_info, fvr_status> {
    let f = reopen(image)?;
    let h = f.header();
    let kind = h.filter.kind();
    let filter = fvr_core::filter::FilterKind::ALL
        .iter()
        .position(|&k| k == kind)
        .unwrap_or(0) as u32;
    Ok(fvr_info {
        n: h.n as u32,
        dims: h.dims.map(|d| d as u32),
        precision: h.precision.code() as u32,
        filter,
        part: h.part.code() as u32,
        max_level: max_level(h.n),
        image_len: f.layout().file_len,
    })
}

/// Floats each buffer of `request` needs.
///
/// # Errors
/// A level beyond the deepest, or an image of side 0 or beyond the
/// level's grid.
pub fn lens(image: &[u8], request: &fvr_request) -> Result<fvr_lens, fvr_status> {
    let n = reopen(image)?.header().n;
    if request.level > max_level(n) {
        return Err(fvr_status::FVR_ERR_SIZE);
    }
    let m = n >> request.level;
    let (w, h) = (request.width as usize, request.height as usize);
    if w == 0 || h == 0 || w > m || h > m {
        return Err(fvr_status::FVR_ERR_SIZE);
    }
    Ok(fvr_lens {
        grid: grid_len(m),
        aux: aux_len(m),
        out: w * h,
    })
}

/// Render `request` from the opened `image` into the buffers: the X-ray
/// projection `fvr_core::render` makes, through
/// `render_projection_with`, which is the same code without the scene
/// path (a device links no shading code it cannot call).
///
/// # Errors
/// As [`lens`]; a bad view; short buffers.
pub fn render(
    image: &[u8],
    request: &fvr_request,
    grid: &mut [f32],
    aux: &mut [f32],
    out: &mut [f32],
) -> Result<(), fvr_status> {
    let f = reopen(image)?;
    let need = lens(image, request)?;
    if grid.len() < need.grid || aux.len() < need.aux || out.len() < need.out {
        return Err(fvr_status::FVR_ERR_BUFFER_TOO_SMALL);
    }
    let req = Request {
        level: request.level,
        ..Request::new(
            View {
                dir: request.dir,
                up: request.up,
            },
            request.width as usize,
            request.height as usize,
        )
    };
    let kernel = f.kernel()?;
    let twiddles = f.twiddles()?;
    let buffers = Buffers::new(grid, aux, &mut out[..need.out]);
    let inverse = Inverse::Radix2(&twiddles);
    let done = match f.header().precision {
        Precision::F16 => {
            render_projection_with(&f.spectrum_f16()?, &kernel, inverse, &req, buffers)
        }
        Precision::F32 => {
            render_projection_with(&f.spectrum_f32()?, &kernel, inverse, &req, buffers)
        }
    };
    done.map_err(fvr_status::from)
}
