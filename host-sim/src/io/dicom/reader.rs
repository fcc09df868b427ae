//! A bounded reader of DICOM Part 10 files: the element stream of a file
//! held in memory, read into a `dicom-object` object for the attribute
//! lookups and for `dicom-pixeldata`.
//!
//! Every declared length is checked against the bytes left (in the file,
//! and in the item or sequence that holds the element) before any value is
//! copied, so memory grows with the bytes actually present: values are
//! copies of the file's bytes, and an element, item or split string costs
//! a bounded number of bytes for each byte of its header. A deflated data
//! set is inflated up to the memory limit.
//!
//! Read: the 128-byte preamble (optional) and `DICM`; the file meta group
//! (explicit VR little endian, read for as many bytes as its group length
//! (0002,0000) says); then the data set in its transfer syntax: explicit VR
//! little endian, implicit VR little endian (VRs from the standard
//! dictionary, pixel and overlay data as OW), explicit VR big endian, or
//! deflated explicit VR little endian. Defined and undefined lengths,
//! sequences and items (nested at most [`MAX_DEPTH`] deep), and
//! encapsulated pixel data (basic offset table, then fragments). Values
//! become the `PrimitiveValue`s `dicom-parser` gives them (strings split at
//! `\`, decoded in the `SpecificCharacterSet`; numbers in the file's byte
//! order).

use std::io::Read;

use dicom_core::value::{DataSetSequence, PixelFragmentSequence, C};
use dicom_core::{DataElement, DicomValue, Length, PrimitiveValue, Tag, VR};
use dicom_encoding::text::{DefaultCharacterSetCodec, SpecificCharacterSet, TextCodec};
use dicom_object::mem::InMemElement;
use dicom_object::{DefaultDicomObject, FileMetaTableBuilder, InMemDicomObject};

use crate::io::nrrd::{format_error, IoError};

use super::values::{check_value_size, implicit_vr, numbers_u32, primitive, us_or_ss};
use super::FORMAT;

/// Transfer syntaxes whose data set is not explicit VR little endian.
const IMPLICIT_VR_LITTLE_ENDIAN: &str = "1.2.840.10008.1.2";
const EXPLICIT_VR_BIG_ENDIAN: &str = "1.2.840.10008.1.2.2";
const DEFLATED_EXPLICIT_VR_LITTLE_ENDIAN: &str = "1.2.840.10008.1.2.1.99";

/// Deepest nesting of sequences and items accepted (each sequence and each
/// item is a level); CT slices use a handful.
pub(crate) const MAX_DEPTH: usize = 64;

const UNDEFINED: u32 = u32::MAX;
const ITEM: (u16, u16) = (0xFFFE, 0xE000);
const ITEM_END: (u16, u16) = (0xFFFE, 0xE00D);
const SEQUENCE_END: (u16, u16) = (0xFFFE, 0xE0DD);
pub(super) const PIXEL_DATA: (u16, u16) = (0x7FE0, 0x0010);
const PIXEL_REPRESENTATION: (u16, u16) = (0x0028, 0x0103);

/// Read a whole Part 10 file (preamble optional).
///
/// # Errors
/// No `DICM`, a malformed file meta group, a declared length beyond the
/// bytes left, a length that splits a binary value, structure errors
/// (misplaced items or delimiters, nesting beyond [`MAX_DEPTH`]), text not
/// valid in its character set; each names the element.
pub(crate) fn read(bytes: &[u8]) -> Result<DefaultDicomObject, IoError> {
    let start = if bytes.get(128..132) == Some(b"DICM") {
        132
    } else if bytes.starts_with(b"DICM") {
        4
    } else {
        return Err(format_error(
            FORMAT,
            "file meta",
            "not a DICOM Part 10 file: no `DICM` at byte 128 (or 0)",
        ));
    };
    let mut meta = Cursor::new(bytes, start, true, false);
    let (builder, syntax) = read_meta(&mut meta)?;
    let meta_table = builder
        .build()
        .map_err(|e| format_error(FORMAT, "file meta", format!("cannot be read: {e}")))?;
    let inflated;
    let mut cursor = match syntax.as_str() {
        DEFLATED_EXPLICIT_VR_LITTLE_ENDIAN => {
            inflated = inflate(&bytes[meta.pos..])?;
            Cursor::new(&inflated, 0, true, false)
        }
        IMPLICIT_VR_LITTLE_ENDIAN => Cursor::new(bytes, meta.pos, false, false),
        EXPLICIT_VR_BIG_ENDIAN => Cursor::new(bytes, meta.pos, true, true),
        _ => Cursor::new(bytes, meta.pos, true, false),
    };
    let elements = cursor.data_set()?;
    Ok(InMemDicomObject::from_element_iter(elements).with_exact_meta(meta_table))
}

