//! The stored 3D Hartley spectrum and its one-time preparation.
//!
//! # Layout
//! A cube of side `n` (a power of two, or on the host an even
//! `2^a·3^b·5^c`: [`crate::volume::GridOversampling`]), `x` fastest. Index `k` on an axis
//! holds the signed frequency `k` for `k < n/2` and `k − n` above (DC at
//! index 0). The spatial origin of the transform is the volume's centre: the
//! volume is stored circularly shifted so that voxel `⌊n_a/2⌋` lands at index
//! 0 on each axis. The fractional rest of the centre `c = n_a/2` (½ on odd
//! axes) is applied per view as an exact sub-pixel shift.
//!
//! # Scaling rule
//! Stored values are `s·H` with `s = 2^e` chosen so that `s·Σ|g|` lies in
//! `(2^(t−1), 2^t]`, where `g` is the premultiplied volume and `t` is the
//! format's [`crate::num::Sample::SCALE_LOG2`] (`t = 14` for f16, as below; formats of
//! narrower range use a smaller `t`, so that `2^(t+1)` fits them). During the
//! transform every stored value is bounded by `2·Σ|g|` (x pass: `√2` times a
//! line sum; y pass: 2 times a plane sum; final: `√2·Σ|g|`, since
//! `|cas| ≤ √2`), so nothing exceeds `2^15 < 65504`, the f16 maximum, and the
//! largest coefficients sit within a factor 4 of it, keeping small ones as
//! far from underflow as the format allows. `s` is a power of two, so scaling
//! is exact. Renderers divide by `s` at the end.

mod prepare;
mod prepare_fixed;
mod stored;

pub use prepare::{
    check_scale, premultiplier_table, prepare_scratch_len, scale_for, scale_for_target,
    LineBlockStorage,
};
pub use prepare_fixed::Q15Storage;
pub use stored::{CubeSide, Side, Spectrum};
