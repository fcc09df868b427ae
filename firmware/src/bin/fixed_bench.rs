//! `fvr-fixed-bench`: the integer-only Hartley transforms of the core on a
//! Cortex-M3 without FPU (thumbv7m-none-eabi, QEMU mps2-an385). On one
//! 64 × 64 block (`src/fixed_input.rs`) it counts the instructions of the
//! inverse 2D transform in Q15, in Q31 and in soft-float f32, and of making
//! the Q15 twiddle table on the device (soft-float `sin`) against taking it
//! from flash (made by `build.rs`). Then the whole plain kb3 64² view of
//! the scene: in integers from the Q15 spectrum in flash
//! (`fvr_firmware::fixed_view`, with its set-up, extraction and finish
//! counted apart), and by the f32 core path in soft float from the f16
//! spectrum (`fvr_firmware::frame::render_frame`, as on the M4F). It
//! writes every result to the host (`fvr-fixed-bench-{q15,q31,f32}.bin`,
//! `fvr-fixed-bench-view-{q15,f32}.bin`) for `tests/qemu_fixed.rs`
//! (`bash scripts/firmware.sh`).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
#[allow(dead_code)]
#[path = "../fixed_input.rs"]
mod fixed_input;

#[cfg(target_os = "none")]
mod device {
    use fvr_core::dht::fixed::{idht_2d, FixedTwiddles};
    use fvr_core::dht::{self, Twiddles};
    use fvr_core::image::fixed::FixedBuffers;
    use fvr_core::render::Buffers;
    use fvr_core::slice::fixed::FixedPhases;
    use fvr_firmware::capture::ByteSink;
    use fvr_firmware::device::{calibrated_clock, exit_with, HostFile, RunError, SysTickClock};
    use fvr_firmware::fixed_view::{render_view, ViewBuffers, ViewError, WIDTH};
    use fvr_firmware::frame::{
        render_frame, tables_for, FrameBuffers, FrameError, InstructionClock,
    };
    use fvr_firmware::scene::SCENE_FRAMES;
    use fvr_firmware::stored::{twiddles, DENSITY_KB3};

    use crate::fixed_input::{f32_from_q15, q15_block, q31_from_q15, LEN, SIDE};

    include!(concat!(env!("OUT_DIR"), "/fixed_tables.rs"));

    const PROGRAM: &str = "fvr-fixed-bench";
    const TWIDDLES_LEN: usize = FixedTwiddles::<i16>::buffer_len(SIDE);

    /// The blocks, in `.bss`.
    pub struct Blocks {
        pub q15: &'static mut [i16; LEN],
        pub q31: &'static mut [i32; LEN],
        pub f32: &'static mut [f32; LEN],
    }

    /// The buffers of the two whole views, in `.bss`.
    pub struct Views {
        pub phases: &'static mut FixedPhases<WIDTH>,
        pub grid: &'static mut [i32; LEN],
        pub aux: &'static mut [i32; AUX],
        pub block: &'static mut [i16; LEN],
        pub image: &'static mut [i16; LEN],
        pub staged: &'static mut [i16; LEN],
        pub float_aux: &'static mut [f32; FLOAT_AUX],
        pub float_image: &'static mut [f32; LEN],
        pub float_staged: &'static mut [f32; LEN],
    }

    /// Elements of the integer view's auxiliary scratch.
    pub const AUX: usize = fvr_firmware::fixed_view::AUX_LEN;
    /// Elements of the f32 view's auxiliary scratch.
    pub const FLOAT_AUX: usize = fvr_firmware::frame::AUX_LEN;

    pub fn run(blocks: Blocks, views: Views) -> ! {
        exit_with(PROGRAM, measure(blocks, views))
    }

    fn core_error(e: fvr_core::Error) -> RunError {
        RunError::Frame(FrameError::Core(e))
    }

    /// Instructions `f` takes, and its result.
    fn count<T>(clock: &SysTickClock, f: impl FnOnce() -> T) -> (u64, T) {
        let t0 = clock.now();
        let out = f();
        (clock.now() - t0, out)
    }

    /// Write `head`, then each of `values`, to the file `name` on the host.
    fn send<const W: usize>(
        name: &str,
        head: &[u8],
        values: impl Iterator<Item = [u8; W]>,
    ) -> Result<(), RunError> {
        let failed = |_| RunError::Host("write to the host");
        let mut file = HostFile::create(name)?;
        file.put(head).map_err(failed)?;
        for v in values {
            file.put(&v).map_err(failed)?;
        }
        Ok(())
    }

