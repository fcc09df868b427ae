//! The planner on real heads, on and off axis: for `brainsmall`, `ct-head`
//! (when installed, HU + 1024 so that air is 0) and `mri-head` (when
//! `FVR_MRI_HEAD` is set), each resampled whole to 64 and cropped to its
//! central 64³ (content cut at every face), the configuration chosen for
//! 40, 50 and 60 dB ([`choose`] on the power-of-two grids, [`choose_among`]
//! on [`ALL_GRIDS`]) is measured on the three axis views against the voxel
//! sums and on oblique views against the ideal slice DFT on a 2× slice
//! ([`slice_dft_projection`]), the slice of the 2× pipeline. Measured must
//! reach the target and the prediction must not be optimistic by more than
//! 3 dB. The oblique views are also measured, for the record, against the
//! ideal on a 4× slice: the band-limited image's faint tails repeat every
//! `m` pixels, so the two ideals differ (by 61–83 dB on these volumes).
//!
//! `FVR_CT_HEAD=$(bash scripts/fetch-ct-head.sh) FVR_MRI_HEAD=$(bash
//! scripts/fetch-mri-head.sh) cargo test -p fvr-host --release --test
//! plan_real -- --ignored --nocapture` prints the table of docs/accuracy.md.

use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;
use fvr_core::volume::GridOversampling;
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::plan::{
    choose, choose_among, grid_filter, image_side, predict_grid, Candidate, Constraints, Plan,
    ALL_GRIDS, AXIS_VIEWS,
};
use fvr_engine::spectrum::{AnySpectrum, Precision};
use fvr_engine::volume::Volume;
use fvr_host::reference::axis::axis_projection;
use fvr_host::reference::slice_dft::slice_dft_projection;
use fvr_host::reference::snr_db;
use fvr_host::sources::datasets::{ct_head_path, load_dataset, MRI_HEAD_ENV};

/// Never optimistic by more than this (dB).
const OPTIMISM_LIMIT_DB: f64 = 3.0;

/// Side of the test volumes.
const SIDE: usize = 64;

/// The oblique views measured against the ideal slice DFT.
const OBLIQUE: [[f64; 3]; 2] = [[1.0, 0.6, 0.3], [-0.3, 1.0, 0.8]];

