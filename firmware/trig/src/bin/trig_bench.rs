//! `fvr-trig-bench`: the instructions of the per-view transcendental
//! functions (`fvr_firmware_trig`) with the core's `libm` f64 functions,
//! `libm`'s f32 ones and `micromath`'s f32 approximations: the shift
//! phasors of the scene's 64² view of a 63³ volume (4·64 `cos` and
//! `sin`; the 64³ view has no sub-pixel shift), and square
//! roots (the view frame's norms, the lights' normalisation), with the
//! whole `View::frame` for scale. Built for the Cortex-M4F
//! (thumbv7em-none-eabihf, QEMU mps2-an386) and the Cortex-M3
//! (thumbv7m-none-eabi, mps2-an385) by `bash scripts/firmware.sh`; the
//! image each costs is measured on the host (`tests/trig.rs`).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod device {
    use core::hint::black_box;
    use fvr_core::image::placement;
    use fvr_firmware::device::{calibrated_clock, exit_with, RunError, SysTickClock};
    use fvr_firmware::frame::InstructionClock;
    use fvr_firmware::scene::{IMAGE_SIDE, VIEW};
    use fvr_firmware_trig::{phasors_len, shift_phasors, Trig};

    const PROGRAM: &str = "fvr-trig-bench";
    const M: usize = IMAGE_SIDE;
    /// Square roots timed per function, over arguments of the size of the
    /// frame's and the lights' squared norms.
    const ROOTS: usize = 16;

    /// Instructions `f` takes, and its result.
    fn count<T>(clock: &SysTickClock, f: impl FnOnce() -> T) -> (u64, T) {
        let t0 = clock.now();
        let out = f();
        (clock.now() - t0, out)
    }

    pub fn run() -> ! {
        exit_with(PROGRAM, measure())
    }

    fn measure() -> Result<(), RunError> {
        let mut clock = calibrated_clock()?;
        let view = black_box(VIEW);
        let (frame_count, frame) = count(&clock, || view.frame());
        let frame = frame.map_err(|_| RunError::Host("view frame"))?;
        defmt::println!(
            "trig view-frame: View::frame {=u64} instructions",
            frame_count
        );
        // The scene's 64³ view has no sub-pixel shift (the core evaluates no
        // phasor); a 63³ volume's has.
        let shift = black_box(placement([M - 1; 3], &frame, M, M).shift);
        let mut reference = [0.0f32; phasors_len(M)];
        shift_phasors(Trig::LibmF64, M, shift, &mut reference);
        let mut table = [0.0f32; phasors_len(M)];
        for trig in Trig::ALL {
            let (phasors, ()) = count(&clock, || shift_phasors(trig, M, shift, &mut table));
            let error = table
                .iter()
                .zip(&reference)
                .fold(0.0f32, |e, (a, b)| e.max((a - b).abs()));
            let (roots, sum) = count(&clock, || {
                (1..=ROOTS).fold(0.0, |s, i| s + trig.sqrt(black_box(0.37 * i as f64)))
            });
            defmt::println!(
                "trig {=str}: shift phasors (4x{=usize} cos and sin) {=u64} instructions, max |error| {=f32} against libm-f64; sqrt {=u64} instructions per call (sum {=f64})",
                trig.name(),
                M,
                phasors,
                error,
                roots / ROOTS as u64,
                sum
            );
        }
        clock.finish()
    }
}

#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    device::run()
}

#[cfg(target_os = "none")]
fvr_firmware::hard_fault_handler!();

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "fvr-trig-bench runs on thumbv7em-none-eabihf (mps2-an386) and thumbv7m-none-eabi \
         (mps2-an385) under QEMU: bash scripts/firmware.sh"
    );
    std::process::exit(2);
}
