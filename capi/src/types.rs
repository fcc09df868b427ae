//! The structs C sees. All `#[repr(C)]`, plain data, owned by the caller.
#![forbid(unsafe_code)]

/// An opened .fvrs image. Opaque: fill it with `fvr_source_open` only. It
/// refers to the image, which must stay in place and unchanged while the
/// handle is used; the library keeps no other state.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct fvr_source {
    /// Private: a tag, the image's address and length.
    pub opaque: [u64; 4],
}

/// A view to render: the X-ray projection along `dir`, a `width × height`
/// image in voxel units, at progressive `level` (0: full resolution; level
/// `L` samples the projection every `2^L` voxels, on a grid of side
/// `n >> L`).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct fvr_request {
    /// Direction from the eye into the scene (any length but zero).
    pub dir: [f64; 3],
    /// Up hint (any length but zero, not parallel to `dir`).
    pub up: [f64; 3],
    /// Image width in pixels, at most `n >> level`.
    pub width: u32,
    /// Image height in pixels, at most `n >> level`.
    pub height: u32,
    /// Progressive level, at most `fvr_info.max_level`.
    pub level: u32,
}

/// The caller's float buffers for a view, with their lengths in floats.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct fvr_buffers {
    /// The slice grid, `fvr_lens.grid` floats.
    pub grid: *mut f32,
    /// Its length in floats.
    pub grid_len: usize,
    /// Scratch, `fvr_lens.aux` floats.
    pub aux: *mut f32,
    /// Its length in floats.
    pub aux_len: usize,
    /// The image, `fvr_lens.out` floats, row 0 at the top.
    pub out: *mut f32,
    /// Its length in floats.
    pub out_len: usize,
}

/// Floats each buffer of a view needs (`fvr_buffer_lens`).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct fvr_lens {
    /// Slice grid.
    pub grid: usize,
    /// Scratch.
    pub aux: usize,
    /// Image: `width · height`.
    pub out: usize,
}

/// What an opened image holds (`fvr_source_info`).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct fvr_info {
    /// Cube side `n`.
    pub n: u32,
    /// Volume dimensions.
    pub dims: [u32; 3],
    /// 1 = f16, 2 = f32 (the header's code).
    pub precision: u32,
    /// Filter code: 0 nearest, 1 linear, 2 cubic, 3 kb3 … 6 kb6.
    pub filter: u32,
    /// Part code: 0 host, 1 m4f, 2 m3, 3 m7.
    pub part: u32,
    /// The deepest progressive level.
    pub max_level: u32,
    /// Bytes of the image.
    pub image_len: u64,
}
