//! Which bricks of `8³` samples a level's marks hold whole, and how far
//! each whole brick is from one that is not: one byte per brick (`n³/512`
//! bytes, 32 KiB at `n = 256`), so that the adaptive walk
//! ([`super::fast_adaptive`]) settles most points of a weak spectrum from
//! a table that stays in cache, skips runs of points that stay among whole
//! bricks, and reads the marks themselves (`n³/8` bytes, scattered along a
//! slice) only in the bricks at the edge of the marked region.

/// Side of a brick, in samples.
pub const BRICK: usize = 8;

/// The bricks of one level's marks that are marked in every sample, with
/// their distances to the others.
#[derive(Clone, Debug, Default)]
pub struct MarksSummary {
    /// Per brick (numbered `bx + m·(by + m·bz)`, `m = n/8`): 0 if some
    /// sample is not marked, else the Chebyshev distance in bricks, on the
    /// periodic grid, to the nearest such brick (at most 255, which it
    /// also is when there is none). Empty where the side is not served.
    distance: Vec<u8>,
    /// `log₂ m`.
    bits: u32,
}

impl MarksSummary {
    /// The summary of `words`, the marks of a cube of side `n` (sample
    /// `x + n·(y + n·z)` at bit `i mod 32` of word `i/32`). A side that is
    /// not a power of two of at least [`BRICK`], or too few words, gives a
    /// summary that holds no brick (the walk then reads every mark).
    pub fn new(words: &[u32], n: usize) -> Self {
        if !n.is_power_of_two() || n < BRICK || words.len() * 32 < n * n * n {
            return Self::default();
        }
        let m = n / BRICK;
        // A brick's row of 8 samples along x starts at a multiple of 8: one
        // byte of one word.
        let byte = |i: usize| (words[i / 32] >> (i % 32)) & 0xFF;
        let mut distance: Vec<u8> = (0..m * m * m)
            .map(|b| {
                let (bx, by, bz) = (b % m, b / m % m, b / (m * m));
                let whole = (0..BRICK * BRICK).all(|r| {
                    let (y, z) = (by * BRICK + r % BRICK, bz * BRICK + r / BRICK);
                    byte(bx * BRICK + n * (y + n * z)) == 0xFF
                });
                if whole {
                    u8::MAX
                } else {
                    0
                }
            })
            .collect();
        chebyshev(&mut distance, m);
        Self {
            distance,
            bits: m.trailing_zeros(),
        }
    }

    /// Whether every sample of the brick holding sample `(x, y, z)` is
    /// marked (`false` for a summary that serves no side).
    #[inline(always)]
    pub fn holds(&self, at: [usize; 3]) -> bool {
        self.distance(at) > 0
    }

    /// 0 if the brick holding sample `(x, y, z)` (indices `0 … n − 1`) is
    /// not held whole (or the summary serves no side), else `d ≥ 1` such
    /// that every brick within `d − 1` bricks of it on each axis (the grid
    /// periodic) is held whole.
    #[inline(always)]
    pub fn distance(&self, [x, y, z]: [usize; 3]) -> u8 {
        let s = BRICK.trailing_zeros();
        let b = (x >> s) | ((y >> s) << self.bits) | ((z >> s) << (2 * self.bits));
        self.distance.get(b).copied().unwrap_or(0)
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.distance.len()
    }
}

