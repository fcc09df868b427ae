//! The per-view sums of the accuracy model ([`super`]), in one pass over
//! the volume, x-row by x-row, with every access contiguous.
//!
//! A voxel counts towards the edge term (`b = 0`) when any of its three
//! grid positions is an edge position, else towards the kernel term
//! (`b = 1`). For the view along axis `a` the two in-plane positions are
//! fixed per pixel, so each pixel keeps three running sums along the view
//! axis (plain, `c_a`- and `s_a`-weighted) over edge positions of axis `a`,
//! and three over the others; the pixel's own edge flag then makes them its
//! `b = 0` and `b = 1` sums, or adds them into its `b = 0` sums. A weight of
//! zero adds an exact zero, so the y- and z-view sums are the sequence of
//! additions of a loop over the voxels that skips the others; the x view's
//! dot products and `Σg²` add in a few independent partial sums, and the
//! edge pixels' final addition differs too (all tested against the voxel
//! loop, to rounding). The rows are read in blocks that keep the pixel sums
//! being added to in cache, and each sum is its own array, so that adding a
//! row is a vector loop.

use super::weights::AxisWeights;
use crate::memory::written_zeros;
use crate::volume::Volume;

/// Per-view sums over the projection axis, split by edge (0) and interior
/// (1) voxels, on the `n × n` grid of the two other axes (lower axis
/// fastest): [`PixelSums`] written out, for the tests.
#[cfg(test)]
pub(super) struct ViewSums {
    pub(super) plain: [Vec<f64>; 2],
    pub(super) cos: [Vec<f64>; 2],
    pub(super) sin: [Vec<f64>; 2],
}

#[cfg(test)]
impl ViewSums {
    fn new(n: usize) -> Self {
        let z = || [written_zeros(n * n), written_zeros(n * n)];
        Self {
            plain: z(),
            cos: z(),
            sin: z(),
        }
    }
}

/// One view's sums over the projection axis, kept on the pixels of the
/// volume's own extent ([`Lines`]) and read on the `n × n` grid of the two
/// other axes by [`PixelSums::pixel`]: no `n²` arrays, zero beyond the
/// extent.
pub(super) struct PixelSums {
    sums: [Vec<f64>; SUMS],
    /// Per grid index of the lower in-plane axis, the extent's index, or
    /// `None` beyond it; of the upper one, that index times the lower
    /// extent.
    p: Vec<Option<usize>>,
    q: Vec<Option<usize>>,
    /// Whether a grid index is an edge position.
    edge: Vec<bool>,
}

impl PixelSums {
    /// The pixel at grid indices `(gp, gq)`: for the edge (0) and interior
    /// (1) voxels, the plain, `c` and `s` sums. An edge pixel counts every
    /// voxel to 0.
    #[inline]
    pub(super) fn pixel(&self, gp: usize, gq: usize) -> [[f64; 3]; 2] {
        let (Some(p), Some(q)) = (self.p[gp], self.q[gq]) else {
            return [[0.0; 3]; 2];
        };
        let i = p + q;
        let s = &self.sums;
        if self.edge[gp] || self.edge[gq] {
            [
                [s[0][i] + s[3][i], s[1][i] + s[4][i], s[2][i] + s[5][i]],
                [0.0; 3],
            ]
        } else {
            [[s[0][i], s[1][i], s[2][i]], [s[3][i], s[4][i], s[5][i]]]
        }
    }
}

/// The six sums of a pixel: plain, `c` and `s` over edge positions, then
/// over the others.
const SUMS: usize = 6;

/// Independent partial sums in the pass's reductions (`Σg²` and the x
/// view's dot products), so that their additions do not wait on each
/// other; the order they add in is the voxel loop's reordered once.
const LANES: usize = 4;

/// One position along a view axis: its three weights (plain, `c`, `s`)
/// and where its sums start, 0 for an edge position and 3 for the others
/// (the other three weights are zeros, whose additions change nothing and
/// are skipped).
#[derive(Clone, Copy)]
struct Weight {
    at: usize,
    w: [f64; 3],
}

/// The weights of the positions `0 … len` of one axis of the volume.
fn along(w: &AxisWeights, grid: &impl Fn(usize) -> usize, len: usize) -> Vec<Weight> {
    (0..len)
        .map(|i| {
            let g = grid(i);
            Weight {
                at: if w.edge[g] { 0 } else { 3 },
                w: [1.0, w.c[g], w.s[g]],
            }
        })
        .collect()
}

