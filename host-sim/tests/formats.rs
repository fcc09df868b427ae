//! The volume readers: NIfTI-1, VolPack `.den`, InVesalius `.inv3`, NRRD
//! (detached headers and spacings), format detection, and bad input.

use std::io::Write;
use std::path::{Path, PathBuf};

use fvr_engine::volume::{check_spacing, Volume, DEFAULT_SPACING};
use fvr_host::io::den::{encode_den, parse_den, HEADER_BYTES as DEN_HEADER};
use fvr_host::io::inv3::{encode_archive, encode_inv3_i16, main_plist_text, parse_inv3};
use fvr_host::io::nifti::{encode_nifti_f32, offsets, parse_nifti, read_nifti};
use fvr_host::io::nrrd::Encoding::Raw;
use fvr_host::io::nrrd::{encode_nrrd, parse_nrrd, read_nrrd, Endian, IoError, SampleType};
use fvr_host::io::{detect, read_volume, Format};
use fvr_host::sources::datasets::{BRAINSMALL_DEN_GZ, BRAINSMALL_DIMS};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fvr-formats-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn gunzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Read;
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(bytes)
        .read_to_end(&mut out)
        .unwrap();
    out
}

/// The error's message, which must contain every needle.
fn expect_err(result: Result<Volume, IoError>, needles: &[&str]) -> String {
    let msg = match result {
        Ok(v) => panic!(
            "expected an error with {needles:?}, got a volume of {:?}",
            v.dims
        ),
        Err(e) => e.to_string(),
    };
    for n in needles {
        assert!(msg.contains(n), "`{n}` not in: {msg}");
    }
    msg
}

/// A gzip stream with its last `cut` bytes removed (CRC and size first).
fn truncate(mut bytes: Vec<u8>, cut: usize) -> Vec<u8> {
    bytes.truncate(bytes.len() - cut);
    bytes
}

/// A gzip stream with a run of its deflate data overwritten.
fn corrupt(mut bytes: Vec<u8>) -> Vec<u8> {
    let mid = bytes.len() / 2;
    for b in &mut bytes[mid..mid + 16] {
        *b ^= 0x5a;
    }
    bytes
}

fn ramp(n: usize) -> Vec<f32> {
    (0..n).map(|i| (i % 251) as f32 - 17.5).collect()
}

// ---------------------------------------------------------------- VolPack

#[test]
fn brainsmall_fixture_reads_with_its_header_sizes_and_every_byte() {
    let raw = gunzip(BRAINSMALL_DEN_GZ);
    assert_eq!(raw.len(), DEN_HEADER + 128 * 128 * 84);
    let vol = parse_den(BRAINSMALL_DEN_GZ).expect("brainsmall");
    assert_eq!(vol.dims, BRAINSMALL_DIMS);
    assert_eq!(vol.spacing, DEFAULT_SPACING);
    let expected: Vec<f32> = raw[DEN_HEADER..].iter().map(|&b| b as f32).collect();
    assert_eq!(vol.data, expected);
    // An MRI head, not a constant: background and tissue both present.
    let max = vol.data.iter().cloned().fold(0.0, f32::max);
    let zeros = vol.data.iter().filter(|&&v| v == 0.0).count();
    assert!(max > 100.0 && zeros > 1000, "max {max}, zeros {zeros}");
    // And the uncompressed form reads the same.
    assert_eq!(parse_den(&raw).expect("plain").data, vol.data);
}

#[test]
fn den_round_trips_in_both_byte_orders_and_from_files() {
    let dims = [5, 3, 2];
    let data: Vec<u8> = (0..30).map(|i| (i * 7) as u8).collect();
    let dir = temp_dir("den");
    for endian in [Endian::Little, Endian::Big] {
        let bytes = encode_den(dims, &data, endian);
        assert_eq!(bytes.len(), DEN_HEADER + 30);
        let vol = parse_den(&bytes).expect("den");
        assert_eq!(vol.dims, dims);
        assert_eq!(vol.data, data.iter().map(|&b| b as f32).collect::<Vec<_>>());
        assert_eq!(vol.get(4, 2, 1), data[4 + 5 * (2 + 3)] as f32);
        let path = dir.join(format!("v-{endian:?}.den.gz"));
        std::fs::write(&path, gzip(&bytes)).unwrap();
        assert_eq!(
            fvr_host::io::read_volume(&path).expect("den.gz file").data,
            vol.data
        );
        assert_eq!(read_volume(&path).expect("dispatch").data, vol.data);
    }
}

