//! Unit tests of NRRD and raw volume I/O.

use super::*;

const ALL_TYPES: [SampleType; 8] = [
    SampleType::U8,
    SampleType::I8,
    SampleType::U16,
    SampleType::I16,
    SampleType::U32,
    SampleType::I32,
    SampleType::F32,
    SampleType::F64,
];

/// A NRRD file from header field lines (each ending in `\n`) and data bytes.
fn nrrd(fields: &str, data: &[u8]) -> Vec<u8> {
    let mut out = format!("NRRD0004\n{fields}\n").into_bytes();
    out.extend_from_slice(data);
    out
}

fn gzip_bytes(bytes: &[u8]) -> Vec<u8> {
    super::gzip(bytes)
}

fn parse_err(bytes: &[u8]) -> IoError {
    match parse_nrrd(bytes) {
        Ok(v) => panic!("expected an error, got a volume of dims {:?}", v.dims),
        Err(e) => e,
    }
}

fn parse_msg(bytes: &[u8]) -> String {
    parse_err(bytes).to_string()
}

/// Values exactly representable in `ty`, including its extremes.
fn values_for(ty: SampleType) -> Vec<f64> {
    match ty {
        SampleType::U8 => vec![0.0, 1.0, 127.0, 128.0, 255.0],
        SampleType::I8 => vec![-128.0, -1.0, 0.0, 1.0, 127.0],
        SampleType::U16 => vec![0.0, 1.0, 256.0, 32768.0, 65535.0],
        SampleType::I16 => vec![-32768.0, -256.0, -1.0, 0.0, 32767.0],
        SampleType::U32 => vec![0.0, 1.0, 65536.0, 16_777_216.0, u32::MAX as f64],
        SampleType::I32 => vec![i32::MIN as f64, -65536.0, -1.0, 0.0, i32::MAX as f64],
        SampleType::F32 => vec![-f32::MAX as f64, -1.5, 0.0, 1e-30, f32::MAX as f64],
        SampleType::F64 => vec![-f32::MAX as f64, -2.25, 0.0, 1e-40, 3.0e38],
    }
}

/// Expected `f32` sample for value `v` of type `ty`.
fn expected_f32(ty: SampleType, v: f64) -> f32 {
    match ty {
        SampleType::U32 => v as u32 as f32,
        SampleType::I32 => v as i32 as f32,
        _ => v as f32,
    }
}

#[test]
fn round_trip_every_type_encoding_and_endian() {
    let sizes = [3, 2, 2];
    for ty in ALL_TYPES {
        let base = values_for(ty);
        let values: Vec<f64> = (0..12).map(|n| base[n % base.len()]).collect();
        for encoding in [Encoding::Raw, Encoding::Gzip] {
            for endian in [Endian::Little, Endian::Big] {
                let bytes = encode_nrrd(&sizes, ty, encoding, endian, &values);
                let vol = parse_nrrd(&bytes)
                    .unwrap_or_else(|e| panic!("{ty:?} {encoding:?} {endian:?}: {e}"));
                assert_eq!(vol.dims, [3, 2, 2]);
                let expected: Vec<f32> = values.iter().map(|&v| expected_f32(ty, v)).collect();
                assert_eq!(vol.data, expected, "{ty:?} {encoding:?} {endian:?}");
            }
        }
    }
}

#[test]
fn u32_max_becomes_2_pow_32_in_f32() {
    let bytes = encode_nrrd(
        &[1],
        SampleType::U32,
        Encoding::Raw,
        Endian::Big,
        &[u32::MAX as f64],
    );
    let vol = parse_nrrd(&bytes).expect("valid file");
    assert_eq!(vol.data, vec![u32::MAX as f32]);
    assert_eq!(vol.data[0], 4_294_967_296.0);
}