/// The runs of equal [`Weight::at`] along `weights`: `(start, end, at)`.
fn runs(weights: &[Weight]) -> Vec<(usize, usize, usize)> {
    let mut out: Vec<(usize, usize, usize)> = Vec::new();
    for (i, w) in weights.iter().enumerate() {
        match out.last_mut() {
            Some(last) if last.2 == w.at => last.1 = i + 1,
            _ => out.push((i, i + 1, w.at)),
        }
    }
    out
}

/// Rows of `j` and of `k` per block of the pass: the pixel sums of a
/// block's y- and z-view lines (`2·8·d0·6` values, 192 KiB at `d0 = 256`)
/// stay in cache while the block's rows are read.
const BLOCK: usize = 8;

/// One view's pixel sums, one array per sum ([`SUMS`]), each on the
/// pixels of the volume's own extent: contiguous along a row, so that
/// adding a row of voxels is three vector loops.
struct Lines {
    sums: [Vec<f64>; SUMS],
}

impl Lines {
    fn new(pixels: usize) -> Self {
        Self {
            sums: std::array::from_fn(|_| written_zeros(pixels)),
        }
    }

    /// Adds the row `row`, weighted by `c`, to the pixels `line·len ..` of
    /// the sums `c.at ..`: plain, `c` and, unless `sin` is false (all `s`
    /// weights zero, as for odd widths), `s`; the three in one loop, which
    /// reads the row once.
    fn add(&mut self, c: Weight, line: usize, row: &[f64], sin: bool) {
        let len = row.len();
        let [plain, cos, s] = &mut self.sums[c.at..c.at + 3] else {
            unreachable!("three sums from 0 or 3");
        };
        let pixels = line * len..(line + 1) * len;
        let (wc, ws) = (c.w[1], c.w[2]);
        let both = plain[pixels.clone()]
            .iter_mut()
            .zip(&mut cos[pixels.clone()])
            .zip(row);
        if sin {
            for (((p, q), &v), r) in both.zip(&mut s[pixels]) {
                *p += v;
                *q += v * wc;
                *r += v * ws;
            }
        } else {
            for ((p, q), &v) in both {
                *p += v;
                *q += v * wc;
            }
        }
    }
}

/// `Σ (row·weight)²` in [`LANES`] partial sums.
fn weighted_squares(row: &[f64], weight: &[f64]) -> f64 {
    let mut lanes = [0.0; LANES];
    let chunks = row.chunks_exact(LANES).zip(weight.chunks_exact(LANES));
    let tail = row.len() / LANES * LANES;
    for (v, p) in chunks {
        for l in 0..LANES {
            let g = v[l] * p[l];
            lanes[l] += g * g;
        }
    }
    for (&v, &p) in row[tail..].iter().zip(&weight[tail..]) {
        let g = v * p;
        lanes[0] += g * g;
    }
    lanes.iter().sum()
}

/// `Σ row·w[t]` for the plain, `c` and (if `sin`) `s` weights of the
/// positions, `c` and `s` given apart (contiguous, so that the lanes are
/// vector lanes), in [`LANES`] partial sums each. The plain weight is 1:
/// `v·1 = v`.
fn dot3(row: &[f64], c: &[f64], s: &[f64], sin: bool) -> [f64; 3] {
    let mut lanes = [[0.0; LANES]; 3];
    let tail = row.len() / LANES * LANES;
    let chunks = row
        .chunks_exact(LANES)
        .zip(c.chunks_exact(LANES))
        .zip(s.chunks_exact(LANES));
    for ((v, c), s) in chunks {
        for l in 0..LANES {
            lanes[0][l] += v[l];
            lanes[1][l] += v[l] * c[l];
        }
        if sin {
            for l in 0..LANES {
                lanes[2][l] += v[l] * s[l];
            }
        }
    }
    for ((&v, &c), &s) in row[tail..].iter().zip(&c[tail..]).zip(&s[tail..]) {
        lanes[0][0] += v;
        lanes[1][0] += v * c;
        if sin {
            lanes[2][0] += v * s;
        }
    }
    lanes.map(|l| l.iter().sum())
}

