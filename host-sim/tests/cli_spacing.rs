//! `fvr render` in physical units: the volume's spacing by default,
//! `--pixel-size`, `--ignore-spacing`, and the refusal of cued or lit scenes
//! on anisotropic voxels.

mod common;
use common::{assert_error, assert_ok, fvr, fvr_line, fvr_ok, temp_dir};

use std::path::Path;

use fvr_core::geometry::{Sampling, View};
use fvr_engine::volume::phantom::{sample_spaced, GaussianMixture};
use fvr_host::io::nrrd::read_nrrd;
use fvr_host::reference::{exact_projection_sampled, snr_db};

const SPACING: [f64; 3] = [0.8, 0.8, 1.5];
/// 33 × 1.5 = 49.5 mm ≤ 64 × 0.8: the default pixel size is the smallest
/// spacing.
const DIMS: [usize; 3] = [64, 63, 33];

/// Eight Gaussians in a 51.2 mm cube, each at least 1.5·max Δ wide (see
/// `tests/anisotropic.rs`).
fn object() -> GaussianMixture {
    GaussianMixture::random_in(1, 51.2, 8, 2.25, 6.1)
}

/// A float NRRD with `spacings` (`None`: no spacing field, so 1 mm).
fn write_volume(path: &Path, spacing: Option<[f64; 3]>) {
    write_volume_of(path, DIMS, spacing);
}

fn write_volume_of(path: &Path, dims: [usize; 3], spacing: Option<[f64; 3]>) {
    let volume = sample_spaced(&object(), dims, SPACING).unwrap();
    let mut bytes = format!(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: {} {} {}\n",
        dims[0], dims[1], dims[2]
    );
    if let Some(s) = spacing {
        bytes += &format!("spacings: {} {} {}\n", s[0], s[1], s[2]);
    }
    bytes += "encoding: raw\nendian: little\n\n";
    let mut bytes = bytes.into_bytes();
    for v in &volume.data {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}

/// By default the spacing from the file is used, with the smallest spacing
/// as pixel size: the image matches the exact line integrals in mm at the
/// kb4/f16 floor (50 dB), and `--stats` reports both.
#[test]
fn render_uses_the_files_spacing_and_matches_exact_in_mm() {
    let dir = temp_dir("spacing-default");
    write_volume(&dir.join("v.nrrd"), Some(SPACING));
    let stdout = fvr_ok("render v.nrrd --dir 1,0.3,0.2 --out a.nrrd --stats", &dir);
    assert!(
        stdout.contains("spacing       0.8 x 0.8 x 1.5 mm"),
        "{stdout}"
    );
    assert!(stdout.contains("pixel size    0.8 mm"), "{stdout}");
    let image = read_nrrd(&dir.join("a.nrrd")).unwrap();
    assert_eq!(image.dims, [64, 64, 1]);
    let sampling = Sampling::new(SPACING, 0.8).unwrap();
    let view = View::along([1.0, 0.3, 0.2]);
    let exact = exact_projection_sampled(&object(), DIMS, &view, &sampling, 64, 64).unwrap();
    let got: Vec<f64> = image.data.iter().map(|&v| v as f64).collect();
    let snr = snr_db(&exact, &got);
    assert!(snr >= 50.0, "{snr:.2} dB");

    // A coarser --pixel-size halves the pixel count across the same extent.
    fvr_ok(
        "render v.nrrd --dir 1,0.3,0.2 --pixel-size 1.6 --size 32 --out b.nrrd",
        &dir,
    );
    let coarse = read_nrrd(&dir.join("b.nrrd")).unwrap();
    let sampling = Sampling::new(SPACING, 1.6).unwrap();
    let exact = exact_projection_sampled(&object(), DIMS, &view, &sampling, 32, 32).unwrap();
    let got: Vec<f64> = coarse.data.iter().map(|&v| v as f64).collect();
    let snr = snr_db(&exact, &got);
    assert!(snr >= 50.0, "--pixel-size 1.6: {snr:.2} dB");
}

/// When the longest physical side would not fit the default image at the
/// smallest spacing (35 × 1.5 = 52.5 mm > 64 × 0.8 mm), the default pixel
/// size is the one that fits it: 52.5/64 mm.
#[test]
fn default_pixel_size_fits_the_longest_side() {
    let dir = temp_dir("spacing-fit");
    write_volume_of(&dir.join("v.nrrd"), [64, 63, 35], Some(SPACING));
    let stdout = fvr_ok("render v.nrrd --dir 0,1,0 --out a.nrrd --stats", &dir);
    assert!(stdout.contains("pixel size    0.8203125 mm"), "{stdout}");
    let out = fvr_line(
        "render v.nrrd --dir 0,1,0 --out b.nrrd --pixel-size 0.5",
        &dir,
    );
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("wrap"), "{err}");
}

