//! DICOM series: slice sorting, spacing, rescale, series selection and bad
//! input, on series written by `CtSlice::encode`.

use std::path::{Path, PathBuf};

use fvr_host::io::dicom::{parse_slice, read_dicom, CtSlice};
use fvr_host::io::{detect, read_volume, Format};

const AXIAL: [f64; 6] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fvr-dicom-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Pixels of slice `k`: distinct per pixel and slice.
fn pixels(k: usize, n: usize) -> Vec<i16> {
    (0..n).map(|i| (100 * k + i) as i16).collect()
}

/// Write slices `k` at depth `depths[k]` along `normal`, file names in the
/// order given by `names` (so the directory order is not the slice order).
fn write_series(dir: &Path, series: &str, depths: &[f64], orientation: [f64; 6], names: &[&str]) {
    let row = [orientation[0], orientation[1], orientation[2]];
    let col = [orientation[3], orientation[4], orientation[5]];
    let normal = [
        row[1] * col[2] - row[2] * col[1],
        row[2] * col[0] - row[0] * col[2],
        row[0] * col[1] - row[1] * col[0],
    ];
    for (k, &d) in depths.iter().enumerate() {
        let position = [
            10.0 + d * normal[0],
            -20.0 + d * normal[1],
            5.0 + d * normal[2],
        ];
        let bytes = CtSlice {
            series,
            instance: k as u32 + 1,
            size: [5, 3],
            pixel_spacing: [0.7, 0.6],
            position,
            orientation,
            intercept: -1024.0,
            pixels: &pixels(k, 15),
            // Every other file in implicit VR: a series may mix the two.
            implicit_vr: k % 2 == 1,
        }
        .encode();
        std::fs::write(dir.join(names[k]), bytes).unwrap();
    }
}