#[test]
fn den_bad_input_names_the_field() {
    let good = encode_den([4, 4, 4], &[9; 64], Endian::Little);
    let mut magic = good.clone();
    magic[0] = 7;
    expect_err(
        parse_den(&magic),
        &["map_version", "not a VolPack density file"],
    );
    expect_err(
        parse_den(&good[..40]),
        &["map_version", "ends after 40 bytes"],
    );
    expect_err(
        parse_den(&good[..good.len() - 5]),
        &["truncated", "expected 64", "found 59"],
    );
    let mut zero = good.clone();
    zero[50 + 2] = 0; // map_len[1] = 0
    expect_err(parse_den(&zero), &["map_len", "size 1 is 0"]);
    let mut negative = good.clone();
    negative[50..52].copy_from_slice(&(-4i16).to_le_bytes());
    expect_err(parse_den(&negative), &["map_len", "-4"]);
    let mut inconsistent = good.clone();
    inconsistent[58..62].copy_from_slice(&65i32.to_le_bytes());
    expect_err(parse_den(&inconsistent), &["map_length", "inconsistent"]);
    expect_err(parse_den(&truncate(gzip(&good), 6)), &["gzip"]);
    expect_err(
        parse_den(&corrupt(gzip(&encode_den(
            [40, 40, 40],
            &vec![3; 64000],
            Endian::Big,
        )))),
        &["gzip"],
    );
    expect_err(parse_den(&[]), &["map_version", "ends after 0 bytes"]);
}

// ---------------------------------------------------------------- NIfTI-1

#[test]
fn nifti_round_trips_with_spacing_scaling_and_either_byte_order() {
    let dims = [6, 5, 4];
    let data = ramp(120);
    for endian in [Endian::Little, Endian::Big] {
        let bytes = encode_nifti_f32(dims, [0.5, 0.75, 2.5], (1.0, 0.0), &data, endian);
        let vol = parse_nifti(&bytes).expect("nii");
        assert_eq!(vol.dims, dims);
        assert_eq!(vol.spacing, [0.5, 0.75, 2.5]);
        assert_eq!(vol.data, data);
        let scaled = encode_nifti_f32(dims, [1.0; 3], (2.0, -3.0), &data, endian);
        let vol = parse_nifti(&gzip(&scaled)).expect("nii.gz, scaled");
        let expected: Vec<f32> = data.iter().map(|&x| 2.0 * x - 3.0).collect();
        assert_eq!(vol.data, expected);
    }
    // A zero slope means no scaling (NIfTI-1).
    let unscaled = encode_nifti_f32(dims, [1.0; 3], (0.0, 5.0), &data, Endian::Little);
    assert_eq!(parse_nifti(&unscaled).unwrap().data, data);
}

#[test]
fn nifti_units_convert_to_millimetres() {
    let mut bytes = encode_nifti_f32(
        [2, 2, 2],
        [0.001, 0.002, 0.003],
        (1.0, 0.0),
        &[1.0; 8],
        Endian::Little,
    );
    bytes[offsets::XYZT_UNITS] = 1; // metre
    let s = parse_nifti(&bytes).unwrap().spacing;
    for (got, want) in s.iter().zip([1.0, 2.0, 3.0]) {
        assert!((got - want).abs() < 1e-6, "{s:?}");
    }
    bytes[offsets::XYZT_UNITS] = 3 | 8; // micron, seconds
    let s = parse_nifti(&bytes).unwrap().spacing;
    assert!((s[0] - 1e-6).abs() < 1e-12, "{s:?}");
    bytes[offsets::XYZT_UNITS] = 5;
    expect_err(parse_nifti(&bytes), &["xyzt_units", "5"]);
}

#[test]
fn nifti_header_and_image_pair_reads_from_files() {
    let dir = temp_dir("nifti-pair");
    let data = ramp(24);
    let mut bytes = encode_nifti_f32(
        [4, 3, 2],
        [1.0, 2.0, 3.0],
        (1.0, 0.0),
        &data,
        Endian::Little,
    );
    bytes[offsets::MAGIC..offsets::MAGIC + 4].copy_from_slice(b"ni1\0");
    bytes[offsets::VOX_OFFSET..offsets::VOX_OFFSET + 4].copy_from_slice(&0f32.to_le_bytes());
    std::fs::write(dir.join("pair.hdr"), &bytes[..348]).unwrap();
    let err = read_nifti(&dir.join("pair.hdr")).unwrap_err().to_string();
    assert!(err.contains("no .img or .img.gz"), "{err}");
    std::fs::write(dir.join("pair.img.gz"), gzip(&bytes[352..])).unwrap();
    let vol = read_volume(&dir.join("pair.hdr")).expect("pair");
    assert_eq!(
        (vol.dims, vol.data, vol.spacing),
        ([4, 3, 2], data, [1.0, 2.0, 3.0])
    );
    expect_err(parse_nifti(&bytes), &["ni1", "separate .img"]);
}

