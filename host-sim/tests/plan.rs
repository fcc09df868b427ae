//! The accuracy predictor against measurement: for axis views with pixels
//! on voxels the exact image is the voxel sum along each line
//! ([`axis_projection`]), and the prediction ([`predict`]) must never be
//! optimistic by more than 3 dB. The chooser ([`choose`]) must pick a
//! configuration whose measured accuracy meets the target.
//!
//! `cargo test -p fvr-host --release --test plan -- --ignored --nocapture`
//! prints the table of docs/accuracy.md (with ct-head rows when
//! `FVR_CT_HEAD` names the CT head).

mod common;

use common::xorshift_noise;
use fvr_core::filter::FilterKind;
use fvr_core::volume::GridOversampling;
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::plan::{
    choose, choose_among, cost_grid, grid_filter, image_side, predict_grid, Candidate, Constraints,
    ALL_GRIDS, AXIS_VIEWS, MARGIN_DB,
};
use fvr_engine::spectrum::{AnySpectrum, Precision};
use fvr_engine::volume::Volume;
use fvr_host::reference::axis::axis_projection;
use fvr_host::reference::snr_db;
use fvr_host::sources::datasets::load_dataset;
use fvr_host::sources::phantom_by_name;

/// Never optimistic by more than this (dB).
const OPTIMISM_LIMIT_DB: f64 = 3.0;

fn phantom(spec: &str) -> Volume {
    phantom_by_name(spec).unwrap().unwrap().volume
}

/// `brainsmall` at half size (64 × 64 × 42): the MRI head touches the box.
fn brain64() -> Volume {
    load_dataset("brainsmall")
        .unwrap()
        .unwrap()
        .resample_isotropic(64)
        .unwrap()
}

/// The Gaussians at 64³ rolled by a quarter of the box along x and y, so
/// that blobs cross the faces: content at the edges of the box.
fn rolled_gaussians() -> Volume {
    let src = phantom("gaussians@64");
    let [nx, ny, nz] = src.dims;
    let mut out = Volume::zeros(src.dims);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let v = src.get((i + nx / 4) % nx, (j + ny / 4) % ny, k);
                let at = out.index(i, j, k);
                out.data[at] = v;
            }
        }
    }
    out
}

/// Uniform noise in [0, 1) filling a 32³ box (fixed seed).
fn noise_box() -> Volume {
    xorshift_noise([32; 3], 0x2545_f491_4f6c_dd1d)
}

/// Measured SNR of each axis view against the voxel sums, on the
/// power-of-two grid of the candidate's oversampling.
fn measure(volume: &Volume, c: Candidate) -> [f64; 3] {
    let grid = GridOversampling::from_integer(c.oversample).unwrap();
    measure_grid(volume, c, grid)
}

/// [`measure`] on the grid `grid` (mixed radix for σ = 1.25 and 1.5).
fn measure_grid(volume: &Volume, c: Candidate, grid: GridOversampling) -> [f64; 3] {
    let filter = grid_filter(volume, c.filter, grid, KbDesign::Auto).unwrap();
    let spec = AnySpectrum::prepare_grid(volume, filter, c.precision, grid).unwrap();
    let side = image_side(volume.dims, spec.n()).unwrap();
    AXIS_VIEWS.map(|view| {
        let image = spec.render(&view, side, side).unwrap();
        let exact = axis_projection(volume, &view, side, side)
            .unwrap()
            .expect("axis views with pixels on voxels");
        snr_db(&exact, &image)
    })
}

fn volumes() -> Vec<(&'static str, Volume)> {
    vec![
        ("gaussians@64", phantom("gaussians@64")),
        ("shepp-logan@64", phantom("shepp-logan@64")),
        ("sphere@64", phantom("sphere@64")),
        ("brainsmall/2", brain64()),
        ("rolled gaussians", rolled_gaussians()),
        ("noise 32³", noise_box()),
    ]
}

