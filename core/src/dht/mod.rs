//! In-place discrete Hartley transforms: radix 2, and mixed radix for
//! lengths `2^a·3^b·5^c` ([`mixed`]).
//!
//! # Normalization and order
//! The forward transform of a length-`N` sequence is
//! `H(k) = Σ_x f(x) cas(2πkx/N)`, with `cas θ = cos θ + sin θ`, unnormalized.
//! The DHT is its own inverse up to `1/N`: [`idht`] divides by `N`.
//! Output is in natural order, `H(0)` (DC) first; index `k ≥ N/2` holds the
//! signed frequency `k − N`.
//!
//! The 2D and 3D transforms are the *true* multidimensional DHT with kernel
//! `cas(2π(k·x)/N)` (not the separable `cas·cas` product): row-column passes
//! followed by the Hao–Bracewell correction.
//!
//! # Precision
//! Each radix-2 stage adds at most a few units of roundoff, so the relative
//! RMS error of a length-`N` transform grows like `ε·log₂N` (ε the unit
//! roundoff of the arithmetic type); the tests check this bound against a
//! naive O(N²) transform evaluated in f64.

mod cube;
pub mod fixed;
mod line;
pub mod mixed;
mod plane;
mod sparse;
mod store;
mod twiddles;

pub use cube::{dht_3d, dht_3d_rounding, dht_3d_scratch_len, dht_3d_store, Rounding};
pub use line::{dht, idht};
pub use mixed::{
    dht_2d_mixed, dht_2d_mixed_scratch_len, dht_3d_mixed, dht_3d_mixed_scratch_len,
    dht_3d_mixed_store, dht_mixed, fast_len, idht_mixed, is_fast_len, mixed_scratch_len,
    mixed_table_len, MixedPlan,
};
pub use plane::{dht_2d, dht_2d_lines, idht_2d};
pub use sparse::dht_2d_sparse_len;
pub use store::{Elements, LineBlocks, LineStore, Pass};
pub use twiddles::Twiddles;

/// Index of `−k` modulo `n` (a power of two).
#[inline(always)]
pub(crate) fn neg_mod(k: usize, n: usize) -> usize {
    (n - k) & (n - 1)
}

/// Signed frequency of index `k` on an axis of length `m`.
#[inline(always)]
pub fn signed_index(k: usize, m: usize) -> i64 {
    if 2 * k < m {
        k as i64
    } else {
        k as i64 - m as i64
    }
}
