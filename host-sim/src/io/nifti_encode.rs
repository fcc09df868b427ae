//! A NIfTI-1 encoder for tests and fixtures, and the header's field
//! offsets.

use super::nifti::{HEADER_BYTES, MAGIC_OFFSET, MAGIC_SINGLE};
use crate::io::nrrd::Endian;

/// Encode a single-file NIfTI-1 (`.nii`) of float32 samples in `endian`
/// order, with `pixdim` spacing in mm and scaling `(scl_slope, scl_inter)`.
/// A test and fixture helper: it writes the fields this reader uses, the
/// magic, and no extensions.
///
/// # Panics
/// If `data.len()` is not the product of `dims` or a size exceeds `i16::MAX`.
pub fn encode_nifti_f32(
    dims: [usize; 3],
    spacing: [f64; 3],
    scaling: (f32, f32),
    data: &[f32],
    endian: Endian,
) -> Vec<u8> {
    assert_eq!(
        data.len(),
        dims.iter().product::<usize>(),
        "encode_nifti_f32"
    );
    let i16b = |v: i16| match endian {
        Endian::Little => v.to_le_bytes(),
        Endian::Big => v.to_be_bytes(),
    };
    let f32b = |v: f32| match endian {
        Endian::Little => v.to_le_bytes(),
        Endian::Big => v.to_be_bytes(),
    };
    let mut h = vec![0u8; HEADER_BYTES];
    let mut put = |off: usize, bytes: &[u8]| h[off..off + bytes.len()].copy_from_slice(bytes);
    put(
        0,
        &match endian {
            Endian::Little => 348i32.to_le_bytes(),
            Endian::Big => 348i32.to_be_bytes(),
        },
    );
    put(40, &i16b(3));
    for (a, &d) in dims.iter().enumerate() {
        put(
            42 + 2 * a,
            &i16b(i16::try_from(d).expect("NIfTI sizes fit in i16")),
        );
    }
    for a in 3..7 {
        put(42 + 2 * a, &i16b(1));
    }
    put(70, &i16b(16)); // datatype float32
    put(72, &i16b(32)); // bitpix
    put(76, &f32b(1.0)); // pixdim[0] (qfac)
    for (a, &s) in spacing.iter().enumerate() {
        put(80 + 4 * a, &f32b(s as f32));
    }
    put(108, &f32b(352.0)); // vox_offset
    put(112, &f32b(scaling.0));
    put(116, &f32b(scaling.1));
    put(123, &[2]); // xyzt_units: mm
    put(MAGIC_OFFSET, MAGIC_SINGLE);
    h.extend_from_slice(&[0; 4]); // no extensions
    for &v in data {
        h.extend_from_slice(&f32b(v));
    }
    h
}

/// Byte offsets of header fields, for tests that corrupt them.
pub mod offsets {
    /// `dim[0..8]`, i16 each.
    pub const DIM: usize = 40;
    /// `datatype`, i16.
    pub const DATATYPE: usize = 70;
    /// `pixdim[0..8]`, f32 each.
    pub const PIXDIM: usize = 76;
    /// `vox_offset`, f32.
    pub const VOX_OFFSET: usize = 108;
    /// `scl_slope`, f32.
    pub const SCL_SLOPE: usize = 112;
    /// `scl_inter`, f32.
    pub const SCL_INTER: usize = 116;
    /// `xyzt_units`, u8.
    pub const XYZT_UNITS: usize = 123;
    /// `qform_code`, i16.
    pub const QFORM_CODE: usize = 252;
    /// `sform_code`, i16.
    pub const SFORM_CODE: usize = 254;
    /// `quatern_b`, `quatern_c`, `quatern_d`, f32 each.
    pub const QUATERN_B: usize = 256;
    /// `srow_x`, `srow_y`, `srow_z`, 4 f32 each.
    pub const SROW_X: usize = 280;
    /// `magic`, 4 bytes.
    pub const MAGIC: usize = super::MAGIC_OFFSET;
}
