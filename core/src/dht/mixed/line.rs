//! The 1D mixed-radix DHT: a complex FFT of half the length on the even
//! and odd samples packed as complex values, then one pass that separates
//! the two spectra and forms `H = Re X − Im X`.

use super::butterfly::{even_split, C};
use super::fft::fft;
use super::plan::{mixed_scratch_len, MixedPlan};
use crate::error::{require_len, Result};
use crate::num::Real;

/// Forward DHT of `data` in place, unnormalized:
/// `H(k) = Σ_x f(x) cas(2πkx/N)`, natural order, `N = data.len()`.
///
/// `scratch` needs [`mixed_scratch_len`]`(N)` elements; `plan` must be for
/// length `N`.
///
/// # Errors
/// [`crate::Error::LengthMismatch`] if the plan is for another length,
/// [`crate::Error::BufferTooSmall`] for short scratch.
pub fn dht_mixed<T: Real>(
    data: &mut [T],
    scratch: &mut [T],
    plan: &MixedPlan<'_, T>,
) -> Result<()> {
    plan.check("mixed-radix DHT data", data.len())?;
    require_len(
        "mixed-radix DHT scratch",
        mixed_scratch_len(data.len()),
        scratch.len(),
    )?;
    dht_mixed_unchecked(data, scratch, plan);
    Ok(())
}

/// Inverse DHT in place: the forward transform divided by `N`.
///
/// # Errors
/// As [`dht_mixed`].
pub fn idht_mixed<T: Real>(
    data: &mut [T],
    scratch: &mut [T],
    plan: &MixedPlan<'_, T>,
) -> Result<()> {
    dht_mixed(data, scratch, plan)?;
    let inv = T::from_f64(1.0 / data.len() as f64);
    for v in data.iter_mut() {
        *v *= inv;
    }
    Ok(())
}

/// [`dht_mixed`] once the caller has checked the plan's length against
/// `data` and `scratch` against [`mixed_scratch_len`].
pub(in crate::dht) fn dht_mixed_unchecked<T: Real>(
    data: &mut [T],
    scratch: &mut [T],
    plan: &MixedPlan<'_, T>,
) {
    let n = data.len();
    if n <= 1 {
        return;
    }
    if n % 2 == 0 {
        dht_even(data, &mut scratch[..n], plan);
    } else {
        dht_odd(data, &mut scratch[..4 * n], plan);
    }
}

/// Even `N = 2M`: `z(x) = f(2x) + i·f(2x+1)` is `data` itself read as `M`
/// complex values. With `Z` its DFT of length `M`, the DFTs of the even and
/// odd samples are `E(k) = ½[Z(k) + Z̄(M−k)]` and
/// `O(k) = −½i[Z(k) − Z̄(M−k)]`, and `X(k) = E(k) + e^{−2πik/N}·O(k)`
/// for `k ≤ M` (indices of `Z` mod `M`). The input is real, so
/// `X(N−k) = X̄(k)` and `H(k) = Re X(k) − Im X(k)`,
/// `H(N−k) = Re X(k) + Im X(k)`.
fn dht_even<T: Real>(data: &mut [T], scratch: &mut [T], plan: &MixedPlan<'_, T>) {
    let n = data.len();
    let m = n / 2;
    let table = plan.table();
    let in_scratch = fft(data, scratch, plan.radices(), table, 2);
    if !in_scratch {
        scratch.copy_from_slice(data);
    }
    let z = |k: usize| C {
        re: scratch[2 * k],
        im: scratch[2 * k + 1],
    };
    let z0 = z(0);
    data[0] = z0.re + z0.im;
    data[m] = z0.re - z0.im;
    for k in 1..m {
        let w = C {
            re: table[2 * k],
            im: table[2 * k + 1],
        };
        (data[k], data[n - k]) = even_split(z(k), z(m - k), w);
    }
}

/// Odd `N`: the complex FFT of `N` on the real input (imaginary parts
/// zero), in two complex buffers of `scratch`, then `H = Re X − Im X`.
fn dht_odd<T: Real>(data: &mut [T], scratch: &mut [T], plan: &MixedPlan<'_, T>) {
    let n = data.len();
    let (a, b) = scratch.split_at_mut(2 * n);
    for (pair, &v) in a.chunks_exact_mut(2).zip(data.iter()) {
        pair[0] = v;
        pair[1] = T::ZERO;
    }
    let in_b = fft(a, b, plan.radices(), plan.table(), 1);
    let x: &[T] = if in_b { b } else { a };
    for (h, pair) in data.iter_mut().zip(x.chunks_exact(2)) {
        *h = pair[0] - pair[1];
    }
}
