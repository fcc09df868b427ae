//! Unit tests of the stored formats against the f64 pipeline.

use super::*;
use fvr_engine::volume::phantom::{sample, GaussianMixture};

fn gaussians(n: usize) -> Volume {
    sample(&GaussianMixture::random(1, n, 8), [n, n, n])
}

/// Block encoding rounds every coefficient once: the error is at most
/// half a mantissa step of its block, `2^(e−16)` for Q15 (`2^(e−8)` for
/// Q7), and the exponent is the smallest that holds the block's maximum.
#[test]
fn block_encoding_errs_by_at_most_half_a_step_of_the_block() {
    let volume = gaussians(16);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let src = StoredSpectrum::<f32>::prepare::<f32>(&volume, filter, Rounding::PerPass).unwrap();
    for layout in [
        BlockLayout::Line,
        BlockLayout::Brick(2),
        BlockLayout::Brick(4),
    ] {
        let q = StoredSpectrum::<Q15>::encode(&src, Blocking::Blocks(layout)).unwrap();
        let q7 = StoredSpectrum::<Q7>::encode(&src, Blocking::Blocks(layout)).unwrap();
        let (spec, spec7) = (q.view(), q7.view());
        let exps = spec.blocks().unwrap().exponents();
        let mut block_max = vec![0.0f64; exps.len()];
        for i in 0..src.data.len() {
            let (x, y, z) = (i % 16, (i / 16) % 16, i / 256);
            let b = layout.block_of(16, x, y, z);
            let v = src.data[i] as f64;
            block_max[b] = block_max[b].max(v.abs());
            let e = exps[b] as i32;
            assert!(
                (spec.value(i) - v).abs() <= 2f64.powi(e - 16),
                "{layout:?} {i}"
            );
            let e7 = spec7.blocks().unwrap().exponents()[b] as i32;
            assert!(
                (spec7.value(i) - v).abs() <= 2f64.powi(e7 - 8),
                "{layout:?} {i}"
            );
        }
        for (b, &e) in exps.iter().enumerate() {
            let m = block_max[b];
            if m > 0.0 {
                // Smallest exponent: one less would not hold the maximum.
                assert!(m * 2f64.powi(-(e as i32)) <= 32767.5 / 32768.0);
                assert!(m * 2f64.powi(1 - e as i32) > 32767.5 / 32768.0);
            }
        }
    }
}
