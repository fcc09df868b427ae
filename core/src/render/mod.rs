//! Rendering a view: the one entry point, [`render`].
//!
//! By the projection-slice theorem (paper §1, fig. 1), the 2D Hartley
//! transform of the projection along `d` equals the 3D spectrum on the plane
//! through the origin spanned by `r` and `u`: a view is a slice
//! ([`crate::slice`]) finished into an image ([`crate::image`]). A
//! [`Scene`] (depth cues, shading) computes its slices in
//! [`crate::shading`] and is finished the same way, one channel at a time.
//!
//! # Progressive previews (the paper's conclusion)
//! Level `L` renders a `(W/2^L) × (H/2^L)` image at a pitch of `2^L`
//! voxels. Its slice is the central `m × m` block of the full slice,
//! `m = n/2^L`, so extraction reads `4^L` times fewer points and the 2D
//! inverse transform is `m × m`. The image is the full-resolution
//! projection low-passed to `|k| < m/2` and sampled every `2^L` voxels:
//! `P_L(x) = (1/n²)·Σ_{|k|<m/2} S(k)·cas(2πk·x/m)`, which is the `m`-point
//! inverse transform scaled by `(m/n)² = 4^−L`.
//!
//! # Physical units
//! With [`Sampling`] (voxel spacing `Δ`, pixel size `p`, in mm) the slice
//! is spanned by [`Sampling::slice_axes`] and the image is multiplied by
//! `Δx·Δy·Δz/(2^L·p)²` (level `L` samples the same plane `2^L` times more
//! coarsely in frequency, and `m = n/2^L` makes `n/(m·2^L·p) = 1/p`).
//! [`Sampling::UNIT`] gives the voxel-unit image bit for bit.

pub mod fixed;
mod scene;

use crate::dht::Twiddles;
use crate::error::{require_len, Error, Result};
use crate::filter::{DerivativeTable, KernelTable};
use crate::geometry::{Sampling, View};
use crate::image::{
    aux_len, check_image, finish_in_grid, finish_with, grid_len, placement_on_axes, Crop, Inverse,
};
use crate::num::{Real, Sample};
use crate::shading::Scene;
use crate::slice::extract_central_slice_on;
use crate::spectrum::{CubeSide, Spectrum};
use scene::render_scene;

/// What a view is rendered from: the spectra and the tables that read and
/// transform them.
#[derive(Clone, Copy, Debug)]
pub struct Source<'a, S, Z, T> {
    /// The density spectrum.
    pub spectrum: &'a Spectrum<'a, S, Z>,
    /// The `|∇f|` spectrum ([`crate::shading::gradient`]), required iff the
    /// scene [`Scene::needs_gradient_spectrum`], with the same side, filter
    /// and volume dims as `spectrum`.
    pub gradient: Option<&'a Spectrum<'a, S, Z>>,
    /// The kernel table of the spectrum's filter.
    pub kernel: &'a KernelTable<T>,
    /// The kernel's derivative, required iff the scene
    /// [`Scene::needs_kernel_derivative`].
    pub derivative: Option<&'a DerivativeTable<T>>,
    /// Twiddles serving the slice's side.
    pub twiddles: &'a Twiddles<'a, T>,
}

impl<'a, S, Z, T> Source<'a, S, Z, T> {
    /// A plain source: one spectrum, its kernel and twiddles.
    pub fn new(
        spectrum: &'a Spectrum<'a, S, Z>,
        kernel: &'a KernelTable<T>,
        twiddles: &'a Twiddles<'a, T>,
    ) -> Self {
        Self {
            spectrum,
            gradient: None,
            kernel,
            derivative: None,
            twiddles,
        }
    }
}

