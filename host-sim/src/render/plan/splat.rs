//! One direction's shadow of the volume (`wrap.rs`): each voxel added to
//! its nearest pixel on a square canvas centred on the volume's centre,
//! plain and weighted by `sin(πδ)` of its offset `δ` from that pixel
//! along the image's right and up axes.
//!
//! The three sums of a pixel sit side by side (one cache line for the
//! three additions of a voxel), the products of the x coordinate with the
//! frame are made once per direction, and `sin(πδ)` is a polynomial
//! without divisions: the additions are the voxel loop's, in its order, so
//! the plain sums are bit for bit its, and the weighted ones agree to the
//! polynomial's rounding (tested).

use crate::volume::Volume;

/// `sin(πδ)` for `|δ| ≤ ½` to 0.5% (odd Taylor polynomial to degree 5,
/// `πδ − (πδ)³/6 + (πδ)⁵/120`, in Horner form in `δ`): one per voxel and
/// direction.
pub(super) fn sin_pi(d: f64) -> f64 {
    use std::f64::consts::PI;
    const C1: f64 = PI;
    const C3: f64 = -PI * PI * PI / 6.0;
    const C5: f64 = PI * PI * PI * PI * PI / 120.0;
    let d2 = d * d;
    d * (C1 + d2 * (C3 + d2 * C5))
}

/// The canvas of side `2·half + 1` of the view with right and up axes
/// `r`, `u`: per pixel (row `q` fastest-varying last) the sum `Σf`, then
/// `Σf·sin(πδ)` along `r` and along `u`.
pub(super) fn splat(volume: &Volume, r: [f64; 3], u: [f64; 3], half: i64) -> Vec<[f64; 3]> {
    let d = volume.dims;
    // Voxel i sits at i − ⌊d/2⌋ from the transform origin.
    let c = d.map(|v| (v / 2) as f64);
    let side = (2 * half + 1) as usize;
    let mut cells = vec![[0.0; 3]; side * side];
    // Pixels from the canvas corner, plus ½ so that truncation rounds to
    // the nearest (every coordinate is non-negative).
    let offset = half as f64 + 0.5;
    let along_x =
        |axis: [f64; 3]| -> Vec<f64> { (0..d[0]).map(|i| (i as f64 - c[0]) * axis[0]).collect() };
    let (xr, xu) = (along_x(r), along_x(u));
    // The cell being added to, held in registers while consecutive voxels
    // fall on it (the same additions in the same order).
    let (mut at, mut acc) = (usize::MAX, [0.0; 3]);
    for k in 0..d[2] {
        let z = k as f64 - c[2];
        for j in 0..d[1] {
            let y = j as f64 - c[1];
            let p0 = y * r[1] + z * r[2] + offset;
            let q0 = y * u[1] + z * u[2] + offset;
            let row = &volume.data[(k * d[1] + j) * d[0]..][..d[0]];
            for ((&v, &xr), &xu) in row.iter().zip(&xr).zip(&xu) {
                if v == 0.0 {
                    continue;
                }
                let (yp, yq) = (xr + p0, xu + q0);
                let (p, q) = (yp as usize, yq as usize);
                let here = q * side + p;
                if here != at {
                    if let Some(cell) = cells.get_mut(at) {
                        *cell = acc;
                    }
                    at = here;
                    match cells.get(at) {
                        Some(cell) => acc = *cell,
                        None => continue,
                    }
                }
                let v = f64::from(v);
                acc[0] += v;
                // The offsets from the nearest pixel, in [−½, ½).
                acc[1] += v * sin_pi(yp - p as f64 - 0.5);
                acc[2] += v * sin_pi(yq - q as f64 - 0.5);
            }
        }
    }
    if let Some(cell) = cells.get_mut(at) {
        *cell = acc;
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The polynomial of [`sin_pi`] as first written, with divisions.
    fn sin_pi_divided(d: f64) -> f64 {
        let x = std::f64::consts::PI * d;
        let x2 = x * x;
        x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0))
    }

    /// The voxel loop the splat replaces, three canvases apart, and per
    /// pixel `Σ|f|` and the voxel count: the reference.
    fn reference(volume: &Volume, r: [f64; 3], u: [f64; 3], half: i64) -> [Vec<f64>; 5] {
        let d = volume.dims;
        let c = d.map(|v| (v / 2) as f64);
        let side = (2 * half + 1) as usize;
        let mut out: [Vec<f64>; 5] = core::array::from_fn(|_| vec![0.0; side * side]);
        let offset = half as f64 + 0.5;
        for k in 0..d[2] {
            for j in 0..d[1] {
                for i in 0..d[0] {
                    let v = f64::from(volume.get(i, j, k));
                    if v == 0.0 {
                        continue;
                    }
                    let [x, y, z] = [i as f64 - c[0], j as f64 - c[1], k as f64 - c[2]];
                    let yp = x * r[0] + (y * r[1] + z * r[2] + offset);
                    let yq = x * u[0] + (y * u[1] + z * u[2] + offset);
                    let (p, q) = (yp as usize, yq as usize);
                    let at = q * side + p;
                    if at < side * side {
                        out[0][at] += v;
                        out[1][at] += v * sin_pi_divided(yp - p as f64 - 0.5);
                        out[2][at] += v * sin_pi_divided(yq - q as f64 - 0.5);
                        out[3][at] += v.abs();
                        out[4][at] += 1.0;
                    }
                }
            }
        }
        out
    }

    #[test]
    fn the_splat_is_the_voxel_loop_to_rounding() {
        let dims = [13, 10, 7];
        let volume = super::super::test_volume::random(dims, 6);
        let s = 0.5f64.sqrt();
        // A generic frame and a face diagonal's, on a canvas reaching
        // beyond the box's corners (as `wrap.rs` makes it).
        for (r, u, half) in [
            ([0.6, -0.48, 0.64], [-0.8, -0.36, 0.48], 10),
            ([s, -s, 0.0], [0.0, 0.0, 1.0], 12),
        ] {
            let fast = splat(&volume, r, u, half);
            let slow = reference(&volume, r, u, half);
            let plain: Vec<f64> = fast.iter().map(|cell| cell[0]).collect();
            assert_eq!(plain, slow[0], "half {half}");
            for t in 1..3 {
                for (at, cell) in fast.iter().enumerate() {
                    // Each term within 8ε of the divided polynomial's (both
                    // a few roundings from the exact one), and each of the
                    // `count` additions within ε of the running sum.
                    let bound = (8.0 + 2.0 * slow[4][at]) * f64::EPSILON * slow[3][at];
                    let diff = (cell[t] - slow[t][at]).abs();
                    assert!(diff <= bound, "sum {t} at {at}: {diff} > {bound}");
                }
            }
            // Not vacuous: many pixels hit.
            assert!(slow[0].iter().filter(|&&v| v != 0.0).count() > 20);
        }
    }

    #[test]
    fn sin_pi_is_accurate_to_half_a_percent() {
        for i in 0..=50 {
            let d = i as f64 / 100.0;
            let exact = (std::f64::consts::PI * d).sin();
            assert!((sin_pi(d) - exact).abs() <= 5e-3 * exact.max(1e-300), "{d}");
            // The divided form's polynomial, to its rounding.
            let divided = sin_pi_divided(d);
            assert!(
                (sin_pi(d) - divided).abs() <= 8.0 * f64::EPSILON * divided,
                "{d}"
            );
        }
    }
}
