//! The pieces of the depth-cue and shading model on their own: kernel
//! derivatives, cue weights, the profile fit, and the spectral gradient.

use fvr_core::dht::Twiddles;
use fvr_core::filter::{DerivativeTable, Filter, FilterKind, TABLE_RESOLUTION};
use fvr_core::shading::gradient::{gradient_magnitude, gradient_scratch_len};
use fvr_core::shading::{CueTerms, DepthCue};
use fvr_core::volume::DenseVolume;
use fvr_engine::volume::phantom::{sample, Gaussian, Phantom};
use fvr_host::reference::snr_db;

/// `k'` in closed form against central differences of `k` (step 1e-5:
/// truncation ≈ h²/6·|k'''| ≈ 1e-9, rounding ≈ ε/h ≈ 2e-11), away from the
/// kinks of the piecewise kernels.
#[test]
fn kernel_derivative_matches_finite_differences() {
    let h = 1e-5;
    for kind in FilterKind::ALL {
        if kind == FilterKind::Nearest {
            continue;
        }
        for os in [1, 2] {
            let f = Filter::new(kind, os).unwrap();
            let half = f.width() as f64 / 2.0;
            let mut t = -half + 0.01;
            while t < half - 0.01 {
                let near_kink = (t.abs() - t.abs().round()).abs() < 2.0 * h;
                if !near_kink {
                    let fd = (f.kernel(t + h) - f.kernel(t - h)) / (2.0 * h);
                    let exact = f.kernel_derivative(t);
                    assert!(
                        (fd - exact).abs() < 1e-7,
                        "{kind:?} os{os} t={t}: {exact} vs {fd}"
                    );
                }
                t += 0.0137;
            }
        }
    }
}

/// The table reproduces `k'` within linear interpolation's `Δ²/8·max|k'''|`
/// (Δ = 1/1024), `k'''` estimated by differences of `k'`, plus f32 rounding.
#[test]
fn derivative_table_within_interpolation_bound() {
    let delta = 1.0 / TABLE_RESOLUTION as f64;
    for kind in [
        FilterKind::Cubic,
        FilterKind::Kb3,
        FilterKind::Kb4,
        FilterKind::Kb6,
    ] {
        let f = Filter::new(kind, 2).unwrap();
        let table = DerivativeTable::<f64>::new(f).unwrap();
        let half = f.width() as f64 / 2.0;
        let samples = 4000;
        let (mut k3, mut err) = (0.0f64, 0.0f64);
        for s in 1..samples {
            let t = -half + 2.0 * half * s as f64 / samples as f64;
            let e = 1e-3;
            let second = (f.kernel_derivative(t + e) - 2.0 * f.kernel_derivative(t)
                + f.kernel_derivative(t - e))
                / (e * e);
            if (t.abs() - 1.0).abs() > 2.0 * e && t.abs() > 2.0 * e {
                k3 = k3.max(second.abs());
            }
            err = err.max((table.eval(t) - f.kernel_derivative(t)).abs());
        }
        let bound = delta * delta / 8.0 * k3 * 1.5 + 1e-12;
        assert!(
            err <= bound,
            "{kind:?}: error {err:e} above bound {bound:e}"
        );
    }
    assert!(DerivativeTable::<f32>::new(Filter::new(FilterKind::Nearest, 1).unwrap()).is_err());
}

#[test]
fn linear_and_sine_cues_pass_through_front_and_back() {
    let r = 32.0;
    for (front, back) in [(1.0, 0.0), (0.2, 1.0), (1.0, 0.5), (0.7, 0.7)] {
        for cue in [
            DepthCue::Linear { front, back },
            DepthCue::Sine { front, back },
        ] {
            let terms = CueTerms::new(&cue, r).unwrap();
            assert!((terms.weight(-r) - front).abs() < 1e-12, "{cue:?}");
            assert!((terms.weight(r) - back).abs() < 1e-12, "{cue:?}");
        }
    }
}

/// The sine and linear cues from 1 at the front to `back`, over radius `r`.
fn sine_and_linear(back: f64, r: f64) -> (CueTerms, CueTerms) {
    let terms = |cue| CueTerms::new(&cue, r).unwrap();
    (
        terms(DepthCue::Sine { front: 1.0, back }),
        terms(DepthCue::Linear { front: 1.0, back }),
    )
}

