//! The `fvr` program's inputs and outputs end to end: file formats, PNG
//! options, turntables, help, version, exit codes and progress output.

mod common;
use common::{assert_error, fvr, fvr_in, fvr_line, temp_dir};

use std::path::Path;
use std::process::Output;

use fvr_host::io::den::encode_den;
use fvr_host::io::nifti::encode_nifti_f32;
use fvr_host::io::nrrd::Endian::{self, Little};

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn assert_ok(out: &Output) {
    assert!(out.status.success(), "stderr: {}", stderr(out));
}

fn png_info(path: &Path) -> png::Info<'static> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    decoder.read_info().unwrap().info().clone()
}

#[test]
fn version_and_help_document_the_exit_status() {
    let dir = temp_dir("io-help");
    let out = fvr_line("--version", &dir);
    assert_ok(&out);
    assert_eq!(
        stdout(&out).trim(),
        format!("fvr {}", env!("CARGO_PKG_VERSION"))
    );
    let out = fvr_line("--help", &dir);
    assert_ok(&out);
    let help = stdout(&out);
    for needle in [
        "EXIT STATUS",
        "0  success",
        "2  any error",
        "fvr: error:",
        "--quiet",
        "turntable",
    ] {
        assert!(help.contains(needle), "`{needle}` not in --help:\n{help}");
    }
    let out = fvr_line("render --help", &dir);
    let help = stdout(&out);
    for needle in [
        "NIfTI-1",
        ".den",
        ".inv3",
        "ct-head",
        "brainsmall",
        "--bits",
        "--window",
        "--colormap",
        "EXIT STATUS",
    ] {
        assert!(
            help.contains(needle),
            "`{needle}` not in render --help:\n{help}"
        );
    }
}

/// `--name` and its `[default: ...]` in a help text.
fn option_defaults(help: &str) -> Vec<(String, String)> {
    let mut found = Vec::new();
    let mut current: Option<String> = None;
    for line in help.lines() {
        let t = line.trim_start();
        if let Some(rest) = t.strip_prefix("--") {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '-')
                .collect();
            current = Some(name.clone());
            found.push((name, String::new()));
        }
        if let (Some(_), Some(d)) = (&current, t.find("[default: ")) {
            let default = t[d..].to_owned();
            if let Some(last) = found.last_mut() {
                last.1 = default;
            }
        }
    }
    found
}

#[test]
fn turntable_options_match_render_options() {
    let dir = temp_dir("io-options");
    let render = option_defaults(&stdout(&fvr_line("render --help", &dir)));
    let spin = option_defaults(&stdout(&fvr_line("turntable --help", &dir)));
    let shared = [
        "size",
        "filter",
        "oversample",
        "precision",
        "kb-design",
        "bits",
        "window",
        "level",
        "percentiles",
        "colormap",
        "raw-dims",
        "raw-type",
        "raw-endian",
        "up",
        "pixel-size",
        "ignore-spacing",
        "depth-cue",
        "cue-harmonics",
        "ambient",
        "light",
        "light-ring",
        "no-cue-correction",
        "resample",
        "preview-level",
        "stats",
        "stats-json",
    ];
    for name in shared {
        let r = render.iter().find(|(n, _)| n == name);
        let s = spin.iter().find(|(n, _)| n == name);
        assert!(
            r.is_some() && s.is_some(),
            "--{name}: render {r:?}, turntable {s:?}"
        );
        assert_eq!(r, s, "--{name} differs between render and turntable");
    }
}

#[test]
fn renders_nifti_den_and_named_volumes_to_styled_pngs() {
    let dir = temp_dir("io-formats");
    let data: Vec<f32> = (0..16 * 16 * 8).map(|i| ((i * 37) % 101) as f32).collect();
    let nii = encode_nifti_f32([16, 16, 8], [1.0, 1.0, 2.0], (1.0, 0.0), &data, Little);
    std::fs::write(dir.join("v.nii"), nii).unwrap();
    let den = encode_den([8, 8, 8], &[7; 512], Endian::Big);
    std::fs::write(dir.join("v.den"), den).unwrap();
    let out = fvr_line("render v.nii --dir 1,0.2,0.1 --out n.png --bits 16", &dir);
    assert_ok(&out);
    let info = png_info(&dir.join("n.png"));
    assert_eq!(
        (info.width, info.height, info.bit_depth),
        (16, 16, png::BitDepth::Sixteen)
    );
    let out = fvr_line(
        "render v.den --dir 0,1,0 --out d.png --colormap bone --window 20 --level 40",
        &dir,
    );
    assert_ok(&out);
    assert_eq!(png_info(&dir.join("d.png")).color_type, png::ColorType::Rgb);
    let out = fvr_line("render brainsmall --dir 1,0,0 --out b.png --size 64", &dir);
    assert_ok(&out);
    assert_eq!(png_info(&dir.join("b.png")).width, 64);
    // Piped stderr is not a terminal: no progress bars, no control codes.
    let err = stderr(&out);
    assert!(
        !err.contains("loading") && !err.contains('\u{1b}'),
        "{err:?}"
    );
}

