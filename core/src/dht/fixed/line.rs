//! The fixed-point 1D radix-2 DHT in place with one block exponent, and
//! the stages the 2D transform shares.

use super::{peak, round_shift, FixedSample, FixedTwiddles, Shift};
use crate::dht::line::for_each_bit_reversed_swap;
use crate::error::Result;

/// Forward DHT of `data` in place, unnormalized (see [`super`]); returns
/// the exponent `e`: the transform is `data · 2^e` in the input's units.
///
/// # Errors
/// The length is not a power of two, or exceeds the twiddle table's length.
pub fn dht<S: FixedSample>(data: &mut [S], tw: &FixedTwiddles<'_, S>) -> Result<i32> {
    tw.check(data.len())?;
    let n = data.len();
    for_each_bit_reversed_swap(n, |i, j| data.swap(i, j));
    let (exp, _) = stages(data, n, 1, peak(data), tw);
    Ok(exp)
}

/// Inverse DHT in place: [`dht`] with `log₂N` taken off the exponent (the
/// `1/N` is exact in block floating point).
///
/// # Errors
/// As [`dht`].
pub fn idht<S: FixedSample>(data: &mut [S], tw: &FixedTwiddles<'_, S>) -> Result<i32> {
    let exp = dht(data, tw)?;
    Ok(exp - data.len().trailing_zeros() as i32)
}

/// Every radix-2 stage of length-`n` transforms on `data`, whose elements
/// are groups of `w` values (the same butterfly on each value of a group):
/// `w = 1` for lines laid end to end, `w = nx` for the columns of an
/// `nx`-wide array, whose rows are then the elements. Elements are already
/// in bit-reversed order; `peak` is `max |v|` over `data`. Returns the
/// summed exponent and the final peak.
///
/// Decimation in time as in [`crate::dht`]: a block of `2m` combines the
/// DHTs `X` (even) and `Y` (odd) of length `m`,
/// `H(k) = X(k) + c·Y(k) + s·Y(m−k)`, `H(k+m) = X(k) − (same)`, with
/// `(c, s) = (cos, sin)(πk/m)`.
#[inline(always)]
pub(super) fn stages<S: FixedSample>(
    data: &mut [S],
    n: usize,
    w: usize,
    mut peak: i64,
    tw: &FixedTwiddles<'_, S>,
) -> (i32, i64) {
    let limits = S::LIMITS;
    if n == 1 && peak >> S::FRAC_BITS != 0 {
        // The identity, on data holding the most negative integer: halve
        // the block so that no output holds the overflow flag of Q15
        // storage.
        for v in data.iter_mut() {
            *v = S::narrow(round_shift(v.widen(), 1));
        }
        return (1, peak >> 1);
    }
    let mut exp = 0;
    let mut m = 1;
    while m < n {
        // Stages of half-length 1 and 2 have no twiddled butterfly.
        let kind = if m <= 2 {
            limits.plain
        } else {
            limits.twiddled
        };
        let shift = Shift::choose(peak, kind);
        if shift.pre > 0 {
            // Rare (small inputs, or a stage that cancelled): a pass of its
            // own keeps the shift out of the butterflies.
            for v in data.iter_mut() {
                *v = S::narrow(v.widen() << shift.pre);
            }
        }
        peak = match shift.post {
            0 => stage::<S, 0>(data, w, m, tw),
            1 => stage::<S, 1>(data, w, m, tw),
            _ => stage::<S, 2>(data, w, m, tw),
        };
        exp += shift.exponent();
        m *= 2;
    }
    (exp, peak)
}

