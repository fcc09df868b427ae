//! Pictures a person looks at: window/level, 8- or 16-bit PNG, colormaps
//! for X-ray images, and animated PNG (APNG) turntables.
//!
//! # Windowing
//! A window `[low, high]` maps pixel values linearly to black…white (or the
//! colormap's first…last colour), clamping outside. It is either explicit,
//! from `--window W --level L` as `[L − W/2, L + W/2]` (the radiology
//! convention: the level is the centre, the window the width), or automatic,
//! from two percentiles of the finite pixel values (0.5th and 99.5th by
//! default, [`crate::image::AUTO_WINDOW_PERCENTILES`]). NaN pixels map to
//! the low end.
//!
//! # Colormaps
//! `gray` (the default), and two classic maps for X-ray images, as
//! piecewise-linear ramps whose breakpoints are those of matplotlib's
//! `lib/matplotlib/_cm.py` (`_bone_data`, `_hot_data`), which reproduce
//! MATLAB's `bone` and `hot`:
//! - `bone`: grey with a blue tint in the shadows and a cyan mid-tone, the
//!   look of a radiograph on a light box (MATLAB defines it as
//!   `(7·gray + hot with channels reversed)/8`);
//! - `hot`: black–red–yellow–white, for seeing small differences in dense
//!   regions.

use std::path::Path;
use std::str::FromStr;

use crate::image::AUTO_WINDOW_PERCENTILES;

/// Bits per channel of a PNG.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bits {
    /// 8 bits: 256 levels, what every viewer shows.
    Eight,
    /// 16 bits: 65,536 levels, for measurement and later re-windowing.
    Sixteen,
}

impl FromStr for Bits {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "8" => Ok(Bits::Eight),
            "16" => Ok(Bits::Sixteen),
            _ => Err(format!("bit depth `{s}` must be 8 or 16")),
        }
    }
}

/// How pixel values map to the output range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Window {
    /// The `(low, high)` percentiles of the finite pixel values.
    Percentiles(f64, f64),
    /// An explicit range `[low, high]`, `low < high`.
    Range(f64, f64),
}

impl Default for Window {
    fn default() -> Self {
        Window::Percentiles(AUTO_WINDOW_PERCENTILES.0, AUTO_WINDOW_PERCENTILES.1)
    }
}

impl Window {
    /// The window of width `width` centred on `level`.
    ///
    /// # Errors
    /// A width that is not finite and positive, or a level that is not finite.
    pub fn from_width_level(width: f64, level: f64) -> Result<Self, String> {
        if !(width.is_finite() && width > 0.0) {
            return Err(format!(
                "--window {width}: the width must be a positive number"
            ));
        }
        if !level.is_finite() {
            return Err(format!(
                "--level {level}: the level must be a finite number"
            ));
        }
        Ok(Window::Range(level - width / 2.0, level + width / 2.0))
    }

    /// The window from percentiles `low` and `high` (0 to 100).
    ///
    /// # Errors
    /// Percentiles outside `[0, 100]` or not increasing.
    pub fn from_percentiles(low: f64, high: f64) -> Result<Self, String> {
        if !(0.0..=100.0).contains(&low) || !(0.0..=100.0).contains(&high) || low >= high {
            return Err(format!(
                "percentiles {low},{high} must satisfy 0 <= low < high <= 100"
            ));
        }
        Ok(Window::Percentiles(low, high))
    }

    /// The range `[low, high]` this window gives for `pixels` (widened to a
    /// non-empty interval for constant images).
    pub fn resolve(&self, pixels: &[f64]) -> (f64, f64) {
        match *self {
            Window::Range(lo, hi) => (lo, hi),
            Window::Percentiles(p_lo, p_hi) => percentile_range(pixels, p_lo, p_hi),
        }
    }
}

/// The `p_lo`-th and `p_hi`-th percentiles of the finite values (nearest
/// rank on the sorted values), widened to a non-empty interval. Each rank
/// is selected in linear time, not sorted for (a turntable's frames hold
/// millions of pixels).
pub fn percentile_range(pixels: &[f64], p_lo: f64, p_hi: f64) -> (f64, f64) {
    let mut v: Vec<f64> = pixels.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return (0.0, 1.0);
    }
    let rank = |p: f64| (((p / 100.0) * (v.len() - 1) as f64).round() as usize).min(v.len() - 1);
    let (r_lo, r_hi) = (rank(p_lo), rank(p_hi));
    let hi = *v.select_nth_unstable_by(r_hi, f64::total_cmp).1;
    // Ranks below `r_hi` now sit before it.
    let lo = *v[..=r_hi]
        .select_nth_unstable_by(r_lo.min(r_hi), f64::total_cmp)
        .1;
    if hi > lo {
        (lo, hi)
    } else {
        (lo, lo + 1.0)
    }
}

/// A colormap for grey-level images.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Colormap {
    /// Black to white (a grey PNG).
    Gray,
    /// matplotlib/MATLAB `bone`.
    Bone,
    /// matplotlib/MATLAB `hot`.
    Hot,
}

