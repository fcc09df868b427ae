//! Interpolation filters for slice extraction and their spatial responses.
//!
//! A filter is a separable kernel `k(t)` in spectrum index units, normalized
//! to `k(0) = 1`, with support `|t| < W/2` for width `W`. Its spatial
//! response is `ĥ(ν) = ∫ k(t) e^{−i2πνt} dt` at `ν = x/N` cycles per voxel;
//! the volume is premultiplied by `1/ĥ(x/N)` per axis (paper §2, fig. 2),
//! so that the slice's interpolation returns the unattenuated spectrum.
//!
//! Kernels are read from a table ([`KernelTable`]) during extraction, so no
//! transcendental function runs per tap.

use crate::error::{Error, Result};
use crate::real::Real;
use crate::spectrum::VoxelSource;

/// The interpolation filters offered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilterKind {
    /// Nearest neighbour, 1³ taps.
    Nearest,
    /// Trilinear, 2³ taps.
    Linear,
    /// Keys cubic convolution with a = −½, 4³ taps.
    Cubic,
    /// Kaiser–Bessel of width 3 (the paper's 3³ size).
    Kb3,
    /// Kaiser–Bessel of width 4.
    Kb4,
    /// Kaiser–Bessel of width 5.
    Kb5,
    /// Kaiser–Bessel of width 6.
    Kb6,
}

impl FilterKind {
    /// Every filter, cheapest first.
    pub const ALL: [FilterKind; 7] = [
        FilterKind::Nearest,
        FilterKind::Linear,
        FilterKind::Cubic,
        FilterKind::Kb3,
        FilterKind::Kb4,
        FilterKind::Kb5,
        FilterKind::Kb6,
    ];

    /// Taps per axis.
    pub const fn width(self) -> usize {
        match self {
            FilterKind::Nearest => 1,
            FilterKind::Linear => 2,
            FilterKind::Kb3 => 3,
            FilterKind::Cubic | FilterKind::Kb4 => 4,
            FilterKind::Kb5 => 5,
            FilterKind::Kb6 => 6,
        }
    }

    /// `true` for the Kaiser–Bessel kernels, which have a shape parameter β.
    pub const fn is_kaiser_bessel(self) -> bool {
        matches!(
            self,
            FilterKind::Kb3 | FilterKind::Kb4 | FilterKind::Kb5 | FilterKind::Kb6
        )
    }

    /// Command-line name: `nearest`, `linear`, `cubic`, `kb3` … `kb6`.
    pub const fn name(self) -> &'static str {
        match self {
            FilterKind::Nearest => "nearest",
            FilterKind::Linear => "linear",
            FilterKind::Cubic => "cubic",
            FilterKind::Kb3 => "kb3",
            FilterKind::Kb4 => "kb4",
            FilterKind::Kb5 => "kb5",
            FilterKind::Kb6 => "kb6",
        }
    }

    /// Parse a command-line name; `None` if unknown.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// Largest filter width supported.
pub const MAX_WIDTH: usize = 6;

/// A filter together with the oversampling factor it is designed for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Filter {
    kind: FilterKind,
    oversample: u32,
    beta: f64,
}

impl Filter {
    /// The filter `kind` for oversampling factor 1 or 2.
    ///
    /// Kaiser–Bessel shape parameters follow Beatty, Nishimura & Pauly
    /// (IEEE TMI 2005, eq. 5): `β = π·√((W/σ)²(σ − ½)² − 0.8)`.
    ///
    /// # Errors
    /// An oversampling factor other than 1 or 2.
    pub fn new(kind: FilterKind, oversample: u32) -> Result<Self> {
        Self::with_design_oversampling(kind, oversample, oversample as f64)
    }

    /// The filter `kind` for a grid oversampled by `oversample` (1 or 2),
    /// with the Kaiser–Bessel shape designed for the *effective*
    /// oversampling `design` of the data: `σ_eff = n / (2·r)` when the data
    /// lies within `r` voxels of the centre on a grid of side `n`. Data that
    /// fills only the middle of the grid tolerates a sharper kernel, and
    /// Beatty's formula at `σ_eff` gives the β that minimizes aliasing for
    /// that extent. `design` is clamped to `[oversample, 4]`.
    ///
    /// # Errors
    /// An oversampling factor other than 1 or 2, or a non-finite `design`.
    pub fn with_design_oversampling(
        kind: FilterKind,
        oversample: u32,
        design: f64,
    ) -> Result<Self> {
        if oversample != 1 && oversample != 2 {
            return Err(Error::UnsupportedOversampling { factor: oversample });
        }
        if !design.is_finite() {
            return Err(Error::UnsupportedOversampling { factor: oversample });
        }
        let w = kind.width() as f64;
        let s = design.clamp(oversample as f64, 4.0);
        // β only shapes the Kaiser–Bessel kernels; 0 elsewhere keeps filters comparable.
        let beta = if kind.is_kaiser_bessel() {
            core::f64::consts::PI * libm::sqrt((w / s) * (w / s) * (s - 0.5) * (s - 0.5) - 0.8)
        } else {
            0.0
        };
        Ok(Self {
            kind,
            oversample,
            beta,
        })
    }

