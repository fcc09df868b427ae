//! `--taper`: content cut by the volume's box (a CT head's neck) rings in
//! a frequency-domain projection; the taper fades it and says what it did.

mod common;
use std::path::Path;

use common::{assert_error, assert_ok, fvr_line, fvr_ok, temp_dir};
use fvr_host::io::nrrd::read_nrrd_image;

/// A 32 × 32 × 24 volume of CT-like voxels (1 × 1 × 1.5 mm): a column
/// with a smooth (Gaussian) profile across, rising to 1 at the `k−` face,
/// which cuts it, and fading smoothly above k = 10. The cut is its only
/// sharp edge. The image's rows (1 mm) fall between the slices (1.5 mm),
/// where the trigonometric interpolant of the step rings.
fn write_cut_column(path: &Path) {
    let [nx, ny, nz] = [32usize, 32, 24];
    let mut bytes = format!(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: {nx} {ny} {nz}\n\
         spacings: 1 1 1.5\nendian: little\nencoding: raw\n\n"
    )
    .into_bytes();
    for k in 0..nz {
        let along = match k {
            0..=10 => 1.0,
            11..=18 => (std::f64::consts::FRAC_PI_2 * (k - 10) as f64 / 9.0)
                .cos()
                .powi(2),
            _ => 0.0,
        };
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (i as f64 - 15.5, j as f64 - 15.5);
                let v = along * (-(x * x + y * y) / 25.0).exp();
                bytes.extend_from_slice(&(v as f32).to_le_bytes());
            }
        }
    }
    std::fs::write(path, bytes).unwrap();
}

/// The most negative pixel as a share of the largest.
fn undershoot(path: &Path) -> f64 {
    let image = read_nrrd_image(path).unwrap();
    let max = image.data.iter().fold(f32::MIN, |m, &v| m.max(v)) as f64;
    let min = image.data.iter().fold(f32::MAX, |m, &v| m.min(v)) as f64;
    -min / max
}

fn stats(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

#[test]
fn taper_fades_the_cut_and_the_ringing() {
    let dir = temp_dir("taper-cut");
    write_cut_column(&dir.join("cut.nrrd"));
    // Seen from the side, the cut face is edge on: a step in the image.
    let view = "render cut.nrrd --dir 1,0,0 --filter kb4 --oversample 1 --precision f32";
    fvr_ok(&format!("{view} --out plain.nrrd"), &dir);
    let out = fvr_line(
        &format!("{view} --taper 4 --out tapered.nrrd --stats-json"),
        &dir,
    );
    let json = stats(&assert_ok(&out));
    assert_eq!(json["taper"]["voxels"], 4, "{json}");
    assert_eq!(json["taper"]["faces"], serde_json::json!(["k-"]), "{json}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("k-") && err.contains("4 voxels"), "{err}");
    let (plain, tapered) = (
        undershoot(&dir.join("plain.nrrd")),
        undershoot(&dir.join("tapered.nrrd")),
    );
    assert!(plain > 0.02, "the cut rings: {plain}");
    assert!(tapered < plain / 10.0, "plain {plain}, tapered {tapered}");
    // Without a number, 8 voxels; a scene says `taper = N`.
    let json = stats(&fvr_ok(
        &format!("{view} --taper --out t8.nrrd --stats-json"),
        &dir,
    ));
    assert_eq!(json["taper"]["voxels"], 8, "{json}");
    std::fs::write(
        dir.join("s.toml"),
        "[volume]\npath = \"cut.nrrd\"\ntaper = 4\n[camera]\ndir = [1, 0, 0]\n\
         [spectrum]\nfilter = \"kb4\"\noversample = 1\nprecision = \"f32\"\n\
         [output]\npath = \"scene.nrrd\"\n",
    )
    .unwrap();
    fvr_ok("render --scene s.toml", &dir);
    let a = std::fs::read(dir.join("tapered.nrrd")).unwrap();
    let b = std::fs::read(dir.join("scene.nrrd")).unwrap();
    assert_eq!(a, b, "the scene's taper = 4 is --taper 4");
    assert_ne!(a, std::fs::read(dir.join("plain.nrrd")).unwrap());
}

#[test]
fn nothing_cut_nothing_changed() {
    let dir = temp_dir("taper-none");
    let view = "sphere@32 --dir 1,0.3,0.2 --filter kb4 --oversample 1";
    fvr_ok(&format!("render {view} --out a.nrrd"), &dir);
    let out = fvr_line(&format!("render {view} --taper --out b.nrrd"), &dir);
    assert_ok(&out);
    assert!(String::from_utf8_lossy(&out.stderr).contains("nothing tapered"));
    assert_eq!(
        std::fs::read(dir.join("a.nrrd")).unwrap(),
        std::fs::read(dir.join("b.nrrd")).unwrap()
    );
    // The turntable and the projection set take it too.
    let json = stats(&fvr_ok(
        "project sphere@16 --random 2 --taper 3 --out p.npy --stats-json",
        &dir,
    ));
    assert_eq!(json["taper"]["voxels"], 3, "{json}");
    assert_eq!(json["taper"]["faces"], serde_json::json!([]), "{json}");
    fvr_ok("turntable sphere@16 --frames 2 --taper --out t.apng", &dir);
}

#[test]
fn bad_tapers_are_one_line() {
    let dir = temp_dir("taper-bad");
    write_cut_column(&dir.join("cut.nrrd"));
    for (line, needles) in [
        (
            "render cut.nrrd --dir 1,0,0 --taper 0 --out x.png",
            &["--taper 0", "1 or more"][..],
        ),
        (
            "render cut.nrrd --dir 1,0,0 --taper 13 --out x.png",
            &["--taper 13", "24 voxels along k", "at most 12"][..],
        ),
        (
            "project cut.nrrd --random 2 --taper 0 --out x.npy",
            &["--taper 0"][..],
        ),
        (
            "render cut.nrrd --dir 1,0,0 --taper=x --out x.png",
            &["--taper"][..],
        ),
    ] {
        let out = fvr_line(line, &dir);
        assert_error(&out, needles);
        assert_eq!(
            String::from_utf8_lossy(&out.stderr).trim().lines().count(),
            1,
            "{line}"
        );
        assert!(!dir.join("x.png").exists() && !dir.join("x.npy").exists());
    }
}