#[test]
fn dimensions_one_and_two_are_padded() {
    let one = encode_nrrd(
        &[4],
        SampleType::U8,
        Encoding::Raw,
        Endian::Little,
        &[1.0, 2.0, 3.0, 4.0],
    );
    assert_eq!(parse_nrrd(&one).expect("1D").dims, [4, 1, 1]);
    let two = encode_nrrd(
        &[2, 3],
        SampleType::I16,
        Encoding::Gzip,
        Endian::Big,
        &[0.0; 6],
    );
    let vol = parse_nrrd(&two).expect("2D");
    assert_eq!(vol.dims, [2, 3, 1]);
    assert_eq!(vol.get(1, 2, 0), 0.0);
}

#[test]
fn dimension_four_is_rejected() {
    let bytes = nrrd(
        "type: uchar\ndimension: 4\nsizes: 1 1 1 1\nencoding: raw\n",
        &[0],
    );
    let msg = parse_msg(&bytes);
    assert!(msg.contains("`dimension`") && msg.contains("4"), "{msg}");
    let zero = nrrd("type: uchar\ndimension: 0\nsizes: \nencoding: raw\n", &[0]);
    assert!(parse_msg(&zero).contains("`dimension`"));
}

#[test]
fn header_comments_pairs_crlf_skips_and_ignored_fields() {
    let mut bytes = b"NRRD0001\r\n# a comment: with colon\r\ncontent: my:=volume\r\n\
        Type: unsigned short int\r\nDIMENSION: 3\r\nspace: left-posterior-superior\r\n\
        sizes:   2  1   1 \r\nspace directions: (1,0,0) (0,1,0) (0,0,1)\r\nkinds: domain domain domain\r\n\
        centers: cell cell cell\r\nspacings: 1 1 1\r\nmodality:=DWMRI\r\nweird key: x:=y\r\n\
        endian: big\r\nencoding: raw\r\nline skip: 2\r\nbyteskip: 3\r\nempty:\r\n\r\n"
        .to_vec();
    bytes.extend_from_slice(b"skip me\nand me\n\xff\xff\xff\x01\x02\xfe\xff");
    let vol = parse_nrrd(&bytes).expect("valid header");
    assert_eq!(vol.dims, [2, 1, 1]);
    assert_eq!(vol.data, vec![258.0, 65279.0]);
}

#[test]
fn endian_is_ignored_for_one_byte_types_but_required_otherwise() {
    let ok = nrrd(
        "type: char\ndimension: 1\nsizes: 2\nencoding: raw\nendian: sideways\n",
        &[0xff, 5],
    );
    assert_eq!(
        parse_nrrd(&ok).expect("endian ignored").data,
        vec![-1.0, 5.0]
    );
    let missing = nrrd(
        "type: short\ndimension: 1\nsizes: 1\nencoding: raw\n",
        &[0, 0],
    );
    let msg = parse_msg(&missing);
    assert!(msg.contains("`endian`") && msg.contains("missing"), "{msg}");
    let bad = nrrd(
        "type: short\ndimension: 1\nsizes: 1\nencoding: raw\nendian: middle\n",
        &[0, 0],
    );
    assert!(parse_msg(&bad).contains("`endian`"));
}

#[test]
fn all_nrrd_type_synonyms_are_understood() {
    let cases: [(&[&str], SampleType); 8] = [
        (&["signed char", "int8", "int8_t", "char"], SampleType::I8),
        (
            &["uchar", "unsigned char", "uint8", "uint8_t"],
            SampleType::U8,
        ),
        (
            &[
                "short",
                "short int",
                "signed short",
                "signed short int",
                "int16",
                "int16_t",
            ],
            SampleType::I16,
        ),
        (
            &[
                "ushort",
                "unsigned short",
                "unsigned short int",
                "uint16",
                "uint16_t",
            ],
            SampleType::U16,
        ),
        (&["int", "signed int", "int32", "int32_t"], SampleType::I32),
        (
            &["uint", "unsigned int", "uint32", "uint32_t"],
            SampleType::U32,
        ),
        (&["float"], SampleType::F32),
        (&["double"], SampleType::F64),
    ];
    for (names, ty) in cases {
        for name in names {
            assert_eq!(SampleType::from_nrrd_field(name).expect(name), ty);
            assert_eq!(name.parse::<SampleType>().expect(name), ty);
            let fields =
                format!("type: {name}\ndimension: 1\nsizes: 1\nendian: little\nencoding: raw\n");
            let data = vec![0u8; ty.size_bytes()];
            assert_eq!(
                parse_nrrd(&nrrd(&fields, &data)).expect(name).data,
                vec![0.0]
            );
        }
    }
}

