//! The arithmetic of the mixed-radix transforms, one complex value at a
//! time: the radix-2, 3, 4 and 5 butterflies, the twiddle lookup and the
//! pass from the packed FFT to the DHT of even length. The core's stages
//! ([`super::dht_mixed`]) and any other layout of the same transform (the
//! engine runs it on lanes of lines) call these, so both compute the same
//! values operation for operation.

use crate::num::Real;

/// One complex value.
#[derive(Clone, Copy)]
pub struct C<T> {
    /// Real part.
    pub re: T,
    /// Imaginary part.
    pub im: T,
}

// Plain methods rather than the operator traits: the butterflies read as
// the formulas, and no caller needs `+` on complex values.
#[allow(clippy::should_implement_trait)]
impl<T: Real> C<T> {
    /// `self + o`.
    #[inline(always)]
    pub fn add(self, o: Self) -> Self {
        C {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
    /// `self − o`.
    #[inline(always)]
    pub fn sub(self, o: Self) -> Self {
        C {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
    /// `self · o`.
    #[inline(always)]
    pub fn mul(self, o: Self) -> Self {
        C {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    /// `self · a` for real `a`.
    #[inline(always)]
    pub fn scale(self, a: T) -> Self {
        C {
            re: self.re * a,
            im: self.im * a,
        }
    }
    /// `self · (−i)`.
    #[inline(always)]
    pub fn mul_neg_i(self) -> Self {
        C {
            re: self.im,
            im: -self.re,
        }
    }
}

/// `ω_ℓ^e` for `e < ℓ` from a plan's twiddle `table` (interleaved
/// `e^{−2πij/L}`), `step` the table index of `ω_ℓ^1`; `1` past its end.
#[inline(always)]
pub fn twiddle<T: Real>(table: &[T], step: usize, e: usize) -> C<T> {
    let i = 2 * e * step;
    match table.get(i..i + 2) {
        Some(t) => C { re: t[0], im: t[1] },
        None => C {
            re: T::ONE,
            im: T::ZERO,
        },
    }
}

/// The radix-2 butterfly.
#[inline(always)]
pub fn radix2<T: Real>([a0, a1]: [C<T>; 2]) -> [C<T>; 2] {
    [a0.add(a1), a0.sub(a1)]
}

/// The radix-3 butterfly.
#[inline(always)]
pub fn radix3<T: Real>([a0, a1, a2]: [C<T>; 3]) -> [C<T>; 3] {
    // ω_3 = −½ − i·√3/2.
    let s3 = T::from_f64(0.866_025_403_784_438_6);
    let t = a1.add(a2);
    let d = a1.sub(a2).scale(s3).mul_neg_i();
    let base = a0.sub(t.scale(T::HALF));
    [a0.add(t), base.add(d), base.sub(d)]
}

/// The radix-4 butterfly.
#[inline(always)]
pub fn radix4<T: Real>([a0, a1, a2, a3]: [C<T>; 4]) -> [C<T>; 4] {
    let (t0, t1) = (a0.add(a2), a0.sub(a2));
    let (t2, t3) = (a1.add(a3), a1.sub(a3).mul_neg_i());
    [t0.add(t2), t1.add(t3), t0.sub(t2), t1.sub(t3)]
}

/// The radix-5 butterfly.
#[inline(always)]
pub fn radix5<T: Real>([a0, a1, a2, a3, a4]: [C<T>; 5]) -> [C<T>; 5] {
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

/// The even-length DHT from `Z`, the FFT of `z(x) = f(2x) + i·f(2x+1)` of
/// length `M = N/2`, for `0 < k < M`: with `a = Z(k)`, `b = Z(M−k)` and
/// `w = e^{−2πik/N}` (entry `k` of the plan's table), returns
/// `(H(k), H(N−k))`. `2E = Z(k) + Z̄(M−k)`, `2O = −i[Z(k) − Z̄(M−k)]`,
/// `X(k) = E(k) + w·O(k)`, `H(k) = Re X − Im X` and `H(N−k) = Re X + Im X`.
#[inline(always)]
pub fn even_split<T: Real>(a: C<T>, b: C<T>, w: C<T>) -> (T, T) {
    let e = C {
        re: a.re + b.re,
        im: a.im - b.im,
    };
    let d = C {
        re: a.re - b.re,
        im: a.im + b.im,
    };
    let o = C {
        re: d.im,
        im: -d.re,
    };
    let wo = C {
        re: w.re * o.re - w.im * o.im,
        im: w.re * o.im + w.im * o.re,
    };
    let (xr, xi) = (T::HALF * (e.re + wo.re), T::HALF * (e.im + wo.im));
    (xr - xi, xr + xi)
}
