//! Mixed-radix discrete Hartley transforms for any length
//! `N = 2^a·3^b·5^c`, in 1D, 2D and 3D, in place on caller buffers.
//!
//! # Normalization and order
//! As the radix-2 transforms (see [`crate::dht`]): forward
//! `H(k) = Σ_x f(x) cas(2πkx/N)` unnormalized, [`idht_mixed`] divides by
//! `N`, natural order in and out. The 2D and 3D transforms are the true
//! multidimensional DHT, `cas(2π Σ_i k_i x_i / N_i)` with one length per
//! axis.
//!
//! # Algorithm
//! A DHT of even `N` is a complex FFT of `N/2` on the samples packed as
//! `f(2x) + i·f(2x+1)` (the data buffer itself, read as complex values),
//! then an O(N) pass that splits the even and odd spectra and forms
//! `H(k) = Re X(k) − Im X(k)` (`X` the DFT with kernel `e^{−2πikx/N}`). Odd
//! `N` takes a complex FFT of `N` on the real input. The FFT is a Stockham
//! autosort with radices 4, 2, 3 and 5, ping-ponging between the data and
//! the scratch, so no permutation pass.
//!
//! # Precision
//! Each stage rounds a few times per value, so the relative RMS error
//! against the exact transform grows like `ε·log₂N` (ε the unit roundoff of
//! `T`), as for radix 2; the tests bound it against a naive transform in
//! f64 for every supported `N ≤ 512`.

pub mod butterfly;
mod fft;
mod line;
mod multi;
mod plan;
pub mod stage;

pub use line::{dht_mixed, idht_mixed};
pub use multi::{
    dht_2d_mixed, dht_2d_mixed_scratch_len, dht_3d_mixed, dht_3d_mixed_scratch_len,
    dht_3d_mixed_store,
};
pub use plan::{fast_len, is_fast_len, mixed_scratch_len, mixed_table_len, MixedPlan};
