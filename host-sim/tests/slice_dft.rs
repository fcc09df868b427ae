//! The ideal slice-DFT projection ([`slice_dft_projection`]) against the
//! exact references it must equal: the voxel sums for axis views with
//! pixels on voxels (any slice side holding the volume), the O(n⁵)
//! [`ideal_projection`] on the same slice, and, for oblique views, the f64
//! pipeline with kb6 at 2× padding, which must agree to its predicted
//! accuracy (the planner's claim, never optimistic by more than 3 dB).

mod common;

use common::xorshift_noise;
use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;
use fvr_core::volume::{padded_size, GridOversampling};
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::plan::{grid_filter, predict_grid, Candidate, AXIS_VIEWS};
use fvr_engine::spectrum::{AnySpectrum, Precision};
use fvr_engine::volume::Volume;
use fvr_host::reference::axis::axis_projection;
use fvr_host::reference::slice_dft::slice_dft_projection;
use fvr_host::reference::{ideal_projection, max_abs_error, snr_db};
use fvr_host::sources::datasets::load_dataset;

/// Uniform noise in [0, 1) (fixed seed): every frequency present, content
/// at every face.
fn noise(dims: [usize; 3]) -> Volume {
    xorshift_noise(dims, 0x9e37_79b9_7f4a_7c15)
}

/// Rounding bound for an image of sums of `volume`: each DFT value sums
/// `N³` products (four partial sums, then rows and planes) and the inverse
/// transform adds `2·log₂m` passes, each erring by a unit roundoff of the
/// largest partial sum, at most `Σ|f|`.
fn rounding_bound(volume: &Volume, m: usize) -> f64 {
    let total: f64 = volume.data.iter().map(|&v| f64::from(v).abs()).sum();
    let terms = volume.dims.iter().sum::<usize>() as f64 + 2.0 * (m as f64).log2();
    f64::EPSILON * terms * total
}

/// The image repeats every `m` pixels: a slice side larger than the volume
/// along the image axes keeps pixels beyond the volume at 0 (a 16-voxel
/// side on a 16-pixel slice would wrap the pixel at 16, beyond the volume
/// when `right` is `−x`, onto voxel 0).
#[test]
fn axis_views_are_the_voxel_sums_on_any_slice_side_beyond_the_volume() {
    for (dims, sides) in [([14, 12, 10], [16, 32]), ([16, 12, 10], [32, 64])] {
        let volume = noise(dims);
        let side = padded_size(volume.dims, 1).unwrap();
        for (m, view) in sides.into_iter().flat_map(|m| AXIS_VIEWS.map(|v| (m, v))) {
            let exact = axis_projection(&volume, &view, side, side)
                .unwrap()
                .unwrap();
            let ideal = slice_dft_projection(&volume, &view, side, side, m).unwrap();
            let err = max_abs_error(&exact, &ideal);
            let bound = rounding_bound(&volume, m);
            assert!(err <= bound, "{dims:?} m {m} {view:?}: {err:e} > {bound:e}");
        }
    }
}

#[test]
fn equals_the_direct_ideal_projection_on_oblique_views() {
    let volume = noise([12, 10, 8]);
    let side = padded_size(volume.dims, 1).unwrap();
    for dir in [[1.0, 0.3, 0.2], [-0.4, 1.0, 0.7], [0.2, -0.5, -1.0]] {
        let view = View::along(dir);
        let direct = ideal_projection(&volume, &view, side, side).unwrap();
        let ideal = slice_dft_projection(&volume, &view, side, side, side).unwrap();
        let err = max_abs_error(&direct, &ideal);
        let bound = 2.0 * rounding_bound(&volume, side);
        assert!(err <= bound, "{dir:?}: {err:e} > {bound:e}");
    }
}

#[test]
fn rejects_slices_that_cannot_hold_the_volume() {
    let volume = noise([12, 10, 8]);
    let view = View::along([1.0, 0.3, 0.2]);
    assert!(slice_dft_projection(&volume, &view, 16, 16, 8).is_err());
    assert!(slice_dft_projection(&volume, &view, 16, 16, 24).is_err());
    assert!(slice_dft_projection(&volume, &view, 32, 32, 16).is_err());
}

/// Oblique views of the MRI head `brainsmall` (at 32, touching the box):
/// the f64 pipeline with kb6 at 2× agrees with the ideal projection on the
/// same 2× slice to at least its predicted accuracy less 3 dB.
#[test]
fn f64_kb6_at_2x_agrees_with_the_ideal_on_oblique_views() {
    let volume = load_dataset("brainsmall")
        .unwrap()
        .unwrap()
        .resample_isotropic(32)
        .unwrap()
        .cropped_to_even();
    let grid = GridOversampling::X2;
    let c = Candidate {
        filter: FilterKind::Kb6,
        oversample: 2,
        precision: Precision::F64,
    };
    let predicted = predict_grid(&volume, c, grid, KbDesign::Auto).unwrap().db;
    let filter = grid_filter(&volume, c.filter, grid, KbDesign::Auto).unwrap();
    let spec = AnySpectrum::prepare_grid(&volume, filter, c.precision, grid).unwrap();
    let side = padded_size(volume.dims, 1).unwrap();
    for dir in [[1.0, 0.6, 0.3], [-0.3, 1.0, 0.8]] {
        let view = View::along(dir);
        let ideal = slice_dft_projection(&volume, &view, side, side, spec.n()).unwrap();
        let image = spec.render(&view, side, side).unwrap();
        let db = snr_db(&ideal, &image);
        println!("{dir:?}: kb6 2x f64 {db:.1} dB against the ideal, predicted {predicted:.1} dB");
        assert!(
            db >= predicted - 3.0,
            "{dir:?}: {db:.1} dB, predicted {predicted:.1}"
        );
    }
}