    /// Rebuild a filter from stored parts (e.g. next to a spectrum in flash).
    ///
    /// # Errors
    /// An oversampling factor other than 1 or 2, or a non-finite β.
    pub fn from_parts(kind: FilterKind, oversample: u32, beta: f64) -> Result<Self> {
        if (oversample != 1 && oversample != 2) || !beta.is_finite() {
            return Err(Error::UnsupportedOversampling { factor: oversample });
        }
        Ok(Self {
            kind,
            oversample,
            beta,
        })
    }

    /// The filter `kind` whose Kaiser–Bessel β best suits `volume`: among
    /// Beatty's β for design oversamplings `σ_d` from `oversample` to 4
    /// (17 steps, geometric), the one minimizing the predicted aliasing
    /// error `Σ_a Σ_x |f|²·A(x_a/n)`, where `A(ν)` is
    /// [`Filter::aliasing_power`] and `x_a` the signed distance from the
    /// centre along axis `a` on the padded grid of side `n`. A volume that
    /// fills its grid keeps `σ_d = oversample`; compact data gets a sharper
    /// kernel. Filters without a shape parameter are returned unchanged.
    /// Returns the filter and the chosen `σ_d`.
    ///
    /// # Errors
    /// An unsupported oversampling, an empty volume, or a NaN or infinite
    /// voxel (named).
    pub fn fit<V: VoxelSource>(
        kind: FilterKind,
        oversample: u32,
        volume: &V,
    ) -> Result<(Self, f64)> {
        let base = Self::new(kind, oversample)?;
        if !kind.is_kaiser_bessel() {
            return Ok((base, oversample as f64));
        }
        let dims = volume.dims();
        let n = crate::spectrum::padded_size(dims, oversample)?;
        let energy = axis_energy_profile(volume, n)?;
        let mut best = (base, oversample as f64, f64::INFINITY);
        for step in 0..=16 {
            let design = oversample as f64 * libm::pow(4.0 / oversample as f64, step as f64 / 16.0);
            let f = Self::with_design_oversampling(kind, oversample, design)?;
            let mut cost = 0.0;
            for (b, e) in energy.iter().enumerate() {
                if *e > 0.0 {
                    let nu = (b as f64 + 0.5) / (2.0 * PROFILE_BINS as f64);
                    cost += e * f.aliasing_power(nu);
                }
            }
            if cost < best.2 {
                best = (f, design, cost);
            }
        }
        Ok((best.0, best.1))
    }

    /// Predicted mean-square relative error of one axis of interpolation
    /// for data at `ν` cycles per voxel: `|Σ_m k(d−j_m)e^{−i2π(j_m−d)ν}/ĥ(ν) − 1|²`
    /// averaged over 16 fractional sample offsets `d`. By Poisson summation
    /// this is the power of the replicas `ĥ(ν+p)`, `p ≠ 0`, relative to the
    /// premultiplied main term.
    pub fn aliasing_power(&self, nu: f64) -> f64 {
        let w = self.width();
        let h = self.response(nu);
        let mut sum = 0.0;
        for di in 0..16 {
            let d = di as f64 / 16.0;
            let j0 = libm::floor(d - w as f64 / 2.0) + 1.0;
            let (mut re, mut im) = (0.0, 0.0);
            for m in 0..w {
                let j = j0 + m as f64;
                let k = self.kernel(d - j);
                let ph = -2.0 * core::f64::consts::PI * (j - d) * nu;
                re += k * libm::cos(ph);
                im += k * libm::sin(ph);
            }
            let (er, ei) = (re / h - 1.0, im / h);
            sum += er * er + ei * ei;
        }
        sum / 16.0
    }

    /// Which kernel.
    pub fn kind(&self) -> FilterKind {
        self.kind
    }

    /// Oversampling factor it was designed for.
    pub fn oversample(&self) -> u32 {
        self.oversample
    }

    /// Taps per axis.
    pub fn width(&self) -> usize {
        self.kind.width()
    }

    /// Kaiser–Bessel shape parameter β (meaningful for `kb*` only).
    pub fn beta(&self) -> f64 {
        self.beta
    }

