//! Pictures: the rendered [`Image`] (grey or RGB) with its NRRD and PNG
//! output, windowing, colormaps and APNG ([`output`]), and study plots
//! ([`plot`]).

mod apng;
pub mod film;
pub mod nrrd_image;
pub mod output;
pub mod plot;
mod png;

use output::percentile_range;

/// Lower and upper percentile of the automatic PNG window.
pub const AUTO_WINDOW_PERCENTILES: (f64, f64) = (0.5, 99.5);

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

pub use fvr_engine::image::Image;

/// Writing an [`Image`] to the files the program produces.
pub trait ImageFiles {
    /// Write as a float32 NRRD: `sizes: W H` for grey, `sizes: 3 W H`
    /// (channel fastest) for RGB.
    ///
    /// # Errors
    /// File errors, with the path.
    fn write_nrrd(&self, path: &std::path::Path) -> Result<(), String>;

    /// Write as an 8-bit PNG, grey or RGB, auto-windowed over all channels
    /// together (one window keeps the lights' colour balance).
    ///
    /// # Errors
    /// File or encoding errors, with the path.
    fn write_png(&self, path: &std::path::Path) -> Result<(), String>;

    /// Write as an 8-bit PNG, grey or RGB, every channel through the
    /// window `range`.
    ///
    /// # Errors
    /// File or encoding errors, with the path.
    fn write_png_window(&self, path: &std::path::Path, range: (f64, f64)) -> Result<(), String>;
}

impl ImageFiles for Image {
    fn write_nrrd(&self, path: &std::path::Path) -> Result<(), String> {
        let data: Vec<f32> = self.data.iter().map(|&v| v as f32).collect();
        let sizes: Vec<usize> = if self.channels == 1 {
            vec![self.width, self.height]
        } else {
            vec![self.channels, self.width, self.height]
        };
        crate::io::nrrd::write_nrrd_f32(path, &sizes, &data).map_err(|e| e.to_string())
    }

    fn write_png(&self, path: &std::path::Path) -> Result<(), String> {
        let (lo, hi) = AUTO_WINDOW_PERCENTILES;
        self.write_png_window(path, percentile_range(&self.data, lo, hi))
    }

    fn write_png_window(&self, path: &std::path::Path, range: (f64, f64)) -> Result<(), String> {
        let bytes = to_gray8(&self.data, range);
        let color = if self.channels == 1 {
            ::png::ColorType::Grayscale
        } else {
            ::png::ColorType::Rgb
        };
        png::write(
            path,
            (self.width, self.height),
            color,
            ::png::BitDepth::Eight,
            &bytes,
        )
    }
}