fn nifti_with(edit: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let mut bytes = encode_nifti_f32([4, 4, 4], [1.0; 3], (1.0, 0.0), &[1.0; 64], Endian::Little);
    edit(&mut bytes);
    bytes
}

fn put_i16(bytes: &mut [u8], at: usize, v: i16) {
    bytes[at..at + 2].copy_from_slice(&v.to_le_bytes());
}

fn put_f32(bytes: &mut [u8], at: usize, v: f32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

#[test]
fn nifti_bad_input_names_the_field() {
    let magic = nifti_with(|b| b[offsets::MAGIC] = b'x');
    expect_err(parse_nifti(&magic), &["magic", "not a NIfTI-1 file"]);
    let v2 = nifti_with(|b| b[..4].copy_from_slice(&540i32.to_le_bytes()));
    expect_err(parse_nifti(&v2), &["NIfTI-2"]);
    expect_err(
        parse_nifti(&nifti_with(|b| b.truncate(200))),
        &["sizeof_hdr", "ends after 200 bytes"],
    );
    expect_err(
        parse_nifti(&nifti_with(|b| b.truncate(352 + 100))),
        &["truncated", "expected 256", "found 100"],
    );
    expect_err(
        parse_nifti(&nifti_with(|b| put_i16(b, offsets::DIM + 4, 0))),
        &["`dim`", "dim[2] is 0"],
    );
    expect_err(
        parse_nifti(&nifti_with(|b| put_i16(b, offsets::DIM + 2, -3))),
        &["`dim`", "-3"],
    );
    expect_err(
        parse_nifti(&nifti_with(|b| put_i16(b, offsets::DIM, 0))),
        &["dim[0]", "is 0"],
    );
    // 8 and 256 are each other's byte swap: the order comes from sizeof_hdr.
    for rank in [8, 256, -1] {
        expect_err(
            parse_nifti(&nifti_with(|b| put_i16(b, offsets::DIM, rank))),
            &["dim[0]", &format!("is {rank};")],
        );
    }
    let four_d = nifti_with(|b| {
        put_i16(b, offsets::DIM, 4);
        put_i16(b, offsets::DIM + 8, 3);
    });
    expect_err(
        parse_nifti(&four_d),
        &["dim[4] is 3", "3 volumes", "single 3D volume"],
    );
    let one_4d = nifti_with(|b| put_i16(b, offsets::DIM, 4));
    assert_eq!(
        parse_nifti(&one_4d).expect("4D with one volume").dims,
        [4, 4, 4]
    );
    expect_err(
        parse_nifti(&nifti_with(|b| put_i16(b, offsets::DATATYPE, 32))),
        &["datatype", "Complex64", "not supported"],
    );
    expect_err(
        parse_nifti(&nifti_with(|b| put_i16(b, offsets::DATATYPE, 9999))),
        &["datatype", "9999"],
    );
    for (bad, word) in [
        (0.0, "zero"),
        (-1.0, "negative"),
        (f32::NAN, "not a number"),
        (f32::INFINITY, "infinite"),
    ] {
        let bytes = nifti_with(|b| put_f32(b, offsets::PIXDIM + 8, bad));
        expect_err(parse_nifti(&bytes), &["pixdim", "pixdim[2]", word]);
    }
    expect_err(
        parse_nifti(&nifti_with(|b| put_f32(b, offsets::VOX_OFFSET, 100.0))),
        &["vox_offset", "100"],
    );
    expect_err(
        parse_nifti(&nifti_with(|b| put_f32(b, offsets::VOX_OFFSET, 1e9))),
        &["vox_offset", "file ends"],
    );
    expect_err(
        parse_nifti(&nifti_with(|b| {
            put_f32(b, offsets::SCL_SLOPE, f32::INFINITY)
        })),
        &["scl_slope", "finite"],
    );
    expect_err(
        parse_nifti(&nifti_with(|b| put_f32(b, offsets::SCL_INTER, f32::NAN))),
        &["scl_inter"],
    );
    let overflow = nifti_with(|b| put_f32(b, offsets::SCL_SLOPE, 1e38));
    let big = encode_nifti_f32(
        [2, 1, 1],
        [1.0; 3],
        (1e38, 0.0),
        &[1.0, 1e3],
        Endian::Little,
    );
    assert!(parse_nifti(&overflow).is_ok(), "1e38 x 1 fits in f32");
    expect_err(
        parse_nifti(&big),
        &["scl_slope", "voxel (1, 0, 0)", "beyond f32"],
    );
    let nan_voxel = encode_nifti_f32(
        [2, 1, 1],
        [1.0; 3],
        (1.0, 0.0),
        &[1.0, f32::NAN],
        Endian::Little,
    );
    expect_err(parse_nifti(&nan_voxel), &["non-finite", "voxel (1, 0, 0)"]);
    let gz = gzip(&nifti_with(|_| {}));
    expect_err(parse_nifti(&truncate(gz.clone(), 4)), &["gzip"]);
    expect_err(parse_nifti(&corrupt(gz)), &["gzip"]);
}

// -------------------------------------------------------------- InVesalius

#[test]
fn inv3_round_trips_shape_spacing_and_samples() {
    let dims = [5, 4, 3];
    let data: Vec<i16> = (0..60).map(|i| (i * 97 - 1024) as i16).collect();
    let bytes = encode_inv3_i16(dims, [0.957_031_2, 0.957_031_2, 1.5], &data);
    let vol = parse_inv3(&bytes).expect("inv3");
    assert_eq!(vol.dims, dims);
    assert_eq!(vol.spacing, [0.957_031_2, 0.957_031_2, 1.5]);
    assert_eq!(vol.data, data.iter().map(|&v| v as f32).collect::<Vec<_>>());
    // x fastest: the plist's shape is [z, y, x].
    assert_eq!(vol.get(4, 0, 0), data[4] as f32);
    assert_eq!(vol.get(0, 1, 0), data[5] as f32);
    // The matrix member may come before main.plist, with other members around.
    let plist = main_plist_text(dims, "int16", [1.0, 2.0, 3.0]);
    let matrix: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    let reordered = encode_archive(&[
        ("mask_0.dat", &[1, 2, 3]),
        ("matrix.dat", &matrix),
        ("main.plist", plist.as_bytes()),
    ]);
    let vol = parse_inv3(&reordered).expect("matrix first");
    assert_eq!((vol.data.len(), vol.spacing), (60, [1.0, 2.0, 3.0]));
}

fn inv3_with_plist(plist: &str, matrix: &[u8]) -> Vec<u8> {
    encode_archive(&[("main.plist", plist.as_bytes()), ("matrix.dat", matrix)])
}

#[test]
fn inv3_bad_input_names_the_field() {
    let matrix = vec![0u8; 2 * 60];
    let plist = main_plist_text([5, 4, 3], "int16", [1.0, 1.0, 1.0]);
    expect_err(
        parse_inv3(&encode_archive(&[("matrix.dat", &matrix)])),
        &["no main.plist"],
    );
    expect_err(
        parse_inv3(&inv3_with_plist(&plist, &matrix[..100])),
        &["matrix.dat", "holds 100 bytes", "needs 120"],
    );
    let renamed = encode_archive(&[("main.plist", plist.as_bytes()), ("other.dat", &matrix)]);
    expect_err(
        parse_inv3(&renamed),
        &["matrix.filename", "not in the archive"],
    );
    let dtype = main_plist_text([5, 4, 3], "complex128", [1.0; 3]);
    expect_err(
        parse_inv3(&inv3_with_plist(&dtype, &matrix)),
        &["matrix.dtype", "complex128"],
    );
    let zero = main_plist_text([5, 0, 3], "int16", [1.0; 3]);
    expect_err(
        parse_inv3(&inv3_with_plist(&zero, &matrix)),
        &["matrix.shape", "at least 1"],
    );
    let huge = main_plist_text([1 << 30, 1 << 30, 1 << 30], "int16", [1.0; 3]);
    expect_err(
        parse_inv3(&inv3_with_plist(&huge, &matrix)),
        &["matrix.shape", "overflow"],
    );
    for (s, word) in [
        (0.0, "zero"),
        (-1.5, "negative"),
        (f64::NAN, "not a number"),
    ] {
        let p = main_plist_text([5, 4, 3], "int16", [1.0, s, 1.0]);
        expect_err(
            parse_inv3(&inv3_with_plist(&p, &matrix)),
            &["spacing", word],
        );
    }
    let broken = plist.replace("</dict>\n</plist>", "");
    expect_err(
        parse_inv3(&inv3_with_plist(&broken, &matrix)),
        &["main.plist", "xml"],
    );
    let missing = plist.replace("spacing", "spacings");
    expect_err(
        parse_inv3(&inv3_with_plist(&missing, &matrix)),
        &["`spacing`", "missing"],
    );
    let good = inv3_with_plist(&plist, &matrix);
    expect_err(parse_inv3(&truncate(good.clone(), 200)), &["archive"]);
    expect_err(parse_inv3(&corrupt(good)), &["InVesalius"]);
    expect_err(parse_inv3(b"not a tar at all"), &["archive"]);
}

// -------------------------------------------------------------------- NRRD

fn nrrd_header(fields: &str) -> String {
    format!("NRRD0004\n{fields}")
}

#[test]
fn nrrd_detached_headers_find_their_data_file() {
    let dir = temp_dir("nhdr");
    let data: Vec<u8> = (0..24).collect();
    std::fs::write(dir.join("vol.raw"), &data).unwrap();
    std::fs::write(dir.join("vol.raw.gz"), gzip(&data)).unwrap();
    let fields = "type: uchar\ndimension: 3\nsizes: 4 3 2\nspacings: 0.5 0.5 2\n";
    for (name, extra) in [
        ("a.nhdr", "encoding: raw\ndata file: vol.raw\n"),
        ("b.nhdr", "encoding: gzip\ndatafile: ./vol.raw.gz\n"),
    ] {
        std::fs::write(dir.join(name), nrrd_header(&format!("{fields}{extra}"))).unwrap();
        let vol = read_volume(&dir.join(name)).expect(name);
        assert_eq!(vol.dims, [4, 3, 2]);
        assert_eq!(vol.spacing, [0.5, 0.5, 2.0]);
        assert_eq!(vol.data, data.iter().map(|&b| b as f32).collect::<Vec<_>>());
    }
    let absolute = format!(
        "{fields}encoding: raw\ndata file: {}\n\n",
        dir.join("vol.raw").display()
    );
    std::fs::write(dir.join("c.nhdr"), nrrd_header(&absolute)).unwrap();
    assert_eq!(
        read_nrrd(&dir.join("c.nhdr")).expect("absolute").data.len(),
        24
    );
    // The error of a header `name` whose samples are in `data_file`.
    let detached_error = |name: &str, data_file: &str| {
        let text = format!("{fields}encoding: raw\ndata file: {data_file}\n");
        std::fs::write(dir.join(name), nrrd_header(&text)).unwrap();
        read_nrrd(&dir.join(name)).unwrap_err().to_string()
    };
    let e = detached_error("d.nhdr", "gone.raw");
    assert!(
        e.contains("d.nhdr") && e.contains("gone.raw") && e.contains("No such file"),
        "{e}"
    );
    let e = detached_error("e.nhdr", "LIST");
    assert!(
        e.contains("`data file`") && e.contains("several data files"),
        "{e}"
    );
    std::fs::write(dir.join("short.raw"), &data[..20]).unwrap();
    let e = detached_error("f.nhdr", "short.raw");
    assert!(
        e.contains("short.raw") && e.contains("expected 24") && e.contains("found 20"),
        "{e}"
    );
}

#[test]
fn nrrd_spacing_comes_from_spacings_or_space_directions() {
    let base = "type: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n";
    let parse = |extra: &str| parse_nrrd(format!("NRRD0004\n{base}{extra}\n\x07").as_bytes());
    assert_eq!(parse("").unwrap().spacing, DEFAULT_SPACING);
    assert_eq!(
        parse("spacings: 0.25 1 4\n").unwrap().spacing,
        [0.25, 1.0, 4.0]
    );
    let oblique = parse("space: RAS\nspace directions: (0,0.6,0.8) (2,0,0) (0,0,-3)\n").unwrap();
    assert_eq!(oblique.spacing, [1.0, 2.0, 3.0]);
    for (bad, needles) in [
        ("spacings: 1 0 1\n", vec!["`spacings`", "zero"]),
        ("spacings: 1 -2 1\n", vec!["`spacings`", "negative"]),
        ("spacings: nan 1 1\n", vec!["`spacings`", "not a number"]),
        ("spacings: 1 1\n", vec!["`spacings`", "expected 3 numbers"]),
        (
            "space directions: (1,0,0) (0,0,0) (0,0,1)\n",
            vec!["`space directions`", "axis 1", "non-zero"],
        ),
        (
            "space directions: (1,0,0) (0,1,nan) (0,0,1)\n",
            vec!["`space directions`", "axis 1"],
        ),
        (
            "space directions: (1,0,0) (0,1,0)\n",
            vec!["`space directions`", "expected 3 vectors"],
        ),
        (
            "space directions: (1,0,0) (0,1,0) [0,0,1]\n",
            vec!["`space directions`", "expected vectors"],
        ),
    ] {
        let msg = match parse(bad) {
            Ok(v) => panic!("{bad}: got spacing {:?}", v.spacing),
            Err(e) => e.to_string(),
        };
        for n in needles {
            assert!(msg.contains(n), "{bad}: `{n}` not in {msg}");
        }
    }
}

#[test]
fn sizes_whose_product_overflows_are_refused_before_allocating() {
    let big = usize::MAX / 2;
    let header = format!(
        "NRRD0004\ntype: short\ndimension: 3\nsizes: {big} 4 1\nendian: little\nencoding: raw\n\n"
    );
    let msg = parse_nrrd(header.as_bytes()).unwrap_err().to_string();
    assert!(
        msg.contains("`sizes`") && msg.contains("overflows"),
        "{msg}"
    );
    let raw = fvr_host::io::nrrd::parse_raw(&[0; 8], [big, 3, 1], SampleType::U8, Endian::Little);
    assert!(raw.unwrap_err().to_string().contains("overflows"));
    // A header that claims a large volume but holds a few bytes fails on
    // the missing bytes, not on memory.
    let claims = encode_nrrd(&[2], SampleType::U8, Raw, Endian::Little, &[1.0, 2.0]);
    let text = String::from_utf8_lossy(&claims).replace("sizes: 2", "sizes: 600000000");
    let msg = parse_nrrd(text.as_bytes()).unwrap_err().to_string();
    assert!(
        msg.contains("truncated") || msg.contains("too large"),
        "{msg}"
    );
}

// ----------------------------------------------------------------- Dispatch

#[test]
fn formats_are_detected_by_magic_before_extension() {
    let dir = temp_dir("detect");
    let nrrd = encode_nrrd(&[2, 2, 2], SampleType::U8, Raw, Endian::Little, &[1.0; 8]);
    let nii = encode_nifti_f32([2, 2, 2], [1.0; 3], (1.0, 0.0), &[1.0; 8], Endian::Little);
    let den = encode_den([2, 2, 2], &[1; 8], Endian::Little);
    let inv3 = encode_inv3_i16([2, 2, 2], [1.0; 3], &[1; 8]);
    let cases: [(&str, Vec<u8>, Format); 6] = [
        ("a.nrrd", nrrd.clone(), Format::Nrrd),
        ("misnamed.nii", nrrd, Format::Nrrd),
        ("b.nii.gz", gzip(&nii), Format::Nifti),
        ("noext", den.clone(), Format::Den),
        ("c.den.gz", gzip(&den), Format::Den),
        ("d.inv3", inv3, Format::Inv3),
    ];
    for (name, bytes, format) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        assert_eq!(detect(&path).expect(name), format, "{name}");
        let vol = read_volume(&path).expect(name);
        assert_eq!((vol.dims, vol.data), ([2, 2, 2], vec![1.0; 8]), "{name}");
    }
    for (name, bytes) in [
        ("junk.bin", b"hello world, not a volume".to_vec()),
        ("empty", Vec::new()),
        ("z.gz", gzip(b"plain text")),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let msg = read_volume(&path).unwrap_err().to_string();
        assert!(
            msg.contains("unknown volume format") && msg.contains(name) && msg.contains("NIfTI-1"),
            "{msg}"
        );
    }
    // A known extension with foreign content: the reader names its magic.
    let path = dir.join("fake.nii");
    std::fs::write(&path, b"not a header").unwrap();
    let msg = read_volume(&path).unwrap_err().to_string();
    assert!(
        msg.contains("fake.nii") && msg.contains("NIfTI-1 header"),
        "{msg}"
    );
}

