//! The mixed-radix DHTs against naive transforms evaluated in f64 with
//! compensated sums (error about one unit roundoff of f64, from the
//! rounded `cas` values), and against the radix-2 transforms.
//!
//! Tolerances: relative RMS error `‖H − H_ref‖₂ / ‖H_ref‖₂ ≤ C·ε·log₂N`,
//! `ε` the unit roundoff of the arithmetic type and `N` the number of
//! points (at least 2 in the logarithm). `C` is stated per test; the worst
//! measured ratio is printed (`--nocapture`).

use fvr_core::dht::{
    dht_2d_mixed, dht_2d_mixed_scratch_len, dht_3d, dht_3d_mixed, dht_3d_mixed_scratch_len,
    dht_3d_scratch_len, dht_mixed, fast_len, idht_mixed, is_fast_len, mixed_scratch_len,
    mixed_table_len, MixedPlan, Twiddles,
};
use fvr_core::num::{Real, Sample};
use fvr_core::Error;

/// Fixed-seed uniform values in [−0.5, 0.5).
fn signal(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect()
}

/// Neumaier-compensated sum of exact products (`mul_add` recovers each
/// product's rounding error).
#[derive(Default)]
struct Acc {
    sum: f64,
    comp: f64,
}

impl Acc {
    fn add(&mut self, v: f64) {
        let t = self.sum + v;
        self.comp += if self.sum.abs() >= v.abs() {
            (self.sum - t) + v
        } else {
            (v - t) + self.sum
        };
        self.sum = t;
    }
    fn add_product(&mut self, a: f64, b: f64) {
        let p = a * b;
        self.add(p);
        self.add(a.mul_add(b, -p));
    }
    fn value(&self) -> f64 {
        self.sum + self.comp
    }
}

/// `cas(2π·num/den)`, the argument reduced exactly to the nearest quarter
/// turn `q` plus at most an eighth of a turn, so `cos` and `sin` see an
/// argument of at most π/4 (error within 1 ulp of f64 each).
fn cas(num: u128, den: u128) -> f64 {
    let j = num % den;
    let q = (4 * j + den / 2) / den;
    let r = (4 * j) as i128 - (q * den) as i128;
    let a = std::f64::consts::FRAC_PI_2 * r as f64 / den as f64;
    let (s, c) = a.sin_cos();
    match q % 4 {
        0 => c + s,
        1 => c - s,
        2 => -c - s,
        _ => s - c,
    }
}

/// Naive true DHT of an array of dims `d` (x fastest), O(N²).
fn naive_dht(f: &[f64], d: [usize; 3]) -> Vec<f64> {
    let [nx, ny, nz] = d.map(|v| v as u128);
    let den = nx * ny * nz;
    let n = f.len();
    let mut out = vec![0.0; n];
    for (k, o) in out.iter_mut().enumerate() {
        let k = k as u128;
        let (u, v, w) = (k % nx, (k / nx) % ny, k / (nx * ny));
        let mut acc = Acc::default();
        for (i, &fv) in f.iter().enumerate() {
            let i = i as u128;
            let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
            // (ux/nx + vy/ny + wz/nz) in units of 1/(nx·ny·nz).
            let num = u * x * ny * nz + v * y * nx * nz + w * z * nx * ny;
            acc.add_product(fv, cas(num, den));
        }
        *o = acc.value();
    }
    out
}

fn rel_rms<T: Real>(got: &[T], want: &[f64]) -> f64 {
    let (mut e, mut r) = (0.0, 0.0);
    for (g, w) in got.iter().zip(want) {
        e += (g.to_f64() - w).powi(2);
        r += w * w;
    }
    if r == 0.0 {
        e.sqrt()
    } else {
        (e / r).sqrt()
    }
}

/// `C` in the error bound for `n` points in type `T`: the measured error
/// as a multiple of `ε·log₂N`.
fn ratio<T: Real>(err: f64, n: usize) -> f64 {
    err / (T::EPSILON_HALF * (n.max(2) as f64).log2())
}

fn fast_lens(max: usize) -> Vec<usize> {
    (1..=max).filter(|&n| is_fast_len(n)).collect()
}

