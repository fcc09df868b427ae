//! The fast Hartley transforms against direct O(N²) summation in f64.

use fvr_core::dht::{
    dht, dht_2d, dht_2d_lines, dht_2d_sparse_len, dht_3d, dht_3d_scratch_len, idht, idht_2d,
    Twiddles,
};
use fvr_core::Error;
use fvr_engine::volume::phantom::SplitMix64;
use fvr_host::reference::{naive_dht, naive_dht_2d, naive_dht_3d};
use fvr_tests::twiddles;
use half::f16;

/// Deterministic test signal in [−1, 1) (SplitMix64).
fn signal(len: usize, seed: u64) -> Vec<f64> {
    let mut rng = SplitMix64::new(seed);
    (0..len).map(|_| rng.next_f64() * 2.0 - 1.0).collect()
}

/// Relative RMS error ‖a − b‖ / ‖b‖.
fn rel_rms(a: &[f64], b: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let den: f64 = b.iter().map(|y| y * y).sum();
    (num / den).sqrt()
}

/// Error budget of a radix-2 transform: each of the log₂N stages adds a few
/// roundings (a butterfly has one multiply-add chain of depth 3) of unit
/// roundoff u, plus twiddle error ≤ u. We allow 4·u·(log₂N + 1) relative RMS.
fn budget(unit_roundoff: f64, n: usize) -> f64 {
    4.0 * unit_roundoff * ((n as f64).log2() + 1.0)
}

#[test]
fn dht_matches_naive_for_all_sizes_1_to_2048() {
    twiddles!(4096; tw64: f64, tw32: f32);
    let mut n = 1;
    while n <= 2048 {
        let x = signal(n, n as u64);
        let reference = naive_dht(&x);
        let mut y64 = x.clone();
        dht(&mut y64, &tw64).unwrap();
        let e64 = rel_rms(&y64, &reference);
        assert!(e64 <= budget(f64::EPSILON / 2.0, n), "f64 N={n}: {e64:e}");
        let mut y32: Vec<f32> = x.iter().map(|&v| v as f32).collect();
        dht(&mut y32, &tw32).unwrap();
        let y32: Vec<f64> = y32.into_iter().map(f64::from).collect();
        let e32 = rel_rms(&y32, &reference);
        assert!(
            e32 <= budget(f32::EPSILON as f64 / 2.0, n),
            "f32 N={n}: {e32:e}"
        );
        n *= 2;
    }
}

#[test]
fn forward_then_inverse_is_identity_up_to_4096() {
    twiddles!(4096; tw: f64);
    for log in 0..=12 {
        let n = 1 << log;
        let x = signal(n, 7 + n as u64);
        let mut y = x.clone();
        dht(&mut y, &tw).unwrap();
        idht(&mut y, &tw).unwrap();
        let e = rel_rms(&y, &x);
        assert!(e <= 2.0 * budget(f64::EPSILON / 2.0, n), "N={n}: {e:e}");
    }
}

#[test]
fn non_power_of_two_and_short_tables_are_errors() {
    let mut tw = vec![0.0f32; Twiddles::<f32>::buffer_len(64)];
    assert!(matches!(
        Twiddles::new(&mut tw, 48),
        Err(Error::NotPowerOfTwo { len: 48, .. })
    ));
    let tw = Twiddles::new(&mut tw, 64).unwrap();
    let mut x = vec![0.0f32; 12];
    assert!(matches!(
        dht(&mut x, &tw),
        Err(Error::NotPowerOfTwo { len: 12, .. })
    ));
    let mut x = vec![0.0f32; 128];
    assert!(matches!(
        dht(&mut x, &tw),
        Err(Error::TwiddlesTooShort {
            table_len: 64,
            needed: 128
        })
    ));
    let mut short = [0.0f32; 3];
    assert!(matches!(
        Twiddles::new(&mut short, 64),
        Err(Error::BufferTooSmall {
            needed: 17,
            got: 3,
            ..
        })
    ));
    let message = dht(&mut [0.0f32; 12], &tw).unwrap_err().to_string();
    assert!(
        message.contains("power of two") && message.contains("12"),
        "{message}"
    );
}

