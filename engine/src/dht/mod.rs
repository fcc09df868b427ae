//! The 3D Hartley transform on the host: through real FFTs on all cores
//! ([`real_fft`]), mixed-radix butterflies in lanes ([`lanes`]), and the
//! rounding of the result to the storage format ([`store`]).

pub mod lanes;
pub mod real;
pub mod real_fft;
pub mod store;