/// What to render: the view, the image's size and units, the preview level
/// and an optional scene.
#[derive(Clone, Copy, Debug)]
pub struct Request<'a> {
    /// Where the camera looks from.
    pub view: View,
    /// Voxel spacing and pixel size ([`Sampling::UNIT`]: voxel units).
    pub sampling: Sampling,
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Progressive level ([`max_level`]): 0 for the full image.
    pub level: u32,
    /// Depth cues and lights; `None` for the X-ray projection. Scenes are
    /// rendered at level 0 in voxel units.
    pub scene: Option<&'a Scene>,
}

impl Request<'_> {
    /// The full `width × height` X-ray projection along `view`, in voxel
    /// units.
    pub fn new(view: View, width: usize, height: usize) -> Self {
        Self {
            view,
            sampling: Sampling::UNIT,
            width,
            height,
            level: 0,
            scene: None,
        }
    }
}

/// The caller's buffers a view renders into.
#[derive(Debug)]
pub struct Buffers<'a, T> {
    /// Slice grids: [`grid_len`]`(n >> level)` for a projection,
    /// [`crate::shading::fields_len`] for a
    /// scene.
    pub grid: &'a mut [T],
    /// Auxiliary scratch, [`aux_len`] of the slice's side.
    pub aux: &'a mut [T],
    /// The image, `channels·width·height` (channel fastest).
    pub out: &'a mut [T],
}

impl<'a, T> Buffers<'a, T> {
    /// The slice grid(s), the auxiliary scratch and the image.
    pub fn new(grid: &'a mut [T], aux: &'a mut [T], out: &'a mut [T]) -> Self {
        Self { grid, aux, out }
    }

    /// The same buffers, borrowed again for one call of a function that
    /// takes them by value.
    pub fn reborrow(&mut self) -> Buffers<'_, T> {
        Buffers {
            grid: self.grid,
            aux: self.aux,
            out: self.out,
        }
    }
}

/// Deepest level: the preview grid keeps at least 2 samples a side.
pub fn max_level(n: usize) -> u32 {
    n.max(2).trailing_zeros().saturating_sub(1)
}

/// The preview size of a `width × height` image at `level` (each side
/// divided by `2^level`, at least 1).
pub fn preview_size(width: usize, height: usize, level: u32) -> (usize, usize) {
    let shrink = |v: usize| (v >> level.min(usize::BITS - 1)).max(1);
    (shrink(width), shrink(height))
}

/// Render `request` from `source` into `buffers.out`: a
/// `width × height` image, row 0 at the top, of one channel (the X-ray
/// projection, `∫ f dt` in voxel units of the input volume, or in mm ×
/// volume units with a [`Sampling`]) or of [`Scene::channels`] interleaved
/// channels. Returns the number of channels written.
///
/// # Errors
/// Bad view vectors, an image side of 0 or above the slice's side, a level
/// beyond [`max_level`], short buffers, twiddles too short, a kernel for
/// another filter than the spectrum was premultiplied for; for a scene also
/// invalid scene values ([`Scene::validate`]), a missing or mismatched
/// gradient spectrum or derivative table, and a level or sampling other
/// than the default.
pub fn render<S: Sample, Z: CubeSide, T: Real>(
    source: &Source<'_, S, Z, T>,
    request: &Request<'_>,
    buffers: Buffers<'_, T>,
) -> Result<usize> {
    match request.scene {
        Some(scene) => {
            if request.level != 0 {
                return Err(Error::SceneUnsupported {
                    what: "a progressive level",
                });
            }
            if request.sampling != Sampling::UNIT {
                return Err(Error::SceneUnsupported {
                    what: "physical units",
                });
            }
            if !source.spectrum.n().is_power_of_two() {
                return Err(Error::SceneUnsupported {
                    what: "a cube side that is not a power of two (mixed-radix grid)",
                });
            }
            render_scene(source, scene, request, buffers)
        }
        None => render_projection(
            source.spectrum,
            source.kernel,
            Inverse::Radix2(source.twiddles),
            request,
            buffers.grid,
            buffers.aux,
            Output::Image(buffers.out),
        )
        .map(|()| 1),
    }
}

