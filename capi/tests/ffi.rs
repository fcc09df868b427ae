//! The FFI boundary, called as C calls it: a good image renders bit for
//! bit as `fvr_core::render` does from the same file, and each bad input
//! (null pointers, short, misaligned or overlapping buffers, an unopened
//! handle, a corrupt, truncated or foreign image, a bad view or size) is
//! its own error status.
#![allow(unsafe_code)]

use std::ffi::CStr;

use fvr_capi::ffi::{
    fvr_buffer_lens, fvr_render, fvr_source_info, fvr_source_open, fvr_status_str,
};
use fvr_capi::fvr_status::{self, *};
use fvr_capi::{fvr_buffers, fvr_info, fvr_lens, fvr_request, fvr_source};
use fvr_core::dht::Twiddles;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::fvrs::{write, write_len, Fvrs, Header, Part, Precision};
use fvr_core::geometry::View;
use fvr_core::spectrum::{prepare_scratch_len, Spectrum};
use fvr_core::volume::DenseVolume;
use fvr_core::{f16, render, Buffers, Request, Source};

const DIMS: [usize; 3] = [14, 12, 9];
const N: usize = 16;

/// An 8-aligned .fvrs image of a small volume, as `u64` words.
fn image() -> (Vec<u64>, usize) {
    let data: Vec<f32> = (0..DIMS.iter().product::<usize>())
        .map(|i| ((i * 29 % 53) as f32).sqrt())
        .collect();
    let vol = DenseVolume::new(DIMS, &data).unwrap();
    let filter = Filter::new(FilterKind::Kb3, 1).unwrap();
    let mut tw = vec![0f32; Twiddles::<f32>::buffer_len(N)];
    let twiddles = Twiddles::new(&mut tw, N).unwrap();
    let mut scratch = vec![0f32; prepare_scratch_len(N)];
    let mut st = vec![f16::ZERO; N * N * N];
    let spec = Spectrum::prepare(&vol, filter, &mut st, &mut scratch, &twiddles).unwrap();
    let header = Header {
        precision: Precision::F16,
        filter,
        part: Part::Host,
        n: N,
        dims: DIMS,
        scale: spec.scale(),
    };
    let bytes: Vec<u8> = spec.data().iter().flat_map(|v| v.to_le_bytes()).collect();
    let kernel = KernelTable::<f32>::new(filter);
    let len = write_len(&header).unwrap();
    let mut out = vec![0u8; len];
    write(&header, &bytes, kernel.values(), &tw, &mut out).unwrap();
    let mut words = vec![0u64; len.div_ceil(8) + 1];
    bytes_of(&mut words)[..len].copy_from_slice(&out);
    (words, len)
}

fn bytes_of(words: &mut [u64]) -> &mut [u8] {
    // SAFETY: u8 has no alignment or validity requirement; same memory.
    unsafe { std::slice::from_raw_parts_mut(words.as_mut_ptr().cast(), words.len() * 8) }
}

fn request(w: u32, h: u32) -> fvr_request {
    fvr_request {
        dir: [1.0, 0.3, 0.2],
        up: [0.0, 0.0, 1.0],
        width: w,
        height: h,
        level: 0,
    }
}

fn open(words: &[u64], len: usize) -> (fvr_status, fvr_source) {
    let mut src = fvr_source { opaque: [7; 4] };
    let s = unsafe { fvr_source_open(&mut src, words.as_ptr().cast(), len) };
    (s, src)
}

struct Bufs {
    grid: Vec<f32>,
    aux: Vec<f32>,
    out: Vec<f32>,
}

impl Bufs {
    fn new(l: fvr_lens) -> Self {
        Self {
            grid: vec![0.0; l.grid],
            aux: vec![0.0; l.aux],
            out: vec![0.0; l.out],
        }
    }
    fn c(&mut self) -> fvr_buffers {
        fvr_buffers {
            grid: self.grid.as_mut_ptr(),
            grid_len: self.grid.len(),
            aux: self.aux.as_mut_ptr(),
            aux_len: self.aux.len(),
            out: self.out.as_mut_ptr(),
            out_len: self.out.len(),
        }
    }
}

/// The pointer and length of buffer `k` of `c`: 0 the grid, 1 the
/// scratch, 2 the image.
fn buffer(c: &mut fvr_buffers, k: usize) -> (&mut *mut f32, &mut usize) {
    match k {
        0 => (&mut c.grid, &mut c.grid_len),
        1 => (&mut c.aux, &mut c.aux_len),
        _ => (&mut c.out, &mut c.out_len),
    }
}

fn lens(src: &fvr_source, req: &fvr_request) -> fvr_lens {
    let mut l = fvr_lens::default();
    assert_eq!(unsafe { fvr_buffer_lens(src, req, &mut l) }, FVR_OK);
    l
}

/// The image, the source opened on it, a 16 × 16 request and buffers of
/// the lengths the library asks for.
struct Setup {
    words: Vec<u64>,
    len: usize,
    src: fvr_source,
    req: fvr_request,
    b: Bufs,
}

