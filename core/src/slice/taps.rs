//! The extraction's hot loop: tap sums over x-lines, from the phase
//! tables (plain and per-line-exponent spectra) or from the kernel table
//! (any storage).

use super::rows::SliceRows;
use crate::filter::PhaseTable;
use crate::num::{Real, Sample};
use crate::spectrum::{CubeSide, Spectrum};

/// The tap reads of [`extract_lines`]: a spectrum of side `n` stored as
/// `data` (exactly `n³` values), with one block exponent per x-line in
/// `exponents` when `LINE_EXP`. `POW2`: `n` is a power of two, and tap
/// indices wrap by masks; otherwise (mixed-radix sides) by a remainder
/// per axis and a conditional subtraction per tap.
struct TapSums<'a, const W: usize, const LINE_EXP: bool, const POW2: bool, S> {
    data: &'a [S],
    n: usize,
    exponents: &'a [i8],
}

impl<const W: usize, const LINE_EXP: bool, const POW2: bool, S: Sample>
    TapSums<'_, W, LINE_EXP, POW2, S>
{
    /// An x-line's sum `acc_x` times the line's power of two, if lines
    /// carry one.
    #[inline(always)]
    fn line_sum<T: Real>(&self, line: usize, acc_x: T) -> T {
        if LINE_EXP {
            let e = self.exponents.get(line / self.n).copied().unwrap_or(0);
            acc_x * T::exp2i(e as i32)
        } else {
            acc_x
        }
    }

    /// The value at the taps `j + t` of each axis (`t < W`, wrapping
    /// around the cube) with weights `w[t]`; the x-weights carry the raw
    /// gain of [`Real::load_raw`].
    #[inline(always)]
    fn value<T: Real>(
        &self,
        jx: i32,
        wx: &[T; W],
        jy: i32,
        wy: &[T; W],
        jz: i32,
        wz: &[T; W],
    ) -> T {
        let (data, n) = (self.data, self.n);
        let (nn, mask) = (n * n, n - 1);
        let (lines, planes, x0): ([usize; W], [usize; W], usize) = if POW2 {
            // `((j + b) mod n)·n` as `(j·n + b·n) mod n²`, in wrapping usize:
            // the offsets of the taps' lines and planes with one product an
            // axis.
            let (y0, z0) = (
                (jy as usize).wrapping_mul(n),
                (jz as usize).wrapping_mul(nn),
            );
            (
                core::array::from_fn(|b| y0.wrapping_add(b * n) & (nn - n)),
                core::array::from_fn(|c| z0.wrapping_add(c * nn) & (nn * n - nn)),
                jx as usize & mask,
            )
        } else {
            let (y0, z0) = (wrap(jy as i64, n), wrap(jz as i64, n));
            (
                core::array::from_fn(|b| step(y0, b, n) * n),
                core::array::from_fn(|c| step(z0, c, n) * nn),
                wrap(jx as i64, n),
            )
        };
        let mut acc = T::ZERO;
        if x0 + W <= n {
            for c in 0..W {
                let mut acc_y = T::ZERO;
                for b in 0..W {
                    let start = planes[c] + lines[b] + x0;
                    // The run of W taps from `start`. For W ≤ 4, as the tail
                    // from `start` and its first chunk: two length tests and
                    // no overflow test of `start + W` (plain kb3 −32 k, kb4
                    // −55 k instructions on the M4F); kb6's loop compiles
                    // worse that way (+690 k), so it keeps the range.
                    let run = if W <= 4 {
                        data.get(start..).and_then(|rest| rest.first_chunk::<W>())
                    } else {
                        data.get(start..start + W)
                            .and_then(|s| <&[S; W]>::try_from(s).ok())
                    };
                    let acc_x = match run {
                        Some(run) => {
                            let mut sum = T::ZERO;
                            for t in 0..W {
                                sum += wx[t] * T::load_raw(run[t]);
                            }
                            sum
                        }
                        None => T::ZERO,
                    };
                    acc_y += wy[b] * self.line_sum(start, acc_x);
                }
                acc += wz[c] * acc_y;
            }
        } else {
            let xs: [usize; W] = core::array::from_fn(|t| {
                if POW2 {
                    (jx + t as i32) as usize & mask
                } else {
                    step(x0, t, n)
                }
            });
            acc = wrapped_tap_sum(data, [&planes, &lines, &xs], [wx, wy, wz], self);
        }
        acc
    }
}

