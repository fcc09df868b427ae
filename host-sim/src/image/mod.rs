//! Writing rendered images: float32 NRRD, or auto-windowed 8-bit PNG.

pub mod output;
pub mod plot;

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// Lower and upper percentile of the automatic PNG window.
pub const AUTO_WINDOW_PERCENTILES: (f64, f64) = (0.5, 99.5);

/// The automatic window `(low, high)`: the 0.5th and 99.5th percentiles of
/// the finite pixel values, widened to a non-empty interval.
pub fn auto_window(pixels: &[f64]) -> (f64, f64) {
    let mut v: Vec<f64> = pixels.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return (0.0, 1.0);
    }
    v.sort_by(f64::total_cmp);
    let at = |p: f64| v[((p / 100.0) * (v.len() - 1) as f64).round() as usize];
    let (lo, hi) = (at(AUTO_WINDOW_PERCENTILES.0), at(AUTO_WINDOW_PERCENTILES.1));
    if hi > lo {
        (lo, hi)
    } else {
        (lo, lo + 1.0)
    }
}

/// Map pixels to 8-bit grey through `window`, clamping outside it.
pub fn to_gray8(pixels: &[f64], window: (f64, f64)) -> Vec<u8> {
    let (lo, hi) = window;
    pixels
        .iter()
        .map(|&x| {
            let t = if x.is_finite() {
                (x - lo) / (hi - lo)
            } else {
                0.0
            };
            (t.clamp(0.0, 1.0) * 255.0).round() as u8
        })
        .collect()
}

/// Write a `width × height` grey image (row 0 at the top) as an 8-bit PNG,
/// auto-windowed ([`auto_window`]).
///
/// # Errors
/// File creation or encoding failure, with the path in the message.
pub fn write_png(path: &Path, width: usize, height: usize, pixels: &[f64]) -> Result<(), String> {
    let gray = to_gray8(pixels, auto_window(pixels));
    let fail = |e: &dyn std::fmt::Display| format!("cannot write PNG `{}`: {e}", path.display());
    let file = File::create(path).map_err(|e| fail(&e))?;
    let mut enc = png::Encoder::new(BufWriter::new(file), width as u32, height as u32);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header().map_err(|e| fail(&e))?;
    writer.write_image_data(&gray).map_err(|e| fail(&e))?;
    writer.finish().map_err(|e| fail(&e))
}
