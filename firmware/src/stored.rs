//! The tables `build.rs` keeps in flash: the scene's f16 spectra (density
//! and, for lit frames, `|∇f|`), their kernel tables, the kernel-derivative
//! tables for linear depth cues and the twiddles, each made on the host by
//! the core (`Spectrum::prepare`, `gradient_magnitude`, `KernelTable::new`,
//! `DerivativeTable::new`, `Twiddles::new`), so the device evaluates no
//! Bessel series and no transform of the volume.

use fvr_core::dht::Twiddles;
use fvr_core::f16;
use fvr_core::filter::{DerivativeTable, Filter, FilterKind, KernelTable};
use fvr_core::spectrum::{Side, Spectrum};
use fvr_core::Result;

use crate::scene::{StoredKind, SIDE};

/// What a spectrum in flash, f16 ([`StoredSpectrum`]) or Q15
/// (`crate::stored_q15::StoredQ15`), was prepared with on the host.
#[derive(Debug)]
pub struct StoredHeader {
    /// Oversampling factor of the filter design.
    pub oversample: u32,
    /// Kaiser–Bessel β the volume was premultiplied for.
    pub beta: f64,
    /// The power-of-two scale `s` of the stored values.
    pub scale: f64,
    /// Side of the cube.
    pub n: usize,
    /// Dimensions of the original volume.
    pub dims: [usize; 3],
}

impl StoredHeader {
    /// The filter of `kind`, as designed on the host.
    ///
    /// # Errors
    /// A bad oversampling or β (not for tables made by `build.rs`).
    pub fn filter(&self, kind: FilterKind) -> Result<Filter> {
        Filter::from_parts(kind, self.oversample, self.beta)
    }
}

/// A spectrum in flash with what it takes to rebuild the core's objects.
#[derive(Debug)]
pub struct StoredSpectrum {
    /// What was transformed, and for which filter.
    pub kind: StoredKind,
    /// How it was prepared.
    pub header: StoredHeader,
    /// The coefficients `s·H`, `x` fastest.
    pub data: &'static [f16],
    /// The kernel, `k(i/1024)` for `i = 0 ..= W·512`.
    pub kernel: &'static [f32],
}

impl StoredSpectrum {
    /// The interpolation filter.
    pub fn filter_kind(&self) -> FilterKind {
        self.kind.filter()
    }

    /// The filter, as designed on the host.
    ///
    /// # Errors
    /// A bad oversampling or β (not for tables made by `build.rs`).
    pub fn filter(&self) -> Result<Filter> {
        self.header.filter(self.filter_kind())
    }

    /// The core's view of the spectrum.
    ///
    /// Its side is the scene's [`SIDE`], fixed at compile time
    /// (`Spectrum::with_side`): the extraction's index arithmetic folds to
    /// constants, with no bounds test per tap run.
    ///
    /// # Errors
    /// As `Spectrum::from_parts`; a side other than [`SIDE`].
    pub fn spectrum(&self) -> Result<Spectrum<'static, f16, Side<SIDE>>> {
        let h = &self.header;
        Spectrum::from_parts(self.data, h.n, h.scale, self.filter()?, h.dims)?.with_side::<SIDE>()
    }

    /// The kernel table, copied from flash (12 KiB of f32 at most).
    ///
    /// # Errors
    /// As `KernelTable::from_values`.
    pub fn kernel_table(&self) -> Result<KernelTable<f32>> {
        KernelTable::from_values(self.filter()?, self.kernel)
    }

    /// Bytes of flash the spectrum and its kernel table take (spectra of
    /// the same filter share one kernel table).
    pub fn flash_bytes(&self) -> usize {
        core::mem::size_of_val(self.data) + core::mem::size_of_val(self.kernel)
    }
}

/// A kernel-derivative table in flash (for frames with a linear depth cue).
#[derive(Debug)]
pub struct StoredDerivative {
    /// The interpolation filter.
    pub kind: FilterKind,
    /// Oversampling factor of the filter design.
    pub oversample: u32,
    /// Kaiser–Bessel β (the density spectrum's).
    pub beta: f64,
    /// `k'(i/1024)` for `i = 0 ..= W·512`.
    pub values: &'static [f32],
}

impl StoredDerivative {
    /// The filter, as designed on the host.
    ///
    /// # Errors
    /// A bad oversampling or β (not for tables made by `build.rs`).
    pub fn filter(&self) -> Result<Filter> {
        Filter::from_parts(self.kind, self.oversample, self.beta)
    }

    /// The derivative table, copied from flash (12 KiB of f32 at most).
    ///
    /// # Errors
    /// As `DerivativeTable::from_values`.
    pub fn table(&self) -> Result<DerivativeTable<f32>> {
        DerivativeTable::from_values(self.filter()?, self.values)
    }
}

/// The twiddles for transforms up to the scene's side.
///
/// # Errors
/// None for the generated table (its length is checked).
pub fn twiddles() -> Result<Twiddles<'static, f32>> {
    Twiddles::from_table(&TWIDDLES, SIDE)
}

/// Every stored spectrum, for the host-side checks. (Firmware programs name
/// the ones they use, so that the linker keeps only those.)
pub fn all() -> [&'static StoredSpectrum; 4] {
    [&DENSITY_KB3, &DENSITY_KB4, &DENSITY_KB6, &GRADIENT_KB3]
}

/// Every stored kernel-derivative table, for the host-side checks.
pub fn all_derivatives() -> [&'static StoredDerivative; 1] {
    [&DERIVATIVE_KB3]
}

/// Decode little-endian f16 bytes at compile time, so a spectrum lands in
/// flash as `[f16; N]` with no unsafe cast and no runtime copy.
const fn decode_f16<const N: usize, const B: usize>(bytes: &[u8; B]) -> [f16; N] {
    assert!(B == 2 * N, "a spectrum file holds 2 bytes per coefficient");
    let mut out = [f16::ZERO; N];
    let mut i = 0;
    while i < N {
        out[i] = f16::from_bits(u16::from_le_bytes([bytes[2 * i], bytes[2 * i + 1]]));
        i += 1;
    }
    out
}

include!(concat!(env!("OUT_DIR"), "/tables.rs"));
