//! Special functions of the kernels: sinc, the Keys cubic, the modified
//! Bessel functions of the Kaiser–Bessel window, and Gauss–Legendre
//! quadrature for their spatial responses.

pub(super) fn sinc(x: f64) -> f64 {
    if libm::fabs(x) < 1e-8 {
        1.0
    } else {
        libm::sin(x) / x
    }
}

pub(super) fn keys_cubic_derivative(a: f64) -> f64 {
    const A: f64 = -0.5;
    if a <= 1.0 {
        (3.0 * (A + 2.0) * a - 2.0 * (A + 3.0)) * a
    } else if a < 2.0 {
        (3.0 * A * a - 10.0 * A) * a + 8.0 * A
    } else {
        0.0
    }
}

pub(super) fn keys_cubic(a: f64) -> f64 {
    const A: f64 = -0.5;
    if a <= 1.0 {
        ((A + 2.0) * a - (A + 3.0)) * a * a + 1.0
    } else if a < 2.0 {
        ((A * a - 5.0 * A) * a + 8.0 * A) * a - 4.0 * A
    } else {
        0.0
    }
}

/// Modified Bessel function of the first kind, order 0, by its power series
/// `Σ ((x/2)^k / k!)²`, summed until terms fall below 1e-17 of the sum.
pub fn bessel_i0(x: f64) -> f64 {
    let q = x * x / 4.0;
    power_series(1.0, |k| q / (k * k))
}

/// `I1(x)/x` by its power series `½·Σ (x²/4)^k / (k!·(k+1)!)`, finite at 0.
pub fn bessel_i1_over_x(x: f64) -> f64 {
    let q = x * x / 4.0;
    power_series(0.5, |k| q / (k * (k + 1.0)))
}

/// `Σ t_k` for `t_0 = first` and `t_k = t_{k−1}·ratio(k)`, summed until a
/// term falls below 1e-17 of the sum (at most 499 terms after the first).
#[inline(always)]
fn power_series(first: f64, ratio: impl Fn(f64) -> f64) -> f64 {
    let mut term = first;
    let mut sum = first;
    let mut k = 1.0;
    while term > 1e-17 * sum && k < 500.0 {
        term *= ratio(k);
        sum += term;
        k += 1.0;
    }
    sum
}

/// 16-point Gauss–Legendre nodes and weights on [−1, 1] (positive half;
/// standard tabulated values, Abramowitz & Stegun table 25.4).
const GL16: [(f64, f64); 8] = [
    (0.095_012_509_837_637_44, 0.189_450_610_455_068_5),
    (0.281_603_550_779_258_9, 0.182_603_415_044_923_6),
    (0.458_016_777_657_227_4, 0.169_156_519_395_002_5),
    (0.617_876_244_402_643_7, 0.149_595_988_816_576_7),
    (0.755_404_408_355_003, 0.124_628_971_255_533_9),
    (0.865_631_202_387_831_7, 0.095_158_511_682_492_78),
    (0.944_575_023_073_232_6, 0.062_253_523_938_647_89),
    (0.989_400_934_991_649_9, 0.027_152_459_411_754_09),
];

pub(crate) fn gauss_legendre_16(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let mid = 0.5 * (a + b);
    let half = 0.5 * (b - a);
    let mut sum = 0.0;
    for &(x, w) in GL16.iter() {
        sum += w * (f(mid - half * x) + f(mid + half * x));
    }
    sum * half
}
