//! The spatial-domain peer ray caster: correct before it is fast.

use fvr_core::geometry::View;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_host::reference::raycast::RayCaster;
use fvr_host::reference::{exact_projection, snr_db, spatial_projection};

/// Against the f64 trilinear ray integrator at a fine step, the f32 caster
/// at the same step differs only by f32 accumulation (≈ 2⁻²⁴·√samples) and
/// the placement of the midpoints (O(h²·f'') with h = ¼).
#[test]
fn ray_caster_matches_f64_trilinear_integrator_and_exact() {
    let n = 48;
    let mixture = GaussianMixture::random(9, n, 6);
    let volume = sample(&mixture, [n; 3]);
    let caster = RayCaster::new(&volume);
    for view in [
        View::along([1.0, 0.0, 0.0]),
        View::along([1.0, 0.45, -0.3]),
        View {
            dir: [0.0, 0.0, 1.0],
            up: [0.0, 1.0, 0.0],
        },
    ] {
        let image: Vec<f64> = caster
            .project(&view, n, n, 0.25, 0)
            .unwrap()
            .into_iter()
            .map(f64::from)
            .collect();
        let f64_ref = spatial_projection(&volume, &view, n, n, 0.25).unwrap();
        let exact = exact_projection(&mixture, [n; 3], &view, n, n).unwrap();
        let (s_ref, s_exact) = (snr_db(&f64_ref, &image), snr_db(&exact, &image));
        assert!(s_ref >= 60.0, "{view:?}: vs f64 integrator {s_ref:.1} dB");
        // Trilinear interpolation of σ ≥ 1.5 Gaussians: about 40 dB.
        assert!(s_exact >= 35.0, "{view:?}: vs exact {s_exact:.1} dB");
        assert!(image.iter().all(|v| v.is_finite()));
    }
}

#[test]
fn ray_caster_threads_do_not_change_the_image() {
    let volume = sample(&GaussianMixture::random(4, 32, 4), [32, 20, 27]);
    let caster = RayCaster::new(&volume);
    let view = View::along([0.3, 1.0, 0.2]);
    let one = caster.project(&view, 31, 17, 0.5, 1).unwrap();
    for threads in [2, 3, 8] {
        assert_eq!(caster.project(&view, 31, 17, 0.5, threads).unwrap(), one);
    }
    assert!(caster.project(&view, 8, 8, 0.0, 1).is_err());
    assert!(caster.project(&view, 8, 8, f32::NAN, 1).is_err());
    assert!(caster
        .project(&View::along([0.0; 3]), 8, 8, 1.0, 1)
        .is_err());
}
