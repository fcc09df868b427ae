//! Mixed-radix (2, 3, 4, 5) Stockham complex FFT, forward
//! (`X(t) = Σ z(x) e^{−2πixt/F}`), ping-ponging between two buffers of
//! interleaved complex values.
//!
//! The stages themselves are [`super::stage`]'s; this file is their
//! kernel on interleaved buffers.

use super::butterfly::C;
use super::stage::{run_stages, Stage, StageKernel};
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
    let radices = radices.iter().map(|&r| r as usize);
    run_stages(&mut Interleaved { a, b }, f, radices, table, g)
}

/// The two buffers of interleaved complex values.
struct Interleaved<'a, T> {
    a: &'a mut [T],
    b: &'a mut [T],
}

impl<T: Real> StageKernel<T> for Interleaved<'_, T> {
    #[inline(always)]
    fn run<const R: usize>(&mut self, st: &Stage<T>, bfly: impl Fn([C<T>; R]) -> [C<T>; R]) {
        let (x, y): (&[T], &mut [T]) = if st.from_b {
            (&*self.b, &mut *self.a)
        } else {
            (&*self.a, &mut *self.b)
        };
        let (m, s) = (st.m, st.s);
        let run = 2 * s; // reals in one run of s complex values
        let span = 2 * m * s; // reals from input index p to p + m
        for (p, out) in y.chunks_exact_mut(R * run).enumerate().take(m) {
            let w: [C<T>; R] = core::array::from_fn(|k| st.twiddle(p * k));
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
}
