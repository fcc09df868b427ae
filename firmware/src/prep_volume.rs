//! The volume the device-preparation programs read from flash: the scene's
//! phantom sampled to u8 voxels on a cube of side `side`.
//!
//! Shared, verbatim, by `build.rs` (which writes the voxels and fits the
//! filter on the host) and the library. It depends on [`crate::scene`]
//! (`build.rs` includes that file as a sibling module).

use super::scene::{density, SIDE};

/// The side of the device-prepared cube on the Cortex-M4F (512 KiB of RAM):
/// the largest power of two whose f16 spectrum fits with the view buffers
/// and the stack (`32³·2` = 64 KiB; `64³·2` = 512 KiB is all of the RAM).
pub const M4F_SIDE: usize = 32;

/// The side of the device-prepared cube on the Cortex-M7 with 1 MiB of RAM.
pub const M7_SIDE: usize = 64;

/// u8 per unit of phantom density: the densest voxel (about 1.2) lands
/// near 240, below the clamp.
pub const QUANT_GAIN: f64 = 200.0;

/// Voxel `(i, j, k)` of the `side³` u8 volume: the phantom at the centre of
/// the voxel's cell in the phantom's `SIDE³` frame, times [`QUANT_GAIN`],
/// rounded and clamped to `0 ..= 255`.
pub fn voxel_u8(side: usize, [i, j, k]: [usize; 3]) -> u8 {
    let cell = SIDE as f64 / side as f64;
    let at = |v: usize| (v as f64 + 0.5) * cell - 0.5;
    let d = density([at(i), at(j), at(k)]) * QUANT_GAIN;
    libm::round(d).clamp(0.0, 255.0) as u8
}