#[test]
fn true_2d_dht_matches_naive() {
    twiddles!(64; tw: f64);
    for (nx, ny) in [(1, 1), (2, 4), (8, 8), (16, 4), (32, 16)] {
        let x = signal(nx * ny, (nx * 100 + ny) as u64);
        let reference = naive_dht_2d(&x, nx, ny);
        let mut y = x.clone();
        let mut col = vec![0.0; ny];
        dht_2d(&mut y, nx, ny, &mut col, &tw).unwrap();
        let e = rel_rms(&y, &reference);
        assert!(
            e <= 2.0 * budget(f64::EPSILON / 2.0, nx * ny),
            "{nx}x{ny}: {e:e}"
        );
        idht_2d(&mut y, nx, ny, &mut col, &tw).unwrap();
        assert!(rel_rms(&y, &x) < 1e-13, "{nx}x{ny} round trip");
    }
}

#[test]
fn batched_2d_dht_matches_naive_and_the_line_path_bit_for_bit() {
    // f32 against the naive f64 sum: the radix-2 bound ε·log₂N per pass.
    twiddles!(128; tw32: f32);
    // Squares from 4 to 64 take the transposes that also run the first
    // radix-2² stages (64 with its side fixed at compile time), 128 the
    // tiled transposes; odd log₂n (8, 32) ends on a radix-2 stage.
    for (nx, ny) in [
        (1, 1),
        (2, 2),
        (4, 4),
        (8, 8),
        (16, 16),
        (32, 32),
        (4, 16),
        (16, 4),
        (64, 64),
        (128, 32),
        (128, 128),
    ] {
        let x = signal(nx * ny, (nx * 1000 + ny) as u64);
        let reference = naive_dht_2d(&x, nx, ny);
        let x32: Vec<f32> = x.iter().map(|&v| v as f32).collect();
        let mut batched = x32.clone();
        let mut lines = x32.clone();
        let mut col = vec![0.0f32; ny];
        dht_2d(&mut batched, nx, ny, &mut col, &tw32).unwrap();
        dht_2d_lines(&mut lines, nx, ny, &mut col, &tw32).unwrap();
        // The same butterflies on the same operands: identical bits.
        for (i, (a, b)) in batched.iter().zip(&lines).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "{nx}x{ny} at {i}");
        }
        let wide: Vec<f64> = batched.iter().map(|&v| v as f64).collect();
        let e = rel_rms(&wide, &reference);
        assert!(
            e <= 2.0 * budget(f32::EPSILON as f64 / 2.0, nx * ny),
            "{nx}x{ny}: {e:e}"
        );
    }
}

#[test]
fn square_2d_dht_with_few_nonzero_rows_matches_the_line_path() {
    // From side 128, at most n/4 rows holding a nonzero value take their
    // row pass alone, the zero rows skipped: as the lanes of one batched
    // transform with `dht_2d_sparse_len(n)` of scratch, else one row at a
    // time; one more row takes the full batched pass. Either way the
    // values are the line path's bit for bit (a zero only up to its sign).
    twiddles!(256; tw32: f32);
    for n in [128, 256] {
        for rows in [1, 2, n / 8, n / 4, n / 4 + 1] {
            for (scattered, scratch) in [
                (false, n),
                (false, dht_2d_sparse_len(n)),
                (true, dht_2d_sparse_len(n)),
            ] {
                let x = signal(n * n, (n * 7 + rows) as u64);
                // Rows `0 … a` and `n − b … n − 1` (a slice's low
                // frequencies on both sides of zero), or rows spread over
                // the array with a zero first value; the rest zero.
                let (a, b) = (rows.div_ceil(2), rows / 2);
                let held = |y: usize| match scattered {
                    false => y < a || y >= n - b,
                    true => (y * 37 + 5) % n < rows,
                };
                let x32: Vec<f32> = x
                    .iter()
                    .enumerate()
                    .map(|(i, &v)| match held(i / n) && !(scattered && i % n == 0) {
                        true => v as f32,
                        false => 0.0,
                    })
                    .collect();
                let mut batched = x32.clone();
                let mut lines = x32;
                let mut col = vec![0.0f32; scratch];
                dht_2d(&mut batched, n, n, &mut col, &tw32).unwrap();
                dht_2d_lines(&mut lines, n, n, &mut col, &tw32).unwrap();
                let case =
                    format!("{n}² with {rows} rows (scattered {scattered}, scratch {scratch})");
                let mut zeros = 0;
                for (i, (a, b)) in batched.iter().zip(&lines).enumerate() {
                    match *a == 0.0 {
                        true => zeros += 1,
                        false => assert_eq!(a.to_bits(), b.to_bits(), "{case} at {i}"),
                    }
                    assert_eq!(a, b, "{case} at {i}");
                }
                // Values that are zero are rare in a transform of noise.
                assert!(zeros < n, "{case}: {zeros} zeros");
            }
        }
    }
}