/// The set-up of the tests that break one argument of a good render.
fn setup_16x16() -> Setup {
    let (words, len) = image();
    // The handle points into `words`' heap buffer, which moving the `Vec`
    // into `Setup` leaves in place.
    let (_, src) = open(&words, len);
    let req = request(16, 16);
    let b = Bufs::new(lens(&src, &req));
    Setup {
        words,
        len,
        src,
        req,
        b,
    }
}

#[test]
fn renders_bit_for_bit_as_the_core_from_the_same_image() {
    let (words, len) = image();
    let (s, src) = open(&words, len);
    assert_eq!(s, FVR_OK);
    let mut info = fvr_info::default();
    assert_eq!(unsafe { fvr_source_info(&src, &mut info) }, FVR_OK);
    assert_eq!(
        (
            info.n,
            info.dims,
            info.precision,
            info.filter,
            info.image_len
        ),
        (16, [14, 12, 9], 1, 3, len as u64)
    );
    let req = request(14, 11);
    let l = lens(&src, &req);
    assert_eq!(l.out, 14 * 11);
    let mut b = Bufs::new(l);
    assert_eq!(unsafe { fvr_render(&src, &req, &b.c()) }, FVR_OK);

    let mut w2 = words.clone();
    let f = Fvrs::parse(&bytes_of(&mut w2)[..len]).unwrap();
    let (spec, kernel, tw) = (
        f.spectrum_f16().unwrap(),
        f.kernel().unwrap(),
        f.twiddles().unwrap(),
    );
    let mut want = Bufs::new(l);
    let view = View {
        dir: req.dir,
        up: req.up,
    };
    render(
        &Source::new(&spec, &kernel, &tw),
        &Request::new(view, 14, 11),
        Buffers::new(&mut want.grid, &mut want.aux, &mut want.out),
    )
    .unwrap();
    assert!(want.out.iter().any(|v| *v != 0.0));
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&b.out), bits(&want.out));

    // A progressive level: an image of the level's grid.
    let req = fvr_request {
        level: 1,
        width: 7,
        height: 6,
        ..request(0, 0)
    };
    let mut b = Bufs::new(lens(&src, &req));
    assert_eq!(unsafe { fvr_render(&src, &req, &b.c()) }, FVR_OK);
}

#[test]
fn null_pointers_are_fvr_err_null() {
    let mut t = setup_16x16();
    let null = std::ptr::null_mut::<f32>();
    unsafe {
        assert_eq!(
            fvr_source_open(std::ptr::null_mut(), t.words.as_ptr().cast(), t.len),
            FVR_ERR_NULL
        );
        let mut s = fvr_source { opaque: [0; 4] };
        assert_eq!(
            fvr_source_open(&mut s, std::ptr::null(), t.len),
            FVR_ERR_NULL
        );
        assert_eq!(
            fvr_source_info(std::ptr::null(), &mut fvr_info::default()),
            FVR_ERR_NULL
        );
        assert_eq!(fvr_source_info(&t.src, std::ptr::null_mut()), FVR_ERR_NULL);
        assert_eq!(
            fvr_buffer_lens(&t.src, std::ptr::null(), &mut fvr_lens::default()),
            FVR_ERR_NULL
        );
        assert_eq!(
            fvr_buffer_lens(&t.src, &t.req, std::ptr::null_mut()),
            FVR_ERR_NULL
        );
        assert_eq!(fvr_render(std::ptr::null(), &t.req, &t.b.c()), FVR_ERR_NULL);
        assert_eq!(fvr_render(&t.src, std::ptr::null(), &t.b.c()), FVR_ERR_NULL);
        assert_eq!(fvr_render(&t.src, &t.req, std::ptr::null()), FVR_ERR_NULL);
        for k in 0..3 {
            let mut c = t.b.c();
            *buffer(&mut c, k).0 = null;
            assert_eq!(fvr_render(&t.src, &t.req, &c), FVR_ERR_NULL, "buffer {k}");
        }
    }
}

#[test]
fn short_buffers_are_fvr_err_buffer_too_small() {
    let mut t = setup_16x16();
    for k in 0..3 {
        let mut c = t.b.c();
        *buffer(&mut c, k).1 -= 1;
        assert_eq!(
            unsafe { fvr_render(&t.src, &t.req, &c) },
            FVR_ERR_BUFFER_TOO_SMALL,
            "{k}"
        );
    }
    assert!(t.b.out.iter().all(|v| *v == 0.0), "nothing rendered");
}

#[test]
fn misaligned_pointers_are_fvr_err_misaligned() {
    let mut t = setup_16x16();
    for k in 0..3 {
        let mut c = t.b.c();
        let (p, _) = buffer(&mut c, k);
        // One byte on: no longer 4-byte aligned.
        *p = p.cast::<u8>().wrapping_add(1).cast::<f32>();
        assert_eq!(
            unsafe { fvr_render(&t.src, &t.req, &c) },
            FVR_ERR_MISALIGNED,
            "{k}"
        );
    }
    // The image one byte past an 8-byte boundary (moved there whole).
    let bytes = bytes_of(&mut t.words);
    bytes.copy_within(0..t.len, 1);
    let mut s = fvr_source { opaque: [0; 4] };
    let at1 = unsafe { t.words.as_ptr().cast::<u8>().add(1) };
    assert_eq!(
        unsafe { fvr_source_open(&mut s, at1, t.len) },
        FVR_ERR_MISALIGNED
    );
    // A misaligned handle.
    let mut raw = [0u64; 8];
    let handle = unsafe { raw.as_mut_ptr().cast::<u8>().add(4).cast::<fvr_source>() };
    assert_eq!(
        unsafe { fvr_source_open(handle, at1, t.len) },
        FVR_ERR_MISALIGNED
    );
}

