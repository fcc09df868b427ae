//! Anisotropic voxels in the frequency domain (physical units,
//! `fvr_core::geometry::Sampling`), against the reference ladder: exact line
//! integrals of a Gaussian mixture given in mm and sampled at
//! `Δ = (0.8, 0.8, 1.5)` mm, the same object sampled isotropically, and the
//! voxel-unit path at unit sampling.
//!
//! Why the isotropic floors carry over: every component is at least
//! `1.5·max Δ` mm wide, so in index units it is at least 1.5 samples wide
//! along every axis, as the isotropic accuracy phantom is. The spectrum then
//! decays as fast towards the index Nyquist cube, and the slice, sheared in
//! index space but still a plane, meets the same interpolation error per
//! sample. The image's band `|η| < 1/(2p)` with `p = min Δ` loses at most what
//! the isotropic image loses at `p = 1` voxel for components 1.5 voxels wide.

use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::{Sampling, View};
use fvr_core::image::{aux_len, grid_len};
use fvr_core::render::{render, Buffers, Request, Source};
use fvr_core::shading::{DepthCue, Light, Scene};
use fvr_core::Error;
use fvr_engine::plan::filter::{choose_filter, KbDesign};
use fvr_engine::render::shaded::SceneSpectra;
use fvr_engine::spectrum::{AnySpectrum, Precision};
use fvr_engine::volume::phantom::{sample_spaced, GaussianMixture};
use fvr_host::reference::shaded::exact_scene_projection_sampled;
use fvr_host::reference::{exact_projection_sampled, snr_db};
use fvr_host::studies::accuracy::{CONFIGS, VIEWS};
use fvr_tests::mixture_spectrum;
use half::f16;

/// The anisotropic spacing under test (mm).
const SPACING: [f64; 3] = [0.8, 0.8, 1.5];
/// Odd sides along `j` and `k` exercise the half-voxel centre offset with a
/// non-unit spacing.
const DIMS: [usize; 3] = [64, 63, 35];
/// Physical side of the phantom's cube (mm): 64 × 0.8.
const SIDE_MM: f64 = 51.2;

/// Eight Gaussians in mm, each at least `1.5·max Δ = 2.25` mm wide, inside
/// the sphere of radius `0.4·SIDE_MM` around `SIDE_MM/2`: within the
/// sampled box (≥ 49.6 × 49.6 × 51 mm) and within the image's period
/// `64 × 0.8 = 51.2` mm on every view.
fn phantom(seed: u64, side: f64) -> GaussianMixture {
    GaussianMixture::random_in(seed, side, 8, 1.5 * 1.5, 0.12 * side)
}

/// The views of the accuracy table, and one looking down the coarse axis.
fn views() -> Vec<View> {
    let mut v: Vec<View> = VIEWS.iter().map(|&d| View::along(d)).collect();
    v.push(View {
        dir: [0.2, -0.3, 1.0],
        up: [0.0, 1.0, 0.0],
    });
    v
}

/// The accuracy table's configurations and floors, on the anisotropic
/// volume in physical units: against exact line integrals in mm, or against
/// the same pipeline in f64.
#[test]
fn anisotropic_projection_meets_the_isotropic_floors() {
    let object = phantom(1, SIDE_MM);
    let volume = sample_spaced(&object, DIMS, SPACING).unwrap();
    let sampling = Sampling::new(SPACING, 0.8).unwrap();
    let (w, h) = (64, 64);
    for (config, floor) in CONFIGS {
        if !floor.is_finite() {
            continue;
        }
        let filter =
            choose_filter(&volume, config.filter, config.oversample, KbDesign::Auto).unwrap();
        let spec = AnySpectrum::prepare(&volume, filter, config.precision).unwrap();
        let reference_spec = config
            .against_f64
            .then(|| AnySpectrum::prepare(&volume, filter, Precision::F64).unwrap());
        let mut figures = Vec::new();
        for view in views() {
            let image = spec.render_sampled(&view, &sampling, w, h).unwrap();
            let reference = match &reference_spec {
                Some(r) => r.render_sampled(&view, &sampling, w, h).unwrap(),
                None => exact_projection_sampled(&object, DIMS, &view, &sampling, w, h).unwrap(),
            };
            let snr = snr_db(&reference, &image);
            figures.push(format!("{snr:.1}"));
            assert!(
                snr >= floor,
                "{config:?} along {:?}: {snr:.2} dB < {floor} dB",
                view.dir
            );
        }
        println!(
            "{:?} oversample {} {} {}: {} dB (floor {floor})",
            config.filter,
            config.oversample,
            config.precision,
            if config.against_f64 {
                "vs f64 pipeline"
            } else {
                "vs exact"
            },
            figures.join(", ")
        );
    }
}

