//! Reading NumPy `.npy` images and stacks of views, as `fvr project`
//! writes them (`<f4`, C order, shape `(B, H, W)`), for `fvr compare`:
//! a grey image `(H, W)` or a stack `(B, H, W)` of `<f4` or `<f8`
//! samples. Other layouts (Fortran order, colour or other sample types)
//! are refused in one line naming what the file holds.
//!
//! Input is untrusted: the header is parsed without panics, the samples'
//! size is checked against the file and the memory limit before any is
//! read, and a NaN or infinite sample is an error.

use std::io::Read;
use std::path::Path;

use fvr_engine::volume::Volume;

use super::error::format_error;
use super::nrrd::ImageKind;
use super::IoError;

/// The magic bytes that open every `.npy` file.
pub const NPY_MAGIC: &[u8; 6] = b"\x93NUMPY";

/// Longest header accepted (numpy writes at most a few hundred bytes).
const MAX_HEADER: usize = 1 << 16;

/// Whether `bytes` (a file's first bytes) open a `.npy` file.
pub fn is_npy(bytes: &[u8]) -> bool {
    bytes.starts_with(NPY_MAGIC)
}

/// Read the `.npy` image or stack at `path`: dims `[W, H, B]` (`B` = 1 for
/// an image) and [`ImageKind::Scalar`] or [`ImageKind::Stack`].
///
/// # Errors
/// An unreadable file, a malformed header, a layout other than those
/// above, fewer samples than the shape needs, more memory than the limit,
/// or a non-finite sample; each carries the path.
pub fn read_npy_image(path: &Path) -> Result<(Volume, ImageKind), IoError> {
    read(path).map_err(|e| e.in_file(path))
}