#[test]
fn sample_type_from_str_short_forms_and_errors() {
    let short = ["u8", "i8", "u16", "i16", "u32", "i32", "f32", "f64"];
    for (name, ty) in short.iter().zip(ALL_TYPES) {
        assert_eq!(name.parse::<SampleType>().expect(name), ty);
    }
    assert_eq!(
        " Unsigned   SHORT ".parse::<SampleType>().expect("spaces"),
        SampleType::U16
    );
    let err = "quaternion".parse::<SampleType>().expect_err("unknown");
    assert!(err.to_string().contains("`quaternion`"), "{err}");
}

#[test]
fn unknown_and_unsupported_types_name_the_field_and_value() {
    let msg = parse_msg(&nrrd(
        "type: complex\ndimension: 1\nsizes: 1\nencoding: raw\n",
        &[0],
    ));
    assert!(
        msg.contains("NRRD field `type`") && msg.contains("`complex`"),
        "{msg}"
    );
    let msg = parse_msg(&nrrd(
        "type: int64\ndimension: 1\nsizes: 1\nendian: little\nencoding: raw\n",
        &[0; 8],
    ));
    assert!(
        msg.contains("`type`") && msg.contains("`int64`") && msg.contains("not supported"),
        "{msg}"
    );
}

#[test]
fn unsupported_encodings_are_named() {
    for enc in ["ascii", "hex", "bzip2", "txt", "text", "zstd"] {
        let fields = format!("type: uchar\ndimension: 1\nsizes: 1\nencoding: {enc}\n");
        let msg = parse_msg(&nrrd(&fields, b"1\n"));
        assert!(
            msg.contains("`encoding`") && msg.contains(&format!("`{enc}`")),
            "{msg}"
        );
        assert!(msg.contains("not supported"), "{msg}");
    }
    let gz = nrrd(
        "type: uchar\ndimension: 1\nsizes: 2\nencoding: gz\n",
        &gzip_bytes(&[7, 9]),
    );
    assert_eq!(parse_nrrd(&gz).expect("gz synonym").data, vec![7.0, 9.0]);
}

#[test]
fn detached_data_files_need_the_header_path() {
    for key in ["data file", "datafile"] {
        let fields =
            format!("type: uchar\ndimension: 1\nsizes: 1\nencoding: raw\n{key}: vol.raw\n");
        let mut bytes = fields.into_bytes();
        bytes.splice(0..0, b"NRRD0004\n".iter().copied());
        let msg = parse_msg(&bytes);
        assert!(
            msg.contains("separate file") && msg.contains("header's path"),
            "{msg}"
        );
        assert!(msg.contains("vol.raw"), "{msg}");
    }
}

#[test]
fn missing_required_fields_are_named() {
    let all = [
        ("type", "type: uchar\n"),
        ("dimension", "dimension: 1\n"),
        ("sizes", "sizes: 1\n"),
        ("encoding", "encoding: raw\n"),
    ];
    for (missing, _) in all {
        let fields: String = all
            .iter()
            .filter(|(n, _)| *n != missing)
            .map(|(_, l)| *l)
            .collect();
        let err = parse_err(&nrrd(&fields, &[0]));
        assert!(
            matches!(err, IoError::MissingField { field } if field == missing),
            "{err:?}"
        );
        assert!(err.to_string().contains(&format!("`{missing}`")), "{err}");
    }
}