/// The same object in mm, sampled at `(0.75, 0.75, 1.5)` mm and at 0.75 mm
/// on every axis (the rotation centres coincide: `64 × 0.75/2 = 32 × 1.5/2`),
/// renders to the same physical image. Each is compared with the exact line
/// integrals and with the other: two images each within `S` dB of the exact
/// one differ by at most twice the error, so they agree to `S − 6.02` dB.
#[test]
fn anisotropic_and_isotropic_samplings_of_one_object_agree() {
    let side = 48.0;
    let object = phantom(2, side);
    let aniso_spacing = [0.75, 0.75, 1.5];
    let (aniso_dims, iso_dims) = ([64, 64, 32], [64, 64, 64]);
    let aniso = sample_spaced(&object, aniso_dims, aniso_spacing).unwrap();
    let iso = sample_spaced(&object, iso_dims, [0.75; 3]).unwrap();
    let aniso_sampling = Sampling::new(aniso_spacing, 0.75).unwrap();
    let iso_sampling = Sampling::new([0.75; 3], 0.75).unwrap();
    assert_eq!(
        aniso_sampling.center(aniso_dims),
        iso_sampling.center(iso_dims)
    );
    let (w, h) = (64, 64);
    for (kind, oversample, precision, floor) in [
        (FilterKind::Kb6, 2, Precision::F64, 85.0),
        (FilterKind::Kb4, 1, Precision::F16, 50.0),
    ] {
        let prepare = |v| {
            let filter = choose_filter(v, kind, oversample, KbDesign::Auto).unwrap();
            AnySpectrum::prepare(v, filter, precision).unwrap()
        };
        let (aniso_spec, iso_spec) = (prepare(&aniso), prepare(&iso));
        for view in views() {
            let exact =
                exact_projection_sampled(&object, iso_dims, &view, &iso_sampling, w, h).unwrap();
            let a = aniso_spec
                .render_sampled(&view, &aniso_sampling, w, h)
                .unwrap();
            let i = iso_spec.render_sampled(&view, &iso_sampling, w, h).unwrap();
            let (sa, si, sai) = (snr_db(&exact, &a), snr_db(&exact, &i), snr_db(&i, &a));
            println!(
                "{kind:?} oversample {oversample} {precision} along {:?}: anisotropic {sa:.1} dB, \
                 isotropic {si:.1} dB vs exact; anisotropic vs isotropic {sai:.1} dB",
                view.dir
            );
            assert!(sa >= floor, "anisotropic vs exact {sa:.2} dB < {floor}");
            assert!(si >= floor, "isotropic vs exact {si:.2} dB < {floor}");
            assert!(
                sai >= floor - 6.03,
                "anisotropic vs isotropic {sai:.2} dB < {floor} − 6.02"
            );
        }
    }
}

