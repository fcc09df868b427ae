//! The points of each slice row whose nearest spectrum samples may lie in
//! a brick that a level's marks do not hold whole ([`MarksSummary`]): the
//! adaptive walk ([`crate::slice::adaptive::walk`]) settles those point by point
//! and counts the rest of the row, whose nearest samples all lie in whole
//! bricks, without looking at them.
//!
//! The slice's point `(kx, ky)` sits at `q = kx·right + ky·up`, and its
//! nearest sample is `⌊q + ½⌋` on each axis. A brick holding samples
//! `lo … lo + 7` on each axis is reached only from the box
//! `[lo − ½, lo + 7½]³`, and the box only from the part of the slice's
//! plane inside it: the rows `ky` between the box's least and greatest
//! `w·q` (`w` the dual of `up` in the plane, so that `w·q = ky` there),
//! and along each such row, the `kx` where the line is inside all three
//! slabs. Each bound is widened by [`MARGIN`] and then by one point, so
//! the rounding of the walk's positions cannot move a point out.

use crate::slice::adaptive::summary::{MarksSummary, BRICK};

/// Samples added to each side of a brick's box: the walk's positions
/// (`kx·right + ky·up` in `f32`, `|q| ≤ n/2`) are within a few ulps of
/// `n/2` of the exact ones, far below this for every side the summary
/// serves (`n ≤ 2^16`, an ulp of `2^15` being `2^−8`).
const MARGIN: f64 = 0.125;

/// For each row of a slice, the spans of `kx` (inclusive, ascending,
/// apart) whose points may reach a brick not held whole.
#[derive(Clone, Debug, Default)]
pub struct PartialSpans {
    /// Row `i`'s spans are `spans[at[i] .. at[i + 1]]`.
    at: Vec<u32>,
    spans: Vec<(i32, i32)>,
}

impl PartialSpans {
    /// The spans of the `n × n` slice with axes `right` and `up` (as the
    /// walk rounds them), row `ky mod n` holding frequency `ky`, against
    /// `summary`'s bricks; `None` where the summary serves no side, the
    /// axes span no plane, or more bricks than a slice can cross (`2m²` of
    /// the `m³`, `m = n/8`; a plane crosses at most `√3·m²`) are not held
    /// whole: then the spans would cost more than settling every point (a
    /// CT head's marks at 40 dB).
    pub fn new(summary: &MarksSummary, n: usize, right: [f64; 3], up: [f64; 3]) -> Option<Self> {
        let partial = summary.partial()?;
        let m = n / BRICK;
        if partial.len() > 2 * m * m {
            return None;
        }
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (rr, ru, uu) = (dot(right, right), dot(right, up), dot(up, up));
        let det = rr * uu - ru * ru;
        if !(det > 0.0 && det.is_finite()) {
            return None;
        }
        let dual: [f64; 3] = core::array::from_fn(|a| (rr * up[a] - ru * right[a]) / det);
        let normal = [
            right[1] * up[2] - right[2] * up[1],
            right[2] * up[0] - right[0] * up[2],
            right[0] * up[1] - right[1] * up[0],
        ];
        let half = (n / 2) as i64;
        let mask = n as i64 - 1;
        let mut found: Vec<(usize, i32, i32)> = Vec::new();
        for brick in partial {
            // Each axis: the brick's samples as signed frequencies; the
            // brick at −n/2 also holds +n/2 (the same index), which the
            // points on the cube's far face reach.
            let starts = brick.map(|b| {
                let lo = (b as usize * BRICK) as i64;
                let lo = if lo >= half { lo - n as i64 } else { lo };
                [Some(lo), (lo == -half).then_some(half)]
            });
            for at in 0..8 {
                let lo = [0, 1, 2].map(|a| starts[a][(at >> a) & 1]);
                let [Some(x), Some(y), Some(z)] = lo else {
                    continue;
                };
                let lo = [x, y, z].map(|c| c as f64 - 0.5 - MARGIN);
                let hi = lo.map(|c| c + BRICK as f64 + 2.0 * MARGIN);
                let (n_lo, n_hi) = extent(normal, lo, hi);
                if n_lo > 0.0 || n_hi < 0.0 {
                    continue;
                }
                let (w_lo, w_hi) = extent(dual, lo, hi);
                let first = (w_lo.floor() as i64 - 1).max(-half);
                let last = (w_hi.ceil() as i64 + 1).min(half - 1);
                for ky in first..=last {
                    if let Some((from, to)) = along_row(right, up, ky as f64, lo, hi, half) {
                        found.push(((ky & mask) as usize, from, to));
                    }
                }
            }
        }
        found.sort_unstable();
        let mut at = Vec::with_capacity(n + 1);
        let mut spans: Vec<(i32, i32)> = Vec::with_capacity(found.len());
        let mut next = found.iter().peekable();
        for row in 0..n {
            at.push(spans.len() as u32);
            let start = spans.len();
            while let Some(&(_, from, to)) = next.next_if(|f| f.0 == row) {
                match spans[start..].last_mut() {
                    Some(last) if from <= last.1.saturating_add(1) => last.1 = last.1.max(to),
                    _ => spans.push((from, to)),
                }
            }
        }
        at.push(spans.len() as u32);
        Some(Self { at, spans })
    }

    /// Points in all the spans.
    pub fn points(&self) -> usize {
        let length = |&(from, to): &(i32, i32)| (to - from) as usize + 1;
        self.spans.iter().map(length).sum()
    }

