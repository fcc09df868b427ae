//! Adaptive filtering (paper §4): the tolerance holds, the marks are what
//! the paper defines, and the statistics add up.

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::slice::adaptive::{mark, marks_words, threshold_for, Marks};
use fvr_engine::slice::adaptive::{AdaptiveMarks, AdaptiveSettings, Bound, Cheaper, Level};
use fvr_engine::spectrum::{AnySpectrum, OwnedSpectrum};
use fvr_engine::volume::phantom::{sample, GaussianMixture, SheppLogan};
use fvr_host::options::{parse_chain, parse_tolerance};
use fvr_host::reference::snr_db;
use fvr_tests::mixture_spectrum;
use half::f16;

/// Adaptive settings with the 1³ filter and the given bound, every view
/// walked adaptively (never the plain walk's fallback, whose image is the
/// full filter's).
fn nearest(tolerance_db: f64, bound: Bound) -> AdaptiveSettings {
    AdaptiveSettings {
        bound,
        plain_below: 0.0,
        ..AdaptiveSettings::new(tolerance_db)
    }
}

/// An 8³ Gaussian mixture's kb4 spectrum at oversampling 2 (16³): small
/// enough for the naive transforms of [`direct_error_ratio`].
fn eighth_spectrum() -> OwnedSpectrum<f16> {
    let n = 8;
    let volume = sample(&GaussianMixture::random(6, n, 4), [n; 3]);
    OwnedSpectrum::<f16>::prepare::<f32>(&volume, Filter::new(FilterKind::Kb4, 2).unwrap()).unwrap()
}

/// The one-filter chains the bounds are checked for, each with the gain of
/// its level (NaN: the level's own).
const CHEAPER: [(Cheaper, f64); 2] = [
    (Cheaper::Zero, 0.0),
    (Cheaper::Filter(FilterKind::Nearest), f64::NAN),
];

/// The level of the marks of `spec` for the chain of `cheaper` alone at
/// `tol` dB, with `bound` and `probes`.
fn first_level(
    spec: &OwnedSpectrum<f16>,
    cheaper: Cheaper,
    tol: f64,
    bound: Bound,
    probes: usize,
) -> Level {
    let settings = AdaptiveSettings {
        chain: vec![cheaper],
        probes,
        ..nearest(tol, bound)
    };
    AdaptiveMarks::build(spec, &settings).unwrap().levels[0].clone()
}

/// The guarantee: the adaptive image is never further from the full-filter
/// image than the tolerance, over volumes, views, filters, tolerances and
/// both bounds.
#[test]
fn adaptive_images_stay_within_the_requested_tolerance() {
    let n = 64;
    let volumes = [
        (
            "gaussians:1",
            sample(&GaussianMixture::random(1, n, 8), [n; 3]),
        ),
        (
            "gaussians:2",
            sample(&GaussianMixture::random(2, n, 8), [n; 3]),
        ),
        (
            "blobs",
            sample(&GaussianMixture::random_with(4, n, 24, 0.05), [n; 3]),
        ),
        ("shepp-logan", sample(&SheppLogan::new([n; 3]), [n; 3])),
    ];
    let views = [
        View::along([1.0, 0.3, 0.2]),
        View::along([0.0, 1.0, 0.0]),
        View::along([1.0, 1.0, 1.0]),
    ];
    let mut substituted = [0u64; 2];
    for (name, volume) in &volumes {
        for kind in [FilterKind::Kb4, FilterKind::Kb6] {
            let filter = Filter::new(kind, 2).unwrap();
            let spec = OwnedSpectrum::<f16>::prepare::<f32>(volume, filter).unwrap();
            let any = AnySpectrum::F16(spec.clone());
            let fulls: Vec<Vec<f64>> = views.iter().map(|v| any.render(v, n, n).unwrap()).collect();
            for (b, bound) in [Bound::Paper, Bound::Exact].into_iter().enumerate() {
                for tol in [30.0, 40.0, 50.0, 60.0] {
                    let marks = AdaptiveMarks::build(&spec, &nearest(tol, bound)).unwrap();
                    for (view, full) in views.iter().zip(&fulls) {
                        let (image, stats) = marks.render::<f16, f32>(&spec, view, n, n).unwrap();
                        substituted[b] += stats.per_filter[1];
                        let snr = snr_db(full, &image);
                        assert!(
                            snr >= tol,
                            "{name} {kind:?} {bound:?} {view:?} tolerance {tol}: {snr:.1} dB"
                        );
                    }
                }
            }
        }
    }
    // The sweep must exercise the substitution, not only the full filter,
    // and the exact bound must substitute more than the paper's.
    assert!(substituted[0] > 100_000, "{substituted:?}");
    assert!(substituted[1] > substituted[0], "{substituted:?}");
}