/// `Sampling::UNIT` is the voxel-unit path bit for bit: the full view and
/// a progressive preview, in f16 storage with f32 arithmetic.
#[test]
fn unit_sampling_is_bit_identical_to_voxel_units() {
    assert_eq!(Sampling::new([1.0; 3], 1.0).unwrap(), Sampling::UNIT);
    let dims = [40, 37, 33];
    let (spec, filter) = mixture_spectrum::<f16, f32>((5, 40, 6), dims, FilterKind::Kb4, 1);
    let n = spec.n();
    let kernel = KernelTable::<f32>::new(filter);
    fvr_tests::twiddles!(n; tw: f32);
    let mut grid = vec![0.0f32; grid_len(n)];
    let mut aux = vec![0.0f32; aux_len(n)];
    let unit = Sampling::new([1.0; 3], 1.0).unwrap();
    for dir in [[1.0, 0.3, 0.2], [-0.4, 1.0, 0.7]] {
        let view = View::along(dir);
        // The full view, then a progressive preview.
        for (level, (w, h)) in [(0, (63, 50)), (1, (31, 25))] {
            let m = n >> level;
            let defaults = Request {
                level,
                ..Request::new(view, w, h)
            };
            let sampled = Request {
                sampling: unit,
                ..defaults
            };
            let [old, new] = [defaults, sampled].map(|request| {
                let mut out = vec![0.0f32; w * h];
                let buffers = Buffers::new(&mut grid[..m * m], &mut aux, &mut out);
                render(&Source::new(&spec.view(), &kernel, &tw), &request, buffers).unwrap();
                out
            });
            assert!(old.iter().any(|&v| v != 0.0));
            assert_eq!(
                old.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                new.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            );
        }
    }
}

/// A progressive preview in physical units: level 1 is the projection at
/// pixels of `2p` mm, low-passed to their Nyquist frequency. For components
/// at least 2.25 mm wide, the spectrum beyond `1/(4p) = 0.31` cycles/mm
/// holds `exp(−4π²σ²η²) ≤ −72 dB` of the energy per component, so the
/// preview stays within the kb4 floor of the exact image at `2p`.
#[test]
fn anisotropic_preview_matches_exact_at_its_pitch() {
    let object = phantom(1, SIDE_MM);
    let volume = sample_spaced(&object, DIMS, SPACING).unwrap();
    let filter = choose_filter(&volume, FilterKind::Kb4, 1, KbDesign::Auto).unwrap();
    let spec = AnySpectrum::prepare(&volume, filter, Precision::F16).unwrap();
    let full = Sampling::new(SPACING, 0.8).unwrap();
    let coarse = Sampling::new(SPACING, 1.6).unwrap();
    for view in views() {
        let preview = spec.render_level_sampled(&view, &full, 32, 32, 1).unwrap();
        let exact = exact_projection_sampled(&object, DIMS, &view, &coarse, 32, 32).unwrap();
        let snr = snr_db(&exact, &preview);
        println!("kb4 f16 level 1 along {:?}: {snr:.1} dB", view.dir);
        assert!(snr >= 50.0, "preview {snr:.2} dB < 50 dB");
    }
}

/// Bad spacing or pixel size is refused with an error naming it.
#[test]
fn bad_spacing_and_pixel_size_are_named_errors() {
    for (spacing, axis) in [
        ([0.0, 1.0, 1.0], 0),
        ([1.0, -0.5, 1.0], 1),
        ([1.0, 1.0, f64::NAN], 2),
        ([1.0, f64::INFINITY, 1.0], 1),
    ] {
        let e = Sampling::new(spacing, 1.0).unwrap_err();
        match e {
            Error::InvalidSpacing { axis: a, .. } => assert_eq!(a, axis),
            other => panic!("{spacing:?}: {other:?}"),
        }
        let text = e.to_string();
        assert!(text.contains("voxel spacing"), "{text}");
        assert!(text.contains(["i (x)", "j (y)", "k (z)"][axis]), "{text}");
    }
    for p in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = Sampling::new([1.0; 3], p).unwrap_err();
        assert!(matches!(e, Error::InvalidPixelSize { .. }), "{e:?}");
        assert!(e.to_string().contains("pixel size"), "{e}");
    }
    let e = Sampling::new([1e300; 3], 1e-300).unwrap_err();
    assert!(matches!(e, Error::SamplingOutOfRange { .. }), "{e:?}");
    assert!(e.to_string().contains("pixel size"), "{e}");
    let e = Sampling::new([1e-200; 3], 1e200).unwrap_err();
    assert!(matches!(e, Error::SamplingOutOfRange { .. }), "{e:?}");
}

