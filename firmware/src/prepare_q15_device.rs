//! The device runtime of the Q15 preparation programs
//! (`fvr-prepare-q15`, `fvr-prepare-q15-m7`): [`run`] and
//! [`prepare_q15_main!`](crate::prepare_q15_main). The cube, the phase
//! table and the view buffers are statics in `.bss`, borrowed once in a
//! critical section; the kernel is read in flash and the image is cut
//! into the view's Q15 block, so nothing large sits on the stack.
//!
//! Output, in QEMU's working directory: `<program>-spectrum.q15` (the
//! `n²` exponents, then the `n³` mantissas, little-endian, `x` fastest) and
//! `<program>-image.q15` (the image's exponent as `i32`, then its `n²`
//! mantissas); the counts, the scale and the spectrum's checksum go to the
//! defmt log.

use fvr_core::num::Q15;
use fvr_core::slice::fixed::FixedPhases;

use crate::capture::ByteSink;
use crate::device::{calibrated_clock, exit_with, put_all, HostFile, RunError};
use crate::frame::InstructionClock;
use crate::prepare::PrepInput;
use crate::prepare_q15::{
    fnv1a_q15, prepare_and_render_q15, time_dht_3d_q15, twiddles_i16, twiddles_q15, Q15Buffers,
    TWIDDLES_LEN, WIDTH,
};

/// Prepare `input`'s Q15 spectrum of side `N` in `bufs`, render the view
/// from it, write both to the host and log the counts; exit QEMU with
/// status 0 (1 on any error). `phases` is filled here, from the kernel in
/// flash.
pub fn run<const N: usize>(
    program: &str,
    files: (&str, &str),
    input: &PrepInput,
    phases: &mut FixedPhases<WIDTH>,
    bufs: Q15Buffers<'_>,
) -> ! {
    exit_with(program, run_inner::<N>(program, files, input, phases, bufs))
}

fn run_inner<const N: usize>(
    program: &str,
    (spectrum_file, image_file): (&str, &str),
    input: &PrepInput,
    phases: &mut FixedPhases<WIDTH>,
    mut bufs: Q15Buffers<'_>,
) -> Result<(), RunError> {
    let mut clock = calibrated_clock()?;
    let mut tw_buf = [Q15(0); TWIDDLES_LEN];
    let tw_data = twiddles_q15(&mut tw_buf)?;
    let tw_view = twiddles_i16()?;
    // Once per filter: the Q15 phase table from the f32 kernel, read in
    // flash.
    let t0 = clock.now();
    phases.fill_from(input.filter()?, input.kernel)?;
    let phase_count = clock.now() - t0;

    let prepared =
        prepare_and_render_q15::<N, _>(input, (&tw_data, &tw_view), phases, &mut bufs, &clock)?;
    let (mantissas, exponents) = (
        &bufs.storage.mantissas[..N * N * N],
        &bufs.storage.exponents[..N * N],
    );
    let checksum = fnv1a_q15(mantissas, exponents);

    let mut file = HostFile::create(spectrum_file)?;
    put_all(&mut file, exponents, |&e| [e as u8])?;
    put_all(&mut file, mantissas, |v| v.0.to_le_bytes())?;
    let mut image = HostFile::create(image_file)?;
    image
        .put(&prepared.image_exponent.to_le_bytes())
        .map_err(|_| RunError::Host("write to the host"))?;
    put_all(&mut image, &bufs.block[..N * N], |v| v.to_le_bytes())?;

    let dht = time_dht_3d_q15::<N, _>(&tw_data, &mut bufs, &clock)?;
    defmt::println!(
        "prepare-q15 {=str}: side {=usize}, scale 2^{=i32}, spectrum fnv1a {=u32:#010x}; preparation {=u64} instructions (3D DHT alone on a test signal {=u64}); render {=usize}x{=usize} view {=u64}; phase table {=u64}",
        program,
        N,
        libm::ilogb(prepared.scale),
        checksum,
        prepared.counts.prepare,
        dht,
        N,
        N,
        prepared.counts.render,
        phase_count
    );
    clock.finish()
}

/// The entry point of a Q15 preparation program, its statics (the cube of
/// side `$side`, its exponents, the phase table and the view buffers, all
/// `const`-initialised to zero bits, so in `.bss`) and the HardFault
/// handler: `prepare_q15_main!(name, input, side)`.
#[macro_export]
macro_rules! prepare_q15_main {
    ($program:expr, $input:expr, $side:expr) => {
        const SIDE: usize = $side;
        const LENS: (usize, usize, usize, usize, usize) = $crate::prepare_q15::q15_lens(SIDE);

        type Ram<T> = cortex_m::interrupt::Mutex<core::cell::RefCell<T>>;
        type Phases = fvr_core::slice::fixed::FixedPhases<{ $crate::prepare_q15::WIDTH }>;
        static CUBE: Ram<[fvr_core::num::Q15; LENS.0]> =
            Ram::new(core::cell::RefCell::new([fvr_core::num::Q15(0); LENS.0]));
        static EXPONENTS: Ram<[i8; LENS.1]> = Ram::new(core::cell::RefCell::new([0; LENS.1]));
        static PREMUL: Ram<[i32; LENS.2]> = Ram::new(core::cell::RefCell::new([0; LENS.2]));
        static GRID: Ram<[i32; LENS.3]> = Ram::new(core::cell::RefCell::new([0; LENS.3]));
        static AUX: Ram<[i32; LENS.4]> = Ram::new(core::cell::RefCell::new([0; LENS.4]));
        static BLOCK: Ram<[i16; LENS.3]> = Ram::new(core::cell::RefCell::new([0; LENS.3]));
        static PHASES: Ram<Phases> = Ram::new(core::cell::RefCell::new(Phases::new()));

        #[cortex_m_rt::entry]
        fn main() -> ! {
            // The program runs inside the critical section: it uses no
            // interrupts.
            cortex_m::interrupt::free(|cs| {
                let mut cube = CUBE.borrow(cs).borrow_mut();
                let mut exponents = EXPONENTS.borrow(cs).borrow_mut();
                let mut premul = PREMUL.borrow(cs).borrow_mut();
                let mut grid = GRID.borrow(cs).borrow_mut();
                let mut aux = AUX.borrow(cs).borrow_mut();
                let mut block = BLOCK.borrow(cs).borrow_mut();
                let mut phases = PHASES.borrow(cs).borrow_mut();
                let bufs = $crate::prepare_q15::Q15Buffers {
                    storage: fvr_core::spectrum::Q15Storage {
                        mantissas: &mut cube[..],
                        exponents: &mut exponents[..],
                        premul: &mut premul[..],
                    },
                    grid: &mut grid[..],
                    aux: &mut aux[..],
                    block: &mut block[..],
                };
                $crate::prepare_q15_device::run::<SIDE>(
                    $program,
                    (
                        concat!($program, "-spectrum.q15"),
                        concat!($program, "-image.q15"),
                    ),
                    &$input,
                    &mut phases,
                    bufs,
                )
            })
        }

        $crate::hard_fault_handler!();
    };
}
