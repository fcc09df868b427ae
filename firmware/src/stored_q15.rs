//! The Q15 spectrum of the Cortex-M3's integer view: the scene's kb3
//! density spectrum with one block exponent per x-line, made by `build.rs`
//! on the host (prepared in f64 by the core and rounded once), kept in
//! flash: 512 KiB of mantissas and 4 KiB of exponents.

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::num::{BlockExponents, BlockLayout, Q15};
use fvr_core::spectrum::{Side, Spectrum};
use fvr_core::Result;

use crate::scene::SIDE;
use crate::stored::StoredHeader;

/// A Q15 line-block spectrum in flash.
#[derive(Debug)]
pub struct StoredQ15 {
    /// How it was prepared (for kb3).
    pub header: StoredHeader,
    /// The mantissas, `x` fastest.
    pub data: &'static [Q15],
    /// One exponent per x-line.
    pub exponents: &'static [i8],
}

impl StoredQ15 {
    /// The kb3 filter, as designed on the host.
    ///
    /// # Errors
    /// A bad oversampling or β (not for tables made by `build.rs`).
    pub fn filter(&self) -> Result<Filter> {
        self.header.filter(FilterKind::Kb3)
    }

    /// The core's view of the spectrum, its side fixed at compile time.
    ///
    /// # Errors
    /// As `Spectrum::from_blocks`; a side other than [`SIDE`].
    pub fn spectrum(&self) -> Result<Spectrum<'static, Q15, Side<SIDE>>> {
        let h = &self.header;
        let blocks = BlockExponents::new(BlockLayout::Line, self.exponents, h.n)?;
        Spectrum::from_blocks(self.data, blocks, h.n, h.scale, self.filter()?, h.dims)?
            .with_side::<SIDE>()
    }

    /// Bytes of flash the mantissas and exponents take.
    pub fn flash_bytes(&self) -> usize {
        core::mem::size_of_val(self.data) + self.exponents.len()
    }
}

/// Decode little-endian i16 mantissas at compile time.
const fn decode_q15<const N: usize, const B: usize>(bytes: &[u8; B]) -> [Q15; N] {
    assert!(
        B == 2 * N,
        "a Q15 spectrum file holds 2 bytes per coefficient"
    );
    let mut out = [Q15(0); N];
    let mut i = 0;
    while i < N {
        out[i] = Q15(i16::from_le_bytes([bytes[2 * i], bytes[2 * i + 1]]));
        i += 1;
    }
    out
}

/// Decode exponents (one byte each) at compile time.
const fn decode_i8<const N: usize>(bytes: &[u8; N]) -> [i8; N] {
    let mut out = [0i8; N];
    let mut i = 0;
    while i < N {
        out[i] = bytes[i] as i8;
        i += 1;
    }
    out
}

include!(concat!(env!("OUT_DIR"), "/q15_tables.rs"));
