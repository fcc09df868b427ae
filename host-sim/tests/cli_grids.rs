//! The mixed-radix grids on the command line: `--oversample 1.25|1.5`, the
//! planner choosing them for plain X-ray views only, the scene key, and
//! the refusals for what needs a power-of-two side.

mod common;
use common::{assert_error, assert_refused, fvr_in, stats_json, temp_dir};

#[test]
fn an_explicit_mixed_grid_renders_on_its_side_with_the_default_image() {
    // brainsmall is 128×128×84: σ = 1.25 gives the side 160, σ = 1.5 192,
    // and the image keeps the σ = 1 side, 128.
    for (sigma, side) in [("1.25", 160), ("1.5", 192)] {
        let (stats, _) = stats_json(
            &format!(
                "render brainsmall --dir 1,0.3,0.2 --oversample {sigma} --out a.png --stats-json"
            ),
            &temp_dir(&format!("grid-{sigma}")),
        );
        assert_eq!(stats["spectrum_side"], side, "{stats}");
        assert_eq!(stats["oversample"].as_f64(), sigma.parse().ok(), "{stats}");
        assert_eq!(stats["image"], serde_json::json!([128, 128, 1]), "{stats}");
        let acc = &stats["accuracy"];
        assert_eq!(acc["oversample"], stats["oversample"], "{stats}");
    }
}

#[test]
fn the_planner_may_choose_mixed_grids_for_plain_views_only() {
    // A cued view of the same head keeps to the power-of-two grids.
    let dir = temp_dir("grid-cued");
    let (stats, _) = stats_json(
        "render brainsmall --dir 0,1,0 --depth-cue linear:1,0.3 --out a.png --stats-json",
        &dir,
    );
    let side = stats["spectrum_side"].as_u64().unwrap();
    assert!(side.is_power_of_two(), "{stats}");
    assert!(stats["oversample"].is_u64(), "{stats}");
    // The plain view: whatever is chosen meets the prediction's target and
    // is no larger than the cued view's grid.
    let (plain, _) = stats_json(
        "render brainsmall --dir 0,1,0 --out a.png --stats-json",
        &dir,
    );
    assert!(
        plain["accuracy"]["predicted_db"].as_f64().unwrap() >= 50.0,
        "{plain}"
    );
    assert!(
        plain["spectrum_side"].as_u64().unwrap() <= side,
        "{plain} against {stats}"
    );
}

#[test]
fn mixed_grids_are_refused_where_a_power_of_two_is_needed() {
    let (dir, out) = fvr_in(
        "grid-refused",
        "render brainsmall --dir 1,0,0 --oversample 1.5 --adaptive 40 --out a.png",
    );
    assert_error(&out, &["--oversample 1.5", "plain X-ray views", "1 or 2"]);
    assert_refused(
        &dir,
        &[
            (
                "render brainsmall --dir 1,0,0 --oversample 1.25 --light 0,1,0:1,1,1 --out a.png",
                &["--oversample 1.25", "plain X-ray views"],
            ),
            (
                "render brainsmall --dir 1,0,0 --oversample 3 --out a.png",
                &["expected 1, 1.25, 1.5 or 2, got `3`"],
            ),
        ],
    );
}

#[test]
fn turntables_and_scene_files_take_mixed_grids() {
    let dir = temp_dir("grid-turntable");
    let (stats, _) = stats_json(
        "turntable sphere@32 --frames 2 --oversample 1.25 --filter kb5 --out t.png --stats-json",
        &dir,
    );
    assert_eq!(stats["spectrum_side"], 40, "{stats}");
    assert_eq!(stats["oversample"], 1.25, "{stats}");
    assert_eq!(stats["image"], serde_json::json!([32, 32, 1]), "{stats}");
    std::fs::write(
        dir.join("s.toml"),
        "[volume]\nbuiltin = \"sphere@32\"\n[camera]\ndir = [1, 0, 0]\n\
         [spectrum]\noversample = 1.5\n[output]\npath = \"s.png\"\n",
    )
    .unwrap();
    let (stats, _) = stats_json("render --scene s.toml --stats-json", &dir);
    assert_eq!(stats["spectrum_side"], 48, "{stats}");
    assert_eq!(stats["oversample"], 1.5, "{stats}");
}