/// The file meta group's builder and its transfer syntax UID.
fn read_meta(cur: &mut Cursor<'_>) -> Result<(FileMetaTableBuilder, String), IoError> {
    let bad = |problem: String| format_error(FORMAT, "file meta", problem);
    let group_length = match cur.header()? {
        Some(h) if h.tag == (0x0002, 0x0000) && h.len == 4 => {
            let v = cur.value(h.tag, h.len)?;
            u32::from_le_bytes([v[0], v[1], v[2], v[3]])
        }
        _ => {
            return Err(bad(
                "the file meta group does not start with its 4-byte length (0002,0000)".into(),
            ))
        }
    };
    let mut builder = FileMetaTableBuilder::new();
    let mut syntax = String::new();
    let mut read = 0u32;
    while read < group_length {
        let at = cur.pos;
        let Some(h) = cur.header()? else {
            return Err(bad(format!(
                "the file ends inside the file meta group ({group_length} bytes declared, {read} read)"
            )));
        };
        if h.len == UNDEFINED {
            return Err(bad(format!(
                "element ({:04X},{:04X}) has an undefined length",
                h.tag.0, h.tag.1
            )));
        }
        let value = cur.value(h.tag, h.len)?;
        let uid = || -> Result<String, IoError> {
            let s = DefaultCharacterSetCodec.decode(value).map_err(|e| {
                bad(format!(
                    "element ({:04X},{:04X}) is not text: {e}",
                    h.tag.0, h.tag.1
                ))
            })?;
            Ok(s.trim_end_matches(['\0', ' ']).to_owned())
        };
        builder = match h.tag {
            (0x0002, 0x0002) => builder.media_storage_sop_class_uid(uid()?),
            (0x0002, 0x0003) => builder.media_storage_sop_instance_uid(uid()?),
            (0x0002, 0x0010) => {
                let ts = uid()?;
                // As `dicom-object` looks it up: trailing whitespace too.
                syntax = ts
                    .trim_end_matches(|c: char| c.is_whitespace() || c == '\0')
                    .to_owned();
                builder.transfer_syntax(ts)
            }
            _ => builder,
        };
        read = read.saturating_add((cur.pos - at) as u32);
    }
    Ok((builder, syntax))
}

/// Inflate a deflated data set, refusing more than the memory limit.
fn inflate(deflated: &[u8]) -> Result<Vec<u8>, IoError> {
    let limit = crate::budget::limit_bytes();
    let mut out = Vec::new();
    flate2::read::DeflateDecoder::new(deflated)
        .take(limit.saturating_add(1))
        .read_to_end(&mut out)
        .map_err(|e| {
            format_error(
                FORMAT,
                "data set",
                format!("the deflated data set cannot be inflated: {e}"),
            )
        })?;
    if out.len() as u64 > limit {
        return Err(format_error(
            FORMAT,
            "data set",
            format!("the deflated data set inflates to more than the memory limit ({limit} bytes)"),
        ));
    }
    Ok(out)
}

/// An element header: tag, VR (from the file, or the dictionary in
/// implicit VR; none for the item group), declared length.
pub(super) struct Header {
    pub(super) tag: (u16, u16),
    pub(super) vr: VR,
    pub(super) len: u32,
}