/// The 1D forward transform of `input` (rounded to `T`) and the naive one of
/// the same rounded values.
fn forward_1d<T: Real>(input: &[f64]) -> (Vec<T>, Vec<f64>) {
    let n = input.len();
    let mut table = vec![T::ZERO; mixed_table_len(n)];
    let plan = MixedPlan::new(&mut table, n).unwrap();
    let mut data: Vec<T> = input.iter().map(|&v| T::from_f64(v)).collect();
    let exact: Vec<f64> = data.iter().map(|v| v.to_f64()).collect();
    let mut scratch = vec![T::ZERO; mixed_scratch_len(n)];
    dht_mixed(&mut data, &mut scratch, &plan).unwrap();
    (data, naive_dht(&exact, [n, 1, 1]))
}

/// Every length `2^a·3^b·5^c ≤ 512` (68 of them) in type `T`: relative RMS
/// error within `c·ε·log₂N`. Returns the worst ratio and its length.
fn every_length<T: Real>(c: f64) -> (f64, usize) {
    let mut worst = (0.0, 0);
    let lens = fast_lens(512);
    assert_eq!(lens.len(), 68);
    for n in lens {
        let (got, want) = forward_1d::<T>(&signal(n, n as u64));
        let r = ratio::<T>(rel_rms(&got, &want), n);
        assert!(r <= c, "N = {n}: error {r:.3}·ε·log₂N above {c}");
        if r > worst.0 {
            worst = (r, n);
        }
    }
    worst
}

#[test]
fn every_length_to_512_f64() {
    // C = 2: the measured worst case is below 1.
    let (worst, n) = every_length::<f64>(2.0);
    println!("1D f64: worst relative RMS error {worst:.3}·ε·log₂N (N = {n}) over N ≤ 512");
}

#[test]
fn every_length_to_512_f32() {
    // C = 2, as for f64 (the reference's own error is 2^-29 of ε_f32).
    let (worst, n) = every_length::<f32>(2.0);
    println!("1D f32: worst relative RMS error {worst:.3}·ε·log₂N (N = {n}) over N ≤ 512");
}

#[test]
fn the_grid_sizes_of_oversampled_volumes() {
    // Beyond 512: lengths the per-axis grids use, f32, same bound.
    for n in [
        160usize, 180, 320, 400, 640, 720, 768, 800, 1000, 1024, 1215,
    ] {
        let (got, want) = forward_1d::<f32>(&signal(n, 7));
        let err = rel_rms(&got, &want);
        let r = ratio::<f32>(err, n);
        assert!(r <= 2.0, "N = {n}: {r:.3}");
        println!("1D f32 N = {n}: relative RMS error {err:.2e} = {r:.3}·ε·log₂N");
    }
}

#[test]
fn round_trip_is_identity() {
    // Forward then inverse: within C = 4 (two transforms and the scaling;
    // the measured worst case is below 1.5).
    let mut worst: f64 = 0.0;
    for n in fast_lens(512) {
        let input = signal(n, 3 * n as u64);
        let mut table = vec![0.0f64; mixed_table_len(n)];
        let plan = MixedPlan::new(&mut table, n).unwrap();
        let mut scratch = vec![0.0; mixed_scratch_len(n)];
        let mut data = input.clone();
        dht_mixed(&mut data, &mut scratch, &plan).unwrap();
        idht_mixed(&mut data, &mut scratch, &plan).unwrap();
        let r = ratio::<f64>(rel_rms(&data, &input), n);
        assert!(r <= 4.0, "N = {n}: {r:.3}");
        worst = worst.max(r);
    }
    println!("round trip f64: worst {worst:.3}·ε·log₂N");
}

#[test]
fn length_one_is_the_identity() {
    let mut table = [0.0f32; 2];
    let plan = MixedPlan::new(&mut table, 1).unwrap();
    let mut data = [0.75f32];
    let mut scratch = [0.0f32; 4];
    dht_mixed(&mut data, &mut scratch, &plan).unwrap();
    assert_eq!(data, [0.75]);
    idht_mixed(&mut data, &mut scratch, &plan).unwrap();
    assert_eq!(data, [0.75]);
    assert_eq!(mixed_scratch_len(1), 4);
}

#[test]
fn lengths_with_other_prime_factors_are_refused() {
    for n in [0usize, 7, 14, 49, 11 * 16, 2 * 3 * 5 * 7, 1 << 10 | 1] {
        let mut table = vec![0.0f64; mixed_table_len(n).max(2)];
        let err = MixedPlan::new(&mut table, n).unwrap_err();
        assert_eq!(err, Error::UnsupportedLength { len: n });
        assert!(err.to_string().contains(&n.to_string()), "{err}");
        assert_eq!(
            MixedPlan::<f64>::from_table(&table, n).unwrap_err(),
            Error::UnsupportedLength { len: n }
        );
    }
}

