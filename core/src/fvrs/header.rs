//! The header's fields, their codes and byte offsets, and the section
//! layout they imply (`docs/fvrs.md`, "Header").

use super::error::FvrsError;
use super::{align_up, kernel_entries, twiddle_entries, HEADER_LEN};
use crate::filter::{Filter, FilterKind};
use crate::volume::check_side;

/// How the spectrum's coefficients are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// IEEE binary16, rendered in f32 arithmetic.
    F16,
    /// IEEE binary32.
    F32,
}

impl Precision {
    /// The header's code.
    pub const fn code(self) -> u8 {
        match self {
            Precision::F16 => 1,
            Precision::F32 => 2,
        }
    }

    /// Bytes per coefficient.
    pub const fn bytes(self) -> usize {
        match self {
            Precision::F16 => 2,
            Precision::F32 => 4,
        }
    }

    /// `f16` or `f32`.
    pub const fn name(self) -> &'static str {
        match self {
            Precision::F16 => "f16",
            Precision::F32 => "f32",
        }
    }

    fn from_code(code: u8) -> Option<Self> {
        [Precision::F16, Precision::F32]
            .into_iter()
            .find(|p| p.code() == code)
    }
}

/// The part a file was prepared and budgeted for (informational: any
/// reader renders any part's file).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// A host computer: no memory budget.
    Host,
    /// Cortex-M4F (`memory.x` in the workspace root).
    M4f,
    /// Cortex-M3, no FPU (`firmware/memory-m3.x`).
    M3,
    /// Cortex-M7 (`firmware/memory-m7.x`).
    M7,
}

impl Part {
    /// Every part, in code order.
    pub const ALL: [Part; 4] = [Part::Host, Part::M4f, Part::M3, Part::M7];

    /// The header's code.
    pub const fn code(self) -> u8 {
        match self {
            Part::Host => 0,
            Part::M4f => 1,
            Part::M3 => 2,
            Part::M7 => 3,
        }
    }

    /// `host`, `m4f`, `m3` or `m7`.
    pub const fn name(self) -> &'static str {
        match self {
            Part::Host => "host",
            Part::M4f => "m4f",
            Part::M3 => "m3",
            Part::M7 => "m7",
        }
    }

    /// The part named `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    fn from_code(code: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.code() == code)
    }
}

/// A filter's code: its index in [`FilterKind::ALL`].
fn filter_code(kind: FilterKind) -> u8 {
    FilterKind::ALL.iter().position(|&k| k == kind).unwrap_or(0) as u8
}

/// Where a section lies in the image, in bytes from its start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Section {
    /// Offset of the first byte (a multiple of [`super::SECTION_ALIGN`]).
    pub offset: u64,
    /// Length in bytes.
    pub len: u64,
}

impl Section {
    fn end(self) -> Option<u64> {
        self.offset.checked_add(self.len)
    }
}

/// The three sections and the image's length a header implies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// The spectrum, `n³` coefficients.
    pub spectrum: Section,
    /// The kernel table, f32.
    pub kernel: Section,
    /// The quarter-wave twiddles, f32.
    pub twiddles: Section,
    /// Bytes of the whole image (the end of the last section).
    pub file_len: u64,
}

/// What a file describes: everything but the section offsets and
/// checksums, which follow from it ([`Header::layout`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Header {
    /// Storage of the coefficients.
    pub precision: Precision,
    /// The filter the volume was premultiplied for.
    pub filter: Filter,
    /// The part the file was budgeted for.
    pub part: Part,
    /// The cube side: a power of two, the padded size of `dims`.
    pub n: usize,
    /// The volume's dimensions.
    pub dims: [usize; 3],
    /// The stored values' scale `s` (a power of two).
    pub scale: f64,
}

/// Byte offsets of the header's fields (`docs/fvrs.md`).
pub(crate) mod at {
    pub const MAGIC: usize = 0;
    pub const MAJOR: usize = 8;
    pub const MINOR: usize = 10;
    pub const HEADER_CRC: usize = 12;
    pub const HEADER_LEN: usize = 16;
    pub const FLAGS: usize = 20;
    pub const FILE_LEN: usize = 24;
    pub const PRECISION: usize = 32;
    pub const FILTER: usize = 33;
    pub const OVERSAMPLE: usize = 34;
    pub const PART: usize = 35;
    pub const N: usize = 36;
    pub const DIMS: usize = 40;
    pub const RESERVED: usize = 52;
    pub const BETA: usize = 56;
    pub const SCALE: usize = 64;
    /// Three entries of 24 bytes: offset u64, length u64, CRC-32 u32,
    /// reserved u32 (zero).
    pub const SECTIONS: usize = 72;
    pub const SECTION_ENTRY: usize = 24;
}

impl Header {
    /// The sections this header implies: spectrum, kernel table and
    /// twiddles, in that order, each at the next multiple of 64 bytes.
    ///
    /// # Errors
    /// A side that does not suit the dims and filter, a side that is not a
    /// power of two, a scale that is not a positive finite power of two,
    /// or sizes beyond `u64`.
    pub fn layout(&self) -> Result<Layout, FvrsError> {
        self.layout_after(HEADER_LEN as u64)
    }

