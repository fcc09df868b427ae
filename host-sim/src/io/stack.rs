//! Stacks of projections as one float32 file: NRRD (`sizes: W H B`, with
//! kinds and the pixel spacing, which 3D Slicer and ITK read as a volume of
//! images) or NumPy's `.npy` (shape `(B, H, W)`, C order, which
//! `numpy.load` reads without a copy). Colour frames add a channel axis:
//! NRRD `sizes: 3 W H B` with kind `RGB-color`, `.npy` shape `(B, H, W, 3)`.
//!
//! Written through the one atomic writer ([`super::atomic`]): a stack is
//! whole or absent.

use std::io::Write;
use std::path::Path;

use super::atomic::Output;

/// The frames of a stack: `views` frames of `width × height` pixels of
/// `channels` interleaved values, frame after frame, row 0 at the top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StackShape {
    /// Frames.
    pub views: usize,
    /// Values per pixel: 1 or 3.
    pub channels: usize,
    /// Pixels across.
    pub width: usize,
    /// Pixels down.
    pub height: usize,
}

impl StackShape {
    /// The sizes of the stack's axes, fastest first: the channels (colour
    /// only), then width, height and views.
    fn sizes(&self) -> Vec<usize> {
        let colour = (self.channels != 1).then_some(self.channels);
        colour
            .into_iter()
            .chain([self.width, self.height, self.views])
            .collect()
    }

    /// Values in the whole stack.
    pub fn len(&self) -> usize {
        self.views * self.channels * self.width * self.height
    }

    /// Whether the stack holds no value.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The file formats a stack is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StackFormat {
    /// NRRD, raw float32, little endian.
    Nrrd,
    /// NumPy `.npy` version 1.0, `<f4`.
    Npy,
}

impl StackFormat {
    /// The format an output name asks for, by its extension in any case.
    pub fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "nrrd" => Some(Self::Nrrd),
            "npy" => Some(Self::Npy),
            _ => None,
        }
    }
}

/// The NRRD header of a stack whose pixels are `pixel_size` apart (mm, or
/// voxels in voxel units).
pub fn nrrd_header(shape: StackShape, pixel_size: f64) -> String {
    let sizes = shape.sizes();
    let (kinds, spacings) = if shape.channels == 1 {
        ("space space list", format!("{pixel_size} {pixel_size} nan"))
    } else {
        (
            "RGB-color space space list",
            format!("nan {pixel_size} {pixel_size} nan"),
        )
    };
    let (views, dimension) = (shape.views, sizes.len());
    let sizes: Vec<String> = sizes.iter().map(usize::to_string).collect();
    let sizes = sizes.join(" ");
    format!(
        "NRRD0004\n# {views} projections by fvr: one frame per view, row 0 at the top\n\
         type: float\ndimension: {dimension}\nsizes: {sizes}\nkinds: {kinds}\n\
         spacings: {spacings}\nencoding: raw\nendian: little\n\n"
    )
}

/// The `.npy` (version 1.0) header of a stack: the magic, the version, the
/// header's length and the dictionary, padded with spaces to a multiple of
/// 64 bytes and ended by a newline, as NumPy's format document asks.
pub fn npy_header(shape: StackShape) -> Vec<u8> {
    // NumPy's C order: slowest axis first.
    let dims: Vec<String> = shape.sizes().iter().rev().map(usize::to_string).collect();
    let dims = format!("({})", dims.join(", "));
    let mut dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {dims}, }}");
    // 6 magic + 2 version + 2 length bytes, then the dictionary and '\n'.
    while (10 + dict.len() + 1) % 64 != 0 {
        dict.push(' ');
    }
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    // A 64-byte multiple below 2^16 for any shape of usize numbers.
    out.extend((dict.len() as u16).to_le_bytes());
    out.extend(dict.as_bytes());
    out
}

/// Write `data` (of `shape`) to `path` in `format`, atomically.
///
/// # Errors
/// `data` not of `shape.len()` values; file errors, with the path.
pub fn write_stack(
    path: &Path,
    format: StackFormat,
    shape: StackShape,
    pixel_size: f64,
    data: &[f32],
) -> Result<(), String> {
    if data.len() != shape.len() {
        return Err(format!(
            "a stack of {shape:?} holds {} values, not {}",
            shape.len(),
            data.len()
        ));
    }
    let header = match format {
        StackFormat::Nrrd => nrrd_header(shape, pixel_size).into_bytes(),
        StackFormat::Npy => npy_header(shape),
    };
    let write = || -> std::io::Result<()> {
        let mut out = Output::create(path)?;
        out.write_all(&header)?;
        for chunk in data.chunks(1 << 16) {
            let bytes: Vec<u8> = chunk.iter().flat_map(|v| v.to_le_bytes()).collect();
            out.write_all(&bytes)?;
        }
        out.commit()
    };
    write().map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape([views, channels, width, height]: [usize; 4]) -> StackShape {
        StackShape {
            views,
            channels,
            width,
            height,
        }
    }

    #[test]
    fn npy_headers_are_padded_to_64_bytes_and_name_the_shape() {
        for (shape, text) in [
            (shape([5, 1, 7, 3]), "'shape': (5, 3, 7), }"),
            (
                shape([100000, 3, 4096, 2048]),
                "'shape': (100000, 2048, 4096, 3), }",
            ),
        ] {
            let h = npy_header(shape);
            assert_eq!(h.len() % 64, 0);
            assert_eq!(&h[..8], b"\x93NUMPY\x01\x00");
            let len = u16::from_le_bytes([h[8], h[9]]) as usize;
            assert_eq!(len + 10, h.len());
            let dict = std::str::from_utf8(&h[10..]).unwrap();
            assert!(dict.starts_with("{'descr': '<f4', 'fortran_order': False,"));
            assert!(dict.contains(text), "{dict}");
            assert!(dict.ends_with('\n'));
        }
    }

    #[test]
    fn nrrd_headers_give_kinds_and_spacing() {
        let grey = nrrd_header(shape([4, 1, 8, 6]), 0.5);
        assert!(grey.contains("sizes: 8 6 4\n"));
        assert!(grey.contains("kinds: space space list\n"));
        assert!(grey.contains("spacings: 0.5 0.5 nan\n"));
        assert!(grey.ends_with("\n\n"));
        let rgb = nrrd_header(shape([2, 3, 8, 6]), 1.0);
        assert!(rgb.contains("dimension: 4\nsizes: 3 8 6 2\n"));
        assert!(rgb.contains("kinds: RGB-color space space list\n"));
    }

    #[test]
    fn a_stack_of_the_wrong_length_is_refused_and_nothing_written() {
        let dir = std::env::temp_dir().join(format!("fvr-stack-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.npy");
        let shape = shape([2, 1, 2, 2]);
        assert!(write_stack(&path, StackFormat::Npy, shape, 1.0, &[0.0; 7]).is_err());
        assert!(!path.exists());
        let data: Vec<f32> = (0..8).map(|i| i as f32 - 2.5).collect();
        write_stack(&path, StackFormat::Npy, shape, 1.0, &data).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let body = &bytes[npy_header(shape).len()..];
        let back: Vec<f32> = body
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        assert_eq!(back, data);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
