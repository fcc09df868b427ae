//! The image stage: the 2D inverse transform that turns a slice into a
//! projection ([`inverse`]) and its zero-padded, magnified form
//! ([`zoom`]), the image type the renderers return, and the
//! agreement measure.

mod agreement;
pub mod finite;
pub mod inverse;
pub mod zoom;

pub use agreement::{max_abs_error, snr_db};

/// An image of 1 (grey) or 3 (RGB) interleaved channels, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Channels per pixel.
    pub channels: usize,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `data[(row·width + col)·channels + c]`.
    pub data: Vec<f64>,
}

impl Image {
    /// Channel `c` as its own `width × height` image.
    pub fn channel(&self, c: usize) -> Vec<f64> {
        self.data
            .iter()
            .skip(c)
            .step_by(self.channels)
            .copied()
            .collect()
    }
}