    /// [`Header::layout`] after a header of `header_len` bytes (longer in
    /// later minor versions).
    pub(crate) fn layout_after(&self, header_len: u64) -> Result<Layout, FvrsError> {
        check_side(self.dims, self.filter.oversample(), self.n).map_err(FvrsError::Core)?;
        if !self.n.is_power_of_two() {
            return Err(FvrsError::Field {
                field: "cube side n (must be a power of two)",
                value: self.n as u64,
            });
        }
        let s = self.scale;
        if !(s.is_finite() && s > 0.0 && libm::frexp(s).0 == 0.5) {
            return Err(FvrsError::Number {
                field: "scale (must be a positive finite power of two)",
                value: s,
            });
        }
        let too_big = FvrsError::Field {
            field: "cube side n (the image would exceed 2^64 bytes)",
            value: self.n as u64,
        };
        let n = self.n as u64;
        let spectrum_len = n
            .checked_mul(n)
            .and_then(|v| v.checked_mul(n))
            .and_then(|v| v.checked_mul(self.precision.bytes() as u64))
            .ok_or(too_big)?;
        let place = |after: u64, len: u64| -> Result<Section, FvrsError> {
            let offset = align_up(after).ok_or(too_big)?;
            let s = Section { offset, len };
            s.end().ok_or(too_big).map(|_| s)
        };
        let spectrum = place(header_len, spectrum_len)?;
        let kernel = place(
            spectrum.offset + spectrum.len,
            4 * kernel_entries(&self.filter) as u64,
        )?;
        let twiddles = place(
            kernel.offset + kernel.len,
            4 * twiddle_entries(self.n) as u64,
        )?;
        Ok(Layout {
            spectrum,
            kernel,
            twiddles,
            file_len: twiddles.offset + twiddles.len,
        })
    }

    /// The header's bytes for `layout` and the sections' CRC-32s
    /// (spectrum, kernel, twiddles), with its own CRC filled in.
    pub(crate) fn encode(&self, layout: &Layout, crcs: [u32; 3]) -> [u8; HEADER_LEN] {
        let mut h = [0u8; HEADER_LEN];
        h[at::MAGIC..at::MAGIC + 8].copy_from_slice(&super::MAGIC);
        put(&mut h, at::MAJOR, &super::VERSION_MAJOR.to_le_bytes());
        put(&mut h, at::MINOR, &super::VERSION_MINOR.to_le_bytes());
        put(&mut h, at::HEADER_LEN, &(HEADER_LEN as u32).to_le_bytes());
        put(&mut h, at::FILE_LEN, &layout.file_len.to_le_bytes());
        h[at::PRECISION] = self.precision.code();
        h[at::FILTER] = filter_code(self.filter.kind());
        h[at::OVERSAMPLE] = self.filter.oversample() as u8;
        h[at::PART] = self.part.code();
        put(&mut h, at::N, &(self.n as u32).to_le_bytes());
        for (a, d) in self.dims.iter().enumerate() {
            put(&mut h, at::DIMS + 4 * a, &(*d as u32).to_le_bytes());
        }
        put(&mut h, at::BETA, &self.filter.beta().to_le_bytes());
        put(&mut h, at::SCALE, &self.scale.to_le_bytes());
        let sections = [layout.spectrum, layout.kernel, layout.twiddles];
        for (i, (s, crc)) in sections.iter().zip(crcs).enumerate() {
            let e = at::SECTIONS + i * at::SECTION_ENTRY;
            put(&mut h, e, &s.offset.to_le_bytes());
            put(&mut h, e + 8, &s.len.to_le_bytes());
            put(&mut h, e + 16, &crc.to_le_bytes());
        }
        let crc = header_crc(&h);
        put(&mut h, at::HEADER_CRC, &crc.to_le_bytes());
        h
    }

    /// Decode the fields of a header whose magic, version, length and CRC
    /// have been checked.
    pub(crate) fn decode(h: &[u8]) -> Result<Self, FvrsError> {
        let code = |field: &'static str, value: u8| FvrsError::Field {
            field,
            value: value as u64,
        };
        let precision = Precision::from_code(h[at::PRECISION])
            .ok_or(code("precision code", h[at::PRECISION]))?;
        let kind = FilterKind::ALL
            .get(h[at::FILTER] as usize)
            .copied()
            .ok_or(code("filter code", h[at::FILTER]))?;
        let oversample = h[at::OVERSAMPLE];
        if oversample != 1 && oversample != 2 {
            return Err(code("oversample (must be 1 or 2)", oversample));
        }
        let part = Part::from_code(h[at::PART]).ok_or(code("part code", h[at::PART]))?;
        let beta = f64_at(h, at::BETA);
        if !(beta.is_finite() && beta >= 0.0) {
            return Err(FvrsError::Number {
                field: "Kaiser-Bessel beta (must be finite and not negative)",
                value: beta,
            });
        }
        let filter = Filter::from_parts(kind, oversample as u32, beta).map_err(FvrsError::Core)?;
        let header = Header {
            precision,
            filter,
            part,
            n: u32_at(h, at::N) as usize,
            dims: [0, 1, 2].map(|a| u32_at(h, at::DIMS + 4 * a) as usize),
            scale: f64_at(h, at::SCALE),
        };
        Ok(header)
    }
}

/// The CRC-32 of a header's bytes with its CRC field read as zero.
pub(crate) fn header_crc(h: &[u8]) -> u32 {
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&h[..at::HEADER_CRC]);
    hasher.update(&[0; 4]);
    hasher.update(&h[at::HEADER_CRC + 4..]);
    hasher.finalize()
}

fn put(h: &mut [u8], at: usize, bytes: &[u8]) {
    h[at..at + bytes.len()].copy_from_slice(bytes);
}

pub(crate) fn u16_at(h: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([h[at], h[at + 1]])
}

pub(crate) fn u32_at(h: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([h[at], h[at + 1], h[at + 2], h[at + 3]])
}

pub(crate) fn u64_at(h: &[u8], at: usize) -> u64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&h[at..at + 8]);
    u64::from_le_bytes(b)
}

fn f64_at(h: &[u8], at: usize) -> f64 {
    f64::from_bits(u64_at(h, at))
}
