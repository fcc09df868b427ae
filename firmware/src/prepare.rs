//! A spectrum prepared on the device: a u8 volume in flash
//! ([`crate::prep_volume`]) premultiplied, padded and transformed in place
//! in RAM by the core (`Spectrum::prepare`: f32 arithmetic, f16 storage
//! rounded after each pass), then the plain kb3 view rendered from it.
//!
//! [`prepare_and_render`] is the whole device program but its I/O; the host
//! tests run it too, on the same tables, for the bit-for-bit comparison.

use fvr_core::dht::{dht_3d, Twiddles};
use fvr_core::f16;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::image::{aux_len, grid_len};
use fvr_core::render::{render_in_grid, Request, Source};
use fvr_core::spectrum::{prepare_scratch_len, Spectrum};
use fvr_core::volume::DenseVolume;
use fvr_core::Result;

use crate::frame::InstructionClock;
use crate::scene::VIEW;

/// A u8 volume in flash with the filter designed for it on the host.
#[derive(Debug)]
pub struct PrepInput {
    /// Side of the volume (and of the cube: oversampling 1).
    pub side: usize,
    /// The filter (kb3), its oversampling and its Kaiser–Bessel β, from
    /// `Filter::fit` on the host for this volume.
    pub kind: FilterKind,
    /// Oversampling of the filter design.
    pub oversample: u32,
    /// Kaiser–Bessel β.
    pub beta: f64,
    /// `side³` voxels, `i` fastest ([`crate::prep_volume::voxel_u8`]).
    pub voxels: &'static [u8],
    /// The kernel, `k(i/1024)` for `i = 0 ..= W·512`, from
    /// `KernelTable::new` on the host.
    pub kernel: &'static [f32],
}

impl PrepInput {
    /// `[side; 3]`.
    pub fn dims(&self) -> [usize; 3] {
        [self.side; 3]
    }

    /// The core's view of the voxels.
    ///
    /// # Errors
    /// A voxel count other than `side³` (not for tables made by `build.rs`).
    pub fn volume(&self) -> Result<DenseVolume<'static, u8>> {
        DenseVolume::new(self.dims(), self.voxels)
    }

    /// The filter, as designed on the host.
    ///
    /// # Errors
    /// A bad oversampling or β (not for tables made by `build.rs`).
    pub fn filter(&self) -> Result<Filter> {
        Filter::from_parts(self.kind, self.oversample, self.beta)
    }

    /// The kernel table, copied from flash.
    ///
    /// # Errors
    /// As `KernelTable::from_values`.
    pub fn kernel_table(&self) -> Result<KernelTable<f32>> {
        KernelTable::from_values(self.filter()?, self.kernel)
    }
}

/// f16 elements of the spectrum of side `n`.
pub const fn spectrum_len(n: usize) -> usize {
    n * n * n
}

/// f32 elements of the preparation's scratch for side `n`.
pub const fn scratch_len(n: usize) -> usize {
    prepare_scratch_len(n)
}

/// Everything the program holds in RAM: the spectrum and the buffers of
/// the preparation and of one `n × n` view, whose image is cut into its
/// slice grid (`render_in_grid`: no image buffer of its own).
#[derive(Debug)]
pub struct PrepBuffers<'a> {
    /// The cube, [`spectrum_len`]: the padded volume, then its spectrum.
    pub spectrum: &'a mut [f16],
    /// The preparation's scratch, [`scratch_len`].
    pub scratch: &'a mut [f32],
    /// The view's slice grid, `n²`, and then its `n × n` image.
    pub grid: &'a mut [f32],
    /// The view's auxiliary scratch, `4n`.
    pub aux: &'a mut [f32],
}

/// Elements of the view buffers for side `n`: `(grid, aux)`.
pub const fn view_lens(n: usize) -> (usize, usize) {
    (grid_len(n), aux_len(n))
}

/// Instruction counts of a device preparation ([`prepare_and_render`],
/// `crate::prepare_q15::prepare_and_render_q15`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PrepCounts {
    /// The preparation: for f16, `Spectrum::prepare` (premultiplier table,
    /// the volume's bound, premultiplication and placement, and the 3D
    /// DHT).
    pub prepare: u64,
    /// The `n × n` plain view rendered from the spectrum.
    pub render: u64,
}

