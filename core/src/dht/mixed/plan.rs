//! The plan of a mixed-radix transform: its length, radices and twiddle
//! table, and the lengths it accepts.

use crate::error::{check_len, require_len, Error, Result};
use crate::num::Real;

/// Most radices a length can have (each at least 2, so at most 64 of them).
const MAX_RADICES: usize = usize::BITS as usize;

/// A 1D transform of one length `n = 2^a·3^b·5^c`: its radices and its
/// twiddle table, which lives in a caller-provided slice of
/// [`mixed_table_len`]`(n)` elements.
///
/// The table holds `e^{−2πij/n} = (cos 2πj/n, −sin 2πj/n)` for `j < n`,
/// interleaved, each computed by `libm` in f64 and rounded once to `T`
/// (within 0.5 ulp of `T` plus < 1e-16 absolute). One table serves one
/// length; a 3D transform takes one plan per axis (the same plan twice for
/// two axes of one length).
#[derive(Debug)]
pub struct MixedPlan<'a, T> {
    n: usize,
    table: &'a [T],
    /// Radices of the complex FFT (of `n/2` for even `n`, else of `n`),
    /// in the order the stages run.
    radices: [u8; MAX_RADICES],
    stages: usize,
}

/// Table elements a plan of length `n` needs: `2n` (a complex root of
/// unity per index), saturating.
pub const fn mixed_table_len(n: usize) -> usize {
    n.saturating_mul(2)
}

/// Scratch elements a 1D transform of length `n` needs: `n` for even `n`
/// (a complex FFT of `n/2` ping-pongs between the data and the scratch),
/// `4n` for odd `n` (a complex FFT of `n` on two complex buffers),
/// saturating.
pub const fn mixed_scratch_len(n: usize) -> usize {
    if n % 2 == 0 {
        n
    } else {
        n.saturating_mul(4)
    }
}

/// `true` if `n ≥ 1` has no prime factor above 5.
pub const fn is_fast_len(n: usize) -> bool {
    if n == 0 {
        return false;
    }
    let mut m = n;
    while m % 2 == 0 {
        m /= 2;
    }
    while m % 3 == 0 {
        m /= 3;
    }
    while m % 5 == 0 {
        m /= 5;
    }
    m == 1
}

/// The smallest `2^a·3^b·5^c ≥ n_min` (1 for `n_min ≤ 1`), or `None` if
/// there is none in `usize`.
pub const fn fast_len(n_min: usize) -> Option<usize> {
    let mut best: Option<usize> = None;
    let mut p5: usize = 1;
    loop {
        let mut p35 = p5;
        loop {
            // The smallest p35·2^a ≥ n_min.
            let mut c = p35;
            let mut fits = true;
            while c < n_min {
                match c.checked_mul(2) {
                    Some(d) => c = d,
                    None => {
                        fits = false;
                        break;
                    }
                }
            }
            if fits {
                best = match best {
                    Some(b) if b <= c => Some(b),
                    _ => Some(c),
                };
            }
            match p35.checked_mul(3) {
                Some(d) => p35 = d,
                None => break,
            }
        }
        match p5.checked_mul(5) {
            Some(d) => p5 = d,
            None => break,
        }
    }
    best
}

#[cold]
fn unsupported(len: usize) -> Error {
    Error::UnsupportedLength { len }
}

impl<'a, T: Real> MixedPlan<'a, T> {
    /// Fill `buf` with the twiddle table for length `n` and plan it.
    ///
    /// # Errors
    /// [`Error::UnsupportedLength`] for `n = 0` or a prime factor above 5;
    /// `buf` shorter than [`mixed_table_len`]`(n)`.
    pub fn new(buf: &'a mut [T], n: usize) -> Result<Self> {
        let (radices, stages) = plan_radices(n)?;
        let len = mixed_table_len(n);
        require_len("mixed-radix twiddle buffer", len, buf.len())?;
        let step = 2.0 * core::f64::consts::PI / n as f64;
        for (j, pair) in buf[..len].chunks_exact_mut(2).enumerate() {
            let (c, s) = root(j, n, step);
            pair[0] = T::from_f64(c);
            pair[1] = T::from_f64(-s);
        }
        Ok(Self {
            n,
            table: &buf[..len],
            radices,
            stages,
        })
    }

    /// Wrap a table filled earlier by [`MixedPlan::new`] for length `n`
    /// (or stored, e.g. in flash, from its output).
    ///
    /// # Errors
    /// As [`MixedPlan::new`].
    pub fn from_table(table: &'a [T], n: usize) -> Result<Self> {
        let (radices, stages) = plan_radices(n)?;
        let len = mixed_table_len(n);
        require_len("mixed-radix twiddle table", len, table.len())?;
        Ok(Self {
            n,
            table: &table[..len],
            radices,
            stages,
        })
    }

    /// The transform length.
    pub fn len(&self) -> usize {
        self.n
    }

    /// `false`: a plan has length at least 1.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The radices of the complex FFT stages, in order.
    pub(super) fn radices(&self) -> &[u8] {
        &self.radices[..self.stages]
    }

    /// The interleaved table `e^{−2πij/n}`, `j < n`.
    pub(super) fn table(&self) -> &[T] {
        self.table
    }

    /// `Ok` if this plan is for length `got`.
    pub(super) fn check(&self, what: &'static str, got: usize) -> Result<()> {
        check_len(what, self.n, got)
    }
}

/// `(cos, sin)` of `2πj/n`, from `libm` on an argument reduced to at most
/// `π/4` around the nearest multiple of `π/2`: the axes come out exact and
/// entries `j` and `n − j` exact mirrors.
fn root(j: usize, n: usize, step: f64) -> (f64, f64) {
    let (j, n) = (j as u128, n as u128);
    // Nearest quarter turn q and the remainder 4j − q·n, |4j − q·n| ≤ n/2.
    let q = (4 * j + n / 2) / n;
    let r = (4 * j) as i128 - (q * n) as i128;
    let a = step * (r as f64) / 4.0;
    let (s, c) = (libm::sin(a), libm::cos(a));
    match q % 4 {
        0 => (c, s),
        1 => (-s, c),
        2 => (-c, -s),
        _ => (s, -c),
    }
}

/// The radices of the complex FFT for a DHT of length `n`: fours first,
/// then a two, threes, fives.
fn plan_radices(n: usize) -> Result<([u8; MAX_RADICES], usize)> {
    if !is_fast_len(n) {
        return Err(unsupported(n));
    }
    let mut m = if n % 2 == 0 { n / 2 } else { n };
    let mut radices = [0u8; MAX_RADICES];
    let mut stages = 0;
    for r in [4usize, 2, 3, 5] {
        while m % r == 0 && stages < MAX_RADICES {
            radices[stages] = r as u8;
            stages += 1;
            m /= r;
        }
    }
    Ok((radices, stages))
}