    fn measure(blocks: Blocks, views: Views) -> Result<(), RunError> {
        let mut clock = calibrated_clock()?;

        // (d) The Q15 twiddles: made here in soft float, or checked in flash.
        let mut made = [0i16; TWIDDLES_LEN];
        let (build, built) = count(&clock, || {
            FixedTwiddles::<i16>::new(&mut made, SIDE).map(|_| ())
        });
        built.map_err(core_error)?;
        let (load, tw) = count(&clock, || FixedTwiddles::from_table(&TWIDDLES_Q15, SIDE));
        let tw = tw.map_err(core_error)?;
        if made != TWIDDLES_Q15 {
            return Err(RunError::Host(
                "the Q15 twiddles made on the device differ from the flash table",
            ));
        }
        defmt::println!(
            "fixed twiddles-q15: build {=u64} instructions (soft-float sin), flash {=u64} (range checks); equal tables",
            build,
            load
        );

        // (a) Q15.
        q15_block(&mut blocks.q15[..]);
        let (q15, exp) = count(&clock, || idht_2d(&mut blocks.q15[..], SIDE, SIDE, &tw));
        let exp = exp.map_err(core_error)?;
        defmt::println!(
            "fixed idht-2d-q15: {=u64} instructions (64x64, exponent {=i32})",
            q15,
            exp
        );
        send(
            "fvr-fixed-bench-q15.bin",
            &exp.to_le_bytes(),
            blocks.q15.iter().map(|m| m.to_le_bytes()),
        )?;

        // (b) Q31, on the same values.
        let tw31 = FixedTwiddles::from_table(&TWIDDLES_Q31, SIDE).map_err(core_error)?;
        q15_block(&mut blocks.q15[..]);
        for (w, &m) in blocks.q31.iter_mut().zip(blocks.q15.iter()) {
            *w = q31_from_q15(m);
        }
        let (q31, exp) = count(&clock, || idht_2d(&mut blocks.q31[..], SIDE, SIDE, &tw31));
        let exp = exp.map_err(core_error)?;
        defmt::println!(
            "fixed idht-2d-q31: {=u64} instructions (64x64, exponent {=i32})",
            q31,
            exp
        );
        send(
            "fvr-fixed-bench-q31.bin",
            &exp.to_le_bytes(),
            blocks.q31.iter().map(|m| m.to_le_bytes()),
        )?;

        // (c) f32 in soft float, on the same values.
        let mut f32_twiddles = [0.0f32; Twiddles::<f32>::buffer_len(SIDE)];
        let ftw = Twiddles::new(&mut f32_twiddles, SIDE).map_err(core_error)?;
        for (f, &m) in blocks.f32.iter_mut().zip(blocks.q15.iter()) {
            *f = f32_from_q15(m);
        }
        let mut column = [0.0f32; SIDE];
        let (soft, done) = count(&clock, || {
            dht::idht_2d(&mut blocks.f32[..], SIDE, SIDE, &mut column, &ftw)
        });
        done.map_err(core_error)?;
        defmt::println!(
            "fixed idht-2d-f32: {=u64} instructions (64x64, soft float)",
            soft
        );
        send(
            "fvr-fixed-bench-f32.bin",
            &[],
            blocks.f32.iter().map(|v| v.to_le_bytes()),
        )?;

        whole_views(&clock, &tw, blocks.f32, views)?;
        clock.finish()
    }

