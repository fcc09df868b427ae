//! A point's tap sum on the linear layout, in the core's order
//! (`fvr_core::slice`), and the index arithmetic it shares with the walks:
//! wrapping around the cube ([`Side`]) and the starts of a point's runs
//! ([`run_starts`], which the exact walk also prefetches).

use fvr_core::num::{Real, Sample};
use fvr_core::slice::{wrapped_tap_sum, Unscaled};

/// `i mod n` for the indices of one cube side: a mask when `POW2` (`n` a
/// power of two), else as the core's mixed-radix walk: a remainder per
/// axis and, for taps, a conditional subtraction.
#[derive(Clone, Copy)]
pub(crate) struct Side<const POW2: bool> {
    pub(crate) n: usize,
}

impl<const POW2: bool> Side<POW2> {
    /// `j mod n` for any `j`.
    #[inline(always)]
    pub(crate) fn wrap(self, j: i64) -> usize {
        if POW2 {
            j as usize & (self.n - 1)
        } else {
            j.rem_euclid(self.n as i64) as usize
        }
    }

    /// `k mod n` for a signed frequency `|k| ≤ n/2`.
    #[inline(always)]
    pub(crate) fn signed(self, k: i32) -> usize {
        if POW2 {
            k as usize & (self.n - 1)
        } else if k < 0 {
            (k + self.n as i32) as usize
        } else {
            k as usize
        }
    }

    /// `(i + t) mod n` for `i < n` and a tap offset `t < W`.
    #[inline(always)]
    pub(crate) fn step(self, i: usize, t: usize) -> usize {
        if POW2 {
            (i + t) & (self.n - 1)
        } else {
            let mut v = i + t;
            while v >= self.n {
                v -= self.n;
            }
            v
        }
    }
}

/// `Σ_c wz_c Σ_b wy_b Σ_t wx_t·c[z + c, y + b, x + t]` (indices wrapping
/// around the cube of power-of-two side `n`), as [`tap_sum_on`].
#[inline(always)]
pub(crate) fn tap_sum<const W: usize, S: Sample, T: Real>(
    data: &[S],
    n: usize,
    taps: [i32; 3],
    weights: [&[T; W]; 3],
) -> T {
    tap_sum_on(data, Side::<true> { n }, taps, weights)
}

/// The starts of the `W × W` runs of a point's taps at `[jx, jy, jz]`:
/// the lines' offsets within a plane, the planes' offsets and the run's
/// first `x` (indices wrapping around the cube of side `side.n`).
#[inline(always)]
pub(crate) fn run_starts<const W: usize, const POW2: bool>(
    side: Side<POW2>,
    [jx, jy, jz]: [i32; 3],
) -> ([usize; W], [usize; W], usize) {
    let n = side.n;
    let nn = n * n;
    if POW2 {
        // `((j + b) mod n)·n` as `(j·n + b·n) mod n²`, in wrapping usize.
        let (y0, z0) = (
            (jy as usize).wrapping_mul(n),
            (jz as usize).wrapping_mul(nn),
        );
        (
            core::array::from_fn(|b| y0.wrapping_add(b * n) & (nn - n)),
            core::array::from_fn(|c| z0.wrapping_add(c * nn) & (nn * n - nn)),
            side.wrap(jx as i64),
        )
    } else {
        let (y0, z0) = (side.wrap(jy as i64), side.wrap(jz as i64));
        (
            core::array::from_fn(|b| side.step(y0, b) * n),
            core::array::from_fn(|c| side.step(z0, c) * nn),
            side.wrap(jx as i64),
        )
    }
}

/// `Σ_c wz_c Σ_b wy_b Σ_t wx_t·c[z + c, y + b, x + t]` (indices wrapping
/// around the cube), summed in the core's order: each x-line from
/// zero, tap by tap, then lines into planes, planes into the value. The
/// samples are read raw ([`Real::load_raw`]): `wx` carries `2^e`
/// ([`Real::raw_exponent`]), which leaves every product as the core's.
#[inline(always)]
pub(crate) fn tap_sum_on<const W: usize, const POW2: bool, S: Sample, T: Real>(
    data: &[S],
    side: Side<POW2>,
    [jx, jy, jz]: [i32; 3],
    [wx, wy, wz]: [&[T; W]; 3],
) -> T {
    let (lines, planes, x0) = run_starts::<W, POW2>(side, [jx, jy, jz]);
    let n = side.n;
    let mut acc = T::ZERO;
    // Up to W = 5 plane by plane: kb5 side by side took 1.03 to 1.5× the
    // CPU time (`FVR_BENCH_FILTERS=kb5 cargo bench -p fvr-host --bench
    // view_cpu`, sides 256 and 320).
    if x0 + W <= n && W <= 5 {
        for c in 0..W {
            let mut acc_y = T::ZERO;
            for b in 0..W {
                let start = planes[c] + lines[b] + x0;
                let mut acc_x = T::ZERO;
                if let Some(run) = data.get(start..start + W) {
                    for t in 0..W {
                        acc_x += wx[t] * T::load_raw(run[t]);
                    }
                }
                acc_y += wy[b] * acc_x;
            }
            acc += wz[c] * acc_y;
        }
    } else if x0 + W <= n {
        // kb6: every plane's sums side by side (lanes `c`),
        // each in the core's order: the same operations per plane,
        // interleaved, which the compiler vectorizes (kb6 about 1.1 to
        // 1.5× less CPU time a view; kb4 compiles slower this way).
        // The runs are borrowed, not copied: a copy into an array on the
        // stack was written in 8- and 4-byte pieces and read back in 16,
        // which defeats store forwarding (a stall a run; half the kb6 walk's
        // samples under `perf record` on a tilted turntable at 256³).
        let zeros = [S::default(); W];
        let mut acc_y = [T::ZERO; W];
        for b in 0..W {
            let runs: [&[S; W]; W] = core::array::from_fn(|c| {
                let start = planes[c] + lines[b] + x0;
                data.get(start..start + W)
                    .and_then(|s| <&[S; W]>::try_from(s).ok())
                    .unwrap_or(&zeros)
            });
            let mut acc_x = [T::ZERO; W];
            for t in 0..W {
                for c in 0..W {
                    acc_x[c] += wx[t] * T::load_raw(runs[c][t]);
                }
            }
            for c in 0..W {
                acc_y[c] += wy[b] * acc_x[c];
            }
        }
        for c in 0..W {
            acc += wz[c] * acc_y[c];
        }
    } else {
        let xs: [usize; W] = core::array::from_fn(|t| side.step(x0, t));
        acc = wrapped_tap_sum(data, [&planes, &lines, &xs], [wx, wy, wz], &Unscaled);
    }
    acc
}