#[test]
fn overlapping_buffers_are_fvr_err_overlap() {
    let mut t = setup_16x16();
    let mut c = t.b.c();
    c.out = c.grid;
    c.out_len = 16 * 16;
    assert_eq!(unsafe { fvr_render(&t.src, &t.req, &c) }, FVR_ERR_OVERLAP);
    let mut c = t.b.c();
    c.aux = unsafe { c.grid.add(1) };
    c.aux_len = 1.min(c.aux_len);
    assert_eq!(unsafe { fvr_render(&t.src, &t.req, &c) }, FVR_ERR_OVERLAP);
}

#[test]
fn corrupt_truncated_and_foreign_images_are_refused_and_leave_the_handle_closed() {
    let (words, len) = image();
    let cases: [(usize, Option<usize>, fvr_status); 4] = [
        (300, None, FVR_ERR_CHECKSUM),      // a spectrum byte
        (12, None, FVR_ERR_CHECKSUM),       // the header's CRC
        (0, None, FVR_ERR_NOT_FVRS),        // the magic
        (0, Some(len - 1), FVR_ERR_LENGTH), // truncated by one byte
    ];
    for (at, cut, want) in cases {
        let mut w = words.clone();
        if cut.is_none() {
            bytes_of(&mut w)[at] ^= 0x20;
        }
        let (s, src) = open(&w, cut.unwrap_or(len));
        assert_eq!(s, want, "byte {at}");
        let mut info = fvr_info::default();
        assert_eq!(
            unsafe { fvr_source_info(&src, &mut info) },
            FVR_ERR_NOT_OPEN
        );
        let mut b = Bufs::new(fvr_lens {
            grid: 1,
            aux: 1,
            out: 1,
        });
        assert_eq!(
            unsafe { fvr_render(&src, &request(1, 1), &b.c()) },
            FVR_ERR_NOT_OPEN
        );
    }
    let mut w = words.clone();
    bytes_of(&mut w)[8] = 9; // major version 9
    assert_eq!(open(&w, len).0, FVR_ERR_VERSION);
    // A handle that was never opened.
    let never = fvr_source { opaque: [0; 4] };
    assert_eq!(
        unsafe { fvr_source_info(&never, &mut fvr_info::default()) },
        FVR_ERR_NOT_OPEN
    );
}

#[test]
fn bad_views_and_sizes_are_named() {
    let (words, len) = image();
    let (_, src) = open(&words, len);
    let mut b = Bufs::new(lens(&src, &request(16, 16)));
    let c = b.c();
    let cases = [
        (
            fvr_request {
                dir: [0.0; 3],
                ..request(16, 16)
            },
            FVR_ERR_VIEW,
        ),
        (
            fvr_request {
                up: [2.0, 0.6, 0.4],
                ..request(16, 16)
            },
            FVR_ERR_VIEW,
        ),
        (
            fvr_request {
                dir: [f64::NAN, 0.0, 1.0],
                ..request(16, 16)
            },
            FVR_ERR_VIEW,
        ),
        (request(0, 16), FVR_ERR_SIZE),
        (request(17, 16), FVR_ERR_SIZE),
        (
            fvr_request {
                level: 2,
                ..request(8, 8)
            },
            FVR_ERR_SIZE,
        ),
        (
            fvr_request {
                level: 9,
                ..request(1, 1)
            },
            FVR_ERR_SIZE,
        ),
    ];
    for (req, want) in cases {
        assert_eq!(unsafe { fvr_render(&src, &req, &c) }, want, "{req:?}");
    }
    let mut l = fvr_lens::default();
    assert_eq!(
        unsafe { fvr_buffer_lens(&src, &request(17, 1), &mut l) },
        FVR_ERR_SIZE
    );
}

#[test]
fn every_status_has_a_text_and_unknown_codes_too() {
    for s in fvr_status::all() {
        let text = unsafe { CStr::from_ptr(fvr_status_str(s as i32)) }
            .to_str()
            .unwrap();
        assert!(!text.is_empty() && !text.contains('\0'), "{s:?}");
    }
    assert_eq!(
        unsafe { CStr::from_ptr(fvr_status_str(FVR_OK as i32)) }
            .to_str()
            .unwrap(),
        "ok"
    );
    for code in [-1, 16, i32::MAX, i32::MIN] {
        let text = unsafe { CStr::from_ptr(fvr_status_str(code)) }
            .to_str()
            .unwrap();
        assert!(text.starts_with("unknown"), "{code}");
    }
}