#[test]
fn named_volumes_load_through_the_scene() {
    let brain = fvr_host::sources::load_volume("brainsmall", None).expect("embedded");
    assert_eq!(brain.dims, BRAINSMALL_DIMS);
    let msg = fvr_host::sources::load_volume("no-such-thing", None).unwrap_err();
    assert!(
        msg.contains("ct-head") && msg.contains("NIfTI-1") && msg.contains("shepp-logan"),
        "{msg}"
    );
}

#[test]
fn spacing_checks_reject_zero_negative_and_non_finite() {
    assert_eq!(check_spacing([0.5, 1.0, 2.0]), Ok([0.5, 1.0, 2.0]));
    for (bad, word) in [
        (0.0, "zero"),
        (-0.5, "negative"),
        (f64::NAN, "not a number"),
        (f64::INFINITY, "infinite"),
    ] {
        let e = check_spacing([1.0, 1.0, bad]).unwrap_err();
        assert_eq!(e.axis, 2);
        assert!(e.to_string().contains(word), "{e}");
        assert!(Volume::zeros([1, 1, 1])
            .with_spacing([bad, 1.0, 1.0])
            .is_err());
    }
}

/// The real CT head (GPL-2, never committed): `scripts/test-all.sh` installs
/// it first, so this test fails rather than skips when it is missing.
#[test]
fn ct_head_reads_with_its_shape_spacing_and_hounsfield_range() {
    let path = fvr_host::sources::datasets::ct_head_path()
        .unwrap_or_else(|e| panic!("{e} (scripts/test-all.sh installs it)"));
    let vol = read_volume(Path::new(&path)).expect("CT head");
    assert_eq!(vol.dims, fvr_host::sources::datasets::CT_HEAD_DIMS);
    assert_eq!(vol.spacing, fvr_host::sources::datasets::CT_HEAD_SPACING);
    let min = vol.data.iter().cloned().fold(f32::INFINITY, f32::min);
    let max = vol.data.iter().cloned().fold(f32::NEG_INFINITY, f32::max);
    // main.plist's scalar_range is [-1024, 3033]; air is -1024 HU.
    assert_eq!(min, -1024.0);
    assert!((1000.0..=3033.0).contains(&max), "max {max}");
    let loaded = fvr_host::sources::load_volume("ct-head", None).expect("by name");
    assert_eq!(loaded.data, vol.data);
}

