//! `fvr render --view`: views named in the patient's frame, from the
//! file's orientation. A marker blob at the patient's right-anterior-
//! superior corner must land in the image quadrant each view puts it in,
//! whichever way the file stores its axes (NIfTI sform, NRRD LPS space
//! directions), and a volume stored permuted and flipped renders the same
//! image.

mod common;
use common::{assert_error, assert_ok, fvr, fvr_line, temp_dir};

use std::path::Path;

use fvr_host::io::nifti::{encode_nifti_f32, offsets};
use fvr_host::io::nrrd::{read_nrrd, Endian};
use fvr_host::reference::snr_db;

const N: usize = 20;

/// The patient-frame density at RAS index `p`: a wide faint blob at the
/// centre and a bright marker towards the right-anterior-superior corner.
fn density(p: [usize; 3]) -> f32 {
    let g = |c: [f64; 3], s: f64| {
        let d2: f64 = (0..3).map(|a| (p[a] as f64 - c[a]).powi(2)).sum();
        (-d2 / (2.0 * s * s)).exp()
    };
    (0.2 * g([9.5; 3], 4.0) + g([15.0, 15.0, 15.0], 1.5)) as f32
}

/// How a file stores the patient grid: file voxel `(i, j, k)` holds RAS
/// index `ras(i, j, k)`; `columns[a]` is file axis `a` in RAS, `origin`
/// the RAS position of file voxel 0.
struct Storage {
    ras: fn([usize; 3]) -> [usize; 3],
    columns: [[f64; 3]; 3],
    origin: [f64; 3],
}

const IDENTITY: Storage = Storage {
    ras: |p| p,
    columns: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    origin: [0.0; 3],
};