/// A container being read: the data set or an item (elements), a sequence
/// (items), or encapsulated pixel data (fragments). `end` is the byte where
/// a defined length ends it; `limit` the end of the innermost container of
/// defined length around it (or of the input).
enum Frame {
    Item {
        elements: Vec<InMemElement>,
        end: Option<usize>,
        limit: usize,
    },
    Sequence {
        tag: (u16, u16),
        vr: VR,
        len: u32,
        items: Vec<InMemDicomObject>,
        end: Option<usize>,
        limit: usize,
    },
    Pixels {
        vr: VR,
        offsets: Option<C<u32>>,
        fragments: Vec<Vec<u8>>,
        limit: usize,
    },
}

impl Frame {
    fn end(&self) -> Option<usize> {
        match self {
            Frame::Item { end, .. } | Frame::Sequence { end, .. } => *end,
            Frame::Pixels { .. } => None,
        }
    }

    fn limit(&self) -> usize {
        match self {
            Frame::Item { limit, .. }
            | Frame::Sequence { limit, .. }
            | Frame::Pixels { limit, .. } => *limit,
        }
    }
}

/// A position in the bytes of a file meta group or data set.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    explicit: bool,
    big_endian: bool,
    charset: SpecificCharacterSet,
    /// `PixelRepresentation` once read: with signed pixel data, elements
    /// the dictionary gives "US or SS" are read as SS (as `dicom-parser`
    /// does).
    signed: Option<bool>,
}

fn structure_error(problem: String) -> IoError {
    format_error(FORMAT, "element structure", problem)
}

impl<'a> Cursor<'a> {
    fn new(bytes: &'a [u8], pos: usize, explicit: bool, big_endian: bool) -> Self {
        Cursor {
            bytes,
            pos,
            explicit,
            big_endian,
            charset: SpecificCharacterSet::default(),
            signed: None,
        }
    }

    fn u16_at(&self, at: usize) -> Option<u16> {
        let b = self.bytes.get(at..at.checked_add(2)?)?;
        Some(if self.big_endian {
            u16::from_be_bytes([b[0], b[1]])
        } else {
            u16::from_le_bytes([b[0], b[1]])
        })
    }

    fn u32_at(&self, at: usize) -> Option<u32> {
        let b = self.bytes.get(at..at.checked_add(4)?)?;
        let a = [b[0], b[1], b[2], b[3]];
        Some(if self.big_endian {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        })
    }

    /// The next element header, or `None` at the end of the input; like
    /// `dicom-parser`, bytes too few for a header at the end are ignored
    /// (a sequence or item left open there is refused by the caller).
    fn header(&mut self) -> Result<Option<Header>, IoError> {
        let at = self.pos;
        if at >= self.bytes.len() {
            return Ok(None);
        }
        let (Some(group), Some(elem)) = (self.u16_at(at), self.u16_at(at + 2)) else {
            return Ok(None);
        };
        let tag = (group, elem);
        // Items and delimiters have no VR, in every transfer syntax.
        if group == 0xFFFE {
            let Some(len) = self.u32_at(at + 4) else {
                return Ok(None);
            };
            self.pos = at + 8;
            return Ok(Some(Header {
                tag,
                vr: VR::UN,
                len,
            }));
        }
        let (vr, len, header) = if self.explicit {
            let Some(code) = self.bytes.get(at + 4..at + 6) else {
                return Ok(None);
            };
            // The VRs with a 2-byte length (PS3.5 7.1.2); any other code,
            // unknown ones included (read as UN), has 2 reserved bytes and
            // a 4-byte length.
            let long = !matches!(
                code,
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
            let vr = VR::from_binary([code[0], code[1]]).unwrap_or(VR::UN);
            let len = if long {
                self.u32_at(at + 8)
            } else {
                self.u16_at(at + 6).map(u32::from)
            };
            let Some(len) = len else {
                return Ok(None);
            };
            (vr, len, if long { 12 } else { 8 })
        } else {
            let Some(len) = self.u32_at(at + 4) else {
                return Ok(None);
            };
            (implicit_vr(tag), len, 8)
        };
        self.pos = at + header;
        let vr = if self.signed == Some(true) && us_or_ss(tag) {
            VR::SS
        } else {
            vr
        };
        Ok(Some(Header { tag, vr, len }))
    }

    /// Refuse `len` bytes beyond the input, or beyond `limit` (the end of
    /// the container holding the element).
    fn check(&self, (group, elem): (u16, u16), len: u32, limit: usize) -> Result<(), IoError> {
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
        let inside = limit.saturating_sub(self.pos);
        if len as usize > inside {
            return Err(format_error(
                FORMAT,
                "element length",
                format!(
                    "element ({group:04X},{elem:04X}) declares {len} bytes but the item or sequence holding it has only {inside} after it"
                ),
            ));
        }
        Ok(())
    }

    /// The `len` bytes of a value (checked against the input), stepped over.
    fn value(&mut self, tag: (u16, u16), len: u32) -> Result<&'a [u8], IoError> {
        self.check(tag, len, self.bytes.len())?;
        let v = &self.bytes[self.pos..self.pos + len as usize];
        self.pos += len as usize;
        Ok(v)
    }