impl<const W: usize, const LINE_EXP: bool, const POW2: bool, S: Sample, T: Real> LineSum<T>
    for TapSums<'_, W, LINE_EXP, POW2, S>
{
    #[inline(always)]
    fn line_sum(&self, line: usize, sum: T) -> T {
        TapSums::line_sum(self, line, sum)
    }
}

/// How [`wrapped_tap_sum`] takes an x-line's sum: scaled by the line's
/// block exponent, or as it is ([`Unscaled`]). A trait rather than a
/// closure: its method is always inlined, so the walk keeps the bounds the
/// compiler proved on the data.
pub trait LineSum<T> {
    /// The sum `sum` of the x-line starting at `line`, as the value takes it.
    fn line_sum(&self, line: usize, sum: T) -> T;
}

/// Every x-line's sum as it is.
#[derive(Clone, Copy, Debug)]
pub struct Unscaled;

impl<T> LineSum<T> for Unscaled {
    #[inline(always)]
    fn line_sum(&self, _line: usize, sum: T) -> T {
        sum
    }
}

/// The value at taps whose x-runs may wrap around the cube, tap by tap:
/// `Σ_c wz_c·Σ_b wy_b·line_sum(line, Σ_t wx_t·raw(data[line + xs_t]))`
/// with `line = planes_c + lines_b`, in this order (the core's bits; the
/// host engine's walks fall back on it too). A tap past the data reads 0.
#[inline(always)]
pub fn wrapped_tap_sum<const W: usize, S: Sample, T: Real>(
    data: &[S],
    [planes, lines, xs]: [&[usize; W]; 3],
    [wx, wy, wz]: [&[T; W]; 3],
    lines_as: &impl LineSum<T>,
) -> T {
    let mut acc = T::ZERO;
    for c in 0..W {
        let mut acc_y = T::ZERO;
        for b in 0..W {
            let line = planes[c] + lines[b];
            let mut acc_x = T::ZERO;
            for t in 0..W {
                let v = data.get(line + xs[t]).copied().unwrap_or_default();
                acc_x += wx[t] * T::load_raw(v);
            }
            acc_y += wy[b] * lines_as.line_sum(line, acc_x);
        }
        acc += wz[c] * acc_y;
    }
    acc
}

/// The extraction's hot loop: per slice point, three phase-table lookups
/// for the weights, then `W²` x-lines of `W` taps, each line one
/// contiguous run with one bounds check unless its taps wrap around the
/// cube. The `W` x-weights carry the `2^e` of [`Real::load_raw`], so a tap
/// costs a load, its raw widening, a multiplication and an addition; the
/// products are the same numbers as with the full widening (a power of two
/// moved between factors is exact). `LINE_EXP`: multiply each line's sum
/// by its block exponent's power of two (`exponents`, one per x-line).
#[inline(always)]
pub(super) fn extract_lines<
    const W: usize,
    const LINE_EXP: bool,
    const POW2: bool,
    S: Sample,
    Z: CubeSide,
    T: Real,
>(
    spec: &Spectrum<'_, S, Z>,
    phases: &PhaseTable<T, W>,
    geometry: &SliceRows<T>,
    exponents: &[i8],
    grid: &mut [T],
) {
    let n = spec.n();
    let nn = n * n;
    // Exactly `n³` (as `Spectrum` guarantees): with a compile-time side
    // ([`CubeSide`]) the compiler then proves every masked tap index in
    // range and drops the bounds tests.
    let Some(data) = spec.data().get(..nn * n) else {
        grid.fill(T::ZERO);
        return;
    };
    let raw_gain = T::exp2i(T::raw_exponent::<S>());
    let taps = TapSums::<W, LINE_EXP, POW2, S> { data, n, exponents };
    // The mirror `−q` of a point: taps `−j − t`, i.e. the run from
    // `−j − (W − 1)` with the weights reversed.
    let mirror = |j: i32| -j - (W as i32 - 1);
    let reversed = |w: &[T; W]| -> [T; W] { core::array::from_fn(|t| w[W - 1 - t]) };
    geometry.for_each_fixed_pair::<W, POW2>(n, grid, |y, plus, minus| {
        let (jx, wx) = phases.taps_fixed_point(y[0]);
        let (jy, wy) = phases.taps_fixed_point(y[1]);
        let (jz, wz) = phases.taps_fixed_point(y[2]);
        let wx = wx.map(|w| w * raw_gain);
        let value = if plus {
            taps.value(jx, &wx, jy, &wy, jz, &wz)
        } else {
            T::ZERO
        };
        let mirrored = if minus {
            let (rx, ry, rz) = (reversed(&wx), reversed(&wy), reversed(&wz));
            taps.value(mirror(jx), &rx, mirror(jy), &ry, mirror(jz), &rz)
        } else {
            T::ZERO
        };
        (value, mirrored)
    });
}

