//! Interpolation filters for slice extraction and their spatial responses.
//!
//! A filter is a separable kernel `k(t)` in spectrum index units, normalized
//! to `k(0) = 1`, with support `|t| < W/2` for width `W`. Its spatial
//! response is `ĥ(ν) = ∫ k(t) e^{−i2πνt} dt` at `ν = x/N` cycles per voxel;
//! the volume is premultiplied by `1/ĥ(x/N)` per axis (paper §2, fig. 2),
//! so that the slice's interpolation returns the unattenuated spectrum.
//!
//! Kernels are read from a table ([`KernelTable`]) during extraction, so no
//! transcendental function runs per tap.

mod kernel;
mod special;
mod table;

pub use kernel::{EnergyProfile, Filter, FilterKind, MAX_WIDTH};
pub use special::{bessel_i0, bessel_i1_over_x};
pub use table::{DerivativeTable, KernelTable, PhaseTable, TABLE_RESOLUTION};

pub(crate) use special::gauss_legendre_16;
pub(crate) use table::{fill_rows, phase_entry};
