//! The device runtime of the Q15 preparation programs
//! (`fvr-prepare-q15`, `fvr-prepare-q15-m7`): [`run`] and
//! [`prepare_q15_main!`](crate::prepare_q15_main). The cube and the view
//! buffers are statics in `.bss`, borrowed once in a critical section.
//!
//! Output, in QEMU's working directory: `<program>-spectrum.q15` (the
//! `n²` exponents, then the `n³` mantissas, little-endian, `x` fastest) and
//! `<program>-image.q15` (the image's exponent as `i32`, then its `n²`
//! mantissas); the counts, the scale and the spectrum's checksum go to the
//! defmt log.

use fvr_core::slice::fixed::FixedPhases;

use crate::capture::ByteSink;
use crate::device::{HostFile, RunError, SysTickClock};
use crate::frame::{FrameError, InstructionClock};
use crate::prepare::PrepInput;
use crate::prepare_q15::{
    fnv1a_q15, prepare_and_render_q15, time_dht_3d_q15, twiddles_i16, twiddles_q15, Q15Buffers,
    TWIDDLES_LEN, WIDTH,
};

fn core_error(e: fvr_core::Error) -> RunError {
    RunError::Frame(FrameError::Core(e))
}

/// Prepare `input`'s Q15 spectrum of side `N` in `bufs`, render the view
/// from it, write both to the host and log the counts; exit QEMU with
/// status 0 (1 on any error).
pub fn run<const N: usize>(
    program: &str,
    files: (&str, &str),
    input: &PrepInput,
    phases: &mut FixedPhases<WIDTH>,
    bufs: Q15Buffers<'_>,
) -> ! {
    let status = match run_inner::<N>(program, files, input, phases, bufs) {
        Ok(()) => 0,
        Err(e) => {
            defmt::error!("{=str}: {}", program, defmt::Debug2Format(&e));
            1
        }
    };
    semihosting::process::exit(status)
}

