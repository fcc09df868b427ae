//! One statistics schema for every subcommand that renders: `render`,
//! `turntable` and `project` print the same keys in the same units with
//! `--stats-json` (stdout holding that one JSON object and nothing else),
//! and the same lines with `--stats`.

mod common;
use common::{assert_ok, fvr_line, fvr_ok, temp_dir};

/// The keys every renderer's `--stats-json` starts with, in order.
const COMMON: [&str; 25] = [
    "command",
    "volume",
    "dims",
    "spacing_mm",
    "pixel_size",
    "ignore_spacing",
    "image",
    "kind",
    "spectrum_side",
    "precision",
    "spectrum_bytes",
    "gradient_spectrum_bytes",
    "filter",
    "oversample",
    "storage_snr_db",
    "predicted_db",
    "load_ms",
    "plan_ms",
    "prepare_ms",
    "views",
    "views_ms",
    "ms_per_view",
    "output",
    "accuracy",
    "taper",
];

const RUNS: [(&str, &str, usize); 3] = [
    ("render", "render sphere@16 --dir 1,0.3,0.2 --out r.png", 1),
    (
        "turntable",
        "turntable sphere@16 --frames 3 --out t.apng",
        3,
    ),
    ("project", "project sphere@16 --random 2 --out p.npy", 2),
];

#[test]
fn render_turntable_and_project_print_one_schema_and_only_json() {
    let dir = temp_dir("stats-schema");
    for (command, line, views) in RUNS {
        let stdout = fvr_ok(&format!("{line} --stats-json"), &dir);
        assert_eq!(stdout.lines().count(), 1, "{command}: {stdout}");
        let stats: serde_json::Value = serde_json::from_str(stdout.trim())
            .unwrap_or_else(|e| panic!("{command}: {e}: {stdout}"));
        // The common keys come first, in order (serde_json's map sorts
        // them, so their places are read off the text).
        let at = |key: &str| {
            stdout
                .find(&format!("\"{key}\": "))
                .unwrap_or_else(|| panic!("{command}: no `{key}` in {stdout}"))
        };
        let places: Vec<usize> = COMMON.iter().map(|k| at(k)).collect();
        assert!(
            places.windows(2).all(|p| p[0] < p[1]),
            "{command}: {stdout}"
        );
        assert_eq!(places[0], 1, "{command}: {stdout}");
        assert_eq!(stats["command"], command);
        assert_eq!(stats["volume"], "sphere@16");
        assert_eq!(stats["dims"], serde_json::json!([16, 16, 16]));
        assert_eq!(stats["image"], serde_json::json!([16, 16, 1]), "{command}");
        assert_eq!(stats["kind"], "grey");
        assert_eq!(stats["views"], views, "{command}");
        let per = stats["ms_per_view"].as_f64().unwrap();
        let all = stats["views_ms"].as_f64().unwrap();
        assert!(
            (per * views as f64 - all).abs() <= 1e-9 * all.max(1.0),
            "{stats}"
        );
        assert!(stats["prepare_ms"].as_f64().unwrap() > 0.0, "{stats}");
        assert!(stats["predicted_db"].as_f64().unwrap() >= 50.0, "{stats}");
    }
}

#[test]
fn stats_lines_are_the_same_for_every_renderer() {
    let dir = temp_dir("stats-human");
    for (command, line, views) in RUNS {
        let stdout = fvr_ok(&format!("{line} --stats --quiet"), &dir);
        for needle in [
            "  volume        16x16x16 (sphere@16)",
            "  pixel size    1 mm",
            "  image         16x16 grey",
            "  prepare       ",
            &format!("  views         {views} in "),
        ] {
            assert!(stdout.contains(needle), "{command}: `{needle}` in {stdout}");
        }
    }
}

/// Coloured lights make RGB images, and every renderer says so.
#[test]
fn rgb_images_are_announced_as_rgb() {
    let dir = temp_dir("stats-rgb");
    for line in [
        "render teapot@32 --dir 0,-1,0 --light-ring 3 --out r.png",
        "turntable teapot@32 --frames 2 --light-ring 3 --out t.apng",
    ] {
        let stdout = fvr_ok(&format!("{line} --stats"), &dir);
        assert!(
            stdout.contains("32x32 RGB") && !stdout.contains("grey"),
            "{stdout}"
        );
        let stdout = fvr_ok(&format!("{line} --stats-json"), &dir);
        let stats: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
        assert_eq!(stats["image"], serde_json::json!([32, 32, 3]), "{stats}");
        assert_eq!(stats["kind"], "RGB", "{stats}");
    }
}

/// `--stats` and `--stats-json` read the same in every renderer's help:
/// one wording, because they are one option pair.
#[test]
fn the_stats_options_are_described_alike() {
    let dir = temp_dir("stats-help");
    let described = |command: &str| -> Vec<String> {
        let out = fvr_line(&format!("{command} --help"), &dir);
        assert_ok(&out);
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        let lines: Vec<&str> = text.lines().map(str::trim).collect();
        ["--stats", "--stats-json"]
            .iter()
            .map(|flag| {
                let at = lines
                    .iter()
                    .position(|l| l.split_whitespace().next() == Some(flag))
                    .unwrap_or_else(|| panic!("{command}: no {flag} in its help"));
                // clap prints a short help on the option's line, a long one
                // on the lines below it up to a blank line.
                let beside: Vec<&str> = lines[at].split_whitespace().skip(1).collect();
                let below = lines[at + 1..].iter().take_while(|l| !l.is_empty());
                if beside.is_empty() {
                    below.copied().collect::<Vec<_>>().join(" ")
                } else {
                    beside.join(" ")
                }
            })
            .collect()
    };
    let render = described("render");
    assert!(render[1].contains("JSON"), "{render:?}");
    for command in ["turntable", "project"] {
        assert_eq!(described(command), render, "{command} against render");
    }
}
