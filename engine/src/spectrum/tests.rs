//! The fast preparation ([`crate::spectrum::prepare`]) against the core's
//! in-place one ([`OwnedSpectrum::prepare_in_place`]) in f64.

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::num::Sample;
use half::f16;

use crate::image::snr_db;
use crate::memory::{LimitSource, MemoryLimit};
use crate::spectrum::prepare::{fast_budget, prepare_fast};
use crate::spectrum::{AnySpectrum, OwnedSpectrum, PipelineError};
use crate::volume::phantom::{sample, GaussianMixture};
use crate::volume::Volume;

/// Uniform values in `[−1, 1)` from a fixed-seed linear congruential stream,
/// with a positive offset so that the DC dominates as in real volumes.
fn random_volume(dims: [usize; 3], seed: u64) -> Volume {
    let mut state = seed;
    let count = dims.iter().product();
    let data = (0..count)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            0.5 + ((state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0)
        })
        .collect();
    Volume::new(dims, data)
}

/// `√(Σ(a − b)² / Σb²)` of two spectra, each divided by its scale.
fn relative_rms<S: Sample>(a: &OwnedSpectrum<S>, b: &OwnedSpectrum<f64>) -> f64 {
    assert_eq!(a.n(), b.n());
    let (mut err, mut sig) = (0.0f64, 0.0f64);
    for (x, y) in a.data().iter().zip(b.data()) {
        let (x, y) = (x.to_f64() / a.scale(), y / b.scale());
        err += (x - y) * (x - y);
        sig += y * y;
    }
    (err / sig).sqrt()
}

const CASES: [([usize; 3], FilterKind, u32); 6] = [
    ([5, 7, 3], FilterKind::Kb4, 1),
    ([5, 7, 3], FilterKind::Linear, 2),
    ([33, 20, 17], FilterKind::Kb3, 1),
    ([33, 20, 17], FilterKind::Kb6, 2),
    ([16, 16, 16], FilterKind::Cubic, 1),
    ([9, 30, 2], FilterKind::Kb5, 2),
];

/// `T`-arithmetic fast spectra stored in f64 agree with the core's f64
/// pipeline to `c·ε·log₂N` relative RMS, `N = n³`, `ε` the unit roundoff of
/// `T`. The `log₂N` radix stages each add at most a few `ε` of worst-case
/// error, but their roundings are nearly independent, so the RMS grows
/// like `ε·√log₂N`; the premultiplied input (three table factors and three
/// products, each rounded once) adds about `ε`. Measured: 1.7–2.9 `ε` in
/// f32 and 2–4.8 `ε` in f64 at `log₂N` = 9 to 21. `c = 1/2` keeps a factor
/// 2 above the worst of these, while a wrong sign or index costs O(1).
fn agrees_with_core<T: crate::dht::real::FftReal>(eps: f64) {
    for (seed, (dims, kind, oversample)) in CASES.into_iter().enumerate() {
        let filter = Filter::new(kind, oversample).unwrap();
        let volume = random_volume(dims, seed as u64 + 1);
        let reference = OwnedSpectrum::<f64>::prepare_in_place::<f64>(&volume, filter).unwrap();
        let fast = OwnedSpectrum::<f64>::prepare::<T>(&volume, filter).unwrap();
        assert_eq!(fast.scale(), reference.scale(), "{dims:?} {kind:?}");
        let n = fast.n() as f64;
        let bound = 0.5 * eps * (n * n * n).log2();
        let rel = relative_rms(&fast, &reference);
        assert!(
            rel <= bound,
            "{dims:?} {kind:?}/{oversample}: {rel:e} > {bound:e}"
        );
    }
}

#[test]
fn fast_f32_agrees_with_core_f64() {
    agrees_with_core::<f32>(2f64.powi(-24));
}

#[test]
fn fast_f64_agrees_with_core_f64() {
    agrees_with_core::<f64>(2f64.powi(-53));
}

