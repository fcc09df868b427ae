//! The wrap term of a prediction: an oblique view's shadow of the volume
//! is wider than its box, and the image, periodic with the grid's side
//! `n` (the slice is sampled `n` times across), folds what lies beyond
//! `±n/2` back over itself at full strength. Axis views never see it (a
//! box side is at most `n`), so the axis-view model misses it.
//!
//! The shadows are estimated by splatting each voxel to its nearest pixel
//! along the box's face and body diagonals, the views whose shadow is
//! widest, each with the command line's default up (0, 0, 1).
//!
//! The same splat gives the **tails** term: an oblique view projects voxels
//! between pixels, and the band-limited image of such a point is a
//! periodic sinc (`D_N(t) = sin(πt)·cot(πt/N)/N` for an image repeating
//! every `N` pixels) whose tails, unlike an on-pixel point's, do not vanish
//! on the other pixels. The pipeline's image repeats every grid side `n`;
//! the ideal one every `N_ref` = twice the σ = 1 side (the ideal slice DFT
//! on a 2× slice, the limit of 2× padding). Per axis, at pixel `p` from a
//! point at `c + δ` (`c` its nearest pixel):
//!
//! `D_n(p − c − δ) − D_ref(p − c − δ) ≈ −(−1)^{p−c}·sin(πδ)·h(p − c)`,
//! `h(t) = cot(πt/n)/n − cot(πt/N_ref)/N_ref`,
//!
//! smooth (`h(t) ≈ −πt/4n²` near 0 for `N_ref = 2n`) up to the fold at
//! `|t| = n`. The 2D kernel differs by that along one axis times the sinc
//! along the other, taken as its nearest pixel; so each splat keeps, per
//! pixel, `Σ f·sin(πδ)` along each image axis, and the error is two 1D
//! convolutions of those with `(−1)^t·h(t)`. It is the content between
//! pixels, modulated at the image's Nyquist frequency: the volume's
//! spectral energy near Nyquist, which a head resampled to a few voxels
//! carries and a smooth phantom does not. It is independent of the kernel.

use fvr_core::geometry::View;
use fvr_core::volume::padded_size;
use rayon::prelude::*;

use crate::volume::Volume;

/// The oblique directions: four generic ones (no image axis along a grid
/// axis, so that both image axes fall between pixels: the tails' worst
/// case), the six face diagonals and the four body diagonals.
const DIRECTIONS: [[f64; 3]; 14] = [
    [0.7, 0.2, 1.0],
    [0.4, -1.0, 0.55],
    [1.0, 0.35, -0.6],
    [0.15, 0.8, -1.0],
    [1.0, 1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 0.0, 1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, 1.0],
    [0.0, 1.0, -1.0],
    [1.0, 1.0, 1.0],
    [1.0, -1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [-1.0, -1.0, 1.0],
];

/// One view's unwrapped shadow: pixel sums on a square canvas of side
/// `2·half + 1` centred on the volume's centre, and the sums weighted by
/// `sin(πδ)` of each voxel's offset from its pixel along the image's
/// right and up axes.
struct Shadow {
    half: i64,
    sums: Vec<f64>,
    off: [Vec<f64>; 2],
}

/// The volume's shadows along [`DIRECTIONS`], made once and folded for
/// each grid side.
pub(super) struct Shadows {
    shadows: Vec<Shadow>,
    /// The ideal image's period `N_ref`.
    reference: usize,
}

/// The tails' error power is taken this many times the model's: it keeps
/// only the nearest pixel of the sinc along the other image axis and
/// samples a few directions (fitted so that no measured oblique view of
/// the real heads falls more than 3 dB below its prediction, from the
/// nominal 1; `tests/plan_real.rs`).
const TAIL_POWER_GAIN: f64 = 3.0;

/// `sin(πδ)` for `|δ| ≤ ½` to 0.5% (odd Taylor polynomial to degree 5):
/// one per voxel and direction.
fn sin_pi(d: f64) -> f64 {
    let x = std::f64::consts::PI * d;
    let x2 = x * x;
    x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0))
}

