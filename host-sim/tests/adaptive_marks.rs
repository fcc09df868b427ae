//! The host's marking (`fvr_engine::slice::adaptive::marks::mark`) against the
//! core's (`fvr_core::slice::adaptive::mark`): the same words and count,
//! for sides served by the word-wide erosion (32, 64) and one that goes to
//! the core (16), radii from 0 to beyond half the side.

use fvr_core::slice::adaptive::{mark as core_mark, marks_words};
use fvr_engine::slice::adaptive::marks::mark;

/// A smooth field with noise (fixed-seed LCG), so that the erosion keeps
/// some samples and removes others.
fn field(n: usize, seed: u64) -> Vec<f64> {
    let mut state = seed;
    (0..n * n * n)
        .map(|i| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let noise = (state >> 40) as f64 / (1u64 << 24) as f64;
            let (x, y, z) = ((i % n) as f64, ((i / n) % n) as f64, (i / (n * n)) as f64);
            let smooth = (x * 0.37).sin() * (y * 0.23).cos() + (z * 0.11).sin();
            (smooth.abs() + 0.1 * noise) * if state & 1 == 0 { 1.0 } else { -1.0 }
        })
        .collect()
}

#[test]
fn same_words_as_the_core() {
    for (n, tau) in [(16, 0.9), (32, 0.9), (64, 1.2)] {
        let values = field(n, n as u64);
        let total = n * n * n;
        for radius in [0, 1, 2, 3, n / 2 + 3] {
            let mut expected = vec![0u32; marks_words(n)];
            let mut line = vec![false; n];
            let count = core_mark(n, |i| values[i], tau, radius, &mut expected, &mut line).unwrap();
            // Garbage first: every word must be written.
            let mut words = vec![0x5a5a_5a5a_u32; marks_words(n)];
            let got = mark(n, |i| values[i], tau, radius, &mut words).unwrap();
            assert_eq!(got, count, "n {n}, radius {radius}");
            assert_eq!(words, expected, "n {n}, radius {radius}");
            if radius <= 1 {
                assert!(
                    count > 0 && count < total,
                    "n {n}, radius {radius}: {count} marked"
                );
            }
        }
    }
    // Too few words: the core's error.
    let mut short = vec![0u32; marks_words(32) - 1];
    assert!(mark(32, |_| 0.0, 1.0, 1, &mut short).is_err());
}
