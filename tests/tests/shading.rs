//! Depth cueing and shading (paper §3) against the reference ladder: closed
//! forms on analytic Gaussian mixtures, the f64 pipeline, and a spatial
//! ray marcher.
//!
//! Floors: the 50 dB (kb6, oversampling 2, f32) and 45 dB (kb4, f16).
//! What limits them in practice (measured with these tests' scenes): the
//! `|∇f|` spectrum, whose samples alias where the gradient vanishes (about
//! 87 dB), and for f16 the storage rounding (65–80 dB).

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::shading::{DepthCue, Light, Scene, MAX_LIGHTS};
use fvr_core::Error;
use fvr_engine::plan::filter::{choose_filter, KbDesign};
use fvr_engine::render::shaded::{SceneRenderer, SceneSpectra};
use fvr_engine::spectrum::{AnySpectrum, Precision};
use fvr_engine::volume::phantom::{sample, Gaussian, GaussianMixture};
use fvr_host::reference::shaded::{exact_scene_projection, spatial_scene_projection};
use fvr_host::reference::snr_db;

const N: usize = 64;
/// Simpson step for the numerically integrated `|∇f|` term (voxels):
/// the fourth-order error at σ ≥ 1.5 is far below every floor.
const GRADIENT_STEP: f64 = 0.05;

/// Three lights of different colours, none perpendicular to the views used.
fn three_lights() -> [Light; 3] {
    [
        Light {
            towards: [0.0, 1.0, 0.2],
            color: [1.0, 0.25, 0.1],
        },
        Light {
            towards: [0.3, -0.6, 0.8],
            color: [0.1, 0.9, 0.3],
        },
        Light {
            towards: [-0.7, -0.4, -0.5],
            color: [0.2, 0.3, 1.0],
        },
    ]
}

fn lit(cue: DepthCue) -> Scene {
    let mut scene = Scene {
        cue,
        ambient: [0.2, 0.2, 0.25],
        ..Scene::xray()
    };
    for light in three_lights() {
        scene.add_light(light).unwrap();
    }
    scene
}

fn profile(weights: &[f64], harmonics: usize) -> DepthCue {
    DepthCue::Profile {
        weights: weights.iter().copied().collect(),
        harmonics,
    }
}

fn scenes() -> Vec<(&'static str, Scene)> {
    let linear = DepthCue::Linear {
        front: 1.0,
        back: 0.15,
    };
    let sine = DepthCue::Sine {
        front: 1.0,
        back: 0.15,
    };
    vec![
        (
            "linear cue",
            Scene {
                cue: linear.clone(),
                ..Scene::xray()
            },
        ),
        (
            "sine cue",
            Scene {
                cue: sine.clone(),
                ..Scene::xray()
            },
        ),
        (
            "profile cue",
            Scene {
                cue: profile(&[0.2, 1.0, 0.2], 6),
                ..Scene::xray()
            },
        ),
        ("shaded", lit(DepthCue::None)),
        ("shaded + linear cue", lit(linear)),
        ("shaded + sine cue", lit(sine)),
    ]
}

fn views() -> [View; 2] {
    [
        View::along([1.0, 0.45, -0.3]),
        View {
            dir: [-0.2, 1.0, 0.7],
            up: [1.0, 0.0, 0.0],
        },
    ]
}

#[test]
fn cued_and_shaded_images_meet_floors_against_closed_forms() {
    let mixture = GaussianMixture::random(7, N, 8);
    let volume = sample(&mixture, [N; 3]);
    let configs = [
        (FilterKind::Kb6, 2, Precision::F32, 50.0),
        (FilterKind::Kb4, 1, Precision::F16, 45.0),
    ];
    let scenes = scenes();
    let exact: Vec<Vec<_>> = views()
        .iter()
        .map(|view| {
            scenes
                .iter()
                .map(|(_, s)| {
                    exact_scene_projection(&mixture, [N; 3], s, view, (N, N), GRADIENT_STEP)
                        .unwrap()
                })
                .collect()
        })
        .collect();
    for (kind, os, precision, floor) in configs {
        let filter = choose_filter(&volume, kind, os, KbDesign::Auto).unwrap();
        // One preparation with the |∇f| spectrum serves every scene.
        let spectra = SceneSpectra::prepare(&volume, filter, precision, &lit(DepthCue::None))
            .expect("prepare");
        for (v, view) in views().iter().enumerate() {
            for (s, (name, scene)) in scenes.iter().enumerate() {
                let image = spectra.render(scene, view, N, N).unwrap();
                assert_eq!(image.channels, scene.channels());
                assert!(image.data.iter().all(|x| x.is_finite()));
                let snr = snr_db(&exact[v][s].data, &image.data);
                eprintln!("{kind:?} os{os} {precision:?} view {v} {name}: {snr:.1} dB");
                assert!(
                    snr >= floor,
                    "{kind:?} os{os} {precision:?} view {v} {name}: {snr:.1} dB < {floor} dB"
                );
            }
        }
    }
}