/// `--ignore-spacing` is the voxel-unit render, bit for bit the render of
/// the same samples stored without a spacing.
#[test]
fn ignore_spacing_is_the_voxel_unit_render() {
    let dir = temp_dir("spacing-ignore");
    write_volume(&dir.join("spaced.nrrd"), Some(SPACING));
    write_volume(&dir.join("plain.nrrd"), None);
    for (input, extra, out) in [
        ("spaced.nrrd", Some("--ignore-spacing"), "ignored.nrrd"),
        ("plain.nrrd", None, "plain-out.nrrd"),
    ] {
        let mut args = vec!["render", input, "--dir", "1,0.3,0.2", "--out", out];
        args.extend(extra);
        assert_ok(&fvr(&args, &dir));
    }
    let a = std::fs::read(dir.join("ignored.nrrd")).unwrap();
    let b = std::fs::read(dir.join("plain-out.nrrd")).unwrap();
    assert_eq!(a, b);
    let spaced = {
        fvr_ok("render spaced.nrrd --dir 1,0.3,0.2 --out mm.nrrd", &dir);
        std::fs::read(dir.join("mm.nrrd")).unwrap()
    };
    assert_ne!(a, spaced, "the spacing must change the image");
}

/// Lights or a depth cue on anisotropic voxels: exit 2 with the way out;
/// after `--resample` (cubic voxels) they render.
#[test]
fn cued_or_lit_anisotropic_renders_are_refused_until_resampled() {
    let dir = temp_dir("spacing-scene");
    write_volume(&dir.join("v.nrrd"), Some(SPACING));
    let base = "render v.nrrd --dir 1,0.3,0.2 --out s.png";
    for extra in ["--light-ring 3", "--depth-cue linear:1,0.2"] {
        assert_error(
            &fvr_line(&format!("{base} {extra}"), &dir),
            &["0.8 x 0.8 x 1.5 mm", "--resample", "--ignore-spacing"],
        );
        fvr_ok(&format!("{base} {extra} --resample 48"), &dir);
    }
}

/// Bad pixel sizes, and --pixel-size with --ignore-spacing, are errors.
#[test]
fn bad_pixel_size_is_an_error() {
    let dir = temp_dir("spacing-bad");
    let base = "render gaussians@16 --dir 1,0,0 --out x.png";
    for bad in ["0", "-1", "nan", "inf"] {
        let out = fvr_line(&format!("{base} --pixel-size {bad}"), &dir);
        assert_error(&out, &["pixel size"]);
    }
    let out = fvr_line(&format!("{base} --pixel-size 1 --ignore-spacing"), &dir);
    assert_error(&out, &["--ignore-spacing"]);
}

/// `fvr turntable` takes the same units: the spacing by default,
/// `--pixel-size` checked, `--ignore-spacing` for voxel units.
#[test]
fn turntable_uses_the_spacing_too() {
    let dir = temp_dir("spacing-turntable");
    write_volume(&dir.join("v.nrrd"), Some(SPACING));
    let base = "turntable v.nrrd --frames 2 --size 32";
    for extra in ["", "--ignore-spacing", "--pixel-size 1.6"] {
        fvr_ok(&format!("{base} {extra} --out s.apng"), &dir);
        assert!(dir.join("s.apng").exists());
    }
    let out = fvr_line(&format!("{base} --pixel-size 0 --out t.apng"), &dir);
    assert_error(&out, &["pixel size"]);
}

/// `--adaptive` on cubic voxels imaged at their own size renders in mm (the
/// voxel-unit image times Δ, within the tolerance of the full-filter render
/// in mm); on anisotropic voxels it is refused with the ways out.
#[test]
fn adaptive_renders_cubic_voxels_in_mm_and_refuses_anisotropic_ones() {
    let dir = temp_dir("spacing-adaptive");
    let dims = [32, 32, 32];
    write_volume_of(&dir.join("c.nrrd"), dims, Some([2.0; 3]));
    let base = [
        "render",
        "c.nrrd",
        "--dir",
        "1,0.3,0.2",
        "--oversample",
        "2",
    ];
    let run = |extra: &[&str], out: &str| {
        let mut args = base.to_vec();
        args.extend(extra);
        args.extend(["--out", out]);
        assert_ok(&fvr(&args, &dir));
        let data: Vec<f64> = read_nrrd(&dir.join(out))
            .unwrap()
            .data
            .iter()
            .map(|&v| f64::from(v))
            .collect();
        data
    };
    let full = run(&[], "full.nrrd");
    let adaptive = run(&["--adaptive", "40"], "adaptive.nrrd");
    let voxel_units = run(&["--ignore-spacing"], "voxel.nrrd");
    let snr = snr_db(&full, &adaptive);
    assert!(snr >= 40.0, "{snr}");
    // The mm image is the voxel-unit one times Δ = 2 (exactly: a power of two).
    let doubled: Vec<f64> = voxel_units.iter().map(|v| 2.0 * v).collect();
    assert_eq!(full, doubled);

    write_volume(&dir.join("a.nrrd"), Some(SPACING));
    assert_error(
        &fvr_line(
            "render a.nrrd --dir 1,0.3,0.2 --oversample 2 --adaptive 40 --out x.png",
            &dir,
        ),
        &["cubic voxels", "--resample", "--ignore-spacing"],
    );
}
