//! Every prefix of a valid file is refused with an error, never a panic or
//! a volume: a deterministic, exhaustive companion to the fuzzers in
//! `fuzz/` that runs in every test pass.

use std::io::Write;

use fvr_engine::volume::Volume;
use fvr_host::io::den::{encode_den, parse_den};
use fvr_host::io::dicom::{parse_slice, CtSlice};
use fvr_host::io::inv3::{encode_inv3_i16, parse_inv3};
use fvr_host::io::nifti::{encode_nifti_f32, parse_nifti};
use fvr_host::io::nrrd::IoError;
use fvr_host::io::nrrd::{encode_nrrd, parse_nrrd, Encoding, Endian, Endian::Little, SampleType};

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// `parse` accepts `whole` and refuses every strict prefix of it; returns
/// what `whole` gave. `what` names an accepted value in the failure message.
fn refuse_every_prefix<T>(
    name: &str,
    whole: &[u8],
    parse: impl Fn(&[u8]) -> Result<T, IoError>,
    what: impl Fn(&T) -> String,
) -> T {
    let full = parse(whole).unwrap_or_else(|e| panic!("{name}: the whole file fails: {e}"));
    for len in 0..whole.len() {
        if let Ok(v) = parse(&whole[..len]) {
            panic!(
                "{name}: a prefix of {len} of {} bytes gave {}",
                whole.len(),
                what(&v)
            );
        }
    }
    full
}

/// [`refuse_every_prefix`] for a volume reader; the whole file has samples.
fn every_prefix_is_refused(
    name: &str,
    whole: &[u8],
    parse: impl Fn(&[u8]) -> Result<Volume, IoError>,
) {
    let full = refuse_every_prefix(name, whole, parse, |v| format!("a volume of {:?}", v.dims));
    assert!(!full.data.is_empty());
}

#[test]
fn prefixes_of_every_format_are_errors() {
    let den = encode_den(
        [3, 4, 5],
        &(0..60).map(|i| i as u8).collect::<Vec<_>>(),
        Endian::Big,
    );
    every_prefix_is_refused("den", &den, parse_den);
    every_prefix_is_refused("den.gz", &gzip(&den), parse_den);
    let data: Vec<f32> = (0..24).map(|i| i as f32 * 0.5).collect();
    let nii = encode_nifti_f32([4, 3, 2], [0.5, 1.0, 2.0], (2.0, 1.0), &data, Little);
    every_prefix_is_refused("nii", &nii, parse_nifti);
    every_prefix_is_refused("nii.gz", &gzip(&nii), parse_nifti);
    let inv3 = encode_inv3_i16(
        [3, 2, 2],
        [0.9, 0.9, 1.5],
        &[-1024, 0, 5, 7, 9, 11, 13, 15, 17, 19, 21, 3033],
    );
    every_prefix_is_refused("inv3", &inv3, parse_inv3);
    let values: Vec<f64> = (0..12).map(|i| i as f64).collect();
    for encoding in [Encoding::Raw, Encoding::Gzip] {
        let nrrd = encode_nrrd(&[3, 2, 2], SampleType::I16, encoding, Endian::Big, &values);
        every_prefix_is_refused("nrrd", &nrrd, parse_nrrd);
    }
}

#[test]
fn prefixes_of_a_dicom_slice_are_errors() {
    // Explicit and implicit VR: the length walk reads each differently.
    for implicit_vr in [false, true] {
        let bytes = CtSlice {
            series: "1.2",
            pixel_spacing: [0.5, 0.5],
            intercept: -1024.0,
            implicit_vr,
            ..CtSlice::axial([3, 2], &[1, 2, 3, 4, 5, 6])
        }
        .encode();
        let slice = refuse_every_prefix("dicom", &bytes, parse_slice, |s| {
            format!("a slice of {:?}", s.size)
        });
        assert_eq!(
            slice.pixels,
            vec![-1023.0, -1022.0, -1021.0, -1020.0, -1019.0, -1018.0]
        );
    }
}
