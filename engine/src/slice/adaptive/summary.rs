//! Which bricks of `8³` samples a level's marks hold whole: one byte per
//! brick (`n³/512` bytes, 32 KiB at `n = 256`), so that the adaptive walk
//! ([`crate::slice::adaptive::walk`]) settles most points of a weak spectrum from
//! a table that stays in cache, and the list of the others, so that it
//! walks point by point only the parts of a slice's rows that may reach
//! them ([`crate::slice::adaptive::spans`]) and reads the marks themselves (`n³/8`
//! bytes, scattered along a slice) only there.

/// Side of a brick, in samples.
pub const BRICK: usize = 8;

/// The bricks of one level's marks that are marked in every sample, and
/// the others.
#[derive(Clone, Debug, Default)]
pub struct MarksSummary {
    /// Per brick (numbered `bx + m·(by + m·bz)`, `m = n/8`): whether every
    /// sample is marked. Empty where the side is not served.
    whole: Vec<bool>,
    /// The bricks not held whole, `[bx, by, bz]` in that order.
    partial: Vec<[u16; 3]>,
    /// `log₂ m`.
    bits: u32,
}

impl MarksSummary {
    /// The summary of `words`, the marks of a cube of side `n` (sample
    /// `x + n·(y + n·z)` at bit `i mod 32` of word `i/32`). A side that is
    /// not a power of two from [`BRICK`] to `2^16`, or too few words,
    /// gives a summary that holds no brick (the walk then reads every
    /// mark).
    pub fn new(words: &[u32], n: usize) -> Self {
        if !n.is_power_of_two() || !(BRICK..=1 << 16).contains(&n) || words.len() * 32 < n * n * n {
            return Self::default();
        }
        let m = n / BRICK;
        // A brick's row of 8 samples along x starts at a multiple of 8: one
        // byte of one word.
        let byte = |i: usize| (words[i / 32] >> (i % 32)) & 0xFF;
        let whole: Vec<bool> = (0..m * m * m)
            .map(|b| {
                let (bx, by, bz) = (b % m, b / m % m, b / (m * m));
                (0..BRICK * BRICK).all(|r| {
                    let (y, z) = (by * BRICK + r % BRICK, bz * BRICK + r / BRICK);
                    byte(bx * BRICK + n * (y + n * z)) == 0xFF
                })
            })
            .collect();
        let partial = (0..m * m * m)
            .filter(|&b| !whole[b])
            .map(|b| [b % m, b / m % m, b / (m * m)].map(|c| c as u16))
            .collect();
        Self {
            whole,
            partial,
            bits: m.trailing_zeros(),
        }
    }

    /// Whether every sample of the brick holding sample `(x, y, z)`
    /// (indices `0 … n − 1`) is marked (`false` for a summary that serves
    /// no side).
    #[inline(always)]
    pub fn holds(&self, [x, y, z]: [usize; 3]) -> bool {
        let s = BRICK.trailing_zeros();
        let b = (x >> s) | ((y >> s) << self.bits) | ((z >> s) << (2 * self.bits));
        self.whole.get(b).copied().unwrap_or(false)
    }

    /// The bricks not held whole (`[bx, by, bz]`, samples `8·b … 8·b + 7`
    /// on each axis); `None` for a summary that serves no side.
    pub fn partial(&self) -> Option<&[[u16; 3]]> {
        (!self.whole.is_empty()).then_some(&self.partial[..])
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.whole.len() + self.partial.len() * size_of::<[u16; 3]>()
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
            let partial = summary.partial().unwrap();
            let unheld: Vec<[u16; 3]> = (0..m * m * m)
                .filter(|&b| !brick_whole[b])
                .map(|b| [b % m, b / m % m, b / (m * m)].map(|c| c as u16))
                .collect();
            assert_eq!(partial, &unheld[..], "n {n}");
            assert_eq!(summary.bytes(), m * m * m + 6 * unheld.len());
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
            assert!(summary.partial().is_none(), "n {n}");
            assert_eq!(summary.bytes(), 0);
        }
    }
}