#[test]
fn background_becomes_zero_and_lower_values_clamp() {
    let mut v = Volume::new([4, 1, 1], vec![-1024.0, -1000.0, 0.0, 2000.0]);
    v.subtract_background(-1024.0).unwrap();
    assert_eq!(v.data, vec![0.0, 24.0, 1024.0, 3024.0]);
    v.subtract_background(100.0).unwrap();
    assert_eq!(v.data, vec![0.0, 0.0, 924.0, 2924.0]);
    assert!(v.subtract_background(f64::NAN).is_err());
}

/// Brute force: the sample of `v` (file order) at the world position `q`
/// after mapping file axis `a` to world axis `world[a]`, reversed by `flip[a]`.
fn at_world(v: &[f32], dims: [usize; 3], world: [usize; 3], flip: [bool; 3], q: [usize; 3]) -> f32 {
    let p: [usize; 3] = std::array::from_fn(|a| {
        let c = q[world[a]];
        if flip[a] {
            dims[a] - 1 - c
        } else {
            c
        }
    });
    v[p[0] + dims[0] * (p[1] + dims[1] * p[2])]
}

fn check_reoriented(
    vol: &Volume,
    data: &[f32],
    dims: [usize; 3],
    spacing: [f64; 3],
    world: [usize; 3],
    flip: [bool; 3],
) {
    let mut want_dims = [0; 3];
    let mut want_spacing = [0.0; 3];
    for a in 0..3 {
        want_dims[world[a]] = dims[a];
        want_spacing[world[a]] = spacing[a];
    }
    assert_eq!((vol.dims, vol.spacing), (want_dims, want_spacing));
    for z in 0..want_dims[2] {
        for y in 0..want_dims[1] {
            for x in 0..want_dims[0] {
                assert_eq!(
                    vol.data[x + want_dims[0] * (y + want_dims[1] * z)],
                    at_world(data, dims, world, flip, [x, y, z]),
                    "at {x},{y},{z}"
                );
            }
        }
    }
}