#[test]
fn malformed_sizes_are_rejected() {
    let header = |sizes: &str| {
        nrrd(
            &format!("type: uchar\ndimension: 3\nsizes: {sizes}\nencoding: raw\n"),
            &[0; 8],
        )
    };
    assert_eq!(
        parse_msg(&header("12 x")),
        "NRRD field `sizes`: expected 3 positive integers, got `12 x`"
    );
    for bad in ["0 2 2", "2 2", "2 2 2 2", "-1 2 2", "2.5 2 2", ""] {
        let err = parse_err(&header(bad));
        assert!(
            matches!(err, IoError::Field { field: "sizes", .. }),
            "{bad}: {err:?}"
        );
    }
    let huge = format!("{} 2 1", usize::MAX);
    let msg = parse_msg(&header(&huge));
    assert!(
        msg.contains("`sizes`") && msg.contains("overflows"),
        "{msg}"
    );
    let bytes_overflow = nrrd(
        &format!(
            "type: double\ndimension: 1\nsizes: {}\nendian: little\nencoding: raw\n",
            usize::MAX / 4
        ),
        &[],
    );
    assert!(parse_msg(&bytes_overflow).contains("overflows"));
}

#[test]
fn bad_magic_is_rejected() {
    for bad in [
        &b""[..],
        b"NRRD0006\n\n",
        b"NRRD0000\n\n",
        b"P6\n3 2\n255\n",
        b"nrrd0004\n\n",
        b"NRRD00041\n",
    ] {
        let err = parse_err(bad);
        assert!(matches!(err, IoError::BadMagic { .. }), "{err:?}");
        assert!(err.to_string().contains("magic"), "{err}");
    }
    for version in 1..=5 {
        let bytes =
            format!("NRRD000{version}\ntype: uchar\ndimension: 1\nsizes: 1\nencoding: raw\n\n\x2a");
        assert_eq!(
            parse_nrrd(bytes.as_bytes()).expect("version").data,
            vec![42.0]
        );
    }
}

#[test]
fn malformed_and_unterminated_headers_are_rejected() {
    let err = parse_err(&nrrd("type uchar\n", &[0]));
    assert!(matches!(err, IoError::Header { line: 2, .. }), "{err:?}");
    let dup = parse_err(&nrrd(
        "type: uchar\ntype: float\ndimension: 1\nsizes: 1\nencoding: raw\n",
        &[0],
    ));
    assert!(dup.to_string().contains("`type`") && dup.to_string().contains("more than once"));
    let unterminated = b"NRRD0004\ntype: uchar\ndimension: 1\nsizes: 1\nencoding: raw\n";
    let msg = parse_msg(unterminated);
    assert!(msg.contains("blank line"), "{msg}");
    let mut long_line = b"NRRD0004\n# ".to_vec();
    long_line.resize(3 << 20, b'x');
    assert!(matches!(
        parse_err(&long_line),
        IoError::Header { line: 2, .. }
    ));
}

#[test]
fn byte_skip_and_line_skip_errors() {
    let base = "type: uchar\ndimension: 1\nsizes: 2\nencoding: raw\n";
    let minus_one = parse_msg(&nrrd(&format!("{base}byte skip: -1\n"), &[1, 2]));
    assert!(
        minus_one.contains("`byte skip`") && minus_one.contains("-1"),
        "{minus_one}"
    );
    let past_end = parse_msg(&nrrd(&format!("{base}byte skip: 10\n"), &[1, 2]));
    assert!(past_end.contains("`byte skip`"), "{past_end}");
    let lines = parse_msg(&nrrd(&format!("{base}line skip: 3\n"), b"a\nb\n"));
    assert!(lines.contains("`line skip`"), "{lines}");
    let bad = parse_msg(&nrrd(&format!("{base}line skip: many\n"), &[1, 2]));
    assert!(
        bad.contains("`line skip`") && bad.contains("`many`"),
        "{bad}"
    );
}

#[test]
fn gzip_byte_skip_applies_after_decompression() {
    let fields = "type: uchar\ndimension: 1\nsizes: 2\nencoding: gzip\nbyte skip: 3\n";
    let vol = parse_nrrd(&nrrd(fields, &gzip_bytes(&[9, 9, 9, 4, 5]))).expect("skip");
    assert_eq!(vol.data, vec![4.0, 5.0]);
}

