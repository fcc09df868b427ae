//! Kernel tables read during extraction: the kernel and its derivative
//! sampled 1024 times per unit, and the per-phase weight rows of the hot
//! loop.

use super::{Filter, FilterKind, MAX_WIDTH};
use crate::error::{Error, Result};
use crate::num::Real;

/// Table samples per unit of kernel argument.
pub const TABLE_RESOLUTION: usize = 1024;
const TABLE_CAP: usize = MAX_WIDTH / 2 * TABLE_RESOLUTION + 2;

/// Samples `g(i/1024)`, `i = 0 ..= W·512`, of an even or odd function over
/// `[0, W/2]`, read with linear interpolation: the storage and lookup shared
/// by [`KernelTable`] and [`DerivativeTable`].
#[derive(Clone, Debug)]
struct Samples<T> {
    values: [T; TABLE_CAP],
    len: usize,
}

impl<T: Real> Samples<T> {
    /// Entries for `filter`: `W·1024/2 + 1`.
    const fn len_for(filter: &Filter) -> usize {
        filter.kind.width() * TABLE_RESOLUTION / 2 + 1
    }

    /// Tabulate `g` over `[0, W/2]`.
    fn tabulate(filter: &Filter, g: impl Fn(f64) -> f64) -> Self {
        let len = Self::len_for(filter);
        let mut values = [T::ZERO; TABLE_CAP];
        for (i, v) in values[..len].iter_mut().enumerate() {
            *v = T::from_f64(g(i as f64 / TABLE_RESOLUTION as f64));
        }
        Self { values, len }
    }

    /// Wrap stored `values` of the `what` table for `filter`.
    ///
    /// # Errors
    /// The wrong length, or a NaN or infinite entry (named by its index).
    fn from_values(what: &'static str, filter: &Filter, values: &[T]) -> Result<Self> {
        let len = Self::len_for(filter);
        if values.len() != len {
            return Err(crate::error::mismatch(what, len, values.len()));
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFiniteTableEntry { what, index });
        }
        let mut table = [T::ZERO; TABLE_CAP];
        table[..len].copy_from_slice(values);
        Ok(Self { values: table, len })
    }

    fn values(&self) -> &[T] {
        &self.values[..self.len]
    }

    /// `g(a)` for `a ≥ 0`, 0 beyond the table.
    #[inline(always)]
    fn lerp(&self, a: T) -> T {
        let x = a * T::from_usize(TABLE_RESOLUTION);
        let i = x.trunc_usize();
        if i + 1 >= self.len {
            return if i < self.len {
                self.values[i]
            } else {
                T::ZERO
            };
        }
        let f = x - T::from_usize(i);
        self.values[i] + f * (self.values[i + 1] - self.values[i])
    }
}

/// The taps of a sample at fractional index `q` for a filter of width
/// `weights.len()`: returns `j0 = ⌊q − W/2⌋ + 1` (may be negative) and
/// writes `eval(q − j0 − m)` for `m = 0 … W−1`.
#[inline(always)]
fn tap_weights<T: Real>(q: T, weights: &mut [T], eval: impl Fn(T) -> T) -> i64 {
    let j0 = (q - T::from_usize(weights.len()) * T::HALF).floor_i64() + 1;
    // q − j0 in (W/2 − 1, W/2]; exact in T because j0 is small.
    let mut d = q - T::from_i32(j0 as i32);
    for wt in weights.iter_mut() {
        *wt = eval(d);
        d -= T::ONE;
    }
    j0
}

/// A kernel tabulated at `1/1024` steps over `[0, W/2]`, read with linear
/// interpolation.
///
/// # Accuracy
/// Linear interpolation errs by at most `Δ²/8·max|k''|` with `Δ = 1/1024`:
/// about `1.2e-7·max|k''|`. For the widest, sharpest kernel here (kb6 at
/// σ = 2, β ≈ 13.9, `max|k''| ≈ 11`) that is 1.3e-6 of `k(0)`, below −115 dB.
/// Nearest and linear kernels are reproduced exactly (their breakpoints lie
/// on the grid).
#[derive(Clone, Debug)]
pub struct KernelTable<T> {
    filter: Filter,
    samples: Samples<T>,
}

impl<T: Real> KernelTable<T> {
    /// Tabulate `filter`'s kernel.
    pub fn new(filter: Filter) -> Self {
        // The table runs over |t|; the half-open nearest support is handled
        // by the tap selection, which never asks for |t| > ½.
        let samples = Samples::tabulate(&filter, |t| match filter.kind {
            FilterKind::Nearest => 1.0,
            _ => filter.kernel(t),
        });
        Self { filter, samples }
    }