    /// The spans of row `index` (`ky mod n`); none for a row out of range.
    #[inline]
    pub fn row(&self, index: usize) -> &[(i32, i32)] {
        match (self.at.get(index), self.at.get(index + 1)) {
            (Some(&from), Some(&to)) => self.spans.get(from as usize..to as usize).unwrap_or(&[]),
            _ => &[],
        }
    }
}

/// The least and greatest `v·q` over the box `lo … hi`.
fn extent(v: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> (f64, f64) {
    (0..3).fold((0.0, 0.0), |(min, max), a| {
        let (p, q) = (v[a] * lo[a], v[a] * hi[a]);
        (min + p.min(q), max + p.max(q))
    })
}

/// The `kx` (widened by one point each way, within `±(half + 1)`) where
/// the row at `ky` is inside the box `lo … hi`; `None` where it misses.
fn along_row(
    right: [f64; 3],
    up: [f64; 3],
    ky: f64,
    lo: [f64; 3],
    hi: [f64; 3],
    half: i64,
) -> Option<(i32, i32)> {
    let (mut from, mut to) = (f64::NEG_INFINITY, f64::INFINITY);
    for a in 0..3 {
        let c = ky * up[a];
        if right[a] == 0.0 {
            if c < lo[a] || c > hi[a] {
                return None;
            }
            continue;
        }
        let (s, t) = ((lo[a] - c) / right[a], (hi[a] - c) / right[a]);
        from = from.max(s.min(t));
        to = to.min(s.max(t));
    }
    if from > to {
        return None;
    }
    let limit = (half + 1) as f64;
    let from = (from.floor() - 1.0).max(-limit) as i32;
    let to = (to.ceil() + 1.0).min(limit) as i32;
    (from <= to).then_some((from, to))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random bricks left out of otherwise whole marks, oblique and axis
    /// directions: every point of the slice whose nearest sample (computed
    /// in `f32` as the walk computes it) lies in a brick not held is inside
    /// one of its row's spans, and the spans of a row are ascending and
    /// apart.
    #[test]
    fn every_point_reaching_a_partial_brick_is_in_a_span() {
        let n = 64usize;
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let directions: [([f64; 3], [f64; 3]); 4] = [
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
            (unit([1.0, 0.3, 0.2]), unit([-0.3, 1.0, 0.05])),
            (unit([0.6, -0.7, 0.4]), unit([0.7, 0.6, 0.0])),
        ];
        let half = (n / 2) as i32;
        let nearest = |q: [f32; 3]| q.map(|c| ((c + 0.5).floor() as i64 as usize) & (n - 1));
        let position = |right: [f64; 3], up: [f64; 3], kx: i32, ky: i32| -> [f32; 3] {
            core::array::from_fn(|a| kx as f32 * right[a] as f32 + ky as f32 * up[a] as f32)
        };
        for trial in 0..6 {
            for (right, up) in directions {
                // An up made orthogonal to right, as the frames are.
                let up = unit(sub(up, scale(right, dot(right, up))));
                let [right, up] = [right, up].map(|v| v.map(|c| c as f32 as f64));
                // Samples left unmarked: some anywhere, some nearest to a
                // point of the slice.
                let mut words = vec![u32::MAX; (n * n * n).div_ceil(32)];
                for i in 0..6 + trial {
                    let i = match i % 2 {
                        0 => next() as usize % (n * n * n),
                        _ => {
                            let [kx, ky] = [0; 2].map(|_| (next() % n as u64) as i32 - half);
                            let [x, y, z] = nearest(position(right, up, kx / 2, ky / 2));
                            x + n * (y + n * z)
                        }
                    };
                    words[i / 32] &= !(1 << (i % 32));
                }
                let summary = MarksSummary::new(&words, n);
                let spans = PartialSpans::new(&summary, n, right, up).unwrap();
                let mut reached = 0;
                for ky in -half..half {
                    let row = spans.row((ky as usize) & (n - 1));
                    assert!(row
                        .windows(2)
                        .all(|w| w[0].0 <= w[0].1 && w[0].1 + 1 < w[1].0));
                    for kx in -half..half {
                        let q = position(right, up, kx, ky);
                        if q.iter().any(|&c| c.abs() > half as f32) {
                            continue;
                        }
                        let s = nearest(q);
                        if summary.holds(s) {
                            continue;
                        }
                        reached += 1;
                        assert!(
                            row.iter().any(|&(from, to)| (from..=to).contains(&kx)),
                            "trial {trial}, axes {right:?} {up:?}: ({kx}, {ky}) reaches {s:?}"
                        );
                    }
                }
                assert!(
                    reached > 0,
                    "trial {trial}: no point reaches a partial brick"
                );
            }
        }
    }

    /// A summary of a side it does not serve gives no spans, nor do axes
    /// that span no plane, nor marks that hold too few bricks whole.
    #[test]
    fn no_spans_without_bricks_or_plane() {
        let words = vec![u32::MAX; 64];
        let unserved = MarksSummary::new(&words, 12);
        assert!(PartialSpans::new(&unserved, 12, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]).is_none());
        let mut words = [u32::MAX; 32 * 32 * 32 / 32];
        words[5] = 0;
        let served = MarksSummary::new(&words, 32);
        assert!(PartialSpans::new(&served, 32, [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]).is_none());
        assert!(PartialSpans::new(&served, 32, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]).is_some());
        // Every brick not held whole: more than a slice can cross.
        let none = MarksSummary::new(&[0u32; 32 * 32 * 32 / 32], 32);
        assert!(PartialSpans::new(&none, 32, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]).is_none());
    }

    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
        a.map(|c| c * s)
    }

    fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }

    fn unit(a: [f64; 3]) -> [f64; 3] {
        scale(a, 1.0 / dot(a, a).sqrt())
    }
}