#[test]
fn truncated_raw_data_reports_expected_and_found() {
    let mut bytes = encode_nrrd(
        &[4, 2],
        SampleType::U16,
        Encoding::Raw,
        Endian::Little,
        &[1.0; 8],
    );
    bytes.truncate(bytes.len() - 5);
    let err = parse_err(&bytes);
    assert!(
        matches!(
            err,
            IoError::Truncated {
                expected: 16,
                found: 11,
                gzip: false
            }
        ),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(msg.contains("16") && msg.contains("11"), "{msg}");
}

#[test]
fn truncated_gzip_data_reports_expected_and_found() {
    let fields = "type: float\ndimension: 2\nsizes: 3 3\nendian: little\nencoding: gzip\n";
    let err = parse_err(&nrrd(fields, &gzip_bytes(&[0u8; 30])));
    assert!(
        matches!(
            err,
            IoError::Truncated {
                expected: 36,
                found: 30,
                gzip: true
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("gzip"));
    // A compressed stream cut short is either corrupt or truncated, never a panic.
    let mut cut = encode_nrrd(
        &[64],
        SampleType::F64,
        Encoding::Gzip,
        Endian::Big,
        &[1.5; 64],
    );
    cut.truncate(cut.len() - 12);
    let err = parse_err(&cut);
    assert!(
        matches!(err, IoError::Gzip { .. } | IoError::Truncated { .. }),
        "{err:?}"
    );
}

#[test]
fn extra_trailing_bytes_are_accepted() {
    let mut raw = encode_nrrd(
        &[2],
        SampleType::I16,
        Encoding::Raw,
        Endian::Big,
        &[-3.0, 4.0],
    );
    raw.extend_from_slice(b"trailing junk");
    assert_eq!(parse_nrrd(&raw).expect("raw").data, vec![-3.0, 4.0]);
    let fields = "type: uchar\ndimension: 1\nsizes: 2\nencoding: gzip\n";
    let gz = nrrd(fields, &gzip_bytes(&[1, 2, 3, 4, 5]));
    assert_eq!(parse_nrrd(&gz).expect("gzip").data, vec![1.0, 2.0]);
}

#[test]
fn multi_member_gzip_is_read() {
    let mut data = gzip_bytes(&[1, 2, 3]);
    data.extend(gzip_bytes(&[4, 5]));
    data.extend(gzip_bytes(&[6]));
    let fields = "type: uchar\ndimension: 2\nsizes: 3 2\nencoding: gzip\n";
    let vol = parse_nrrd(&nrrd(fields, &data)).expect("multi-member");
    assert_eq!(vol.data, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
}

#[test]
fn corrupt_gzip_is_reported() {
    let good = encode_nrrd(
        &[8, 8],
        SampleType::U16,
        Encoding::Gzip,
        Endian::Little,
        &[7.0; 64],
    );
    let data_at = good
        .windows(2)
        .position(|w| w == [0x1f, 0x8b])
        .expect("gzip magic");
    let mut bad_magic = good.clone();
    bad_magic[data_at] = b'X';
    let msg = parse_msg(&bad_magic);
    assert!(msg.contains("gzip"), "{msg}");
    let mut bad_crc = good.clone();
    let crc_at = good.len() - 8;
    bad_crc[crc_at] ^= 0xff;
    assert!(matches!(parse_err(&bad_crc), IoError::Gzip { .. }));
    let garbage = nrrd(
        "type: uchar\ndimension: 1\nsizes: 4\nencoding: gzip\n",
        b"not gzip at all",
    );
    assert!(matches!(parse_err(&garbage), IoError::Gzip { .. }));
}

#[test]
fn memory_guard_refuses_huge_volumes_before_reading_data() {
    let header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1000 1000 1\nencoding: raw\n\n";
    let mut bytes = header.as_bytes().to_vec();
    bytes.extend_from_slice(b"data that must not be read");
    let mut reader = &bytes[..];
    let err = read_nrrd_from(&mut reader, 1 << 20)
        .map(|v| v.dims)
        .expect_err("too large");
    let needed = 5 * 1000u64.pow(2);
    assert!(
        matches!(err, IoError::TooLarge { needed: n, limit } if n == needed && limit == 1 << 20),
        "{err:?}"
    );
    assert_eq!(reader, b"data that must not be read", "data was read");
    let msg = err.to_string();
    assert!(
        msg.contains(&needed.to_string()) && msg.contains("1048576"),
        "{msg}"
    );
    // A small volume passes a small limit, and the limit counts f32 + raw bytes.
    let small = encode_nrrd(
        &[10],
        SampleType::U16,
        Encoding::Raw,
        Endian::Little,
        &[1.0; 10],
    );
    assert!(parse_nrrd_limited(&small, 60).is_ok());
    assert!(matches!(
        parse_nrrd_limited(&small, 59),
        Err(IoError::TooLarge { needed: 60, .. })
    ));
    // Beyond the process's own limit (the public entry point's), the
    // whole-job check refuses first: 5e15 bytes.
    let huge =
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\n\n";
    let mut reader = huge.as_bytes();
    let err = read_nrrd_from(&mut reader, 1 << 20)
        .map(|v| v.dims)
        .expect_err("too large");
    assert!(matches!(err, IoError::OverBudget(_)), "{err:?}");
}

#[test]
fn gzip_bomb_is_not_fully_decompressed() {
    let bomb = gzip_bytes(&vec![0u8; 32 << 20]);
    let bytes = nrrd(
        "type: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: gzip\n",
        &bomb,
    );
    let mut reader = &bytes[..];
    let vol = read_nrrd_from(&mut reader, 1 << 20).expect("extra data accepted");
    assert_eq!(vol.data, vec![0.0; 64]);
    assert!(
        reader.len() > bomb.len() / 2,
        "consumed {} of {} compressed bytes",
        bomb.len() - reader.len(),
        bomb.len()
    );
}

#[test]
fn non_finite_float_samples_name_the_voxel() {
    let mut values = vec![1.0f64; 24];
    let (i, j, k) = (2, 1, 1);
    values[i + 4 * (j + 3 * k)] = f64::NAN;
    for endian in [Endian::Little, Endian::Big] {
        for encoding in [Encoding::Raw, Encoding::Gzip] {
            let bytes = encode_nrrd(&[4, 3, 2], SampleType::F32, encoding, endian, &values);
            let err = parse_err(&bytes);
            assert!(
                matches!(err, IoError::NonFinite { voxel: [2, 1, 1], value } if value.is_nan()),
                "{err:?}"
            );
            assert!(err.to_string().contains("(2, 1, 1)"), "{err}");
        }
    }
    let inf = encode_nrrd(
        &[3],
        SampleType::F64,
        Encoding::Raw,
        Endian::Big,
        &[0.0, f64::NEG_INFINITY, f64::NAN],
    );
    let msg = parse_msg(&inf);
    assert!(msg.contains("-inf") && msg.contains("(1, 0, 0)"), "{msg}");
    let too_big = encode_nrrd(
        &[2],
        SampleType::F64,
        Encoding::Raw,
        Endian::Little,
        &[0.0, 1e300],
    );
    let err = parse_err(&too_big);
    assert!(
        matches!(err, IoError::NonFinite { voxel: [1, 0, 0], value } if value == 1e300),
        "{err:?}"
    );
    assert!(err.to_string().contains("1e300"), "{err}");
}

#[test]
fn non_finite_sample_in_a_later_chunk_has_the_right_index() {
    let n = CHUNK_BYTES / 4 * 2 + 10;
    let mut values = vec![0.5f64; n];
    let bad = CHUNK_BYTES / 4 + 7;
    values[bad] = f64::INFINITY;
    let bytes = encode_nrrd(
        &[n],
        SampleType::F32,
        Encoding::Raw,
        Endian::Little,
        &values,
    );
    let err = parse_err(&bytes);
    assert!(
        matches!(err, IoError::NonFinite { voxel: [i, 0, 0], .. } if i == bad),
        "{err:?}"
    );
}

/// Tiny deterministic PRNG for the fuzz test.
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn mutate(rng: &mut XorShift, base: &[u8]) -> Vec<u8> {
    let mut bytes = base.to_vec();
    match rng.below(4) {
        0 => bytes.truncate(rng.below(base.len() + 1)),
        1 => {
            for _ in 0..=rng.below(4) {
                let at = rng.below(bytes.len());
                bytes[at] ^= 1 << rng.below(8);
            }
        }
        2 => {
            let at = rng.below(bytes.len());
            bytes[at] = rng.next() as u8;
            bytes.truncate(bytes.len() - rng.below(8).min(bytes.len()));
        }
        _ => {
            let at = rng.below(bytes.len() + 1);
            let digit = b"0123456789 -x\n"[rng.below(14)];
            bytes.insert(at, digit);
        }
    }
    bytes
}

#[test]
fn fuzzed_inputs_never_panic() {
    let values: Vec<f64> = (0..60).map(|n| (n as f64 - 30.0) * 1.25).collect();
    let bases = [
        encode_nrrd(
            &[5, 4, 3],
            SampleType::F32,
            Encoding::Gzip,
            Endian::Little,
            &values,
        ),
        encode_nrrd(
            &[5, 4, 3],
            SampleType::I16,
            Encoding::Raw,
            Endian::Big,
            &values,
        ),
        encode_nrrd(
            &[6, 10],
            SampleType::F64,
            Encoding::Raw,
            Endian::Little,
            &values,
        ),
    ];
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    let (mut ok, mut err) = (0, 0);
    for base in &bases {
        for _ in 0..300 {
            let input = mutate(&mut rng, base);
            match parse_nrrd_limited(&input, 1 << 24) {
                Ok(_) => ok += 1,
                Err(_) => err += 1,
            }
        }
    }
    assert_eq!(ok + err, 900);
    assert!(ok > 0 && err > 0, "ok {ok}, err {err}");
}

#[test]
fn raw_files_parse_with_explicit_layout() {
    let values = [-2.0, 1000.0, 0.0, 65.0, 7.0, -32768.0];
    let bytes = samples::encode_values(&values, SampleType::I16, Endian::Big);
    let vol = parse_raw(&bytes, [3, 2, 1], SampleType::I16, Endian::Big).expect("raw");
    assert_eq!(vol.dims, [3, 2, 1]);
    assert_eq!(vol.data, values.map(|v| v as f32).to_vec());
    assert_eq!(vol.get(0, 1, 0), 65.0);
    let err = parse_raw(&bytes[..7], [3, 2, 1], SampleType::I16, Endian::Big).expect_err("short");
    assert!(
        matches!(
            err,
            IoError::Truncated {
                expected: 12,
                found: 7,
                gzip: false
            }
        ),
        "{err:?}"
    );
    assert!(parse_raw(&bytes, [3, 0, 1], SampleType::I16, Endian::Big).is_err());
    assert!(parse_raw(&bytes, [usize::MAX, 2, 1], SampleType::U8, Endian::Big).is_err());
    let nan = f32::NAN.to_le_bytes();
    let err = parse_raw(&nan, [1, 1, 1], SampleType::F32, Endian::Little).expect_err("nan");
    assert!(matches!(
        err,
        IoError::NonFinite {
            voxel: [0, 0, 0],
            ..
        }
    ));
}

/// A unique path in the temporary directory, removed on drop.
struct TempFile(std::path::PathBuf);

impl TempFile {
    fn new(tag: &str) -> Self {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let name = format!(
            "fvr-nrrd-test-{}-{nanos}-{}-{tag}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        );
        TempFile(std::env::temp_dir().join(name))
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

#[test]
fn write_then_read_file_round_trip() {
    let file = TempFile::new("vol.nrrd");
    let data: Vec<f32> = (0..60).map(|n| (n as f32 - 17.0) / 3.0).collect();
    write_nrrd_f32(&file.0, &[5, 4, 3], &data).expect("write");
    let vol = read_nrrd(&file.0).expect("read");
    assert_eq!(vol.dims, [5, 4, 3]);
    assert_eq!(vol.data, data);
    let text = std::fs::read(&file.0).expect("bytes");
    let header = String::from_utf8_lossy(&text[..text.len() - 240]);
    for field in [
        "type: float",
        "dimension: 3",
        "sizes: 5 4 3",
        "encoding: raw",
        "endian: little",
    ] {
        assert!(header.contains(field), "{header}");
    }
    let image = TempFile::new("img.nrrd");
    write_nrrd_f32(&image.0, &[3, 2], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).expect("write 2D");
    assert_eq!(read_nrrd(&image.0).expect("read 2D").dims, [3, 2, 1]);
}

#[test]
fn file_errors_carry_the_path() {
    let missing = TempFile::new("missing.nrrd");
    let err = read_nrrd(&missing.0).expect_err("no such file");
    assert!(
        err.to_string().contains(&missing.0.display().to_string()),
        "{err}"
    );
    assert!(matches!(err.root(), IoError::Io { .. }));
    assert!(std::error::Error::source(&err).is_some());
    let bad = TempFile::new("bad.nrrd");
    std::fs::write(&bad.0, b"NRRD0004\ntype: uchar\n\n").expect("write");
    let err = read_nrrd(&bad.0).expect_err("missing fields");
    assert!(
        err.to_string().contains(&bad.0.display().to_string()),
        "{err}"
    );
    assert!(matches!(err.root(), IoError::MissingField { .. }));
    let mismatch = write_nrrd_f32(&bad.0, &[2, 2], &[0.0; 3]).expect_err("size mismatch");
    assert!(matches!(mismatch.root(), IoError::InvalidArgument { .. }));
    let raw_err =
        read_raw(&missing.0, [1, 1, 1], SampleType::U8, Endian::Little).expect_err("no file");
    assert!(raw_err
        .to_string()
        .contains(&missing.0.display().to_string()));
}

#[test]
fn read_raw_from_file() {
    let file = TempFile::new("vol.raw");
    let values = [1.0, 2.0, 70000.0, 4.0];
    std::fs::write(
        &file.0,
        samples::encode_values(&values, SampleType::U32, Endian::Little),
    )
    .expect("write");
    let vol = read_raw(&file.0, [2, 2, 1], SampleType::U32, Endian::Little).expect("read");
    assert_eq!(vol.data, vec![1.0, 2.0, 70000.0, 4.0]);
}

#[test]
#[should_panic(expected = "do not match")]
fn encode_panics_on_mismatched_sizes() {
    let _ = encode_nrrd(
        &[2, 2],
        SampleType::U8,
        Encoding::Raw,
        Endian::Little,
        &[0.0; 3],
    );
}

#[test]
fn encode_rounds_and_saturates_integers() {
    let bytes = encode_nrrd(
        &[4],
        SampleType::U8,
        Encoding::Raw,
        Endian::Little,
        &[-5.0, 1.6, 300.0, f64::NAN],
    );
    assert_eq!(
        parse_nrrd(&bytes).expect("u8").data,
        vec![0.0, 2.0, 255.0, 0.0]
    );
}

#[test]
fn volume_write_keeps_samples_and_spacing() {
    let file = TempFile::new("spaced.nrrd");
    let volume = Volume {
        dims: [5, 4, 3],
        data: (0..60).map(|n| (n as f32 - 17.0) / 3.0).collect(),
        spacing: [0.957_031_25, 0.1 + 0.2, 1.5],
        orientation: None,
    };
    write_volume_nrrd(&file.0, &volume).expect("write");
    let back = read_nrrd(&file.0).expect("read");
    assert_eq!(back.dims, volume.dims);
    assert_eq!(back.data, volume.data);
    assert_eq!(back.spacing, volume.spacing);
    let bad = Volume {
        spacing: [1.0, 0.0, 1.0],
        orientation: None,
        ..volume
    };
    let err = write_volume_nrrd(&file.0, &bad).expect_err("zero spacing");
    assert!(
        matches!(err.root(), IoError::InvalidArgument { .. }),
        "{err}"
    );
}
