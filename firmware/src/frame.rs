//! Rendering one [`FrameSpec`] on the device, with instruction counts.
//!
//! A plain frame is rendered twice from the same tables: once by
//! `fvr_core::render::render` (the image written out, and the total count),
//! and once stage by stage (`View::frame` and [`extract_slice`], then
//! [`placement`] and [`finish`]: the shift, the 2D inverse DHT
//! and the crop), to count each stage. The two images must agree bit for
//! bit, which checks that the stages are the whole of `render`.
//!
//! A depth-cued or shaded frame is rendered once, by
//! `fvr_core::render::render` with a scene, whose stages are not public. Its
//! inverse (one [`finish`] per channel) is timed again afterwards on
//! the scratch it left: that cost depends on the geometry only, not on the
//! data (the plain frame checks this, [`Split::Staged::inverse_again`]), and
//! extraction with the per-channel combination is the rest.

use core::fmt;

use fvr_core::dht::{dht_2d, Twiddles};
use fvr_core::filter::FilterKind;
use fvr_core::image::{aux_len, finish, grid_len, placement, Crop};
use fvr_core::render::{render, Buffers, Request, Source};
use fvr_core::slice::extract_slice;

use crate::scene::{FrameSpec, Shading, StoredKind, IMAGE_SIDE, SIDE};
use crate::stored::{StoredDerivative, StoredSpectrum};

/// A source of instruction counts (SysTick on the device; anything
/// monotonic on the host).
pub trait InstructionClock {
    /// Instructions retired so far.
    fn now(&self) -> u64;
}

/// How a frame's count was split into extraction and inverse.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// Both stages timed in a second, staged render whose image equals
    /// `render`'s bit for bit (plain frames).
    Staged {
        /// The inverse timed once more, on the grid as the staged inverse
        /// left it (other data). Equal to the inverse within the clock's
        /// ±40 shows that the inverse's cost does not depend on the data,
        /// which [`Split::Retimed`] relies on.
        inverse_again: u64,
    },
    /// The inverse (`channels` × [`finish`]) timed again after
    /// `render_scene`; extraction (with the per-channel combination of the
    /// accumulated spectra) is `render − inverse`.
    Retimed {
        /// Channels inverse-transformed.
        channels: usize,
    },
}

/// Instruction counts of one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameCounts {
    /// `render` (or `render_scene`) from view vectors to the finished image.
    pub render: u64,
    /// The camera frame and the slice extraction (see [`Split`]).
    pub extract: u64,
    /// Placement, sub-pixel shift, 2D inverse DHT and crop, for every
    /// channel.
    pub inverse: u64,
    /// Of `inverse`, one 2D DHT alone (`fvr_core::dht::dht_2d`, timed again
    /// on the grid afterwards: its cost does not depend on the data).
    pub dht_2d: u64,
    /// How `extract` and `inverse` were obtained.
    pub split: Split,
}

/// A rendered frame: the image is the first `channels·IMAGE_LEN` elements
/// of the image of [`FrameBuffers::render`], channel fastest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rendered {
    /// Channels of the image (1 grey, 3 RGB).
    pub channels: usize,
    /// Instruction counts.
    pub counts: FrameCounts,
}

/// Elements of one slice grid (`n²` for the scene's side).
pub const GRID_LEN: usize = grid_len(IMAGE_SIDE);
/// Elements of the auxiliary scratch.
pub const AUX_LEN: usize = aux_len(IMAGE_SIDE);
/// Pixels of an image.
pub const IMAGE_LEN: usize = IMAGE_SIDE * IMAGE_SIDE;

/// The buffers a frame renders into (in `.bss` on the device), sized for a
/// program's frames by [`crate::scene::buffer_sizes`].
#[derive(Debug)]
pub struct FrameBuffers<'a> {
    /// The buffers [`render`] writes: its scratch grids (the slice grid of
    /// a plain frame, [`GRID_LEN`]; the fields of `render_scene`,
    /// `fields_len(scene, n)`), the auxiliary scratch ([`AUX_LEN`]) and
    /// the image (`channels·`[`IMAGE_LEN`]).
    pub render: Buffers<'a, f32>,
    /// The image of the staged render, or of the re-timed inverse (as
    /// long as the image).
    pub staged: &'a mut [f32],
}