    /// Kernel value at distance `t` (index units), exact, in f64.
    pub fn kernel(&self, t: f64) -> f64 {
        let a = libm::fabs(t);
        let half = self.width() as f64 / 2.0;
        match self.kind {
            FilterKind::Nearest => {
                // Half-open support (−½, ½] matches the tap selection.
                if t > -0.5 && t <= 0.5 {
                    1.0
                } else {
                    0.0
                }
            }
            FilterKind::Linear => {
                if a < 1.0 {
                    1.0 - a
                } else {
                    0.0
                }
            }
            FilterKind::Cubic => keys_cubic(a),
            _ => {
                if a > half {
                    0.0
                } else {
                    let r = 2.0 * a / self.width() as f64;
                    bessel_i0(self.beta * libm::sqrt(1.0 - r * r)) / bessel_i0(self.beta)
                }
            }
        }
    }

    /// Kernel derivative `k'(t)` (index units), exact, in f64: the weights
    /// of `∇H` for linear depth cueing (paper eq. 5).
    ///
    /// Kaiser–Bessel: with `r = 2|t|/W`, `s = √(1 − r²)`,
    /// `k'(t) = −sign(t)·β²·(2r/W)·[I1(βs)/(βs)] / I0(β)`; Keys cubic and
    /// linear: the derivatives of their polynomial pieces (0 at the linear
    /// kernel's kink at `t = 0`). Nearest neighbour has no derivative worth
    /// the name (two impulses) and returns 0; scenes refuse it.
    pub fn kernel_derivative(&self, t: f64) -> f64 {
        let a = libm::fabs(t);
        let sign = if t < 0.0 { -1.0 } else { 1.0 };
        let half = self.width() as f64 / 2.0;
        let magnitude = match self.kind {
            FilterKind::Nearest => 0.0,
            FilterKind::Linear => {
                if a > 0.0 && a < 1.0 {
                    -1.0
                } else {
                    0.0
                }
            }
            FilterKind::Cubic => keys_cubic_derivative(a),
            _ => {
                if a > half {
                    0.0
                } else {
                    let w = self.width() as f64;
                    let r = 2.0 * a / w;
                    let x = self.beta * libm::sqrt(1.0 - r * r);
                    -self.beta * self.beta * (2.0 * r / w) * bessel_i1_over_x(x)
                        / bessel_i0(self.beta)
                }
            }
        };
        sign * magnitude
    }

    /// Spatial response `ĥ(ν) = ∫ k(t) cos(2πνt) dt` at `ν` cycles per voxel.
    ///
    /// Closed forms: `sinc(ν)` for nearest, `sinc²(ν)` for linear, and for
    /// Kaiser–Bessel `W·sinh(z)/z / I0(β)` with `z = √(β² − (πWν)²)`
    /// (`sin(|z|)/|z|` once `z²` turns negative). Keys cubic is integrated
    /// numerically (16-point Gauss–Legendre on each unit piece, where the
    /// kernel is a cubic polynomial: error below 1e-14).
    pub fn response(&self, nu: f64) -> f64 {
        let pi = core::f64::consts::PI;
        match self.kind {
            FilterKind::Nearest => sinc(pi * nu),
            FilterKind::Linear => {
                let s = sinc(pi * nu);
                s * s
            }
            FilterKind::Cubic => {
                let mut sum = 0.0;
                for piece in 0..2 {
                    sum += gauss_legendre_16(piece as f64, piece as f64 + 1.0, |t| {
                        keys_cubic(t) * libm::cos(2.0 * pi * nu * t)
                    });
                }
                2.0 * sum
            }
            _ => {
                let w = self.width() as f64;
                let z2 = self.beta * self.beta - (pi * w * nu) * (pi * w * nu);
                let ratio = if z2 > 1e-12 {
                    let z = libm::sqrt(z2);
                    libm::sinh(z) / z
                } else if z2 < -1e-12 {
                    let z = libm::sqrt(-z2);
                    libm::sin(z) / z
                } else {
                    1.0
                };
                w * ratio / bessel_i0(self.beta)
            }
        }
    }
}

const PROFILE_BINS: usize = 32;

/// Energy `Σ|f|²` of the volume binned by `|x_a|/n ∈ [0, ½]` on each axis,
/// `x_a` being the signed distance from the transform origin `⌊n_a/2⌋`.
fn axis_energy_profile<V: VoxelSource>(volume: &V, n: usize) -> Result<[f64; PROFILE_BINS]> {
    let dims = volume.dims();
    let mut energy = [0.0f64; PROFILE_BINS];
    let bin = |i: usize, axis: usize| {
        let x = (i as i64 - (dims[axis] / 2) as i64).unsigned_abs() as usize;
        (x * 2 * PROFILE_BINS / n).min(PROFILE_BINS - 1)
    };
    for k in 0..dims[2] {
        let bz = bin(k, 2);
        for j in 0..dims[1] {
            let by = bin(j, 1);
            for i in 0..dims[0] {
                let v = volume.voxel(i, j, k);
                if !v.is_finite() {
                    return Err(Error::NonFiniteVoxel {
                        index: [i, j, k],
                        value: v,
                    });
                }
                let e = v * v;
                energy[bin(i, 0)] += e;
                energy[by] += e;
                energy[bz] += e;
            }
        }
    }
    Ok(energy)
}

