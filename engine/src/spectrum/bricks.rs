//! A host copy of a plain spectrum in bricks ([`Bricked`]): the cube cut
//! into `bx × by × bz` blocks stored one after another, `x` fastest inside
//! a block, so that the taps of neighbouring slice points share cache
//! lines on any plane, not only on planes that run along x.
//!
//! Where coefficient `(x, y, z)` lives is separable: `X[x] + Y[y] + Z[z]`
//! with `X[x] = ⌊x/bx⌋·bx·by·bz + x mod bx`,
//! `Y[y] = ⌊y/by⌋·bx·by·bz·(n/bx) + (y mod by)·bx` and
//! `Z[z] = ⌊z/bz⌋·n²·bz + (z mod bz)·bx·by`. The tables run over indices
//! `−n − W … 2n + W` (wrapped around the cube), so a tap run needs no
//! wrapping: a tap's sample is three table reads and two additions away.
//! Bricks of `n × n × n` give the linear layout.

use fvr_core::filter::{Filter, MAX_WIDTH};
use fvr_core::num::{Real, Sample};
use fvr_core::spectrum::Spectrum;

/// A plain spectrum's coefficients in bricks, with its offset tables.
#[derive(Clone, Debug)]
pub struct Bricked<S> {
    data: Vec<S>,
    n: usize,
    brick: [usize; 3],
    filter: Filter,
    /// Offset tables of the three axes, indexed by `j + ORIGIN`.
    offsets: [Vec<u32>; 3],
}

/// Table index of cube index 0: room for every tap of a point inside the
/// Nyquist cube (`|j| ≤ n/2 + W`) and of its mirror.
fn origin(n: usize) -> usize {
    n + MAX_WIDTH
}

impl<S: Sample> Bricked<S> {
    /// The bricked copy of `spec` (`brick` divides its side on every axis),
    /// or `None` when the spectrum is not plain (block exponents), the
    /// brick does not divide the side or the offsets overflow `u32`.
    pub fn from_spectrum(spec: &Spectrum<'_, S>, brick: [usize; 3]) -> Option<Self> {
        let n = spec.n();
        let linear = spec.data();
        let mut out = Self::layout(n, brick, *spec.filter())?;
        if spec.blocks().is_some() || linear.len() != n * n * n {
            return None;
        }
        out.data = vec![S::default(); n * n * n];
        let [xs, ys, zs] = &out.offsets;
        let o = origin(n);
        for (z, plane) in linear.chunks_exact(n * n).enumerate() {
            for (y, line) in plane.chunks_exact(n).enumerate() {
                let base = (zs[z + o] + ys[y + o]) as usize;
                for (x, &v) in line.iter().enumerate() {
                    out.data[base + xs[x + o] as usize] = v;
                }
            }
        }
        Some(out)
    }

    /// The tables of `brick` on side `n`, with no data yet.
    fn layout(n: usize, brick: [usize; 3], filter: Filter) -> Option<Self> {
        let [bx, by, bz] = brick;
        if n == 0 || brick.iter().any(|&b| b == 0 || n % b != 0) {
            return None;
        }
        if u32::try_from(n.checked_pow(3)?).is_err() {
            return None;
        }
        let volume = bx * by * bz;
        let axis = |b: usize, outer: usize, inner: usize| -> Vec<u32> {
            let o = origin(n) as i64;
            (0..2 * origin(n) + n + MAX_WIDTH)
                .map(|i| {
                    let j = (i as i64 - o).rem_euclid(n as i64) as usize;
                    ((j / b) * outer + (j % b) * inner) as u32
                })
                .collect()
        };
        Some(Self {
            data: Vec::new(),
            n,
            brick,
            filter,
            offsets: [
                axis(bx, volume, 1),
                axis(by, volume * (n / bx), bx),
                axis(bz, n * n * bz, bx * by),
            ],
        })
    }