    /// The elements of the data set, up to the end of the input.
    fn data_set(&mut self) -> Result<Vec<InMemElement>, IoError> {
        let mut stack = vec![Frame::Item {
            elements: Vec::new(),
            end: None,
            limit: self.bytes.len(),
        }];
        loop {
            let Some(top) = stack.last() else {
                return Err(structure_error("no data set".into()));
            };
            if top.end() == Some(self.pos) {
                close(&mut stack)?;
                continue;
            }
            let limit = top.limit();
            let Some(h) = self.header()? else { break };
            if self.pos > limit {
                return Err(structure_error(format!(
                    "the header of element ({:04X},{:04X}) runs past the end of the item or sequence holding it",
                    h.tag.0, h.tag.1
                )));
            }
            self.step(&mut stack, h, limit)?;
            if stack.len() > MAX_DEPTH {
                return Err(structure_error(format!(
                    "sequences and items nested more than {MAX_DEPTH} deep"
                )));
            }
        }
        match stack.pop() {
            Some(Frame::Item { elements, .. }) if stack.is_empty() => Ok(elements),
            _ => Err(structure_error(
                "the file ends inside a sequence, item or pixel data: truncated".into(),
            )),
        }
    }

    /// Handle one header `h` read inside the top frame of `stack`.
    fn step(&mut self, stack: &mut Vec<Frame>, h: Header, limit: usize) -> Result<(), IoError> {
        let (group, elem) = h.tag;
        let misplaced = |what: &str| {
            structure_error(format!(
                "element ({group:04X},{elem:04X}) where {what} was expected"
            ))
        };
        let depth = stack.len();
        match stack.last() {
            Some(Frame::Pixels { .. }) => match h.tag {
                ITEM if h.len != UNDEFINED => {
                    let v = self.bounded_value(h.tag, h.len, limit)?;
                    if let Some(Frame::Pixels {
                        offsets, fragments, ..
                    }) = stack.last_mut()
                    {
                        match offsets {
                            None => *offsets = Some(numbers_u32(v, self.big_endian)),
                            Some(_) => fragments.push(v.to_vec()),
                        }
                    }
                }
                SEQUENCE_END => close(stack)?,
                _ => return Err(misplaced("a pixel data fragment or its delimiter")),
            },
            Some(Frame::Sequence { .. }) => match h.tag {
                ITEM => {
                    let end = self.container_end(h.tag, h.len, limit)?;
                    stack.push(Frame::Item {
                        elements: Vec::new(),
                        end,
                        limit: end.unwrap_or(limit),
                    });
                }
                SEQUENCE_END => close(stack)?,
                _ => return Err(misplaced("an item or a sequence delimiter")),
            },
            Some(Frame::Item { .. }) => match h.tag {
                ITEM_END if depth > 1 => close(stack)?,
                // A stray item delimiter in the data set is ignored.
                ITEM_END => {}
                ITEM | SEQUENCE_END => return Err(misplaced("a data element")),
                // Any other element of the item group is no item or
                // delimiter: its value is checked and skipped.
                (0xFFFE, _) => {
                    if h.len != UNDEFINED {
                        self.bounded_value(h.tag, h.len, limit)?;
                    }
                }
                _ if h.len == UNDEFINED => {
                    if h.tag == PIXEL_DATA {
                        stack.push(Frame::Pixels {
                            vr: h.vr,
                            offsets: None,
                            fragments: Vec::new(),
                            limit,
                        });
                    } else if !self.explicit || h.vr == VR::SQ || h.vr == VR::UN {
                        stack.push(Frame::Sequence {
                            tag: h.tag,
                            vr: VR::SQ,
                            len: h.len,
                            items: Vec::new(),
                            end: None,
                            limit,
                        });
                    } else {
                        return Err(format_error(
                            FORMAT,
                            "element length",
                            format!(
                                "element ({group:04X},{elem:04X}) has an undefined length but is not a sequence or pixel data"
                            ),
                        ));
                    }
                }
                _ => {
                    check_value_size(&h)?;
                    if h.vr == VR::SQ {
                        let end = self.container_end(h.tag, h.len, limit)?;
                        stack.push(Frame::Sequence {
                            tag: h.tag,
                            vr: h.vr,
                            len: h.len,
                            items: Vec::new(),
                            end,
                            limit: end.unwrap_or(limit),
                        });
                    } else {
                        let v = self.bounded_value(h.tag, h.len, limit)?;
                        let value = primitive(&h, v, self.big_endian, &mut self.charset)?;
                        if let (PIXEL_REPRESENTATION, PrimitiveValue::U16(r)) = (h.tag, &value) {
                            self.signed = r.first().map(|r| *r != 0);
                        }
                        if let Some(Frame::Item { elements, .. }) = stack.last_mut() {
                            // The declared length, as `dicom-parser` keeps it.
                            elements.push(DataElement::new_with_len(
                                Tag(group, elem),
                                h.vr,
                                Length(h.len),
                                DicomValue::Primitive(value),
                            ));
                        }
                    }
                }
            },
            None => return Err(structure_error("no data set".into())),
        }
        Ok(())
    }