/// The sums of the views along x, y and z ([`super::AXIS_VIEWS`]), and
/// `Σg²` of the premultiplied volume `g = f·p_x·p_y·p_z`.
///
/// The y- and z-view sums add their voxels in order along the view axis,
/// as the voxel loop does, whatever the blocking; the x view's and `Σg²`
/// add theirs in [`LANES`] partial sums.
///
/// # Errors
/// [`fvr_core::Error::NonFiniteVoxel`] naming a non-finite voxel (the
/// first in memory order).
pub(super) fn pixel_sums(
    volume: &Volume,
    w: &AxisWeights,
    n: usize,
) -> Result<([PixelSums; 3], f64), fvr_core::Error> {
    if let Some(at) = volume.first_non_finite() {
        let [d0, d1, _] = volume.dims;
        return Err(fvr_core::Error::NonFiniteVoxel {
            index: [at % d0, at / d0 % d1, at / (d0 * d1)],
            value: f64::from(volume.data[at]),
        });
    }
    let [d0, d1, d2] = volume.dims;
    let grid = |a: usize| move |i: usize| (i + n - volume.dims[a] / 2 % n) % n;
    let (gx, gy, gz) = (grid(0), grid(1), grid(2));
    let (wx, wy, wz) = (along(w, &gx, d0), along(w, &gy, d1), along(w, &gz, d2));
    // Odd widths have no `s` weights: their sums stay zero.
    let sin = w.s.iter().any(|&s| s != 0.0);
    let x_runs = runs(&wx);
    let (cx, sx): (Vec<f64>, Vec<f64>) = wx.iter().map(|w| (w.w[1], w.w[2])).unzip();
    let px: Vec<f64> = (0..d0).map(|i| w.p[gx(i)]).collect();
    // Pixel sums on the volume's own extent: x view (j, k), y view (i, k),
    // z view (i, j).
    let mut xs = Lines::new(d1 * d2);
    let mut ys = Lines::new(d0 * d2);
    let mut zs = Lines::new(d0 * d1);
    let mut row = vec![0.0f64; d0];
    let mut g2 = 0.0;
    // Each row's term of Σg², kept until its block is done.
    let mut squares = [0.0f64; BLOCK * BLOCK];
    for j0 in (0..d1).step_by(BLOCK) {
        for k0 in (0..d2).step_by(BLOCK) {
            let (j1, k1) = ((j0 + BLOCK).min(d1), (k0 + BLOCK).min(d2));
            // The block's rows in memory order: consecutive j are adjacent.
            // Each y-view line k adds its rows in order of j, each z-view
            // line j its rows in order of k, as before any reordering.
            for k in k0..k1 {
                for j in j0..j1 {
                    let source = &volume.data[(k * d1 + j) * d0..][..d0];
                    for (r, &v) in row.iter_mut().zip(source) {
                        *r = f64::from(v);
                    }
                    let pyz = w.p[gy(j)] * w.p[gz(k)];
                    squares[(j - j0) * BLOCK + k - k0] = weighted_squares(&row, &px) * (pyz * pyz);
                    let pixel = j + d1 * k;
                    for &(start, end, at) in &x_runs {
                        let sums = dot3(&row[start..end], &cx[start..end], &sx[start..end], sin);
                        for (t, s) in sums.into_iter().enumerate() {
                            xs.sums[at + t][pixel] += s;
                        }
                    }
                    ys.add(wy[j], k, &row, sin);
                    zs.add(wz[k], j, &row, sin);
                }
            }
            // Σg² adds the block's rows in order of j, then k.
            for j in j0..j1 {
                for k in k0..k1 {
                    g2 += squares[(j - j0) * BLOCK + k - k0];
                }
            }
        }
    }
    // View `a`: in-plane axes (pa, qa), the pixel sums' extents (lp, lq).
    let view = |lines: Lines, lp: usize, lq: usize, pa: usize, qa: usize| {
        let mut p = vec![None; n];
        for i in 0..lp {
            p[grid(pa)(i)] = Some(i);
        }
        let mut q = vec![None; n];
        for i in 0..lq {
            q[grid(qa)(i)] = Some(i * lp);
        }
        PixelSums {
            sums: lines.sums,
            p,
            q,
            edge: w.edge.clone(),
        }
    };
    Ok((
        [
            view(xs, d1, d2, 1, 2),
            view(ys, d0, d2, 0, 2),
            view(zs, d0, d1, 0, 1),
        ],
        g2,
    ))
}