    /// Entries a table for `filter` holds: `W·1024/2 + 1`, the samples
    /// `k(i/1024)` for `i = 0 ..= W·512`.
    pub const fn len_for(filter: &Filter) -> usize {
        Samples::<T>::len_for(filter)
    }

    /// Rebuild a table from the values [`KernelTable::values`] returned for
    /// the same filter, e.g. a table in flash generated at build time, so a
    /// target without fast f64 never evaluates the Bessel series. The result
    /// equals `KernelTable::new(filter)` bit for bit when `values` came from
    /// it.
    ///
    /// # Errors
    /// `values.len()` other than [`KernelTable::len_for`]`(&filter)`, or a
    /// NaN or infinite entry (named by its index).
    pub fn from_values(filter: Filter, values: &[T]) -> Result<Self> {
        let samples = Samples::from_values("kernel table", &filter, values)?;
        Ok(Self { filter, samples })
    }

    /// The tabulated samples `k(i/1024)`, `i = 0 ..= W·512`.
    pub fn values(&self) -> &[T] {
        self.samples.values()
    }

    /// The filter tabulated.
    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// Kernel at distance `t`, `|t| ≤ W/2` (the kernel is even).
    #[inline(always)]
    pub fn eval(&self, t: T) -> T {
        self.samples.lerp(if t < T::ZERO { -t } else { t })
    }

    /// Per-axis taps for a sample at fractional index `q`: the first tap's
    /// index `j0 = ⌊q − W/2⌋ + 1` (may be negative) and the weights
    /// `k(q − j0 − m)` for `m = 0 … W−1`, written to `weights`.
    #[inline(always)]
    pub fn taps(&self, q: T, weights: &mut [T; MAX_WIDTH]) -> i64 {
        tap_weights(q, &mut weights[..self.filter.width()], |d| self.eval(d))
    }

    /// [`KernelTable::taps`] for a width known at compile time (`W` must be
    /// the filter's width): the same weights and `j0`, in a fixed array, so
    /// tap loops unroll.
    #[inline(always)]
    pub fn taps_fixed<const W: usize>(&self, q: T, weights: &mut [T; W]) -> i64 {
        tap_weights(q, weights, |d| self.eval(d))
    }
}

/// The weights of all `W` taps of a sample at every phase `p = i/1024`,
/// `i = 0 … 1023`, gathered from a [`KernelTable`]: row `i` holds
/// `k(p + W/2 − 1 − m)` for `m = 0 … W−1`, each an entry of the kernel table
/// itself (`|i + (W−2)·512 − 1024·m|`), so no value is rounded anew, and
/// the differences to the next row's (`i + 1 = 1024` included).
///
/// [`PhaseTable::taps_fixed_point`] finds a sample's first tap and phase
/// from its position in fixed point ([`PhaseTable::fixed_position`]: one
/// floor, or along a slice row one integer step) and interpolates its `W`
/// weights between two adjacent rows, where
/// [`KernelTable::taps_fixed`] looks each weight up on its own. This is the
/// per-axis setup of every slice sample (3 per pixel), so it matters.
///
/// # Accuracy
/// As [`KernelTable`]: the same entries, linearly interpolated at the same
/// fractions (to the rounding of the fraction: `ε·1024·|q|` in index units
/// for the position, `2^−42` for the fixed point).
#[derive(Clone, Debug)]
pub struct PhaseTable<T, const W: usize> {
    /// Row `i`: the weights at phase `i/1024` and their differences to
    /// row `i + 1` (the same `p1 − p0` the interpolation would compute),
    /// so that a weight is one multiply-add.
    rows: [[[T; W]; 2]; TABLE_RESOLUTION],
}

impl<T: Real, const W: usize> PhaseTable<T, W> {
    /// An all-zero table, to be [`PhaseTable::fill`]ed in place (the table
    /// is up to 48 KiB in f32: built where it stays, it is not copied).
    pub fn zeroed() -> Self {
        Self {
            rows: [[[T::ZERO; W]; 2]; TABLE_RESOLUTION],
        }
    }

    /// Gather the rows from `kernel`, whose width must be `W`.
    ///
    /// # Errors
    /// A kernel of another width ([`Error::LengthMismatch`]).
    pub fn fill(&mut self, kernel: &KernelTable<T>) -> Result<()> {
        let width = kernel.filter().width();
        if width != W {
            return Err(crate::error::mismatch("phase table width", width, W));
        }
        self.gather(&kernel.samples, false);
        Ok(())
    }