#[test]
fn true_3d_dht_matches_naive_in_f64_f32_and_f16_storage() {
    twiddles!(16; tw64: f64, tw32: f32);
    for dims in [
        [1, 1, 1],
        [2, 2, 2],
        [4, 8, 2],
        [8, 8, 8],
        [16, 4, 8],
        [2, 16, 16],
    ] {
        let len = dims.iter().product();
        let x = signal(len, len as u64 + dims[0] as u64);
        let reference = naive_dht_3d(&x, dims);
        let mut scratch64 = vec![0.0f64; dht_3d_scratch_len(dims)];
        let mut y = x.clone();
        dht_3d(&mut y, dims, &mut scratch64, &tw64).unwrap();
        let e = rel_rms(&y, &reference);
        assert!(
            e <= 3.0 * budget(f64::EPSILON / 2.0, len),
            "f64 {dims:?}: {e:e}"
        );

        let mut scratch32 = vec![0.0f32; dht_3d_scratch_len(dims)];
        let mut y32: Vec<f32> = x.iter().map(|&v| v as f32).collect();
        dht_3d(&mut y32, dims, &mut scratch32, &tw32).unwrap();
        let y32: Vec<f64> = y32.into_iter().map(f64::from).collect();
        let e = rel_rms(&y32, &reference);
        assert!(
            e <= 3.0 * budget(f32::EPSILON as f64 / 2.0, len),
            "f32 {dims:?}: {e:e}"
        );

        // f16 storage: the input rounding plus three roundings (x, y and the
        // fused z + correction pass), each ≤ 2^-11 relative to its value and
        // about 2^-11/√3 RMS. Orthogonal passes add errors in energy, so the
        // relative RMS stays below 2·2^-11 ≈ 1e-3 with margin.
        let mut y16: Vec<f16> = x.iter().map(|&v| f16::from_f64(v)).collect();
        let x16: Vec<f64> = y16.iter().map(|v| v.to_f64()).collect();
        let reference16 = naive_dht_3d(&x16, dims);
        dht_3d(&mut y16, dims, &mut scratch32, &tw32).unwrap();
        let y16: Vec<f64> = y16.into_iter().map(f64::from).collect();
        let e = rel_rms(&y16, &reference16);
        assert!(e <= 2.0 * 2f64.powi(-11), "f16 {dims:?}: {e:e}");
    }
}

#[test]
fn f16_overflow_in_the_3d_transform_is_an_error() {
    twiddles!(8; tw: f32);
    let mut data = vec![f16::from_f32(60000.0); 512];
    let mut scratch = vec![0.0f32; dht_3d_scratch_len([8, 8, 8])];
    let err = dht_3d(&mut data, [8, 8, 8], &mut scratch, &tw).unwrap_err();
    assert!(matches!(err, Error::Overflow { .. }), "{err}");
    assert!(err.to_string().contains("x pass"), "{err}");
}