/// [`pixel_sums`] written out on the `n × n` grids.
#[cfg(test)]
pub(super) fn view_sums(
    volume: &Volume,
    w: &AxisWeights,
    n: usize,
) -> Result<([ViewSums; 3], f64), fvr_core::Error> {
    let (pixels, g2) = pixel_sums(volume, w, n)?;
    let out = pixels.map(|sums| {
        let mut view = ViewSums::new(n);
        for gq in 0..n {
            for gp in 0..n {
                let at = gp + n * gq;
                for (b, [plain, cos, sin]) in sums.pixel(gp, gq).into_iter().enumerate() {
                    view.plain[b][at] = plain;
                    view.cos[b][at] = cos;
                    view.sin[b][at] = sin;
                }
            }
        }
        view
    });
    Ok((out, g2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The voxel-by-voxel loop the pass replaces: the reference.
    fn reference(volume: &Volume, w: &AxisWeights, n: usize) -> ([ViewSums; 3], f64) {
        let dims = volume.dims;
        let grid = |i: usize, a: usize| (i + n - dims[a] / 2 % n) % n;
        let mut sums = [ViewSums::new(n), ViewSums::new(n), ViewSums::new(n)];
        let mut g2 = 0.0;
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let v = volume.get(i, j, k) as f64;
                    if v == 0.0 {
                        continue;
                    }
                    let g = [grid(i, 0), grid(j, 1), grid(k, 2)];
                    let b = usize::from(!(w.edge[g[0]] || w.edge[g[1]] || w.edge[g[2]]));
                    let gv = v * w.p[g[0]] * w.p[g[1]] * w.p[g[2]];
                    g2 += gv * gv;
                    for (a, s) in sums.iter_mut().enumerate() {
                        let (pa, qa) = super::super::weights::in_plane(a);
                        let at = g[pa] + n * g[qa];
                        s.plain[b][at] += v;
                        s.cos[b][at] += v * w.c[g[a]];
                        s.sin[b][at] += v * w.s[g[a]];
                    }
                }
            }
        }
        (sums, g2)
    }

    #[test]
    fn the_row_pass_agrees_with_the_voxel_loop_to_rounding() {
        // A box of odd and even sides touching the grid's faces, with zeros,
        // negative values and edge positions on every axis.
        let dims = [13, 15, 11];
        let volume = super::super::test_volume::random(dims, 7);
        for kind in [
            fvr_core::filter::FilterKind::Cubic,
            fvr_core::filter::FilterKind::Kb4,
            fvr_core::filter::FilterKind::Kb5,
        ] {
            for n in [16, 20] {
                let mut compared = 0;
                let filter = fvr_core::filter::Filter::new(kind, 1).expect("filter");
                let w = super::super::weights::axis_weights(&filter, n);
                assert!(w.edge.iter().any(|&e| e) && w.edge.iter().any(|&e| !e));
                let (fast, g2) = view_sums(&volume, &w, n).expect("finite");
                let (slow, g2_ref) = reference(&volume, &w, n);
                // Σg² adds its positive terms in another order: within
                // N·ε of the voxel loop's.
                let bound = volume.data.len() as f64 * f64::EPSILON * g2_ref;
                assert!(
                    (g2 - g2_ref).abs() <= bound,
                    "{kind:?} n={n}: {g2} vs {g2_ref}"
                );
                let largest = w.c.iter().chain(&w.s).fold(1.0f64, |m, x| m.max(x.abs()));
                for a in 0..3 {
                    // A sum of at most d_a terms, each |v·w| ≤ largest,
                    // reordered once: within d_a·ε·(d_a·largest).
                    let d = dims[a] as f64;
                    let bound = d * f64::EPSILON * d * largest;
                    for b in 0..2 {
                        for (name, x, y) in [
                            ("plain", &fast[a].plain[b], &slow[a].plain[b]),
                            ("cos", &fast[a].cos[b], &slow[a].cos[b]),
                            ("sin", &fast[a].sin[b], &slow[a].sin[b]),
                        ] {
                            let worst = x
                                .iter()
                                .zip(y)
                                .map(|(p, q)| (p - q).abs())
                                .fold(0.0, f64::max);
                            assert!(
                                worst <= bound,
                                "{kind:?} n={n} view {a} b={b} {name}: {worst}"
                            );
                            compared += y.iter().filter(|&&v| v != 0.0).count();
                        }
                    }
                }
                // Not vacuous: edge and interior sums on every view.
                assert!(compared > 6 * 13 * 11, "{kind:?} n={n}: {compared}");
            }
        }
    }

    #[test]
    fn a_non_finite_voxel_is_named() {
        let mut data = vec![1.0f32; 4 * 4 * 4];
        data[(2 * 4 + 1) * 4 + 3] = f32::NAN;
        let volume = Volume::new([4; 3], data);
        let filter =
            fvr_core::filter::Filter::new(fvr_core::filter::FilterKind::Kb3, 1).expect("filter");
        let w = super::super::weights::axis_weights(&filter, 4);
        match view_sums(&volume, &w, 4) {
            Err(fvr_core::Error::NonFiniteVoxel { index, .. }) => assert_eq!(index, [3, 1, 2]),
            other => panic!("{:?}", other.map(|r| r.1)),
        }
    }
}
