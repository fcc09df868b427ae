//! The input block of `fvr-fixed-bench`, made with integer arithmetic only,
//! so that the Cortex-M3 and the host build the same values. Shared by
//! path with `build.rs`, the program and the host test
//! (`tests/qemu_fixed.rs`).

/// Side of the square block.
pub const SIDE: usize = 64;
/// Values in the block.
pub const LEN: usize = SIDE * SIDE;

/// Seed of the linear congruential generator.
const SEED: u32 = 0x2545_F491;

/// The Q15 mantissas of a spectrum-like block, `x` fastest: a smooth
/// elliptic bump around the zero frequency (indices wrap, as frequencies
/// do), `(256 − r²)²/4` for `r² = dx² + 2·dy² < 256` (peak 16,384), plus
/// uniform noise in `[−2048, 2047]` from an LCG (Numerical Recipes
/// constants).
pub fn q15_block(out: &mut [i16]) {
    let mut state = SEED;
    for (i, v) in out.iter_mut().enumerate() {
        let wrap = |c: usize| c.min(SIDE - c) as i32;
        let (dx, dy) = (wrap(i % SIDE), wrap(i / SIDE));
        let r2 = dx * dx + 2 * dy * dy;
        let bump = if r2 < 256 {
            (256 - r2) * (256 - r2) / 4
        } else {
            0
        };
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let noise = (state >> 20) as i32 - 2048;
        *v = (bump + noise) as i16;
    }
}

/// A Q15 mantissa as the Q31 mantissa of the same value.
pub fn q31_from_q15(m: i16) -> i32 {
    (m as i32) << 16
}

/// A Q15 mantissa as the f32 of the same value (exact).
pub fn f32_from_q15(m: i16) -> f32 {
    m as f32 / 32768.0
}
