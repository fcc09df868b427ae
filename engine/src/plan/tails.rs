//! The tails term of an oblique view (`wrap.rs`): along each image axis,
//! the splat's `Σ f·sin(πδ)` sums on each canvas line through the image,
//! convolved with `(−1)^t·h(t)` over `|t| < n`.
//!
//! The kernel is the same for every line of every direction, so it is
//! transformed once and each line costs one real FFT forward and one back
//! of a length `M ≥ w + side − 1` (canvas width `w`, image side `side`):
//! every lag `p − c` between an image pixel and a canvas pixel is then a
//! distinct residue mod `M`, and the circular convolution of the line with
//! the kernel cut to those lags is the direct sum's, to the transform's
//! rounding (`O(ε·log₂M)` relative to the line's norm; tested against the
//! direct sum).

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};

/// The tails' error power is taken this many times the model's: it keeps
/// only the nearest pixel of the sinc along the other image axis and
/// samples a few directions (fitted so that no measured oblique view of
/// the real heads falls more than 3 dB below its prediction, from the
/// nominal 1; `tests/plan_real.rs`).
const TAIL_POWER_GAIN: f64 = 3.0;

/// `(−1)^t·h(t)` for `|t| < n` (index `t + n − 1`): the tails' kernel.
pub(super) fn tail_kernel(n: usize, reference: usize) -> Vec<f64> {
    use std::f64::consts::PI;
    let n_i = n as i64;
    let cot = |t: f64, m: usize| {
        if t == 0.0 {
            0.0
        } else {
            1.0 / ((PI * t / m as f64).tan() * m as f64)
        }
    };
    (1 - n_i..n_i)
        .map(|t| {
            // cot(πt/N)/N − 1/(πt) is smooth at 0; the difference of two is too.
            let h = cot(t as f64, n) - cot(t as f64, reference);
            let h = h * TAIL_POWER_GAIN.sqrt();
            if t % 2 == 0 {
                h
            } else {
                -h
            }
        })
        .collect()
}

/// The smallest `2^a·3^b·5^c ≥ at_least`: a length the FFT handles with
/// its fastest radices.
fn smooth_length(at_least: usize) -> usize {
    (at_least.max(1)..)
        .find(|&m| {
            let mut r = m;
            for f in [2, 3, 5] {
                while r % f == 0 {
                    r /= f;
                }
            }
            r == 1
        })
        .unwrap_or(at_least)
}

/// The tails of one grid side `n`, for canvases of half-width `half` and
/// images of side `side`.
pub(super) struct Tails {
    /// Canvas half-width: canvas pixel `c` at index `c + half`.
    half: i64,
    side: i64,
    m: usize,
    /// The kernel cut to the lags `p − c` that occur, wrapped mod `M`,
    /// transformed and scaled by `1/M` (the inverse is unnormalised).
    kernel_hat: Vec<Complex<f64>>,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
}

impl Tails {
    /// The tails on the grid of side `n` against the ideal period
    /// `reference`.
    pub(super) fn new(n: usize, reference: usize, half: i64, side: usize) -> Self {
        let kernel = tail_kernel(n, reference);
        let (n, side) = (n as i64, side as i64);
        let w = 2 * half + 1;
        let m = smooth_length((w + side - 1) as usize);
        let mut planner = RealFftPlanner::<f64>::new();
        let (r2c, c2r) = (planner.plan_fft_forward(m), planner.plan_fft_inverse(m));
        // Output index o = p − lo, input index i = c + half: the lag is
        // t = o − i + lo + half, o − i ∈ [1 − w, side − 1].
        let lo = -side / 2;
        let mut wrapped = vec![0.0; m];
        for d in 1 - w..side {
            let t = d + lo + half;
            if t.abs() < n {
                wrapped[d.rem_euclid(m as i64) as usize] = kernel[(t + n - 1) as usize];
            }
        }
        let mut kernel_hat = r2c.make_output_vec();
        r2c.process(&mut wrapped, &mut kernel_hat)
            .expect("lengths come from the plan");
        let scale = 1.0 / m as f64;
        for k in &mut kernel_hat {
            *k *= scale;
        }
        Self {
            half,
            side,
            m,
            kernel_hat,
            r2c,
            c2r,
        }
    }