#[test]
fn fast_f16_keeps_the_rounding_contract() {
    // One rounding to f16 at the end: images within 70 dB of the f64
    // pipeline's, and the stored spectrum itself within `3/u²` (71 dB for
    // u = 2^−11, the SNR of one uniform rounding) less 1 dB.
    let volume = sample(&GaussianMixture::random(7, 32, 6), [32, 27, 30]);
    for (kind, oversample) in [(FilterKind::Kb4, 1), (FilterKind::Kb6, 2)] {
        let filter = Filter::new(kind, oversample).unwrap();
        let fast = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        let reference = OwnedSpectrum::<f64>::prepare_in_place::<f64>(&volume, filter).unwrap();
        let stored = -20.0 * relative_rms(&fast, &reference).log10();
        assert!(stored >= 70.0, "{kind:?}/{oversample}: {stored:.2} dB");
        let n = fast.n() / oversample as usize;
        let (f, r) = (AnySpectrum::F16(fast), AnySpectrum::F64(reference));
        for dir in [[1.0, 0.0, 0.0], [0.6, -0.3, 0.74]] {
            let view = View::along(dir);
            let image = f.render(&view, n, n).unwrap();
            let want = r.render(&view, n, n).unwrap();
            let snr = snr_db(&want, &image);
            assert!(snr >= 70.0, "{kind:?}/{oversample} {dir:?}: {snr:.2} dB");
        }
    }
}

#[test]
fn fast_path_names_the_first_non_finite_voxel() {
    let mut volume = random_volume([6, 7, 8], 3);
    volume.data[3 + 6 * (4 + 7 * 5)] = f32::NAN;
    volume.data[1 + 6 * (2 + 7 * 6)] = f32::INFINITY;
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let fast = prepare_fast::<f32, f16>(&volume, filter).unwrap_err();
    let core = OwnedSpectrum::<f16>::prepare_in_place::<f32>(&volume, filter).unwrap_err();
    assert_eq!(fast.to_string(), core.to_string());
    assert!(fast.to_string().contains("(3, 4, 5)"), "{fast}");
}

#[test]
fn fast_budget_counts_the_half_spectrum() {
    let n = 256u64;
    let b = fast_budget::<f32, f16>(256);
    // f16 storage 2n³ plus the complex f32 half spectrum 8·(n/2+1)·n².
    let floor = 2 * n * n * n + 8 * (n / 2 + 1) * n * n;
    assert!(b.total() >= floor && b.total() < floor + (64 << 20));
    let limit = MemoryLimit {
        bytes: floor,
        source: LimitSource::Flag,
    };
    let e = b.check(limit, "hint").unwrap_err();
    assert_eq!(e.items[0].0, "half spectrum (complex)");
    assert!(matches!(
        prepare_fast::<f32, f16>(
            &Volume::filled([1, 1, 1 << 20], 0.0),
            Filter::new(FilterKind::Kb4, 1).unwrap()
        ),
        Err(PipelineError::OutOfMemory { .. })
    ));
}

/// The storage SNR estimate's `Σg²` is the stored spectrum's energy, as a
/// value-by-value f64 sum computes it, for f16, f32 and f64 storage.
#[test]
fn storage_snr_estimate_sums_the_stored_energy() {
    let volume = random_volume([20, 18, 16], 7);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let sum: f64 = volume.data.iter().map(|&v| v as f64).sum();
    fn naive<S: Sample>(s: &OwnedSpectrum<S>, sum: f64, u: f64) -> f64 {
        let n = s.n() as f64;
        let g2: f64 = s
            .data()
            .iter()
            .map(|v| (v.to_f64() / s.scale()).powi(2))
            .sum::<f64>()
            / (n * n * n);
        10.0 * ((sum * sum / (n * n)) / (4.0 * u * u / 3.0 * g2)).log10()
    }
    let u = 2f64.powi(-11);
    let f16s = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
    let f32s = OwnedSpectrum::<f32>::prepare::<f32>(&volume, filter).unwrap();
    let f64s = OwnedSpectrum::<f64>::prepare::<f64>(&volume, filter).unwrap();
    for (got, want) in [
        (f16s.storage_snr_estimate_db(sum, u), naive(&f16s, sum, u)),
        (f32s.storage_snr_estimate_db(sum, u), naive(&f32s, sum, u)),
        (f64s.storage_snr_estimate_db(sum, u), naive(&f64s, sum, u)),
    ] {
        assert!(want.is_finite() && want > 20.0, "{want}");
        assert!((got - want).abs() < 1e-9, "{got} against {want}");
    }
    // On one thread and on the default pool: the same bits.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let single = one.install(|| f16s.storage_snr_estimate_db(sum, u));
    assert_eq!(
        single.to_bits(),
        f16s.storage_snr_estimate_db(sum, u).to_bits()
    );
}
