//! Writing CT slices as DICOM Part 10 files, for tests and fixtures.

use dicom_dictionary_std::tags;

/// One CT slice to encode as a DICOM Part 10 file (explicit or implicit VR
/// little endian, 16-bit signed samples, rescale slope 1). A test and fixture
/// helper.
#[derive(Clone, Copy, Debug)]
pub struct CtSlice<'a> {
    /// Series instance UID.
    pub series: &'a str,
    /// Instance number (also makes the SOP instance UID).
    pub instance: u32,
    /// Columns and rows.
    pub size: [u16; 2],
    /// PixelSpacing: row spacing, column spacing (mm).
    pub pixel_spacing: [f64; 2],
    /// ImagePositionPatient (mm).
    pub position: [f64; 3],
    /// ImageOrientationPatient: row and column direction cosines.
    pub orientation: [f64; 6],
    /// RescaleIntercept.
    pub intercept: f64,
    /// `columns × rows` samples, row by row.
    pub pixels: &'a [i16],
    /// Write the data set in implicit VR little endian (the default
    /// transfer syntax, common in older scanners' files) instead of
    /// explicit VR little endian.
    pub implicit_vr: bool,
}

impl<'a> CtSlice<'a> {
    /// An axial slice of `size` (columns, rows) at the origin: series "1",
    /// instance 1, 1 mm pixels, no rescale. Change fields by struct update.
    pub fn axial(size: [u16; 2], pixels: &'a [i16]) -> Self {
        CtSlice {
            series: "1",
            instance: 1,
            size,
            pixel_spacing: [1.0, 1.0],
            position: [0.0; 3],
            orientation: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            intercept: 0.0,
            pixels,
            implicit_vr: false,
        }
    }

    /// The file's bytes.
    ///
    /// # Panics
    /// If `pixels.len()` is not `columns × rows`.
    pub fn encode(&self) -> Vec<u8> {
        let CtSlice {
            series,
            instance,
            size,
            pixel_spacing,
            position,
            orientation,
            intercept,
            pixels,
            implicit_vr,
        } = *self;
        use dicom_core::{PrimitiveValue, VR};
        use dicom_object::mem::InMemElement;
        use dicom_object::{FileMetaTableBuilder, InMemDicomObject};
        assert_eq!(
            pixels.len(),
            size[0] as usize * size[1] as usize,
            "CtSlice::encode"
        );
        let ds = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x}"))
                .collect::<Vec<_>>()
                .join("\\")
        };
        let mut obj = InMemDicomObject::new_empty();
        let sop = format!("1.2.826.0.1.3680043.2.1125.{instance}");
        let put = |obj: &mut InMemDicomObject, tag, vr, value: PrimitiveValue| {
            obj.put(InMemElement::new(tag, vr, value));
        };
        put(
            &mut obj,
            tags::SOP_CLASS_UID,
            VR::UI,
            PrimitiveValue::from(dicom_dictionary_std::uids::CT_IMAGE_STORAGE),
        );
        put(
            &mut obj,
            tags::SOP_INSTANCE_UID,
            VR::UI,
            PrimitiveValue::from(sop.as_str()),
        );
        put(&mut obj, tags::MODALITY, VR::CS, PrimitiveValue::from("CT"));
        put(
            &mut obj,
            tags::SERIES_INSTANCE_UID,
            VR::UI,
            PrimitiveValue::from(series),
        );
        put(
            &mut obj,
            tags::INSTANCE_NUMBER,
            VR::IS,
            PrimitiveValue::from(instance.to_string()),
        );
        put(
            &mut obj,
            tags::IMAGE_POSITION_PATIENT,
            VR::DS,
            PrimitiveValue::from(ds(&position)),
        );
        put(
            &mut obj,
            tags::IMAGE_ORIENTATION_PATIENT,
            VR::DS,
            PrimitiveValue::from(ds(&orientation)),
        );
        put(
            &mut obj,
            tags::PIXEL_SPACING,
            VR::DS,
            PrimitiveValue::from(ds(&pixel_spacing)),
        );
        put(
            &mut obj,
            tags::SAMPLES_PER_PIXEL,
            VR::US,
            PrimitiveValue::from(1u16),
        );
        put(
            &mut obj,
            tags::PHOTOMETRIC_INTERPRETATION,
            VR::CS,
            PrimitiveValue::from("MONOCHROME2"),
        );
        put(&mut obj, tags::ROWS, VR::US, PrimitiveValue::from(size[1]));
        put(
            &mut obj,
            tags::COLUMNS,
            VR::US,
            PrimitiveValue::from(size[0]),
        );
        for (tag, value) in [
            (tags::BITS_ALLOCATED, 16u16),
            (tags::BITS_STORED, 16),
            (tags::HIGH_BIT, 15),
            (tags::PIXEL_REPRESENTATION, 1),
        ] {
            put(&mut obj, tag, VR::US, PrimitiveValue::from(value));
        }
        put(
            &mut obj,
            tags::RESCALE_INTERCEPT,
            VR::DS,
            PrimitiveValue::from(format!("{intercept}")),
        );
        put(
            &mut obj,
            tags::RESCALE_SLOPE,
            VR::DS,
            PrimitiveValue::from("1"),
        );
        let bytes: Vec<u8> = pixels.iter().flat_map(|v| v.to_le_bytes()).collect();
        put(
            &mut obj,
            tags::PIXEL_DATA,
            VR::OW,
            PrimitiveValue::from(bytes),
        );
        let file = obj
            .with_meta(FileMetaTableBuilder::new().transfer_syntax(if implicit_vr {
                dicom_dictionary_std::uids::IMPLICIT_VR_LITTLE_ENDIAN
            } else {
                dicom_dictionary_std::uids::EXPLICIT_VR_LITTLE_ENDIAN
            }))
            .expect("a complete file meta table");
        let mut out = Vec::new();
        file.write_all(&mut out).expect("writing DICOM into a Vec");
        out
    }
}
