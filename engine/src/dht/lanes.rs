//! The core's mixed-radix 1D DHT of even length (`fvr_core::dht::dht_mixed`)
//! on up to [`LANES`] lines at once, bit for bit the core's values: the
//! lines are the lanes of every operation, so each stage's inner loop runs
//! over contiguous lanes (which the compiler vectorizes) instead of one
//! line's strided elements.
//!
//! The arithmetic is the core's, operation for operation: the even and odd
//! samples packed as `z(x) = f(2x) + i·f(2x+1)`, a Stockham FFT of `N/2`
//! with radices 4, 2, 3, 5 in the plan's order and the plan's twiddle
//! table, then the pass that splits the even and odd spectra and forms
//! `H = Re X ∓ Im X` (`core/src/dht/mixed/`).

use fvr_core::dht::mixed::butterfly::{even_split, C};
use fvr_core::dht::mixed::stage::{run_stages, Stage, StageKernel};
use fvr_core::num::Real;

/// Lines transformed together.
pub const LANES: usize = 16;

/// The radices of the complex FFT of a plan of length `n` (of `n/2` for
/// even `n`), in the core's order: fours, a two, threes, fives.
fn radices(n: usize) -> Vec<usize> {
    let mut m = if n % 2 == 0 { n / 2 } else { n };
    let mut out = Vec::new();
    for r in [4usize, 2, 3, 5] {
        while m > 1 && m % r == 0 {
            out.push(r);
            m /= r;
        }
    }
    out
}

/// Working buffers for [`Lanes::dht_rows`]: two complex planes of
/// `n/2 ×` [`LANES`] values, real and imaginary parts apart.
pub struct Lanes<T> {
    n: usize,
    radices: Vec<usize>,
    table: Vec<T>,
    a: [Vec<T>; 2],
    b: [Vec<T>; 2],
}

impl<T: Real> Lanes<T> {
    /// Buffers for the even length `n` with its plan's twiddle `table`
    /// (`fvr_core::dht::MixedPlan::new`'s, `2n` values).
    ///
    /// # Panics
    /// If `n` is odd or the table short.
    pub fn new(n: usize, table: &[T]) -> Self {
        assert!(n % 2 == 0, "odd side {n}");
        let half = n / 2 * LANES;
        Self {
            n,
            radices: radices(n),
            table: table[..2 * n].to_vec(),
            a: [vec![T::ZERO; half], vec![T::ZERO; half]],
            b: [vec![T::ZERO; half], vec![T::ZERO; half]],
        }
    }

    /// The DHT in place of each row of `strip` (at most [`LANES`] rows of
    /// `n`), each bit for bit the core's `dht_mixed` of that row.
    pub fn dht_rows(&mut self, strip: &mut [T]) {
        let (n, half) = (self.n, self.n / 2);
        debug_assert!(strip.len() <= LANES * n && strip.len() % n == 0);
        {
            let [ar, ai] = &mut self.a;
            for (l, row) in strip.chunks_exact(n).enumerate() {
                for (e, pair) in row.chunks_exact(2).enumerate() {
                    ar[e * LANES + l] = pair[0];
                    ai[e * LANES + l] = pair[1];
                }
            }
        }
        let radices = self.radices.iter().copied();
        let mut buffers = Planes {
            a: &mut self.a,
            b: &mut self.b,
        };
        let in_b = run_stages(&mut buffers, half, radices, &self.table, 2);
        let (z, out) = if in_b {
            (&self.b, &mut self.a)
        } else {
            (&self.a, &mut self.b)
        };
        split([&z[0], &z[1]], out, &self.table, n);
        let [low, high] = &*out;
        for (l, row) in strip.chunks_exact_mut(n).enumerate() {
            let (lo, hi) = row.split_at_mut(half);
            for (k, h) in lo.iter_mut().enumerate() {
                *h = low[k * LANES + l];
            }
            for (k, h) in hi.iter_mut().enumerate() {
                *h = high[k * LANES + l];
            }
        }
    }
}

