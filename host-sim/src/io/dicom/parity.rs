//! The bounded reader gives the data sets `dicom-object`'s own parser gives
//! on valid files, in each transfer syntax it reads.

use dicom_core::value::{DataSetSequence, PixelFragmentSequence};
use dicom_core::{DataElement, DicomValue, Length, PrimitiveValue, Tag, VR};
use dicom_dictionary_std::{tags, uids};
use dicom_object::file::ReadPreamble;
use dicom_object::mem::InMemElement;
use dicom_object::{DefaultDicomObject, FileMetaTableBuilder, InMemDicomObject, OpenFileOptions};

use super::reader;

fn by_dicom_object(bytes: &[u8]) -> Result<DefaultDicomObject, String> {
    OpenFileOptions::new()
        .read_preamble(ReadPreamble::Auto)
        .from_reader(bytes)
        .map_err(|e| e.to_string())
}

fn put(obj: &mut InMemDicomObject, tag: Tag, vr: VR, value: PrimitiveValue) {
    obj.put(InMemElement::new(tag, vr, value));
}

/// An item holding a code value and, if `nested`, a sequence of one such
/// item.
fn item(code: &str, nested: bool) -> InMemDicomObject {
    let mut obj = InMemDicomObject::new_empty();
    put(
        &mut obj,
        tags::CODE_VALUE,
        VR::SH,
        PrimitiveValue::from(code),
    );
    if nested {
        obj.put(DataElement::new(
            tags::PURPOSE_OF_REFERENCE_CODE_SEQUENCE,
            VR::SQ,
            DicomValue::Sequence(DataSetSequence::new(
                vec![item("inner", false)],
                Length::UNDEFINED,
            )),
        ));
    }
    obj
}

/// A file in transfer syntax `ts` with text, numbers of each size, a tag,
/// nested sequences and pixel data (native, or two fragments when
/// `encapsulated`).
fn sample(ts: &str, encapsulated: bool) -> Vec<u8> {
    let mut obj = InMemDicomObject::new_empty();
    put(
        &mut obj,
        tags::SOP_CLASS_UID,
        VR::UI,
        PrimitiveValue::from(uids::CT_IMAGE_STORAGE),
    );
    put(
        &mut obj,
        tags::SOP_INSTANCE_UID,
        VR::UI,
        PrimitiveValue::from("1.2.3.4"),
    );
    put(&mut obj, tags::MODALITY, VR::CS, PrimitiveValue::from("CT"));
    put(
        &mut obj,
        tags::PATIENT_NAME,
        VR::PN,
        PrimitiveValue::from("Doe^Jane"),
    );
    put(
        &mut obj,
        tags::IMAGE_COMMENTS,
        VR::LT,
        PrimitiveValue::Str("a\\b c ".into()),
    );
    put(
        &mut obj,
        tags::PIXEL_SPACING,
        VR::DS,
        PrimitiveValue::from("0.5\\0.25"),
    );
    put(&mut obj, tags::ROWS, VR::US, PrimitiveValue::from(2u16));
    put(&mut obj, tags::COLUMNS, VR::US, PrimitiveValue::from(2u16));
    put(
        &mut obj,
        tags::FRAME_INCREMENT_POINTER,
        VR::AT,
        PrimitiveValue::Tags([Tag(0x0018, 0x1063)].into_iter().collect()),
    );
    put(
        &mut obj,
        tags::REFERENCE_PIXEL_PHYSICAL_VALUE_X,
        VR::FD,
        PrimitiveValue::from(-1.5f64),
    );
    put(
        &mut obj,
        tags::RECOMMENDED_DISPLAY_FRAME_RATE_IN_FLOAT,
        VR::FL,
        PrimitiveValue::from(2.5f32),
    );
    put(
        &mut obj,
        tags::REFERENCE_PIXEL_X0,
        VR::SL,
        PrimitiveValue::from(-7i32),
    );
    obj.put(DataElement::new(
        tags::REFERENCED_IMAGE_SEQUENCE,
        VR::SQ,
        DicomValue::Sequence(DataSetSequence::new(
            vec![item("first", true), item("second", false)],
            Length::UNDEFINED,
        )),
    ));
    if encapsulated {
        obj.put(DataElement::new(
            tags::PIXEL_DATA,
            VR::OB,
            DicomValue::PixelSequence(PixelFragmentSequence::new(
                vec![0u32],
                vec![vec![1u8, 2, 3, 4], vec![5, 6]],
            )),
        ));
    } else {
        put(
            &mut obj,
            tags::PIXEL_DATA,
            VR::OW,
            PrimitiveValue::U16([1u16, 2, 0x8003, 0xF004].into_iter().collect()),
        );
    }
    let file = obj
        .with_meta(
            FileMetaTableBuilder::new()
                .transfer_syntax(ts)
                .media_storage_sop_class_uid(uids::CT_IMAGE_STORAGE)
                .media_storage_sop_instance_uid("1.2.3.4"),
        )
        .expect("a complete file meta table");
    let mut out = Vec::new();
    file.write_all(&mut out).expect("writing DICOM into a Vec");
    out
}