/// `(−1)^t·h(t)` for `|t| < n` (index `t + n − 1`): the tails' kernel.
fn tail_kernel(n: usize, reference: usize) -> Vec<f64> {
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

impl Shadows {
    pub(super) fn new(volume: &Volume) -> Self {
        let d = volume.dims;
        // Voxel i sits at i − ⌊d/2⌋ from the transform origin.
        let c = d.map(|v| (v / 2) as f64);
        let reach = (0..3)
            .map(|a| c[a].max((d[a] - 1) as f64 - c[a]).powi(2))
            .sum::<f64>()
            .sqrt();
        let half = reach.ceil() as i64 + 1;
        let reference = 2 * padded_size(d, 1).unwrap_or(1);
        let side = (2 * half + 1) as usize;
        let shadows = DIRECTIONS
            .par_iter()
            .map(|&dir| {
                let up = if dir[0] == 0.0 && dir[1] == 0.0 {
                    [0.0, 1.0, 0.0]
                } else {
                    [0.0, 0.0, 1.0]
                };
                let frame = View { dir, up }.frame().expect("fixed directions");
                let (r, u) = (frame.right, frame.up);
                let mut sums = vec![0.0; side * side];
                let mut off = [vec![0.0; side * side], vec![0.0; side * side]];
                // Pixels from the canvas corner, plus ½ so that truncation
                // rounds to the nearest (every coordinate is non-negative).
                let offset = half as f64 + 0.5;
                for k in 0..d[2] {
                    let z = k as f64 - c[2];
                    for j in 0..d[1] {
                        let y = j as f64 - c[1];
                        let p0 = y * r[1] + z * r[2] + offset;
                        let q0 = y * u[1] + z * u[2] + offset;
                        let row = &volume.data[(k * d[1] + j) * d[0]..][..d[0]];
                        for (i, &v) in row.iter().enumerate() {
                            if v == 0.0 {
                                continue;
                            }
                            let x = i as f64 - c[0];
                            let (yp, yq) = (x * r[0] + p0, x * u[0] + q0);
                            let (p, q) = (yp as usize, yq as usize);
                            let at = q * side + p;
                            if at < sums.len() {
                                let v = f64::from(v);
                                sums[at] += v;
                                // The offsets from the nearest pixel, in [−½, ½).
                                off[0][at] += v * sin_pi(yp - p as f64 - 0.5);
                                off[1][at] += v * sin_pi(yq - q as f64 - 0.5);
                            }
                        }
                    }
                }
                Shadow { half, sums, off }
            })
            .collect();
        Self { shadows, reference }
    }

    /// The worst share of error energy over the directions, `Σe²/Σs²`, in
    /// a `side × side` image on the grid of side `n`: `e` the shadow
    /// beyond `[−n/2, n/2)` folded into the image plus the tails, `s` the
    /// shadow in it.
    pub(super) fn worst_ratio(&self, n: usize, side: usize) -> f64 {
        self.ratio(n, side, true)
    }

    /// [`Self::worst_ratio`], the tails left out unless `with_tails`.
    fn ratio(&self, n: usize, side: usize, with_tails: bool) -> f64 {
        let kernel = (with_tails && n < self.reference).then(|| tail_kernel(n, self.reference));
        let (n, side) = (n as i64, side as i64);
        let fold = |p: i64| (p + n / 2).rem_euclid(n) - n / 2;
        let window = |p: i64| p >= -side / 2 && p < side - side / 2;
        self.shadows
            .par_iter()
            .map(|s| {
                let w = (2 * s.half + 1) as usize;
                let len = side as usize;
                let mut err = vec![0.0; len * len];
                let mut signal = 0.0;
                for (row, line) in s.sums.chunks_exact(w).enumerate() {
                    let q = row as i64 - s.half;
                    let fq = fold(q);
                    if !window(fq) {
                        continue;
                    }
                    for (col, &v) in line.iter().enumerate() {
                        let p = col as i64 - s.half;
                        let fp = fold(p);
                        if v == 0.0 || !window(fp) {
                            continue;
                        }
                        if fp == p && fq == q {
                            signal += v * v;
                        } else {
                            err[((fq + side / 2) * side + fp + side / 2) as usize] += v;
                        }
                    }
                }
                if let Some(h) = &kernel {
                    tails(s, h, n, side, &mut err);
                }
                let e2: f64 = err.iter().map(|e| e * e).sum();
                if signal > 0.0 {
                    e2 / signal
                } else {
                    0.0
                }
            })
            .reduce(|| 0.0, f64::max)
    }
}

/// Add the tails of `shadow` to the `side × side` error image `err`
/// (module docs): along each image axis, the offsets' sums on the canvas
/// line through each image line, convolved with `kernel` = `(−1)^t·h(t)`
/// (minus sign of the expansion included) over `|t| < n`.
fn tails(shadow: &Shadow, kernel: &[f64], n: i64, side: i64, err: &mut [f64]) {
    let half = shadow.half;
    let w = 2 * half + 1;
    let lo = -side / 2;
    for a in 0..2 {
        let off = &shadow.off[a];
        for line in lo..lo + side {
            let l = line + half;
            if !(0..w).contains(&l) {
                continue;
            }
            // Canvas values along axis a on this line.
            let at = |c: i64| {
                if a == 0 {
                    off[(l * w + c) as usize]
                } else {
                    off[(c * w + l) as usize]
                }
            };
            let values: Vec<(i64, f64)> = (0..w)
                .map(|c| (c - half, at(c)))
                .filter(|&(_, v)| v != 0.0)
                .collect();
            for p in lo..lo + side {
                let mut e = 0.0;
                for &(c, v) in &values {
                    let t = p - c;
                    if t.abs() < n {
                        e += kernel[(t + n - 1) as usize] * v;
                    }
                }
                let (row, col) = if a == 0 { (line, p) } else { (p, line) };
                err[((row - lo) * side + col - lo) as usize] -= e;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(side: usize) -> Volume {
        Volume::new([side; 3], vec![1.0; side * side * side])
    }

    #[test]
    fn a_full_box_wraps_on_its_diagonals_and_not_on_twice_its_side() {
        let volume = cube(32);
        let shadows = Shadows::new(&volume);
        // The face diagonal's shadow is 32·√2 ≈ 45 wide: beyond ±16 on
        // the grid of side 32, within ±32 on the grid of side 64.
        let tight = shadows.worst_ratio(32, 32);
        assert!(tight > 1e-2, "{tight}");
        assert_eq!(shadows.worst_ratio(64, 32), 0.0);
    }

    #[test]
    fn a_ball_inside_the_sphere_of_the_grid_never_wraps() {
        let n = 32;
        let mut data = vec![0.0f32; n * n * n];
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let r2 = [i, j, k]
                        .iter()
                        .map(|&v| (v as f64 - 16.0).powi(2))
                        .sum::<f64>();
                    if r2 < 14.0f64.powi(2) {
                        data[(k * n + j) * n + i] = 1.0;
                    }
                }
            }
        }
        let volume = Volume::new([n; 3], data);
        assert_eq!(Shadows::new(&volume).ratio(32, 32, false), 0.0);
    }

    /// A ball of radius 12 in a 32³ box: sharp (0 or 1) or a Gaussian
    /// of width 3.
    fn ball(sharp: bool) -> Volume {
        let n = 32;
        let data = (0..n * n * n)
            .map(|idx| {
                let r2 = [idx % n, idx / n % n, idx / (n * n)]
                    .iter()
                    .map(|&v| (v as f64 - 16.0).powi(2))
                    .sum::<f64>();
                let v = if sharp {
                    f64::from(u8::from(r2 < 144.0))
                } else {
                    (-r2 / 18.0).exp()
                };
                v as f32
            })
            .collect();
        Volume::new([n; 3], data)
    }

    #[test]
    fn tails_vanish_at_the_reference_period_and_grow_as_the_grid_shrinks() {
        let shadows = Shadows::new(&ball(true));
        // The ball's shadow never wraps; the tails are what remains.
        let (at32, at40, at48) = (
            shadows.worst_ratio(32, 32),
            shadows.worst_ratio(40, 32),
            shadows.worst_ratio(48, 32),
        );
        assert_eq!(shadows.worst_ratio(64, 32), 0.0);
        assert!(
            at32 > at40 && at40 > at48 && at48 > 0.0,
            "{at32} {at40} {at48}"
        );
        // A sharp edge in 32 voxels: tails far above f16 rounding (−66 dB).
        assert!(at32 > 1e-5, "{at32}");
    }

    #[test]
    fn tails_follow_content_near_nyquist() {
        let sharp = Shadows::new(&ball(true)).worst_ratio(32, 32);
        let smooth = Shadows::new(&ball(false)).worst_ratio(32, 32);
        // The Gaussian (σ = 3 voxels, 1e-6 at the faces) has e^{−π²σ²/2} at
        // Nyquist: no tails. The model, first order in the offsets, keeps
        // a floor from the lattice of projected voxels, 8.5 dB below the
        // sharp ball's: it errs on the safe side.
        assert!(smooth < 0.25 * sharp, "smooth {smooth}, sharp {sharp}");
    }

    #[test]
    fn sin_pi_is_accurate_to_half_a_percent() {
        for i in 0..=50 {
            let d = i as f64 / 100.0;
            let exact = (std::f64::consts::PI * d).sin();
            assert!((sin_pi(d) - exact).abs() <= 5e-3 * exact.max(1e-300), "{d}");
        }
    }
}