/// The X-ray projection of `request` (whose scene must be `None`) from
/// `source`, cut into the slice grid itself: afterwards
/// `grid[..width·height]` holds the image, bit for bit the one [`render`]
/// writes to its own buffer. A device saves the image buffer (16 KiB for a
/// 64² f32 view).
///
/// # Errors
/// As [`render`]; a scene ([`Error::SceneUnsupported`]).
pub fn render_in_grid<S: Sample, Z: CubeSide, T: Real>(
    source: &Source<'_, S, Z, T>,
    request: &Request<'_>,
    grid: &mut [T],
    aux: &mut [T],
) -> Result<()> {
    if request.scene.is_some() {
        return Err(Error::SceneUnsupported {
            what: "an image cut into its slice grid (one channel only)",
        });
    }
    render_projection(
        source.spectrum,
        source.kernel,
        Inverse::Radix2(source.twiddles),
        request,
        grid,
        aux,
        Output::InGrid,
    )
}

/// The X-ray projection of `request` (whose scene must be `None`) from
/// `spectrum` with the 2D inverse transform `inverse`: as [`render`], and
/// the way to render a spectrum of mixed-radix side ([`Inverse::Mixed`],
/// a plan for the slice's side `n >> level`).
///
/// # Errors
/// As [`render`]; a scene ([`Error::SceneUnsupported`]); a transform for
/// another side.
pub fn render_projection_with<S: Sample, Z: CubeSide, T: Real>(
    spectrum: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    inverse: Inverse<'_, T>,
    request: &Request<'_>,
    buffers: Buffers<'_, T>,
) -> Result<()> {
    if request.scene.is_some() {
        return Err(Error::SceneUnsupported {
            what: "a given 2D inverse transform (scenes take Source, and no mixed-radix grid)",
        });
    }
    let Buffers { grid, aux, out } = buffers;
    render_projection(
        spectrum,
        kernel,
        inverse,
        request,
        grid,
        aux,
        Output::Image(out),
    )
}

/// Where a projection's image goes.
enum Output<'a, T> {
    /// A buffer of its own.
    Image(&'a mut [T]),
    /// The front of the slice grid ([`finish_in_grid`]).
    InGrid,
}

/// The X-ray projection at `request.level`.
fn render_projection<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    inverse: Inverse<'_, T>,
    request: &Request<'_>,
    grid: &mut [T],
    aux: &mut [T],
    out: Output<'_, T>,
) -> Result<()> {
    let Request {
        view,
        sampling,
        width,
        height,
        level,
        ..
    } = *request;
    let n = spec.n();
    if level > max_level(n) {
        return Err(Error::TooMany {
            what: "progressive levels (the preview grid needs 2 samples a side)",
            given: level as usize,
            capacity: max_level(n) as usize,
        });
    }
    let axes = sampling.slice_axes(&view.frame()?);
    let m = n >> level;
    check_image(width, height, m)?;
    if kernel.filter() != spec.filter() {
        return Err(Error::FilterMismatch);
    }
    require_len("slice grid", grid_len(m), grid.len())?;
    require_len("auxiliary scratch", aux_len(m), aux.len())?;
    if let Output::Image(out) = &out {
        require_len("output image", width * height, out.len())?;
    }
    // Checked before the extraction, which is the bulk of the work.
    inverse.check(m)?;
    let pitch = (1u64 << level) as f64;
    extract_central_slice_on(spec, kernel, &axes, m, grid);
    let crop = Crop::new(
        placement_on_axes(spec.dims(), &axes, width, height, pitch),
        sampling.gain() / (spec.scale() * pitch * pitch),
        width,
        height,
    );
    match out {
        Output::Image(out) => finish_with(&mut grid[..m * m], m, &crop, inverse, aux, out),
        Output::InGrid => finish_in_grid(&mut grid[..m * m], m, &crop, inverse, aux),
    }
}