/// The guarantee with the zero filter, alone and before the 1³ filter:
/// the images stay within the tolerance, the zero level takes points, and
/// its error energy is eq. 15 with `ĥ₂ = 0` evaluated the slow way.
#[test]
fn zero_filter_chains_stay_within_the_tolerance() {
    let n = 64;
    let volumes = [
        (
            "gaussians:1",
            sample(&GaussianMixture::random(1, n, 8), [n; 3]),
        ),
        ("shepp-logan", sample(&SheppLogan::new([n; 3]), [n; 3])),
    ];
    let views = [View::along([1.0, 0.3, 0.2]), View::along([0.0, 1.0, 0.0])];
    let mut zeroed = 0u64;
    for (name, volume) in &volumes {
        let filter = Filter::new(FilterKind::Kb6, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(volume, filter).unwrap();
        let any = AnySpectrum::F16(spec.clone());
        let fulls: Vec<Vec<f64>> = views.iter().map(|v| any.render(v, n, n).unwrap()).collect();
        for chain in ["zero", "zero,nearest"] {
            for bound in [Bound::Paper, Bound::Exact, Bound::Parseval] {
                for tol in [30.0, 40.0, 50.0] {
                    let settings = AdaptiveSettings {
                        chain: parse_chain(chain).unwrap(),
                        ..nearest(tol, bound)
                    };
                    let marks = AdaptiveMarks::build(&spec, &settings).unwrap();
                    assert_eq!(marks.levels[0].gain, 0.0);
                    for (view, full) in views.iter().zip(&fulls) {
                        let (image, stats) = marks.render::<f16, f32>(&spec, view, n, n).unwrap();
                        zeroed += stats.per_filter[1];
                        let snr = snr_db(full, &image);
                        assert!(
                            snr >= tol,
                            "{name} {chain} {bound:?} {view:?} tolerance {tol}: {snr:.1} dB"
                        );
                    }
                }
            }
        }
    }
    assert!(zeroed > 10_000, "{zeroed}");
    // The zero level's energy, against a direct evaluation at 8³.
    let spec = eighth_spectrum();
    let mut checked = 0;
    for tol in [20.0, 30.0, 40.0] {
        let settings = AdaptiveSettings {
            chain: vec![Cheaper::Zero],
            ..nearest(tol, Bound::Exact)
        };
        let level = &AdaptiveMarks::build(&spec, &settings).unwrap().levels[0];
        if level.threshold == 0.0 {
            continue;
        }
        let ratio = level.error_ratio.unwrap();
        let direct = direct_error_ratio(&spec, level.threshold, 0.0);
        assert!(ratio <= 10f64.powf(-tol / 10.0), "{tol}: {ratio}");
        assert!(
            (direct - ratio).abs() <= 1e-4 * ratio,
            "{tol}: direct {direct} against {ratio}"
        );
        checked += 1;
    }
    assert!(checked >= 2, "{checked}");
}

/// Parseval's bound holds: for the zero filter and for 1³, its threshold
/// (without probes) is not above the exact bound's, and the energy it
/// reports is within the budget and not below eq. 15 evaluated the slow
/// way.
#[test]
fn parseval_bound_bounds_the_error_energy() {
    let spec = eighth_spectrum();
    let mut checked = 0;
    for (cheaper, gain) in CHEAPER {
        for tol in [20.0, 30.0, 40.0] {
            let build = |bound| first_level(&spec, cheaper, tol, bound, 0);
            let (bounded, exact) = (build(Bound::Parseval), build(Bound::Exact));
            assert_eq!(bounded.probes, Some(0));
            assert!(bounded.threshold <= exact.threshold, "{cheaper:?} {tol}");
            if bounded.threshold == 0.0 {
                continue;
            }
            let gain = if gain.is_nan() { bounded.gain } else { gain };
            let ratio = bounded.error_ratio.unwrap();
            let direct = direct_error_ratio(&spec, bounded.threshold, gain);
            assert!(
                ratio <= 10f64.powf(-tol / 10.0),
                "{cheaper:?} {tol}: {ratio}"
            );
            assert!(
                direct <= ratio * (1.0 + 1e-4),
                "{cheaper:?} {tol}: direct {direct} above the bound {ratio}"
            );
            checked += 1;
        }
    }
    assert!(checked >= 3, "{checked}");
}

/// Probes raise Parseval's threshold and keep the guarantee: with 1 or 2
/// probes the threshold is never below Parseval's alone, at most that many
/// transforms run, and eq. 15 evaluated the slow way stays within the
/// budget. An accepted probe's energy is the direct one, against the
/// preparation's floor of the reference (at most 0.12 dB below it,
/// docs/adaptive.md); a seed never beaten keeps Parseval's bound.
#[test]
fn probes_raise_parsevals_threshold_within_budget() {
    let spec = eighth_spectrum();
    let mut raised = 0;
    for (cheaper, gain) in CHEAPER {
        for tol in [20.0, 30.0, 40.0] {
            let build = |probes| first_level(&spec, cheaper, tol, Bound::Parseval, probes);
            let alone = build(0);
            assert!(!alone.evaluated, "{cheaper:?} {tol}");
            for probes in [1, 2] {
                let at = format!("{cheaper:?} {tol} dB, {probes} probes");
                let level = build(probes);
                assert!(level.threshold >= alone.threshold, "{at}");
                assert!(level.probes.unwrap() <= probes, "{at}: {:?}", level.probes);
                let budget = 10f64.powf(-tol / 10.0);
                let ratio = level.error_ratio.unwrap();
                assert!(ratio <= budget, "{at}: {ratio}");
                if level.threshold == 0.0 {
                    continue;
                }
                let gain = if gain.is_nan() { level.gain } else { gain };
                let direct = direct_error_ratio(&spec, level.threshold, gain);
                assert!(direct <= budget, "{at}: direct {direct}");
                match level.evaluated {
                    true => {
                        assert!(direct <= ratio * (1.0 + 1e-4), "{at}: {direct} {ratio}");
                        assert!(
                            direct >= ratio * 10f64.powf(-0.12 / 10.0),
                            "{at}: {direct} {ratio}"
                        );
                        raised += usize::from(level.threshold > alone.threshold);
                    }
                    false => {
                        assert_eq!(level.threshold, alone.threshold, "{at}");
                        assert_eq!(level.error_ratio, alone.error_ratio, "{at}");
                    }
                }
            }
        }
    }
    assert!(raised >= 2, "{raised}");
}

/// The exact bound accepts the largest threshold the 3D criterion allows:
/// its verified error energy is within budget, it is never below the
/// paper's threshold when the paper's h_d covers the whole grid, and the
/// error energy it reports is what a direct evaluation of eq. 15 gives.
#[test]
fn exact_bound_is_within_budget_and_no_tighter_than_the_papers() {
    let n = 32;
    let (spec, _) = mixture_spectrum::<f16, f32>((5, n, 8), [n; 3], FilterKind::Kb4, 2);
    for tol in [30.0, 45.0, 60.0] {
        let exact = AdaptiveMarks::build(&spec, &nearest(tol, Bound::Exact)).unwrap();
        let paper = AdaptiveMarks::build(&spec, &nearest(tol, Bound::Paper)).unwrap();
        let (e, p) = (&exact.levels[0], &paper.levels[0]);
        let ratio = e.error_ratio.unwrap();
        assert!(ratio <= 10f64.powf(-tol / 10.0), "{tol}: {ratio}");
        assert!(paper.levels[0].error_ratio.is_none());
        assert!(
            e.threshold >= p.threshold,
            "{tol}: {} < {}",
            e.threshold,
            p.threshold
        );
        assert!(e.marked >= p.marked);
    }
}

/// The error energy the exact bound verifies is eq. 15 evaluated the slow
/// way. A 16³ spectrum keeps the naive transform (O(N²), N = 4096) cheap.
#[test]
fn exact_bound_energy_matches_a_direct_evaluation() {
    let spec = eighth_spectrum();
    let mut checked = 0;
    for tol in [20.0, 30.0, 40.0] {
        let exact = AdaptiveMarks::build(&spec, &nearest(tol, Bound::Exact)).unwrap();
        let level = &exact.levels[0];
        let ratio = level.error_ratio.unwrap();
        if level.threshold == 0.0 {
            continue;
        }
        // f32 transforms against f64 sums: relative agreement to ~1e-5 of
        // the energy (f32 ε·log₂N on amplitudes, squared, with margin).
        let direct = direct_error_ratio(&spec, level.threshold, level.gain);
        assert!(
            (direct - ratio).abs() <= 1e-4 * ratio,
            "{tol}: direct {direct} against {ratio}"
        );
        // The largest ⅛-octave step within the budget: the next one is not
        // (unless every sample is already below the threshold).
        let next = level.threshold * 2f64.powf(0.125);
        let budget = 10f64.powf(-tol / 10.0);
        let all = spec.n().pow(3);
        let largest = (0..all).fold(0.0f64, |m, i| m.max(spec.view().value(i).abs()));
        if next <= largest {
            let beyond = direct_error_ratio(&spec, next, level.gain);
            assert!(beyond > budget, "{tol}: {next} is within the budget too");
        }
        checked += 1;
    }
    assert!(checked >= 2, "{checked}");
}

/// Eq. 15 evaluated the slow way in f64: the naive inverse 3D transform of
/// the samples below `tau`, times `g·ĥ₂ − ĥ₁`, against the whole volume
/// times `ĥ₁`.
fn direct_error_ratio(spec: &OwnedSpectrum<f16>, tau: f64, gain: f64) -> f64 {
    let n = spec.n();
    let view = spec.view();
    let all: Vec<f64> = (0..n * n * n).map(|i| view.value(i)).collect();
    let weak: Vec<f64> = all
        .iter()
        .map(|&v| {
            if (v as f32).abs() < tau as f32 {
                v
            } else {
                0.0
            }
        })
        .collect();
    let f_all = fvr_host::reference::naive_dht_3d(&all, [n; 3]);
    let f_weak = fvr_host::reference::naive_dht_3d(&weak, [n; 3]);
    let small = Filter::new(FilterKind::Nearest, 2).unwrap();
    let large = spec.filter();
    let pos = |k: usize| fvr_core::dht::signed_index(k, n) as f64 / n as f64;
    let (mut err, mut reference) = (0.0, 0.0);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let hl = large.response(pos(x)) * large.response(pos(y)) * large.response(pos(z));
                let hs = small.response(pos(x)) * small.response(pos(y)) * small.response(pos(z));
                let i = x + n * (y + n * z);
                err += (f_weak[i] * (gain * hs - hl)).powi(2);
                reference += (f_all[i] * hl).powi(2);
            }
        }
    }
    err / reference
}

