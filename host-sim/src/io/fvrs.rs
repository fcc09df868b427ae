//! The host's `.fvrs` writer: a prepared spectrum, its kernel table and
//! twiddles as one image (`docs/fvrs.md`), made by
//! [`fvr_core::fvrs::write`], and its reader for files (into 8-byte-aligned
//! memory, as [`Fvrs::parse`] requires).

use std::path::Path;

use fvr_core::dht::Twiddles;
use fvr_core::filter::KernelTable;
use fvr_core::fvrs::{write, write_len, Fvrs, Header, Part, Precision};
use fvr_core::spectrum::Spectrum;
use fvr_engine::spectrum::AnySpectrum;

/// The `.fvrs` image of `spectrum`, budgeted for `part`.
///
/// # Errors
/// An f64 spectrum (the format stores f16 or f32), or the writer's refusals.
pub fn image(spectrum: &AnySpectrum, part: Part) -> Result<Vec<u8>, String> {
    match spectrum {
        AnySpectrum::F16(s) => image_of(&s.view(), Precision::F16, part),
        AnySpectrum::F32(s) => image_of(&s.view(), Precision::F32, part),
        AnySpectrum::F64(_) => {
            Err(".fvrs files store f16 or f32 spectra, not f64: use --precision f16 or f32".into())
        }
    }
}

/// The image of a spectrum whose coefficients are `precision` values.
fn image_of<S: bytemuck::NoUninit + fvr_core::num::Sample>(
    spec: &Spectrum<'_, S>,
    precision: Precision,
    part: Part,
) -> Result<Vec<u8>, String> {
    let header = Header {
        precision,
        filter: *spec.filter(),
        part,
        n: spec.n(),
        dims: spec.dims(),
        scale: spec.scale(),
    };
    let kernel = KernelTable::<f32>::new(header.filter);
    let mut twiddles = vec![0f32; Twiddles::<f32>::buffer_len(header.n)];
    Twiddles::new(&mut twiddles, header.n).map_err(|e| e.to_string())?;
    let mut out = vec![0u8; write_len(&header).map_err(|e| e.to_string())?];
    let bytes: &[u8] = bytemuck::cast_slice(spec.data());
    write(&header, bytes, kernel.values(), &twiddles, &mut out).map_err(|e| e.to_string())?;
    Ok(out)
}

/// An image read from `path` into 8-byte-aligned memory, checked.
pub struct FvrsFile {
    words: Vec<u64>,
    len: usize,
}

impl FvrsFile {
    /// Read and check `path` (every field, length and CRC).
    ///
    /// # Errors
    /// One line naming the file and what is wrong with it.
    pub fn read(path: &Path) -> Result<Self, String> {
        use std::io::Read;
        let fail = |e: std::io::Error| format!("cannot read `{}`: {e}", path.display());
        // Straight into aligned memory: one pass over the bytes, not a read
        // and a copy (a prepared CT head is 32 MiB).
        let mut f = std::fs::File::open(path).map_err(fail)?;
        let len = usize::try_from(f.metadata().map_err(fail)?.len())
            .map_err(|_| format!("`{}` is too large for this machine", path.display()))?;
        // The image, and the owned copy of its spectrum a renderer takes.
        let mut budget = crate::budget::Budget::new();
        budget.hold("the .fvrs image", len as u64, 1).hold(
            "its spectrum, copied for rendering",
            len as u64,
            1,
        );
        budget
            .check(crate::budget::limit(), "raise --max-memory or free memory")
            .map_err(|e| format!("`{}`: {e}", path.display()))?;
        let mut words = vec![0u64; len.div_ceil(8)];
        f.read_exact(&mut bytemuck::cast_slice_mut::<u64, u8>(&mut words)[..len])
            .map_err(fail)?;
        let file = Self { words, len };
        Fvrs::parse(file.bytes()).map_err(|e| format!("`{}`: {e}", path.display()))?;
        Ok(file)
    }

    /// `bytes` copied into aligned memory (not checked).
    pub fn from_bytes(bytes: &[u8]) -> Self {
        let mut words = vec![0u64; bytes.len().div_ceil(8)];
        bytemuck::cast_slice_mut::<u64, u8>(&mut words)[..bytes.len()].copy_from_slice(bytes);
        Self {
            words,
            len: bytes.len(),
        }
    }

    /// The image's bytes, 8-byte aligned.
    pub fn bytes(&self) -> &[u8] {
        &bytemuck::cast_slice(&self.words)[..self.len]
    }

    /// The checked image.
    ///
    /// # Errors
    /// As [`Fvrs::parse`].
    pub fn parse(&self) -> Result<Fvrs<'_>, fvr_core::fvrs::FvrsError> {
        Fvrs::parse(self.bytes())
    }

    /// The image [`FvrsFile::read`] checked, without checking its sections
    /// again ([`Fvrs::parse_trusting_sections`]: the header's checks, in
    /// O(1)). For an image made by [`FvrsFile::from_bytes`], use
    /// [`FvrsFile::parse`].
    ///
    /// # Errors
    /// As [`Fvrs::parse_trusting_sections`].
    pub fn parse_read(&self) -> Result<Fvrs<'_>, fvr_core::fvrs::FvrsError> {
        Fvrs::parse_trusting_sections(self.bytes())
    }
}