/// File axis 0 runs posterior, axis 1 to the left, axis 2 superior.
const PERMUTED: Storage = Storage {
    ras: |[i, j, k]| [N - 1 - j, N - 1 - i, k],
    columns: [[0.0, -1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
    origin: [(N - 1) as f64, (N - 1) as f64, 0.0],
};

fn samples(s: &Storage) -> Vec<f32> {
    let mut data = Vec::with_capacity(N * N * N);
    for k in 0..N {
        for j in 0..N {
            for i in 0..N {
                data.push(density((s.ras)([i, j, k])));
            }
        }
    }
    data
}

fn write_nifti(path: &Path, s: &Storage) {
    let mut bytes = encode_nifti_f32([N; 3], [1.0; 3], (1.0, 0.0), &samples(s), Endian::Little);
    bytes[offsets::SFORM_CODE..offsets::SFORM_CODE + 2].copy_from_slice(&1i16.to_le_bytes());
    for w in 0..3 {
        for a in 0..4 {
            let v = if a < 3 { s.columns[a][w] } else { s.origin[w] } as f32;
            let at = offsets::SROW_X + 16 * w + 4 * a;
            bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(path, bytes).unwrap();
}

/// A NRRD in LPS, as ITK and 3D Slicer write it.
fn write_nrrd_lps(path: &Path, s: &Storage) {
    let lps = |v: [f64; 3]| format!("({},{},{})", -v[0], -v[1], v[2]);
    let mut bytes = format!(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: {N} {N} {N}\nspace: left-posterior-superior\n\
         space directions: {} {} {}\nspace origin: {}\nkinds: domain domain domain\n\
         encoding: raw\nendian: little\n\n",
        lps(s.columns[0]),
        lps(s.columns[1]),
        lps(s.columns[2]),
        lps(s.origin)
    )
    .into_bytes();
    for v in samples(s) {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}

/// Render `volume` with `--view view` and return the image and which
/// quadrant its brightest pixel is in: "top-left", "top-right", ...
fn render(dir: &Path, volume: &str, view: &str) -> (Vec<f32>, &'static str) {
    let out = format!("{view}.nrrd");
    assert_ok(&fvr(
        &[
            "render",
            volume,
            "--view",
            view,
            "--accuracy",
            "60",
            "--out",
            &out,
        ],
        dir,
    ));
    let image = read_nrrd(&dir.join(&out)).unwrap();
    let [w, h, _] = image.dims;
    let (at, _) = image
        .data
        .iter()
        .enumerate()
        .fold((0, f32::MIN), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
    let (col, row) = (at % w, at / w);
    let quadrant = match (2 * row < h, 2 * col < w) {
        (true, true) => "top-left",
        (true, false) => "top-right",
        (false, true) => "bottom-left",
        (false, false) => "bottom-right",
    };
    (image.data, quadrant)
}

/// Where each view puts the patient's right-anterior-superior corner.
const EXPECTED: [(&str, &str); 6] = [
    // From the front, superior up: the patient's right on the image's left.
    ("anterior", "top-left"),
    ("posterior", "top-right"),
    // From the patient's left: anterior to the image's left.
    ("left", "top-left"),
    ("right", "top-right"),
    // From above, anterior up: the patient's right on the right.
    ("superior", "top-right"),
    // From the feet, anterior up: the patient's right on the left.
    ("inferior", "top-left"),
];

#[test]
fn named_views_put_the_marker_where_the_patient_has_it() {
    let dir = temp_dir("anatomy");
    write_nifti(&dir.join("ras.nii"), &IDENTITY);
    write_nifti(&dir.join("permuted.nii"), &PERMUTED);
    write_nrrd_lps(&dir.join("permuted.nrrd"), &PERMUTED);
    write_nrrd_lps(&dir.join("ras.nrrd"), &IDENTITY);
    for (view, quadrant) in EXPECTED {
        let (reference, q) = render(&dir, "ras.nii", view);
        assert_eq!(q, quadrant, "ras.nii --view {view}");
        for file in ["permuted.nii", "permuted.nrrd", "ras.nrrd"] {
            let (image, q) = render(&dir, file, view);
            assert_eq!(q, quadrant, "{file} --view {view}");
            if file == "permuted.nrrd" {
                // Left-handed storage: flipped along x before rendering,
                // and the rotation centre (voxel n/2) moves one voxel with
                // it, so the image matches only to that shift.
                continue;
            }
            let a: Vec<f64> = reference.iter().map(|&v| v as f64).collect();
            let b: Vec<f64> = image.iter().map(|&v| v as f64).collect();
            let db = snr_db(&a, &b);
            // The NIfTI reader reorders the axes exactly; the NRRD volume is
            // rendered in its own frame, along the turned view (rounding and
            // the interpolation's tails only).
            assert!(
                db > 50.0,
                "{file} --view {view}: {db:.1} dB against ras.nii"
            );
        }
    }
}

#[test]
fn view_conflicts_with_dir_and_notes_a_missing_orientation() {
    let dir = temp_dir("anatomy-cli");
    let out = fvr_line("render sphere@16 --view left --dir 1,0,0 --out x.png", &dir);
    assert_error(&out, &["fvr: error:", "--view", "--dir"]);
    assert_eq!(
        String::from_utf8_lossy(&out.stderr)
            .trim_end()
            .lines()
            .count(),
        1
    );
    assert!(!dir.join("x.png").exists());
    let out = fvr_line("render sphere@16 --view sideways --out x.png", &dir);
    assert_error(&out, &["fvr: error:", "sideways"]);
    let out = fvr_line("render sphere@16 --view left --out x.png", &dir);
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no orientation") && err.contains("RAS"),
        "{err}"
    );
}

/// brainsmall's orientation is built in (x posterior, y inferior, z to
/// the right): no note, and its left view is the upright side view
/// `--dir 0,0,1 --up 0,-1,0`, bit for bit, which
/// examples/brainsmall-xray-hot.toml uses.
#[test]
fn brainsmall_named_views_need_no_note() {
    let dir = temp_dir("anatomy-brainsmall");
    let out = fvr_line("render brainsmall --view left --out a.nrrd", &dir);
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("no orientation"), "{err}");
    let out = fvr_line(
        "render brainsmall --dir 0,0,1 --up 0,-1,0 --out b.nrrd",
        &dir,
    );
    assert_ok(&out);
    let a = std::fs::read(dir.join("a.nrrd")).unwrap();
    let b = std::fs::read(dir.join("b.nrrd")).unwrap();
    assert!(a == b, "--view left differs from --dir 0,0,1 --up 0,-1,0");
}