/// Why a frame failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameError {
    /// The core refused (bad tables, buffers, view or scene).
    Core(fvr_core::Error),
    /// The program holds no spectrum of this kind for the frame.
    MissingSpectrum {
        /// The frame.
        frame: &'static str,
        /// The spectrum it needs.
        kind: StoredKind,
    },
    /// The program holds no kernel-derivative table for the frame's filter
    /// (a linear depth cue needs one).
    MissingDerivative {
        /// The frame.
        frame: &'static str,
        /// Its filter.
        filter: FilterKind,
    },
    /// The program links a table none of its frames reads (it would take
    /// flash for nothing, and the flash budget of `build.rs`, which counts
    /// what the frames need, would not see it).
    UnusedTable {
        /// The spectrum, or `None` for a kernel-derivative table.
        kind: Option<StoredKind>,
        /// Its filter.
        filter: FilterKind,
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
            FrameError::MissingSpectrum { frame, kind } => write!(
                f,
                "frame {frame}: no stored {} spectrum for {}",
                kind.prefix(),
                kind.filter().name()
            ),
            FrameError::MissingDerivative { frame, filter } => write!(
                f,
                "frame {frame}: no stored kernel-derivative table for {} (its linear depth cue needs one)",
                filter.name()
            ),
            FrameError::UnusedTable {
                kind: Some(kind),
                ..
            } => write!(
                f,
                "the {} spectrum for {} is linked but no frame reads it",
                kind.prefix(),
                kind.filter().name()
            ),
            FrameError::UnusedTable { kind: None, filter } => write!(
                f,
                "the kernel-derivative table for {} is linked but no frame reads it",
                filter.name()
            ),
            FrameError::StagesDisagree { frame, pixel } => write!(
                f,
                "frame {frame}: the staged render differs from render() at pixel {pixel}"
            ),
        }
    }
}

/// The flash tables one frame reads.
#[derive(Clone, Copy, Debug)]
pub struct FrameTables {
    /// The density spectrum (with its kernel table).
    pub density: &'static StoredSpectrum,
    /// The `|∇f|` spectrum, for a frame with a light.
    pub gradient: Option<&'static StoredSpectrum>,
    /// The kernel-derivative table, for a frame with a linear depth cue.
    pub derivative: Option<&'static StoredDerivative>,
}

