//! Adaptive views that fall back to the plain walk
//! (`AdaptiveMarks::plain_below`): marks that substitute too little give
//! the full filter's image bit for bit and say so; marks that substitute
//! enough keep the adaptive walk; the count that decides
//! (`walk::tally`) is the adaptive walk's own.

mod common;
use common::{assert_ok, fvr, temp_dir};

use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::View;
use fvr_engine::render::adaptive::{AdaptiveRenderer, Walked};
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::slice::adaptive::walk::{extract, tally, AdaptiveJob};
use fvr_engine::slice::adaptive::{AdaptiveMarks, AdaptiveSettings};
use fvr_engine::slice::exact::Tiling;
use fvr_engine::spectrum::{AnySpectrum, OwnedSpectrum};
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use half::f16;

const DIRECTIONS: [[f64; 3]; 3] = [[1.0, 0.3, 0.2], [0.0, -1.0, 0.0], [-0.4, 0.7, -0.6]];

/// A smooth 64³ volume (Gaussian blobs, fixed seed) prepared for kb6.
fn smooth_kb6() -> OwnedSpectrum<f16> {
    let n = 64;
    let volume = sample(&GaussianMixture::random(1, n, 8), [n; 3]);
    let filter = Filter::new(FilterKind::Kb6, 1).unwrap();
    OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap()
}

#[test]
fn marks_that_substitute_nothing_render_the_plain_view_bit_for_bit() {
    let spec = smooth_kb6();
    let n = spec.n();
    // 400 dB: no sample's substitution fits the budget.
    let marks = AdaptiveMarks::build(&spec, &AdaptiveSettings::new(400.0)).unwrap();
    assert_eq!(marks.levels[0].marked, 0);
    let any = AnySpectrum::F16(spec.clone());
    let mut plain = ViewRenderer::<f32>::new(n, spec.filter());
    for parallel in [true, false] {
        let mut renderer = AdaptiveRenderer::<f32>::new(&marks, &spec)
            .unwrap()
            .with_parallel(parallel);
        for dir in DIRECTIONS {
            let view = View::along(dir);
            let mut out = vec![7.0f32; n * n];
            let stats = renderer.render_into(&spec, &view, n, n, &mut out).unwrap();
            assert_eq!(renderer.walked(), Walked::Plain { share: 0.0 }, "{dir:?}");
            assert!(stats.samples > 0);
            assert_eq!(stats.per_filter[0], stats.samples, "{stats:?}");
            assert_eq!(stats.taps, stats.full_taps, "{stats:?}");
            assert_eq!(stats.full_taps, stats.samples * 216, "{stats:?}");
            let mut expected = vec![0.0f32; n * n];
            plain
                .render_into(&spec, &view, n, n, &mut expected)
                .unwrap();
            for (a, b) in expected.iter().zip(&out) {
                assert_eq!(a.to_bits(), b.to_bits(), "{dir:?}, parallel {parallel}");
            }
            let full = any.render(&view, n, n).unwrap();
            assert!(full.iter().zip(&out).all(|(a, &b)| *a == b as f64));
            let note = marks.note(&stats, renderer.walked()).unwrap();
            assert!(note.contains("plain walk used"), "{note}");
        }
    }
    // A share of 0 always walks adaptively.
    let always = AdaptiveMarks::build(
        &spec,
        &AdaptiveSettings {
            plain_below: 0.0,
            ..AdaptiveSettings::new(400.0)
        },
    )
    .unwrap();
    let mut renderer = AdaptiveRenderer::<f32>::new(&always, &spec).unwrap();
    let mut out = vec![0.0f32; n * n];
    let view = View::along(DIRECTIONS[0]);
    renderer.render_into(&spec, &view, n, n, &mut out).unwrap();
    assert_eq!(renderer.walked(), Walked::Adaptive);
    // Shares outside 0 … 1 are refused.
    for bad in [-0.1, 1.5, f64::NAN] {
        let settings = AdaptiveSettings {
            plain_below: bad,
            ..AdaptiveSettings::new(40.0)
        };
        assert!(AdaptiveMarks::build(&spec, &settings).is_err(), "{bad}");
    }
}

