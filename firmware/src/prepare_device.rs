//! The device runtime of the preparation programs (`fvr-prepare` on the
//! Cortex-M4F, `fvr-prepare-m7` on the Cortex-M7): [`run`] and
//! [`prepare_main!`](crate::prepare_main). The spectrum and the view
//! buffers are statics in `.bss`, borrowed once in a critical section (the
//! spectrum is too large to pass through the stack, as `singleton!` would).
//!
//! Output, in QEMU's working directory: `<program>-spectrum.f16` (the
//! spectrum, little-endian f16, `x` fastest) and `<program>-image.nrrd`;
//! the counts, the scale and the spectrum's checksum go to the defmt log.

use crate::capture::ByteSink;
use crate::device::{calibrated_clock, exit_with, put_all, HostFile, RunError};
use crate::nrrd::{write_samples_le, Header};
use crate::prepare::{
    fnv1a_f16, prepare_and_render, spectrum_len, time_dht_3d, PrepBuffers, PrepInput,
};
use crate::stored::twiddles;

/// The names of the files a program writes on the host.
#[derive(Clone, Copy, Debug)]
pub struct OutputFiles {
    /// `<program>-spectrum.f16`.
    pub spectrum: &'static str,
    /// `<program>-image.nrrd`.
    pub image: &'static str,
}

/// Prepare `input`'s spectrum of side `N` in `bufs`, render the view from
/// it, write both to the host and log the counts; exit QEMU with status 0
/// (1 on any error).
pub fn run<const N: usize>(
    program: &str,
    files: OutputFiles,
    input: &PrepInput,
    bufs: PrepBuffers<'_>,
) -> ! {
    exit_with(program, run_inner::<N>(program, files, input, bufs))
}

fn run_inner<const N: usize>(
    program: &str,
    files: OutputFiles,
    input: &PrepInput,
    mut bufs: PrepBuffers<'_>,
) -> Result<(), RunError> {
    let mut clock = calibrated_clock()?;
    // The flash table serves every power of two up to the scene's side.
    let tw = twiddles()?;
    let prepared = prepare_and_render::<N, _>(input, &tw, &mut bufs, &clock)?;
    let spectrum = &bufs.spectrum[..spectrum_len(N)];
    let checksum = fnv1a_f16(spectrum);

    let mut file = HostFile::create(files.spectrum)?;
    put_all(&mut file, spectrum, |v| v.to_bits().to_le_bytes())?;
    let mut nrrd = HostFile::create(files.image)?;
    let header = Header::image_f32(
        1,
        N,
        N,
        format_args!("{program}: spectrum prepared and view rendered on the device"),
    )
    .map_err(|_| RunError::Host("NRRD header too long"))?;
    nrrd.put(header.as_bytes())
        .map_err(|_| RunError::Host("NRRD write"))?;
    write_samples_le(&bufs.grid[..N * N], |b| nrrd.put(b))
        .map_err(|_| RunError::Host("NRRD write"))?;

    let dht = time_dht_3d::<N, _>(&tw, &mut bufs, &clock)?;
    defmt::println!(
        "prepare {=str}: side {=usize}, scale 2^{=i32}, spectrum fnv1a {=u32:#010x}; preparation {=u64} instructions (3D DHT alone on a test signal {=u64}); render {=usize}x{=usize} view {=u64}",
        program,
        N,
        libm::ilogb(prepared.scale),
        checksum,
        prepared.counts.prepare,
        dht,
        N,
        N,
        prepared.counts.render
    );
    clock.finish()
}

/// The entry point of a preparation program, its statics (the spectrum of
/// side `$side` and the view buffers, in `.bss`) and the HardFault handler:
/// `prepare_main!(name, input, side)`.
#[macro_export]
macro_rules! prepare_main {
    ($program:expr, $input:expr, $side:expr) => {
        const SIDE: usize = $side;
        const CUBE: usize = $crate::prepare::spectrum_len(SIDE);
        const SCRATCH: usize = $crate::prepare::scratch_len(SIDE);
        const VIEW: (usize, usize) = $crate::prepare::view_lens(SIDE);

        type Ram<T> = cortex_m::interrupt::Mutex<core::cell::RefCell<T>>;
        static SPECTRUM: Ram<[fvr_core::f16; CUBE]> =
            Ram::new(core::cell::RefCell::new([fvr_core::f16::ZERO; CUBE]));
        static PREP_SCRATCH: Ram<[f32; SCRATCH]> =
            Ram::new(core::cell::RefCell::new([0.0; SCRATCH]));
        static GRID: Ram<[f32; VIEW.0]> = Ram::new(core::cell::RefCell::new([0.0; VIEW.0]));
        static AUX: Ram<[f32; VIEW.1]> = Ram::new(core::cell::RefCell::new([0.0; VIEW.1]));

        #[cortex_m_rt::entry]
        fn main() -> ! {
            // The program runs inside the critical section: it uses no
            // interrupts.
            cortex_m::interrupt::free(|cs| {
                let mut spectrum = SPECTRUM.borrow(cs).borrow_mut();
                let mut scratch = PREP_SCRATCH.borrow(cs).borrow_mut();
                let mut grid = GRID.borrow(cs).borrow_mut();
                let mut aux = AUX.borrow(cs).borrow_mut();
                let bufs = $crate::prepare::PrepBuffers {
                    spectrum: &mut spectrum[..],
                    scratch: &mut scratch[..],
                    grid: &mut grid[..],
                    aux: &mut aux[..],
                };
                $crate::prepare_device::run::<SIDE>(
                    $program,
                    $crate::prepare_device::OutputFiles {
                        spectrum: concat!($program, "-spectrum.f16"),
                        image: concat!($program, "-image.nrrd"),
                    },
                    &$input,
                    bufs,
                )
            })
        }

        $crate::hard_fault_handler!();
    };
}