/// The f64 pipeline evaluates the same model: it agrees with the closed
/// forms at the f32 pipeline's level, and f32 agrees with f64 far above
/// either's distance to the reference (f32 rounding ≈ 2⁻²⁴ per operation).
#[test]
fn f64_pipeline_evaluates_the_same_model() {
    let mixture = GaussianMixture::random(3, N, 6);
    let volume = sample(&mixture, [N; 3]);
    let filter = choose_filter(&volume, FilterKind::Kb6, 2, KbDesign::Auto).unwrap();
    let scene = lit(DepthCue::Linear {
        front: 0.3,
        back: 1.0,
    });
    let view = views()[0];
    let exact = exact_scene_projection(&mixture, [N; 3], &scene, &view, (N, N), GRADIENT_STEP)
        .unwrap()
        .data;
    let f64_image = SceneSpectra::prepare(&volume, filter, Precision::F64, &scene)
        .unwrap()
        .render(&scene, &view, N, N)
        .unwrap()
        .data;
    let f32_image = SceneSpectra::prepare(&volume, filter, Precision::F32, &scene)
        .unwrap()
        .render(&scene, &view, N, N)
        .unwrap()
        .data;
    let (e64, e32, d) = (
        snr_db(&exact, &f64_image),
        snr_db(&exact, &f32_image),
        snr_db(&f64_image, &f32_image),
    );
    eprintln!("vs exact: f64 {e64:.1} dB, f32 {e32:.1} dB; f32 vs f64 {d:.1} dB");
    assert!(e64 >= 50.0, "f64 pipeline vs exact {e64:.1} dB");
    assert!(
        (e64 - e32).abs() < 1.0,
        "f64 {e64:.1} dB vs f32 {e32:.1} dB"
    );
    assert!(d >= 100.0, "f32 vs f64 pipeline {d:.1} dB");
}

/// The spatial ray marcher (trilinear, step ¼ voxel) integrates the same
/// model on the same samples; trilinear interpolation limits it to about
/// 48 dB on this phantom, so it cross-checks signs and geometry, not digits.
#[test]
fn spatial_ray_marcher_agrees_with_frequency_domain() {
    let mixture = GaussianMixture::random(11, 48, 6);
    let volume = sample(&mixture, [48; 3]);
    let filter = choose_filter(&volume, FilterKind::Kb6, 2, KbDesign::Auto).unwrap();
    let scene = lit(DepthCue::Linear {
        front: 1.0,
        back: 0.2,
    });
    let view = views()[1];
    let freq = SceneSpectra::prepare(&volume, filter, Precision::F32, &scene)
        .unwrap()
        .render(&scene, &view, 48, 48)
        .unwrap();
    let spatial = spatial_scene_projection(&volume, &scene, &view, 48, 48, 0.25).unwrap();
    let snr = snr_db(&spatial.data, &freq.data);
    eprintln!("spatial vs frequency domain: {snr:.1} dB");
    assert!(snr >= 40.0, "spatial vs frequency domain {snr:.1} dB");
}

/// §3.3: shading the depth-cued spectrum misses `(d·L)·∫w'·f`. With a light
/// off the view's perpendicular plane the uncorrected image is far off; the
/// eq. 14 correction restores the floor. With every light perpendicular to
/// the view the correction term is exactly zero and the images are equal.
#[test]
fn eq14_correction_fixes_lights_not_perpendicular_to_the_view() {
    let mixture = GaussianMixture::random(5, N, 8);
    let volume = sample(&mixture, [N; 3]);
    let filter = choose_filter(&volume, FilterKind::Kb6, 2, KbDesign::Auto).unwrap();
    let view = View::along([1.0, 0.0, 0.0]);
    let cue = DepthCue::Linear {
        front: 1.0,
        back: 0.1,
    };
    let oblique = {
        let mut s = Scene {
            cue: cue.clone(),
            ambient: [0.1; 3],
            ..Scene::xray()
        };
        s.add_light(Light {
            towards: [-1.0, 0.5, 0.3],
            color: [1.0, 0.8, 0.6],
        })
        .unwrap();
        s
    };
    let spectra = SceneSpectra::prepare(&volume, filter, Precision::F32, &oblique).unwrap();
    let exact =
        exact_scene_projection(&mixture, [N; 3], &oblique, &view, (N, N), GRADIENT_STEP).unwrap();
    let corrected = spectra.render(&oblique, &view, N, N).unwrap();
    let uncorrected_scene = Scene {
        correct_cue_shading: false,
        ..oblique.clone()
    };
    let uncorrected = spectra.render(&uncorrected_scene, &view, N, N).unwrap();
    let (good, bad) = (
        snr_db(&exact.data, &corrected.data),
        snr_db(&exact.data, &uncorrected.data),
    );
    eprintln!("eq. 14: corrected {good:.1} dB, uncorrected {bad:.1} dB");
    assert!(good >= 50.0, "corrected {good:.1} dB");
    assert!(
        good - bad >= 20.0,
        "correction gains only {:.1} dB ({bad:.1} → {good:.1})",
        good - bad
    );

    let perpendicular = fvr_tests::with_light(
        Scene {
            cue,
            ambient: [0.1; 3],
            ..Scene::xray()
        },
        [0.0, 0.6, 0.8],
        [1.0; 3],
    );
    let with = spectra.render(&perpendicular, &view, N, N).unwrap();
    let without = spectra
        .render(
            &Scene {
                correct_cue_shading: false,
                ..perpendicular
            },
            &view,
            N,
            N,
        )
        .unwrap();
    assert_eq!(with.data, without.data);
}

