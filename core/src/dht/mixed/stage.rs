//! The Stockham stages of the mixed-radix FFT, written once for every
//! memory layout: which stages run, with which sizes and twiddles, and the
//! ping-pong between two buffers. How a stage moves its values (interleaved
//! complex values here, runs of lanes in the host engine) is the layout's
//! [`StageKernel`].
//!
//! A stage of radix `r` on sub-transforms of length `ℓ = r·m`, `s` of them
//! interleaved (element `p` of sub-transform `q` at `q + s·p`), splits each
//! input index as `p + j·m` and each output index as `k + r·t`:
//! `X(k + r·t) = Σ_p ω_m^{pt} · [ω_ℓ^{pk} · Σ_j z(p + j·m) ω_r^{jk}]`,
//! so the bracket, stored at `q + s·(r·p + k)`, is element `p` of
//! sub-transform `q + s·k` of length `m` at stride `r·s`. The output of the
//! last stage (`m = 1`) is in natural order; no permutation pass.

use super::butterfly::{radix2, radix3, radix4, radix5, twiddle, C};
use crate::num::Real;

/// One stage: `m` and `s` as in the module's notes, and the twiddle table
/// read at a stride.
#[derive(Clone, Copy, Debug)]
pub struct Stage<'t, T> {
    /// Length of each output sub-transform.
    pub m: usize,
    /// Sub-transforms interleaved on input.
    pub s: usize,
    /// The data is in the second buffer (and goes into the first).
    pub from_b: bool,
    table: &'t [T],
    /// Table index of `ω_ℓ^1`.
    step: usize,
}

impl<T: Real> Stage<'_, T> {
    /// `ω_ℓ^e`, `e < ℓ`.
    #[inline(always)]
    pub fn twiddle(&self, e: usize) -> C<T> {
        twiddle(self.table, self.step, e)
    }
}

/// A memory layout's stage: one stage of radix `R`, from the buffer that
/// holds the data (the second one if [`Stage::from_b`]) into the other,
/// each `R`-point butterfly computed by `bfly`.
pub trait StageKernel<T> {
    /// Runs `st`.
    fn run<const R: usize>(&mut self, st: &Stage<T>, bfly: impl Fn([C<T>; R]) -> [C<T>; R]);
}

/// Every stage of the forward FFT of `f` complex values, radices in order
/// (each 2, 3, 4 or 5; their product `f`), with `table` holding
/// `e^{−2πij/L}` for `j < L = g·f`. Returns `true` if the result ended in
/// the second buffer.
#[inline(always)]
pub fn run_stages<T: Real, K: StageKernel<T>>(
    kernel: &mut K,
    f: usize,
    radices: impl IntoIterator<Item = usize>,
    table: &[T],
    g: usize,
) -> bool {
    let (mut s, mut m, mut in_b) = (1, f, false);
    for r in radices {
        m /= r;
        let stage = Stage {
            m,
            s,
            from_b: in_b,
            table,
            step: g * s,
        };
        match r {
            2 => kernel.run::<2>(&stage, radix2),
            3 => kernel.run::<3>(&stage, radix3),
            4 => kernel.run::<4>(&stage, radix4),
            _ => kernel.run::<5>(&stage, radix5),
        }
        in_b = !in_b;
        s *= r;
    }
    in_b
}
