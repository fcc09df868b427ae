//! The walks' sums on x86-64 cores with F16C, for binary16 spectra summed
//! in `f32`. In a point's tap sum ([`crate::slice::taps::tap_sum_on`],
//! the exact walk), each run of `W ≤ 8`
//! taps along x is read as one 16-byte load, widened by one `vcvtph2ps`
//! and multiplied by the x weights in one `vmulps`, instead of tap by tap
//! through the software conversion
//! ([`fvr_core::num::f16_bits_to_f32_finite`]).
//!
//! The values are the same bits as the scalar sum's: the widening is exact
//! (every binary16 is a binary32), each lane's product is the same IEEE
//! product, and the products are then added one by one in the scalar
//! order, from zero. Lanes past `W` are read (they belong to the next taps
//! of the line, or the next line) and never used. The strip walk's
//! reduction of a plane ([`scale_add`]) runs eight cells a step the same
//! way.
//!
//! [`fused_sum`] is the same tap sum reordered for the default walk,
//! which promises the core's values to within rounding, not bit for bit:
//! the `W × W` x-runs accumulate in lanes by fused multiply-adds and meet
//! in one horizontal sum, a quarter of the exact order's operations at kb5.
//!
//! The features are detected at run time ([`available`],
//! [`fused_available`]); the sums are `#[target_feature]` functions, so
//! each call is an `unsafe` block, the only ones in this crate
//! ([`crate::slice::exact`], [`crate::slice::strip`]).

use core::arch::x86_64::{
    __m128i, __m256, _mm256_add_ps, _mm256_castps256_ps128, _mm256_cvtph_ps, _mm256_extractf128_ps,
    _mm256_fmadd_ps, _mm256_mul_ps, _mm256_set1_ps, _mm256_setzero_ps, _mm_add_ps, _mm_add_ss,
    _mm_and_si128, _mm_cvtss_f32, _mm_movehl_ps, _mm_shuffle_ps,
};

use fvr_core::num::{Real, Sample};

use crate::slice::taps::{run_starts, Side};

/// Whether this core has F16C and AVX, and `S` and `T` are binary16
/// storage summed in `f32`: the case [`tap_sum`] serves.
pub(crate) fn available<S: Sample, T: Real>() -> bool {
    S::NAME == "f16"
        && core::mem::size_of::<T>() == 4
        && std::arch::is_x86_feature_detected!("f16c")
        && std::arch::is_x86_feature_detected!("avx")
}

/// The starts of a point's runs ([`run_starts`]) when each run fits one
/// 8-lane read: `W ≤ 8` and the run does not wrap around the cube.
#[inline(always)]
fn lane_runs<const W: usize, const POW2: bool>(
    side: Side<POW2>,
    taps: [i32; 3],
) -> Option<([usize; W], [usize; W], usize)> {
    let (lines, planes, x0) = run_starts::<W, POW2>(side, taps);
    (W <= 8 && x0 + W <= side.n).then_some((lines, planes, x0))
}

/// [`crate::slice::taps::tap_sum_on`] for `W ≤ 8`, bit for bit, with each
/// x-run widened and multiplied in lanes. Only for binary16 `S` and `f32`
/// `T` ([`available`]); a run that wraps around the cube or ends within
/// 8 values of the data's end is summed tap by tap.
#[target_feature(enable = "avx,f16c")]
pub(crate) fn tap_sum<const W: usize, const POW2: bool, S: Sample, T: Real>(
    data: &[S],
    side: Side<POW2>,
    taps: [i32; 3],
    [wx, wy, wz]: [&[T; W]; 3],
) -> T {
    let Some((lines, planes, x0)) = lane_runs::<W, POW2>(side, taps) else {
        return crate::slice::taps::tap_sum_on(data, side, taps, [wx, wy, wz]);
    };
    // `T` is f32 here: these conversions are exact and fold away.
    let mut lanes = [0.0f32; 8];
    for t in 0..W {
        lanes[t] = wx[t].to_f64() as f32;
    }
    let weights: __m256 = bytemuck::cast(lanes);
    let mut acc = 0.0f32;
    for c in 0..W {
        // The plane's runs widened and multiplied first, then their sums
        // side by side: each run's products still added in order, from
        // zero, but the W chains of additions overlap.
        let mut products = [[0.0f32; 8]; W];
        for (b, p) in products.iter_mut().enumerate() {
            let start = planes[c] + lines[b] + x0;
            if let Some(run) = data.get(start..start + 8) {
                let bits: [u16; 8] =
                    core::array::from_fn(|t| run[t].pattern16().unwrap_or_default());
                let wide = _mm256_cvtph_ps(bytemuck::cast::<[u16; 8], __m128i>(bits));
                *p = bytemuck::cast(_mm256_mul_ps(wide, weights));
            } else if let Some(run) = data.get(start..start + W) {
                for t in 0..W {
                    p[t] = lanes[t] * run[t].to_f32_raw();
                }
            }
        }
        let mut acc_x = [0.0f32; W];
        for t in 0..W {
            for b in 0..W {
                acc_x[b] += products[b][t];
            }
        }
        let mut acc_y = 0.0f32;
        for b in 0..W {
            acc_y += wy[b].to_f64() as f32 * acc_x[b];
        }
        acc += wz[c].to_f64() as f32 * acc_y;
    }
    T::from_f64(acc as f64)
}

