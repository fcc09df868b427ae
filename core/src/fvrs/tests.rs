//! The `.fvrs` reader against its writer: a round trip renders the same
//! image bit for bit, and every field, section, CRC and length, corrupted
//! or cut, is refused with the error that names it.

extern crate std;
use std::vec;
use std::vec::Vec;

use half::f16;

use super::header::at;
use super::*;
use crate::filter::{Filter, FilterKind};
use crate::geometry::View;
use crate::render::{render, Buffers, Request, Source};
use crate::spectrum::{prepare_scratch_len, Spectrum};
use crate::volume::DenseVolume;

const DIMS: [usize; 3] = [12, 10, 7];
const N: usize = 16;

/// An aligned image: `u64` storage viewed as bytes.
struct Image {
    words: Vec<u64>,
    len: usize,
}

impl Image {
    fn bytes(&self) -> &[u8] {
        &bytemuck::cast_slice(&self.words)[..self.len]
    }
    fn bytes_mut(&mut self) -> &mut [u8] {
        &mut bytemuck::cast_slice_mut(&mut self.words)[..self.len]
    }
    fn from(bytes: &[u8]) -> Self {
        let mut img = Image {
            words: vec![0; bytes.len().div_ceil(8) + 1],
            len: bytes.len(),
        };
        img.bytes_mut().copy_from_slice(bytes);
        img
    }
}

fn volume() -> Vec<f32> {
    (0..DIMS.iter().product::<usize>())
        .map(|i| ((i * 37 % 101) as f32) * 0.25)
        .collect()
}

/// The f16 spectrum of the test volume, its header and image.
fn made(precision: Precision) -> (Vec<u8>, Header) {
    let data = volume();
    let vol = DenseVolume::new(DIMS, &data).unwrap();
    let filter = Filter::new(FilterKind::Kb3, 1).unwrap();
    let mut tw = vec![0f32; Twiddles::<f32>::buffer_len(N)];
    let tw = Twiddles::new(&mut tw, N).unwrap();
    let mut scratch = vec![0f32; prepare_scratch_len(N)];
    let kernel = KernelTable::<f32>::new(filter);
    let (bytes, scale) = match precision {
        Precision::F16 => {
            let mut st = vec![f16::ZERO; N * N * N];
            let s = Spectrum::prepare(&vol, filter, &mut st, &mut scratch, &tw).unwrap();
            (bytemuck::cast_slice(s.data()).to_vec(), s.scale())
        }
        Precision::F32 => {
            let mut st = vec![0f32; N * N * N];
            let s = Spectrum::prepare(&vol, filter, &mut st, &mut scratch, &tw).unwrap();
            (bytemuck::cast_slice(s.data()).to_vec(), s.scale())
        }
    };
    let header = Header {
        precision,
        filter,
        part: Part::M4f,
        n: N,
        dims: DIMS,
        scale,
    };
    let mut twv = vec![0f32; Twiddles::<f32>::buffer_len(N)];
    Twiddles::new(&mut twv, N).unwrap();
    let mut out = vec![0u8; write_len(&header).unwrap()];
    write(&header, &bytes, kernel.values(), &twv, &mut out).unwrap();
    (out, header)
}

fn parse(bytes: &[u8]) -> Result<Fvrs<'_>, FvrsError> {
    Fvrs::parse(bytes)
}

fn image(f: &Fvrs<'_>) -> Vec<f32> {
    let spec = f.spectrum_f16().unwrap();
    let kernel = f.kernel().unwrap();
    let tw = f.twiddles().unwrap();
    let mut grid = vec![0f32; crate::image::grid_len(N)];
    let mut aux = vec![0f32; crate::image::aux_len(N)];
    let mut out = vec![0f32; 12 * 10];
    let view = View {
        dir: [1.0, 0.3, 0.2],
        up: [0.0, 0.0, 1.0],
    };
    render(
        &Source::new(&spec, &kernel, &tw),
        &Request::new(view, 12, 10),
        Buffers::new(&mut grid, &mut aux, &mut out),
    )
    .unwrap();
    out
}

