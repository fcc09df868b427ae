//! What the core's tests share: the agreement of two signals in dB. The
//! unit tests use it as `crate::test_support`; the integration tests in
//! `core/tests/` include this file as a module of their own.
#![allow(dead_code)] // each test crate uses a different part

extern crate std;

/// Agreement of `got` with `reference` in dB,
/// `10·log10(Σ r² / Σ (g − r)²)` (the argument order of
/// `fvr_engine::image::snr_db`); infinite when exact.
pub fn snr_db(reference: &[f64], got: &[f64]) -> f64 {
    let signal: f64 = reference.iter().map(|r| r * r).sum();
    let noise: f64 = got
        .iter()
        .zip(reference)
        .map(|(g, r)| (g - r) * (g - r))
        .sum();
    if noise == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (signal / noise).log10()
    }
}
