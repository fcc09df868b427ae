//! `fvr convert`: any volume `fvr` reads, written as a float NRRD file with
//! its spacing, reads back with the same voxels and spacing; bad output
//! names are refused in one line before any work.

mod common;
use common::{assert_error, fvr_line, fvr_ok, temp_dir};

use fvr_host::io::nrrd::{encode_nrrd, read_nrrd, Encoding, Endian, SampleType};
use fvr_host::sources::{load_volume, RawLayout};

/// A built-in phantom converts to the same voxels and (unit) spacing the
/// library loads, and converting again overwrites the output as render does.
#[test]
fn phantom_round_trips() {
    let dir = temp_dir("convert-phantom");
    let expected = load_volume("gaussians@24", None).unwrap();
    for _ in 0..2 {
        fvr_ok("convert gaussians@24 --out g.nrrd --quiet", &dir);
        let back = read_nrrd(&dir.join("g.nrrd")).unwrap();
        assert_eq!(back.dims, expected.dims);
        assert_eq!(back.data, expected.data);
        assert_eq!(back.spacing, expected.spacing);
    }
}

/// An anisotropic NRRD in 16-bit integers keeps its spacing, and
/// `--background` is applied as when rendering: max(v - B, 0).
#[test]
fn spacing_and_background_are_kept() {
    let dir = temp_dir("convert-spacing");
    let dims = [6usize, 5, 4];
    let values: Vec<f64> = (0..120).map(|n| ((n * 37) % 101) as f64 - 40.0).collect();
    let bytes = encode_nrrd(&dims, SampleType::I16, Encoding::Gzip, Endian::Big, &values);
    let text = String::from_utf8_lossy(&bytes);
    let header_end = text.find("\n\n").unwrap();
    // Add the spacing to the header the helper wrote.
    let mut with_spacing = bytes[..header_end + 1].to_vec();
    with_spacing.extend_from_slice(b"spacings: 0.957031 0.957031 1.5\n");
    with_spacing.extend_from_slice(&bytes[header_end + 1..]);
    std::fs::write(dir.join("ct.nrrd"), with_spacing).unwrap();

    fvr_ok("convert ct.nrrd --background -20 --out f.nrrd", &dir);
    let back = read_nrrd(&dir.join("f.nrrd")).unwrap();
    assert_eq!(back.dims, dims);
    assert_eq!(back.spacing, [0.957031, 0.957031, 1.5]);
    let want: Vec<f32> = values.iter().map(|&v| (v + 20.0).max(0.0) as f32).collect();
    assert_eq!(back.data, want);
}

/// A headerless raw file with the raw flags converts to its samples at
/// unit spacing.
#[test]
fn raw_input_converts() {
    let dir = temp_dir("convert-raw");
    let samples: Vec<u16> = (0..60u16).map(|n| n * 1000).collect();
    let bytes: Vec<u8> = samples.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join("v.raw"), bytes).unwrap();
    fvr_ok(
        "convert v.raw --raw-dims 5,4,3 --raw-type u16 --out v.nrrd",
        &dir,
    );
    let back = read_nrrd(&dir.join("v.nrrd")).unwrap();
    let expected = load_volume(
        dir.join("v.raw").to_str().unwrap(),
        Some(RawLayout {
            dims: [5, 4, 3],
            ty: SampleType::U16,
            endian: Endian::Little,
        }),
    )
    .unwrap();
    assert_eq!(back.dims, [5, 4, 3]);
    assert_eq!(back.data, expected.data);
    assert_eq!(back.data[59], 59_000.0);
    assert_eq!(back.spacing, [1.0; 3]);
}

/// Wrong extension, a missing directory and the input itself are refused by
/// name, and nothing is written.
#[test]
fn bad_outputs_are_refused() {
    let dir = temp_dir("convert-bad");
    let out = fvr_line("convert gaussians@16 --out g.png", &dir);
    assert_error(&out, &["g.png", "the extension must be one of .nrrd"]);
    assert!(!dir.join("g.png").exists());
    let out = fvr_line("convert gaussians@16 --out missing/g.nrrd", &dir);
    assert_error(&out, &["missing/g.nrrd", "its directory does not exist"]);
    fvr_ok("convert gaussians@16 --out g.nrrd", &dir);
    let before = std::fs::read(dir.join("g.nrrd")).unwrap();
    let out = fvr_line("convert g.nrrd --out g.nrrd", &dir);
    assert_error(&out, &["refusing to overwrite an input"]);
    assert_eq!(std::fs::read(dir.join("g.nrrd")).unwrap(), before);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert_error(&fvr_line("convert --out g.nrrd", &dir), &["VOLUME"]);
}