/// Odd, unequal sides move the depth origin by half a voxel (`t` is
/// measured from `c = n/2`, the transform from `⌊n/2⌋`). The Gaussians are
/// at least 2.2 voxels wide: at 1.6 the aliasing of the sampled `|∇f|` (a
/// cone-like kink where the gradient vanishes) alone limits the lit image
/// to about 50 dB, and a wider one would be truncated by the box faces.
#[test]
fn odd_volume_cue_and_shading_match_closed_forms() {
    let dims = [37, 50, 29];
    let mixture = GaussianMixture {
        components: vec![
            Gaussian::new(
                1.0,
                [15.3, 27.1, 13.0],
                [2.8, 3.5, 2.5],
                [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            ),
            Gaussian::new(
                0.7,
                [21.0, 21.0, 15.5],
                [2.2, 2.7, 3.1],
                [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            ),
        ],
    };
    let volume = sample(&mixture, dims);
    let filter = choose_filter(&volume, FilterKind::Kb6, 2, KbDesign::Auto).unwrap();
    let view = View::along([0.3, 1.0, 0.5]);
    for scene in [
        lit(DepthCue::Linear {
            front: 0.2,
            back: 1.0,
        }),
        lit(DepthCue::Sine {
            front: 1.0,
            back: 0.3,
        }),
    ] {
        let image = SceneSpectra::prepare(&volume, filter, Precision::F32, &scene)
            .unwrap()
            .render(&scene, &view, 33, 41)
            .unwrap();
        let exact =
            exact_scene_projection(&mixture, dims, &scene, &view, (33, 41), GRADIENT_STEP).unwrap();
        let snr = snr_db(&exact.data, &image.data);
        eprintln!("odd dims {:?}: {snr:.1} dB", scene.cue);
        assert!(snr >= 50.0, "{:?}: {snr:.1} dB", scene.cue);
    }
}

/// Model only what the scene needs: no lights → no `|∇f|` spectrum, one
/// grey channel, one field, no derivative table, and the same image as the
/// plain projection, bit for bit.
#[test]
fn plain_scene_builds_nothing_extra_and_matches_plain_render() {
    let mixture = GaussianMixture::random(2, 32, 4);
    let volume = sample(&mixture, [32; 3]);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let xray = Scene::xray();
    let spectra = SceneSpectra::prepare(&volume, filter, Precision::F16, &xray).unwrap();
    assert!(spectra.gradient.is_none());
    assert_eq!(spectra.bytes(), spectra.density.bytes());
    assert_eq!(xray.field_count(), 1);
    assert!(!xray.needs_kernel_derivative());
    let view = View::along([0.4, 1.0, 0.2]);
    let plain = AnySpectrum::prepare(&volume, filter, Precision::F16)
        .unwrap()
        .render(&view, 32, 32)
        .unwrap();
    assert_eq!(spectra.render(&xray, &view, 32, 32).unwrap().data, plain);
    // A cue with equal ends weighs every depth alike: half the plain image
    // for a weight of 0.5 (a power of two, so exact).
    for cue in [
        DepthCue::Linear {
            front: 0.5,
            back: 0.5,
        },
        DepthCue::Sine {
            front: 0.5,
            back: 0.5,
        },
    ] {
        let flat = Scene {
            cue,
            ..Scene::xray()
        };
        let half: Vec<f64> = plain.iter().map(|v| 0.5 * v).collect();
        assert_eq!(spectra.render(&flat, &view, 32, 32).unwrap().data, half);
    }

    let shaded = lit(DepthCue::None);
    let lit_spectra = SceneSpectra::prepare(&volume, filter, Precision::F16, &shaded).unwrap();
    assert!(lit_spectra.gradient.is_some());
    assert_eq!(lit_spectra.bytes(), 2 * spectra.bytes());
    // A sine cue needs no derivative table; only a linear one does.
    let sine = lit(DepthCue::Sine {
        front: 1.0,
        back: 0.5,
    });
    assert!(!sine.needs_kernel_derivative());
    let r = SceneRenderer::<f32>::new(64, filter, &sine).unwrap();
    let r_linear = SceneRenderer::<f32>::new(
        64,
        filter,
        &lit(DepthCue::Linear {
            front: 1.0,
            back: 0.5,
        }),
    )
    .unwrap();
    assert!(r_linear.bytes() > r.bytes());
}

#[test]
fn bad_scene_values_are_refused_with_named_errors() {
    let mixture = GaussianMixture::random(2, 16, 2);
    let volume = sample(&mixture, [16; 3]);
    let filter = Filter::new(FilterKind::Kb3, 1).unwrap();
    let good = lit(DepthCue::None);
    let spectra = SceneSpectra::prepare(&volume, filter, Precision::F32, &good).unwrap();
    let view = View::along([1.0, 0.0, 0.0]);
    let render = |scene: &Scene| spectra.render(scene, &view, 16, 16).map(|_| ());

    let mut zero = good.clone();
    zero.lights[1].towards = [0.0; 3];
    assert_eq!(render(&zero), Err(Error::ZeroLightVector { index: 1 }));

    // Subnormal components pass a test for zero but overflow on the way to
    // a unit vector (1/1e-320 is infinite): refused, not a NaN image.
    let mut short = good.clone();
    short.lights[1].towards = [1e-320, 0.0, -1e-321];
    assert_eq!(render(&short), Err(Error::ShortLightVector { index: 1 }));

    for bad in [f64::NAN, -0.5, f64::INFINITY] {
        let mut colour = good.clone();
        colour.lights[2].color[1] = bad;
        let err = render(&colour).unwrap_err();
        assert!(
            matches!(err, Error::InvalidSceneValue { index: 2, .. }),
            "{err}"
        );
        let mut ambient = good.clone();
        ambient.ambient[0] = bad;
        assert!(matches!(
            render(&ambient),
            Err(Error::InvalidSceneValue { .. })
        ));
        for cue in [
            DepthCue::Linear {
                front: bad,
                back: 1.0,
            },
            DepthCue::Sine {
                front: 1.0,
                back: bad,
            },
            profile(&[1.0, bad, 0.5], 4),
        ] {
            let scene = Scene {
                cue,
                ..Scene::xray()
            };
            let err = render(&scene).unwrap_err();
            assert!(matches!(err, Error::InvalidSceneValue { .. }), "{err}");
            assert!(err.to_string().contains("not allowed"), "{err}");
        }
    }
    let single_point = Scene {
        cue: profile(&[1.0], 4),
        ..Scene::xray()
    };
    assert!(render(&single_point).is_err());
    for harmonics in [0, 17] {
        let scene = Scene {
            cue: profile(&[1.0, 0.5], harmonics),
            ..Scene::xray()
        };
        assert!(matches!(render(&scene), Err(Error::TooMany { .. })));
    }

    let mut full = Scene::xray();
    for _ in 0..MAX_LIGHTS {
        full.add_light(three_lights()[0]).unwrap();
    }
    let err = full.add_light(three_lights()[0]).unwrap_err();
    assert_eq!(
        err,
        Error::TooMany {
            what: "lights",
            given: MAX_LIGHTS + 1,
            capacity: MAX_LIGHTS
        }
    );
    assert!(err.to_string().contains("at most 8"), "{err}");

    // A lit scene on spectra prepared without |∇f|.
    let bare = SceneSpectra::prepare(&volume, filter, Precision::F32, &Scene::xray()).unwrap();
    assert!(matches!(
        bare.render(&good, &view, 16, 16),
        Err(Error::GradientSpectrum { .. })
    ));

    // Linear cueing needs a kernel derivative: nearest has none.
    let nearest = Filter::new(FilterKind::Nearest, 1).unwrap();
    let linear = Scene {
        cue: DepthCue::Linear {
            front: 1.0,
            back: 0.0,
        },
        ..Scene::xray()
    };
    let near = SceneSpectra::prepare(&volume, nearest, Precision::F32, &linear).unwrap();
    assert_eq!(
        near.render(&linear, &view, 16, 16).map(|_| ()),
        Err(Error::NoKernelDerivative)
    );
}
