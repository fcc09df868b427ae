//! The integer preparation (`Spectrum::prepare_q15`) against the f64
//! preparation of the same volume and filter.
//!
//! # The floor
//! The Q15 model of `dht::fixed` (`6.02·(15 − 3) + 7.78 − 10·log10 L −
//! 20·log10 κ` dB): `L` counts the roundings, the transform's
//! `3·log₂n + 1`, the input's one rounding to Q15, and the three
//! premultipliers' (each within `2^−15` of the largest one, so each at
//! most one Q15 rounding of the input); κ is the worse crest factor
//! (peak / RMS) of the premultiplied volume and of its spectrum, the
//! largest a stage meets.

#[path = "../src/test_support.rs"]
mod test_support;

use fvr_core::dht::fixed::FixedTwiddles;
use fvr_core::dht::Twiddles;
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::num::{BlockLayout, Q15};
use fvr_core::spectrum::{prepare_scratch_len, Q15Storage, Spectrum};
use fvr_core::volume::{padded_size, DenseVolume};
use test_support::snr_db;

/// A smooth blob with fixed-seed noise, `side³` u8 voxels, `i` fastest.
fn volume_u8(side: usize, seed: u32) -> Vec<u8> {
    let mut s = seed;
    let c = side as f64 / 2.0;
    let mut out = Vec::with_capacity(side * side * side);
    for k in 0..side {
        for j in 0..side {
            for i in 0..side {
                let r2 = [i, j, k]
                    .map(|v| (v as f64 + 0.5 - c) / c)
                    .iter()
                    .map(|d| d * d)
                    .sum::<f64>();
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                let noise = (s >> 28) as f64;
                let blob = if r2 < 0.6 { 200.0 * (1.0 - r2) } else { 0.0 };
                out.push((blob + noise).min(255.0) as u8);
            }
        }
    }
    out
}

fn crest(v: &[f64]) -> f64 {
    let peak = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    peak / rms
}

fn floor_db(roundings: f64, crest: f64) -> f64 {
    20.0 * 2f64.log10() * 12.0 + 10.0 * 6f64.log10()
        - 10.0 * roundings.log10()
        - 20.0 * crest.log10()
}

/// The Q15 spectrum as `H` (divided by its scale), its exponents, and the
/// f64 reference `H`, with the reference's premultiplied volume.
struct Run {
    q15: Vec<f64>,
    exponents: Vec<i8>,
    mantissas: Vec<Q15>,
    reference: Vec<f64>,
    input: Vec<f64>,
    n: usize,
}

fn run<V: Copy + Into<f64> + Into<u16>>(dims: [usize; 3], voxels: &[V], oversample: u32) -> Run {
    let volume = DenseVolume::new(dims, voxels).unwrap();
    let (filter, _) = Filter::fit(FilterKind::Kb3, oversample, &volume).unwrap();
    let n = padded_size(dims, oversample).unwrap();
    let mut tw_buf = vec![Q15(0); FixedTwiddles::<Q15>::buffer_len(n)];
    let tw = FixedTwiddles::new(&mut tw_buf, n).unwrap();
    let mut mantissas = vec![Q15(0); n * n * n];
    let mut exponents = vec![0i8; n * n];
    let mut premul = vec![0i32; n];
    let spec = Spectrum::prepare_q15(
        &volume,
        filter,
        Q15Storage {
            mantissas: &mut mantissas,
            exponents: &mut exponents,
            premul: &mut premul,
        },
        &tw,
    )
    .unwrap();
    assert_eq!(spec.blocks().unwrap().layout(), BlockLayout::Line);
    assert_eq!(spec.n(), n);
    let q15: Vec<f64> = (0..n * n * n)
        .map(|i| spec.value(i) / spec.scale())
        .collect();

    let mut tw64 = vec![0.0f64; Twiddles::<f64>::buffer_len(n)];
    let tw64 = Twiddles::new(&mut tw64, n).unwrap();
    let mut data = vec![0.0f64; n * n * n];
    let mut scratch = vec![0.0f64; prepare_scratch_len(n)];
    let f64_spec = Spectrum::prepare(&volume, filter, &mut data, &mut scratch, &tw64).unwrap();
    let reference: Vec<f64> = (0..n * n * n)
        .map(|i| f64_spec.value(i) / f64_spec.scale())
        .collect();
    // The premultiplied volume: the reference's inverse.
    let mut input = reference.clone();
    let mut scratch = vec![0.0f64; fvr_core::dht::dht_3d_scratch_len([n; 3])];
    fvr_core::dht::dht_3d(&mut input, [n; 3], &mut scratch, &tw64).unwrap();
    Run {
        q15,
        exponents,
        mantissas,
        reference,
        input,
        n,
    }
}