    /// Gather the rows of the kernel derivative `k'` from `derivative`
    /// (odd: an entry at a negative argument is the negated entry at its
    /// absolute value, as [`DerivativeTable::eval`]), whose width must be
    /// `W`. Its rows pair with a [`PhaseTable::fill`]ed one at the same
    /// positions: the same taps, the derivative weights.
    ///
    /// # Errors
    /// A table of another width ([`Error::LengthMismatch`]).
    pub(crate) fn fill_derivative(&mut self, derivative: &DerivativeTable<T>) -> Result<()> {
        let width = derivative.filter().width();
        if width != W {
            return Err(crate::error::mismatch("phase table width", width, W));
        }
        self.gather(&derivative.samples, true);
        Ok(())
    }

    /// Row `i`, weight `m`: the entry at `i + (W−2)·512 − 1024·m`.
    fn gather(&mut self, samples: &Samples<T>, odd: bool) {
        let values = &samples.values;
        let entry = |i: usize, m: usize| {
            let signed = phase_entry::<W>(i, m);
            // |index| ≤ W·512 < the table's length; 0 beyond, like `lerp`.
            let v = values
                .get(signed.unsigned_abs() as usize)
                .copied()
                .unwrap_or(T::ZERO);
            if odd && signed < 0 {
                -v
            } else {
                v
            }
        };
        fill_rows(&mut self.rows, entry);
    }

    /// The position `Y = 1024·q − 512·W` of a sample at `q` in 32.32 fixed
    /// point, `⌊Y·2^32⌋`: the first tap is `j0 = ⌊q − W/2⌋ + 1 = ⌊F/1024⌋ + 1`
    /// and the phase row `F mod 1024` for `F = ⌊Y⌋`, found by one truncation
    /// and one correction below zero (slice points lie inside the Nyquist
    /// cube, so `|Y| ≤ 512·(n + W)` is far inside the i32 range); the fraction is `Y − F`
    /// (exact in `T`) times `2^32`, truncated. Rows of the slice start from
    /// this and add [`PhaseTable::fixed_step`] per pixel.
    #[inline(always)]
    pub fn fixed_position(q: T) -> i64 {
        let y = q * T::from_usize(TABLE_RESOLUTION) - T::from_usize(W * TABLE_RESOLUTION / 2);
        let t = y.trunc_i32();
        let floor = t - (T::from_i32(t) > y) as i32;
        let fraction = (y - T::from_i32(floor)) * T::from_f64(FIXED_ONE);
        // < 2^32 (a fraction below 1 times a power of two); the bound keeps
        // 64- and 32-bit `usize` alike should it ever not be.
        let fraction = fraction.trunc_usize().min(u32::MAX as usize);
        ((floor as i64) << 32) + fraction as i64
    }

    /// The step of [`PhaseTable::fixed_position`] for a unit step of `q`
    /// along `r`: `1024·r·2^32`, rounded to nearest. Over a row of `m`
    /// pixels its rounding (≤ 2^−33 of a phase step a pixel) moves a sample
    /// by at most `m·2^−43` index units, far below `T`'s own rounding of
    /// `q` in f32 (`2^−24·|q|`).
    pub fn fixed_step(r: T) -> i64 {
        (r * T::from_f64(FIXED_ONE * TABLE_RESOLUTION as f64) + T::HALF).floor_i64()
    }

    /// Taps of the sample at fixed-point position `y`
    /// ([`PhaseTable::fixed_position`]): the first tap's index `j0` and the
    /// weights `k(q − j0 − m)`, `m = 0 … W−1`, interpolated between phase
    /// rows `F mod 1024` and the next by the 32-bit fraction.
    #[inline(always)]
    pub fn taps_fixed_point(&self, y: i64) -> (i32, [T; W]) {
        let floor = (y >> 32) as i32;
        let f = T::from_usize(y as u32 as usize) * T::from_f64(1.0 / FIXED_ONE);
        let row = (floor & (TABLE_RESOLUTION as i32 - 1)) as usize;
        let [p0, dp] = &self.rows[row];
        let weights = core::array::from_fn(|m| p0[m] + f * dp[m]);
        ((floor >> TABLE_RESOLUTION.trailing_zeros()) + 1, weights)
    }
}

/// The signed kernel-table index of weight `m` of phase row `i` of a
/// width-`W` [`PhaseTable`]: `i + (W−2)·512 − 1024·m` (the kernel at
/// `|index|/1024`, negated for an odd table below zero).
#[inline(always)]
pub(crate) const fn phase_entry<const W: usize>(i: usize, m: usize) -> i64 {
    let centre = (W as i64 - 2) * (TABLE_RESOLUTION as i64 / 2);
    i as i64 + centre - (m * TABLE_RESOLUTION) as i64
}