/// Every filter × grid (σ = 1, 1.25, 1.5, 2) × precision the planner
/// considers.
fn candidates() -> Vec<(Candidate, GridOversampling)> {
    let mut out = Vec::new();
    for filter in [
        FilterKind::Cubic,
        FilterKind::Kb3,
        FilterKind::Kb4,
        FilterKind::Kb5,
        FilterKind::Kb6,
    ] {
        for grid in ALL_GRIDS {
            for precision in [Precision::F16, Precision::F32] {
                let c = Candidate {
                    filter,
                    oversample: grid.integer(),
                    precision,
                };
                out.push((c, grid));
            }
        }
    }
    out
}

fn name(c: Candidate) -> String {
    format!("{} os{} {}", c.filter.name(), c.oversample, c.precision)
}

fn grid_name(c: Candidate, grid: GridOversampling) -> String {
    format!("{} σ{} {}", c.filter.name(), grid.name(), c.precision)
}

#[test]
fn prediction_is_never_optimistic_by_more_than_3_db() {
    let mut failures = Vec::new();
    for (vname, volume) in volumes() {
        for (c, grid) in candidates() {
            let p = predict_grid(&volume, c, grid, KbDesign::Auto).unwrap();
            let m = measure_grid(&volume, c, grid);
            for (v, axis) in ["x", "y", "z"].iter().enumerate() {
                let line = format!(
                    "{vname} {axis} {}: predicted {:.1} dB, measured {:.1} dB",
                    grid_name(c, grid),
                    p.views_db[v],
                    m[v]
                );
                println!("{line}");
                if m[v] < p.views_db[v] - OPTIMISM_LIMIT_DB {
                    failures.push(line);
                }
            }
        }
    }
    assert!(failures.is_empty(), "optimistic:\n{}", failures.join("\n"));
}

#[test]
fn chooser_meets_40_and_50_db_on_edge_touching_volumes() {
    for (vname, volume) in [
        ("brainsmall/2", brain64()),
        ("rolled gaussians", rolled_gaussians()),
    ] {
        for target in [40.0, 50.0] {
            let plan = choose(&volume, KbDesign::Auto, target, Constraints::default()).unwrap();
            let c = plan.prediction.candidate;
            let m = measure(&volume, c);
            let worst = m.iter().copied().fold(f64::INFINITY, f64::min);
            println!(
                "{vname} target {target}: {} predicted {:.1} dB, measured {worst:.1} dB",
                name(c),
                plan.prediction.db
            );
            assert!(
                plan.met,
                "{vname}: no candidate predicted to reach {target} dB"
            );
            // Candidates reach the target with the margin on these volumes,
            // so the choice keeps it.
            assert!(
                plan.prediction.db >= target + MARGIN_DB,
                "{vname}: predicted {:.1} dB for {target}",
                plan.prediction.db
            );
            assert!(
                worst >= target,
                "{vname}: {} chosen for {target} dB measures {worst:.1} dB (predicted {:.1})",
                name(c),
                plan.prediction.db
            );
        }
    }
}

