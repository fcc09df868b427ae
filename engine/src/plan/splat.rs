//! One direction's shadow of the volume (`wrap.rs`): each voxel added to
//! its nearest pixel on a square canvas centred on the volume's centre,
//! plain and weighted by `sin(πδ)` of its offset `δ` from that pixel
//! along the image's right and up axes.
//!
//! Every direction the planner splats along is a multiple of a short
//! lattice step `v` (the body diagonal's is (1, 1, 1)), and the voxels on
//! a line `x + t·v` project to one point. So the volume is first summed
//! along those lines, row by row (a row adds the line sums of the row one
//! step back, shifted by `v_x`: contiguous, in a ring of `v_z + 1`
//! planes), and only each line's sum is splatted, at its last voxel, with
//! `sin(πδ)` taken once for the line: `Σ f·sin(πδ) = sin(πδ)·Σ f` on a
//! line. A 256³ volume has `256²·(|v_x| + |v_y| + |v_z|)` lines, 6 to 128
//! times fewer than voxels for the planner's directions. The sums are the
//! voxel loop's reordered (tested against it).
//!
//! `sin(πδ)` is a polynomial without divisions.

use crate::memory::written_zeros;
use crate::volume::Volume;

/// `sin(πδ)` for `|δ| ≤ ½` to 0.5% (odd Taylor polynomial to degree 5,
/// `πδ − (πδ)³/6 + (πδ)⁵/120`, in Horner form in `δ`): one per line and
/// direction.
pub(super) fn sin_pi(d: f64) -> f64 {
    use std::f64::consts::PI;
    const C1: f64 = PI;
    const C3: f64 = -PI * PI * PI / 6.0;
    const C5: f64 = PI * PI * PI * PI * PI / 120.0;
    let d2 = d * d;
    d * (C1 + d2 * (C3 + d2 * C5))
}

/// The shortest lattice step along `dir` (the smallest multiple `m ≤ 64`
/// of `dir` whose coordinates are integers to 1e-9), signed so that
/// `(v_z, v_y)` is positive in order (the step looks back to earlier
/// rows); `None` when there is none, or it runs along x only.
pub(super) fn lattice_step(dir: [f64; 3]) -> Option<[i64; 3]> {
    let v = (1..=64).find_map(|m| {
        let scaled = dir.map(|c| c * m as f64);
        let rounded = scaled.map(f64::round);
        (0..3)
            .all(|a| (scaled[a] - rounded[a]).abs() <= 1e-9 * m as f64)
            .then(|| rounded.map(|c| c as i64))
    })?;
    let back = if v[2] != 0 { v[2] < 0 } else { v[1] < 0 };
    let v = if back { v.map(|c| -c) } else { v };
    (v[1] != 0 || v[2] != 0).then_some(v)
}

/// [`splat_in`] with a ring of its own.
#[cfg(test)]
pub(super) fn splat(
    volume: &Volume,
    r: [f64; 3],
    u: [f64; 3],
    half: i64,
    step: Option<[i64; 3]>,
) -> Vec<[f64; 3]> {
    splat_in(volume, r, u, half, step, &mut Vec::new())
}

