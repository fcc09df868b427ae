//! Rendering one [`FrameSpec`] on the device, with instruction counts.
//!
//! Each frame is rendered twice from the same tables: once by
//! `fvr_core::render::render` (the image written out, and the total count),
//! and once stage by stage (`View::frame` and [`extract_slice`], then
//! [`placement`] and [`finish_projection`]: the shift, the 2D inverse DHT
//! and the crop), to count each stage. The two images must agree bit for
//! bit, which checks that the stages are the whole of `render`.

use core::fmt;

use fvr_core::dht::{dht_2d, Twiddles};
use fvr_core::render::{aux_len, extract_slice, finish_projection, grid_len, placement, render};

use crate::scene::{FrameSpec, Shading, IMAGE_SIDE};
use crate::stored::StoredSpectrum;

/// A source of instruction counts (SysTick on the device; anything
/// monotonic on the host).
pub trait InstructionClock {
    /// Instructions retired so far.
    fn now(&self) -> u64;
}

/// Instruction counts of one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameCounts {
    /// `render` from view vectors to the finished image.
    pub render: u64,
    /// The camera frame and the slice extraction.
    pub extract: u64,
    /// Placement, sub-pixel shift, 2D inverse DHT and crop.
    pub inverse: u64,
    /// Of `inverse`, the 2D DHT alone (`fvr_core::dht::dht_2d`, timed again
    /// on the grid afterwards: its cost does not depend on the data).
    pub dht_2d: u64,
}

/// Elements of the slice grid a frame needs (`n²` for the scene's side).
pub const GRID_LEN: usize = grid_len(IMAGE_SIDE);
/// Elements of the auxiliary scratch.
pub const AUX_LEN: usize = aux_len(IMAGE_SIDE);
/// Pixels of an image.
pub const IMAGE_LEN: usize = IMAGE_SIDE * IMAGE_SIDE;

/// The buffers a frame renders into (in `.bss` on the device).
#[derive(Debug)]
pub struct FrameBuffers<'a> {
    /// Slice grid, [`GRID_LEN`].
    pub grid: &'a mut [f32],
    /// Auxiliary scratch, [`AUX_LEN`].
    pub aux: &'a mut [f32],
    /// The image from `render`, [`IMAGE_LEN`].
    pub image: &'a mut [f32],
    /// The image from the stages, [`IMAGE_LEN`].
    pub staged: &'a mut [f32],
}

/// Why a frame failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameError {
    /// The core refused (bad tables, buffers or view).
    Core(fvr_core::Error),
    /// The program holds no spectrum for the frame's filter.
    MissingSpectrum {
        /// The frame.
        frame: &'static str,
    },
    /// The staged render differs from `render` at this pixel.
    StagesDisagree {
        /// The frame.
        frame: &'static str,
        /// First differing pixel (row-major).
        pixel: usize,
    },
}

impl From<fvr_core::Error> for FrameError {
    fn from(e: fvr_core::Error) -> Self {
        FrameError::Core(e)
    }
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FrameError::Core(e) => write!(f, "core: {e}"),
            FrameError::MissingSpectrum { frame } => {
                write!(f, "frame {frame}: no stored spectrum for its filter")
            }
            FrameError::StagesDisagree { frame, pixel } => write!(
                f,
                "frame {frame}: the staged render differs from render() at pixel {pixel}"
            ),
        }
    }
}

/// The stored spectrum among `spectra` that `spec` renders from.
///
/// # Errors
/// [`FrameError::MissingSpectrum`].
pub fn spectrum_for(
    spec: &FrameSpec,
    spectra: &[&'static StoredSpectrum],
) -> Result<&'static StoredSpectrum, FrameError> {
    spectra
        .iter()
        .copied()
        .find(|s| s.filter_kind() == spec.filter)
        .ok_or(FrameError::MissingSpectrum { frame: spec.name })
}

/// Render `spec` from `stored` into `bufs.image` (a
/// [`IMAGE_SIDE`]² image), counting instructions with `clock`.
///
/// # Errors
/// [`FrameError`]: the core's errors, or stages that disagree with `render`.
pub fn render_frame<C: InstructionClock>(
    spec: &FrameSpec,
    stored: &StoredSpectrum,
    tw: &Twiddles<'_, f32>,
    bufs: &mut FrameBuffers<'_>,
    clock: &C,
) -> Result<FrameCounts, FrameError> {
    let spectrum = stored.spectrum()?;
    let kernel = stored.kernel_table()?;
    let (w, h) = (IMAGE_SIDE, IMAGE_SIDE);
    match spec.shading {
        Shading::Plain => {
            let t0 = clock.now();
            render(
                &spectrum, &kernel, &spec.view, w, h, tw, bufs.grid, bufs.aux, bufs.image,
            )?;
            let t1 = clock.now();
            let frame = spec.view.frame()?;
            let n = spectrum.n();
            extract_slice(&spectrum, &kernel, &frame, &mut bufs.grid[..n * n]);
            let t2 = clock.now();
            let place = placement(spectrum.dims(), &frame, w, h);
            finish_projection(
                &mut bufs.grid[..n * n],
                n,
                &place,
                1.0 / spectrum.scale(),
                w,
                h,
                tw,
                bufs.aux,
                bufs.staged,
            )?;
            let t3 = clock.now();
            if let Some(pixel) = bufs
                .image
                .iter()
                .zip(bufs.staged.iter())
                .position(|(a, b)| a.to_bits() != b.to_bits())
            {
                return Err(FrameError::StagesDisagree {
                    frame: spec.name,
                    pixel,
                });
            }
            let t4 = clock.now();
            dht_2d(&mut bufs.grid[..n * n], n, n, &mut bufs.aux[..n], tw)?;
            let t5 = clock.now();
            Ok(FrameCounts {
                render: t1 - t0,
                extract: t2 - t1,
                inverse: t3 - t2,
                dht_2d: t5 - t4,
            })
        }
    }
}
