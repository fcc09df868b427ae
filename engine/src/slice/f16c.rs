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
//! The features are detected at run time ([`available`]); the sums are
//! `#[target_feature]` functions, so each call is an `unsafe` block, the
//! only ones in this crate ([`crate::slice::exact`],
//! [`crate::slice::strip`]).

use core::arch::x86_64::{__m128i, __m256, _mm256_add_ps, _mm256_cvtph_ps, _mm256_mul_ps};

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
    let (lines, planes, x0) = run_starts::<W, POW2>(side, taps);
    if W > 8 || x0 + W > side.n {
        return crate::slice::taps::tap_sum_on(data, side, taps, [wx, wy, wz]);
    }
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

    #[test]
    fn lane_sums_are_the_scalar_sums_bit_for_bit() {
        if !available::<f16, f32>() {
            eprintln!("this core has no F16C: nothing to compare");
            return;
        }
        assert!(!available::<f16, f64>() && !available::<f32, f32>());
        let n = 16;
        let data = samples(n * n * n);
        let weights: [f32; 8] = [0.37, -1.25, 2.5e-3, 0.9, -0.061, 1.5, 0.25, -3.0];
        fn check<const W: usize>(data: &[f16], n: usize, w: &[f32; 8]) {
            let wx: [f32; W] = core::array::from_fn(|t| w[t]);
            let wy: [f32; W] = core::array::from_fn(|t| w[(t + 3) % 8]);
            let wz: [f32; W] = core::array::from_fn(|t| w[(t + 5) % 8]);
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
        check::<3>(&data, n, &weights);
        check::<4>(&data, n, &weights);
        check::<5>(&data, n, &weights);
        check::<6>(&data, n, &weights);
        check::<8>(&data, n, &weights);

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