#[test]
fn the_ct_head_renders_by_name() {
    let (dir, out) = fvr_in(
        "io-ct",
        "render ct-head --dir 0,1,0 --out ct.png --size 128 --quiet --stats",
    );
    assert_ok(&out);
    assert!(stdout(&out).contains("256x256x108"), "{}", stdout(&out));
    assert_eq!(png_info(&dir.join("ct.png")).width, 128);
}

#[test]
fn turntable_writes_an_apng_and_reports_views_per_second() {
    let (dir, out) = fvr_in(
        "io-spin",
        "turntable gaussians@32 --frames 8 --out spin.apng --colormap hot --stats",
    );
    assert_ok(&out);
    let text = stdout(&out);
    assert!(
        text.contains("8 frames") && text.contains("views/s"),
        "{text}"
    );
    let info = png_info(&dir.join("spin.apng"));
    let actl = info.animation_control.expect("animated");
    assert_eq!((actl.num_frames, actl.num_plays), (8, 0));
    assert_eq!((info.width, info.color_type), (32, png::ColorType::Rgb));
    let out = fvr_line("turntable gaussians@16 --dir 0,0,1 --up 0,0,3", &dir);
    assert_error(&out, &["parallel"]);
    let out = fvr_line("turntable gaussians@16 --frames 0", &dir);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn bad_inputs_and_options_exit_2_with_the_file_and_field() {
    let dir = temp_dir("io-bad");
    let good = encode_nifti_f32([4, 4, 4], [1.0; 3], (1.0, 0.0), &[1.0; 64], Endian::Little);
    let mut gz = {
        use std::io::Write;
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(&good).unwrap();
        e.finish().unwrap()
    };
    gz.truncate(gz.len() - 10);
    std::fs::write(dir.join("cut.nii.gz"), &gz).unwrap();
    let out = fvr_line("render cut.nii.gz --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["fvr: error:", "cut.nii.gz", "gzip"]);
    let mut zero_pixdim = good.clone();
    zero_pixdim[80..84].copy_from_slice(&0f32.to_le_bytes());
    std::fs::write(dir.join("flat.nii"), &zero_pixdim).unwrap();
    let out = fvr_line("render flat.nii --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["flat.nii", "`pixdim`", "zero"]);
    std::fs::write(dir.join("junk.vol"), b"not a volume").unwrap();
    let out = fvr_line("render junk.vol --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["junk.vol", "unknown volume format", "--raw-dims"]);
    let png_cases: [(&[&str], &[&str]); 4] = [
        (&["--window", "10"], &["--level"]),
        (
            &["--window", "0", "--level", "1"],
            &["--window 0", "positive"],
        ),
        (&["--bits", "12"], &["8 or 16"]),
        (&["--percentiles", "90,10"], &["LOW < HIGH"]),
    ];
    for (extra, needles) in png_cases {
        let mut args = vec!["render", "gaussians@16", "--dir", "1,0,0", "--out", "x.png"];
        args.extend_from_slice(extra);
        assert_error(&fvr(&args, &dir), needles);
    }
}

#[test]
fn renders_a_dicom_series_directory() {
    let dir = temp_dir("io-dicom");
    let series = dir.join("series");
    std::fs::create_dir_all(&series).unwrap();
    for k in 0..6u32 {
        let pixels: Vec<i16> = (0..64).map(|i| ((i * 7 + k * 13) % 50) as i16).collect();
        let bytes = fvr_host::io::dicom::CtSlice {
            series: "1.2.3.4",
            instance: k + 1,
            pixel_spacing: [0.5, 0.5],
            position: [0.0, 0.0, 1.25 * k as f64],
            intercept: -10.0,
            ..fvr_host::io::dicom::CtSlice::axial([8, 8], &pixels)
        }
        .encode();
        std::fs::write(series.join(format!("IM{k:04}")), bytes).unwrap();
    }
    let out = fvr_line("render series --dir 1,0.3,0.2 --out s.png --stats", &dir);
    assert_ok(&out);
    assert!(stdout(&out).contains("8x8x6"), "{}", stdout(&out));
    std::fs::write(series.join("IM0002"), b"broken").unwrap();
    let out = fvr_line("render series --dir 1,0,0 --out s.png", &dir);
    assert_error(&out, &["series", "missing slices"]);
}
