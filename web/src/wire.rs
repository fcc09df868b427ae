//! The volume wire format between `fvr view` (which reads any file the
//! project reads, data sets and phantoms) and the page's WebAssembly:
//!
//! ```text
//! bytes  0..8   b"FVRVOL1\n"
//! bytes  8..20  nx, ny, nz          u32, little-endian
//! bytes 20..44  spacing x, y, z mm  f64, little-endian
//! bytes 44..    nx·ny·nz samples    f32, little-endian, x fastest
//! ```
//!
//! The samples start 4-byte aligned, so the page can view them in place.

use fvr_engine::volume::{check_spacing, Volume};

/// The first 8 bytes.
pub const MAGIC: &[u8; 8] = b"FVRVOL1\n";

/// Bytes before the samples.
pub const HEADER_LEN: usize = 44;

/// The most voxels a volume may have in the browser: 512³ (512 MiB of
/// f32 samples; its spectrum and transforms need several times that).
pub const MAX_VOXELS: u64 = 1 << 27;

/// The volume as wire bytes.
pub fn encode(volume: &Volume) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + 4 * volume.data.len());
    out.extend_from_slice(MAGIC);
    for &d in &volume.dims {
        // Volumes the project reads are far below 2³² along an axis.
        out.extend_from_slice(&u32::try_from(d).unwrap_or(u32::MAX).to_le_bytes());
    }
    for &s in &volume.spacing {
        out.extend_from_slice(&s.to_le_bytes());
    }
    for &v in &volume.data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// The dims a header announces, checked against [`MAX_VOXELS`], so that
/// the page can refuse a volume before it holds all of it.
///
/// # Errors
/// Not this format, a zero axis, or too many voxels.
pub fn header_dims(bytes: &[u8]) -> Result<[usize; 3], String> {
    if bytes.len() < HEADER_LEN || &bytes[..8] != MAGIC {
        return Err("not a volume in fvr's wire format".into());
    }
    let dims: [usize; 3] = core::array::from_fn(|a| {
        let at = 8 + 4 * a;
        u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as usize
    });
    let voxels = dims.iter().map(|&d| d as u64).product::<u64>();
    if voxels == 0 {
        return Err(format!(
            "a {}x{}x{} volume has no voxels",
            dims[0], dims[1], dims[2]
        ));
    }
    if voxels > MAX_VOXELS {
        return Err(format!(
            "a {}x{}x{} volume is too large for the browser's memory (at most {MAX_VOXELS} \
             voxels, 512^3); render it with `fvr render`",
            dims[0], dims[1], dims[2]
        ));
    }
    Ok(dims)
}

/// The volume the bytes hold.
///
/// # Errors
/// As [`header_dims`], a length that does not match the dims (a truncated
/// download), a bad spacing or a non-finite sample.
pub fn decode(bytes: &[u8]) -> Result<Volume, String> {
    let dims = header_dims(bytes)?;
    let voxels = dims[0] * dims[1] * dims[2];
    let want = HEADER_LEN + 4 * voxels;
    if bytes.len() != want {
        return Err(format!(
            "a {}x{}x{} volume needs {want} bytes, got {} (truncated?)",
            dims[0],
            dims[1],
            dims[2],
            bytes.len()
        ));
    }
    let spacing: [f64; 3] = core::array::from_fn(|a| {
        let at = 20 + 8 * a;
        let mut b = [0u8; 8];
        b.copy_from_slice(&bytes[at..at + 8]);
        f64::from_le_bytes(b)
    });
    check_spacing(spacing).map_err(|e| e.to_string())?;
    let mut data = Vec::new();
    data.try_reserve_exact(voxels)
        .map_err(|_| format!("{voxels} voxels do not fit in the browser's memory"))?;
    for (i, c) in bytes[HEADER_LEN..].chunks_exact(4).enumerate() {
        let v = f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
        if !v.is_finite() {
            return Err(format!("sample {i} is not finite ({v})"));
        }
        data.push(v);
    }
    let mut volume = Volume::new(dims, data);
    volume.spacing = spacing;
    Ok(volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> Volume {
        let mut v = Volume::new([3, 2, 2], (0..12).map(|i| i as f32 * 0.5).collect());
        v.spacing = [0.5, 1.0, 2.5];
        v
    }

    #[test]
    fn round_trip_keeps_dims_spacing_and_samples() {
        let v = small();
        let bytes = encode(&v);
        assert_eq!(bytes.len(), HEADER_LEN + 48);
        assert_eq!(decode(&bytes).unwrap(), v);
    }

    #[test]
    fn refuses_other_files_truncation_and_huge_dims() {
        let bytes = encode(&small());
        assert!(decode(b"NRRD0004\n").unwrap_err().contains("wire format"));
        let cut = decode(&bytes[..bytes.len() - 4]).unwrap_err();
        assert!(cut.contains("truncated"), "{cut}");
        let mut huge = bytes.clone();
        huge[8..20].copy_from_slice(&[0, 4, 0, 0, 0, 4, 0, 0, 0, 4, 0, 0]);
        let e = header_dims(&huge).unwrap_err();
        assert!(e.contains("too large for the browser"), "{e}");
        let mut nan = bytes;
        nan[HEADER_LEN..HEADER_LEN + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(decode(&nan).unwrap_err().contains("not finite"));
    }
}
