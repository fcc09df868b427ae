//! The device runtime (thumbv7em-none-eabihf under QEMU mps2-an386):
//! instruction counting with SysTick, host files over semihosting, the
//! stack scan, the panic handler and [`firmware_main!`](crate::firmware_main).
//! The Cortex-M3 (thumbv7m-none-eabi, mps2-an385, no FPU) uses all but the
//! scene's [`run`] and the VCVTB measurement, which need the M4F.
//!
//! # Instruction counts
//! QEMU runs with `-icount shift=0`: one instruction is one nanosecond of
//! virtual time, and SysTick on the processor clock (25 MHz on mps2) ticks
//! once every 40 instructions. Counts are therefore exact to ±40 and
//! repeatable run to run. The 24-bit counter never reloads during a run (it
//! would after 671 M instructions); [`run`] fails if it did.

use core::ffi::CStr;
#[cfg(target_abi = "eabihf")]
use core::fmt::Write as _;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use semihosting::fs::File;
use semihosting::io::Write as _;

use crate::capture::ByteSink;
use crate::frame::{FrameError, InstructionClock};
#[cfg(target_abi = "eabihf")]
use crate::{
    capture::CaptureBus,
    display::{DcsPanel, Image, Window},
    frame::{check_linked_tables, render_frame, tables_for, FrameBuffers, Split, IMAGE_LEN},
    nrrd::{write_samples_le, Header},
    scene::{FrameSpec, IMAGE_SIDE},
    stored::{twiddles, StoredDerivative, StoredSpectrum},
};

// The critical-section implementation defmt-semihosting needs.
use cortex_m as _;
use defmt_semihosting as _;

/// Instructions per SysTick tick under `-icount shift=0` on mps2 (1 ns per
/// instruction, a 25 MHz tick).
pub const INSTRUCTIONS_PER_TICK: u64 = 40;
const RELOAD: u32 = 0x00FF_FFFF;

/// SysTick as a free-running instruction counter.
pub struct SysTickClock {
    syst: SYST,
}

impl SysTickClock {
    /// Start counting down from `2^24 − 1` on the processor clock, without
    /// interrupts.
    pub fn start(mut syst: SYST) -> Self {
        syst.disable_interrupt();
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        syst.clear_current();
        syst.enable_counter();
        // Clearing sets the counter to 0; it loads RELOAD on the next tick.
        while SYST::get_current() == 0 {}
        // Reading COUNTFLAG clears it; it is read again at the end.
        let _ = syst.has_wrapped();
        Self { syst }
    }

    /// `true` if the counter reloaded since [`SysTickClock::start`] (the
    /// counts would then be ambiguous).
    pub fn wrapped(&mut self) -> bool {
        self.syst.has_wrapped()
    }

    /// The end of a run: fail if the counter wrapped, else log the peak
    /// stack use.
    ///
    /// # Errors
    /// [`RunError::CounterWrapped`].
    pub fn finish(&mut self) -> Result<(), RunError> {
        if self.wrapped() {
            return Err(RunError::CounterWrapped);
        }
        let stack = unsafe_parts::stack_usage();
        defmt::println!(
            "stack: peak {=usize} bytes of {=usize} free for the stack",
            stack.peak,
            stack.available
        );
        Ok(())
    }
}

impl InstructionClock for SysTickClock {
    fn now(&self) -> u64 {
        (RELOAD - SYST::get_current()) as u64 * INSTRUCTIONS_PER_TICK
    }
}

/// A file on the host, written over semihosting.
pub struct HostFile(File);

impl HostFile {
    /// Create (or truncate) `name` in QEMU's working directory.
    ///
    /// # Errors
    /// A name of 95 bytes or more, or the host refused.
    pub fn create(name: &str) -> Result<Self, RunError> {
        let mut path = [0u8; 96];
        let slot = path
            .get_mut(..name.len())
            .filter(|_| name.len() < 96)
            .ok_or(RunError::Host("file name too long"))?;
        slot.copy_from_slice(name.as_bytes());
        let c = CStr::from_bytes_until_nul(&path).map_err(|_| RunError::Host("bad file name"))?;
        File::create(c)
            .map(HostFile)
            .map_err(|_| RunError::Host("cannot create a file on the host"))
    }
}

impl ByteSink for HostFile {
    type Error = ();
    fn put(&mut self, bytes: &[u8]) -> Result<(), ()> {
        self.0.write_all(bytes).map_err(|_| ())
    }
}

