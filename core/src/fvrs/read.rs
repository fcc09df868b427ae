//! Reading an image: every check of `docs/fvrs.md`, "Reading", in order,
//! then the sections as the core's types, borrowed in place.

use half::f16;

use super::error::FvrsError;
use super::header::{at, header_crc, u16_at, u32_at, u64_at, Header, Layout, Precision, Section};
use super::{crc32, HEADER_LEN, IMAGE_ALIGN, MAGIC, VERSION_MAJOR};
use crate::dht::Twiddles;
use crate::filter::KernelTable;
use crate::spectrum::Spectrum;

/// A checked `.fvrs` image: its header and its sections, borrowed.
#[derive(Clone, Copy, Debug)]
pub struct Fvrs<'a> {
    header: Header,
    layout: Layout,
    minor: u16,
    bytes: &'a [u8],
}

impl<'a> Fvrs<'a> {
    /// Check `bytes` as a whole `.fvrs` image: alignment, magic, version,
    /// header length, header CRC, length, every field, the section table
    /// against the layout the fields imply, zero padding, and each
    /// section's CRC (one pass over the image; no allocation).
    ///
    /// # Errors
    /// The first fault found, as [`FvrsError`].
    pub fn parse(bytes: &'a [u8]) -> Result<Self, FvrsError> {
        let f = Self::parse_with(bytes, true)?;
        f.check_values()?;
        Ok(f)
    }

    /// [`Fvrs::parse`] without the sections' CRCs and value scans: every
    /// header check, in O(1). For an image that [`Fvrs::parse`] accepted
    /// and that has not changed since (the C API checks an image once, at
    /// `fvr_source_open`, and then renders each view after this).
    ///
    /// # Errors
    /// As [`Fvrs::parse`], but for the sections' CRCs and values.
    pub fn parse_trusting_sections(bytes: &'a [u8]) -> Result<Self, FvrsError> {
        Self::parse_with(bytes, false)
    }