#[test]
fn q15_preparation_meets_the_model_against_f64() {
    for (side, oversample) in [(8, 1), (16, 1), (32, 1), (16, 2)] {
        let voxels = volume_u8(side, side as u32);
        let r = run([side; 3], &voxels, oversample);
        let bits = r.n.trailing_zeros() as f64;
        let kappa = crest(&r.input).max(crest(&r.reference));
        let floor = floor_db(3.0 * bits + 5.0, kappa);
        let snr = snr_db(&r.reference, &r.q15);
        println!(
            "{side}³ os {oversample} (n = {}): {snr:.1} dB, floor {floor:.1} (κ {kappa:.1})",
            r.n
        );
        assert!(
            snr >= floor,
            "{side}³ os {oversample}: {snr:.1} < {floor:.1} dB"
        );
    }
}

/// 64³, the device's size: `cargo test -p fvr-core --release --test
/// prepare_q15 -- --ignored --nocapture`.
#[test]
#[ignore]
fn q15_preparation_at_64() {
    let voxels = volume_u8(64, 64);
    let r = run([64; 3], &voxels, 1);
    let kappa = crest(&r.input).max(crest(&r.reference));
    let floor = floor_db(3.0 * 6.0 + 5.0, kappa);
    let snr = snr_db(&r.reference, &r.q15);
    println!("64³: {snr:.1} dB, floor {floor:.1} (κ {kappa:.1})");
    assert!(snr >= floor);
}

#[test]
fn lines_are_normalized_like_encode_blocks() {
    let voxels = volume_u8(16, 3);
    let r = run([16; 3], &voxels, 1);
    for (line, &e) in r.mantissas.chunks_exact(r.n).zip(&r.exponents) {
        let top = line.iter().map(|m| (m.0 as i32).abs()).max().unwrap();
        assert!(line.iter().all(|m| m.0 != i16::MIN));
        if top == 0 {
            assert_eq!(e, i8::MIN);
        } else {
            assert!((16384..=32767).contains(&top), "line peak {top}");
        }
    }
}

#[test]
fn zero_full_scale_and_impulse_volumes() {
    let n = 8;
    // All zero: zeros, every exponent −128.
    let r = run([n; 3], &vec![0u8; n * n * n], 1);
    assert!(r.mantissas.iter().all(|m| m.0 == 0));
    assert!(r.exponents.iter().all(|&e| e == i8::MIN));
    // Full scale, u8 and u16: no wrap, and the model's floor.
    for r in [
        run([n; 3], &vec![255u8; n * n * n], 1),
        run([n; 3], &vec![u16::MAX; n * n * n], 1),
    ] {
        assert!(r.mantissas.iter().all(|m| m.0 != i16::MIN));
        let kappa = crest(&r.input).max(crest(&r.reference));
        let floor = floor_db(3.0 * 3.0 + 5.0, kappa);
        let snr = snr_db(&r.reference, &r.q15);
        assert!(snr >= floor, "full scale: {snr:.1} < {floor:.1} dB");
    }
    // One voxel: its spectrum is a cas pattern of constant magnitude.
    let mut voxels = vec![0u8; n * n * n];
    voxels[3 + n * (5 + n * 2)] = 77;
    let r = run([n; 3], &voxels, 1);
    let kappa = crest(&r.input).max(crest(&r.reference));
    let floor = floor_db(3.0 * 3.0 + 5.0, kappa);
    let snr = snr_db(&r.reference, &r.q15);
    assert!(snr >= floor, "impulse: {snr:.1} < {floor:.1} dB");
}

#[test]
fn short_buffers_are_errors() {
    let voxels = vec![1u8; 512];
    let volume = DenseVolume::new([8; 3], &voxels).unwrap();
    let (filter, _) = Filter::fit(FilterKind::Kb3, 1, &volume).unwrap();
    let mut tw_buf = vec![Q15(0); FixedTwiddles::<Q15>::buffer_len(8)];
    let tw = FixedTwiddles::new(&mut tw_buf, 8).unwrap();
    for (m, e, p) in [(511, 64, 8), (512, 63, 8), (512, 64, 7)] {
        let (mut mantissas, mut exponents, mut premul) =
            (vec![Q15(0); m], vec![0i8; e], vec![0i32; p]);
        let storage = Q15Storage {
            mantissas: &mut mantissas,
            exponents: &mut exponents,
            premul: &mut premul,
        };
        assert!(Spectrum::prepare_q15(&volume, filter, storage, &tw).is_err());
    }
    let mut short_tw = vec![Q15(0); FixedTwiddles::<Q15>::buffer_len(4)];
    let short_tw = FixedTwiddles::new(&mut short_tw, 4).unwrap();
    let (mut mantissas, mut exponents, mut premul) = (vec![Q15(0); 512], vec![0i8; 64], vec![0; 8]);
    let storage = Q15Storage {
        mantissas: &mut mantissas,
        exponents: &mut exponents,
        premul: &mut premul,
    };
    assert!(Spectrum::prepare_q15(&volume, filter, storage, &short_tw).is_err());
}
