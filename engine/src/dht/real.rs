//! The arithmetic the host's transforms run in.

use fvr_core::num::Real;
use rustfft::FftNum;

/// Arithmetic the FFT-based transform runs in: f32 or f64.
pub trait FftReal: Real + FftNum {}
impl<T: Real + FftNum> FftReal for T {}