#[test]
fn wrong_lengths_give_errors() {
    let mut table = vec![0.0f32; mixed_table_len(12)];
    // Short table.
    assert!(matches!(
        MixedPlan::new(&mut table[..23], 12),
        Err(Error::BufferTooSmall { needed: 24, .. })
    ));
    let plan = MixedPlan::new(&mut table, 12).unwrap();
    let mut scratch = vec![0.0f32; 64];
    // Data of another length than the plan.
    for len in [0usize, 11, 13, 24] {
        let mut data = vec![0.0f32; len];
        assert!(matches!(
            dht_mixed(&mut data, &mut scratch, &plan),
            Err(Error::LengthMismatch {
                expected: 12,
                got,
                ..
            }) if got == len
        ));
    }
    // A length whose table would not fit in memory: an error, no overflow.
    let mut big = vec![0.0f32; 64];
    assert!(matches!(
        MixedPlan::new(&mut big, 1 << (usize::BITS - 2)),
        Err(Error::BufferTooSmall { .. })
    ));
    assert_eq!(mixed_table_len(usize::MAX), usize::MAX);
    assert_eq!(dht_3d_mixed_scratch_len([usize::MAX; 3]), usize::MAX);
    // Short scratch.
    let mut data = vec![0.0f32; 12];
    assert!(matches!(
        dht_mixed(&mut data, &mut scratch[..11], &plan),
        Err(Error::BufferTooSmall { needed: 12, .. })
    ));
    // 2D and 3D: a plan for the wrong axis, a wrong data length, short scratch.
    let mut t5 = vec![0.0f32; mixed_table_len(5)];
    let p5 = MixedPlan::new(&mut t5, 5).unwrap();
    let mut data = vec![0.0f32; 60];
    assert!(dht_2d_mixed(&mut data, 5, 12, &mut scratch, [&plan, &p5]).is_err());
    assert!(dht_2d_mixed(&mut data[..59], 12, 5, &mut scratch, [&plan, &p5]).is_err());
    assert!(dht_2d_mixed(&mut data, 12, 5, &mut scratch[..3], [&plan, &p5]).is_err());
    assert!(dht_2d_mixed(&mut data, 12, 5, &mut scratch, [&plan, &p5]).is_ok());
    let mut s3 = vec![0.0f32; dht_3d_mixed_scratch_len([12, 5, 1])];
    let mut t1 = [0.0f32; 2];
    let p1 = MixedPlan::new(&mut t1, 1).unwrap();
    assert!(dht_3d_mixed(&mut data, [12, 5, 1], &mut s3, [&plan, &p5, &p5]).is_err());
    assert!(dht_3d_mixed(&mut data[..59], [12, 5, 1], &mut s3, [&plan, &p5, &p1]).is_err());
    assert!(dht_3d_mixed(&mut data, [usize::MAX, 5, 2], &mut s3, [&plan, &p5, &p1]).is_err());
    let short = s3.len() - 1;
    assert!(dht_3d_mixed(&mut data, [12, 5, 1], &mut s3[..short], [&plan, &p5, &p1]).is_err());
    assert!(dht_3d_mixed(&mut data, [12, 5, 1], &mut s3, [&plan, &p5, &p1]).is_ok());
}

#[test]
fn fast_len_is_the_next_smooth_length() {
    let mut next = None;
    for n in (0..=5000usize).rev() {
        if is_fast_len(n) {
            next = Some(n);
        }
        let want = if n == 0 { Some(1) } else { next };
        assert_eq!(fast_len(n), want, "n_min = {n}");
    }
    assert_eq!(fast_len(161), Some(162));
    assert_eq!(fast_len(321), Some(324));
    assert_eq!(fast_len(400), Some(400));
    // 2^64 − 1 = 3·5·17·257·641·65537·6700417: nothing in usize is above it.
    assert_eq!(fast_len(usize::MAX), None);
    assert!(is_fast_len(fast_len(usize::MAX / 3).unwrap()));
}