/// Whether this core also has FMA, for [`fused_sum`]: [`available`] and
/// the `vfmadd` instructions.
pub(crate) fn fused_available<S: Sample, T: Real>() -> bool {
    available::<S, T>() && std::arch::is_x86_feature_detected!("fma")
}

/// [`crate::slice::taps::tap_sum_on`] for `W ≤ 8`, reordered: per plane
/// `c`, the plane's x-runs (lanes `t`, widened, the lanes past `W`
/// zeroed) accumulate `Σ_b wy_b·run_b` by fused multiply-adds; the planes
/// accumulate `Σ_c wz_c·plane_c` the same way; then `Σ_t wx_t·acc_t` in
/// one multiply and a horizontal sum (lanes 0 + 4, 1 + 5, … then halves).
/// Only for binary16 `S` and `f32` `T` ([`fused_available`]); a run that
/// wraps around the cube is summed by the core's order.
///
/// Every product `w·c` is the same and each of the `2W + 4` roundings on
/// its way to the value is at most `u = ε/2` relative, so the value is the
/// exact one to within `(2W + 4)·u·Σ|w·c|` and the core's to within
/// `(5W + 5)·u·Σ|w·c|` (the core's own sum rounds `3W + 1` times).
#[target_feature(enable = "avx,f16c,fma")]
pub(crate) fn fused_sum<const W: usize, const POW2: bool, S: Sample, T: Real>(
    data: &[S],
    side: Side<POW2>,
    taps: [i32; 3],
    [wx, wy, wz]: [&[T; W]; 3],
) -> T {
    let Some((lines, planes, x0)) = lane_runs::<W, POW2>(side, taps) else {
        return crate::slice::taps::tap_sum_on(data, side, taps, [wx, wy, wz]);
    };
    // The lanes past `W` hold the next taps of the line (or of the next
    // line): zeroed as bits, so that no value there, finite or not, enters.
    let keep: __m128i =
        bytemuck::cast::<[u16; 8], _>(core::array::from_fn(|t| if t < W { u16::MAX } else { 0 }));
    let mut acc = _mm256_setzero_ps();
    for c in 0..W {
        let mut plane = _mm256_setzero_ps();
        for b in 0..W {
            let start = planes[c] + lines[b] + x0;
            // The last runs of the data, within 8 values of its end, are
            // read value by value (`x0 + W ≤ n`: the run itself is there).
            let bits: [u16; 8] = match data.get(start..start + 8) {
                Some(run) => core::array::from_fn(|t| run[t].pattern16().unwrap_or_default()),
                None => core::array::from_fn(|t| {
                    data.get(start + t)
                        .filter(|_| t < W)
                        .and_then(|v| v.pattern16())
                        .unwrap_or_default()
                }),
            };
            let run = _mm_and_si128(bytemuck::cast::<[u16; 8], __m128i>(bits), keep);
            let weight = _mm256_set1_ps(wy[b].to_f64() as f32);
            plane = _mm256_fmadd_ps(_mm256_cvtph_ps(run), weight, plane);
        }
        acc = _mm256_fmadd_ps(plane, _mm256_set1_ps(wz[c].to_f64() as f32), acc);
    }
    let x: [f32; 8] = core::array::from_fn(|t| if t < W { wx[t].to_f64() as f32 } else { 0.0 });
    let lanes = _mm256_mul_ps(acc, bytemuck::cast(x));
    let four = _mm_add_ps(
        _mm256_castps256_ps128(lanes),
        _mm256_extractf128_ps::<1>(lanes),
    );
    let two = _mm_add_ps(four, _mm_movehl_ps(four, four));
    let one = _mm_add_ss(two, _mm_shuffle_ps::<1>(two, two));
    T::from_f64(f64::from(_mm_cvtss_f32(one)))
}

