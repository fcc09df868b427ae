//! `fvr trade`: a tiny sweep end to end, the memory refusal and the
//! conflicting-option errors.

mod common;

use common::{assert_error, assert_ok, fvr, fvr_in, read, temp_dir};

/// The header `fvr trade` writes, as documented in docs/trade/README.md.
const HEADER: &str = "size,grid,filter,oversample,format,adaptive_db,level,image_side,views,\
repeats,ms_per_view,ms_min,snr_db,snr_mean_db,spectrum_bytes,marks_bytes,scratch_bytes,\
held_bytes,prepare_ms,adaptive_taps_fraction,peak_rss_bytes,pareto";

#[test]
fn tiny_sweep_writes_csv_png_and_summary_with_one_row_per_point() {
    let (dir, out) = fvr_in("trade", "trade --sizes 32 --filters linear,kb3 --oversample 1,2 --formats f16,q15-line --adaptive none,40 --levels 0,1 --views 2 --repeats 1 --out-dir out");
    assert_ok(&out);
    let csv = read(&dir, "out/trade.csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], HEADER);
    // Per filter and format: oversampling 1 at levels 0 and 1 (2 points),
    // oversampling 2 at levels 0 and 1 plus adaptive 40 dB at level 0
    // (3 points): 2 filters × 2 formats × 5.
    assert_eq!(lines.len(), 1 + 20, "{csv}");
    let rows: Vec<Vec<&str>> = lines[1..].iter().map(|l| l.split(',').collect()).collect();
    let col = |name: &str| HEADER.split(',').position(|c| c == name).unwrap();
    let (ms, snr, front) = (col("ms_per_view"), col("snr_db"), col("pareto"));
    let points: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r[ms].parse().unwrap(), r[snr].parse().unwrap()))
        .collect();
    for (r, p) in rows.iter().zip(&points) {
        assert_eq!(r.len(), HEADER.split(',').count(), "{r:?}");
        assert!(p.0 > 0.0 && p.0.is_finite(), "{r:?}");
        // Even linear interpolation at 32³ stays far above 0 dB.
        assert!(p.1 > 10.0 && p.1.is_finite(), "{r:?}");
        let adaptive = r[col("adaptive_db")] != "none";
        assert_eq!(adaptive, r[col("marks_bytes")] != "0", "{r:?}");
        assert_eq!(
            adaptive,
            !r[col("adaptive_taps_fraction")].is_empty(),
            "{r:?}"
        );
        if adaptive {
            assert_eq!((r[col("oversample")], r[col("level")]), ("2", "0"), "{r:?}");
        }
        let level: u32 = r[col("level")].parse().unwrap();
        assert_eq!(r[col("image_side")], (32 >> level).to_string(), "{r:?}");
    }
    // The flags in the CSV form the Pareto front of the CSV's own figures.
    for (i, r) in rows.iter().enumerate() {
        let dominated = points.iter().any(|q| {
            q.0 <= points[i].0 && q.1 >= points[i].1 && (q.0 < points[i].0 || q.1 > points[i].1)
        });
        assert_eq!(r[front] == "1", !dominated, "{r:?}");
    }
    let md = read(&dir, "out/trade.md");
    assert!(md.contains("## 32³: the Pareto front"), "{md}");
    assert!(md.contains("fvr trade --sizes 32"), "{md}");
    let png = std::fs::read(dir.join("out/trade.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
}

#[test]
fn every_csv_column_is_documented() {
    let doc = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/trade/README.md"),
    )
    .unwrap();
    for column in HEADER.split(',') {
        assert!(
            doc.contains(&format!("| `{column}` |")),
            "column {column} undocumented"
        );
    }
}

#[test]
fn a_sweep_beyond_memory_is_refused_before_any_work() {
    let (dir, out) = fvr_in(
        "trade-memory",
        "trade --sizes 32,64 --filters kb6 --formats f32 --memory-limit 2M --out-dir out",
    );
    // 64³ at oversampling 2 in f32: a 128³ spectrum of 8 MiB alone.
    assert_error(
        &out,
        &[
            "largest point (64³, kb6 σ=2 f32",
            "needs",
            "2.0 MiB is available",
            "--memory-limit",
        ],
    );
    assert!(!dir.join("out").exists(), "refused after starting work");
}

#[test]
fn conflicting_and_bad_options_are_named_before_any_work() {
    let dir = temp_dir("trade-bad");
    let cases: [(&[&str], &[&str]); 12] = [
        (
            &["--adaptive", "40", "--oversample", "1"],
            &["--adaptive 40 needs --oversample 2"],
        ),
        (
            &["--adaptive", "none,60", "--levels", "1,2"],
            &["--adaptive 60 needs level 0"],
        ),
        (
            &["--adaptive", "40", "--filters", "nearest"],
            &["--adaptive 40 needs a filter wider than nearest"],
        ),
        (
            &["--filters", "kb3,kb9"],
            &[
                "unknown filter `kb9`",
                "nearest, linear, cubic, kb3, kb4, kb5, kb6",
            ],
        ),
        (&["--filters", ""], &["--filters is empty"]),
        (&["--formats", "f16,,f32"], &["--formats", "empty entry"]),
        (&["--formats", "q7"], &["format `q7` is not swept", "f16"]),
        (&["--sizes", "512"], &["size 512", "--large"]),
        (
            &["--sizes", "16", "--levels", "2"],
            &["--levels 2", "below 8"],
        ),
        (&["--views", "0"], &["--views 0", "at least 1"]),
        (&["--memory-limit", "lots"], &["--memory-limit `lots`"]),
        (
            &["--phantom", "shepp-logan"],
            &["--phantom `shepp-logan`", "gaussians or blobs"],
        ),
    ];
    for (args, needles) in cases {
        let mut all = vec!["trade", "--out-dir", "out"];
        all.extend_from_slice(args);
        assert_error(&fvr(&all, &dir), needles);
        assert!(!dir.join("out").exists(), "{args:?} started work");
    }
}

/// `fvr growth` writes its CSV, Markdown and plot for a tiny run, and
/// refuses sizes it cannot do before any work.
#[test]
fn growth_writes_csv_markdown_and_plot_and_refuses_bad_sizes() {
    let (dir, out) = fvr_in("growth", "growth --sizes 16,32 --runs 1 --out-dir g");
    let stdout = assert_ok(&out);
    assert!(stdout.contains("| 32³ |"), "{stdout}");
    let csv = read(&dir, "g/growth.csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "n,frequency_ms,raycast_ms,ratio");
    assert_eq!(lines.len(), 3, "{csv}");
    for line in &lines[1..] {
        let ms: Vec<f64> = line
            .split(',')
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        assert!(ms.iter().all(|v| v.is_finite() && *v > 0.0), "{line}");
    }
    let png = std::fs::read(dir.join("g/growth.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    for (args, needle) in [
        (&["growth", "--sizes", "256,512"][..], "512 needs --large"),
        (&["growth", "--sizes", "100,128"][..], "power of two"),
        (&["growth", "--sizes", "64"][..], "at least two"),
        (
            &["growth", "--sizes", "32,64", "--runs", "0"][..],
            "at least 1",
        ),
    ] {
        assert_error(&fvr(args, &dir), &[needle]);
    }
    assert!(!dir.join("growth").exists());
}