    /// Side of the cube.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The brick's extent on x, y and z.
    pub fn brick(&self) -> [usize; 3] {
        self.brick
    }

    /// The filter the spectrum was premultiplied for.
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// The coefficients, brick after brick.
    pub fn data(&self) -> &[S] {
        &self.data
    }

    /// The coefficient at cube index `(x, y, z)` (each below `n`).
    pub fn get(&self, x: usize, y: usize, z: usize) -> Option<S> {
        let o = origin(self.n);
        let at = |a: usize, i: usize| self.offsets[a].get(i + o).map(|&v| v as usize);
        self.data.get(at(0, x)? + at(1, y)? + at(2, z)?).copied()
    }

    /// `Σ_c wz_c Σ_b wy_b Σ_t wx_t·c[z + c, y + b, x + t]` (indices
    /// wrapping around the cube) in the core's order, as the linear
    /// walk sums it: each x-line from zero, tap by tap, then lines into
    /// planes, planes into the value (kb6's planes side by side, each in
    /// that order).
    #[inline(always)]
    pub(crate) fn tap_sum<const W: usize, T: Real>(
        &self,
        [jx, jy, jz]: [i32; 3],
        [wx, wy, wz]: [&[T; W]; 3],
    ) -> T {
        let o = origin(self.n) as i64;
        let run = |a: usize, j: i32| -> Option<[usize; W]> {
            let i = usize::try_from(j as i64 + o).ok()?;
            let s = self.offsets[a].get(i..i + W)?;
            Some(core::array::from_fn(|t| s[t] as usize))
        };
        let (Some(xs), Some(ys), Some(zs)) = (run(0, jx), run(1, jy), run(2, jz)) else {
            return T::ZERO;
        };
        let data = &self.data[..];
        if W > 5 {
            // kb6: planes side by side, tap by tap (copying runs into
            // arrays first measured slower here).
            let load = |i: usize| T::load_raw(data.get(i).copied().unwrap_or_default());
            let mut acc_y = [T::ZERO; W];
            for b in 0..W {
                let mut acc_x = [T::ZERO; W];
                for t in 0..W {
                    for c in 0..W {
                        acc_x[c] += wx[t] * load(zs[c] + ys[b] + xs[t]);
                    }
                }
                for c in 0..W {
                    acc_y[c] += wy[b] * acc_x[c];
                }
            }
            let mut acc = T::ZERO;
            for c in 0..W {
                acc += wz[c] * acc_y[c];
            }
            acc
        } else if xs[W - 1] == xs[0] + (W - 1) {
            // The run lies inside one brick (most points for bricks wider
            // than the filter): one contiguous read per line.
            let x0 = xs[0];
            sum_runs(ys, zs, [wx, wy, wz], |line| {
                let at = line + x0;
                data.get(at..at + W)
                    .and_then(|s| <[S; W]>::try_from(s).ok())
                    .unwrap_or([S::default(); W])
            })
        } else {
            sum_runs(ys, zs, [wx, wy, wz], |line| {
                core::array::from_fn(|t| data.get(line + xs[t]).copied().unwrap_or_default())
            })
        }
    }
}

/// The tap sum over the runs `run(zs[c] + ys[b])` of `W` samples, for
/// `W ≤ 5` (line by line, as the linear walk sums them).
#[inline(always)]
fn sum_runs<const W: usize, S: Sample, T: Real>(
    ys: [usize; W],
    zs: [usize; W],
    [wx, wy, wz]: [&[T; W]; 3],
    run: impl Fn(usize) -> [S; W],
) -> T {
    let mut acc = T::ZERO;
    for c in 0..W {
        let mut acc_y = T::ZERO;
        for b in 0..W {
            let r = run(zs[c] + ys[b]);
            let mut acc_x = T::ZERO;
            for t in 0..W {
                acc_x += wx[t] * T::load_raw(r[t]);
            }
            acc_y += wy[b] * acc_x;
        }
        acc += wz[c] * acc_y;
    }
    acc
}