#[test]
fn round_trip_renders_bit_for_bit_as_the_spectrum_it_came_from() {
    let (bytes, header) = made(Precision::F16);
    let img = Image::from(&bytes);
    let f = parse(img.bytes()).unwrap();
    assert_eq!(*f.header(), header);
    assert_eq!(f.layout().spectrum.offset, 192);
    assert_eq!(f.layout().file_len as usize, bytes.len());
    // The same render from the writer's own inputs.
    let data = volume();
    let vol = DenseVolume::new(DIMS, &data).unwrap();
    let mut tw = vec![0f32; Twiddles::<f32>::buffer_len(N)];
    let tw = Twiddles::new(&mut tw, N).unwrap();
    let mut scratch = vec![0f32; prepare_scratch_len(N)];
    let mut st = vec![f16::ZERO; N * N * N];
    let spec = Spectrum::prepare(&vol, header.filter, &mut st, &mut scratch, &tw).unwrap();
    let kernel = KernelTable::<f32>::new(header.filter);
    let mut grid = vec![0f32; crate::image::grid_len(N)];
    let mut aux = vec![0f32; crate::image::aux_len(N)];
    let mut out = vec![0f32; 12 * 10];
    render(
        &Source::new(&spec, &kernel, &tw),
        &Request::new(
            View {
                dir: [1.0, 0.3, 0.2],
                up: [0.0, 0.0, 1.0],
            },
            12,
            10,
        ),
        Buffers::new(&mut grid, &mut aux, &mut out),
    )
    .unwrap();
    let from_file = image(&f);
    assert!(out.iter().any(|&v| v != 0.0));
    assert_eq!(
        out.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        from_file.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
}

#[test]
fn f32_files_read_as_f32_and_refuse_f16() {
    let (bytes, _) = made(Precision::F32);
    let img = Image::from(&bytes);
    let f = parse(img.bytes()).unwrap();
    assert_eq!(f.spectrum_f32().unwrap().n(), N);
    assert_eq!(
        f.spectrum_f16().unwrap_err(),
        FvrsError::PrecisionMismatch {
            file: "f32",
            asked: "f16"
        }
    );
    let (bytes, _) = made(Precision::F16);
    let img = Image::from(&bytes);
    assert!(matches!(
        parse(img.bytes()).unwrap().spectrum_f32(),
        Err(FvrsError::PrecisionMismatch { .. })
    ));
}

/// `bytes` with `edit` applied and the header's CRC made right again, so
/// that the field's own check is what refuses it.
fn edited(bytes: &[u8], edit: impl Fn(&mut [u8])) -> Image {
    let mut img = Image::from(bytes);
    let b = img.bytes_mut();
    edit(b);
    let len = (header::u32_at(b, at::HEADER_LEN) as usize).clamp(HEADER_LEN, b.len());
    let crc = header::header_crc(&b[..len]);
    b[at::HEADER_CRC..at::HEADER_CRC + 4].copy_from_slice(&crc.to_le_bytes());
    img
}

fn refused(img: &Image) -> FvrsError {
    let e = parse(img.bytes()).unwrap_err();
    let text = std::format!("{e}");
    assert!(!text.contains('\n') && text.len() < 200, "{text}");
    e
}

#[test]
fn every_truncation_is_refused_as_truncated() {
    let (bytes, _) = made(Precision::F16);
    // Every cut inside the header, then a sample of cuts in the sections.
    let cuts = (0..HEADER_LEN + 8).chain((HEADER_LEN..bytes.len()).step_by(97));
    for cut in cuts {
        let img = Image::from(&bytes[..cut]);
        match refused(&img) {
            FvrsError::Truncated { needed, got, .. } => {
                assert_eq!(got, cut as u64);
                assert!(needed > got);
            }
            e => panic!("cut at {cut}: {e:?}"),
        }
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(matches!(
        refused(&Image::from(&longer)),
        FvrsError::TrailingBytes { .. }
    ));
}

#[test]
fn every_header_byte_flipped_is_refused() {
    let (bytes, _) = made(Precision::F16);
    for i in 0..HEADER_LEN {
        for bit in [0x01u8, 0x80] {
            let mut img = Image::from(&bytes);
            img.bytes_mut()[i] ^= bit;
            // Without the CRC repaired: the magic, the version, the header
            // length or (at last) the CRC refuses it.
            let e = refused(&img);
            assert!(
                matches!(
                    e,
                    FvrsError::BadMagic
                        | FvrsError::Version { .. }
                        | FvrsError::Field { .. }
                        | FvrsError::Truncated { .. }
                        | FvrsError::Checksum { what: "header", .. }
                ),
                "byte {i}: {e:?}"
            );
        }
    }
}

#[test]
fn every_field_out_of_range_is_named() {
    let (bytes, _) = made(Precision::F16);
    let field = |e: FvrsError| match e {
        FvrsError::Field { field, .. } | FvrsError::Number { field, .. } => field,
        FvrsError::Section { what, .. } => what,
        FvrsError::NonZero { what, .. } => what,
        e => panic!("{e:?}"),
    };
    type Edit = (&'static str, fn(&mut [u8]));
    let cases: [Edit; 16] = [
        ("flags", |b| b[at::FLAGS] = 1),
        ("precision", |b| b[at::PRECISION] = 3),
        ("precision", |b| b[at::PRECISION] = 0),
        ("filter", |b| b[at::FILTER] = 7),
        ("oversample", |b| b[at::OVERSAMPLE] = 3),
        ("part", |b| b[at::PART] = 4),
        ("reserved", |b| b[at::RESERVED + 2] = 9),
        ("beta", |b| {
            b[at::BETA..at::BETA + 8].copy_from_slice(&f64::NAN.to_le_bytes())
        }),
        ("beta", |b| {
            b[at::BETA..at::BETA + 8].copy_from_slice(&(-1.0f64).to_le_bytes())
        }),
        ("scale", |b| {
            b[at::SCALE..at::SCALE + 8].copy_from_slice(&3.0f64.to_le_bytes())
        }),
        ("scale", |b| {
            b[at::SCALE..at::SCALE + 8].copy_from_slice(&f64::INFINITY.to_le_bytes())
        }),
        ("header length", |b| b[at::HEADER_LEN] = 140),
        ("whole image", |b| b[at::FILE_LEN] ^= 0x40),
        ("spectrum", |b| b[at::SECTIONS] ^= 0x40),
        ("kernel-table", |b| {
            b[at::SECTIONS + at::SECTION_ENTRY + 8] ^= 4
        }),
        ("reserved section-table", |b| {
            b[at::SECTIONS + 2 * at::SECTION_ENTRY + 21] = 1
        }),
    ];
    for (want, edit) in cases {
        let e = refused(&edited(&bytes, edit));
        assert!(field(e).contains(want), "{want}: {e:?}");
    }
}

#[test]
fn mismatched_grid_and_dims_are_refused_by_the_core_rules() {
    let (bytes, _) = made(Precision::F16);
    // A side the core allows for these dims (a finer grid) but not the
    // one the sections were written for: the image length no longer follows.
    let e = refused(&edited(&bytes, |b| b[at::N] = 32));
    assert!(
        matches!(e, FvrsError::Section { what: "whole image", got, .. } if got == bytes.len() as u64),
        "{e:?}"
    );
    // A side too small for the dims, a zero dim, dims beyond the side.
    for edit in [
        (|b: &mut [u8]| b[at::N] = 8) as fn(&mut [u8]),
        |b| b[at::DIMS] = 0,
        |b| b[at::DIMS + 4] = 40,
    ] {
        let e = refused(&edited(&bytes, edit));
        assert!(matches!(e, FvrsError::Core(_)), "{e:?}");
    }
    // The filter changed (kb3 -> kb4): the kernel section's length no
    // longer follows.
    let e = refused(&edited(&bytes, |b| b[at::FILTER] = 4));
    assert!(matches!(e, FvrsError::Section { .. }), "{e:?}");
}

#[test]
fn a_flipped_payload_byte_fails_its_sections_checksum() {
    let (bytes, _) = made(Precision::F16);
    let f = Image::from(&bytes);
    let layout = *parse(f.bytes()).unwrap().layout();
    let cases = [
        (layout.spectrum.offset + 5, "spectrum section"),
        (
            layout.spectrum.offset + layout.spectrum.len - 1,
            "spectrum section",
        ),
        (layout.kernel.offset + 100, "kernel-table section"),
        (layout.twiddles.offset, "twiddle section"),
    ];
    for (at, want) in cases {
        let mut img = Image::from(&bytes);
        img.bytes_mut()[at as usize] ^= 0x10;
        match refused(&img) {
            FvrsError::Checksum { what, .. } => assert_eq!(what, want),
            e => panic!("{e:?}"),
        }
        // Only the sections' CRCs see it.
        assert!(Fvrs::parse_trusting_sections(img.bytes()).is_ok());
    }
    // Padding between sections must stay zero (it is outside every CRC).
    let mut img = Image::from(&bytes);
    img.bytes_mut()[HEADER_LEN + 3] = 1;
    assert!(matches!(
        refused(&img),
        FvrsError::NonZero {
            what: "padding",
            offset: 147
        }
    ));
}

#[test]
fn versions_and_alignment() {
    let (bytes, _) = made(Precision::F16);
    let e = refused(&edited(&bytes, |b| b[at::MAJOR] = 2));
    assert_eq!(e, FvrsError::Version { major: 2, minor: 0 });
    // A later minor of the same major is read.
    let img = edited(&bytes, |b| b[at::MINOR] = 7);
    assert_eq!(parse(img.bytes()).unwrap().minor_version(), 7);
    // One byte past an aligned start.
    let mut words = vec![0u64; bytes.len() / 8 + 2];
    let raw: &mut [u8] = bytemuck::cast_slice_mut(&mut words);
    raw[1..1 + bytes.len()].copy_from_slice(&bytes);
    assert_eq!(
        parse(&raw[1..1 + bytes.len()]).unwrap_err(),
        FvrsError::Misaligned { remainder: 1 }
    );
    assert_eq!(
        refused(&Image::from(b"PK\x03\x04 not ours")),
        FvrsError::BadMagic
    );
}

#[test]
fn a_nan_coefficient_with_a_right_checksum_is_refused_at_parse() {
    let (bytes, _) = made(Precision::F16);
    let mut img = Image::from(&bytes);
    let layout = *parse(img.bytes()).unwrap().layout();
    let b = img.bytes_mut();
    let at_coef = layout.spectrum.offset as usize + 2 * 17;
    b[at_coef..at_coef + 2].copy_from_slice(&f16::NAN.to_le_bytes());
    let crc = crc32(&b[layout.spectrum.offset as usize..][..layout.spectrum.len as usize]);
    let e = at::SECTIONS + 16;
    b[e..e + 4].copy_from_slice(&crc.to_le_bytes());
    let h = header::header_crc(&b[..HEADER_LEN]);
    b[at::HEADER_CRC..at::HEADER_CRC + 4].copy_from_slice(&h.to_le_bytes());
    assert!(matches!(
        refused(&img),
        FvrsError::Core(crate::Error::NonFiniteTableEntry { index: 17, .. })
    ));
    // Trusting the sections (after a first parse) skips the scan.
    assert!(Fvrs::parse_trusting_sections(img.bytes()).is_ok());
}

#[test]
fn the_writer_checks_its_inputs() {
    let (_, header) = made(Precision::F16);
    let len = write_len(&header).unwrap();
    let mut out = vec![0u8; len];
    let kernel = KernelTable::<f32>::new(header.filter);
    let tw = vec![0f32; Twiddles::<f32>::buffer_len(N)];
    let short = vec![0u8; 10];
    assert!(write(&header, &short, kernel.values(), &tw, &mut out).is_err());
    let spec = vec![0u8; N * N * N * 2];
    let mut small = vec![0u8; len - 1];
    assert!(write(&header, &spec, kernel.values(), &tw, &mut small).is_err());
    let bad = Header { n: 24, ..header };
    assert!(write_len(&bad).is_err());
}