/// Whether two data sets hold the same elements. Compared through `Debug`,
/// which shows every field: `Length`'s `==` is false for two undefined
/// lengths, so `==` fails on any sequence.
fn same(a: &InMemDicomObject, b: &InMemDicomObject) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

/// The same data set and transfer syntax from both readers.
fn assert_same(bytes: &[u8]) {
    let ours = reader::read(bytes).expect("the bounded reader");
    let theirs = by_dicom_object(bytes).expect("dicom-object");
    assert_eq!(
        ours.meta().transfer_syntax(),
        theirs.meta().transfer_syntax()
    );
    assert!(same(&ours, &theirs), "{:#?}\n!=\n{:#?}", *ours, *theirs);
}

#[test]
fn every_transfer_syntax_reads_as_dicom_object_reads_it() {
    for ts in [
        uids::EXPLICIT_VR_LITTLE_ENDIAN,
        uids::IMPLICIT_VR_LITTLE_ENDIAN,
        // Explicit VR big endian (retired).
        "1.2.840.10008.1.2.2",
        uids::DEFLATED_EXPLICIT_VR_LITTLE_ENDIAN,
    ] {
        assert_same(&sample(ts, false));
    }
    for ts in [uids::RLE_LOSSLESS, uids::JPEG_BASELINE8_BIT] {
        assert_same(&sample(ts, true));
    }
    // Without the preamble.
    assert_same(&sample(uids::EXPLICIT_VR_LITTLE_ENDIAN, false)[128..]);
}

/// Every file of `FVR_DICOM_PARITY_DIR` (e.g. `fuzz/corpus/dicom`) that the
/// bounded reader accepts reads the same with `dicom-object`, when that
/// reads it at all. `dicom-object` allocates declared lengths: run under a
/// memory limit (`ulimit -v`).
#[test]
#[ignore = "needs FVR_DICOM_PARITY_DIR"]
fn a_directory_reads_as_dicom_object_reads_it() {
    let Some(dir) = std::env::var_os("FVR_DICOM_PARITY_DIR") else {
        return;
    };
    let (mut equal, mut only_ours, mut differ, mut only_theirs) = (0, 0, Vec::new(), Vec::new());
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("FVR_DICOM_PARITY_DIR")
        .map(|e| e.expect("entry").path())
        .collect();
    entries.sort();
    for path in entries {
        let bytes = std::fs::read(&path).expect("file");
        let ours = match reader::read(&bytes) {
            Ok(ours) => ours,
            Err(e) => {
                if by_dicom_object(&bytes).is_ok() {
                    only_theirs.push(format!("{}: {e}", path.display()));
                }
                continue;
            }
        };
        match by_dicom_object(&bytes) {
            Ok(theirs) if same(&ours, &theirs) => equal += 1,
            Ok(theirs) => {
                let first = ours
                    .iter()
                    .map(|e| format!("{e:?}"))
                    .zip(theirs.iter().map(|e| format!("{e:?}")))
                    .find(|(a, b)| a != b);
                differ.push(format!("{}: {first:?}", path.display()));
            }
            Err(_) => only_ours += 1,
        }
    }
    eprintln!(
        "same: {equal}, read only by the bounded reader: {only_ours}, differ: {differ:?}, read only by dicom-object: {only_theirs:#?}"
    );
    assert!(differ.is_empty(), "{differ:?}");
}
