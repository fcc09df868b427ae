//! The `extern "C"` functions: the crate's only unsafe code.
//!
//! Each function checks every pointer before it becomes a reference or a
//! slice: not null, aligned for its type, its byte range not wrapping the
//! address space nor beyond `isize::MAX`, and (for the float buffers) not
//! overlapping another buffer or the image. What cannot be checked is the
//! C caller's side of the contract, stated in `fvr.h`: a pointer with a
//! length points to that many readable (or, for outputs, writable) bytes,
//! and an opened image stays in place, unchanged, while its handle is used.
//! Then every call is sound whatever the values; a wrong value is a status.
#![allow(unsafe_code)]

use core::ffi::c_char;
use core::mem::{align_of, size_of};

use crate::api;
use crate::status::{fvr_status, UNKNOWN};
use crate::types::{fvr_buffers, fvr_info, fvr_lens, fvr_request, fvr_source};

/// The handle's first word once opened: "FVRSOPEN" in ASCII.
const TAG: u64 = u64::from_be_bytes(*b"FVRSOPEN");

type Status<T> = Result<T, fvr_status>;

/// `ptr` as a reference, if not null and aligned.
///
/// # Safety
/// A non-null, aligned `ptr` points to a readable `T` that lives for `'a`
/// (the C contract). Every type passed here is plain data, valid for any
/// bit pattern.
unsafe fn read<'a, T>(ptr: *const T) -> Status<&'a T> {
    if ptr.is_null() {
        return Err(fvr_status::FVR_ERR_NULL);
    }
    if ptr as usize % align_of::<T>() != 0 {
        return Err(fvr_status::FVR_ERR_MISALIGNED);
    }
    // SAFETY: non-null and aligned (checked); readable by the C contract.
    Ok(unsafe { &*ptr })
}

/// Write `value` through `ptr`, if not null and aligned.
///
/// # Safety
/// A non-null, aligned `ptr` points to a writable `T` (the C contract).
unsafe fn write<T>(ptr: *mut T, value: T) -> Status<()> {
    if ptr.is_null() {
        return Err(fvr_status::FVR_ERR_NULL);
    }
    if ptr as usize % align_of::<T>() != 0 {
        return Err(fvr_status::FVR_ERR_MISALIGNED);
    }
    // SAFETY: non-null and aligned (checked); writable by the C contract.
    unsafe { ptr.write(value) };
    Ok(())
}

/// The byte range of `len` values of `T` at `ptr`: checked for null,
/// alignment, `isize::MAX` and wrapping.
fn range<T>(ptr: *const T, len: usize) -> Status<(usize, usize)> {
    if ptr.is_null() {
        return Err(fvr_status::FVR_ERR_NULL);
    }
    let start = ptr as usize;
    if start % align_of::<T>() != 0 {
        return Err(fvr_status::FVR_ERR_MISALIGNED);
    }
    let bytes = len
        .checked_mul(size_of::<T>())
        .filter(|&b| b <= isize::MAX as usize)
        .ok_or(fvr_status::FVR_ERR_SIZE)?;
    let end = start.checked_add(bytes).ok_or(fvr_status::FVR_ERR_SIZE)?;
    Ok((start, end))
}

/// The image a handle refers to.
///
/// # Safety
/// An opened handle's address and length are those given to
/// `fvr_source_open`, which by the C contract stay readable and unchanged
/// while the handle is used.
unsafe fn image<'a>(source: *const fvr_source) -> Status<&'a [u8]> {
    // SAFETY: as `read`.
    let s = unsafe { read(source)? };
    let [tag, ptr, len, _] = s.opaque;
    if tag != TAG {
        return Err(fvr_status::FVR_ERR_NOT_OPEN);
    }
    let (ptr, len) = (ptr as usize as *const u8, len as usize);
    range(ptr, len)?;
    // SAFETY: checked as at open (non-null, in range); readable and
    // unchanged by the C contract.
    Ok(unsafe { core::slice::from_raw_parts(ptr, len) })
}

fn status(r: Status<()>) -> fvr_status {
    match r {
        Ok(()) => fvr_status::FVR_OK,
        Err(e) => e,
    }
}