/// The conservative marking of the paper: marked iff the sample and all
/// samples within Chebyshev distance r (circularly) are below τ.
#[test]
fn marks_match_the_definition_by_brute_force() {
    let n = 8;
    let mut lcg = fvr_tests::Lcg(0x1234_5678);
    let values: Vec<f64> = (0..n * n * n)
        .map(|_| {
            let u = (lcg.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            // Mostly weak, some strong.
            if u < 0.9 {
                u * 0.1
            } else {
                u * 10.0
            }
        })
        .collect();
    for radius in [0usize, 1, 2] {
        let tau = 0.05;
        let mut words = vec![0u32; marks_words(n)];
        let mut line = vec![false; n];
        let count = mark(n, |i| values[i], tau, radius, &mut words, &mut line).unwrap();
        let marks = Marks::new(&words, n).unwrap();
        let mut expected = 0;
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let r = radius as i64;
                    let all = (-r..=r).all(|dz| {
                        (-r..=r).all(|dy| {
                            (-r..=r).all(|dx| {
                                let i =
                                    |c: usize, d: i64| (c as i64 + d).rem_euclid(n as i64) as usize;
                                values[i(x, dx) + n * (i(y, dy) + n * i(z, dz))] < tau
                            })
                        })
                    });
                    assert_eq!(
                        marks.get(x + n * (y + n * z)),
                        all,
                        "r {radius} at {x},{y},{z}"
                    );
                    expected += usize::from(all);
                }
            }
        }
        assert_eq!(count, expected);
        assert_eq!(marks.count(), expected);
    }
}