    /// [`Cursor::value`] within `limit`.
    fn bounded_value(
        &mut self,
        tag: (u16, u16),
        len: u32,
        limit: usize,
    ) -> Result<&'a [u8], IoError> {
        self.check(tag, len, limit)?;
        self.value(tag, len)
    }

    /// Where a sequence or item of length `len` ends (`None` when
    /// undefined), checked against the input and `limit`.
    fn container_end(
        &self,
        tag: (u16, u16),
        len: u32,
        limit: usize,
    ) -> Result<Option<usize>, IoError> {
        if len == UNDEFINED {
            return Ok(None);
        }
        self.check(tag, len, limit)?;
        Ok(Some(self.pos + len as usize))
    }
}

/// Close the top frame of `stack` into its parent: an item into its
/// sequence, a sequence or pixel data into its item.
fn close(stack: &mut Vec<Frame>) -> Result<(), IoError> {
    let (Some(frame), Some(parent)) = (stack.pop(), stack.last_mut()) else {
        return Err(structure_error(
            "a delimiter or length ends the data set itself".into(),
        ));
    };
    match (frame, parent) {
        (Frame::Item { elements, .. }, Frame::Sequence { items, .. }) => {
            items.push(InMemDicomObject::from_element_iter(elements));
        }
        (
            Frame::Sequence {
                tag,
                vr,
                len,
                items,
                ..
            },
            Frame::Item { elements, .. },
        ) => {
            let length = if len == UNDEFINED {
                Length::UNDEFINED
            } else {
                Length(len)
            };
            elements.push(DataElement::new_with_len(
                Tag(tag.0, tag.1),
                vr,
                length,
                DicomValue::Sequence(DataSetSequence::new(items, length)),
            ));
        }
        (
            Frame::Pixels {
                vr,
                offsets,
                fragments,
                ..
            },
            Frame::Item { elements, .. },
        ) => {
            elements.push(DataElement::new_with_len(
                Tag(PIXEL_DATA.0, PIXEL_DATA.1),
                vr,
                Length::UNDEFINED,
                DicomValue::PixelSequence(PixelFragmentSequence::new(
                    offsets.unwrap_or_default(),
                    fragments,
                )),
            ));
        }
        _ => return Err(structure_error("an item outside a sequence".into())),
    }
    Ok(())
}