/// The core's `dht_even` pass on every lane: from `Z`, the FFT of `z`, to
/// `H(k) = Re X(k) − Im X(k)` and `H(N−k) = Re X(k) + Im X(k)`, with
/// `H(k)` for `k < N/2` in `out[0]` and `H(N/2 + k)` in `out[1]`.
fn split<T: Real>([zr, zi]: [&[T]; 2], out: &mut [Vec<T>; 2], table: &[T], n: usize) {
    let m = n / 2;
    let [low, high] = out;
    {
        let (r0, i0) = (lanes(zr, 0), lanes(zi, 0));
        let (h0, hm) = (lanes_mut(low, 0), lanes_mut(high, 0));
        for l in 0..LANES {
            h0[l] = r0[l] + i0[l];
            hm[l] = r0[l] - i0[l];
        }
    }
    for k in 1..m {
        let w = C {
            re: table[2 * k],
            im: table[2 * k + 1],
        };
        let (a, b) = (k * LANES, (m - k) * LANES);
        let (ar, ai, br, bi) = (lanes(zr, a), lanes(zi, a), lanes(zr, b), lanes(zi, b));
        let (lo, hi) = (lanes_mut(low, a), lanes_mut(high, b));
        for l in 0..LANES {
            let a = C {
                re: ar[l],
                im: ai[l],
            };
            let b = C {
                re: br[l],
                im: bi[l],
            };
            (lo[l], hi[l]) = even_split(a, b, w);
        }
    }
}

/// The [`LANES`] values from `at`.
#[inline(always)]
fn lanes<T>(values: &[T], at: usize) -> &[T; LANES] {
    values[at..at + LANES]
        .try_into()
        .expect("a whole run of lanes")
}

/// The [`LANES`] values from `at`, to write.
#[inline(always)]
fn lanes_mut<T>(values: &mut [T], at: usize) -> &mut [T; LANES] {
    (&mut values[at..at + LANES])
        .try_into()
        .expect("a whole run of lanes")
}

/// The two ping-pong buffers of the FFT, each a complex plane of runs of
/// lanes (real and imaginary parts apart).
struct Planes<'a, T> {
    a: &'a mut [Vec<T>; 2],
    b: &'a mut [Vec<T>; 2],
}

/// One Stockham stage, every complex value a run of lanes.
impl<T: Real> StageKernel<T> for Planes<'_, T> {
    /// Element `p` of input sub-transform `q`, for `j`, sits at complex
    /// index `p·s + j·m·s + q`; the output for `k` at `p·R·s + k·s + q`.
    #[inline(always)]
    fn run<const R: usize>(&mut self, st: &Stage<T>, bfly: impl Fn([C<T>; R]) -> [C<T>; R]) {
        let ([ar, ai], [br, bi]) = (&mut *self.a, &mut *self.b);
        let ([xr, xi], [yr, yi]): ([&[T]; 2], [&mut [T]; 2]) = if st.from_b {
            ([br, bi], [ar, ai])
        } else {
            ([ar, ai], [br, bi])
        };
        let (m, s) = (st.m, st.s);
        let block = R * s * LANES;
        for (p, (out_r, out_i)) in yr
            .chunks_exact_mut(block)
            .zip(yi.chunks_exact_mut(block))
            .enumerate()
            .take(m)
        {
            let w: [C<T>; R] = core::array::from_fn(|k| st.twiddle(p * k));
            let mut chunks_r = out_r.chunks_exact_mut(s * LANES);
            let mut chunks_i = out_i.chunks_exact_mut(s * LANES);
            let mut outs_r: [&mut [T]; R] =
                core::array::from_fn(|_| chunks_r.next().unwrap_or_default());
            let mut outs_i: [&mut [T]; R] =
                core::array::from_fn(|_| chunks_i.next().unwrap_or_default());
            for q in 0..s {
                let at = |j: usize| (p * s + j * m * s + q) * LANES;
                let ins_r: [&[T; LANES]; R] = core::array::from_fn(|j| lanes(xr, at(j)));
                let ins_i: [&[T; LANES]; R] = core::array::from_fn(|j| lanes(xi, at(j)));
                let o = q * LANES;
                let dst_r: [&mut [T; LANES]; R] = outs_r.each_mut().map(|c| lanes_mut(c, o));
                let dst_i: [&mut [T; LANES]; R] = outs_i.each_mut().map(|c| lanes_mut(c, o));
                for l in 0..LANES {
                    let v: [C<T>; R] = core::array::from_fn(|j| C {
                        re: ins_r[j][l],
                        im: ins_i[j][l],
                    });
                    let v = bfly(v);
                    for k in 0..R {
                        let c = if k == 0 { v[0] } else { v[k].mul(w[k]) };
                        dst_r[k][l] = c.re;
                        dst_i[k][l] = c.im;
                    }
                }
            }
        }
    }
}