    /// The plain kb3 64² view in integers and in soft-float f32.
    fn whole_views(
        clock: &SysTickClock,
        tw: &FixedTwiddles<'_, i16>,
        float_grid: &mut [f32; LEN],
        views: Views,
    ) -> Result<(), RunError> {
        // Per filter, once: the Q15 phase table from the f32 kernel table
        // in flash (soft-float roundings).
        let kernel = DENSITY_KB3.kernel_table().map_err(core_error)?;
        let (table, filled) = count(clock, || views.phases.fill(&kernel));
        filled.map_err(core_error)?;
        defmt::println!(
            "fixed phases-q15: {=u64} instructions (kb3 phase table from the f32 kernel, once per filter; {=u32} fraction bits)",
            table,
            views.phases.fraction_bits()
        );
        let view_error = |e: ViewError| match e {
            ViewError::Core(e) => core_error(e),
            ViewError::StagedDiffers => {
                RunError::Host("the staged integer view differs from render_fixed")
            }
        };
        let (exp, counts) = render_view(
            views.phases,
            tw,
            ViewBuffers {
                view: FixedBuffers {
                    grid: &mut views.grid[..],
                    aux: &mut views.aux[..],
                    block: &mut views.block[..],
                    out: &mut views.image[..],
                },
                staged: &mut views.staged[..],
            },
            clock,
        )
        .map_err(view_error)?;
        defmt::println!(
            "fixed view-q15: {=u64} instructions = set-up {=u64} + extraction {=u64} + finish {=u64} (staged; image exponent {=i32})",
            counts.render,
            counts.setup,
            counts.extract,
            counts.finish,
            exp
        );
        send(
            "fvr-fixed-bench-view-q15.bin",
            &exp.to_le_bytes(),
            views.image.iter().map(|m| m.to_le_bytes()),
        )?;

        let spec = &SCENE_FRAMES[0];
        let tables = tables_for(spec, &[&DENSITY_KB3], &[]).map_err(RunError::Frame)?;
        let ftw = twiddles().map_err(core_error)?;
        let mut bufs = FrameBuffers {
            render: Buffers::new(
                &mut float_grid[..],
                &mut views.float_aux[..],
                &mut views.float_image[..],
            ),
            staged: &mut views.float_staged[..],
        };
        let rendered =
            render_frame(spec, &tables, &ftw, &mut bufs, clock).map_err(RunError::Frame)?;
        let c = rendered.counts;
        defmt::println!(
            "fixed view-f32: {=u64} instructions = extraction {=u64} + inverse {=u64} (soft float, f16 spectrum, {=str})",
            c.render,
            c.extract,
            c.inverse,
            spec.name
        );
        send(
            "fvr-fixed-bench-view-f32.bin",
            &[],
            views.float_image.iter().map(|v| v.to_le_bytes()),
        )
    }
}

#[cfg(target_os = "none")]
#[cortex_m_rt::entry]
fn main() -> ! {
    use fixed_input::LEN;
    let q15 = cortex_m::singleton!(Q15: [i16; LEN] = [0; LEN]);
    let q31 = cortex_m::singleton!(Q31: [i32; LEN] = [0; LEN]);
    let f32 = cortex_m::singleton!(F32: [f32; LEN] = [0.0; LEN]);
    // Each singleton is taken once, here.
    let (Some(q15), Some(q31), Some(f32)) = (q15, q31, f32) else {
        fvr_firmware::device::abort("blocks taken twice")
    };
    use device::{AUX, FLOAT_AUX};
    use fvr_core::slice::fixed::FixedPhases;
    use fvr_firmware::fixed_view::WIDTH;
    fn take<T>(buffer: Option<T>) -> T {
        buffer.unwrap_or_else(|| fvr_firmware::device::abort("view buffers taken twice"))
    }
    device::run(
        device::Blocks { q15, q31, f32 },
        device::Views {
            phases: take(cortex_m::singleton!(PHASES: FixedPhases<WIDTH> = FixedPhases::new())),
            grid: take(cortex_m::singleton!(GRID: [i32; LEN] = [0; LEN])),
            aux: take(cortex_m::singleton!(AUX_I32: [i32; AUX] = [0; AUX])),
            block: take(cortex_m::singleton!(BLOCK: [i16; LEN] = [0; LEN])),
            image: take(cortex_m::singleton!(IMAGE: [i16; LEN] = [0; LEN])),
            staged: take(cortex_m::singleton!(STAGED: [i16; LEN] = [0; LEN])),
            float_aux: take(cortex_m::singleton!(
                FLOAT_AUX_F32: [f32; FLOAT_AUX] = [0.0; FLOAT_AUX]
            )),
            float_image: take(cortex_m::singleton!(FLOAT_IMAGE: [f32; LEN] = [0.0; LEN])),
            float_staged: take(cortex_m::singleton!(FLOAT_STAGED: [f32; LEN] = [0.0; LEN])),
        },
    )
}

#[cfg(target_os = "none")]
fvr_firmware::hard_fault_handler!();

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "fvr-fixed-bench runs on thumbv7m-none-eabi under QEMU mps2-an385: bash scripts/firmware.sh"
    );
    std::process::exit(2);
}