/// The tables among `spectra` and `derivatives` that `spec` renders from:
/// exactly those it needs.
///
/// # Errors
/// [`FrameError::MissingSpectrum`], [`FrameError::MissingDerivative`].
pub fn tables_for(
    spec: &FrameSpec,
    spectra: &[&'static StoredSpectrum],
    derivatives: &[&'static StoredDerivative],
) -> Result<FrameTables, FrameError> {
    let find = |kind: StoredKind| {
        spectra
            .iter()
            .copied()
            .find(|s| s.kind == kind)
            .ok_or(FrameError::MissingSpectrum {
                frame: spec.name,
                kind,
            })
    };
    let (density, gradient) = spec.spectra();
    let derivative = if spec.shading.needs_kernel_derivative() {
        Some(
            derivatives
                .iter()
                .copied()
                .find(|d| d.kind == spec.filter)
                .ok_or(FrameError::MissingDerivative {
                    frame: spec.name,
                    filter: spec.filter,
                })?,
        )
    } else {
        None
    };
    Ok(FrameTables {
        density: find(density)?,
        gradient: gradient.map(find).transpose()?,
        derivative,
    })
}

/// Check that a program links exactly what its frames read: every frame
/// finds its tables ([`tables_for`]) and every linked table is read by some
/// frame.
///
/// # Errors
/// The first missing table ([`FrameError::MissingSpectrum`],
/// [`FrameError::MissingDerivative`]) or unused one
/// ([`FrameError::UnusedTable`]).
pub fn check_linked_tables(
    frames: &[FrameSpec],
    spectra: &[&'static StoredSpectrum],
    derivatives: &[&'static StoredDerivative],
) -> Result<(), FrameError> {
    for spec in frames {
        tables_for(spec, spectra, derivatives)?;
    }
    for s in spectra {
        let read = frames.iter().any(|f| {
            let (density, gradient) = f.spectra();
            density == s.kind || gradient == Some(s.kind)
        });
        if !read {
            return Err(FrameError::UnusedTable {
                kind: Some(s.kind),
                filter: s.filter_kind(),
            });
        }
    }
    for d in derivatives {
        let read = frames
            .iter()
            .any(|f| f.filter == d.kind && f.shading.needs_kernel_derivative());
        if !read {
            return Err(FrameError::UnusedTable {
                kind: None,
                filter: d.kind,
            });
        }
    }
    Ok(())
}

/// Render `spec` from `tables` into `bufs.image` (an [`IMAGE_SIDE`]²
/// image of 1 or 3 channels), counting instructions with `clock`.
///
/// # Errors
/// [`FrameError`]: the core's errors (short buffers among them), or stages
/// that disagree with `render`.
pub fn render_frame<C: InstructionClock>(
    spec: &FrameSpec,
    tables: &FrameTables,
    tw: &Twiddles<'_, f32>,
    bufs: &mut FrameBuffers<'_>,
    clock: &C,
) -> Result<Rendered, FrameError> {
    match spec.shading {
        Shading::Plain => render_plain(spec, tables.density, tw, bufs, clock),
        Shading::Scene(scene) => render_cued_or_shaded(spec, &scene, tables, tw, bufs, clock),
    }
}

// The two kinds of frame are separate, never inlined functions so that the
// stack holds the kernel tables (12 KiB each, copied from flash) of one
// kind at a time.
#[inline(never)]
fn render_plain<C: InstructionClock>(
    spec: &FrameSpec,
    density: &StoredSpectrum,
    tw: &Twiddles<'_, f32>,
    bufs: &mut FrameBuffers<'_>,
    clock: &C,
) -> Result<Rendered, FrameError> {
    let spectrum = density.spectrum()?;
    // Borrowed from the Result rather than moved out with `?`: each move of
    // a 12 KiB table can cost another 12 KiB of stack.
    let kernel = density.kernel_table();
    let kernel = kernel.as_ref().map_err(|e| *e)?;
    let (w, h) = (IMAGE_SIDE, IMAGE_SIDE);
    let n = spectrum.n();
    let t0 = clock.now();
    render(
        &Source::new(&spectrum, kernel, tw),
        &Request::new(spec.view, w, h),
        bufs.render.reborrow(),
    )?;
    let t1 = clock.now();
    let frame = spec.view.frame()?;
    extract_slice(&spectrum, kernel, &frame, &mut bufs.render.grid[..n * n]);
    let t2 = clock.now();
    let place = placement(spectrum.dims(), &frame, w, h);
    finish(
        &mut bufs.render.grid[..n * n],
        n,
        &Crop::new(place, 1.0 / spectrum.scale(), w, h),
        tw,
        bufs.render.aux,
        bufs.staged,
    )?;
    let t3 = clock.now();
    if let Some(pixel) = bufs.render.out[..w * h]
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
    inverse_again(&spectrum, &frame, 1, tw, bufs)?;
    let t5 = clock.now();
    dht_2d(
        &mut bufs.render.grid[..n * n],
        n,
        n,
        &mut bufs.render.aux[..n],
        tw,
    )?;
    let t6 = clock.now();
    Ok(Rendered {
        channels: 1,
        counts: FrameCounts {
            render: t1 - t0,
            extract: t2 - t1,
            inverse: t3 - t2,
            dht_2d: t6 - t5,
            split: Split::Staged {
                inverse_again: t5 - t4,
            },
        },
    })
}

#[inline(never)]
fn render_cued_or_shaded<C: InstructionClock>(
    spec: &FrameSpec,
    scene: &crate::scene::SceneSpec,
    tables: &FrameTables,
    tw: &Twiddles<'_, f32>,
    bufs: &mut FrameBuffers<'_>,
    clock: &C,
) -> Result<Rendered, FrameError> {
    let scene = scene.scene()?;
    let spectrum = tables.density.spectrum()?;
    let kernel = tables.density.kernel_table();
    let kernel = kernel.as_ref().map_err(|e| *e)?;
    let gradient = match tables.gradient {
        Some(g) => Some(g.spectrum()?),
        None => None,
    };
    let derivative = tables.derivative.map(|d| d.table());
    let derivative = match &derivative {
        Some(Ok(d)) => Some(d),
        Some(Err(e)) => return Err((*e).into()),
        None => None,
    };
    let t0 = clock.now();
    let channels = render(
        &Source {
            spectrum: &spectrum,
            gradient: gradient.as_ref(),
            kernel,
            derivative,
            twiddles: tw,
        },
        &Request {
            scene: Some(&scene),
            ..Request::new(spec.view, IMAGE_SIDE, IMAGE_SIDE)
        },
        bufs.render.reborrow(),
    )?;
    let t1 = clock.now();
    let frame = spec.view.frame()?;
    let t2 = clock.now();
    inverse_again(&spectrum, &frame, channels, tw, bufs)?;
    let t3 = clock.now();
    let n = spectrum.n();
    dht_2d(
        &mut bufs.render.grid[..n * n],
        n,
        n,
        &mut bufs.render.aux[..n],
        tw,
    )?;
    let t4 = clock.now();
    let render = t1 - t0;
    let inverse = t3 - t2;
    Ok(Rendered {
        channels,
        counts: FrameCounts {
            render,
            extract: render.saturating_sub(inverse),
            inverse,
            dht_2d: t4 - t3,
            split: Split::Retimed { channels },
        },
    })
}

/// The inverse of a frame of `channels` again, on whatever the first
/// scratch grid holds, into `bufs.staged`: the placement, then one
/// [`finish`] (shift, 2D inverse DHT, crop) per channel, as
/// `render` and `render_scene` do it.
fn inverse_again(
    spectrum: &fvr_core::spectrum::Spectrum<'_, fvr_core::f16, fvr_core::spectrum::Side<SIDE>>,
    frame: &fvr_core::geometry::Frame,
    channels: usize,
    tw: &Twiddles<'_, f32>,
    bufs: &mut FrameBuffers<'_>,
) -> Result<(), FrameError> {
    let (w, h) = (IMAGE_SIDE, IMAGE_SIDE);
    let n = spectrum.n();
    let place = placement(spectrum.dims(), frame, w, h);
    let gain = 1.0 / spectrum.scale();
    for c in 0..channels {
        finish(
            &mut bufs.render.grid[..n * n],
            n,
            &Crop {
                channels,
                channel: c,
                ..Crop::new(place, gain, w, h)
            },
            tw,
            bufs.render.aux,
            bufs.staged,
        )?;
    }
    Ok(())
}
