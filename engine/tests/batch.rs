//! `Renderer::render_batch_into`: every frame equals `Renderer::render`'s
//! image of its view converted to f32, bit for bit, on each path the
//! renderer draws by (voxel units, anisotropic voxels, cubic voxels in mm,
//! a mixed-radix grid, f64 storage, a depth cue, lights, a preview level,
//! adaptive filtering), and bad input is refused without touching `out`.

use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;
use fvr_core::shading::{DepthCue, Light, Scene};
use fvr_core::volume::GridOversampling;
use fvr_engine::slice::adaptive::AdaptiveSettings;
use fvr_engine::spectrum::Precision;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_engine::volume::Volume;
use fvr_engine::{PipelineError, Renderer, Settings, Units};

fn volume(dims: [usize; 3], spacing: [f64; 3]) -> Volume {
    let mixture = GaussianMixture::random(7, dims[0].max(dims[1]).max(dims[2]), 4);
    sample(&mixture, dims).with_spacing(spacing).unwrap()
}

/// Eleven views: the three axes, views about one axis (the column walk),
/// tilted ones (strips, the exchanged copy from the second such view on)
/// and one with an up hint of its own.
fn views() -> Vec<View> {
    let mut v: Vec<View> = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 0.3, 0.0],
        [0.2, 1.0, 0.0],
        [1.0, 0.3, 0.2],
        [0.1, 1.0, 0.4],
        [-0.4, 0.2, 1.0],
        [0.7, -0.5, 0.3],
        [0.3, 0.9, -0.2],
    ]
    .into_iter()
    .map(View::along)
    .collect();
    v.push(View {
        dir: [0.6, 0.1, -0.3],
        up: [0.2, 1.0, 0.5],
    });
    v.push(View {
        dir: [0.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
    });
    v
}

/// Batch against one by one, frame by frame, bit for bit: a batch of
/// eleven views (in parallel) and a batch of one (one view at a time, on
/// all threads).
fn check(label: &str, volume: &Volume, settings: Settings, size: Option<(usize, usize)>) {
    let renderer = Renderer::new(volume, settings).unwrap();
    check_views(label, &renderer, &views(), size);
    check_views(label, &renderer, &views()[5..6], size);
}

fn check_views(label: &str, renderer: &Renderer, views: &[View], size: Option<(usize, usize)>) {
    let (batch, report) = renderer.render_batch(views, size).unwrap();
    let shape = report.shape;
    assert_eq!(shape.views, views.len(), "{label}");
    assert_eq!(batch.len(), shape.len(), "{label}");
    for (b, view) in views.iter().enumerate() {
        let (image, _) = renderer.render(view, size).unwrap();
        assert_eq!(
            (image.channels, image.width, image.height),
            (shape.channels, shape.width, shape.height),
            "{label}"
        );
        let frame = &batch[b * shape.frame_len()..(b + 1) * shape.frame_len()];
        let energy: f64 = image.data.iter().map(|v| v * v).sum();
        assert!(energy > 0.0, "{label}: view {b} is blank");
        for (i, (got, want)) in frame.iter().zip(&image.data).enumerate() {
            assert_eq!(
                got.to_bits(),
                (*want as f32).to_bits(),
                "{label}: view {b}, value {i}: {got} against {want}"
            );
        }
    }
}

fn fixed(filter: FilterKind, grid: GridOversampling, precision: Precision) -> Settings {
    Settings {
        filter: Some(filter),
        oversample: Some(grid),
        precision: Some(precision),
        ..Settings::default()
    }
}

#[test]
fn plain_views_match_one_by_one() {
    let cube = volume([40, 36, 32], [1.0; 3]);
    check("voxel units", &cube, Settings::default(), None);
    check(
        "voxel units, 30x20",
        &cube,
        Settings::default(),
        Some((30, 20)),
    );
    let ct = volume([40, 36, 24], [0.9, 0.9, 1.5]);
    check("anisotropic mm", &ct, Settings::default(), None);
    let mm = volume([32, 32, 32], [0.5; 3]);
    check("cubic 0.5 mm", &mm, Settings::default(), None);
    check(
        "ignore spacing",
        &ct,
        Settings {
            units: Units {
                ignore_spacing: true,
                pixel_size: None,
            },
            ..Settings::default()
        },
        None,
    );
    check(
        "mixed-radix grid",
        &cube,
        fixed(FilterKind::Kb4, GridOversampling::X1_5, Precision::F16),
        None,
    );
    check(
        "f64",
        &ct,
        fixed(FilterKind::Kb6, GridOversampling::X2, Precision::F64),
        None,
    );
    check(
        "f32, cubic",
        &cube,
        fixed(FilterKind::Cubic, GridOversampling::X1, Precision::F32),
        None,
    );
}

