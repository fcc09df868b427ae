//! The Cortex-M3's integer view: the scene's plain kb3 frame rendered by
//! `fvr_core::render::fixed::render_fixed` from the Q15 spectrum in flash
//! ([`crate::stored_q15`]), once whole and once stage by stage to count
//! instructions. Portable: the host runs the same code for the bit-for-bit
//! check (`tests/qemu_fixed.rs`).

use fvr_core::dht::fixed::FixedTwiddles;
use fvr_core::image::fixed::{finish_fixed, FixedBuffers, FixedSlice};
use fvr_core::image::placement;
use fvr_core::render::fixed::{render_fixed, scale_exponent, FixedSource};
use fvr_core::slice::fixed::{extract_slice_fixed, FixedPhases};

use crate::frame::InstructionClock;
use crate::scene::{IMAGE_SIDE, VIEW};
use crate::stored_q15::DENSITY_KB3_Q15;

/// Width of the scene's kb3 filter.
pub const WIDTH: usize = 3;
/// Elements of the slice grid and of the Q15 block.
pub const GRID_LEN: usize = IMAGE_SIDE * IMAGE_SIDE;
/// Elements of the auxiliary scratch.
pub const AUX_LEN: usize = fvr_core::image::fixed::fixed_aux_len(IMAGE_SIDE);

/// The buffers of the integer view (in `.bss` on the device): the core's
/// (the `i32` slice grid, the auxiliary scratch, the Q15 slice block and
/// the image of `render_fixed`), and the image of the staged render.
#[derive(Debug)]
pub struct ViewBuffers<'a> {
    /// The buffers `render_fixed` and `finish_fixed` take.
    pub view: FixedBuffers<'a>,
    /// The image of the staged render.
    pub staged: &'a mut [i16],
}

/// Instruction counts of the integer view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewCounts {
    /// `render_fixed`, from the view vectors to the image.
    pub render: u64,
    /// The per-view set-up in soft float: camera frame, slice axes,
    /// placement, the scale's exponent.
    pub setup: u64,
    /// `extract_slice_fixed` (with its six roundings of the axes to fixed
    /// point).
    pub extract: u64,
    /// `finish_fixed`: to Q15, inverse 2D DHT and crop.
    pub finish: u64,
}

/// Why the integer view failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewError {
    /// The core refused.
    Core(fvr_core::Error),
    /// The staged render's image or exponent differs from `render_fixed`'s.
    StagedDiffers,
}

impl From<fvr_core::Error> for ViewError {
    fn from(e: fvr_core::Error) -> Self {
        ViewError::Core(e)
    }
}

/// Render the plain kb3 frame in integers into `bufs.view.out` and,
/// staged, into `bufs.staged`; returns the image's exponent (pixel `i` is
/// `image[i]·2^e`) and the counts.
///
/// # Errors
/// The core's, or a staged image that differs.
pub fn render_view<C: InstructionClock>(
    phases: &FixedPhases<WIDTH>,
    tw: &FixedTwiddles<'_, i16>,
    ViewBuffers { mut view, staged }: ViewBuffers<'_>,
    clock: &C,
) -> Result<(i32, ViewCounts), ViewError> {
    let spectrum = DENSITY_KB3_Q15.spectrum()?;
    let source = FixedSource {
        spectrum: &spectrum,
        phases,
        twiddles: tw,
    };
    let size = (IMAGE_SIDE, IMAGE_SIDE);
    let t0 = clock.now();
    let exponent = render_fixed(&source, &VIEW, size, view.reborrow())?;
    let t1 = clock.now();
    let frame = VIEW.frame()?;
    let axes = frame.slice_axes();
    let place = placement(spectrum.dims(), &frame, IMAGE_SIDE, IMAGE_SIDE);
    let scale = scale_exponent(spectrum.scale())?;
    let t2 = clock.now();
    let grid_exponent = extract_slice_fixed(&spectrum, phases, &axes, &mut *view.grid)?;
    let t3 = clock.now();
    let slice = FixedSlice {
        exponent: grid_exponent,
        m: spectrum.n(),
        place,
        size,
        tw,
    };
    let staged_exponent = finish_fixed(
        FixedBuffers {
            out: &mut *staged,
            ..view.reborrow()
        },
        &slice,
    )? - scale;
    let t4 = clock.now();
    if staged_exponent != exponent || *staged != *view.out {
        return Err(ViewError::StagedDiffers);
    }
    Ok((
        exponent,
        ViewCounts {
            render: t1 - t0,
            setup: t2 - t1,
            extract: t3 - t2,
            finish: t4 - t3,
        },
    ))
}