fn read(path: &Path) -> Result<(Volume, ImageKind), IoError> {
    let bad = |field: &'static str, why: String| format_error("NumPy .npy", field, why);
    let mut file = super::open_file(path)?;
    let mut lead = [0u8; 10];
    file.read_exact(&mut lead)
        .map_err(|_| bad("magic", "the file is shorter than a .npy header".into()))?;
    if !is_npy(&lead) {
        return Err(bad("magic", "not a .npy file".into()));
    }
    // Version 1 gives the header's length in 2 bytes, versions 2 and 3 in 4.
    let len = match lead[6] {
        1 => usize::from(u16::from_le_bytes([lead[8], lead[9]])),
        2 | 3 => {
            let mut more = [0u8; 2];
            file.read_exact(&mut more)
                .map_err(|_| bad("header", "cut short".into()))?;
            u32::from_le_bytes([lead[8], lead[9], more[0], more[1]]) as usize
        }
        v => return Err(bad("version", format!("{v} is not 1, 2 or 3"))),
    };
    if len > MAX_HEADER {
        return Err(bad(
            "header",
            format!("{len} bytes long, at most {MAX_HEADER}"),
        ));
    }
    let mut header = vec![0u8; len];
    file.read_exact(&mut header)
        .map_err(|_| bad("header", "cut short".into()))?;
    let header = String::from_utf8_lossy(&header);
    let value = |key: &str| -> Option<&str> {
        let at = header.find(&format!("'{key}':"))? + key.len() + 3;
        Some(header[at..].trim_start())
    };
    let descr = value("descr").ok_or_else(|| bad("descr", "missing".into()))?;
    let size = if descr.starts_with("'<f4'") {
        4
    } else if descr.starts_with("'<f8'") {
        8
    } else {
        let shown: String = descr.chars().take_while(|&c| c != ',').take(12).collect();
        return Err(bad(
            "descr",
            format!("{shown}: only little-endian float32 ('<f4') and float64 ('<f8')"),
        ));
    };
    if !value("fortran_order").is_some_and(|v| v.starts_with("False")) {
        return Err(bad("fortran_order", "only C order (False) is read".into()));
    }
    let shape = value("shape").ok_or_else(|| bad("shape", "missing".into()))?;
    let inner = shape
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| bad("shape", "not a tuple".into()))?;
    let sizes: Vec<usize> = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad("shape", format!("({inner}) is not a tuple of sizes")))?;
    let ([views, height, width], kind) = match sizes[..] {
        [h, w] => ([1, h, w], ImageKind::Scalar),
        [b, h, w] => ([b, h, w], ImageKind::Stack),
        _ => {
            return Err(bad(
                "shape",
                format!("({inner}): an image (H, W) or a stack of views (B, H, W)"),
            ))
        }
    };
    let count = [views, height, width]
        .iter()
        .try_fold(1usize, |c, &d| c.checked_mul(d))
        .filter(|&c| c > 0)
        .ok_or_else(|| bad("shape", format!("({inner}) holds no samples or too many")))?;
    let needed = (count as u64).saturating_mul(4 + size as u64);
    let limit = crate::budget::limit_bytes();
    if needed > limit {
        return Err(IoError::TooLarge { needed, limit });
    }
    let mut raw = Vec::new();
    file.take((count * size) as u64).read_to_end(&mut raw)?;
    if raw.len() < count * size {
        return Err(IoError::Truncated {
            expected: (count * size) as u64,
            found: raw.len() as u64,
            gzip: false,
        });
    }
    let data: Vec<f32> = match size {
        4 => raw
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect(),
        _ => raw
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap_or([0; 8])) as f32)
            .collect(),
    };
    if let Some(at) = data.iter().position(|v| !v.is_finite()) {
        let plane = width * height;
        return Err(IoError::NonFinite {
            voxel: [at % width, at % plane / width, at / plane],
            value: f64::from(data[at]),
        });
    }
    Ok((Volume::new([width, height, views], data), kind))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::stack::{write_stack, StackFormat, StackShape};

    fn dir() -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("fvr-npy-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A hand-made `.npy` of `descr`, `order` and `shape` with `body`.
    fn npy(name: &str, descr: &str, order: &str, shape: &str, body: &[u8]) -> std::path::PathBuf {
        let mut text =
            format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape}, }}");
        while (10 + text.len() + 1) % 64 != 0 {
            text.push(' ');
        }
        text.push('\n');
        let mut bytes = NPY_MAGIC.to_vec();
        bytes.extend([1, 0]);
        bytes.extend((text.len() as u16).to_le_bytes());
        bytes.extend(text.as_bytes());
        bytes.extend(body);
        let path = dir().join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn the_stacks_fvr_writes_read_back_with_their_shape() {
        let shape = StackShape {
            views: 3,
            channels: 1,
            width: 5,
            height: 4,
        };
        let values: Vec<f32> = (0..shape.len()).map(|i| i as f32 * 0.5 - 7.0).collect();
        let path = dir().join("s.npy");
        write_stack(&path, StackFormat::Npy, shape, 1.0, &values).unwrap();
        let (image, kind) = read_npy_image(&path).unwrap();
        assert_eq!((image.dims, kind), ([5, 4, 3], ImageKind::Stack));
        assert_eq!(image.data, values);
        // f64 and a plain image.
        let body: Vec<u8> = [1.5f64, -2.0, 3.25, 0.0, 8.0, 9.5]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let (image, kind) = read_npy_image(&npy("d.npy", "<f8", "False", "(2, 3)", &body)).unwrap();
        assert_eq!((image.dims, kind), ([3, 2, 1], ImageKind::Scalar));
        assert_eq!(image.data, vec![1.5, -2.0, 3.25, 0.0, 8.0, 9.5]);
    }

    #[test]
    fn other_layouts_and_broken_files_are_one_line_errors() {
        let four = [0u8; 4 * 6];
        for (name, descr, order, shape, body, needle) in [
            (
                "i.npy",
                "<i4",
                "False",
                "(2, 3)",
                &four[..],
                "only little-endian float32",
            ),
            (
                "b.npy",
                ">f4",
                "False",
                "(2, 3)",
                &four[..],
                "only little-endian float32",
            ),
            ("f.npy", "<f4", "True", "(2, 3)", &four[..], "only C order"),
            (
                "c.npy",
                "<f4",
                "False",
                "(1, 2, 3, 3)",
                &four[..],
                "a stack of views (B, H, W)",
            ),
            (
                "z.npy",
                "<f4",
                "False",
                "(0, 3)",
                &four[..],
                "holds no samples",
            ),
            (
                "t.npy",
                "<f4",
                "False",
                "(2, 4)",
                &four[..],
                "truncated data",
            ),
            (
                "o.npy",
                "<f4",
                "False",
                "(99999999999, 99999999999)",
                &four[..],
                "too many",
            ),
        ] {
            let err = read_npy_image(&npy(name, descr, order, shape, body)).unwrap_err();
            let text = err.to_string();
            assert!(
                text.contains(needle) && text.contains(name),
                "{name}: {text}"
            );
            assert_eq!(text.lines().count(), 1, "{text}");
        }
        let nan: Vec<u8> = [1.0f32, f32::NAN]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let err = read_npy_image(&npy("n.npy", "<f4", "False", "(1, 2)", &nan)).unwrap_err();
        assert!(err.to_string().contains("NaN"), "{err}");
        let short = dir().join("short.npy");
        std::fs::write(&short, b"\x93NUM").unwrap();
        assert!(read_npy_image(&short)
            .unwrap_err()
            .to_string()
            .contains("shorter"));
    }
}