/// The result of [`prepare_and_render`]: the spectrum is in
/// [`PrepBuffers::spectrum`], the image in [`PrepBuffers::grid`]`[..n²]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prepared {
    /// The spectrum's power-of-two scale `s`.
    pub scale: f64,
    /// Instruction counts.
    pub counts: PrepCounts,
}

/// Prepare `input`'s spectrum in place in `bufs.spectrum` (side `N`), then
/// render the scene's view ([`VIEW`], `N × N` pixels) from it into
/// `bufs.grid[..N²]`, counting instructions with `clock`.
///
/// # Errors
/// The core's: short buffers, twiddles too short, a side other than `N`.
pub fn prepare_and_render<const N: usize, C: InstructionClock>(
    input: &PrepInput,
    tw: &Twiddles<'_, f32>,
    bufs: &mut PrepBuffers<'_>,
    clock: &C,
) -> Result<Prepared> {
    let volume = input.volume()?;
    let filter = input.filter()?;
    let t0 = clock.now();
    let spectrum = Spectrum::prepare(&volume, filter, &mut *bufs.spectrum, bufs.scratch, tw)?;
    let t1 = clock.now();
    let spectrum = spectrum.with_side::<N>()?;
    let kernel = input.kernel_table();
    let kernel = kernel.as_ref().map_err(|e| *e)?;
    let t2 = clock.now();
    render_in_grid(
        &Source::new(&spectrum, kernel, tw),
        &Request::new(VIEW, N, N),
        bufs.grid,
        bufs.aux,
    )?;
    let t3 = clock.now();
    Ok(Prepared {
        scale: spectrum.scale(),
        counts: PrepCounts {
            prepare: t1 - t0,
            render: t3 - t2,
        },
    })
}

/// The 3D DHT alone, timed on a test signal in `bufs.spectrum` (overwritten):
/// an impulse of `2^13` at `x = 1`, whose spectrum `2^13·cas(2πu/N)` stays
/// within f16's range. The f16 rounding's cost depends slightly on the
/// values, so this splits [`PrepCounts::prepare`] only approximately.
///
/// # Errors
/// As `dht_3d`.
pub fn time_dht_3d<const N: usize, C: InstructionClock>(
    tw: &Twiddles<'_, f32>,
    bufs: &mut PrepBuffers<'_>,
    clock: &C,
) -> Result<u64> {
    let cube = &mut bufs.spectrum[..spectrum_len(N)];
    time_on_impulse(cube, f16::from_f32(8192.0), clock, |cube| {
        dht_3d(cube, [N; 3], bufs.scratch, tw)
    })
}

/// The instructions `transform` takes on the test signal of the device
/// preparations in `cube` (overwritten): `impulse` at `x = 1`, zero
/// elsewhere.
///
/// # Errors
/// As `transform`.
pub fn time_on_impulse<S: Copy + Default, R, C: InstructionClock>(
    cube: &mut [S],
    impulse: S,
    clock: &C,
    transform: impl FnOnce(&mut [S]) -> Result<R>,
) -> Result<u64> {
    cube.fill(S::default());
    cube[1] = impulse;
    let t0 = clock.now();
    transform(cube)?;
    Ok(clock.now() - t0)
}

/// FNV-1a (32 bits) over the little-endian bytes of `values`' bit patterns:
/// a checksum of a spectrum the device logs and the host recomputes.
pub fn fnv1a_f16(values: &[f16]) -> u32 {
    fnv1a(values.iter().flat_map(|v| v.to_bits().to_le_bytes()))
}

/// FNV-1a (32 bits) over `bytes`: the checksum of the device preparations'
/// spectra.
pub fn fnv1a(bytes: impl IntoIterator<Item = u8>) -> u32 {
    let mut h: u32 = 0x811C_9DC5;
    for b in bytes {
        h ^= b as u32;
        h = h.wrapping_mul(0x0100_0193);
    }
    h
}

include!(concat!(env!("OUT_DIR"), "/prep_tables.rs"));
