//! Element values as `dicom-parser` reads them, for the bounded reader
//! ([`super::reader`]): VRs in implicit VR, value sizes, and the
//! `PrimitiveValue` of a value's bytes.

use dicom_core::value::C;
use dicom_core::{PrimitiveValue, Tag, VR};
use dicom_encoding::text::{DefaultCharacterSetCodec, SpecificCharacterSet, TextCodec};

use crate::io::nrrd::{format_error, IoError};

use super::reader::{Header, PIXEL_DATA};
use super::FORMAT;

/// The value `v` of the element `h` as `dicom-parser` reads it: numbers
/// in the byte order `big` gives, text in `charset` (which a
/// SpecificCharacterSet (0008,0005) changes).
pub(super) fn primitive(
    h: &Header,
    v: &[u8],
    big: bool,
    charset: &mut SpecificCharacterSet,
) -> Result<PrimitiveValue, IoError> {
    if v.is_empty() {
        return Ok(PrimitiveValue::Empty);
    }
    macro_rules! numbers {
        ($t:ty) => {
            v.chunks_exact(std::mem::size_of::<$t>())
                .map(|c| {
                    let mut a = [0u8; std::mem::size_of::<$t>()];
                    a.copy_from_slice(c);
                    if big {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    }
                })
                .collect()
        };
    }
    let not_text = |e: &dyn std::fmt::Display| {
        format_error(
            FORMAT,
            "element value",
            format!(
                "element ({:04X},{:04X}) is not text in its character set: {e}",
                h.tag.0, h.tag.1
            ),
        )
    };
    Ok(match h.vr {
        VR::AT => {
            let words: C<u16> = numbers!(u16);
            PrimitiveValue::Tags(words.chunks_exact(2).map(|w| Tag(w[0], w[1])).collect())
        }
        VR::AE
        | VR::AS
        | VR::PN
        | VR::SH
        | VR::LO
        | VR::UC
        | VR::UI
        | VR::IS
        | VR::DS
        | VR::DA
        | VR::TM
        | VR::DT
        | VR::CS => {
            let default = matches!(h.vr, VR::AE | VR::CS | VR::AS);
            let parts = v
                .split(|b| *b == b'\\')
                .map(|part| match default {
                    true => DefaultCharacterSetCodec.decode(part),
                    false => charset.decode(part),
                })
                .collect::<Result<C<String>, _>>()
                .map_err(|e| not_text(&e))?;
            if h.tag == (0x0008, 0x0005) {
                if let Some(set) = parts
                    .first()
                    .and_then(|c| SpecificCharacterSet::from_code(c))
                {
                    *charset = set;
                }
            }
            PrimitiveValue::Strs(parts)
        }
        VR::UT | VR::ST | VR::UR | VR::LT => {
            PrimitiveValue::Str(charset.decode(v).map_err(|e| not_text(&e))?)
        }
        VR::US | VR::OW => PrimitiveValue::U16(numbers!(u16)),
        VR::SS => PrimitiveValue::I16(numbers!(i16)),
        VR::FD | VR::OD => PrimitiveValue::F64(numbers!(f64)),
        VR::FL | VR::OF => PrimitiveValue::F32(numbers!(f32)),
        VR::SL => PrimitiveValue::I32(numbers!(i32)),
        VR::OL | VR::UL => PrimitiveValue::U32(numbers!(u32)),
        VR::SV => PrimitiveValue::I64(numbers!(i64)),
        VR::OV | VR::UV => PrimitiveValue::U64(numbers!(u64)),
        // OB, UN, and SQ never reach here (sequences are frames).
        _ => PrimitiveValue::U8(v.iter().copied().collect()),
    })
}

/// A basic offset table's 32-bit offsets.
pub(super) fn numbers_u32(v: &[u8], big: bool) -> C<u32> {
    v.chunks_exact(4)
        .map(|c| {
            let a = [c[0], c[1], c[2], c[3]];
            if big {
                u32::from_be_bytes(a)
            } else {
                u32::from_le_bytes(a)
            }
        })
        .collect()
}

/// Refuse a length that is not a whole number of the VR's binary values:
/// a reader that takes whole values would fall out of step with the
/// element boundaries.
pub(super) fn check_value_size(h: &Header) -> Result<(), IoError> {
    let size = match h.vr {
        VR::SS | VR::US | VR::OW => 2,
        VR::FL | VR::SL | VR::UL | VR::AT | VR::OF | VR::OL => 4,
        VR::FD | VR::SV | VR::UV | VR::OD | VR::OV => 8,
        _ => 1,
    };
    if h.len % size != 0 {
        let (group, elem) = h.tag;
        return Err(format_error(
            FORMAT,
            "element length",
            format!(
                "element ({group:04X},{elem:04X}) of {size}-byte values has length {}, not a multiple of {size}",
                h.len
            ),
        ));
    }
    Ok(())
}

/// The VR an element has in implicit VR: the standard dictionary's,
/// relaxed, with pixel and overlay data as OW; UN (bytes) for a tag the
/// dictionary does not know.
pub(super) fn implicit_vr((group, elem): (u16, u16)) -> VR {
    use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry};
    if (group, elem) == PIXEL_DATA || (group >> 8 == 0x60 && elem == 0x3000) {
        return VR::OW;
    }
    dicom_dictionary_std::StandardDataDictionary
        .by_tag(Tag(group, elem))
        .map_or(VR::UN, |entry| entry.vr().relaxed())
}

/// Whether the dictionary gives `tag` the VR "US or SS".
pub(super) fn us_or_ss((group, elem): (u16, u16)) -> bool {
    use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry, VirtualVr};
    dicom_dictionary_std::StandardDataDictionary
        .by_tag(Tag(group, elem))
        .is_some_and(|entry| entry.vr() == VirtualVr::Xs)
}