/// The canvas of side `2·half + 1` of the view with right and up axes
/// `r`, `u`: per pixel (row `q` fastest-varying last) the sum `Σf`, then
/// `Σf·sin(πδ)` along `r` and along `u`. `step`, the lattice step of the
/// view direction ([`lattice_step`]), must be orthogonal to `r` and `u`;
/// without one, every voxel is a line of its own.
///
/// The line sums are kept in `ring`, grown as needed: every row of it is
/// written before it is read, so a ring left by another direction is
/// reused as it is (no zeroing, no fresh pages).
pub(super) fn splat_in(
    volume: &Volume,
    r: [f64; 3],
    u: [f64; 3],
    half: i64,
    step: Option<[i64; 3]>,
    ring: &mut Vec<f64>,
) -> Vec<[f64; 3]> {
    let d = volume.dims;
    let [d0, d1, d2] = d.map(|v| v as i64);
    // Voxel i sits at i − ⌊d/2⌋ from the transform origin.
    let c = d.map(|v| (v / 2) as f64);
    let side = (2 * half + 1) as usize;
    let mut cells = written_zeros::<[f64; 3]>(side * side);
    // Pixels from the canvas corner, plus ½ so that truncation rounds to
    // the nearest (every coordinate is non-negative).
    let offset = half as f64 + 0.5;
    let along_x =
        |axis: [f64; 3]| -> Vec<f64> { (0..d[0]).map(|i| (i as f64 - c[0]) * axis[0]).collect() };
    let (xr, xu) = (along_x(r), along_x(u));
    // Without a step, a step that always leaves the box: one line a voxel.
    let [vx, vy, vz] = step.unwrap_or([0, 0, d2]);
    let planes = if step.is_some() { vz as usize + 1 } else { 1 };
    let plane = d[0] * d[1];
    if ring.len() < planes * plane {
        ring.resize(planes * plane, 0.0);
    }
    // The x range of a row whose voxels have a predecessor `x − v` (and
    // whose line goes on to `x + v`) in the box.
    // (A step as long as the row leaves it at once: every line ends.)
    let across = vx.abs() < d0;
    let back = (vx.max(0) as usize, (d0 + vx.min(0)).max(0) as usize);
    let ahead = ((-vx).max(0) as usize, (d0 - vx.max(0)).max(0) as usize);
    let shift = (back.0 as i64 - vx) as usize;
    for k in 0..d2 {
        let z = k as f64 - c[2];
        let slot = k as usize % planes;
        for j in 0..d1 {
            let y = j as f64 - c[1];
            let source = &volume.data[((k * d1 + j) * d0) as usize..][..d[0]];
            // The row's line sums go straight into its slot of the ring:
            // its voxels, plus the line sums of the row one step back.
            let at = slot * plane + j as usize * d[0];
            let (jb, kb) = (j - vy, k - vz);
            let prev = (step.is_some() && across && (0..d1).contains(&jb) && (0..d2).contains(&kb))
                .then(|| kb as usize % planes * plane + jb as usize * d[0]);
            line_sums(ring, at, prev, source, back, shift);
            let row = &ring[at..][..d[0]];
            // The lines that end here: the whole row if the next row is
            // out of the box, else the voxels whose successor leaves it.
            let whole = !((0..d1).contains(&(j + vy)) && (0..d2).contains(&(k + vz)));
            let p0 = y * r[1] + z * r[2] + offset;
            let q0 = y * u[1] + z * u[2] + offset;
            let mut end = |i: usize| {
                let v = row[i];
                if v == 0.0 {
                    return;
                }
                let (yp, yq) = (xr[i] + p0, xu[i] + q0);
                let (p, q) = (yp as usize, yq as usize);
                if let Some(cell) = cells.get_mut(q * side + p) {
                    cell[0] += v;
                    // The offsets from the nearest pixel, in [−½, ½).
                    cell[1] += v * sin_pi(yp - p as f64 - 0.5);
                    cell[2] += v * sin_pi(yq - q as f64 - 0.5);
                }
            };
            if whole || !across || step.is_none() {
                (0..d[0]).for_each(&mut end);
            } else {
                (0..ahead.0).chain(ahead.1..d[0]).for_each(&mut end);
            }
        }
    }
    cells
}

/// Writes the row `source` as f64 to `ring[at..]`, adding on
/// `back.0..back.1` the line sums of the row at `prev` (another row of the
/// ring) from `shift` on: `f + p`, the sum the voxel loop makes.
fn line_sums(
    ring: &mut [f64],
    at: usize,
    prev: Option<usize>,
    source: &[f32],
    back: (usize, usize),
    shift: usize,
) {
    let len = source.len();
    let Some(prev) = prev else {
        for (s, &v) in ring[at..][..len].iter_mut().zip(source) {
            *s = f64::from(v);
        }
        return;
    };
    // Two distinct rows of the ring (a step is never zero in y and z).
    let (row, before) = if at < prev {
        let (a, b) = ring.split_at_mut(prev);
        (&mut a[at..][..len], &b[..len])
    } else {
        let (a, b) = ring.split_at_mut(at);
        (&mut b[..len], &a[prev..][..len])
    };
    add_row(row, before, source, back, shift);
}

