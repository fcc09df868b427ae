//! The 1D radix-2 DHT in place (natural order in and out) and its
//! inverse.

use super::Twiddles;
use crate::error::Result;
use crate::num::Real;

/// Forward DHT of `data` in place, unnormalized (see the module docs).
///
/// # Errors
/// The length is not a power of two, or exceeds the twiddle table's length.
pub fn dht<T: Real>(data: &mut [T], tw: &Twiddles<'_, T>) -> Result<()> {
    tw.check(data.len())?;
    dht_unchecked(data, tw);
    Ok(())
}

/// Inverse DHT in place: the forward transform divided by `N`.
///
/// # Errors
/// As [`dht`].
pub fn idht<T: Real>(data: &mut [T], tw: &Twiddles<'_, T>) -> Result<()> {
    dht(data, tw)?;
    let inv = T::from_f64(1.0 / data.len() as f64);
    for v in data.iter_mut() {
        *v *= inv;
    }
    Ok(())
}

fn bit_reverse<T>(data: &mut [T]) {
    for_each_bit_reversed_swap(data.len(), |i, j| data.swap(i, j));
}

/// Calls `swap(i, j)` for every pair `i < j` with `j` the bit reversal of
/// `i` among `0 … n − 1` (`n` a power of two): the swaps that put a
/// sequence of `n` (elements or rows) in bit-reversed order.
#[inline(always)]
pub(super) fn for_each_bit_reversed_swap(n: usize, mut swap: impl FnMut(usize, usize)) {
    let mut j = 0usize;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            swap(i, j);
        }
    }
}

/// Radix-2 decimation in time. A block of length `2m` combines the DHTs `X`
/// (even samples) and `Y` (odd samples) of length `m`:
/// `H(k) = X(k) + cos(πk/m)·Y(k) + sin(πk/m)·Y(m−k)` and
/// `H(k+m) = X(k) − (same)`, with `Y(m) ≡ Y(0)`.
pub(crate) fn dht_unchecked<T: Real>(data: &mut [T], tw: &Twiddles<'_, T>) {
    dht_stages(data, tw, |_| {});
}

/// [`dht_unchecked`] calling `after_stage` on the whole line after every
/// butterfly stage (a no-op closure compiles away).
#[inline(always)]
pub(super) fn dht_stages<T: Real, F: FnMut(&mut [T])>(
    data: &mut [T],
    tw: &Twiddles<'_, T>,
    mut after_stage: F,
) {
    let n = data.len();
    if n <= 1 {
        return;
    }
    bit_reverse(data);
    let mut m = 1;
    while m < n {
        let stride = tw.len / (2 * m);
        for block in data.chunks_exact_mut(2 * m) {
            let (x, y) = block.split_at_mut(m);
            butterfly_pair(&mut x[0], &mut y[0]);
            if m >= 2 {
                let h = m / 2;
                butterfly_pair(&mut x[h], &mut y[h]);
                for k in 1..h {
                    let (c, s) = tw.cos_sin(k * stride);
                    let (yk, ymk) = (y[k], y[m - k]);
                    let t1 = c * yk + s * ymk;
                    let t2 = s * yk - c * ymk;
                    let (xk, xmk) = (x[k], x[m - k]);
                    x[k] = xk + t1;
                    y[k] = xk - t1;
                    x[m - k] = xmk + t2;
                    y[m - k] = xmk - t2;
                }
            }
        }
        after_stage(data);
        m *= 2;
    }
}

#[inline(always)]
pub(super) fn butterfly_pair<T: Real>(a: &mut T, b: &mut T) {
    let (x, y) = (*a, *b);
    *a = x + y;
    *b = x - y;
}
