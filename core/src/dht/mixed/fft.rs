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

use crate::num::Real;

/// One complex value.
#[derive(Clone, Copy)]
pub(super) struct C<T> {
    pub re: T,
    pub im: T,
}

impl<T: Real> C<T> {
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        C {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        C {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        C {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    #[inline(always)]
    fn scale(self, a: T) -> Self {
        C {
            re: self.re * a,
            im: self.im * a,
        }
    }
    /// `self · (−i)`.
    #[inline(always)]
    fn mul_neg_i(self) -> Self {
        C {
            re: self.im,
            im: -self.re,
        }
    }
}

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
        let i = 2 * e * self.step;
        match self.table.get(i..i + 2) {
            Some(t) => C { re: t[0], im: t[1] },
            None => C {
                re: T::ONE,
                im: T::ZERO,
            },
        }
    }
}

#[inline(always)]
fn radix2<T: Real>([a0, a1]: [C<T>; 2]) -> [C<T>; 2] {
    [a0.add(a1), a0.sub(a1)]
}

#[inline(always)]
fn radix3<T: Real>([a0, a1, a2]: [C<T>; 3]) -> [C<T>; 3] {
    // ω_3 = −½ − i·√3/2.
    let s3 = T::from_f64(0.866_025_403_784_438_6);
    let t = a1.add(a2);
    let d = a1.sub(a2).scale(s3).mul_neg_i();
    let base = a0.sub(t.scale(T::HALF));
    [a0.add(t), base.add(d), base.sub(d)]
}

#[inline(always)]
fn radix4<T: Real>([a0, a1, a2, a3]: [C<T>; 4]) -> [C<T>; 4] {
    let (t0, t1) = (a0.add(a2), a0.sub(a2));
    let (t2, t3) = (a1.add(a3), a1.sub(a3).mul_neg_i());
    [t0.add(t2), t1.add(t3), t0.sub(t2), t1.sub(t3)]
}

#[inline(always)]
fn radix5<T: Real>([a0, a1, a2, a3, a4]: [C<T>; 5]) -> [C<T>; 5] {
    // cos and sin of 2π/5 and 4π/5.
    let c1 = T::from_f64(0.309_016_994_374_947_45);
    let c2 = T::from_f64(-0.809_016_994_374_947_5);
    let s1 = T::from_f64(0.951_056_516_295_153_5);
    let s2 = T::from_f64(0.587_785_252_292_473_1);
    let (t1, d1) = (a1.add(a4), a1.sub(a4));
    let (t2, d2) = (a2.add(a3), a2.sub(a3));
    let e1 = a0.add(t1.scale(c1)).add(t2.scale(c2));
    let e2 = a0.add(t1.scale(c2)).add(t2.scale(c1));
    // ω^k + ω^{−k} terms above; the odd parts times −i below.
    let o1 = d1.scale(s1).add(d2.scale(s2)).mul_neg_i();
    let o2 = d1.scale(s2).sub(d2.scale(s1)).mul_neg_i();
    [
        a0.add(t1).add(t2),
        e1.add(o1),
        e2.add(o2),
        e2.sub(o2),
        e1.sub(o1),
    ]
}