#[test]
fn cued_lit_and_preview_views_match_one_by_one() {
    let cube = volume([32, 32, 32], [1.0; 3]);
    let mut lit = Scene {
        ambient: [0.2; 3],
        ..Scene::xray()
    };
    lit.add_light(Light {
        towards: [0.3, 0.2, 1.0],
        color: [1.0, 0.5, 0.2],
    })
    .unwrap();
    let cued = Scene {
        cue: DepthCue::Linear {
            front: 1.0,
            back: 0.3,
        },
        ..Scene::xray()
    };
    let flat_cue = Scene {
        cue: DepthCue::Linear {
            front: 0.5,
            back: 0.5,
        },
        ambient: [2.0; 3],
        ..Scene::xray()
    };
    for (label, scene) in [("lit", lit), ("cued", cued), ("flat cue", flat_cue)] {
        let settings = Settings {
            scene,
            ..Settings::default()
        };
        check(label, &cube, settings, None);
    }
    let preview = Settings {
        preview_level: 1,
        ..Settings::default()
    };
    check("preview", &cube, preview, Some((32, 24)));
    let adaptive = Settings {
        adaptive: Some(AdaptiveSettings::new(30.0)),
        ..Settings::default()
    };
    check("adaptive", &cube, adaptive, None);
}

#[test]
fn bad_input_is_refused_and_out_untouched() {
    let cube = volume([24, 24, 24], [1.0; 3]);
    let renderer = Renderer::new(&cube, Settings::default()).unwrap();
    let shape = renderer.batch_shape(2, None).unwrap();
    let good = View::along([1.0, 0.2, 0.1]);
    let mut out = vec![7.0f32; shape.len()];
    let views = [good, View::along([0.0, 0.0, 0.0])];
    let err = renderer
        .render_batch_into(&views, None, &mut out)
        .unwrap_err();
    let message = err.to_string();
    assert!(message.starts_with("view 1: "), "{message}");
    assert!(!message.contains('\n'), "{message}");
    let parallel = [good, View::along([0.0, 0.0, 1.0])];
    let parallel = [
        parallel[0],
        View {
            up: [0.0, 0.0, 2.0],
            ..parallel[1]
        },
    ];
    let err = renderer.render_batch_into(&parallel, None, &mut out);
    assert!(matches!(err, Err(PipelineError::Settings(m)) if m.starts_with("view 1: ")));
    assert!(out.iter().all(|&v| v == 7.0), "out was written");
    let mut short = vec![0.0f32; shape.len() - 1];
    let err = renderer
        .render_batch_into(&[good, good], None, &mut short)
        .unwrap_err();
    assert!(err.to_string().contains("need"), "{err}");
    let n = renderer.n();
    assert!(renderer
        .render_batch_into(&[good], Some((n + 1, 4)), &mut out)
        .is_err());
    let (empty, report) = renderer.render_batch(&[], None).unwrap();
    assert!(empty.is_empty() && report.shape.views == 0);
}

/// A renderer of `volume` with an ambient colour of 1e300: every image
/// overflows f32.
fn blinding(volume: &Volume) -> Renderer {
    let mut scene = Scene::xray();
    scene.ambient = [1e300; 3];
    let settings = Settings {
        scene,
        ..Settings::default()
    };
    Renderer::new(volume, settings).unwrap()
}

/// A frame that overflows f32 is refused, naming the view and the setting
/// given, and `out` holds no NaN or infinity afterwards: a volume near
/// `f32::MAX` blames the volume, an ambient of 1e300 the ambient colour.
#[test]
fn overflowing_frames_are_refused_and_not_left_in_out() {
    let small = volume([16; 3], [1.0; 3]);
    let renderer = blinding(&small);
    let views = [View::along([1.0, 0.3, 0.2]), View::along([0.0, 1.0, 0.0])];
    let shape = renderer.batch_shape(views.len(), None).unwrap();
    let mut out = vec![7.0f32; shape.len()];
    match renderer.render_batch_into(&views, None, &mut out) {
        Err(PipelineError::Overflow { view, cause, .. }) => {
            assert_eq!(view, 0);
            assert_eq!(cause, "a setting overflowed; lower the ambient colour");
        }
        other => panic!("{other:?}"),
    }
    assert!(
        out.iter().all(|v| v.is_finite()),
        "non-finite values left in out"
    );

    let huge = {
        let mut v = small.clone();
        let peak = v.data.iter().fold(0.0f32, |m, x| m.max(x.abs()));
        for x in v.data.iter_mut() {
            *x *= 3e38 / peak;
        }
        v
    };
    let renderer = Renderer::new(&huge, Settings::default()).unwrap();
    let err = renderer.render_batch(&views, None).unwrap_err().to_string();
    assert!(err.starts_with("view 0 has non-finite pixels"), "{err}");
    assert!(err.contains("rescale the volume"), "{err}");
}

/// One view ([`Renderer::render`]) and a magnified one
/// ([`Renderer::render_zoomed`]) refuse an image that overflows f32 as a
/// batch does: their `f64` pixels are finite, the `f32` every output
/// stores is not.
#[test]
fn single_views_that_overflow_f32_are_refused() {
    let small = volume([16; 3], [1.0; 3]);
    let renderer = blinding(&small);
    let view = View::along([1.0, 0.3, 0.2]);
    for zoom in [1, 2] {
        match renderer.render_zoomed(&view, None, zoom) {
            Err(PipelineError::Overflow { view, cause, .. }) => {
                assert_eq!(view, 0);
                assert_eq!(cause, "a setting overflowed; lower the ambient colour");
            }
            other => panic!("zoom {zoom}: {other:?}"),
        }
    }
    // The same renderer's scene at a sane ambient renders.
    let fine = Renderer::new(&small, Settings::default()).unwrap();
    let (image, _) = fine.render(&view, None).unwrap();
    assert!(image.data.iter().all(|v| v.is_finite()));
}
