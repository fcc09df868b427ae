//! `fvr render --zoom F`: the same field of view, `F` times as many pixels
//! per side (the slice spectrum zero-padded before the inverse transform,
//! [`fvr_engine::image::zoom`]).

use clap::Args;
use fvr_engine::image::zoom::{zoomed_side, MAX_ZOOM};

/// The magnification flag of `fvr render`.
#[derive(Args, Clone, Copy)]
pub(crate) struct ZoomArgs {
    /// Magnify the image F times: the same field of view (--size), F times
    /// as many pixels per side, each --pixel-size / F mm, by sinc
    /// interpolation of the projection (its slice spectrum zero-padded to
    /// F times the grid). F is a whole number from 1 to 64 with no prime
    /// factor above 5 (2, 3, 4, 5, 6, 8, ...); plain X-ray views only.
    /// Pixel (F col, F row) of the zoomed image is pixel (col, row) of the
    /// plain one.
    #[arg(long, value_name = "F", default_value = "1", value_parser = parse_zoom)]
    pub(crate) zoom: usize,
}

impl Default for ZoomArgs {
    fn default() -> Self {
        Self { zoom: 1 }
    }
}

/// A zoom factor: a finite whole number `1 ..= MAX_ZOOM` whose prime factors
/// are 2, 3 and 5.
pub(crate) fn parse_zoom(s: &str) -> Result<usize, String> {
    let bad = |why: &str| format!("expected a zoom factor F, {why}, got `{s}`");
    let f = s
        .trim()
        .parse::<f64>()
        .map_err(|_| bad("a whole number such as 2 or 4"))?;
    if !f.is_finite() || f < 1.0 {
        return Err(bad("a finite number of at least 1"));
    }
    if f > MAX_ZOOM as f64 {
        return Err(bad(&format!(
            "at most {MAX_ZOOM} (a 128-voxel view zoomed {MAX_ZOOM} times is already 8192 x 8192 pixels)"
        )));
    }
    if f.fract() != 0.0 {
        return Err(bad("a whole number such as 2 or 4"));
    }
    let zoom = f as usize;
    zoomed_side(1, zoom)
        .map_err(|_| bad("with no prime factor above 5 (2, 3, 4, 5, 6, 8, 9, 10, ...)"))?;
    Ok(zoom)
}

#[cfg(test)]
mod tests {
    use super::parse_zoom;

    #[test]
    fn zoom_factors() {
        for (s, z) in [("1", 1), ("2", 2), ("4.0", 4), (" 6 ", 6), ("64", 64)] {
            assert_eq!(parse_zoom(s), Ok(z), "{s}");
        }
        for s in [
            "0", "-2", "0.5", "1.5", "7", "65", "1e9", "inf", "NaN", "two", "",
        ] {
            assert!(parse_zoom(s).is_err(), "{s}");
        }
    }
}
