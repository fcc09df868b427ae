//! Which bricks of `8³` samples a level's marks hold whole: one bit per
//! brick (`n³/512` bits, 4 KiB at `n = 256`), so that the adaptive walk
//! ([`super::fast_adaptive`]) settles most points of a weak spectrum from
//! a table that stays in cache, and reads the marks themselves (`n³/8`
//! bytes, scattered along a slice) only in the bricks at the edge of the
//! marked region.

/// Side of a brick, in samples.
pub const BRICK: usize = 8;

/// The bricks of one level's marks that are marked in every sample.
#[derive(Clone, Debug, Default)]
pub struct MarksSummary {
    /// One bit per brick, bricks numbered `bx + m·(by + m·bz)` with
    /// `m = n/8`; empty where the side is not served.
    words: Vec<u32>,
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
        let mut out = vec![0u32; (m * m * m).div_ceil(32)];
        // A brick's row of 8 samples along x starts at a multiple of 8: one
        // byte of one word.
        let byte = |i: usize| (words[i / 32] >> (i % 32)) & 0xFF;
        for bz in 0..m {
            for by in 0..m {
                for bx in 0..m {
                    let whole = (0..BRICK * BRICK).all(|r| {
                        let (y, z) = (by * BRICK + r % BRICK, bz * BRICK + r / BRICK);
                        byte(bx * BRICK + n * (y + n * z)) == 0xFF
                    });
                    if whole {
                        let b = bx + m * (by + m * bz);
                        out[b / 32] |= 1 << (b % 32);
                    }
                }
            }
        }
        Self {
            words: out,
            bits: m.trailing_zeros(),
        }
    }

    /// Whether every sample of the brick holding sample `(x, y, z)` is
    /// marked (`false` for a summary that serves no side).
    #[inline(always)]
    pub fn holds(&self, [x, y, z]: [usize; 3]) -> bool {
        let s = BRICK.trailing_zeros();
        let b = (x >> s) | ((y >> s) << self.bits) | ((z >> s) << (2 * self.bits));
        self.words
            .get(b / 32)
            .is_some_and(|w| (w >> (b % 32)) & 1 == 1)
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.words.len() * 4
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
            assert_eq!(summary.bytes(), (m * m * m).div_ceil(32) * 4);
        }
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
            assert_eq!(summary.bytes(), 0);
        }
    }
}
