//! Declared lengths checked against the file before `dicom-object` reads
//! it (it allocates each value's declared length first).

use crate::io::nrrd::{format_error, IoError};

use super::FORMAT;

/// Transfer syntaxes whose data set is not explicit VR little endian.
const IMPLICIT_VR_LITTLE_ENDIAN: &str = "1.2.840.10008.1.2";
const EXPLICIT_VR_BIG_ENDIAN: &str = "1.2.840.10008.1.2.2";
const DEFLATED_EXPLICIT_VR_LITTLE_ENDIAN: &str = "1.2.840.10008.1.2.1.99";

/// Refuse a file in which an element declares more bytes than the file
/// holds after it.
///
/// `dicom-object` allocates (and zero-fills) each value's declared length
/// before reading it, so without this check a 1 kB file could make it
/// allocate 4 GiB. The walk follows the element headers of the file meta
/// group and of the data set (explicit or implicit VR, either byte order;
/// a deflated data set is left to the decoder, whose output is bounded by
/// the compressed size), descending into sequences and items, and skipping
/// encapsulated pixel data fragments.
pub(crate) fn check_lengths(bytes: &[u8]) -> Result<(), IoError> {
    let start = if bytes.get(128..132) == Some(b"DICM") {
        132
    } else if bytes.starts_with(b"DICM") {
        4
    } else {
        return Ok(()); // Not Part 10: the parser reports it.
    };
    let mut walk = Walk {
        bytes,
        pos: start,
        explicit: true,
        big_endian: false,
        fragments: false,
    };
    // File meta group: explicit VR little endian, starting with its group
    // length (0002,0000); like `dicom-object`, read elements until that many
    // bytes have been read.
    let mut syntax = String::new();
    let group_length = match walk.element()? {
        Some(((0x0002, 0x0000), v)) if v.len() == 4 => {
            u32::from_le_bytes([v[0], v[1], v[2], v[3]]) as usize
        }
        _ => return Ok(()), // The parser reports the malformed meta group.
    };
    let meta_start = walk.pos;
    while walk.pos - meta_start < group_length {
        match walk.element()? {
            Some(((0x0002, 0x0010), value)) => {
                syntax = String::from_utf8_lossy(value)
                    .trim_end_matches(['\0', ' '])
                    .to_owned();
            }
            Some(_) => {}
            None => return Ok(()),
        }
    }
    match syntax.as_str() {
        DEFLATED_EXPLICIT_VR_LITTLE_ENDIAN => return Ok(()),
        IMPLICIT_VR_LITTLE_ENDIAN => walk.explicit = false,
        EXPLICIT_VR_BIG_ENDIAN => walk.big_endian = true,
        _ => {}
    }
    while walk.element()?.is_some() {}
    Ok(())
}

/// The VR `dicom-encoding` gives an element in implicit VR: the standard
/// dictionary's, relaxed, with pixel and overlay data as OW; `None` (read as
/// bytes) for a tag the dictionary does not know.
fn implicit_vr((group, elem): (u16, u16)) -> Option<&'static [u8]> {
    use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry};
    if (group, elem) == (0x7FE0, 0x0010) || (group >> 8 == 0x60 && elem == 0x3000) {
        return Some(b"OW");
    }
    let entry =
        dicom_dictionary_std::StandardDataDictionary.by_tag(dicom_core::Tag(group, elem))?;
    Some(entry.vr().relaxed().to_string().as_bytes())
}

/// A cursor over DICOM element headers (see [`check_lengths`]).
struct Walk<'a> {
    bytes: &'a [u8],
    pos: usize,
    explicit: bool,
    big_endian: bool,
    /// Inside encapsulated pixel data: items are raw fragments.
    fragments: bool,
}

impl<'a> Walk<'a> {
    fn u16_at(&self, at: usize) -> Option<u16> {
        let b = self.bytes.get(at..at + 2)?;
        Some(if self.big_endian {
            u16::from_be_bytes([b[0], b[1]])
        } else {
            u16::from_le_bytes([b[0], b[1]])
        })
    }

    fn u32_at(&self, at: usize) -> Option<u32> {
        let b = self.bytes.get(at..at + 4)?;
        let a = [b[0], b[1], b[2], b[3]];
        Some(if self.big_endian {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        })
    }

