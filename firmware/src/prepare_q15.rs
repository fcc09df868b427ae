//! A Q15 spectrum prepared on the device: the u8 volume in flash
//! ([`crate::prep_volume`]) premultiplied, padded and transformed in place
//! in RAM in integers (`Spectrum::prepare_q15`: fixed-point
//! premultipliers, one rounding to Q15, `dht::fixed::dht_3d_lines`, one
//! exponent per x-line), then the plain kb3 view rendered from it in
//! integers (`render::fixed::render_fixed`, as the Cortex-M3's view).
//!
//! [`prepare_and_render_q15`] is the whole device program but its I/O;
//! the host tests run it too, on the same tables, for the bit-for-bit
//! comparison.

use fvr_core::dht::fixed::{dht_3d_lines, FixedTwiddles};
use fvr_core::image::fixed::fixed_aux_len;
use fvr_core::num::Q15;
use fvr_core::render::fixed::{render_fixed_in_block, FixedSource};
use fvr_core::slice::fixed::FixedPhases;
use fvr_core::spectrum::{Q15Storage, Spectrum};
use fvr_core::Result;

use crate::frame::InstructionClock;
use crate::prepare::{fnv1a, time_on_impulse, PrepCounts, PrepInput};
use crate::scene::VIEW;

/// Width of the kb3 filter the programs prepare for.
pub const WIDTH: usize = 3;

/// Entries of a Q15 twiddle table serving the flash table's length.
pub const TWIDDLES_LEN: usize = FixedTwiddles::<i16>::buffer_len(TWIDDLE_SIDE);

/// Everything the program holds in RAM for side `n`: the cube, its
/// exponents and premultipliers (the core's [`Q15Storage`]), and the
/// buffers of one `n × n` integer view, whose image is cut into its Q15
/// block (`render_fixed_in_block`: no image buffer of its own).
#[derive(Debug)]
pub struct Q15Buffers<'a> {
    /// Where `Spectrum::prepare_q15` works and leaves the spectrum.
    pub storage: Q15Storage<'a, 'a>,
    /// The view's `i32` slice, `n²`.
    pub grid: &'a mut [i32],
    /// The view's auxiliary scratch, `4n`.
    pub aux: &'a mut [i32],
    /// The view's Q15 block, `n²`, and then its `n × n` image.
    pub block: &'a mut [i16],
}

/// Elements of [`Q15Buffers`] for side `n`: `(cube, exponents, premul,
/// grid, aux)`; the block takes `n²` like the grid.
pub const fn q15_lens(n: usize) -> (usize, usize, usize, usize, usize) {
    (n * n * n, n * n, n, n * n, fixed_aux_len(n))
}

/// The result of [`prepare_and_render_q15`]: the spectrum is in
/// [`Q15Buffers::storage`] (mantissas and exponents), the image in
/// [`Q15Buffers::block`]`[..n²]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreparedQ15 {
    /// The spectrum's power-of-two scale `s`.
    pub scale: f64,
    /// The image's exponent: pixel `i` is `image[i]·2^e`.
    pub image_exponent: i32,
    /// Instruction counts: `Spectrum::prepare_q15` (premultipliers in soft
    /// float, `2n` filter responses; the two integer passes over the
    /// volume, the 3D DHT and the lines' normalization) and the integer
    /// view.
    pub counts: PrepCounts,
}

/// The Q15 twiddles for the data (as [`Q15`]) from the flash table, in
/// `buf`.
///
/// # Errors
/// As `FixedTwiddles::from_table` (not for the table `build.rs` makes).
pub fn twiddles_q15(buf: &mut [Q15; TWIDDLES_LEN]) -> Result<FixedTwiddles<'_, Q15>> {
    for (q, &m) in buf.iter_mut().zip(TWIDDLES_Q15.iter()) {
        *q = Q15(m);
    }
    FixedTwiddles::from_table(buf, TWIDDLE_SIDE)
}

/// The Q15 twiddles of the view's inverse, from the flash table.
///
/// # Errors
/// As `FixedTwiddles::from_table`.
pub fn twiddles_i16() -> Result<FixedTwiddles<'static, i16>> {
    FixedTwiddles::from_table(&TWIDDLES_Q15, TWIDDLE_SIDE)
}

/// Prepare `input`'s Q15 spectrum in place in `bufs` (side `N`), then
/// render the scene's view ([`VIEW`], `N × N` pixels) from it in integers
/// into `bufs.block[..N²]`, counting instructions with `clock`. `phases`
/// is the kb3 phase table of `input`'s filter.
///
/// # Errors
/// The core's: short buffers, twiddles too short, a side other than `N`.
pub fn prepare_and_render_q15<const N: usize, C: InstructionClock>(
    input: &PrepInput,
    (tw_data, tw_view): (&FixedTwiddles<'_, Q15>, &FixedTwiddles<'_, i16>),
    phases: &FixedPhases<WIDTH>,
    bufs: &mut Q15Buffers<'_>,
    clock: &C,
) -> Result<PreparedQ15> {
    let volume = input.volume()?;
    let filter = input.filter()?;
    let t0 = clock.now();
    let spectrum = Spectrum::prepare_q15(&volume, filter, bufs.storage.reborrow(), tw_data)?;
    let t1 = clock.now();
    let spectrum = spectrum.with_side::<N>()?;
    let source = FixedSource {
        spectrum: &spectrum,
        phases,
        twiddles: tw_view,
    };
    let t2 = clock.now();
    let image_exponent = render_fixed_in_block(
        &source,
        &VIEW,
        (N, N),
        &mut *bufs.grid,
        &mut *bufs.aux,
        &mut *bufs.block,
    )?;
    let t3 = clock.now();
    Ok(PreparedQ15 {
        scale: spectrum.scale(),
        image_exponent,
        counts: PrepCounts {
            prepare: t1 - t0,
            render: t3 - t2,
        },
    })
}

/// The 3D DHT alone (`dht_3d_lines`), timed on a test signal in
/// `bufs.storage.mantissas` (overwritten): an impulse of `2^13` at `x = 1`. Its
/// cost depends little on the values (the scaling shifts), so this splits
/// [`PrepCounts::prepare`] closely, not exactly.
///
/// # Errors
/// As `dht_3d_lines`.
pub fn time_dht_3d_q15<const N: usize, C: InstructionClock>(
    tw: &FixedTwiddles<'_, Q15>,
    bufs: &mut Q15Buffers<'_>,
    clock: &C,
) -> Result<u64> {
    let Q15Storage {
        mantissas,
        exponents,
        ..
    } = &mut bufs.storage;
    time_on_impulse(&mut mantissas[..N * N * N], Q15(1 << 13), clock, |cube| {
        dht_3d_lines(cube, [N; 3], &mut exponents[..N * N], tw)
    })
}

/// FNV-1a (32 bits) over the little-endian mantissas, then the exponents:
/// the checksum the device logs and the host recomputes.
pub fn fnv1a_q15(mantissas: &[Q15], exponents: &[i8]) -> u32 {
    fnv1a(
        mantissas
            .iter()
            .flat_map(|m| m.0.to_le_bytes())
            .chain(exponents.iter().map(|&e| e as u8)),
    )
}

/// The longest transform the flash table serves (`fvr-fixed-bench`'s side).
const TWIDDLE_SIDE: usize = 64;

#[allow(dead_code)]
mod tables {
    include!(concat!(env!("OUT_DIR"), "/fixed_tables.rs"));
}
use tables::TWIDDLES_Q15;
