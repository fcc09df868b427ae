//! A rendered image as a float32 NRRD that keeps its geometry: `kinds`
//! (`domain domain` for grey, `RGB-color domain domain` for colour, so 3D
//! Slicer opens an RGB render as one colour image rather than a stack of
//! three slices) and the pixel size as `spacings`.

use std::path::Path;

use super::Image;
use crate::io::nrrd::{encode_nrrd_f32, IoError};

/// The header of `image` as [`encode_nrrd_f32`] writes it, with `kinds` and,
/// for a known `pixel_size` (mm, or voxels in voxel units), `spacings`.
pub fn encode_image_nrrd(image: &Image, pixel_size: Option<f64>) -> Vec<u8> {
    let data: Vec<f32> = image.data.iter().map(|&v| v as f32).collect();
    let (sizes, kinds, channel_spacing) = if image.channels == 1 {
        (vec![image.width, image.height], "domain domain", "")
    } else {
        (
            vec![image.channels, image.width, image.height],
            "RGB-color domain domain",
            "nan ",
        )
    };
    let bytes = encode_nrrd_f32(&sizes, &data);
    // The header is the text before the first blank line.
    let end = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .expect("a NRRD header ends with a blank line")
        + 1;
    let mut fields = format!("kinds: {kinds}\n");
    if let Some(p) = pixel_size.filter(|p| p.is_finite() && *p > 0.0) {
        fields.push_str(&format!("spacings: {channel_spacing}{p:?} {p:?}\n"));
    }
    let mut out = Vec::with_capacity(bytes.len() + fields.len());
    out.extend_from_slice(&bytes[..end]);
    out.extend_from_slice(fields.as_bytes());
    out.extend_from_slice(&bytes[end..]);
    out
}

/// Write [`encode_image_nrrd`] atomically. Errors carry the path.
///
/// # Errors
/// File errors.
pub fn write_image_nrrd(path: &Path, image: &Image, pixel_size: Option<f64>) -> Result<(), String> {
    crate::io::atomic::write_bytes(path, &encode_image_nrrd(image, pixel_size))
        .map_err(|e| IoError::from(e).in_file(path).to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(bytes: &[u8]) -> String {
        let end = bytes.windows(2).position(|w| w == b"\n\n").unwrap();
        String::from_utf8(bytes[..end].to_vec()).unwrap()
    }

    #[test]
    fn grey_and_colour_kinds_and_spacing() {
        let grey = Image {
            channels: 1,
            width: 3,
            height: 2,
            data: vec![1.0; 6],
        };
        let h = header(&encode_image_nrrd(&grey, Some(0.25)));
        assert!(h.contains("sizes: 3 2\n"), "{h}");
        assert!(h.contains("kinds: domain domain\n"), "{h}");
        assert!(h.contains("spacings: 0.25 0.25"), "{h}");
        let rgb = Image {
            channels: 3,
            data: vec![1.0; 18],
            ..grey
        };
        let bytes = encode_image_nrrd(&rgb, Some(1.5));
        let h = header(&bytes);
        assert!(h.contains("sizes: 3 3 2\n"), "{h}");
        assert!(h.contains("kinds: RGB-color domain domain\n"), "{h}");
        assert!(h.contains("spacings: nan 1.5 1.5"), "{h}");
        assert!(!header(&encode_image_nrrd(&rgb, None)).contains("spacings"));
        // The samples follow the blank line unchanged.
        assert_eq!(bytes.len() - h.len() - 2, 18 * 4);
    }
}