fn err_of(path: &Path) -> String {
    match read_dicom(path) {
        Ok(v) => panic!("expected an error, got {:?}", v.dims),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_series_is_sorted_by_position_with_spacing_and_rescale() {
    let dir = temp_dir("axial");
    // Depths out of file-name order: c=0, a=2.5, d=5, b=7.5.
    let names = ["a.dcm", "b.dcm", "c.dcm", "d.dcm"];
    write_series(&dir, "1.2.3", &[2.5, 7.5, 0.0, 5.0], AXIAL, &names);
    std::fs::write(dir.join("notes.txt"), "not DICOM").unwrap();
    assert_eq!(detect(&dir).unwrap(), Format::Dicom);
    let vol = read_volume(&dir).expect("series");
    assert_eq!(vol.dims, [5, 3, 4]);
    assert_eq!(vol.spacing, [0.6, 0.7, 2.5]);
    // Slice order by depth is files c, a, d, b = written slices 2, 0, 3, 1.
    for (z, k) in [2usize, 0, 3, 1].into_iter().enumerate() {
        for i in 0..15 {
            let expected = pixels(k, 15)[i] as f32 - 1024.0;
            assert_eq!(vol.get(i % 5, i / 5, z), expected, "z {z} pixel {i}");
        }
    }
    // One file of the series reads the whole series.
    assert_eq!(
        read_volume(&dir.join("b.dcm")).expect("one file").data,
        vol.data
    );
}

#[test]
fn an_oblique_series_sorts_along_its_normal() {
    let dir = temp_dir("coronal");
    // Rows along x, columns along -z: the normal is +y.
    let coronal = [1.0, 0.0, 0.0, 0.0, 0.0, -1.0];
    write_series(
        &dir,
        "9.9",
        &[3.0, 0.0, 1.5],
        coronal,
        &["1.dcm", "2.dcm", "3.dcm"],
    );
    let vol = read_dicom(&dir).expect("coronal");
    assert_eq!(vol.spacing, [0.6, 0.7, 1.5]);
    assert_eq!(vol.get(0, 0, 0), pixels(1, 15)[0] as f32 - 1024.0);
    assert_eq!(vol.get(0, 0, 2), pixels(0, 15)[0] as f32 - 1024.0);
}

#[test]
fn one_file_picks_its_series_and_a_mixed_directory_is_refused() {
    let dir = temp_dir("two-series");
    write_series(&dir, "1.1", &[0.0, 1.0, 2.0], AXIAL, &["a1", "a2", "a3"]);
    write_series(&dir, "2.2", &[0.0, 3.0], AXIAL, &["b1", "b2"]);
    assert_eq!(read_dicom(&dir.join("b2")).unwrap().dims, [5, 3, 2]);
    assert_eq!(read_dicom(&dir.join("a1")).unwrap().dims, [5, 3, 3]);
    let msg = err_of(&dir);
    assert!(
        msg.contains("2 series") && msg.contains("1.1") && msg.contains("2.2"),
        "{msg}"
    );
}

#[test]
fn gaps_duplicates_and_mismatches_are_refused() {
    let gap = temp_dir("gap");
    write_series(
        &gap,
        "1",
        &[0.0, 1.0, 2.0, 4.0],
        AXIAL,
        &["1", "2", "3", "4"],
    );
    let msg = err_of(&gap);
    assert!(
        msg.contains("ImagePositionPatient") && msg.contains("missing slices"),
        "{msg}"
    );
    let dup = temp_dir("dup");
    write_series(&dup, "1", &[0.0, 1.0, 1.0], AXIAL, &["1", "2", "3"]);
    assert!(err_of(&dup).contains("share a position"));
    let size = temp_dir("size");
    write_series(&size, "1", &[0.0, 1.0], AXIAL, &["1", "2"]);
    let other = CtSlice {
        instance: 3,
        pixel_spacing: [0.7, 0.6],
        position: [10.0, -20.0, 7.0],
        ..CtSlice::axial([4, 3], &[0; 12])
    }
    .encode();
    std::fs::write(size.join("3"), other).unwrap();
    assert!(err_of(&size).contains("Rows"), "{}", err_of(&size));
    let zero = temp_dir("zero-spacing");
    let flat = CtSlice {
        pixel_spacing: [0.0, 0.5],
        ..CtSlice::axial([2, 2], &[0; 4])
    }
    .encode();
    std::fs::write(zero.join("1"), flat).unwrap();
    let msg = err_of(&zero);
    assert!(
        msg.contains("PixelSpacing") && msg.contains("zero"),
        "{msg}"
    );
    let skew = temp_dir("skew");
    let half = std::f64::consts::FRAC_1_SQRT_2;
    let bytes = CtSlice {
        orientation: [1.0, 0.0, 0.0, half, half, 0.0],
        ..CtSlice::axial([2, 2], &[0; 4])
    }
    .encode();
    std::fs::write(skew.join("1"), bytes).unwrap();
    assert!(
        err_of(&skew).contains("ImageOrientationPatient"),
        "{}",
        err_of(&skew)
    );
    let empty = temp_dir("empty");
    std::fs::write(empty.join("readme"), "nothing here").unwrap();
    assert!(err_of(&empty).contains("no DICOM image"));
}

#[test]
fn corrupt_files_are_named() {
    let dir = temp_dir("corrupt");
    write_series(&dir, "1", &[0.0, 1.0], AXIAL, &["good", "bad"]);
    let bytes = std::fs::read(dir.join("bad")).unwrap();
    std::fs::write(dir.join("bad"), &bytes[..bytes.len() - 7]).unwrap();
    let msg = err_of(&dir);
    assert!(msg.contains("bad") && msg.contains("DICOM"), "{msg}");
    refused(&bytes[..200], &["DICOM"]);
    assert!(parse_slice(b"hello").is_err());
}

/// Found by `cargo fuzz run dicom`: an element declaring more bytes than
/// the file holds made `dicom-object` zero-fill the declared length first
/// (1.6 s and gigabytes for a 742-byte file). Now refused before parsing.
#[test]
fn fuzz_regression_declared_lengths_beyond_the_file_are_refused() {
    let found = include_bytes!("data/fuzz/dicom-declared-length-beyond-file.dcm");
    refused(
        found,
        &["declares 1396899936 bytes but the file has only 250"],
    );
    // The same for pixel data whose length is patched to nearly 4 GiB.
    let mut bytes = tiny_slice(0.0);
    let at = bytes
        .windows(4)
        .rposition(|w| w == [0xE0, 0x7F, 0x10, 0x00])
        .expect("pixel data tag");
    bytes[at + 8..at + 12].copy_from_slice(&0xFFFF_FF00u32.to_le_bytes());
    refused(&bytes, &["(7FE0,0010) declares 4294967040 bytes"]);
}

/// Found by `cargo fuzz run dicom -s none`: in an implicit-VR data set, a
/// 46-byte (0000,0000), which the dictionary makes a UL, was read as eleven
/// 4-byte values; the parser then took two bytes of value as the next
/// header and allocated about 4 GB (`fvr convert` peaked at 4.2 GB
/// resident). The length walk now takes implicit VRs from the dictionary,
/// as the parser does, and refuses the file before parsing.
#[test]
fn fuzz_regression_implicit_vr_lengths_are_checked_with_the_dictionary_vr() {
    let found = include_bytes!("data/fuzz/dicom-implicit-ul-out-of-step.dcm");
    refused(
        found,
        &["element (0000,0000) of 4-byte values has length 46, not a multiple of 4"],
    );
    // A valid implicit-VR slice, with (0028,xxxx) US and DS values whose
    // sizes come from the dictionary, still reads; a UL group length of
    // 6 bytes in it is refused.
    let implicit = CtSlice {
        implicit_vr: true,
        ..CtSlice::axial([2, 2], &[1, 2, 3, 4])
    }
    .encode();
    assert_eq!(
        parse_slice(&implicit).unwrap().pixels,
        vec![1.0, 2.0, 3.0, 4.0]
    );
    let mut bytes = implicit.clone();
    // (0028,0010) Rows, implicit: tag, 4-byte length 2; renamed to the
    // group length (0028,0000), a UL, and given 6 bytes (4 of the next
    // element's header).
    let at = bytes
        .windows(8)
        .position(|w| w == [0x28, 0x00, 0x10, 0x00, 2, 0, 0, 0])
        .expect("Rows in implicit VR");
    bytes[at + 2..at + 8].copy_from_slice(&[0, 0, 6, 0, 0, 0]);
    refused(&bytes, &["(0028,0000) of 4-byte values has length 6"]);
}

/// Found by `cargo fuzz run dicom -s none`: an element of the item group
/// that is no item or delimiter, (FFFE,FFFF) declaring 0xFDFFFFFF bytes in
/// a 514-byte file, which the parser reads as a value (4 GB allocated) and
/// the length walk used to step into as an item.
#[test]
fn fuzz_regression_item_group_elements_are_values() {
    let found = include_bytes!("data/fuzz/dicom-item-group-4gb.dcm");
    refused(found, &["element (FFFE,FFFF) declares 4261412863 bytes"]);
}

/// Found by `cargo fuzz run dicom -s none`: pixel data as OW of odd length
/// (79 bytes), which the parser reads as 16-bit words, leaving it a byte
/// out of step with the element boundaries; it then read a 3.4 GB length
/// from the bytes that followed (`fvr convert` peaked at 3.3 GB resident).
#[test]
fn fuzz_regression_odd_ow_lengths_are_refused() {
    let found = include_bytes!("data/fuzz/dicom-odd-ow-3gb.dcm");
    refused(
        found,
        &["element (7FE0,0010) of 2-byte values has length 79, not a multiple of 2"],
    );
}

/// Found by `cargo fuzz run dicom -s none`: a transfer syntax UID with a
/// trailing tab, which `dicom-object` trims (explicit VR big endian) and a
/// length walk of exact matches did not (little endian), so the walk and
/// the parser read different lengths; the parser allocated 4,278,190,080
/// bytes (`fvr convert` peaked at 4.2 GB resident). Files are read by the
/// bounded reader, which checks every length before allocating: under a
/// 1 GiB address-space limit `fvr convert` refuses the file in one line.
#[test]
fn fuzz_regression_no_declared_length_is_allocated_before_it_is_checked() {
    const NEEDLE: &str = "element (00FE,FFFF) declares 4278190080 bytes but the file has only 520";
    let found = include_bytes!("data/fuzz/dicom-syntax-whitespace-4gb.dcm");
    refused(found, &[NEEDLE]);
    let dir = temp_dir("whitespace-syntax");
    let input = dir.join("found.dcm");
    std::fs::write(&input, found).unwrap();
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 1048576 && exec '{}' convert '{}' --out '{}'",
            env!("CARGO_BIN_EXE_fvr"),
            input.display(),
            dir.join("out.nrrd").display()
        ))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains(NEEDLE), "{err}");
    assert!(!dir.join("out.nrrd").exists());
}