/// [`line_sums`] on two rows given apart. Not inlined: as arguments of a
/// function of their own the compiler knows the two rows apart (one is
/// borrowed mutably), and the sum is a vector loop without overlap checks.
#[inline(never)]
fn add_row(row: &mut [f64], before: &[f64], source: &[f32], back: (usize, usize), shift: usize) {
    for (s, &v) in row[..back.0].iter_mut().zip(&source[..back.0]) {
        *s = f64::from(v);
    }
    let summed = row[back.0..back.1].iter_mut().zip(&source[back.0..back.1]);
    for ((s, &v), &p) in summed.zip(&before[shift..]) {
        *s = f64::from(v) + p;
    }
    for (s, &v) in row[back.1..].iter_mut().zip(&source[back.1..]) {
        *s = f64::from(v);
    }
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
        for (dir, r, u, half) in [
            (
                [0.0, -0.8, -0.6],
                [0.6, -0.48, 0.64],
                [-0.8, -0.36, 0.48],
                10,
            ),
            ([s, s, 0.0], [s, -s, 0.0], [0.0, 0.0, 1.0], 12),
        ] {
            let slow = reference(&volume, r, u, half);
            for step in [lattice_step(dir), None] {
                let fast = splat(&volume, r, u, half, step);
                for t in 0..3 {
                    for (at, cell) in fast.iter().enumerate() {
                        // Each term within 8ε of the divided polynomial's
                        // (both a few roundings from the exact one, the
                        // line's offset within rounding of each voxel's),
                        // and each of the `count` additions, on a line then
                        // in a cell, here and in the reference, within ε of
                        // the running sum.
                        let bound = (8.0 + 4.0 * slow[4][at]) * f64::EPSILON * slow[3][at];
                        let diff = (cell[t] - slow[t][at]).abs();
                        assert!(diff <= bound, "{step:?} sum {t} at {at}: {diff} > {bound}");
                    }
                }
            }
            // Not vacuous: many pixels hit, and lines longer than a voxel.
            assert!(slow[0].iter().filter(|&&v| v != 0.0).count() > 20);
            assert!(slow[4].iter().any(|&count| count > 2.0));
        }
    }

    #[test]
    fn a_ring_left_by_another_splat_changes_no_bit() {
        // Every row of the ring is written before it is read: a ring full
        // of NaN, as long as any direction needs, gives the fresh ring's
        // canvas bit for bit (whichever step: the comparison needs no
        // frame orthogonal to it).
        let dims = [13, 10, 7];
        let volume = super::super::test_volume::random(dims, 6);
        let (r, u) = ([0.6, -0.48, 0.64], [-0.8, -0.36, 0.48]);
        for step in [
            lattice_step([0.0, -0.8, -0.6]),
            lattice_step([1.0, 1.0, 1.0]),
            None,
        ] {
            let fresh = splat(&volume, r, u, 10, step);
            let mut ring = vec![f64::NAN; 13 * 10 * 8];
            let reused = splat_in(&volume, r, u, 10, step, &mut ring);
            assert!(fresh.iter().any(|c| c[0] != 0.0));
            let bits = |cells: &[[f64; 3]]| -> Vec<u64> {
                cells.iter().flatten().map(|v| v.to_bits()).collect()
            };
            assert_eq!(bits(&fresh), bits(&reused), "{step:?}");
        }
    }

    #[test]
    fn lattice_steps_are_the_shortest_and_look_back() {
        assert_eq!(lattice_step([0.7, 0.2, 1.0]), Some([7, 2, 10]));
        assert_eq!(lattice_step([1.0, 0.35, -0.6]), Some([-20, -7, 12]));
        assert_eq!(lattice_step([1.0, -1.0, 0.0]), Some([-1, 1, 0]));
        assert_eq!(lattice_step([-1.0, -1.0, 1.0]), Some([-1, -1, 1]));
        assert_eq!(lattice_step([1.0, 0.0, 0.0]), None);
        assert_eq!(lattice_step([1.0, 0.5f64.sqrt(), 0.3]), None);
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