/// Replace each nonzero entry of the periodic `m³` grid `d` (`x` fastest)
/// by its Chebyshev distance to the nearest zero entry, saturating at 255:
/// the distance is separable, so one pass per axis, each taking at every
/// cell the least `max(|Δ|, d)` along its line (`m ≤ 512`: at most `m⁴`
/// steps a pass).
fn chebyshev(d: &mut [u8], m: usize) {
    let mut line = vec![0u8; m];
    for stride in [1, m, m * m] {
        for start in 0..m * m * m {
            // Each line once, from its first cell.
            if (start / stride) % m != 0 {
                continue;
            }
            for (i, v) in line.iter_mut().enumerate() {
                *v = d[start + i * stride];
            }
            for i in 0..m {
                let best = (0..m).fold(u8::MAX, |best, j| {
                    let gap = i.abs_diff(j).min(m - i.abs_diff(j));
                    best.min(line[j].max(gap.min(255) as u8))
                });
                d[start + i * stride] = best;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Marks whose bricks are whole, whole but one sample, or random, for
    /// each brick in turn: the summary agrees with a sample-by-sample test
    /// at every sample of the cube.
    #[test]
    fn holds_exactly_the_whole_bricks() {
        for n in [16usize, 32, 64] {
            let total = n * n * n;
            let mut words = vec![0u32; total.div_ceil(32)];
            let mut state = 0x2545_f491_4f6c_dd1du64 ^ n as u64;
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                state
            };
            let get = |w: &[u32], i: usize| (w[i / 32] >> (i % 32)) & 1 == 1;
            let m = n / BRICK;
            let brick_of = |i: usize| {
                let (x, y, z) = (i % n, i / n % n, i / (n * n));
                (x / BRICK, y / BRICK, z / BRICK)
            };
            for i in 0..total {
                let (bx, by, bz) = brick_of(i);
                let kind = (bx + 2 * by + 3 * bz) % 3;
                // The sample at the brick's corner is left out of kind 1.
                let corner = i % n % BRICK == 7 && i / n % n % BRICK == 7;
                let set = match kind {
                    0 => true,
                    1 => !(corner && i / (n * n) % BRICK == 7),
                    _ => next() % 4 != 0,
                };
                if set {
                    words[i / 32] |= 1 << (i % 32);
                }
            }
            let summary = MarksSummary::new(&words, n);
            let mut brick_whole = vec![true; m * m * m];
            for i in 0..total {
                let (bx, by, bz) = brick_of(i);
                brick_whole[bx + m * (by + m * bz)] &= get(&words, i);
            }
            let mut whole = 0;
            for i in 0..total {
                let (bx, by, bz) = brick_of(i);
                let expected = brick_whole[bx + m * (by + m * bz)];
                let at = [i % n, i / n % n, i / (n * n)];
                assert_eq!(summary.holds(at), expected, "n {n} sample {at:?}");
                whole += usize::from(expected);
            }
            assert!(whole > 0 && whole < total, "n {n}: {whole} of {total}");
            distances_agree(&summary, n);
            assert_eq!(summary.bytes(), m * m * m);
        }
    }

    /// The distance of every brick against a search over all bricks: the
    /// cyclic Chebyshev distance to the nearest brick not held, 0 for those,
    /// 255 when there is none. Returns how many bricks are at 2 or more.
    fn distances_agree(summary: &MarksSummary, n: usize) -> usize {
        let m = n / BRICK;
        let at = |b: usize| [b % m, b / m % m, b / (m * m)].map(|c| c * BRICK);
        let unheld: Vec<[usize; 3]> = (0..m * m * m)
            .map(at)
            .filter(|&s| !summary.holds(s))
            .collect();
        let gap = |a: usize, b: usize| {
            let d = a.abs_diff(b) / BRICK;
            d.min(m - d)
        };
        let mut far = 0;
        for b in 0..m * m * m {
            let s = at(b);
            let expected = unheld
                .iter()
                .map(|u| (0..3).map(|a| gap(s[a], u[a])).max().unwrap_or(0))
                .min()
                .map_or(255, |d| d.min(255) as u8);
            assert_eq!(summary.distance(s), expected, "n {n}, brick at {s:?}");
            far += usize::from(expected >= 2);
        }
        far
    }

    /// Marks set everywhere but in a few boxes of samples (signed
    /// coordinates, inclusive, wrapped): the distances of every brick are
    /// the search's, and without any box every brick is at 255.
    #[test]
    fn distances_reach_the_nearest_unheld_brick() {
        let n = 64usize;
        let unmarked = |boxes: &[([i32; 3], [i32; 3])]| {
            let mut words = vec![u32::MAX; (n * n * n).div_ceil(32)];
            for &(lo, hi) in boxes {
                for z in lo[2]..=hi[2] {
                    for y in lo[1]..=hi[1] {
                        for x in lo[0]..=hi[0] {
                            let [x, y, z] = [x, y, z].map(|c| c.rem_euclid(n as i32) as usize);
                            let i = x + n * (y + n * z);
                            words[i / 32] &= !(1 << (i % 32));
                        }
                    }
                }
            }
            MarksSummary::new(&words, n)
        };
        let summary = unmarked(&[([-3, -17, 5], [9, -10, 5])]);
        assert!(distances_agree(&summary, n) > 0);
        let summary = unmarked(&[([0, 0, 0], [0, 0, 0]), ([32, 1, -20], [32, 1, -20])]);
        assert!(distances_agree(&summary, n) > 0);
        let all = unmarked(&[]);
        assert_eq!(distances_agree(&all, n), (n / BRICK).pow(3));
        assert_eq!(all.distance([5, 9, 63]), 255);
    }

    #[test]
    fn unserved_sides_hold_nothing() {
        for (n, words) in [
            (4usize, vec![u32::MAX; 2]),
            (12, vec![u32::MAX; 54]),
            (16, vec![]),
        ] {
            let summary = MarksSummary::new(&words, n);
            assert!(!summary.holds([0, 0, 0]), "n {n}");
            assert_eq!(summary.distance([0, 0, 0]), 0, "n {n}");
            assert_eq!(summary.bytes(), 0);
        }
    }
}