/// Plans for three axes (tables owned by the returned vectors).
fn tables<T: Real>(dims: &[usize]) -> Vec<Vec<T>> {
    dims.iter()
        .map(|&n| vec![T::ZERO; mixed_table_len(n)])
        .collect()
}

/// `dht_3d_mixed` of `data` (storage `S`) in arithmetic `T`, with a plan
/// per axis.
fn mixed_3d<S: Sample, T: Real>(data: &mut [S], dims: [usize; 3]) {
    let mut tabs = tables::<T>(&dims);
    let [tx, ty, tz] = &mut tabs[..] else {
        unreachable!()
    };
    let px = MixedPlan::new(tx, dims[0]).unwrap();
    let py = MixedPlan::new(ty, dims[1]).unwrap();
    let pz = MixedPlan::new(tz, dims[2]).unwrap();
    let mut scratch = vec![T::ZERO; dht_3d_mixed_scratch_len(dims)];
    dht_3d_mixed(data, dims, &mut scratch, [&px, &py, &pz]).unwrap();
}

fn check_2d<T: Real>(nx: usize, ny: usize, c: f64) -> f64 {
    let input = signal(nx * ny, (nx * 31 + ny) as u64);
    let mut data: Vec<T> = input.iter().map(|&v| T::from_f64(v)).collect();
    let exact: Vec<f64> = data.iter().map(|v| v.to_f64()).collect();
    let mut tabs = tables::<T>(&[nx, ny]);
    let [tx, ty] = &mut tabs[..] else {
        unreachable!()
    };
    let px = MixedPlan::new(tx, nx).unwrap();
    let py = MixedPlan::new(ty, ny).unwrap();
    let mut scratch = vec![T::ZERO; dht_2d_mixed_scratch_len(nx, ny)];
    dht_2d_mixed(&mut data, nx, ny, &mut scratch, [&px, &py]).unwrap();
    let r = ratio::<T>(rel_rms(&data, &naive_dht(&exact, [nx, ny, 1])), nx * ny);
    assert!(r <= c, "{nx}×{ny}: {r:.3}");
    r
}

#[test]
fn true_2d_against_naive() {
    // C = 2 in both types; odd, even, unit and mixed sides.
    for (nx, ny) in [
        (6, 10),
        (12, 9),
        (3, 5),
        (5, 1),
        (1, 8),
        (1, 1),
        (16, 15),
        (20, 18),
    ] {
        let a = check_2d::<f64>(nx, ny, 2.0);
        let b = check_2d::<f32>(nx, ny, 2.0);
        println!("2D {nx}×{ny}: f64 {a:.3}, f32 {b:.3} ·ε·log₂N");
    }
}

fn check_3d<T: Real + Sample>(dims: [usize; 3], c: f64) -> f64 {
    let n: usize = dims.iter().product();
    let input = signal(n, (dims[0] * 1000 + dims[1] * 10 + dims[2]) as u64);
    let mut data: Vec<T> = input.iter().map(|&v| <T as Real>::from_f64(v)).collect();
    let exact: Vec<f64> = data.iter().map(|v| Real::to_f64(*v)).collect();
    mixed_3d::<_, T>(&mut data, dims);
    let r = ratio::<T>(rel_rms(&data, &naive_dht(&exact, dims)), n);
    assert!(r <= c, "{dims:?}: {r:.3}");
    r
}

#[test]
fn true_3d_against_naive() {
    // C = 2 in both types (values stored in the arithmetic type).
    for dims in [
        [6, 10, 15],
        [12, 9, 20],
        [3, 5, 1],
        [1, 1, 1],
        [2, 3, 4],
        [5, 1, 6],
        [8, 4, 2],
    ] {
        let a = check_3d::<f64>(dims, 2.0);
        let b = check_3d::<f32>(dims, 2.0);
        println!("3D {dims:?}: f64 {a:.3}, f32 {b:.3} ·ε·log₂N");
    }
}