/// With the mixed-radix grids among the candidates, the chooser still
/// meets the target when measured, at no more cost than the power-of-two
/// grids alone; on content touching the faces at 50 dB it takes a
/// mixed-radix grid (σ = 1 leaks at the faces, σ = 2 costs more).
#[test]
fn chooser_among_mixed_grids_meets_the_target_for_less() {
    for (vname, volume) in [
        ("brainsmall/2", brain64()),
        ("rolled gaussians", rolled_gaussians()),
    ] {
        for target in [40.0, 50.0] {
            let constraints = Constraints::default();
            let plan =
                choose_among(&volume, KbDesign::Auto, target, constraints, &ALL_GRIDS).unwrap();
            let pow2 = choose(&volume, KbDesign::Auto, target, constraints).unwrap();
            let (c, grid) = (plan.prediction.candidate, plan.prediction.grid);
            let m = measure_grid(&volume, c, grid);
            let worst = m.iter().copied().fold(f64::INFINITY, f64::min);
            let cost = cost_grid(c, grid, volume.dims).unwrap();
            let pow2_cost =
                cost_grid(pow2.prediction.candidate, pow2.prediction.grid, volume.dims).unwrap();
            println!(
                "{vname} target {target}: {} predicted {:.1} dB, measured {worst:.1} dB; \
                 cost {:.3e} against {:.3e} for {}",
                grid_name(c, grid),
                plan.prediction.db,
                cost.0,
                pow2_cost.0,
                grid_name(pow2.prediction.candidate, pow2.prediction.grid)
            );
            assert!(plan.met, "{vname}: nothing predicted to reach {target} dB");
            assert!(worst >= target, "{vname}: measured {worst:.1} dB");
            assert!(cost <= pow2_cost, "{vname}: the wider choice costs more");
            // The head at 50 dB: kb5 on a mixed grid costs less than any
            // power of two that reaches the target with the margin.
            if target == 50.0 && vname == "brainsmall/2" {
                assert!(!grid.is_pow2(), "{vname} at 50 dB: {}", grid.name());
            }
        }
    }
}

/// The walk runs only the candidates it must, and passes by those whose
/// wrap term alone keeps them below the target with the margin; its
/// choice is the one made from every candidate predicted: the cheapest
/// at the target with the margin, else at the target, else the best.
#[test]
fn the_walk_chooses_as_predicting_every_candidate_does() {
    let mut passed_cheaper = false;
    for (vname, volume) in [
        ("noise 32³", noise_box()),
        ("rolled gaussians", rolled_gaussians()),
    ] {
        // In the walk's order: grids, then filters, then precisions; then
        // by cost, ties in that order.
        let mut all = Vec::new();
        for grid in ALL_GRIDS {
            for filter in fvr_engine::plan::CANDIDATE_FILTERS {
                for precision in [Precision::F16, Precision::F32] {
                    let c = Candidate {
                        filter,
                        oversample: grid.integer(),
                        precision,
                    };
                    let p = predict_grid(&volume, c, grid, KbDesign::Auto).unwrap();
                    all.push((cost_grid(c, grid, volume.dims).unwrap(), p));
                }
            }
        }
        let best = all
            .iter()
            .map(|(_, p)| *p)
            .max_by(|a, b| a.db.total_cmp(&b.db))
            .unwrap();
        all.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
        for target in [20.0, 30.0, 40.0, 50.0, 60.0, 500.0] {
            let plan = choose_among(
                &volume,
                KbDesign::Auto,
                target,
                Constraints::default(),
                &ALL_GRIDS,
            )
            .unwrap();
            let expected = all
                .iter()
                .find(|(_, p)| p.db >= target + MARGIN_DB)
                .or_else(|| all.iter().find(|(_, p)| p.db >= target))
                .map_or(best, |(_, p)| *p);
            let got = plan.prediction;
            assert_eq!(
                (got.candidate, got.grid),
                (expected.candidate, expected.grid),
                "{vname} at {target} dB"
            );
            // The same passes over the volume, the filter fitted to the
            // same energy profile: the same figures to rounding.
            assert!(
                (got.db - expected.db).abs() < 1e-9,
                "{vname} at {target} dB: {} against {}",
                got.db,
                expected.db
            );
            assert_eq!(plan.met, expected.db >= target, "{vname} at {target} dB");
            passed_cheaper |= plan.met && all[0].1.db < target + MARGIN_DB;
        }
    }
    // Not vacuous: some choice passes cheaper candidates by.
    assert!(passed_cheaper);
}