/// The configurations chosen for `target` dB on the power-of-two grids
/// ([`choose`]) and on every grid ([`choose_among`]), each named.
fn plans(volume: &Volume, target: f64) -> [(&'static str, Plan); 2] {
    let d = Constraints::default();
    let pow2 = choose(volume, KbDesign::Auto, target, d).unwrap();
    let mixed = choose_among(volume, KbDesign::Auto, target, d, &ALL_GRIDS).unwrap();
    [("choose", pow2), ("choose_among", mixed)]
}

/// Records in `failures` what is wrong with `case`: no candidate predicted
/// to meet the target (`met` false), a measurement below it, or a
/// prediction optimistic by more than [`OPTIMISM_LIMIT_DB`].
fn judge(failures: &mut Vec<String>, case: &str, met: bool, target: f64, measured: f64, pred: f64) {
    if !met {
        failures.push(format!("{case}: no candidate predicted to meet it"));
    } else if measured < target {
        failures.push(format!("{case}: below the target"));
    }
    if measured < pred - OPTIMISM_LIMIT_DB {
        failures.push(format!("{case}: optimistic by more than 3 dB"));
    }
}

/// The real heads available: `brainsmall` always, the others when fetched.
fn heads() -> Vec<(&'static str, Volume)> {
    let mut out = vec![("brainsmall", load_dataset("brainsmall").unwrap().unwrap())];
    if ct_head_path().is_ok() {
        let mut ct = load_dataset("ct-head").unwrap().unwrap();
        ct.subtract_background(-1024.0).unwrap();
        out.push(("ct-head", ct));
    }
    if std::env::var_os(MRI_HEAD_ENV).is_some() {
        out.push(("mri-head", load_dataset("mri-head").unwrap().unwrap()));
    }
    out
}

/// The central `side³` block of `volume` (zeros where it is smaller).
fn central_crop(volume: &Volume, side: usize) -> Volume {
    let mut out = Volume::zeros([side; 3]);
    let start: [i64; 3] = std::array::from_fn(|a| (volume.dims[a] as i64 - side as i64) / 2);
    for k in 0..side {
        for j in 0..side {
            for i in 0..side {
                let p = [i, j, k];
                let src: [i64; 3] = std::array::from_fn(|a| start[a] + p[a] as i64);
                if (0..3).all(|a| (0..volume.dims[a] as i64).contains(&src[a])) {
                    let v = volume.get(src[0] as usize, src[1] as usize, src[2] as usize);
                    let at = out.index(i, j, k);
                    out.data[at] = v;
                }
            }
        }
    }
    out
}

/// Each head resampled whole to [`SIDE`] and its central [`SIDE`]³ crop.
fn volumes() -> Vec<(String, Volume)> {
    let mut out = Vec::new();
    for (name, head) in heads() {
        let whole = head.resample_isotropic(SIDE).unwrap().cropped_to_even();
        out.push((format!("{name} whole at {SIDE}"), whole));
        out.push((format!("{name} central {SIDE}³"), central_crop(&head, SIDE)));
    }
    out
}

/// The exact images: voxel sums for the axis views, the ideal slice DFT on
/// a 2× slice for the oblique ones, then the oblique ones again on a 4×
/// slice (whose image repeats twice as far apart).
fn references(volume: &Volume, side: usize) -> Vec<Vec<f64>> {
    let n = fvr_core::volume::padded_size(volume.dims, 1).unwrap();
    let axis = AXIS_VIEWS.iter().map(|view| {
        axis_projection(volume, view, side, side)
            .unwrap()
            .expect("axis views with pixels on voxels")
    });
    let oblique = [2, 4].into_iter().flat_map(|f| {
        OBLIQUE.iter().map(move |&dir| {
            slice_dft_projection(volume, &View::along(dir), side, side, f * n).unwrap()
        })
    });
    axis.chain(oblique).collect()
}

/// Measured dB of `c` on `grid` in every view of [`references`].
fn measure(volume: &Volume, c: Candidate, grid: GridOversampling, exact: &[Vec<f64>]) -> Vec<f64> {
    let filter = grid_filter(volume, c.filter, grid, KbDesign::Auto).unwrap();
    let spec = AnySpectrum::prepare_grid(volume, filter, c.precision, grid).unwrap();
    let side = image_side(volume.dims, spec.n()).unwrap();
    let views = AXIS_VIEWS
        .iter()
        .copied()
        .chain(OBLIQUE.iter().chain(&OBLIQUE).map(|&d| View::along(d)));
    views
        .zip(exact)
        .map(|(view, exact)| snr_db(exact, &spec.render(&view, side, side).unwrap()))
        .collect()
}

fn grid_name(c: Candidate, grid: GridOversampling) -> String {
    format!("{} σ{} {}", c.filter.name(), grid.name(), c.precision)
}

fn list(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| format!("{v:.1}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The ideal reference on a 2× slice against f64 kb6 at 2× (the cross-check)
/// and against the ideal on a 4× slice (the repeats of the image every 2×
/// side that the reference keeps).
#[test]
#[ignore = "seconds per volume in release; run with --release --ignored --nocapture"]
fn ideal_reference_cross_checks_on_real_heads() {
    println!(
        "| volume | view | f64 kb6 σ2 against ideal (dB) | ideal at 2× against 4× slice (dB) |"
    );
    println!("|---|---|---|---|");
    for (vname, volume) in volumes() {
        let side = fvr_core::volume::padded_size(volume.dims, 1).unwrap();
        let grid = GridOversampling::X2;
        let filter = grid_filter(&volume, FilterKind::Kb6, grid, KbDesign::Auto).unwrap();
        let spec = AnySpectrum::prepare_grid(&volume, filter, Precision::F64, grid).unwrap();
        for dir in OBLIQUE {
            let view = View::along(dir);
            let ideal = slice_dft_projection(&volume, &view, side, side, 2 * side).unwrap();
            let wide = slice_dft_projection(&volume, &view, side, side, 4 * side).unwrap();
            let kb6 = snr_db(&ideal, &spec.render(&view, side, side).unwrap());
            let repeats = snr_db(&wide, &ideal);
            println!("| {vname} | {dir:?} | {kb6:.1} | {repeats:.1} |");
            // The reference judges targets up to 60 dB: it must be closer
            // than that to both.
            assert!(kb6 >= 60.0, "{vname} {dir:?}: kb6 at 2x {kb6:.1} dB");
            assert!(repeats >= 60.0, "{vname} {dir:?}: 2x slice {repeats:.1} dB");
        }
    }
}

/// The table of docs/accuracy.md, "Real heads, on and off axis".
#[test]
#[ignore = "minutes in release; run with --release --ignored --nocapture"]
fn planner_meets_targets_on_real_heads_on_and_off_axis() {
    let mut failures = Vec::new();
    println!(
        "| volume | target | chooser | config | predicted dB (x, y, z; oblique) | \
         measured dB (x, y, z; {:?}, {:?}) | oblique against the 4× slice |",
        OBLIQUE[0], OBLIQUE[1]
    );
    println!("|---|---|---|---|---|---|---|");
    for (vname, volume) in volumes() {
        let side = fvr_core::volume::padded_size(volume.dims, 1).unwrap();
        let exact = references(&volume, side);
        for target in [40.0, 50.0, 60.0] {
            for (chooser, plan) in plans(&volume, target) {
                let (c, grid) = (plan.prediction.candidate, plan.prediction.grid);
                let p = predict_grid(&volume, c, grid, KbDesign::Auto).unwrap();
                let m = measure(&volume, c, grid, &exact);
                let predicted: Vec<f64> = p.views_db.iter().copied().chain([p.db; 2]).collect();
                println!(
                    "| {vname} | {target} | {chooser} | {} | {}; {:.1} | {}; {} | {} |",
                    grid_name(c, grid),
                    list(&p.views_db),
                    p.db,
                    list(&m[..3]),
                    list(&m[3..5]),
                    list(&m[5..])
                );
                let views = AXIS_VIEWS
                    .iter()
                    .map(|v| format!("{:?}", v.dir))
                    .chain(OBLIQUE.iter().map(|d| format!("{d:?}")));
                for ((view, &measured), &pred) in views.zip(&m).zip(&predicted) {
                    let case = format!(
                        "{vname}, view {view}, target {target} ({chooser}): {} predicted {pred:.1} dB, measured {measured:.1} dB",
                        grid_name(c, grid)
                    );
                    judge(&mut failures, &case, plan.met, target, measured, pred);
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// The MRI head at full size (cut to even sizes), axis views only: the
/// choices for 40, 50 and 60 dB against the voxel sums.
#[test]
#[ignore = "needs FVR_MRI_HEAD; minutes in release; run with --release --ignored --nocapture"]
fn planner_meets_targets_on_the_full_mri_head_on_axis() {
    let volume = load_dataset("mri-head").unwrap().unwrap().cropped_to_even();
    let mut failures = Vec::new();
    println!(
        "| volume | target | chooser | config | predicted dB (x, y, z) | measured dB (x, y, z) |"
    );
    println!("|---|---|---|---|---|---|");
    let side = fvr_core::volume::padded_size(volume.dims, 1).unwrap();
    let exact: Vec<Vec<f64>> = AXIS_VIEWS
        .iter()
        .map(|view| axis_projection(&volume, view, side, side).unwrap().unwrap())
        .collect();
    for target in [40.0, 50.0, 60.0] {
        for (chooser, plan) in plans(&volume, target) {
            let (c, grid) = (plan.prediction.candidate, plan.prediction.grid);
            let p = predict_grid(&volume, c, grid, KbDesign::Auto).unwrap();
            let filter = grid_filter(&volume, c.filter, grid, KbDesign::Auto).unwrap();
            let spec = AnySpectrum::prepare_grid(&volume, filter, c.precision, grid).unwrap();
            let m: Vec<f64> = AXIS_VIEWS
                .iter()
                .zip(&exact)
                .map(|(view, exact)| snr_db(exact, &spec.render(view, side, side).unwrap()))
                .collect();
            println!(
                "| mri-head {:?} | {target} | {chooser} | {} | {} | {} |",
                volume.dims,
                grid_name(c, grid),
                list(&p.views_db),
                list(&m)
            );
            for (v, (&measured, &pred)) in m.iter().zip(&p.views_db).enumerate() {
                let case = format!(
                    "mri-head axis {v}, target {target} ({chooser}): {} predicted {pred:.1} dB, measured {measured:.1} dB",
                    grid_name(c, grid)
                );
                judge(&mut failures, &case, plan.met, target, measured, pred);
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// What limits the oblique views of the whole heads on σ < 2: the image's
/// period, not the kernel. In f64, kb5 and kb6 agree to 1 dB on every grid
/// σ = 1.25 and 1.5 (a kernel's leak between grid points would differ
/// between them by tens of dB), and on σ = 1 kb6 is closer to the ideal
/// on an `n`-sample slice (the pipeline's period) than to the ideal on a
/// 2n-sample one. The table of docs/accuracy.md, "Oblique views: the
/// image's period".
#[test]
#[ignore = "seconds per volume in release; run with --release --ignored --nocapture"]
fn oblique_error_below_twice_padding_is_the_image_period_not_the_kernel() {
    println!("| volume | view | ideal on an n slice against 2n (dB) | f64 kb5, kb6 against the 2n ideal on σ1, σ1.25, σ1.5, σ2 (dB) | f64 kb6 σ1 against the n ideal (dB) |");
    println!("|---|---|---|---|---|");
    for (vname, volume) in volumes() {
        if !vname.contains("whole") {
            continue;
        }
        let side = fvr_core::volume::padded_size(volume.dims, 1).unwrap();
        for dir in OBLIQUE {
            let view = View::along(dir);
            let ideal = slice_dft_projection(&volume, &view, side, side, 2 * side).unwrap();
            let ideal1 = slice_dft_projection(&volume, &view, side, side, side).unwrap();
            let render = |kind: FilterKind, grid: GridOversampling| {
                let filter = grid_filter(&volume, kind, grid, KbDesign::Auto).unwrap();
                let spec =
                    AnySpectrum::prepare_grid(&volume, filter, Precision::F64, grid).unwrap();
                spec.render(&view, side, side).unwrap()
            };
            let mut cells = Vec::new();
            for grid in ALL_GRIDS {
                let (kb5, kb6) = (
                    snr_db(&ideal, &render(FilterKind::Kb5, grid)),
                    snr_db(&ideal, &render(FilterKind::Kb6, grid)),
                );
                cells.push(format!("{kb5:.1}, {kb6:.1}"));
                if !grid.is_pow2() {
                    assert!(
                        (kb5 - kb6).abs() <= 1.0,
                        "{vname} {dir:?} σ{}: {kb5:.1} {kb6:.1}",
                        grid.name()
                    );
                }
            }
            let kb6_1 = render(FilterKind::Kb6, GridOversampling::X1);
            let (near, far) = (snr_db(&ideal1, &kb6_1), snr_db(&ideal, &kb6_1));
            assert!(near > far, "{vname} {dir:?}: {near:.1} {far:.1}");
            println!(
                "| {vname} | {dir:?} | {:.1} | {} | {near:.1} |",
                snr_db(&ideal, &ideal1),
                cells.join("; ")
            );
        }
    }
}