/// Eq. 16 with the budget: the samples below τ hold at most the allowed
/// energy, and τ is within one ⅛-octave bin of the largest such threshold.
#[test]
fn threshold_meets_the_energy_budget_and_is_nearly_the_largest() {
    let values: Vec<f64> = (1..=5000).map(|i| 1.0 / (i as f64).powf(1.5)).collect();
    let total: f64 = values.iter().map(|v| v * v).sum();
    for (h_d, budget) in [(1.0, 1e-3), (2.5, 1e-4), (0.3, 1e-6)] {
        let tau = threshold_for(values.len(), |i| values[i], h_d, budget);
        let below = |t: f64| {
            values
                .iter()
                .filter(|v| v.abs() < t)
                .map(|v| v * v)
                .sum::<f64>()
        };
        assert!(h_d * h_d * below(tau) <= budget * total);
        assert!(h_d * h_d * below(tau * 2f64.powf(0.25)) > budget * total);
    }
}

#[test]
fn statistics_add_up_and_report_no_effect() {
    let n = 32;
    let (spec, _) = mixture_spectrum::<f16, f32>((3, n, 6), [n; 3], FilterKind::Kb4, 2);
    let view = View::along([1.0, 0.4, 0.1]);
    let settings = AdaptiveSettings {
        chain: parse_chain("nearest").unwrap(),
        ..nearest(40.0, Bound::Exact)
    };
    let marks = AdaptiveMarks::build(&spec, &settings).unwrap();
    let (_, stats) = marks.render::<f16, f32>(&spec, &view, n, n).unwrap();
    assert_eq!(stats.per_filter.iter().sum::<u64>(), stats.samples);
    assert_eq!(stats.full_taps, stats.samples * 64);
    assert_eq!(stats.taps, stats.per_filter[0] * 64 + stats.per_filter[1]);
    assert!(stats.taps < stats.full_taps);
    // The marks, and the summary's byte per brick of 8³ and six per brick
    // not held whole.
    let partial = marks.summary().unwrap().partial().unwrap().len();
    assert!(partial > 0);
    assert_eq!(marks.bytes(), 64 * 64 * 64 / 8 + 8 * 8 * 8 + 6 * partial);

    let tight = AdaptiveMarks::build(&spec, &nearest(400.0, Bound::Exact)).unwrap();
    let (_, s) = tight.render::<f16, f32>(&spec, &view, n, n).unwrap();
    assert!(tight.effect(&s).unwrap().contains("no effect"));
    let loose = AdaptiveMarks::build(
        &spec,
        &AdaptiveSettings {
            h_d: Some(1e-9),
            ..nearest(1e-9, Bound::Paper)
        },
    )
    .unwrap();
    let (_, s) = loose.render::<f16, f32>(&spec, &view, n, n).unwrap();
    assert!(loose.effect(&s).unwrap().contains("so loose"), "{:?}", s);
}

