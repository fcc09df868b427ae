//! The wrap term of a prediction: an oblique view's shadow of the volume
//! is wider than its box, and the image, periodic with the grid's side
//! `n` (the slice is sampled `n` times across), folds what lies beyond
//! `±n/2` back over itself at full strength. Axis views never see it (a
//! box side is at most `n`), so the axis-view model misses it.
//!
//! The shadows are estimated by splatting each voxel to its nearest pixel
//! along the box's face and body diagonals, the views whose shadow is
//! widest, each with the command line's default up (0, 0, 1).

use fvr_core::geometry::View;
use rayon::prelude::*;

use crate::volume::Volume;

/// The oblique directions: the six face diagonals and the four body
/// diagonals.
const DIRECTIONS: [[f64; 3]; 10] = [
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
/// `2·half + 1` centred on the volume's centre.
struct Shadow {
    half: i64,
    sums: Vec<f64>,
}

/// The volume's shadows along [`DIRECTIONS`], made once and folded for
/// each grid side.
pub(super) struct Shadows {
    shadows: Vec<Shadow>,
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
                            let p = (x * r[0] + p0) as usize;
                            let q = (x * u[0] + q0) as usize;
                            if let Some(s) = sums.get_mut(q * side + p) {
                                *s += f64::from(v);
                            }
                        }
                    }
                }
                Shadow { half, sums }
            })
            .collect();
        Self { shadows }
    }

    /// The worst share of error energy over the directions, `Σe²/Σs²`, in
    /// a `side × side` image on the grid of side `n`: `e` the shadow
    /// beyond `[−n/2, n/2)` folded into the image, `s` the shadow in it.
    pub(super) fn worst_ratio(&self, n: usize, side: usize) -> f64 {
        let (n, side) = (n as i64, side as i64);
        let fold = |p: i64| (p + n / 2).rem_euclid(n) - n / 2;
        let window = |p: i64| p >= -side / 2 && p < side - side / 2;
        self.shadows
            .iter()
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
                let e2: f64 = err.iter().map(|e| e * e).sum();
                if signal > 0.0 {
                    e2 / signal
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max)
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
        assert_eq!(Shadows::new(&volume).worst_ratio(32, 32), 0.0);
    }
}