/// `cells[i] = weight·src[i]` (`first`), else `cells[i] += weight·src[i]`,
/// for binary16 `src` and `f32` `T` ([`available`]): the strip walk's
/// reduction of one plane ([`crate::slice::strip`]), eight cells a step,
/// each cell's product and sum the scalar loop's, bit for bit.
#[target_feature(enable = "avx,f16c")]
pub(crate) fn scale_add<S: Sample, T: Real>(weight: T, src: &[S], cells: &mut [T], first: bool) {
    let w = weight.to_f64() as f32;
    let weights: __m256 = bytemuck::cast([w; 8]);
    let mut outs = cells.chunks_exact_mut(8);
    let mut ins = src.chunks_exact(8);
    for (o, s) in (&mut outs).zip(&mut ins) {
        let bits: [u16; 8] = core::array::from_fn(|t| s[t].pattern16().unwrap_or_default());
        let products = _mm256_mul_ps(
            _mm256_cvtph_ps(bytemuck::cast::<[u16; 8], __m128i>(bits)),
            weights,
        );
        let sums = if first {
            products
        } else {
            let old: [f32; 8] = core::array::from_fn(|t| o[t].to_f64() as f32);
            _mm256_add_ps(bytemuck::cast(old), products)
        };
        let sums: [f32; 8] = bytemuck::cast(sums);
        for (o, v) in o.iter_mut().zip(sums) {
            *o = T::from_f64(v as f64);
        }
    }
    for (o, s) in outs.into_remainder().iter_mut().zip(ins.remainder()) {
        let p = w * s.to_f32_raw();
        *o = T::from_f64(if first { p } else { o.to_f64() as f32 + p } as f64);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slice::taps::tap_sum_on;
    use half::f16;

    /// Every kind of binary16 the spectra hold: normals of both signs over
    /// the whole range, subnormals and zeros (a fixed LCG).
    fn samples(len: usize) -> Vec<f16> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        (0..len)
            .map(|_| {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                // Exponent field 0..=30: no infinities or NaNs.
                let bits = (state >> 48) as u16;
                let exponent = (bits >> 10) & 0x1f;
                f16::from_bits(if exponent == 31 { bits & 0x83ff } else { bits })
            })
            .collect()
    }

    /// x, y and z weights of width `W`, of both signs and several scales.
    fn weights<const W: usize>() -> [[f32; W]; 3] {
        let w = [0.37, -1.25, 2.5e-3, 0.9, -0.061, 1.5, 0.25, -3.0];
        [0, 3, 5].map(|shift| core::array::from_fn(|t| w[(t + shift) % 8]))
    }

    /// `(Σ w·c, Σ|w·c|)` of a point's taps in f64: the exact value (every
    /// product of an f32 weight triple and a binary16 is exact in f64 to
    /// well below the bound) and the mass the bound scales with.
    fn exact_sum<const W: usize>(
        data: &[f16],
        n: usize,
        [x, y, z]: [i32; 3],
        [wx, wy, wz]: [&[f32; W]; 3],
    ) -> (f64, f64) {
        let at = |i: i32, k: usize| (i as usize + k) % n;
        let (mut sum, mut mass) = (0.0, 0.0);
        for c in 0..W {
            for b in 0..W {
                for t in 0..W {
                    let v = data[(at(z, c) * n + at(y, b)) * n + at(x, t)].to_f64();
                    let w = f64::from(wx[t]) * f64::from(wy[b]) * f64::from(wz[c]);
                    sum += w * v;
                    mass += (w * v).abs();
                }
            }
        }
        (sum, mass)
    }

    #[test]
    fn fused_sums_are_exact_to_their_roundings_and_read_no_other_lane() {
        if !fused_available::<f16, f32>() {
            eprintln!("this core has no F16C, AVX and FMA: nothing to check");
            return;
        }
        assert!(!fused_available::<f16, f64>() && !fused_available::<f32, f32>());
        let n = 16;
        let data = samples(n * n * n);
        fn check<const W: usize>(data: &[f16], n: usize) -> usize {
            let [wx, wy, wz] = weights::<W>();
            let side = Side::<true> { n };
            let u = f64::from(f32::EPSILON) / 2.0;
            let mut reordered = 0;
            for z in [0, 7, n as i32 - 2, n as i32 - 1] {
                for y in [0, 5, n as i32 - 1] {
                    for x in -2..n as i32 {
                        let taps = [x, y, z];
                        let wrapped = [x.rem_euclid(n as i32), y, z];
                        // SAFETY: the caller checked `fused_available`.
                        #[allow(unsafe_code)]
                        let fused = unsafe { fused_sum(data, side, taps, [&wx, &wy, &wz]) };
                        let (sum, mass) = exact_sum(data, n, wrapped, [&wx, &wy, &wz]);
                        let bound = (2 * W + 4) as f64 * u * mass * 1.001;
                        let err = (f64::from(fused) - sum).abs();
                        assert!(err <= bound, "W {W} at {taps:?}: {err:e} > {bound:e}");
                        let core = tap_sum_on(data, side, taps, [&wx, &wy, &wz]);
                        reordered += usize::from(core.to_bits() != fused.to_bits());
                    }
                }
            }
            reordered
        }
        // Not vacuous: the reordered sums differ from the core's somewhere.
        assert!(check::<3>(&data, n) > 0);
        assert!(check::<4>(&data, n) > 0);
        assert!(check::<5>(&data, n) > 0);
        assert!(check::<6>(&data, n) > 0);
        assert!(check::<8>(&data, n) > 0);

        // A point's runs in a cube of NaN and infinities: the lanes past
        // `W`, read and dropped, change nothing.
        let mut poisoned: Vec<f16> = (0..n * n * n)
            .map(|i| if i % 2 == 0 { f16::NAN } else { f16::INFINITY })
            .collect();
        let (wx, wy, wz) = (
            [0.5f32, -0.25, 2.0],
            [1.0f32, 0.75, -0.5],
            [0.125f32, 1.5, 1.0],
        );
        let taps = [3, 4, 5];
        for c in 0..3 {
            for b in 0..3 {
                for t in 0..3 {
                    poisoned[((5 + c) * n + 4 + b) * n + 3 + t] =
                        f16::from_f32((c * 9 + b * 3 + t) as f32);
                }
            }
        }
        let side = Side::<true> { n };
        // SAFETY: checked above.
        #[allow(unsafe_code)]
        let fused = unsafe { fused_sum(&poisoned, side, taps, [&wx, &wy, &wz]) };
        let core = tap_sum_on(&poisoned, side, taps, [&wx, &wy, &wz]);
        assert!(fused.is_finite() && fused == core, "{fused} against {core}");
    }

    #[test]
    fn lane_sums_are_the_scalar_sums_bit_for_bit() {
        if !available::<f16, f32>() {
            eprintln!("this core has no F16C: nothing to compare");
            return;
        }
        assert!(!available::<f16, f64>() && !available::<f32, f32>());
        let n = 16;
        let data = samples(n * n * n);
        fn check<const W: usize>(data: &[f16], n: usize) {
            let [wx, wy, wz] = weights::<W>();
            let side = Side::<true> { n };
            // Every start, those whose runs wrap around the cube included,
            // and the last ones, whose 8-value reads pass the data's end.
            for z in [0, 7, n as i32 - 2, n as i32 - 1] {
                for y in [0, 5, n as i32 - 1] {
                    for x in -2..n as i32 {
                        let taps = [x, y, z];
                        let scalar = tap_sum_on(data, side, taps, [&wx, &wy, &wz]);
                        // SAFETY: the caller checked `available`.
                        #[allow(unsafe_code)]
                        let lanes = unsafe { tap_sum(data, side, taps, [&wx, &wy, &wz]) };
                        assert_eq!(scalar.to_bits(), lanes.to_bits(), "W {W} at {taps:?}");
                    }
                }
            }
        }
        check::<3>(&data, n);
        check::<4>(&data, n);
        check::<5>(&data, n);
        check::<6>(&data, n);
        check::<8>(&data, n);

        for len in [0, 1, 7, 8, 9, 23, 64] {
            let src = &data[100..100 + len];
            let start: Vec<f32> = samples(len).iter().map(|v| v.to_f32() * 3.0).collect();
            for first in [true, false] {
                let mut scalar = start.clone();
                for (o, v) in scalar.iter_mut().zip(src) {
                    let p = -0.73f32 * v.to_f32();
                    *o = if first { p } else { *o + p };
                }
                let mut lanes = start.clone();
                // SAFETY: the caller checked `available`.
                #[allow(unsafe_code)]
                unsafe {
                    scale_add(-0.73f32, src, &mut lanes, first)
                };
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&scalar), bits(&lanes), "len {len}, first {first}");
            }
        }
    }
}