/// The extraction for any storage (e.g. bricked block exponents): the
/// same mirror-pair walk and phase-table weights as [`extract_lines`], each
/// x-line's taps read through [`Spectrum::line_taps`] (per-tap block
/// exponents). Walking the same pairs matters beyond speed: at a point on
/// an integer position the even-width window is one-sided (the kernel's
/// edge `k(±W/2)` is not zero), and the mirror `−q` takes the window
/// reflected. Evaluating `−q` directly instead picks the other side, which
/// on a low-β Kaiser–Bessel kernel moved a Shepp–Logan image by −30 dB
/// relative to the plain storage of the same coefficients.
#[inline(always)]
pub(super) fn extract_general<const W: usize, const POW2: bool, S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    phases: &PhaseTable<T, W>,
    geometry: &SliceRows<T>,
    grid: &mut [T],
) {
    let n = spec.n();
    let nn = n * n;
    let mask = n - 1;
    // `j mod n`, by the mask for a power-of-two side.
    let wrapped = |j: i64| {
        if POW2 {
            j as usize & mask
        } else {
            wrap(j, n)
        }
    };
    let value = |jx: i32, wx: &[T; W], jy: i32, wy: &[T; W], jz: i32, wz: &[T; W]| {
        let xs: [usize; W] = core::array::from_fn(|t| wrapped(jx as i64 + t as i64));
        let mut acc = T::ZERO;
        for (c, wzc) in wz.iter().enumerate() {
            let z = wrapped(jz as i64 + c as i64) * nn;
            let mut acc_y = T::ZERO;
            for (b, wyb) in wy.iter().enumerate() {
                let line = z + wrapped(jy as i64 + b as i64) * n;
                acc_y += *wyb * spec.line_taps(line, &xs, wx);
            }
            acc += *wzc * acc_y;
        }
        acc
    };
    // The mirror `−q` of a point: taps `−j − t`, as in `extract_lines`.
    let mirror = |j: i32| -j - (W as i32 - 1);
    let reversed = |w: &[T; W]| -> [T; W] { core::array::from_fn(|t| w[W - 1 - t]) };
    geometry.for_each_fixed_pair::<W, POW2>(n, grid, |y, plus, minus| {
        let (jx, wx) = phases.taps_fixed_point(y[0]);
        let (jy, wy) = phases.taps_fixed_point(y[1]);
        let (jz, wz) = phases.taps_fixed_point(y[2]);
        let direct = if plus {
            value(jx, &wx, jy, &wy, jz, &wz)
        } else {
            T::ZERO
        };
        let mirrored = if minus {
            let (rx, ry, rz) = (reversed(&wx), reversed(&wy), reversed(&wz));
            value(mirror(jx), &rx, mirror(jy), &ry, mirror(jz), &rz)
        } else {
            T::ZERO
        };
        (direct, mirrored)
    });
}

/// `j mod n` for any side `n ≥ 1` (one remainder).
#[inline(always)]
fn wrap(j: i64, n: usize) -> usize {
    j.rem_euclid(n as i64) as usize
}

/// `(i + t) mod n` for `i < n` and a tap offset `t < W ≤` [`crate::filter::MAX_WIDTH`]:
/// a conditional subtraction, repeated only on sides below the width.
#[inline(always)]
fn step(i: usize, t: usize, n: usize) -> usize {
    let mut v = i + t;
    while v >= n {
        v -= n;
    }
    v
}
