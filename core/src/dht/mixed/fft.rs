//! Mixed-radix (2, 3, 4, 5) Stockham complex FFT, forward
//! (`X(t) = Σ z(x) e^{−2πixt/F}`), ping-ponging between two buffers of
//! interleaved complex values.
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

/// Forward FFT of the `f = len/2` complex values in `a` (interleaved), with
/// `b` of the same length as the other buffer. `table` holds `e^{−2πij/L}`
/// for `j < L = g·f`. Returns `true` if the result ended in `b`.
pub(super) fn fft<T: Real>(
    a: &mut [T],
    b: &mut [T],
    radices: &[u8],
    table: &[T],
    g: usize,
) -> bool {
    let f = a.len() / 2;
    let mut s = 1;
    let mut m = f;
    let mut in_b = false;
    for &r in radices {
        let r = r as usize;
        m /= r;
        let (x, y): (&[T], &mut [T]) = if in_b { (&*b, &mut *a) } else { (&*a, &mut *b) };
        let st = Stage {
            m,
            s,
            table,
            step: g * s,
        };
        match r {
            2 => st.run::<2>(x, y, radix2),
            3 => st.run::<3>(x, y, radix3),
            4 => st.run::<4>(x, y, radix4),
            _ => st.run::<5>(x, y, radix5),
        }
        in_b = !in_b;
        s *= r;
    }
    in_b
}

struct Stage<'t, T> {
    m: usize,
    s: usize,
    table: &'t [T],
    /// Table index of `ω_ℓ^1`.
    step: usize,
}

impl<T: Real> Stage<'_, T> {
    /// One stage of radix `R` from `x` into `y`.
    #[inline(always)]
    fn run<const R: usize>(&self, x: &[T], y: &mut [T], bfly: impl Fn([C<T>; R]) -> [C<T>; R]) {
        let (m, s) = (self.m, self.s);
        let run = 2 * s; // reals in one run of s complex values
        let span = 2 * m * s; // reals from input index p to p + m
        for (p, out) in y.chunks_exact_mut(R * run).enumerate().take(m) {
            let w: [C<T>; R] = core::array::from_fn(|k| self.twiddle(p * k));
            let ins: [&[T]; R] = core::array::from_fn(|j| {
                let start = p * run + j * span;
                x.get(start..start + run).unwrap_or(&[])
            });
            let mut chunks = out.chunks_exact_mut(run);
            let outs: [&mut [T]; R] = core::array::from_fn(|_| chunks.next().unwrap_or_default());
            for q in 0..s {
                let (i0, i1) = (2 * q, 2 * q + 1);
                let v: [C<T>; R] = core::array::from_fn(|j| match ins[j].get(i0..=i1) {
                    Some(c) => C { re: c[0], im: c[1] },
                    None => C {
                        re: T::ZERO,
                        im: T::ZERO,
                    },
                });
                let v = bfly(v);
                for k in 0..R {
                    let c = if k == 0 { v[0] } else { v[k].mul(w[k]) };
                    if let Some(o) = outs[k].get_mut(i0..=i1) {
                        o[0] = c.re;
                        o[1] = c.im;
                    }
                }
            }
        }
    }

    /// `ω_ℓ^e`, `e < ℓ`.
    #[inline(always)]
    fn twiddle(&self, e: usize) -> C<T> {
        twiddle(self.table, self.step, e)
    }
}