fn run_inner<const N: usize>(
    program: &str,
    (spectrum_file, image_file): (&str, &str),
    input: &PrepInput,
    phases: &mut FixedPhases<WIDTH>,
    mut bufs: Q15Buffers<'_>,
) -> Result<(), RunError> {
    let peripherals = cortex_m::Peripherals::take().ok_or(RunError::Host("peripherals taken"))?;
    let mut clock = SysTickClock::start(peripherals.SYST);
    let t0 = clock.now();
    cortex_m::asm::delay(1_000_000);
    let calibration = clock.now() - t0;
    defmt::println!(
        "calibration: delay loop of 2000002 instructions counted as {=u64}",
        calibration
    );

    let mut tw_buf = [fvr_core::num::Q15(0); TWIDDLES_LEN];
    let tw_data = twiddles_q15(&mut tw_buf).map_err(core_error)?;
    let tw_view = twiddles_i16().map_err(core_error)?;
    // Once per filter: the Q15 phase table from the f32 kernel in flash.
    let kernel = input.kernel_table().map_err(core_error)?;
    let t0 = clock.now();
    phases.fill(&kernel).map_err(core_error)?;
    let phase_count = clock.now() - t0;

    let prepared =
        prepare_and_render_q15::<N, _>(input, (&tw_data, &tw_view), phases, &mut bufs, &clock)
            .map_err(core_error)?;
    let lines = N * N;
    let (mantissas, exponents) = (&bufs.mantissas[..N * N * N], &bufs.exponents[..lines]);
    let checksum = fnv1a_q15(mantissas, exponents);

    let failed = |_| RunError::Host("write to the host");
    let mut file = HostFile::create(spectrum_file)?;
    for e in exponents.chunks(256) {
        let mut chunk = [0u8; 256];
        for (b, &e) in chunk.iter_mut().zip(e) {
            *b = e as u8;
        }
        file.put(&chunk[..e.len()]).map_err(failed)?;
    }
    let mut chunk = [0u8; 256];
    for values in mantissas.chunks(chunk.len() / 2) {
        for (bytes, v) in chunk.chunks_exact_mut(2).zip(values) {
            bytes.copy_from_slice(&v.0.to_le_bytes());
        }
        file.put(&chunk[..2 * values.len()]).map_err(failed)?;
    }
    let mut image = HostFile::create(image_file)?;
    image
        .put(&prepared.image_exponent.to_le_bytes())
        .map_err(failed)?;
    for values in bufs.image[..N * N].chunks(chunk.len() / 2) {
        for (bytes, v) in chunk.chunks_exact_mut(2).zip(values) {
            bytes.copy_from_slice(&v.to_le_bytes());
        }
        image.put(&chunk[..2 * values.len()]).map_err(failed)?;
    }

    let dht = time_dht_3d_q15::<N, _>(&tw_data, &mut bufs, &clock).map_err(core_error)?;
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
/// side `$side`, its exponents and the view buffers, in `.bss`; the phase
/// table through `cortex_m::singleton!`) and the HardFault handler:
/// `prepare_q15_main!(name, input, side)`.
#[macro_export]
macro_rules! prepare_q15_main {
    ($program:expr, $input:expr, $side:expr) => {
        const SIDE: usize = $side;
        const LENS: (usize, usize, usize, usize, usize) = $crate::prepare_q15::q15_lens(SIDE);

        type Ram<T> = cortex_m::interrupt::Mutex<core::cell::RefCell<T>>;
        static CUBE: Ram<[fvr_core::num::Q15; LENS.0]> =
            Ram::new(core::cell::RefCell::new([fvr_core::num::Q15(0); LENS.0]));
        static EXPONENTS: Ram<[i8; LENS.1]> = Ram::new(core::cell::RefCell::new([0; LENS.1]));
        static PREMUL: Ram<[i32; LENS.2]> = Ram::new(core::cell::RefCell::new([0; LENS.2]));
        static GRID: Ram<[i32; LENS.3]> = Ram::new(core::cell::RefCell::new([0; LENS.3]));
        static AUX: Ram<[i32; LENS.4]> = Ram::new(core::cell::RefCell::new([0; LENS.4]));
        static BLOCK: Ram<[i16; LENS.3]> = Ram::new(core::cell::RefCell::new([0; LENS.3]));
        static IMAGE: Ram<[i16; LENS.3]> = Ram::new(core::cell::RefCell::new([0; LENS.3]));

        #[cortex_m_rt::entry]
        fn main() -> ! {
            let Some(filter) = $input.filter().ok() else {
                $crate::device::abort("the kb3 filter in flash")
            };
            let phases = cortex_m::singleton!(
                PHASES: fvr_core::slice::fixed::FixedPhases<{ $crate::prepare_q15::WIDTH }> =
                    fvr_core::slice::fixed::FixedPhases::zeroed(filter)
            );
            let Some(phases) = phases else {
                $crate::device::abort("phase table taken twice")
            };
            // The program runs inside the critical section: it uses no
            // interrupts.
            cortex_m::interrupt::free(|cs| {
                let mut cube = CUBE.borrow(cs).borrow_mut();
                let mut exponents = EXPONENTS.borrow(cs).borrow_mut();
                let mut premul = PREMUL.borrow(cs).borrow_mut();
                let mut grid = GRID.borrow(cs).borrow_mut();
                let mut aux = AUX.borrow(cs).borrow_mut();
                let mut block = BLOCK.borrow(cs).borrow_mut();
                let mut image = IMAGE.borrow(cs).borrow_mut();
                let bufs = $crate::prepare_q15::Q15Buffers {
                    mantissas: &mut cube[..],
                    exponents: &mut exponents[..],
                    premul: &mut premul[..],
                    grid: &mut grid[..],
                    aux: &mut aux[..],
                    block: &mut block[..],
                    image: &mut image[..],
                };
                $crate::prepare_q15_device::run::<SIDE>(
                    $program,
                    (
                        concat!($program, "-spectrum.q15"),
                        concat!($program, "-image.q15"),
                    ),
                    &$input,
                    phases,
                    bufs,
                )
            })
        }

        #[allow(unsafe_code)]
        #[cortex_m_rt::exception]
        unsafe fn HardFault(_frame: &cortex_m_rt::ExceptionFrame) -> ! {
            $crate::device::hard_fault()
        }
    };
}
