//! `fvr render --accuracy DB` and `fvr turntable --accuracy DB`: the choice,
//! its report in `--stats-json`, explicit flags that win, and the warning
//! without the flag.

mod common;
use common::{assert_ok, fvr, temp_dir};

fn json_line(stdout: &[u8]) -> serde_json::Value {
    let text = String::from_utf8_lossy(stdout);
    let line = text
        .lines()
        .find(|l| l.starts_with('{'))
        .unwrap_or_else(|| panic!("no JSON line in: {text}"));
    serde_json::from_str(line).unwrap()
}

#[test]
fn accuracy_chooses_a_configuration_predicted_to_meet_the_target() {
    let dir = temp_dir("accuracy-choose");
    let out = fvr(
        &[
            "render",
            "brainsmall",
            "--dir",
            "1,0,0",
            "--accuracy",
            "45",
            "--out",
            "a.png",
            "--stats-json",
        ],
        &dir,
    );
    assert_ok(&out);
    let stats = json_line(&out.stdout);
    let acc = &stats["accuracy"];
    assert_eq!(acc["target_db"], 45.0, "{stats}");
    assert!(acc["predicted_db"].as_f64().unwrap() >= 45.0, "{stats}");
    // The MRI head touches its box: oversampling 1 cannot reach 45 dB.
    assert_eq!(stats["oversample"], 2, "{stats}");
    assert_eq!(stats["filter"], acc["filter"], "{stats}");
    assert_eq!(stats["precision"], acc["precision"], "{stats}");
}

#[test]
fn explicit_flags_win_and_an_unmet_target_warns() {
    let dir = temp_dir("accuracy-given");
    let out = fvr(
        &[
            "turntable",
            "brainsmall",
            "--frames",
            "2",
            "--accuracy",
            "45",
            "--oversample",
            "1",
            "--out",
            "a.apng",
            "--stats-json",
        ],
        &dir,
    );
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no configuration is predicted to reach 45 dB"),
        "{err}"
    );
    let stats = json_line(&out.stdout);
    assert_eq!(stats["oversample"], 1, "{stats}");
    assert!(
        stats["accuracy"]["predicted_db"].as_f64().unwrap() < 45.0,
        "{stats}"
    );
}

#[test]
fn without_accuracy_a_low_prediction_warns_and_names_the_remedy() {
    let dir = temp_dir("accuracy-warn");
    let args = ["render", "brainsmall", "--dir", "0,1,0", "--out", "a.png"];
    let out = fvr(&args, &dir);
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("predicted to reach only") && err.contains("--accuracy"),
        "{err}"
    );
    let out = fvr(
        &["render", "gaussians@32", "--dir", "0,1,0", "--out", "b.png"],
        &dir,
    );
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("predicted to reach only"), "{err}");
}