/// Breakpoints `(x, value)` of one channel, `x` increasing from 0 to 1.
type Ramp = &'static [(f64, f64)];

/// `bone`: red, green, blue ramps (matplotlib `_cm.py`, `_bone_data`).
const BONE: [Ramp; 3] = [
    &[(0.0, 0.0), (0.746032, 0.652778), (1.0, 1.0)],
    &[
        (0.0, 0.0),
        (0.365079, 0.319444),
        (0.746032, 0.777778),
        (1.0, 1.0),
    ],
    &[(0.0, 0.0), (0.365079, 0.444444), (1.0, 1.0)],
];

/// `hot`: red, green, blue ramps (matplotlib `_cm.py`, `_hot_data`).
const HOT: [Ramp; 3] = [
    &[(0.0, 0.0416), (0.365079, 1.0), (1.0, 1.0)],
    &[(0.0, 0.0), (0.365079, 0.0), (0.746032, 1.0), (1.0, 1.0)],
    &[(0.0, 0.0), (0.746032, 0.0), (1.0, 1.0)],
];

impl Colormap {
    /// Every colormap, with its command-line name.
    pub const ALL: [(Colormap, &'static str); 3] = [
        (Colormap::Gray, "gray"),
        (Colormap::Bone, "bone"),
        (Colormap::Hot, "hot"),
    ];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        Colormap::ALL
            .iter()
            .find(|(c, _)| *c == self)
            .map_or("gray", |(_, n)| n)
    }

    /// Colour `[r, g, b]` in `[0, 1]` for `t` in `[0, 1]` (clamped).
    pub fn rgb(self, t: f64) -> [f64; 3] {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        match self {
            Colormap::Gray => [t; 3],
            Colormap::Bone => BONE.map(|r| ramp(r, t)),
            Colormap::Hot => HOT.map(|r| ramp(r, t)),
        }
    }
}

impl FromStr for Colormap {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Colormap::ALL
            .iter()
            .find(|(_, n)| *n == s)
            .map(|(c, _)| *c)
            .ok_or_else(|| format!("unknown colormap `{s}`: expected gray, bone or hot"))
    }
}

/// Linear interpolation in the breakpoints of `r` at `t ∈ [0, 1]`.
fn ramp(r: Ramp, t: f64) -> f64 {
    for w in r.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if t <= x1 {
            return y0 + (y1 - y0) * (t - x0) / (x1 - x0);
        }
    }
    r.last().map_or(t, |&(_, y)| y)
}

/// How to turn an image of values into PNG pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Bits per channel.
    pub bits: Bits,
    /// Value range.
    pub window: Window,
    /// Colours.
    pub colormap: Colormap,
}

impl Default for Style {
    fn default() -> Self {
        Style {
            bits: Bits::Eight,
            window: Window::default(),
            colormap: Colormap::Gray,
        }
    }
}

impl Style {
    pub(crate) fn png_color(&self) -> png::ColorType {
        match self.colormap {
            Colormap::Gray => png::ColorType::Grayscale,
            _ => png::ColorType::Rgb,
        }
    }

    pub(crate) fn png_depth(&self) -> png::BitDepth {
        match self.bits {
            Bits::Eight => png::BitDepth::Eight,
            Bits::Sixteen => png::BitDepth::Sixteen,
        }
    }

    /// PNG sample bytes (big-endian for 16 bits, as PNG stores them) for
    /// `pixels` through the window `range`.
    pub fn encode(&self, pixels: &[f64], range: (f64, f64)) -> Vec<u8> {
        let (lo, hi) = range;
        let channels = if self.colormap == Colormap::Gray {
            1
        } else {
            3
        };
        let bytes = match self.bits {
            Bits::Eight => 1,
            Bits::Sixteen => 2,
        };
        let mut out = Vec::with_capacity(pixels.len() * channels * bytes);
        for &x in pixels {
            let t = if x.is_finite() {
                (x - lo) / (hi - lo)
            } else {
                0.0
            };
            let rgb = self.colormap.rgb(t);
            for &c in rgb.iter().take(channels) {
                match self.bits {
                    Bits::Eight => out.push((c * 255.0).round() as u8),
                    Bits::Sixteen => out.extend(((c * 65535.0).round() as u16).to_be_bytes()),
                }
            }
        }
        out
    }
}

/// Write a `width × height` image (row 0 at the top) as a PNG in `style`.
///
/// # Errors
/// Pixel count not `width × height`, file creation or encoding failure;
/// the message names the path.
pub fn write_png(
    path: &Path,
    width: usize,
    height: usize,
    pixels: &[f64],
    style: &Style,
) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| super::png::png_error(path, e);
    if pixels.len() != width.saturating_mul(height) {
        return Err(fail(&format!(
            "{} pixels for a {width}x{height} image",
            pixels.len()
        )));
    }
    let data = style.encode(pixels, style.window.resolve(pixels));
    super::png::write(
        path,
        (width, height),
        style.png_color(),
        style.png_depth(),
        &data,
    )
}

pub use super::apng::{write_apng, ApngStream};