#[test]
fn a_smooth_phantom_still_renders_adaptively() {
    let spec = smooth_kb6();
    let n = spec.n();
    let marks = AdaptiveMarks::build(&spec, &AdaptiveSettings::new(40.0)).unwrap();
    let mut renderer = AdaptiveRenderer::<f32>::new(&marks, &spec).unwrap();
    let mut adaptive = 0;
    for dir in DIRECTIONS {
        let view = View::along(dir);
        let mut out = vec![0.0f32; n * n];
        let stats = renderer.render_into(&spec, &view, n, n, &mut out).unwrap();
        // Each view on the walk its share calls for.
        match renderer.walked() {
            Walked::Adaptive => {
                let cheap = (stats.samples - stats.per_filter[0]) as f64;
                assert!(
                    cheap >= marks.plain_below * stats.samples as f64,
                    "{stats:?}"
                );
                assert!(stats.taps < stats.full_taps / 2, "{stats:?}");
                adaptive += 1;
            }
            Walked::Plain { share } => assert!(share < marks.plain_below, "{dir:?} {share}"),
        }
    }
    assert!(adaptive >= DIRECTIONS.len() / 2, "{adaptive}");
    // Asked to walk plainly below a share the view does not reach, it does.
    let strict = AdaptiveMarks::build(
        &spec,
        &AdaptiveSettings {
            plain_below: 1.0,
            ..AdaptiveSettings::new(40.0)
        },
    )
    .unwrap();
    let mut renderer = AdaptiveRenderer::<f32>::new(&strict, &spec).unwrap();
    let view = View::along(DIRECTIONS[0]);
    let mut out = vec![0.0f32; n * n];
    let stats = renderer.render_into(&spec, &view, n, n, &mut out).unwrap();
    match renderer.walked() {
        Walked::Plain { share } => assert!(share > 0.5 && share < 1.0, "{share}"),
        Walked::Adaptive => panic!("walked adaptively: {stats:?}"),
    }
}

/// The tally is the adaptive walk's statistics exactly, on one thread or
/// many.
#[test]
fn tally_counts_as_the_walk_does() {
    let spec = smooth_kb6();
    let n = spec.n();
    let view_spec = spec.view();
    let marks = AdaptiveMarks::build(&spec, &AdaptiveSettings::new(40.0)).unwrap();
    let kernel = KernelTable::<f32>::new(spec.filter());
    let tables = marks.tables::<f32>();
    let levels = marks.core_levels(&tables).unwrap();
    for dir in DIRECTIONS.into_iter().chain([[0.02, -1.0, 0.01]]) {
        let frame = View::along(dir).frame().unwrap();
        let mut grid = vec![0.0f32; n * n];
        let whole = marks.summary();
        let job = AdaptiveJob::new(
            &view_spec,
            &kernel,
            &levels,
            whole,
            &frame,
            Tiling::default(),
            true,
        );
        let walked = extract(&job, &mut grid).unwrap();
        for parallel in [false, true] {
            // With the summary of the first level's marks or without.
            for whole in [marks.summary(), None] {
                let counted = tally(&AdaptiveJob {
                    whole,
                    parallel,
                    ..job
                })
                .unwrap();
                assert_eq!(counted, walked, "{dir:?}, parallel {parallel}");
            }
        }
    }
}

/// `fvr render --stats-json` reports the plain walk, and a note on stderr
/// says so unless --quiet.
#[test]
fn the_cli_reports_the_plain_walk() {
    let dir = temp_dir("adaptive-plain");
    let base = ["render", "gaussians@32", "--dir", "1,0.3,0.2"];
    let mut args = base.to_vec();
    args.extend(["--adaptive", "400", "--stats-json", "--out", "a.nrrd"]);
    let out = fvr(&args, &dir);
    assert_ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stdout.contains("\"plain_walk\": true"), "{stdout}");
    assert!(stdout.contains("plain walk used"), "{stdout}");
    assert!(stderr.contains("plain walk used"), "{stderr}");
    let mut quiet = vec!["--quiet"];
    quiet.extend(args.iter().copied());
    let out = fvr(&quiet, &dir);
    assert_ok(&out);
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("plain walk"),
        "{out:?}"
    );
    // 0 % never walks plainly.
    args.extend(["--adaptive-plain-below", "0"]);
    let out = fvr(&args, &dir);
    assert_ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("\"plain_walk\": false"), "{stdout}");
}
