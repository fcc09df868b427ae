//! `fvr render --accuracy DB` and `fvr turntable --accuracy DB`: the choice,
//! its report in `--stats-json`, the default target of 50 dB, explicit flags
//! and scene settings that win, and the warning for settings predicted low.

mod common;
use common::{assert_ok, fvr_line, stats_json, temp_dir};

#[test]
fn accuracy_chooses_a_configuration_predicted_to_meet_the_target() {
    let dir = temp_dir("accuracy-choose");
    let (stats, _) = stats_json(
        "render brainsmall --dir 1,0,0 --accuracy 45 --out a.png --stats-json",
        &dir,
    );
    let acc = &stats["accuracy"];
    assert_eq!(acc["target_db"], 45.0, "{stats}");
    assert!(acc["predicted_db"].as_f64().unwrap() >= 45.0, "{stats}");
    // The MRI head touches its box: oversampling 1 cannot reach 45 dB.
    assert!(stats["oversample"].as_f64().unwrap() > 1.0, "{stats}");
    assert_eq!(stats["filter"], acc["filter"], "{stats}");
    assert_eq!(stats["precision"], acc["precision"], "{stats}");
}

#[test]
fn explicit_flags_win_and_an_unmet_target_warns() {
    let dir = temp_dir("accuracy-given");
    let (stats, err) = stats_json(
        "turntable brainsmall --frames 2 --accuracy 45 --oversample 1 --out a.apng --stats-json",
        &dir,
    );
    assert!(
        err.contains("no configuration is predicted to reach 45 dB"),
        "{err}"
    );
    assert_eq!(stats["oversample"], 1, "{stats}");
    assert!(
        stats["accuracy"]["predicted_db"].as_f64().unwrap() < 45.0,
        "{stats}"
    );
}

#[test]
fn the_default_target_is_50_db_and_a_touching_head_gets_oversampled() {
    let dir = temp_dir("accuracy-default");
    let (stats, err) = stats_json(
        "render brainsmall --dir 0,1,0 --out a.png --stats-json",
        &dir,
    );
    assert!(!err.contains("warning"), "{err}");
    let acc = &stats["accuracy"];
    assert_eq!(acc["target_db"], 50.0, "{stats}");
    assert_eq!(acc["target_is_default"], true, "{stats}");
    assert!(acc["predicted_db"].as_f64().unwrap() >= 50.0, "{stats}");
    assert!(stats["oversample"].as_f64().unwrap() > 1.0, "{stats}");
}

#[test]
fn settings_given_without_accuracy_win_and_warn_when_predicted_low() {
    let dir = temp_dir("accuracy-warn");
    // All three given: used as given, predicted, and warned about.
    let all = "render brainsmall --dir 0,1,0 --filter kb4 --oversample 1 --precision f16 \
               --out a.png --stats-json";
    // Only the oversampling given: the planner chooses the rest around it.
    let one = "render brainsmall --dir 0,1,0 --oversample 1 --out b.png --stats-json";
    for line in [all, one] {
        let (stats, err) = stats_json(line, &dir);
        assert!(
            err.contains("predicted to reach only") && err.contains("--accuracy"),
            "{line}: {err}"
        );
        assert_eq!(stats["oversample"], 1, "{stats}");
        assert!(
            stats["accuracy"]["predicted_db"].as_f64().unwrap() < 40.0,
            "{stats}"
        );
    }
    // A compact phantom at the default: nothing to warn about.
    let out = fvr_line("render gaussians@32 --dir 0,1,0 --out c.png", &dir);
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn a_scene_file_states_the_accuracy_and_its_settings_win() {
    let dir = temp_dir("accuracy-scene");
    std::fs::write(
        dir.join("target.toml"),
        "[volume]\nbuiltin = \"brainsmall\"\n[spectrum]\naccuracy = 45\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("fixed.toml"),
        "[volume]\nbuiltin = \"brainsmall\"\n[spectrum]\noversample = 1\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("bad.toml"),
        "[volume]\nbuiltin = \"brainsmall\"\n[spectrum]\naccuracy = -3\n",
    )
    .unwrap();
    let line = |scene: &str, extra: &str| {
        format!("render --scene {scene} --dir 0,1,0 --out s.png --stats-json {extra}")
    };
    let (stats, _) = stats_json(&line("target.toml", ""), &dir);
    assert_eq!(stats["accuracy"]["target_db"], 45.0, "{stats}");
    assert_eq!(stats["accuracy"]["target_is_default"], false, "{stats}");
    // The command line wins over the scene.
    let (stats, _) = stats_json(&line("target.toml", "--accuracy 60"), &dir);
    assert_eq!(stats["accuracy"]["target_db"], 60.0, "{stats}");
    // A setting in the scene is the user's choice: kept, and warned about.
    let (stats, err) = stats_json(&line("fixed.toml", ""), &dir);
    assert_eq!(stats["oversample"], 1, "{stats}");
    assert!(err.contains("predicted to reach only"), "{err}");
    let out = fvr_line(&line("bad.toml", ""), &dir);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("`spectrum.accuracy`") && err.contains("positive"),
        "{err}"
    );
}