fn sinc(x: f64) -> f64 {
    if libm::fabs(x) < 1e-8 {
        1.0
    } else {
        libm::sin(x) / x
    }
}

fn keys_cubic_derivative(a: f64) -> f64 {
    const A: f64 = -0.5;
    if a <= 1.0 {
        (3.0 * (A + 2.0) * a - 2.0 * (A + 3.0)) * a
    } else if a < 2.0 {
        (3.0 * A * a - 10.0 * A) * a + 8.0 * A
    } else {
        0.0
    }
}

fn keys_cubic(a: f64) -> f64 {
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
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    while term > 1e-17 * sum && k < 500.0 {
        term *= q / (k * k);
        sum += term;
        k += 1.0;
    }
    sum
}

/// `I1(x)/x` by its power series `½·Σ (x²/4)^k / (k!·(k+1)!)`, finite at 0.
pub fn bessel_i1_over_x(x: f64) -> f64 {
    let q = x * x / 4.0;
    let mut term = 0.5;
    let mut sum = 0.5;
    let mut k = 1.0;
    while term > 1e-17 * sum && k < 500.0 {
        term *= q / (k * (k + 1.0));
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
pub(crate) struct PhaseTable<T, const W: usize> {
    /// Row `i`: the weights at phase `i/1024` and their differences to
    /// row `i + 1` (the same `p1 − p0` the interpolation would compute),
    /// so that a weight is one multiply-add.
    rows: [[[T; W]; 2]; TABLE_RESOLUTION],
}

impl<T: Real, const W: usize> PhaseTable<T, W> {
    /// An all-zero table, to be [`PhaseTable::fill`]ed in place (the table
    /// is up to 48 KiB in f32: built where it stays, it is not copied).
    pub(crate) fn zeroed() -> Self {
        Self {
            rows: [[[T::ZERO; W]; 2]; TABLE_RESOLUTION],
        }
    }

    /// Gather the rows from `kernel`, whose width must be `W`.
    ///
    /// # Errors
    /// A kernel of another width ([`Error::LengthMismatch`]).
    pub(crate) fn fill(&mut self, kernel: &KernelTable<T>) -> Result<()> {
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
        let centre = (W as i64 - 2) * (TABLE_RESOLUTION as i64 / 2);
        let entry = |i: usize, m: usize| {
            let signed = i as i64 + centre - (m * TABLE_RESOLUTION) as i64;
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
        // Each entry is read once: row `i + 1`'s weight is row `i`'s next.
        for m in 0..W {
            let mut w0 = entry(0, m);
            for (i, [weights, differences]) in self.rows.iter_mut().enumerate() {
                let w1 = entry(i + 1, m);
                weights[m] = w0;
                differences[m] = w1 - w0;
                w0 = w1;
            }
        }
    }

    /// The position `Y = 1024·q − 512·W` of a sample at `q` in 32.32 fixed
    /// point, `⌊Y·2^32⌋`: the first tap is `j0 = ⌊q − W/2⌋ + 1 = ⌊F/1024⌋ + 1`
    /// and the phase row `F mod 1024` for `F = ⌊Y⌋`, found by one truncation
    /// and one correction below zero (slice points lie inside the Nyquist
    /// cube, so `|Y| ≤ 512·(n + W)` is far inside the i32 range); the fraction is `Y − F`
    /// (exact in `T`) times `2^32`, truncated. Rows of the slice start from
    /// this and add [`PhaseTable::fixed_step`] per pixel.
    #[inline(always)]
    pub(crate) fn fixed_position(q: T) -> i64 {
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
    pub(crate) fn fixed_step(r: T) -> i64 {
        (r * T::from_f64(FIXED_ONE * TABLE_RESOLUTION as f64) + T::HALF).floor_i64()
    }

    /// Taps of the sample at fixed-point position `y`
    /// ([`PhaseTable::fixed_position`]): the first tap's index `j0` and the
    /// weights `k(q − j0 − m)`, `m = 0 … W−1`, interpolated between phase
    /// rows `F mod 1024` and the next by the 32-bit fraction.
    #[inline(always)]
    pub(crate) fn taps_fixed_point(&self, y: i64) -> (i32, [T; W]) {
        let floor = (y >> 32) as i32;
        let f = T::from_usize(y as u32 as usize) * T::from_f64(1.0 / FIXED_ONE);
        let row = (floor & (TABLE_RESOLUTION as i32 - 1)) as usize;
        let [p0, dp] = &self.rows[row];
        let weights = core::array::from_fn(|m| p0[m] + f * dp[m]);
        ((floor >> TABLE_RESOLUTION.trailing_zeros()) + 1, weights)
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