/// The sform wins over the qform and is followed to the closest RAS order:
/// a file whose i runs to the left, j up and k forward (slightly oblique)
/// comes out with x right, y anterior, z superior.
#[test]
fn nifti_sform_reorients_to_closest_ras() {
    let (dims, spacing) = ([4, 3, 2], [2.0, 1.0, 3.0]);
    let data = ramp(24);
    let bytes = nifti_with_dims(dims, spacing, &data, |b| {
        put_i16(b, offsets::SFORM_CODE, 2);
        put_i16(b, offsets::QFORM_CODE, 1); // ignored: the sform wins
        put_f32(b, offsets::QUATERN_B, 1.0); // a 180° qform that would flip y and z
        let rows = [
            [-2.0, 0.0, 0.1, 10.0],
            [0.0, 0.05, 3.0, -4.0],
            [0.1, 1.0, 0.0, 7.0],
        ];
        for (r, row) in rows.iter().enumerate() {
            for (c, &v) in row.iter().enumerate() {
                put_f32(b, offsets::SROW_X + 16 * r + 4 * c, v);
            }
        }
    });
    let vol = parse_nifti(&bytes).unwrap();
    check_reoriented(&vol, &data, dims, spacing, [0, 2, 1], [true, false, false]);
}

/// Without an sform, the qform's quaternion and qfac give the order: 180°
/// about z flips x and y, and qfac −1 flips z.
#[test]
fn nifti_qform_reorients_with_quaternion_and_qfac() {
    let (dims, spacing) = ([4, 3, 2], [1.0, 1.0, 1.0]);
    let data = ramp(24);
    let bytes = nifti_with_dims(dims, spacing, &data, |b| {
        put_i16(b, offsets::QFORM_CODE, 1);
        put_f32(b, offsets::QUATERN_B + 8, 1.0); // quatern_d
        put_f32(b, offsets::PIXDIM, -1.0); // qfac
    });
    let vol = parse_nifti(&bytes).unwrap();
    check_reoriented(&vol, &data, dims, spacing, [0, 1, 2], [true, true, true]);
    // Codes 0 keep the file's order, whatever the fields hold.
    let kept = nifti_with_dims(dims, spacing, &data, |b| {
        put_f32(b, offsets::QUATERN_B + 8, 1.0);
        put_f32(b, offsets::SROW_X, -1.0);
    });
    let vol = parse_nifti(&kept).unwrap();
    assert_eq!((vol.dims, &vol.data), (dims, &data));
}

