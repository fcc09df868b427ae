//! Outputs keep their geometry: a rendered NRRD carries `kinds` and the
//! pixel size as `spacings` (an RGB render one colour image, not three
//! slices), and `fvr convert` keeps a NIfTI's or NRRD's orientation and
//! origin as `space`, `space directions` and `space origin`.

mod common;
use common::{assert_ok, fvr_line, fvr_ok, temp_dir};

use fvr_engine::volume::Orientation;
use fvr_host::io::nifti::{encode_nifti_f32, offsets};
use fvr_host::io::nrrd::{read_nrrd, read_nrrd_image, Endian};

fn header(path: &std::path::Path) -> String {
    let bytes = std::fs::read(path).unwrap();
    // Through the last field's newline.
    let end = bytes.windows(2).position(|w| w == b"\n\n").unwrap() + 1;
    String::from_utf8(bytes[..end].to_vec()).unwrap()
}

#[test]
fn rendered_nrrd_headers_carry_kinds_and_pixel_size() {
    let dir = temp_dir("geometry-render");
    fvr_ok("render sphere@16 --dir 1,0,0 --out g.nrrd", &dir);
    let h = header(&dir.join("g.nrrd"));
    assert!(h.contains("sizes: 16 16\n"), "{h}");
    assert!(h.contains("kinds: domain domain\n"), "{h}");
    assert!(h.contains("spacings: 1.0 1.0\n"), "{h}");
    // Zoomed: the pixel size divided by the zoom.
    fvr_ok("render sphere@16 --dir 1,0,0 --zoom 4 --out z.nrrd", &dir);
    let h = header(&dir.join("z.nrrd"));
    assert!(
        h.contains("sizes: 64 64\n") && h.contains("spacings: 0.25 0.25\n"),
        "{h}"
    );
    // A pixel size of its own.
    fvr_ok(
        "render sphere@16 --dir 1,0,0 --pixel-size 0.75 --out p.nrrd",
        &dir,
    );
    assert!(header(&dir.join("p.nrrd")).contains("spacings: 0.75 0.75\n"));
    // Colour: one RGB image, which `fvr compare` and the image reader read
    // and the volume reader refuses.
    fvr_ok(
        "render sphere@16 --dir 1,0.3,0.2 --light 1,1,0:1,0.5,0.2 --out c.nrrd",
        &dir,
    );
    let h = header(&dir.join("c.nrrd"));
    assert!(h.contains("sizes: 3 16 16\n"), "{h}");
    assert!(h.contains("kinds: RGB-color domain domain\n"), "{h}");
    assert!(h.contains("spacings: nan 1.0 1.0\n"), "{h}");
    assert_eq!(
        read_nrrd_image(&dir.join("c.nrrd")).unwrap().dims,
        [3, 16, 16]
    );
    assert!(read_nrrd(&dir.join("c.nrrd")).is_err());
    let out = fvr_line("compare c.nrrd c.nrrd", &dir);
    assert_ok(&out);
}

const N: usize = 6;

/// A NIfTI whose axes run posterior, left and superior, 2 mm apart, at
/// origin (30, 40, −5): its sform.
fn write_permuted_nifti(path: &std::path::Path) {
    let data: Vec<f32> = (0..N * N * N).map(|v| v as f32).collect();
    let mut bytes = encode_nifti_f32([N; 3], [2.0; 3], (1.0, 0.0), &data, Endian::Little);
    bytes[offsets::SFORM_CODE..offsets::SFORM_CODE + 2].copy_from_slice(&1i16.to_le_bytes());
    let rows = [
        [0.0f32, -2.0, 0.0, 30.0],
        [-2.0, 0.0, 0.0, 40.0],
        [0.0, 0.0, 2.0, -5.0],
    ];
    for (w, row) in rows.iter().enumerate() {
        for (a, v) in row.iter().enumerate() {
            let at = offsets::SROW_X + 16 * w + 4 * a;
            bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn convert_keeps_orientation_and_origin() {
    let dir = temp_dir("geometry-convert");
    write_permuted_nifti(&dir.join("p.nii"));
    fvr_ok("convert p.nii --out a.nrrd", &dir);
    let h = header(&dir.join("a.nrrd"));
    assert!(h.contains("space: right-anterior-superior\n"), "{h}");
    assert!(!h.contains("spacings"), "{h}");
    let a = read_nrrd(&dir.join("a.nrrd")).unwrap();
    // The reader reorders the axes to R, A, S; the origin moves to the
    // voxel that is now first: file voxel (N−1, N−1, 0), at
    // (30 − 2(N−1), 40 − 2(N−1), −5).
    let o = a.orientation.expect("orientation kept");
    assert_eq!(o.direction, Orientation::IDENTITY.direction);
    let far = 2.0 * (N - 1) as f64;
    assert_eq!(o.origin, [30.0 - far, 40.0 - far, -5.0]);
    assert_eq!(a.spacing, [2.0; 3]);
    // NRRD → NRRD: the same header geometry and samples.
    fvr_ok("convert a.nrrd --out b.nrrd", &dir);
    let b = read_nrrd(&dir.join("b.nrrd")).unwrap();
    assert_eq!(b.orientation, a.orientation);
    assert_eq!(b.spacing, a.spacing);
    assert_eq!(b.data, a.data);
    // An LPS NRRD with an oblique frame: kept, in RAS.
    let (c, s) = (0.6f64, 0.8f64);
    let text = format!(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nspace: left-posterior-superior\n\
         space directions: ({},{},0) ({},{},0) (0,0,1.5)\nspace origin: (1,2,3)\n\
         encoding: raw\nendian: little\n\n",
        c, s, -s, c
    );
    let mut bytes = text.into_bytes();
    for v in 0..8 {
        bytes.extend_from_slice(&(v as f32).to_le_bytes());
    }
    std::fs::write(dir.join("lps.nrrd"), bytes).unwrap();
    fvr_ok("convert lps.nrrd --out c.nrrd", &dir);
    let back = read_nrrd(&dir.join("c.nrrd")).unwrap().orientation.unwrap();
    let want = [[-c, s, 0.0], [-s, -c, 0.0], [0.0, 0.0, 1.0]];
    for w in 0..3 {
        for ax in 0..3 {
            assert!(
                (back.direction[w][ax] - want[w][ax]).abs() < 1e-12,
                "{back:?}"
            );
        }
    }
    assert_eq!(back.origin, [-1.0, -2.0, 3.0]);
}
