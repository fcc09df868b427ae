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
use std::sync::OnceLock;

use super::splat::{lattice_step, splat_in};
use super::tails::Tails;
use crate::memory::written_zeros;
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

/// One view's unwrapped shadow ([`splat_in`]): per pixel of a square canvas
/// of side `2·half + 1`, `Σf` and `Σf·sin(πδ)` along the image's right and
/// up axes.
struct Shadow {
    half: i64,
    cells: Vec<[f64; 3]>,
}

/// The volume's shadows along [`DIRECTIONS`], made once, when a grid side
/// first needs them, and folded for each grid side.
pub(super) struct Shadows<'a> {
    volume: &'a Volume,
    /// The canvas's half side: every voxel's pixel lies within it.
    half: i64,
    /// The ideal image's period `N_ref`.
    reference: usize,
    shadows: OnceLock<Vec<Shadow>>,
}

impl<'a> Shadows<'a> {
    pub(super) fn new(volume: &'a Volume) -> Self {
        let d = volume.dims;
        // Voxel i sits at i − ⌊d/2⌋ from the transform origin: the
        // canvas reaches beyond the farthest corner.
        let c = d.map(|v| (v / 2) as f64);
        let reach = (0..3)
            .map(|a| c[a].max((d[a] - 1) as f64 - c[a]).powi(2))
            .sum::<f64>()
            .sqrt();
        let half = reach.ceil() as i64 + 1;
        let reference = 2 * padded_size(d, 1).unwrap_or(1);
        Self {
            volume,
            half,
            reference,
            shadows: OnceLock::new(),
        }
    }

    /// The shadows, splatted on first use.
    fn splats(&self) -> &[Shadow] {
        let (volume, half) = (self.volume, self.half);
        self.shadows.get_or_init(|| {
            DIRECTIONS
                .par_iter()
                .map_init(Vec::new, |ring, &dir| {
                    let up = if dir[0] == 0.0 && dir[1] == 0.0 {
                        [0.0, 1.0, 0.0]
                    } else {
                        [0.0, 0.0, 1.0]
                    };
                    let frame = View { dir, up }.frame().expect("fixed directions");
                    let step = lattice_step(dir);
                    let cells = splat_in(volume, frame.right, frame.up, half, step, ring);
                    Shadow { half, cells }
                })
                .collect()
        })
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
        let half = self.half;
        let with_tails = with_tails && n < self.reference;
        // A canvas inside [−n/2, n/2) folds nothing, and without tails the
        // error image is zero: the ratio is 0 whatever the content, so the
        // splat is not made (σ = 2 grids).
        if !with_tails && half < (n / 2) as i64 {
            return 0.0;
        }
        let tails = with_tails.then(|| Tails::new(n, self.reference, half, side));
        self.splats()
            .par_iter()
            .map(|s| {
                let (mut err, signal) = folded(s, n, side);
                if let Some(tails) = &tails {
                    tails.subtract(&s.cells, &mut err);
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

/// The `side × side` error image of `s` on the grid of side `n`, the shadow
/// beyond `[−n/2, n/2)` folded into the image, and the energy `Σs²` of the
/// shadow in it.
fn folded(s: &Shadow, n: usize, side: usize) -> (Vec<f64>, f64) {
    let (n, side) = (n as i64, side as i64);
    let fold = |p: i64| (p + n / 2).rem_euclid(n) - n / 2;
    let window = |p: i64| p >= -side / 2 && p < side - side / 2;
    let w = (2 * s.half + 1) as usize;
    let len = side as usize;
    let mut err = written_zeros::<f64>(len * len);
    let mut signal = 0.0;
    for (row, line) in s.cells.chunks_exact(w).enumerate() {
        let q = row as i64 - s.half;
        let fq = fold(q);
        if !window(fq) {
            continue;
        }
        for (col, &[v, _, _]) in line.iter().enumerate() {
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
    (err, signal)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(side: usize) -> Volume {
        Volume::new([side; 3], vec![1.0; side * side * side])
    }

    #[test]
    fn grids_that_cannot_wrap_skip_the_splat_and_lose_nothing() {
        // The full box has the widest shadows; on twice its side the
        // canvas lies inside the image and there are no tails.
        let volume = cube(32);
        let shadows = Shadows::new(&volume);
        assert_eq!(shadows.worst_ratio(64, 32), 0.0);
        assert!(shadows.shadows.get().is_none());
        for s in shadows.splats() {
            let (err, signal) = folded(s, 64, 32);
            assert!(signal > 0.0);
            assert!(err.iter().all(|&e| e == 0.0));
        }
        assert!(shadows.worst_ratio(32, 32) > 0.0);
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
        let volume = ball(true);
        let shadows = Shadows::new(&volume);
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
    fn the_ratio_agrees_with_the_direct_tails_to_rounding() {
        use crate::plan::tails::{tail_kernel, tests::subtract_direct};
        for volume in [ball(true), ball(false), cube(20)] {
            let shadows = Shadows::new(&volume);
            for (n, side) in [(32, 32), (40, 32), (48, 24), (36, 36)] {
                let fast = shadows.worst_ratio(n, side);
                let kernel = tail_kernel(n, shadows.reference);
                let k1: f64 = kernel.iter().map(|k| k.abs()).sum();
                let mut slow = 0.0f64;
                let mut tolerance = 0.0f64;
                for s in shadows.splats() {
                    let (mut err, signal) = folded(s, n, side);
                    subtract_direct(&s.cells, s.half, &kernel, n as i64, side as i64, &mut err);
                    let e2: f64 = err.iter().map(|e| e * e).sum();
                    slow = slow.max(e2 / signal);
                    // Per pixel, as in `tails.rs`: two lines, each within
                    // (10·log₂M + w)·ε·‖k‖₁·‖v‖₂ (‖v‖₂ at most the canvas's);
                    // then |ΔΣe²| ≤ 2‖e‖‖δ‖ + ‖δ‖².
                    let w = (2 * s.half + 1) as f64;
                    let v2 = s
                        .cells
                        .iter()
                        .flat_map(|c| &c[1..])
                        .map(|v| v * v)
                        .sum::<f64>()
                        .sqrt();
                    let log_m = (2.0 * w + side as f64).log2();
                    let pixel = 2.0 * (10.0 * log_m + w) * f64::EPSILON * k1 * v2;
                    let delta = pixel * side as f64;
                    tolerance = tolerance.max((2.0 * e2.sqrt() * delta + delta * delta) / signal);
                }
                assert!(
                    (fast - slow).abs() <= tolerance,
                    "n={n} side={side}: {fast} vs {slow} (tolerance {tolerance})"
                );
                // Not vacuous: tails present and far above the tolerance.
                assert!(slow > 1e6 * tolerance, "n={n} side={side}: {slow}");
            }
        }
    }
}