/// Found by `cargo fuzz run dicom`: a BitsStored of 0 made
/// `dicom-pixeldata` panic building its lookup table
/// (`assertion failed: bits_stored != 0 && bits_stored <= 32`).
#[test]
fn fuzz_regression_bits_stored_out_of_range_is_an_error_not_a_panic() {
    let found = include_bytes!("data/fuzz/dicom-bits-stored-zero-panic.dcm");
    refused(found, &["Bits"]);
    // BitsStored 0 and 33 in an otherwise valid slice.
    let good = tiny_slice(-5.0);
    assert_eq!(
        parse_slice(&good).unwrap().pixels,
        vec![-4.0, -3.0, -2.0, -1.0]
    );
    // (0028,0101) US, length 2, value 16.
    let at = good
        .windows(8)
        .position(|w| w == [0x28, 0x00, 0x01, 0x01, b'U', b'S', 2, 0])
        .expect("BitsStored");
    for bad in [0u16, 33] {
        let mut bytes = good.clone();
        bytes[at + 8..at + 10].copy_from_slice(&bad.to_le_bytes());
        refused(&bytes, &["`BitsStored`", &format!("is {bad}")]);
    }
}

/// Sizes that the pixel data cannot hold are refused before decoding (the
/// decoder allocates the decoded size first; `cargo fuzz run dicom` ran out
/// of memory on such inputs).
#[test]
fn sizes_beyond_the_pixel_data_are_refused_before_decoding() {
    let good = tiny_slice(0.0);
    // (0028,0010) Rows, US, length 2.
    let at = good
        .windows(8)
        .position(|w| w == [0x28, 0x00, 0x10, 0x00, b'U', b'S', 2, 0])
        .expect("Rows");
    let mut bytes = good.clone();
    bytes[at + 8..at + 10].copy_from_slice(&65535u16.to_le_bytes());
    refused(&bytes, &["65535 rows x 2 columns", "pixel data holds (8)"]);
    bytes[at + 8..at + 10].copy_from_slice(&0u16.to_le_bytes());
    refused(&bytes, &["`Rows`: is 0"]);
}

/// `bytes` refused by the parser, with every needle in the message.
fn refused(bytes: &[u8], needles: &[&str]) {
    let e = parse_slice(bytes).unwrap_err().to_string();
    for needle in needles {
        assert!(e.contains(needle), "`{needle}` not in: {e}");
    }
}

/// A valid 2×2 axial CT slice of pixels 1..=4 with `intercept`.
fn tiny_slice(intercept: f64) -> Vec<u8> {
    CtSlice {
        intercept,
        ..CtSlice::axial([2, 2], &[1, 2, 3, 4])
    }
    .encode()
}