    fn parse_with(bytes: &'a [u8], check_sections: bool) -> Result<Self, FvrsError> {
        if cfg!(target_endian = "big") {
            return Err(FvrsError::BigEndian);
        }
        let remainder = bytes.as_ptr() as usize % IMAGE_ALIGN;
        if remainder != 0 {
            return Err(FvrsError::Misaligned { remainder });
        }
        let got = bytes.len() as u64;
        if bytes.len() < at::HEADER_CRC {
            // Too short even for the version: say which of the two it is.
            if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
                return Err(if MAGIC.starts_with(bytes) {
                    FvrsError::Truncated {
                        what: "header",
                        needed: HEADER_LEN as u64,
                        got,
                    }
                } else {
                    FvrsError::BadMagic
                });
            }
        } else if bytes[..MAGIC.len()] != MAGIC {
            return Err(FvrsError::BadMagic);
        }
        if bytes.len() < HEADER_LEN {
            return Err(FvrsError::Truncated {
                what: "header",
                needed: HEADER_LEN as u64,
                got,
            });
        }
        let (major, minor) = (u16_at(bytes, at::MAJOR), u16_at(bytes, at::MINOR));
        if major != VERSION_MAJOR {
            return Err(FvrsError::Version { major, minor });
        }
        // Later minors append fields: the header may be longer, never shorter.
        let header_len = u32_at(bytes, at::HEADER_LEN) as u64;
        if header_len < HEADER_LEN as u64 || header_len % 8 != 0 {
            return Err(FvrsError::Field {
                field: "header length (at least 144, a multiple of 8)",
                value: header_len,
            });
        }
        if header_len > got {
            return Err(FvrsError::Truncated {
                what: "header",
                needed: header_len,
                got,
            });
        }
        let head = &bytes[..header_len as usize];
        let stored = u32_at(head, at::HEADER_CRC);
        let computed = header_crc(head);
        if stored != computed {
            return Err(FvrsError::Checksum {
                what: "header",
                stored,
                computed,
            });
        }
        let flags = u32_at(head, at::FLAGS);
        if flags != 0 {
            return Err(FvrsError::Field {
                field: "flags (none are defined in version 1)",
                value: flags as u64,
            });
        }
        check_zero(head, at::RESERVED..at::BETA, "reserved header")?;
        let header = Header::decode(head)?;
        let layout = header.layout_after(header_len)?;
        let file_len = u64_at(head, at::FILE_LEN);
        if file_len != layout.file_len {
            return Err(FvrsError::Section {
                what: "whole image",
                field: "length (file_len)",
                expected: layout.file_len,
                got: file_len,
            });
        }
        if got < file_len {
            return Err(FvrsError::Truncated {
                what: "file",
                needed: file_len,
                got,
            });
        }
        if got > file_len {
            return Err(FvrsError::TrailingBytes { file_len, got });
        }
        let names = ["spectrum", "kernel-table", "twiddle"];
        let sections = [layout.spectrum, layout.kernel, layout.twiddles];
        let mut end = header_len;
        for (i, (&what, &want)) in names.iter().zip(&sections).enumerate() {
            let e = at::SECTIONS + i * at::SECTION_ENTRY;
            let (offset, len) = (u64_at(head, e), u64_at(head, e + 8));
            for (field, expected, got) in
                [("offset", want.offset, offset), ("length", want.len, len)]
            {
                if expected != got {
                    return Err(FvrsError::Section {
                        what,
                        field,
                        expected,
                        got,
                    });
                }
            }
            check_zero(head, e + 20..e + 24, "reserved section-table")?;
            // The gap before the section (padding to 64 bytes) is zero.
            // (A longer header of a later minor ends where its length says.)
            if offset < end {
                return Err(FvrsError::Field {
                    field: "header length (overlaps the first section)",
                    value: header_len,
                });
            }
            check_zero(bytes, end as usize..offset as usize, "padding")?;
            end = offset + len;
            if !check_sections {
                continue;
            }
            let stored = u32_at(head, e + 16);
            let computed = crc32(slice(bytes, want));
            if stored != computed {
                return Err(FvrsError::Checksum {
                    what: [
                        "spectrum section",
                        "kernel-table section",
                        "twiddle section",
                    ][i],
                    stored,
                    computed,
                });
            }
        }
        Ok(Self {
            header,
            layout,
            minor,
            bytes,
        })
    }

    /// The header's fields.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// Where the sections lie.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The minor version of the file (the major is [`VERSION_MAJOR`]).
    pub fn minor_version(&self) -> u16 {
        self.minor
    }

    /// The f16 spectrum, in place.
    ///
    /// # Errors
    /// A file of another precision ([`FvrsError::PrecisionMismatch`]).
    pub fn spectrum_f16(&self) -> Result<Spectrum<'a, f16>, FvrsError> {
        self.expect(Precision::F16)?;
        let data: &'a [f16] = cast(slice(self.bytes, self.layout.spectrum))?;
        self.spectrum_of(data)
    }

    /// The f32 spectrum, in place.
    ///
    /// # Errors
    /// As [`Fvrs::spectrum_f16`].
    pub fn spectrum_f32(&self) -> Result<Spectrum<'a, f32>, FvrsError> {
        self.expect(Precision::F32)?;
        let data: &'a [f32] = cast(slice(self.bytes, self.layout.spectrum))?;
        self.spectrum_of(data)
    }

    /// The kernel table, copied out of the image (it is a fixed-size value).
    ///
    /// # Errors
    /// A NaN or infinite entry.
    pub fn kernel(&self) -> Result<KernelTable<f32>, FvrsError> {
        let values: &[f32] = cast(slice(self.bytes, self.layout.kernel))?;
        Ok(KernelTable::from_values(self.header.filter, values)?)
    }

    /// The twiddles for transforms up to `n`, in place.
    ///
    /// # Errors
    /// None for a parsed image (kept for tables of other origins).
    pub fn twiddles(&self) -> Result<Twiddles<'a, f32>, FvrsError> {
        let values: &'a [f32] = cast(slice(self.bytes, self.layout.twiddles))?;
        Ok(Twiddles::from_table(values, self.header.n)?)
    }

    /// Every coefficient finite ([`Spectrum::check_finite`]), every kernel
    /// entry finite, every twiddle in `[-1, 1]`: a file whose CRCs were
    /// made over bad values is refused here, once, not per view.
    fn check_values(&self) -> Result<(), FvrsError> {
        let spectrum = slice(self.bytes, self.layout.spectrum);
        match self.header.precision {
            Precision::F16 => self.spectrum_of(cast::<f16>(spectrum)?)?.check_finite()?,
            Precision::F32 => self.spectrum_of(cast::<f32>(spectrum)?)?.check_finite()?,
        }
        self.kernel()?;
        let values: &[f32] = cast(slice(self.bytes, self.layout.twiddles))?;
        if let Some(index) = values.iter().position(|v| v.is_nan() || v.abs() > 1.0) {
            return Err(FvrsError::Core(crate::Error::NonFiniteTableEntry {
                what: "twiddle table (|sin| <= 1)",
                index,
            }));
        }
        Ok(())
    }

    fn expect(&self, asked: Precision) -> Result<(), FvrsError> {
        if self.header.precision == asked {
            Ok(())
        } else {
            Err(FvrsError::PrecisionMismatch {
                file: self.header.precision.name(),
                asked: asked.name(),
            })
        }
    }

    fn spectrum_of<S: crate::num::Sample>(
        &self,
        data: &'a [S],
    ) -> Result<Spectrum<'a, S>, FvrsError> {
        let h = &self.header;
        Ok(Spectrum::from_parts(data, h.n, h.scale, h.filter, h.dims)?)
    }
}

/// The bytes of section `s` (within the image: checked by `parse`).
fn slice(bytes: &[u8], s: Section) -> &[u8] {
    &bytes[s.offset as usize..(s.offset + s.len) as usize]
}

/// `bytes` as values of `T`, read in place.
fn cast<T: bytemuck::AnyBitPattern>(bytes: &[u8]) -> Result<&[T], FvrsError> {
    // Sections start at multiples of 64 in an image aligned to 8 (checked),
    // and their lengths are whole values: this cannot fail, but says so if
    // it did rather than panicking.
    bytemuck::try_cast_slice(bytes).map_err(|_| FvrsError::Misaligned {
        remainder: bytes.as_ptr() as usize % IMAGE_ALIGN,
    })
}

/// `Ok` if `bytes[range]` is all zero, else the first non-zero byte.
fn check_zero(
    bytes: &[u8],
    range: core::ops::Range<usize>,
    what: &'static str,
) -> Result<(), FvrsError> {
    let start = range.start;
    match bytes[range].iter().position(|&b| b != 0) {
        None => Ok(()),
        Some(i) => Err(FvrsError::NonZero {
            what,
            offset: (start + i) as u64,
        }),
    }
}