/// The rows of a width-`W` phase table, float or fixed point: row `i`
/// holds the weights `entry(i, m)` and the differences
/// `entry(i + 1, m) − entry(i, m)`. Each entry is read once: row `i + 1`'s
/// weight is row `i`'s next.
#[inline]
pub(crate) fn fill_rows<E: Copy + core::ops::Sub<Output = E>, const W: usize>(
    rows: &mut [[[E; W]; 2]],
    entry: impl Fn(usize, usize) -> E,
) {
    for m in 0..W {
        let mut w0 = entry(0, m);
        for (i, [weights, differences]) in rows.iter_mut().enumerate() {
            let w1 = entry(i + 1, m);
            weights[m] = w0;
            differences[m] = w1 - w0;
            w0 = w1;
        }
    }
}

/// One in the 32.32 fixed point of [`PhaseTable::fixed_position`].
const FIXED_ONE: f64 = 4_294_967_296.0;

/// The kernel derivative `k'` tabulated like [`KernelTable`] (odd: the table
/// holds `k'(|t|)` and [`DerivativeTable::eval`] restores the sign). Built
/// only for scenes that need `∇H` (linear depth cueing, paper eq. 5).
///
/// # Accuracy
/// As [`KernelTable`], with `k'''` in place of `k''`: `Δ²/8·max|k'''|`,
/// `Δ = 1/1024`.
#[derive(Clone, Debug)]
pub struct DerivativeTable<T> {
    filter: Filter,
    samples: Samples<T>,
}

impl<T: Real> DerivativeTable<T> {
    /// Tabulate `filter`'s kernel derivative.
    ///
    /// # Errors
    /// [`Error::NoKernelDerivative`] for nearest neighbour.
    pub fn new(filter: Filter) -> Result<Self> {
        if filter.kind == FilterKind::Nearest {
            return Err(Error::NoKernelDerivative);
        }
        let samples = Samples::tabulate(&filter, |t| filter.kernel_derivative(t));
        Ok(Self { filter, samples })
    }

    /// Entries a table for `filter` holds: `W·1024/2 + 1`, the samples
    /// `k'(i/1024)` for `i = 0 ..= W·512` (as [`KernelTable::len_for`]).
    pub const fn len_for(filter: &Filter) -> usize {
        Samples::<T>::len_for(filter)
    }

    /// Rebuild a table from the values [`DerivativeTable::values`] returned
    /// for the same filter, e.g. a table in flash generated at build time,
    /// so a target without fast f64 never evaluates the Bessel series. The
    /// result equals `DerivativeTable::new(filter)` bit for bit when
    /// `values` came from it.
    ///
    /// # Errors
    /// [`Error::NoKernelDerivative`] for nearest neighbour (as
    /// [`DerivativeTable::new`]); `values.len()` other than
    /// [`DerivativeTable::len_for`]`(&filter)`; a NaN or infinite entry
    /// (named by its index).
    pub fn from_values(filter: Filter, values: &[T]) -> Result<Self> {
        if filter.kind == FilterKind::Nearest {
            return Err(Error::NoKernelDerivative);
        }
        let samples = Samples::from_values("kernel derivative table", &filter, values)?;
        Ok(Self { filter, samples })
    }

    /// The tabulated samples `k'(i/1024)`, `i = 0 ..= W·512`.
    pub fn values(&self) -> &[T] {
        self.samples.values()
    }

    /// The filter whose derivative is tabulated.
    pub fn filter(&self) -> &Filter {
        &self.filter
    }

    /// `k'(t)` for `|t| ≤ W/2` (0 beyond; the derivative is odd).
    #[inline(always)]
    pub fn eval(&self, t: T) -> T {
        if t < T::ZERO {
            -self.samples.lerp(-t)
        } else {
            self.samples.lerp(t)
        }
    }

    /// Derivative weights `k'(q − j0 − m)`, `m = 0 … W−1`, at the same taps
    /// as [`KernelTable::taps`]; returns `j0`.
    #[inline(always)]
    pub fn taps(&self, q: T, weights: &mut [T; MAX_WIDTH]) -> i64 {
        tap_weights(q, &mut weights[..self.filter.width()], |d| self.eval(d))
    }

    /// [`DerivativeTable::taps`] for a width known at compile time.
    #[inline(always)]
    pub fn taps_fixed<const W: usize>(&self, q: T, weights: &mut [T; W]) -> i64 {
        tap_weights(q, weights, |d| self.eval(d))
    }
}