    /// Subtract the tails of the canvas `cells` (`w × w`, row `q` holding
    /// image row `q`; per pixel the plain sum, then the offsets' sums along
    /// the image's right and up axes) from the `side × side` error image
    /// `err` (the expansion's minus sign).
    pub(super) fn subtract(&self, cells: &[[f64; 3]], err: &mut [f64]) {
        let (half, side) = (self.half, self.side);
        let w = 2 * half + 1;
        let lo = -side / 2;
        let mut line = self.r2c.make_input_vec();
        let mut spectrum = self.r2c.make_output_vec();
        let mut out = self.c2r.make_output_vec();
        let mut scratch = self
            .r2c
            .make_scratch_vec()
            .into_iter()
            .chain(self.c2r.make_scratch_vec())
            .collect::<Vec<_>>();
        let last = spectrum.len() - 1;
        for a in 0..2 {
            for image_line in lo..lo + side {
                let l = image_line + half;
                if !(0..w).contains(&l) {
                    continue;
                }
                let l = l as usize;
                let w = w as usize;
                // The canvas values along axis a on this line.
                line.fill(0.0);
                for (c, v) in line[..w].iter_mut().enumerate() {
                    let at = if a == 0 { l * w + c } else { c * w + l };
                    *v = cells[at][1 + a];
                }
                if line[..w].iter().all(|&v| v == 0.0) {
                    continue;
                }
                self.r2c
                    .process_with_scratch(&mut line, &mut spectrum, &mut scratch)
                    .expect("lengths come from the plan");
                for (s, k) in spectrum.iter_mut().zip(&self.kernel_hat) {
                    *s *= k;
                }
                // Both are real at 0 and (even M) at M/2: keep it exact.
                spectrum[0].im = 0.0;
                if self.m % 2 == 0 {
                    spectrum[last].im = 0.0;
                }
                self.c2r
                    .process_with_scratch(&mut spectrum, &mut out, &mut scratch)
                    .expect("lengths come from the plan");
                let row = (image_line - lo) as usize;
                let side = side as usize;
                for (o, &e) in out[..side].iter().enumerate() {
                    let at = if a == 0 {
                        row * side + o
                    } else {
                        o * side + row
                    };
                    err[at] -= e;
                }
            }
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The direct convolution the transform replaces: the reference.
    pub(in super::super) fn subtract_direct(
        cells: &[[f64; 3]],
        half: i64,
        kernel: &[f64],
        n: i64,
        side: i64,
        err: &mut [f64],
    ) {
        let w = 2 * half + 1;
        let lo = -side / 2;
        for a in 0..2 {
            for line in lo..lo + side {
                let l = line + half;
                if !(0..w).contains(&l) {
                    continue;
                }
                let at = |c: i64| {
                    let at = if a == 0 { l * w + c } else { c * w + l };
                    cells[at as usize][1 + a]
                };
                for p in lo..lo + side {
                    let mut e = 0.0;
                    for c in 0..w {
                        let t = p - (c - half);
                        if t.abs() < n {
                            e += kernel[(t + n - 1) as usize] * at(c);
                        }
                    }
                    let (row, col) = if a == 0 { (line, p) } else { (p, line) };
                    err[((row - lo) * side + col - lo) as usize] -= e;
                }
            }
        }
    }

    #[test]
    fn smooth_lengths_have_only_small_factors() {
        assert_eq!(smooth_length(704), 720);
        assert_eq!(smooth_length(1), 1);
        assert_eq!(smooth_length(97), 100);
        assert_eq!(smooth_length(128), 128);
    }

    #[test]
    fn the_transform_agrees_with_the_direct_sum_to_rounding() {
        let mut state = 0x9e37_79b9_u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state % 2001) as f64 / 1000.0 - 1.0
        };
        // Canvases wider and narrower than the image, odd and even sides,
        // grids below the reference and at half of it.
        for (n, reference, half, side) in [(32, 64, 24, 32), (40, 64, 10, 40), (33, 64, 30, 17)] {
            let w = (2 * half + 1) as usize;
            let cells: Vec<[f64; 3]> = (0..w * w)
                .map(|i| {
                    let mut v = || if i % 5 == 0 { 0.0 } else { next() };
                    [v(), v(), v()]
                })
                .collect();
            let tails = Tails::new(n, reference, half, side);
            let mut fast = vec![0.0; side * side];
            tails.subtract(&cells, &mut fast);
            let mut slow = vec![0.0; side * side];
            let kernel = tail_kernel(n, reference);
            subtract_direct(&cells, half, &kernel, n as i64, side as i64, &mut slow);
            // Each pixel takes one line per axis. The transform's error on
            // a line is within ε·log₂M·‖k‖₁·‖v‖₂ times a small constant
            // (10 here); the direct sum's within w·ε·‖k‖₁·max|v|.
            let k1: f64 = kernel.iter().map(|k| k.abs()).sum();
            let v2 = (w as f64).sqrt(); // |v| ≤ 1
            let log_m = (tails.m as f64).log2();
            let bound = 2.0 * (10.0 * log_m * v2 + w as f64) * f64::EPSILON * k1;
            let worst = fast
                .iter()
                .zip(&slow)
                .map(|(f, s)| (f - s).abs())
                .fold(0.0, f64::max);
            let largest = slow.iter().fold(0.0f64, |m, s| m.max(s.abs()));
            assert!(worst <= bound, "n={n} half={half}: {worst} > {bound}");
            // Not vacuous: the tails are many orders above the bound.
            assert!(largest > 1e6 * bound, "{largest}");
        }
    }
}