#[test]
fn nifti_bad_orientations_are_named() {
    let data = ramp(24);
    let zero_column = nifti_with_dims([4, 3, 2], [1.0; 3], &data, |b| {
        put_i16(b, offsets::SFORM_CODE, 1);
        put_f32(b, offsets::SROW_X, 1.0);
        put_f32(b, offsets::SROW_X + 16 + 4, 1.0); // srow_y: j; nothing for k
    });
    expect_err(
        parse_nifti(&zero_column),
        &["srow_x", "sform", "zero or non-finite column"],
    );
    let not_unit = nifti_with_dims([4, 3, 2], [1.0; 3], &data, |b| {
        put_i16(b, offsets::QFORM_CODE, 1);
        for k in 0..3 {
            put_f32(b, offsets::QUATERN_B + 4 * k, 0.9);
        }
    });
    expect_err(parse_nifti(&not_unit), &["quatern_b", "unit quaternion"]);
    // Rank 1: every index axis maps to the same world direction.
    let rank_one = nifti_with_dims([4, 3, 2], [1.0; 3], &data, |b| {
        put_i16(b, offsets::SFORM_CODE, 1);
        for c in 0..3 {
            put_f32(b, offsets::SROW_X + 4 * c, 1.0);
        }
    });
    expect_err(parse_nifti(&rank_one), &["srow_x", "singular"]);
}