    /// Step over one element header (and its value when it has a defined
    /// length and is not a sequence or item); the tag and value, or `None`
    /// at the end of the input or of what can be walked.
    #[allow(clippy::type_complexity)]
    fn element(&mut self) -> Result<Option<((u16, u16), &'a [u8])>, IoError> {
        let at = self.pos;
        let (Some(group), Some(elem)) = (self.u16_at(at), self.u16_at(at + 2)) else {
            return Ok(None);
        };
        let tag = (group, elem);
        const UNDEFINED: u32 = u32::MAX;
        // Items and delimiters have no VR, in every transfer syntax.
        if group == 0xFFFE {
            let Some(len) = self.u32_at(at + 4) else {
                return Ok(None);
            };
            self.pos = at + 8;
            match elem {
                0xE000 if self.fragments && len != UNDEFINED => self.skip(tag, len)?,
                // An item of elements: walk into it (its length still has
                // to fit the file).
                0xE000 if len != UNDEFINED => self.check(tag, len)?,
                0xE000 | 0xE00D => {}
                0xE0DD => self.fragments = false,
                // Any other element of the group is no item or delimiter:
                // `dicom-parser` reads its value (as UN), so its length is
                // checked and skipped like any value's (a (FFFE,FFFF) of
                // 0xFDFFFFFF bytes in 514 made it allocate 4 GB).
                _ if len != UNDEFINED => self.skip(tag, len)?,
                _ => {}
            }
            return Ok(Some((tag, &[])));
        }
        let (vr, len, header) = if self.explicit {
            let Some(vr) = self.bytes.get(at + 4..at + 6) else {
                return Ok(None);
            };
            // The VRs with a 2-byte length (PS3.5 7.1.2); any other code,
            // unknown ones included (read as UN, as `dicom-encoding` does),
            // has 2 reserved bytes and a 4-byte length.
            let long = !matches!(
                vr,
                b"AE"
                    | b"AS"
                    | b"AT"
                    | b"CS"
                    | b"DA"
                    | b"DS"
                    | b"DT"
                    | b"FL"
                    | b"FD"
                    | b"IS"
                    | b"LO"
                    | b"LT"
                    | b"PN"
                    | b"SH"
                    | b"SL"
                    | b"SS"
                    | b"ST"
                    | b"TM"
                    | b"UI"
                    | b"UL"
                    | b"US"
            );
            let len = if long {
                self.u32_at(at + 8)
            } else {
                self.u16_at(at + 6).map(u32::from)
            };
            let Some(len) = len else {
                return Ok(None);
            };
            (Some(vr), len, if long { 12 } else { 8 })
        } else {
            let Some(len) = self.u32_at(at + 4) else {
                return Ok(None);
            };
            (implicit_vr(tag), len, 8)
        };
        self.pos = at + header;
        if len == UNDEFINED {
            if tag == (0x7FE0, 0x0010) {
                self.fragments = true;
            } else if self.explicit && vr.is_some_and(|v| v != b"SQ" && v != b"UN") {
                return Err(format_error(
                    FORMAT,
                    "element length",
                    format!(
                        "element ({group:04X},{elem:04X}) has an undefined length but is not a sequence or pixel data"
                    ),
                ));
            }
            // A sequence of undefined length: walk into its items.
            return Ok(Some((tag, &[])));
        }
        // Binary numbers: `dicom-parser` reads whole values, so a length
        // that is not a multiple of the value size would put it out of step
        // with the element boundaries (and with this walk). In implicit VR
        // the size comes from the dictionary, as the parser takes it: a
        // 46-byte (0000,0000), a UL, is read as 44 bytes, and the parser then
        // takes two bytes of value as the next header (a corrupt file made
        // it allocate 4 GB that way).
        let size = match vr {
            Some(b"SS" | b"US" | b"OW") => 2,
            Some(b"FL" | b"SL" | b"UL" | b"AT" | b"OF" | b"OL") => 4,
            Some(b"FD" | b"SV" | b"UV" | b"OD" | b"OV") => 8,
            _ => 1,
        };
        if len % size != 0 {
            return Err(format_error(
                FORMAT,
                "element length",
                format!(
                    "element ({group:04X},{elem:04X}) of {}-byte values has length {len}, not a multiple of {size}",
                    size
                ),
            ));
        }
        if vr == Some(b"SQ") {
            self.check(tag, len)?;
            return Ok(Some((tag, &[])));
        }
        let value_at = self.pos;
        self.skip(tag, len)?;
        Ok(Some((tag, &self.bytes[value_at..self.pos])))
    }

    fn check(&self, (group, elem): (u16, u16), len: u32) -> Result<(), IoError> {
        let left = self.bytes.len().saturating_sub(self.pos);
        if len as usize > left {
            return Err(format_error(
                FORMAT,
                "element length",
                format!(
                    "element ({group:04X},{elem:04X}) declares {len} bytes but the file has only {left} after it: truncated or corrupt"
                ),
            ));
        }
        Ok(())
    }

    fn skip(&mut self, tag: (u16, u16), len: u32) -> Result<(), IoError> {
        self.check(tag, len)?;
        self.pos += len as usize;
        Ok(())
    }
}
