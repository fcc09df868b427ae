//! The transcendental functions a device computes per view, three ways:
//! the core's (`libm` in f64), `libm`'s f32 functions and `micromath`'s f32
//! approximations. `fvr-trig-bench` counts their instructions on the
//! device; `tests/trig.rs` measures, on the host, what each costs the image
//! (the functions are plain IEEE f32/f64 code, so the host computes the
//! device's values).
//!
//! A package of its own: `micromath` as a dependency of `fvr-firmware`
//! moves the M4F's code generation (plain kb3 +22,000 instructions with no
//! source change), and as a feature it would rebuild that library for every
//! target; here it links only into this package.
//!
//! Per view the core evaluates `cos` and `sin` at the `4m` phases of the
//! sub-pixel shift (`fvr_core::image`, `φ = −2π·k·t/m` along each axis) and
//! the square roots of the view frame (three norms) and of each light's
//! normalisation.
#![cfg_attr(not(test), no_std)]

use micromath::F32;

/// Where the functions come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Trig {
    /// `libm::cos`, `libm::sin`, `libm::sqrt` in f64 (the core's).
    LibmF64,
    /// `libm::cosf`, `libm::sinf`, `libm::sqrtf` in f32.
    LibmF32,
    /// `micromath::F32`'s approximations in f32.
    Micromath,
}

impl Trig {
    /// All three, the core's first.
    pub const ALL: [Trig; 3] = [Trig::LibmF64, Trig::LibmF32, Trig::Micromath];

    /// A short name for logs and tables.
    pub fn name(self) -> &'static str {
        match self {
            Trig::LibmF64 => "libm-f64",
            Trig::LibmF32 => "libm-f32",
            Trig::Micromath => "micromath",
        }
    }

    /// `(cos φ, sin φ)` rounded to f32.
    #[inline(never)]
    pub fn phasor(self, phase: f64) -> (f32, f32) {
        match self {
            Trig::LibmF64 => (libm::cos(phase) as f32, libm::sin(phase) as f32),
            Trig::LibmF32 => {
                let p = phase as f32;
                (libm::cosf(p), libm::sinf(p))
            }
            Trig::Micromath => {
                let p = F32(phase as f32);
                (p.cos().0, p.sin().0)
            }
        }
    }

    /// `√x`.
    #[inline(never)]
    pub fn sqrt(self, x: f64) -> f64 {
        match self {
            Trig::LibmF64 => libm::sqrt(x),
            Trig::LibmF32 => libm::sqrtf(x as f32) as f64,
            Trig::Micromath => F32(x as f32).sqrt().0 as f64,
        }
    }
}

/// Elements of [`shift_phasors`]' table for side `m`.
pub const fn phasors_len(m: usize) -> usize {
    4 * m
}

/// The shift's phasor table for an `m × m` grid and sub-pixel shift `t`,
/// as `fvr_core::image` fills it (Nyquist rows and columns get phase 0):
/// `[cx | sx | cy | sy]`, `m` each.
pub fn shift_phasors(trig: Trig, m: usize, t: [f64; 2], table: &mut [f32]) {
    fvr_core::image::shift_phasors(m, t, table, |ph| trig.phasor(ph));
}

/// Shift the Hartley slice `grid` (`m × m`, a power of two) by the phasors
/// of [`shift_phasors`]: `H'(k) = cos φ·H(k) + sin φ·H(−k)`, pairwise, the
/// arithmetic of `fvr_core::image` (so [`Trig::LibmF64`] gives its values
/// bit for bit).
pub fn apply_phasors(grid: &mut [f32], m: usize, table: &[f32]) {
    fvr_core::image::apply_phasors(grid, m, table);
}