/// One stage of half-length `m` whose outputs are shifted right by `POST`
/// (a constant, so that an unscaled stage pays nothing for it); returns
/// the peak of its outputs.
#[inline(always)]
pub(super) fn stage<S: FixedSample, const POST: u32>(
    data: &mut [S],
    w: usize,
    m: usize,
    tw: &FixedTwiddles<'_, S>,
) -> i64 {
    let stride = tw.len / (2 * m);
    let mut top = S::Wide::from(0);
    for block in data.chunks_exact_mut(2 * m * w) {
        let (x, y) = block.split_at_mut(m * w);
        plain::<S, POST>(&mut x[..w], &mut y[..w], &mut top);
        if m >= 2 {
            let h = m / 2;
            plain::<S, POST>(
                &mut x[h * w..(h + 1) * w],
                &mut y[h * w..(h + 1) * w],
                &mut top,
            );
            for k in 1..h {
                let (c, s) = tw.cos_sin(k * stride);
                let (x_low, x_high) = x.split_at_mut((m - k) * w);
                let (y_low, y_high) = y.split_at_mut((m - k) * w);
                twiddled::<S, POST>(
                    [
                        &mut x_low[k * w..(k + 1) * w],
                        &mut x_high[..w],
                        &mut y_low[k * w..(k + 1) * w],
                        &mut y_high[..w],
                    ],
                    (c, s),
                    &mut top,
                );
            }
        }
    }
    // One above the largest ones' complement bounds the peak (exact, or one
    // over). Zero means every output is 0 or −1, which no stage can grow
    // past its limits unscaled, so it stands for a peak of 0.
    match S::wide_to_i64(top) {
        0 => 0,
        top => top + 1,
    }
}

/// `|v|` or `|v| − 1` (for negative `v`: the ones' complement
/// `v ^ sign`, one instruction on Thumb-2) into the running `top`; the
/// stage's peak is then `top + 1` at most. Outputs are below `2^(F+2)` in
/// magnitude, so `v >> (F + 2)` is the sign.
#[inline(always)]
fn track<S: FixedSample>(top: &mut S::Wide, v: S::Wide) {
    let a = v ^ (v >> (S::FRAC_BITS + 2));
    if a > *top {
        *top = a;
    }
}

/// `(x, y) ← (x + y, x − y)` over two groups, shifted right by `POST`.
#[inline(always)]
fn plain<S: FixedSample, const POST: u32>(x: &mut [S], y: &mut [S], top: &mut S::Wide) {
    for (a, b) in x.iter_mut().zip(y.iter_mut()) {
        let (p, q) = (a.widen(), b.widen());
        let (u, v) = (round_shift(p + q, POST), round_shift(p - q, POST));
        track::<S>(top, u);
        track::<S>(top, v);
        *a = S::narrow(u);
        *b = S::narrow(v);
    }
}

/// The twiddled butterfly over four groups `x[k], x[m−k], y[k], y[m−k]`:
/// `t1 = c·y[k] + s·y[m−k]`, `t2 = s·y[k] − c·y[m−k]` (each rounded from
/// the wide product once), then `x[k] ± t1` and `x[m−k] ± t2`, shifted
/// right by `POST`.
#[inline(always)]
fn twiddled<S: FixedSample, const POST: u32>(
    [xk, xmk, yk, ymk]: [&mut [S]; 4],
    (c, s): (S::Wide, S::Wide),
    top: &mut S::Wide,
) {
    let len = xk.len();
    let (xmk, yk, ymk) = (&mut xmk[..len], &mut yk[..len], &mut ymk[..len]);
    for i in 0..len {
        let (a, b) = (yk[i].widen(), ymk[i].widen());
        let t1 = round_product::<S>(c * a + s * b);
        let t2 = round_product::<S>(s * a - c * b);
        let (p, q) = (xk[i].widen(), xmk[i].widen());
        // Written out, not `[..].map`: `array::map` is left out of line on
        // thumb targets, a call per butterfly.
        let (o0, o1) = (round_shift(p + t1, POST), round_shift(q + t2, POST));
        let (o2, o3) = (round_shift(p - t1, POST), round_shift(q - t2, POST));
        track::<S>(top, o0);
        track::<S>(top, o1);
        track::<S>(top, o2);
        track::<S>(top, o3);
        xk[i] = S::narrow(o0);
        xmk[i] = S::narrow(o1);
        yk[i] = S::narrow(o2);
        ymk[i] = S::narrow(o3);
    }
}

/// A product sum in units of `2^−2F` to units of `2^−F`, rounded half up:
/// `(v + 2^(F−1)) >> F`. A tie needs the `F` low bits to be exactly
/// `2^(F−1)`, one pattern in `2^F`, so the bias is about `2^−(F+1)` of a
/// unit; half to even would cost two more operations per product.
#[inline(always)]
fn round_product<S: FixedSample>(v: S::Wide) -> S::Wide {
    (v + (S::Wide::from(1) << (S::FRAC_BITS - 1))) >> S::FRAC_BITS
}