#[test]
fn true_3d_agrees_with_radix_2() {
    // Powers of two: the mixed and radix-2 transforms differ by their two
    // roundoffs, C = 4 in f64 (f64 storage: no rounding to a format).
    for dims in [[8usize, 16, 4], [32, 32, 32], [2, 1, 64]] {
        let n: usize = dims.iter().product();
        let input = signal(n, 99);
        let big = *dims.iter().max().unwrap();
        let mut tw_buf = vec![0.0f64; Twiddles::<f64>::buffer_len(big)];
        let tw = Twiddles::new(&mut tw_buf, big).unwrap();
        let mut radix2 = input.clone();
        let mut s2 = vec![0.0f64; dht_3d_scratch_len(dims)];
        dht_3d(&mut radix2, dims, &mut s2, &tw).unwrap();

        let mut mixed = input.clone();
        mixed_3d::<_, f64>(&mut mixed, dims);
        let r = ratio::<f64>(rel_rms(&mixed, &radix2), n);
        assert!(r <= 4.0, "{dims:?}: {r:.3}");
        println!("3D {dims:?} mixed vs radix 2: {r:.3}·ε·log₂N");
    }
}

#[test]
fn one_plan_serves_two_axes() {
    let mut t = vec![0.0f64; mixed_table_len(10)];
    let p = MixedPlan::new(&mut t, 10).unwrap();
    let mut t3 = vec![0.0f64; mixed_table_len(3)];
    let p3 = MixedPlan::new(&mut t3, 3).unwrap();
    let input = signal(300, 5);
    let mut data = input.clone();
    let mut scratch = vec![0.0; dht_3d_mixed_scratch_len([10, 10, 3])];
    dht_3d_mixed(&mut data, [10, 10, 3], &mut scratch, [&p, &p, &p3]).unwrap();
    let r = ratio::<f64>(rel_rms(&data, &naive_dht(&input, [10, 10, 3])), 300);
    assert!(r <= 2.0, "{r:.3}");
}

#[test]
fn f16_storage_rounds_once_per_pass() {
    // f16 storage, f32 arithmetic: three roundings to f16 (unit roundoff
    // u = 2^-11) dominate, each adding a relative RMS error of at most u;
    // bound 3u.
    use fvr_core::f16;
    let dims = [20usize, 18, 16];
    let n: usize = dims.iter().product();
    let input = signal(n, 11);
    let mut data: Vec<f16> = input.iter().map(|&v| f16::from_f64(v)).collect();
    let exact: Vec<f64> = data.iter().map(|v| v.to_f64()).collect();
    mixed_3d::<_, f32>(&mut data, dims);
    let got: Vec<f64> = data.iter().map(|v| v.to_f64()).collect();
    let err = rel_rms(&got, &naive_dht(&exact, dims));
    let u = 2f64.powi(-11);
    assert!(err <= 3.0 * u, "{err:.3e}");
    println!(
        "3D {dims:?} f16 storage: relative RMS error {:.2}·u",
        err / u
    );
}

#[test]
fn overflowing_the_storage_is_an_error() {
    use fvr_core::f16;
    let dims = [6usize, 5, 4];
    let mut data = vec![f16::from_f64(60000.0); 120];
    let mut t6 = vec![0.0f32; mixed_table_len(6)];
    let mut t5 = vec![0.0f32; mixed_table_len(5)];
    let mut t4 = vec![0.0f32; mixed_table_len(4)];
    let p6 = MixedPlan::new(&mut t6, 6).unwrap();
    let p5 = MixedPlan::new(&mut t5, 5).unwrap();
    let p4 = MixedPlan::new(&mut t4, 4).unwrap();
    let mut scratch = vec![0.0f32; dht_3d_mixed_scratch_len(dims)];
    assert!(matches!(
        dht_3d_mixed(&mut data, dims, &mut scratch, [&p6, &p5, &p4]),
        Err(Error::Overflow { .. })
    ));
}

#[test]
fn a_stored_table_gives_the_same_transform() {
    let n = 360;
    let mut buf = vec![0.0f32; mixed_table_len(n)];
    let input: Vec<f32> = signal(n, 1).iter().map(|&v| v as f32).collect();
    let mut scratch = vec![0.0f32; mixed_scratch_len(n)];
    let mut a = input.clone();
    dht_mixed(&mut a, &mut scratch, &MixedPlan::new(&mut buf, n).unwrap()).unwrap();
    let mut b = input;
    let stored = MixedPlan::from_table(&buf, n).unwrap();
    assert_eq!(stored.len(), n);
    dht_mixed(&mut b, &mut scratch, &stored).unwrap();
    assert_eq!(a, b);
    assert!(matches!(
        MixedPlan::<f32>::from_table(&buf[..719], n),
        Err(Error::BufferTooSmall { needed: 720, .. })
    ));
}