#[test]
fn nrrd_degenerate_geometry_and_non_spatial_kinds_are_named() {
    let header = |extra: &str| {
        format!("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n{extra}\n")
            .into_bytes()
            .into_iter()
            .chain([1u8; 8])
            .collect::<Vec<u8>>()
    };
    let repeated = header("space directions: (1,0,0) (1,0,0) (0,0,1)\n");
    expect_err(parse_nrrd(&repeated), &["space directions", "parallel"]);
    let singular = header("space directions: (1,0,0) (0,1,0) (1,1,0)\n");
    expect_err(parse_nrrd(&singular), &["space directions", "parallel"]);
    let rgb = header("kinds: RGB-color domain domain\n");
    expect_err(parse_nrrd(&rgb), &["kinds", "RGB-color"]);
    let fine = header("kinds: domain domain domain\nspace directions: (2,0,0) (0,1,0) (0,0,3)\n");
    assert_eq!(parse_nrrd(&fine).unwrap().spacing, [2.0, 1.0, 3.0]);
}

fn nifti_with_dims(
    dims: [usize; 3],
    spacing: [f64; 3],
    data: &[f32],
    edit: impl FnOnce(&mut Vec<u8>),
) -> Vec<u8> {
    let mut bytes = encode_nifti_f32(dims, spacing, (1.0, 0.0), data, Endian::Little);
    edit(&mut bytes);
    bytes
}

/// A `main.plist` nested deeper than the limit is refused before the value
/// is built, not a stack overflow; the limit itself is accepted.
#[test]
fn deep_plist_nesting_is_refused_not_a_stack_overflow() {
    use fvr_host::io::inv3::{parse_plist, MAX_PLIST_DEPTH};
    let deep = "<array>".repeat(100_000);
    let e = parse_plist(&format!("<plist>{deep}")).unwrap_err();
    assert!(e.contains("nested deeper than 64"), "{e}");
    let n = MAX_PLIST_DEPTH;
    let ok = format!(
        "<plist>{}{}</plist>",
        "<array>".repeat(n),
        "</array>".repeat(n)
    );
    assert!(parse_plist(&ok).is_ok());
}