/// A linear cue and three coloured lights, none perpendicular to the views.
fn lit_cued_scene() -> Scene {
    let mut scene = Scene {
        cue: DepthCue::Linear {
            front: 1.0,
            back: 0.2,
        },
        ambient: [0.2, 0.2, 0.25],
        ..Scene::xray()
    };
    for (towards, color) in [
        ([0.0, 1.0, 0.2], [1.0, 0.25, 0.1]),
        ([0.3, -0.6, 0.8], [0.1, 0.9, 0.3]),
        ([-0.7, -0.4, -0.5], [0.2, 0.3, 1.0]),
    ] {
        scene.add_light(Light { towards, color }).unwrap();
    }
    scene
}

/// Cubic voxels of 0.75 mm imaged at 0.75 mm: cued and lit scenes in
/// physical units (ambient scaled by Δ, see `SceneSpectra::render_sampled`)
/// against the closed forms in mm, at the shading tests' floor for kb4 and
/// f16 (45 dB; `tests/shading.rs`). The Simpson step for `|∇f|` is 0.05 mm.
#[test]
fn cubic_voxels_render_cued_and_lit_scenes_in_mm() {
    let side = 48.0;
    let object = phantom(3, side);
    let dims = [64, 64, 64];
    let volume = sample_spaced(&object, dims, [0.75; 3]).unwrap();
    let sampling = Sampling::new([0.75; 3], 0.75).unwrap();
    let scene = lit_cued_scene();
    let filter = choose_filter(&volume, FilterKind::Kb4, 1, KbDesign::Auto).unwrap();
    let spectra = SceneSpectra::prepare(&volume, filter, Precision::F16, &scene).unwrap();
    // Not the axis view: its d·L = 0 for the first light.
    for view in views().into_iter().skip(1) {
        let image = spectra
            .render_sampled(&scene, &view, &sampling, 64, 64)
            .unwrap();
        let exact =
            exact_scene_projection_sampled(&object, dims, &sampling, &scene, &view, (64, 64), 0.05)
                .unwrap();
        let snr = snr_db(&exact.data, &image.data);
        println!(
            "kb4 f16 lit + linear cue, 0.75 mm voxels, along {:?}: {snr:.1} dB",
            view.dir
        );
        assert!(snr >= 45.0, "{snr:.2} dB < 45 dB");
    }
}

/// Cued or lit scenes on anisotropic voxels are refused with a message that
/// names the way out; X-ray scenes render.
#[test]
fn anisotropic_cued_or_lit_scenes_are_refused() {
    let volume = sample_spaced(&phantom(1, SIDE_MM), DIMS, SPACING).unwrap();
    let sampling = Sampling::new(SPACING, 0.8).unwrap();
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let scene = lit_cued_scene();
    let spectra = SceneSpectra::prepare(&volume, filter, Precision::F32, &scene).unwrap();
    let view = View::along([1.0, 0.3, 0.2]);
    let e = spectra
        .render_sampled(&scene, &view, &sampling, 32, 32)
        .unwrap_err();
    for needle in ["0.8 x 0.8 x 1.5 mm", "--resample", "--ignore-spacing"] {
        assert!(e.contains(needle), "`{needle}` not in: {e}");
    }
    let xray = spectra
        .render_sampled(&Scene::xray(), &view, &sampling, 32, 32)
        .unwrap();
    assert!(xray.data.iter().any(|&v| v > 0.0));
}