#[test]
fn bad_tolerances_and_chains_are_refused() {
    for bad in ["0", "-5", "nan", "inf", "abc", ""] {
        let err = parse_tolerance(bad).unwrap_err();
        assert!(err.contains("positive number of dB"), "{err}");
    }
    assert_eq!(parse_tolerance(" 40 ").unwrap(), 40.0);
    assert!(parse_chain("kb9").unwrap_err().contains("kb9"));
    assert!(parse_chain("nearest,linear,cubic").is_err());
    let volume = sample(&GaussianMixture::random(3, 16, 2), [16; 3]);
    let spec =
        OwnedSpectrum::<f16>::prepare::<f32>(&volume, Filter::new(FilterKind::Kb3, 2).unwrap())
            .unwrap();
    let kb4 = AdaptiveSettings {
        chain: vec![Cheaper::Filter(FilterKind::Kb4)],
        ..AdaptiveSettings::new(40.0)
    };
    let err = AdaptiveMarks::build(&spec, &kb4).unwrap_err();
    assert!(err.contains("not cheaper"), "{err}");
    let negative = AdaptiveSettings {
        h_d: Some(-1.0),
        ..nearest(40.0, Bound::Paper)
    };
    assert!(AdaptiveMarks::build(&spec, &negative).is_err());
    let conflicting = AdaptiveSettings {
        h_d: Some(0.3),
        ..nearest(40.0, Bound::Exact)
    };
    let err = AdaptiveMarks::build(&spec, &conflicting).unwrap_err();
    assert!(err.contains("--adaptive-bound paper"), "{err}");
    assert!(Bound::from_name("tight").unwrap_err().contains("tight"));
}