/// Why a run failed.
#[derive(Debug)]
pub enum RunError {
    /// A frame failed.
    Frame(FrameError),
    /// Host I/O failed.
    Host(&'static str),
    /// The display path failed.
    Display,
    /// The instruction counter reloaded: the run was too long to count.
    CounterWrapped,
}

impl From<FrameError> for RunError {
    fn from(e: FrameError) -> Self {
        RunError::Frame(e)
    }
}

impl From<fvr_core::Error> for RunError {
    fn from(e: fvr_core::Error) -> Self {
        RunError::Frame(FrameError::Core(e))
    }
}

/// Exit QEMU with status 0 if `result` is `Ok`, else log the error for
/// `program` and exit with status 1.
pub fn exit_with(program: &str, result: Result<(), RunError>) -> ! {
    let status = match result {
        Ok(()) => 0,
        Err(e) => {
            defmt::error!("{=str}: {}", program, defmt::Debug2Format(&e));
            1
        }
    };
    semihosting::process::exit(status)
}

/// Take SysTick as the instruction clock and log its calibration:
/// `asm::delay(c)` runs exactly `2c + 2` instructions (`subs`/`bne`
/// `c + 1` times), which the clock must count as `2c`, to its ±40.
///
/// # Errors
/// The core peripherals were taken already.
pub fn calibrated_clock() -> Result<SysTickClock, RunError> {
    let peripherals = cortex_m::Peripherals::take().ok_or(RunError::Host("peripherals taken"))?;
    let clock = SysTickClock::start(peripherals.SYST);
    let t0 = clock.now();
    cortex_m::asm::delay(1_000_000);
    let calibration = clock.now() - t0;
    defmt::println!(
        "calibration: delay loop of 2000002 instructions counted as {=u64}",
        calibration
    );
    Ok(clock)
}

/// Write `values` to `file` as the bytes `bytes` gives each (e.g.
/// `to_le_bytes`), through a 256-byte chunk.
///
/// # Errors
/// The host refused a write.
pub fn put_all<T, const B: usize>(
    file: &mut HostFile,
    values: &[T],
    bytes: impl Fn(&T) -> [u8; B],
) -> Result<(), RunError> {
    let mut chunk = [0u8; 256];
    let per_chunk = chunk.len() / B;
    for values in values.chunks(per_chunk) {
        for (out, v) in chunk.chunks_exact_mut(B).zip(values) {
            out.copy_from_slice(&bytes(v));
        }
        file.put(&chunk[..B * values.len()])
            .map_err(|_| RunError::Host("write to the host"))?;
    }
    Ok(())
}

#[cfg(target_abi = "eabihf")]
/// A file name, `<program>-<frame>.<ext>`, of at most 80 bytes.
struct Name(heapless::String<80>);

#[cfg(target_abi = "eabihf")]
impl Name {
    fn new(program: &str, frame: &str, ext: &str) -> Result<Self, RunError> {
        let mut n = heapless::String::new();
        write!(n, "{program}-{frame}.{ext}").map_err(|_| RunError::Host("file name too long"))?;
        Ok(Name(n))
    }
    fn as_str(&self) -> &str {
        &self.0
    }
}

#[cfg(target_abi = "eabihf")]
/// Render every frame of `frames` from `spectra` and `derivatives` into
/// `bufs`, write each image to `<program>-<frame>.nrrd` and its display
/// recording to `<program>-<frame>.spi` on the host, log the counts with
/// defmt, and exit QEMU with status 0 (1 on any error).
pub fn run(
    program: &str,
    frames: &[FrameSpec],
    spectra: &[&'static StoredSpectrum],
    derivatives: &[&'static StoredDerivative],
    bufs: FrameBuffers<'_>,
) -> ! {
    exit_with(
        program,
        run_inner(program, frames, spectra, derivatives, bufs),
    )
}

#[cfg(target_abi = "eabihf")]
fn run_inner(
    program: &str,
    frames: &[FrameSpec],
    spectra: &[&'static StoredSpectrum],
    derivatives: &[&'static StoredDerivative],
    mut bufs: FrameBuffers<'_>,
) -> Result<(), RunError> {
    let mut clock = calibrated_clock()?;

    f16_codec_report(&clock)?;
    check_linked_tables(frames, spectra, derivatives)?;

    let tw = twiddles().map_err(|e| RunError::Frame(FrameError::Core(e)))?;

    for spec in frames {
        let tables = tables_for(spec, spectra, derivatives)?;
        let rendered = render_frame(spec, &tables, &tw, &mut bufs, &clock)?;
        let (channels, counts) = (rendered.channels, rendered.counts);
        let image = bufs
            .render
            .out
            .get(..channels * IMAGE_LEN)
            .ok_or(RunError::Host("image buffer shorter than the frame"))?;

        let t0 = clock.now();
        let window = Window::fit(image);
        let bus = CaptureBus::new(HostFile::create(
            Name::new(program, spec.name, "spi")?.as_str(),
        )?);
        let mut panel = DcsPanel::new(bus.spi(), bus.dc());
        let mut row = [0u8; 2 * IMAGE_SIDE];
        let picture = Image {
            pixels: image,
            width: IMAGE_SIDE,
            channels,
        };
        panel
            .draw((0, 0), picture, &window, &mut row)
            .map_err(|_| RunError::Display)?;
        let display = clock.now() - t0;

        let mut nrrd = HostFile::create(Name::new(program, spec.name, "nrrd")?.as_str())?;
        let header = Header::image_f32(
            channels,
            IMAGE_SIDE,
            IMAGE_SIDE,
            format_args!("{program} {}: rendered on a Cortex-M4F", spec.name),
        )
        .map_err(|_| RunError::Host("NRRD header too long"))?;
        nrrd.put(header.as_bytes())
            .map_err(|_| RunError::Host("NRRD write"))?;
        write_samples_le(image, |b| nrrd.put(b)).map_err(|_| RunError::Host("NRRD write"))?;

        match counts.split {
            Split::Staged { inverse_again } => defmt::println!(
                "frame {=str} {=str}: render {=u64} instructions = extraction {=u64} + inverse {=u64} (+ {=u64} in render's checks); inverse again on other data {=u64}; 2D DHT alone {=u64}; display sink {=u64}",
                program,
                spec.name,
                counts.render,
                counts.extract,
                counts.inverse,
                counts.render.saturating_sub(counts.extract + counts.inverse),
                inverse_again,
                counts.dht_2d,
                display
            ),
            Split::Retimed { channels } => defmt::println!(
                "frame {=str} {=str}: render {=u64} instructions = extraction {=u64} + inverse {=u64} (the inverse of {=usize} channels timed again after render_scene, extraction and combination the rest); 2D DHT alone {=u64}; display sink {=u64}",
                program,
                spec.name,
                counts.render,
                counts.extract,
                counts.inverse,
                channels,
                counts.dht_2d,
                display
            ),
        }
    }

    clock.finish()
}

#[cfg(target_abi = "eabihf")]
/// On the target's own arithmetic: the fast f16 → f32 widening of the core
/// (`fvr_core::num::f16_bits_to_f32`) against `half`'s, for all 65,536
/// patterns, and the instructions per conversion of each over the 63,488
/// finite patterns (a spectrum holds only finite values).
fn f16_codec_report(clock: &SysTickClock) -> Result<(), RunError> {
    use core::hint::black_box;
    use fvr_core::f16;
    use fvr_core::num::f16_bits_to_f32;

    let differing = (0..=u16::MAX)
        .filter(|&b| f16_bits_to_f32(b).to_bits() != f16::from_bits(b).to_f32().to_bits())
        .count();
    let finite = (0..0x7C00u16).chain(0x8000..0xFC00u16);
    let count = finite.clone().count() as u64;
    let time = |convert: &dyn Fn(u16) -> u32| {
        let t0 = clock.now();
        let mut acc = 0u32;
        for b in finite.clone() {
            acc ^= convert(black_box(b));
        }
        black_box(acc);
        clock.now() - t0
    };
    let empty = time(&|b| b as u32);
    let half = time(&|b| f16::from_bits(b).to_f32().to_bits());
    let fast = time(&|b| f16_bits_to_f32(b).to_bits());
    let hardware = time(&|b| unsafe_parts::vcvtb_f16_to_f32(b).to_bits());
    let hardware_differing = (0..=u16::MAX)
        .filter(|&b| {
            unsafe_parts::vcvtb_f16_to_f32(b).to_bits() != f16::from_bits(b).to_f32().to_bits()
        })
        .count();
    defmt::println!(
        "f16 -> f32: {=usize} of 65536 patterns differ from half (VCVTB: {=usize}); per conversion (x100): half {=u64}, rebias {=u64}, VCVTB {=u64}",
        differing,
        hardware_differing,
        (half - empty) * 100 / count,
        (fast - empty) * 100 / count,
        (hardware - empty) * 100 / count
    );
    if differing != 0 {
        return Err(RunError::Host(
            "the fast f16 widening differs from half on this target",
        ));
    }
    Ok(())
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    semihosting::process::exit(101)
}

/// Log `reason` and end QEMU with status 1.
pub fn abort(reason: &str) -> ! {
    defmt::error!("{=str}", reason);
    semihosting::process::exit(1)
}

/// A HardFault ends QEMU with status 102 instead of looping forever.
pub fn hard_fault() -> ! {
    defmt::error!("HardFault");
    semihosting::process::exit(102)
}

/// The only unsafe code of the crate.
#[allow(unsafe_code)]
pub mod unsafe_parts {
    /// Stack use measured on the painted stack.
    #[derive(Clone, Copy, Debug)]
    pub struct StackUsage {
        /// Bytes between the stack top and the deepest overwritten word.
        pub peak: usize,
        /// Bytes between the stack top and the end of `.bss`/`.uninit`.
        pub available: usize,
    }

    #[cfg(target_abi = "eabihf")]
    /// The FPv4-SP instruction `VCVTB.F32.F16` (IEEE half, FPSCR.AHP = 0):
    /// the conversion the core cannot use, because it forbids `unsafe` and
    /// stable Rust has no other way to emit it. Measured here to show what
    /// it would buy.
    ///
    /// Stable Rust cannot hand an FPU register to `asm!` on this target (the
    /// `sreg` class needs the unstable `vfp2` feature), so the block saves
    /// and restores `s0` itself: 2 of the instructions counted for it would
    /// not be there in compiler-emitted code.
    #[inline(always)]
    pub fn vcvtb_f16_to_f32(bits: u16) -> f32 {
        let out: u32;
        // SAFETY: register-only FPU instructions of the M4F (FPv4-SP with
        // the half-precision extension), whose FPU cortex-m-rt enables for
        // the hard-float target before `main`; `s0` is restored, and the
        // stack use is 4 bytes, balanced. (`readonly`: vpush writes below the
        // stack pointer only, which no Rust code can observe.)
        unsafe {
            core::arch::asm!(
                "vpush {{s0}}",
                "vmov s0, {r}",
                "vcvtb.f32.f16 s0, s0",
                "vmov {o}, s0",
                "vpop {{s0}}",
                r = in(reg) bits as u32,
                o = lateout(reg) out,
                // No `nomem`: vpush and vpop touch the stack.
                options(pure, readonly),
            );
        }
        f32::from_bits(out)
    }

    extern "C" {
        static _stack_start: u32;
        static _stack_end: u32;
    }

    /// Scan the stack painted by cortex-m-rt (`paint-stack`: every word
    /// from `_stack_end` up to `_stack_start` set to 0xCCCC_CCCC at reset)
    /// for the deepest word overwritten since.
    pub fn stack_usage() -> StackUsage {
        let lo = &raw const _stack_end as usize;
        let hi = &raw const _stack_start as usize;
        let mut p = lo;
        // SAFETY: [lo, hi) is RAM reserved for the stack by the linker
        // script, 4-byte aligned (asserted there); reading it is sound, and
        // volatile keeps the compiler from assuming its contents.
        while p < hi
            && unsafe { core::ptr::read_volatile(p as *const u32) }
                == cortex_m_rt::STACK_PAINT_VALUE
        {
            p += 4;
        }
        StackUsage {
            peak: hi - p,
            available: hi - lo,
        }
    }
}

/// The HardFault handler of a firmware program: [`hard_fault`], which
/// ends QEMU with status 102.
#[macro_export]
macro_rules! hard_fault_handler {
    () => {
        #[allow(unsafe_code)]
        #[cortex_m_rt::exception]
        unsafe fn HardFault(_frame: &cortex_m_rt::ExceptionFrame) -> ! {
            $crate::device::hard_fault()
        }
    };
}

/// The entry point, SysTick-free exception handlers, the frame buffers (in
/// `.bss`, sized for the program's frames by
/// [`buffer_sizes`](crate::scene::buffer_sizes)) and the call to [`run`]
/// for a firmware program:
/// `firmware_main!(name, frames, [spectra], [derivative tables])`.
#[macro_export]
macro_rules! firmware_main {
    ($program:expr, $frames:expr, [$($spectrum:expr),+ $(,)?], [$($derivative:expr),* $(,)?]) => {
        const BUFFER_SIZES: $crate::scene::BufferSizes = $crate::scene::buffer_sizes(&$frames);
        const FRAME_FIELDS_LEN: usize = BUFFER_SIZES.fields;
        const FRAME_IMAGE_LEN: usize = BUFFER_SIZES.image;

        #[cortex_m_rt::entry]
        fn main() -> ! {
            let fields = cortex_m::singleton!(FIELDS: [f32; FRAME_FIELDS_LEN] = [0.0; FRAME_FIELDS_LEN]);
            let aux = cortex_m::singleton!(
                AUX: [f32; $crate::frame::AUX_LEN] = [0.0; $crate::frame::AUX_LEN]
            );
            let image = cortex_m::singleton!(IMAGE: [f32; FRAME_IMAGE_LEN] = [0.0; FRAME_IMAGE_LEN]);
            let staged = cortex_m::singleton!(STAGED: [f32; FRAME_IMAGE_LEN] = [0.0; FRAME_IMAGE_LEN]);
            // Each singleton is taken once, here.
            let (Some(fields), Some(aux), Some(image), Some(staged)) = (fields, aux, image, staged)
            else {
                $crate::device::abort("frame buffers taken twice")
            };
            let bufs = $crate::frame::FrameBuffers {
                render: fvr_core::render::Buffers::new(fields, aux, image),
                staged,
            };
            $crate::device::run($program, &$frames, &[$($spectrum),+], &[$($derivative),*], bufs)
        }

        $crate::hard_fault_handler!();
    };
}