#[test]
fn voxel_sums_only_for_axis_views_with_pixels_on_voxels() {
    let volume = phantom("sphere@16");
    let oblique = fvr_core::geometry::View::along([1.0, 0.3, 0.2]);
    assert!(axis_projection(&volume, &oblique, 16, 16)
        .unwrap()
        .is_none());
    // An odd image size puts the pixel centres half a voxel off the grid.
    assert!(axis_projection(&volume, &AXIS_VIEWS[0], 15, 16)
        .unwrap()
        .is_none());
    let sums = axis_projection(&volume, &AXIS_VIEWS[2], 16, 16)
        .unwrap()
        .unwrap();
    let total: f64 = volume.data.iter().map(|&v| v as f64).sum();
    let imaged: f64 = sums.iter().sum();
    assert!(
        (imaged - total).abs() <= 1e-9 * total.abs(),
        "{imaged} against {total}"
    );
}

#[test]
fn explicit_settings_constrain_the_choice() {
    let volume = rolled_gaussians();
    let given = Constraints {
        filter: Some(FilterKind::Kb3),
        ..Constraints::default()
    };
    let plan = choose(&volume, KbDesign::Auto, 50.0, given).unwrap();
    assert_eq!(plan.prediction.candidate.filter, FilterKind::Kb3);
    assert_eq!(plan.prediction.candidate.oversample, 2);
    let hopeless = Constraints {
        oversample: Some(GridOversampling::X1),
        ..Constraints::default()
    };
    let plan = choose(&volume, KbDesign::Auto, 50.0, hopeless).unwrap();
    assert!(
        !plan.met,
        "oversampling 1 cannot reach 50 dB on content at the faces"
    );
    assert_eq!(plan.prediction.candidate.oversample, 1);
}

/// The table of docs/accuracy.md, "Predicted against measured".
#[test]
#[ignore = "prints the docs table; run with --release --ignored --nocapture"]
fn predicted_against_measured_table() {
    let mut rows: Vec<(String, Volume)> = vec![
        ("gaussians@64".into(), phantom("gaussians@64")),
        ("shepp-logan@64".into(), phantom("shepp-logan@64")),
        (
            "brainsmall".into(),
            load_dataset("brainsmall").unwrap().unwrap(),
        ),
        ("rolled gaussians@64".into(), rolled_gaussians()),
        ("noise 32³".into(), noise_box()),
    ];
    if std::env::var_os("FVR_CT_HEAD").is_some() {
        let ct = load_dataset("ct-head").unwrap().unwrap();
        rows.push((
            "ct-head at 256".into(),
            ct.resample_isotropic(256).unwrap().cropped_to_even(),
        ));
    }
    println!("| volume | config | predicted dB | measured dB (x, y, z) | dominant |");
    println!("|---|---|---|---|---|");
    for (vname, volume) in &rows {
        let plain = Candidate {
            filter: FilterKind::Kb4,
            oversample: 1,
            precision: Precision::F16,
        };
        let pow2 = |c: Candidate| (c, GridOversampling::from_integer(c.oversample).unwrap());
        let mut configs = vec![(pow2(plain), "given".to_string())];
        // What `fvr` chooses for plain X-ray views, then for scenes and
        // adaptive filtering (powers of two) at the default.
        for (target, note) in [(40.0, ""), (50.0, ", the default"), (60.0, "")] {
            let d = Constraints::default();
            let plan = choose_among(volume, KbDesign::Auto, target, d, &ALL_GRIDS).unwrap();
            let chosen = (plan.prediction.candidate, plan.prediction.grid);
            configs.push((chosen, format!("--accuracy {target}{note}")));
        }
        let plan = choose(volume, KbDesign::Auto, 50.0, Constraints::default()).unwrap();
        configs.push((
            pow2(plan.prediction.candidate),
            "50 dB, σ = 1 or 2 for scenes".into(),
        ));
        for ((c, grid), why) in configs {
            let p = predict_grid(volume, c, grid, KbDesign::Auto).unwrap();
            let m = measure_grid(volume, c, grid);
            println!(
                "| {vname} {:?} | {} ({why}) | {:.1} | {:.1}, {:.1}, {:.1} | {} |",
                volume.dims,
                grid_name(c, grid),
                p.db,
                m[0],
                m[1],
                m[2],
                p.dominant().name()
            );
        }
    }
}
