//! Animated PNGs, written a frame at a time.
//!
//! The animation goes to a temporary file beside the output
//! ([`crate::io::atomic::Output`]) and is renamed over it only when the last
//! frame is in, so a failed or interrupted job never leaves a truncated
//! animation, nor destroys the file it replaces.

use std::path::{Path, PathBuf};

use super::output::{Style, Window};
use crate::io::atomic::Output;

/// An APNG being written: [`ApngStream::push`] each frame as it is rendered,
/// then [`ApngStream::finish`]. Memory: one encoded frame.
pub struct ApngStream {
    writer: Option<png::Writer<Output>>,
    out: Output,
    path: PathBuf,
    pixels: usize,
    range: (f64, f64),
    style: Style,
    /// Frames of interleaved R, G, B values, each channel windowed alike.
    rgb: bool,
    left: usize,
}

impl ApngStream {
    /// Start an animation of `frames` frames of `width × height` at `fps`
    /// frames per second, looping forever, each frame mapped through the
    /// window `range` in `style`; or, if `rgb`, of 8-bit RGB frames of
    /// `width × height` interleaved R, G, B values, all three mapped
    /// through the window `range` (one window keeps the lights' colour
    /// balance, as [`crate::image::ImageFiles::write_png`] does).
    ///
    /// # Errors
    /// No frames, a frame rate outside 1–1000, a size PNG cannot store, or
    /// file creation failure; the message names the path.
    pub fn create(
        path: &Path,
        (width, height): (usize, usize),
        frames: usize,
        fps: u16,
        style: &Style,
        range: (f64, f64),
        rgb: bool,
    ) -> Result<Self, String> {
        let fail = |e: &dyn std::fmt::Display| apng_error(path, e);
        if frames == 0 {
            return Err(fail(&"no frames to write"));
        }
        if !(1..=1000).contains(&fps) {
            return Err(fail(&format!(
                "frame rate {fps} must be 1 to 1000 per second"
            )));
        }
        let count = u32::try_from(frames).map_err(|e| fail(&e))?;
        let out = Output::create(path).map_err(|e| fail(&e))?;
        let mut stream = Self {
            writer: None,
            out: out.clone(),
            path: path.to_path_buf(),
            pixels: width.saturating_mul(height) * if rgb { 3 } else { 1 },
            range,
            style: *style,
            rgb,
            left: frames,
        };
        let header = (|| {
            let (color, depth) = if rgb {
                (png::ColorType::Rgb, png::BitDepth::Eight)
            } else {
                (style.png_color(), style.png_depth())
            };
            let mut enc = super::png::encoder(out, width, height, color, depth)?;
            enc.set_animated(count, 0).map_err(|e| e.to_string())?;
            enc.set_frame_delay(1, fps).map_err(|e| e.to_string())?;
            enc.write_header().map_err(|e| e.to_string())
        })();
        // On error, `stream` drops here and removes the temporary file.
        stream.writer = Some(header.map_err(|e| fail(&e))?);
        Ok(stream)
    }

    /// Encode the next frame (`width × height` values, or interleaved RGB
    /// triples, row 0 at the top).
    ///
    /// # Errors
    /// A frame of the wrong size, more frames than declared, or an encoding
    /// or write failure.
    pub fn push(&mut self, frame: &[f64]) -> Result<(), String> {
        let path = self.path.clone();
        let fail = |e: &dyn std::fmt::Display| apng_error(&path, e);
        if frame.len() != self.pixels {
            return Err(fail(&format!(
                "a frame of {} pixels in an animation of {}-pixel frames",
                frame.len(),
                self.pixels
            )));
        }
        if self.left == 0 {
            return Err(fail(&"more frames than the animation declared"));
        }
        let writer = self
            .writer
            .as_mut()
            .ok_or_else(|| fail(&"already failed"))?;
        let data = if self.rgb {
            super::to_gray8(frame, self.range)
        } else {
            self.style.encode(frame, self.range)
        };
        writer.write_image_data(&data).map_err(|e| fail(&e))?;
        self.left -= 1;
        Ok(())
    }

    /// Close the animation and move it into place.
    ///
    /// # Errors
    /// Fewer frames than declared, or a write or rename failure.
    pub fn finish(mut self) -> Result<(), String> {
        let path = self.path.clone();
        let fail = |e: &dyn std::fmt::Display| apng_error(&path, e);
        if self.left != 0 {
            return Err(fail(&format!("{} frames were never written", self.left)));
        }
        let writer = self.writer.take().ok_or_else(|| fail(&"already failed"))?;
        writer.finish().map_err(|e| fail(&e))?;
        self.out.commit().map_err(|e| fail(&e))
    }
}

fn apng_error(path: &Path, e: &dyn std::fmt::Display) -> String {
    format!("cannot write APNG `{}`: {e}", path.display())
}

/// Write `frames` (each `width × height`, row 0 at the top) as an animated
/// PNG that loops forever at `fps` frames per second, in `style`. One
/// window serves all frames (percentiles over every frame's pixels), so the
/// brightness does not flicker.
///
/// # Errors
/// No frames, a frame of the wrong size, a frame rate outside 1–1000, file
/// creation or encoding failure; the message names the path.
pub fn write_apng(
    path: &Path,
    width: usize,
    height: usize,
    frames: &[Vec<f64>],
    fps: u16,
    style: &Style,
) -> Result<(), String> {
    if let Some(bad) = frames
        .iter()
        .find(|f| f.len() != width.saturating_mul(height))
    {
        return Err(apng_error(
            path,
            &format!(
                "a frame of {} pixels in a {width}x{height} animation",
                bad.len()
            ),
        ));
    }
    let range = match style.window {
        Window::Range(lo, hi) => (lo, hi),
        Window::Percentiles(..) => style.window.resolve(&frames.concat()),
    };
    let mut stream = ApngStream::create(
        path,
        (width, height),
        frames.len(),
        fps,
        style,
        range,
        false,
    )?;
    for frame in frames {
        stream.push(frame)?;
    }
    stream.finish()
}