/// The documented distance of the sine cue from the linear one: for 1,0 it
/// is `sin(π(R − t)/4R)`, at most 0.2105 above the ramp, near t = −0.121R;
/// for 1,0.5 at most 0.1163.
#[test]
fn sine_cue_departs_from_linear_as_documented() {
    let r = 50.0;
    let (sine, linear) = sine_and_linear(0.0, r);
    let (mut worst, mut at) = (0.0f64, 0.0);
    for s in 0..=10000 {
        let t = -r + 2.0 * r * s as f64 / 10000.0;
        let expected = (std::f64::consts::PI * (r - t) / (4.0 * r)).sin();
        assert!((sine.weight(t) - expected).abs() < 1e-12);
        let d = sine.weight(t) - linear.weight(t);
        if d > worst {
            (worst, at) = (d, t);
        }
    }
    assert!((worst - 0.2105).abs() < 1e-3, "{worst}");
    assert!((at / r + 0.121).abs() < 2e-3, "{at}");
    let (sine, linear) = sine_and_linear(0.5, r);
    let worst = (0..=10000)
        .map(|s| -r + 2.0 * r * s as f64 / 10000.0)
        .map(|t| sine.weight(t) - linear.weight(t))
        .fold(0.0f64, f64::max);
    assert!((worst - 0.1163).abs() < 1e-3, "{worst}");
}

/// The cosine fit of a piecewise-linear profile converges like `1/M` at a
/// kink (coefficients fall as `1/m²`): a tent 0.2, 1, 0.2 is within 0.05 at
/// 8 harmonics and closer at 16, and matches away from the kink sooner.
#[test]
fn profile_fit_converges_to_the_given_weights() {
    let r = 40.0;
    let tent = |t: f64| 1.0 - 0.8 * (t / r).abs();
    let max_error = |harmonics| {
        let cue = DepthCue::Profile {
            weights: [0.2, 1.0, 0.2].into_iter().collect(),
            harmonics,
        };
        let terms = CueTerms::new(&cue, r).unwrap();
        (0..=400)
            .map(|s| -r + 2.0 * r * s as f64 / 400.0)
            .map(|t| (terms.weight(t) - tent(t)).abs())
            .fold(0.0f64, f64::max)
    };
    let (e8, e16) = (max_error(8), max_error(16));
    assert!(e8 < 0.05, "{e8}");
    assert!(e16 < 0.6 * e8, "{e16} vs {e8}");
}

/// The spectral gradient of a sampled Gaussian (σ ≥ 2.5, well inside its
/// box, so band-limited to −100 dB) against the analytic `|∇f|` at the
/// samples.
#[test]
fn spectral_gradient_magnitude_matches_analytic() {
    let dims = [40, 48, 36];
    let g = Gaussian {
        amplitude: 1.0,
        center: [19.3, 24.6, 17.8],
        sigmas: [2.5, 3.5, 3.0],
        rotation: [[0.8, -0.6, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 1.0]],
    };
    let volume = sample(&g, dims);
    let source = DenseVolume::new(dims, &volume.data).unwrap();
    let len = gradient_scratch_len(dims);
    let mut tw_buf = vec![0.0f64; Twiddles::<f64>::buffer_len(len)];
    let tw = Twiddles::new(&mut tw_buf, len).unwrap();
    let mut line = vec![0.0f64; len];
    let mut out = vec![0.0f64; volume.data.len()];
    gradient_magnitude(&source, &mut out, &mut line, &tw).unwrap();
    let mut exact = Vec::with_capacity(out.len());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = [i as f64, j as f64, k as f64];
                let h = 1e-4;
                let grad: Vec<f64> = (0..3)
                    .map(|a| {
                        let (mut lo, mut hi) = (p, p);
                        lo[a] -= h;
                        hi[a] += h;
                        (g.density(hi) - g.density(lo)) / (2.0 * h)
                    })
                    .collect();
                exact.push(grad.iter().map(|x| x * x).sum::<f64>().sqrt());
            }
        }
    }
    let snr = snr_db(&exact, &out);
    assert!(snr >= 90.0, "{snr:.1} dB");
}