/// Check the `.fvrs` image of `len` bytes at `image` (8-byte aligned) in
/// full (header, lengths, every CRC, every value) and make `source` refer
/// to it. On failure `source` is left unopened (if it is writable).
///
/// # Safety
/// `image` points to `len` readable bytes that stay in place and unchanged
/// while `source` is used; `source` points to a writable `fvr_source`.
#[no_mangle]
pub unsafe extern "C" fn fvr_source_open(
    source: *mut fvr_source,
    image: *const u8,
    len: usize,
) -> fvr_status {
    let closed = fvr_source { opaque: [0; 4] };
    // SAFETY: `write` checks null and alignment; writable by contract.
    if let Err(e) = unsafe { write(source, closed) } {
        return e;
    }
    let opened = (|| {
        range(image, len)?;
        // SAFETY: non-null, in range (checked); readable by contract.
        let bytes = unsafe { core::slice::from_raw_parts(image, len) };
        api::open(bytes)?;
        Ok(fvr_source {
            opaque: [TAG, image as usize as u64, len as u64, 0],
        })
    })();
    match opened {
        // SAFETY: as above.
        Ok(handle) => status(unsafe { write(source, handle) }),
        Err(e) => e,
    }
}

/// Describe the opened image into `info`.
///
/// # Safety
/// `source` was opened by `fvr_source_open` (or is any readable
/// `fvr_source`: an unopened one is `FVR_ERR_NOT_OPEN`); `info` points to a
/// writable `fvr_info`.
#[no_mangle]
pub unsafe extern "C" fn fvr_source_info(
    source: *const fvr_source,
    info: *mut fvr_info,
) -> fvr_status {
    // SAFETY: `image` and `write` check their pointers; the rest is the
    // C contract above.
    status(unsafe {
        image(source)
            .and_then(api::info)
            .and_then(|i| write(info, i))
    })
}

/// The floats each buffer of `request` needs, into `lens`.
///
/// # Safety
/// As `fvr_source_info`; `request` points to a readable `fvr_request`,
/// `lens` to a writable `fvr_lens`.
#[no_mangle]
pub unsafe extern "C" fn fvr_buffer_lens(
    source: *const fvr_source,
    request: *const fvr_request,
    lens: *mut fvr_lens,
) -> fvr_status {
    // SAFETY: each helper checks its pointer; the rest is the C contract.
    status(unsafe {
        (|| {
            let image = image(source)?;
            let request = read(request)?;
            write(lens, api::lens(image, request)?)
        })()
    })
}

/// Render `request` from `source` into `buffers` (the X-ray projection,
/// `width × height` floats, row 0 at the top), as `fvr_core::render`.
///
/// # Safety
/// As `fvr_buffer_lens`; `buffers` points to a readable `fvr_buffers`
/// whose three pointers each point to their length of writable floats.
#[no_mangle]
pub unsafe extern "C" fn fvr_render(
    source: *const fvr_source,
    request: *const fvr_request,
    buffers: *const fvr_buffers,
) -> fvr_status {
    // SAFETY: each helper checks its pointer; the rest is the C contract.
    status(unsafe {
        (|| {
            let image = image(source)?;
            let request = read(request)?;
            let b = read(buffers)?;
            let ranges = [
                range(b.grid, b.grid_len)?,
                range(b.aux, b.aux_len)?,
                range(b.out, b.out_len)?,
                range(image.as_ptr(), image.len())?,
            ];
            for i in 0..ranges.len() {
                for j in i + 1..ranges.len() {
                    let (a, c) = (ranges[i], ranges[j]);
                    if a.0 < c.1 && c.0 < a.1 {
                        return Err(fvr_status::FVR_ERR_OVERLAP);
                    }
                }
            }
            // SAFETY: each range is non-null, aligned, within isize::MAX,
            // and disjoint from the others and the image (checked), so the
            // three mutable slices alias nothing; writable by contract.
            let grid = core::slice::from_raw_parts_mut(b.grid, b.grid_len);
            let aux = core::slice::from_raw_parts_mut(b.aux, b.aux_len);
            let out = core::slice::from_raw_parts_mut(b.out, b.out_len);
            api::render(image, request, grid, aux, out)
        })()
    })
}

/// The text of a status code: a static NUL-terminated string, for any
/// integer (an unknown code has a text saying so).
#[no_mangle]
pub extern "C" fn fvr_status_str(status: i32) -> *const c_char {
    let text = fvr_status::from_code(status).map_or(UNKNOWN, fvr_status::text);
    text.as_ptr().cast()
}
