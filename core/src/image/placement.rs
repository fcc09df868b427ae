//! Where a `W × H` image sits on the projection grid: the whole-pixel
//! offset of its corner and the sub-pixel shift.

use crate::geometry::{dot, Frame, SliceAxes};

/// Where a `W × H` image sits on the `m × m` projection grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Grid column (signed, modulo `m`) of image column 0.
    pub col0: i64,
    /// Grid row coordinate (signed, up positive) of image row 0.
    pub row0: i64,
    /// Sub-pixel shift `(ta, tb)` in `[0, 1)`, along `r` and `u`.
    pub shift: [f64; 2],
}

/// The placement of a `width × height` image of a volume of `dims` seen in
/// `frame`: image pixel `(col, row)` is the projection at grid offset
/// `(col0 + col + ta, row0 − row + tb)` from the transform origin.
///
/// The transform origin is voxel `⌊n_a/2⌋`, the centre is `n_a/2`; their
/// difference `δ` (0 or ½ per axis) projects to `(δ·r, δ·u)` on the image.
pub fn placement(dims: [usize; 3], frame: &Frame, width: usize, height: usize) -> Placement {
    placement_at_pitch(dims, frame, width, height, 1.0)
}

/// [`placement`] for pixels `pitch` voxels apart (progressive previews):
/// pixel `(col, row)` sits at `c + (col − W/2)·pitch·r + (H/2 − row)·pitch·u`.
pub fn placement_at_pitch(
    dims: [usize; 3],
    frame: &Frame,
    width: usize,
    height: usize,
    pitch: f64,
) -> Placement {
    placement_on_axes(dims, &frame.slice_axes(), width, height, pitch)
}

/// [`placement_at_pitch`] for slice axes `axes` (index units per pixel):
/// with [`crate::geometry::Sampling::slice_axes`], `δ·r' = Σ δ_a·Δ_a·r_a/p` is the physical
/// offset `δ∘Δ` of the transform origin from the centre, in pixels of `p`
/// mm, as the physical contract needs.
pub fn placement_on_axes(
    dims: [usize; 3],
    axes: &SliceAxes,
    width: usize,
    height: usize,
    pitch: f64,
) -> Placement {
    let delta = dims.map(|d| (d % 2) as f64 * 0.5);
    let a0 = -(width as f64) / 2.0 + dot(delta, axes.right) / pitch;
    let b0 = height as f64 / 2.0 + dot(delta, axes.up) / pitch;
    let (col0, row0) = (libm::floor(a0), libm::floor(b0));
    Placement {
        col0: col0 as i64,
        row0: row0 as i64,
        shift: [a0 - col0, b0 - row0],
    }
}
