//! The `fvr` program end to end: outputs, and clear errors on bad input.

mod common;
use common::{assert_error, assert_ok, assert_refused, fvr, fvr_in, fvr_line, read, temp_dir};

use fvr_host::io::nrrd::SampleType::{F32, U16};
use fvr_host::io::nrrd::{encode_nrrd, Encoding, Endian};

#[test]
fn no_arguments_renders_the_default_scene_and_says_where() {
    let dir = temp_dir("default");
    let out = fvr(&[], &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_ok(&out);
    assert!(stdout.contains("wrote fvr-default.png"), "{stdout}");
    let png = std::fs::read(dir.join("fvr-default.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn render_to_nrrd_and_compare_precisions() {
    let dir = temp_dir("compare");
    for p in ["f16", "f64"] {
        let out = fvr(
            &[
                "render",
                "gaussians@32",
                "--dir",
                "1,0.3,0.2",
                "--filter",
                "kb6",
                "--precision",
                p,
                "--out",
                &format!("{p}.nrrd"),
            ],
            &dir,
        );
        assert_ok(&out);
    }
    let out = fvr_line("compare f64.nrrd f16.nrrd", &dir);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    let db: f64 = stdout
        .split(": ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no dB figure in `{stdout}`"));
    assert!(db > 70.0, "f16 against f64: {db} dB");
    let header = std::fs::read(dir.join("f16.nrrd")).unwrap();
    let text = String::from_utf8_lossy(&header[..200]);
    assert!(
        text.contains("type: float") && text.contains("sizes: 32 32"),
        "{text}"
    );
}

#[test]
fn zero_and_parallel_view_vectors_are_named() {
    let (dir, out) = fvr_in("view", "render sphere@16 --dir 0,0,0 --out x.png");
    assert_error(&out, &["zero view vector", "(0, 0, 0)", "(0, 0, 1)"]);
    let out = fvr_line("render sphere@16 --dir 0,0,-2 --out x.png", &dir);
    assert_error(&out, &["parallel", "(0, 0, -2)", "(0, 0, 1)"]);
    let out = fvr_line("render sphere@16 --dir 1,nan,0 --out x.png", &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("finite"));
}

#[test]
fn oversized_image_unknown_filter_and_bad_output_are_errors() {
    let (dir, out) = fvr_in(
        "args",
        "render sphere@16 --oversample 1 --dir 1,0,0 --size 40x8 --out x.png",
    );
    assert_error(&out, &["40x8", "padded grid size 16"]);
    let out = fvr_line(
        "render sphere@16 --dir 1,0,0 --filter kb9 --out x.png",
        &dir,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown filter `kb9`"));
    let out = fvr_line("render sphere@16 --dir 1,0,0 --out x.bmp", &dir);
    assert_error(&out, &["x.bmp", ".png or .nrrd"]);
    let out = fvr_line("render nosuchthing --dir 1,0,0 --out x.png", &dir);
    assert_error(
        &out,
        &["nosuchthing", "neither a file nor a built-in phantom"],
    );
    let out = fvr_line("render sphere@99999 --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["phantom size `99999`"]);
}

#[test]
fn nan_voxels_truncated_and_malformed_files_are_named() {
    let dir = temp_dir("files");
    let mut values = vec![1.0; 4 * 4 * 4];
    values[1 + 4 * (2 + 4 * 3)] = f64::NAN;
    let nan = encode_nrrd(&[4, 4, 4], F32, Encoding::Raw, Endian::Little, &values);
    std::fs::write(dir.join("nan.nrrd"), &nan).unwrap();
    let out = fvr_line("render nan.nrrd --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["NaN", "(1, 2, 3)"]);

    let good = encode_nrrd(&[4, 4, 4], U16, Encoding::Gzip, Endian::Big, &[7.0; 64]);
    std::fs::write(dir.join("short.nrrd"), &good[..good.len() - 20]).unwrap();
    let out = fvr_line("render short.nrrd --dir 1,0,0 --out x.png", &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));

    let bad = b"NRRD0004\ntype: complex\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n";
    std::fs::write(dir.join("bad.nrrd"), bad).unwrap();
    let out = fvr_line("render bad.nrrd --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["type", "complex"]);

    let huge = b"NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\nendian: little\n\n";
    std::fs::write(dir.join("huge.nrrd"), huge).unwrap();
    let out = fvr_line("render huge.nrrd --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["this job needs about", "decoded volume"]);
}

#[test]
fn help_documents_the_geometry_contract_and_every_option() {
    let (_, out) = fvr_in("help", "render --help");
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "GEOMETRY CONTRACT",
        "c = (nx/2, ny/2, nz/2)",
        "--dir",
        "--up",
        "--size",
        "--filter",
        "--oversample",
        "--precision",
        "--out",
        "--kb-design",
        "gaussians",
    ] {
        assert!(text.contains(needle), "`{needle}` missing from help");
    }
}

#[test]
fn precision_study_writes_markdown_csv_and_png_with_no_non_finite_pixel() {
    let (dir, out) = fvr_in("precision", "precision --volumes gaussians@16,shepp-logan@16 --formats f16,bf16,e4m11,q15-line,q7-brick2,e4m3,f32 --out-dir out");
    assert_ok(&out);
    let csv = read(&dir, "out/precision.csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].starts_with("volume,size,grid,format,arithmetic,bytes_per_voxel"));
    // 2 volumes × (f16×3 + bf16×3 + e4m11×3 + q15-line×3 + q7-brick2 + e4m3×3 + f32×2).
    assert_eq!(lines.len(), 1 + 2 * 18, "{csv}");
    for line in &lines[1..] {
        let cols: Vec<&str> = line.split(',').collect();
        assert_eq!(cols[9], "0", "non-finite pixels in {line}");
        assert_eq!(cols[10], "", "refused: {line}");
        let snr: f64 = cols[6].parse().unwrap();
        assert!(snr > 0.0 || cols[3] == "e4m11", "{line}");
    }
    let md = read(&dir, "out/precision.md");
    assert!(md.contains("| q15-line | host-once |"), "{md}");
    let png = std::fs::read(dir.join("out/precision.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
}

#[test]
fn precision_bad_formats_are_named_before_any_work() {
    let (dir, out) = fvr_in("precision-bad", "precision --formats e5m11");
    assert_error(&out, &["e5m11", "17 bits", "16"]);
    assert_refused(
        &dir,
        &[
            ("precision --formats e9m6", &["e9m6", "f32"]),
            ("precision --formats f24", &["unknown format `f24`"]),
            (
                "precision --volumes gaussians@16 --formats q15-brick6",
                &["q15-brick6", "block size 6 does not divide", "16"],
            ),
            (
                "precision --formats e4m11-line",
                &["only q15 and q7 take block exponents"],
            ),
        ],
    );
}

#[test]
fn precision_extremes_table_reports_every_case() {
    let (_, out) = fvr_in(
        "precision-extremes",
        "precision --extremes 8 --formats f16,q15-line",
    );
    assert_ok(&out);
    let md = String::from_utf8_lossy(&out.stdout);
    for case in [
        "constant 1",
        "impulse",
        "nyquist checkerboard",
        "u16 65535",
        "gaussians x 1e-6",
        "shepp-logan in HU",
    ] {
        assert!(md.contains(case), "{case} missing");
    }
    // Every row ends with its count of NaN/Inf pixels: zero.
    let rows: Vec<&str> = md
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| case"))
        .collect();
    // 2 tables × 6 cases × (f16 and q15-line, 3 arithmetic modes each).
    assert_eq!(rows.len(), 2 * 6 * 6, "{md}");
    assert!(rows.iter().all(|l| l.ends_with("| 0 |")), "{md}");
}
