//! Adaptive filtering (paper §4, eq. 15–16): a cheaper filter wherever the
//! spectrum is weak, with the error bounded by Rayleigh's theorem.
//!
//! # The bound
//! Split the spectrum `F = F₁ + F₂`, `F₂` the samples filtered by the
//! smaller filter `H₂` instead of `H₁`. The image changes by
//! `f₂·(h₂ − h₁)/h₁` in the spatial domain (the volume was premultiplied by
//! `1/h₁`), so by Rayleigh's theorem its energy is at most
//! `h_d² · Σ|F₂|²` with `h_d = max |h₂/h₁ − 1|` over the volume's extent
//! (eq. 16; [`response_difference`] computes it for the actual pair of
//! filters, as the product of the per-axis extremes). Relative to the
//! spectrum's energy `Σ|F|²`, the tolerance `10^(−dB/10)` is met when
//! `h_d² · Σ_{|F|≤τ}|F|² ≤ 10^(−dB/10) · Σ|F|²`; [`threshold_for`] finds the
//! largest such `τ` from a histogram of magnitudes (⅛-octave bins, counted
//! whole, so the chosen `τ` errs on the safe side). A slice samples the
//! spectrum's weak and strong parts alike, so the same ratio bounds each
//! view's image; the tests check it view by view.
//!
//! # The marks
//! A sample is marked when it and every sample within Chebyshev distance
//! `⌈W/2⌉` (the large filter's half support, circularly) are below `τ`:
//! the paper's conservative marking. Extraction then tests only the sample
//! nearest the slice point. Marks are a bitset: `n³` bits, `n³/8` bytes
//! (256 KiB at 128³, 1/16 of an f16 spectrum).

use crate::dht::signed_index;
use crate::error::{mismatch, require_len, Error, Result};
use crate::filter::{Filter, KernelTable, MAX_WIDTH};
use crate::geometry::Frame;
use crate::num::{Real, Sample};
use crate::spectrum::{CubeSide, Spectrum};

/// `u32` words of a bitset over `n³` samples.
pub const fn marks_words(n: usize) -> usize {
    (n * n * n).div_ceil(32)
}

/// A bitset over the `n³` spectrum samples: bit `i` set means sample `i`
/// (x fastest) may use the smaller filter.
#[derive(Clone, Copy, Debug)]
pub struct Marks<'a> {
    words: &'a [u32],
    n: usize,
}

impl<'a> Marks<'a> {
    /// Wrap `words` (at least [`marks_words`]`(n)`) for side `n`.
    ///
    /// # Errors
    /// `n` not a power of two, or too few words.
    pub fn new(words: &'a [u32], n: usize) -> Result<Self> {
        crate::error::require_pow2("marks side", n)?;
        require_len("marks", marks_words(n), words.len())?;
        Ok(Self { words, n })
    }

    /// Side of the cube.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Whether sample `i` is marked.
    #[inline(always)]
    pub fn get(&self, i: usize) -> bool {
        self.words[i >> 5] >> (i & 31) & 1 == 1
    }

    /// Marked samples.
    pub fn count(&self) -> usize {
        let total = self.n * self.n * self.n;
        (0..total).filter(|&i| self.get(i)).count()
    }
}

/// `h_d = max |g·ĥ_small/ĥ_large − 1|` over the volume's extent, with the
/// small filter's gain `g = ĥ_large(0)/ĥ_small(0)` (extraction applies it,
/// so that DC passes unchanged): the
/// transform-origin-relative positions `x_a ∈ [−⌊d_a/2⌋, d_a − 1 − ⌊d_a/2⌋]`
/// at frequency `x_a/n`. The 3D ratio is the product of per-axis ratios,
/// all positive here, so its extremes are the products of the per-axis
/// extremes.
///
/// # Errors
/// A response that vanishes inside the extent (the small filter cannot
/// stand in for the large one there).
pub fn response_difference(
    large: &Filter,
    small: &Filter,
    dims: [usize; 3],
    n: usize,
) -> Result<f64> {
    let (mut lo, mut hi) = (1.0f64, 1.0f64);
    for &d in dims.iter() {
        let first = -((d / 2) as i64);
        let last = d as i64 - 1 - (d / 2) as i64;
        let (mut a_lo, mut a_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for x in first..=last {
            let nu = x as f64 / n as f64;
            let (hl, hs) = (large.response(nu), small.response(nu));
            if hl.is_nan() || hs.is_nan() || hl <= 0.0 || hs <= 0.0 {
                return Err(Error::InvalidSceneValue {
                    what: "filter response inside the volume (adaptive filtering)",
                    index: x.unsigned_abs() as usize,
                    value: hs.min(hl),
                });
            }
            let r = hs / hl * (large.response(0.0) / small.response(0.0));
            a_lo = a_lo.min(r);
            a_hi = a_hi.max(r);
        }
        lo *= a_lo;
        hi *= a_hi;
    }
    Ok((1.0 - lo).abs().max((hi - 1.0).abs()))
}

/// ⅛-octave magnitude bins from 2^−160 to 2^160.
const BINS_PER_OCTAVE: i32 = 8;
const LOW_OCTAVE: i32 = -160;
const BINS: usize = (2 * 160 * BINS_PER_OCTAVE) as usize;

fn bin_of(magnitude: f64) -> usize {
    if magnitude.is_nan() || magnitude <= 0.0 {
        return 0;
    }
    let b = libm::floor(libm::log2(magnitude) * BINS_PER_OCTAVE as f64) as i64
        - (LOW_OCTAVE * BINS_PER_OCTAVE) as i64;
    b.clamp(0, BINS as i64 - 1) as usize
}

/// Lower edge of bin `b`.
fn bin_floor(b: usize) -> f64 {
    libm::exp2((b as i32 + LOW_OCTAVE * BINS_PER_OCTAVE) as f64 / BINS_PER_OCTAVE as f64)
}

/// The largest magnitude threshold `τ` whose samples' energy, times `h_d²`,
/// stays within `budget` (a fraction, e.g. `10^(−dB/10)`) of the total
/// energy of the `len` samples `value(i)`. Returns `0` if no bin fits (no
/// sample may use the small filter).
pub fn threshold_for(len: usize, value: impl Fn(usize) -> f64, h_d: f64, budget: f64) -> f64 {
    let mut energy = [0.0f64; BINS];
    let mut total = 0.0;
    for i in 0..len {
        let v = value(i);
        let e = v * v;
        energy[bin_of(libm::fabs(v))] += e;
        total += e;
    }
    let allowed = budget * total / (h_d * h_d).max(f64::MIN_POSITIVE);
    let mut cumulative = 0.0;
    let mut tau = 0.0;
    for (b, e) in energy.iter().enumerate() {
        cumulative += e;
        if cumulative > allowed {
            break;
        }
        // Every sample in bins 0..=b is below the next bin's floor.
        tau = bin_floor(b + 1);
    }
    tau
}

/// Mark the samples of a cube of side `n` (values `value(i)`, x fastest)
/// that are below `tau` together with every sample within Chebyshev
/// distance `radius`, circularly. `words` needs [`marks_words`]`(n)`,
/// `line` `n` bools of scratch.
///
/// # Errors
/// `n` not a power of two, short buffers.
pub fn mark(
    n: usize,
    value: impl Fn(usize) -> f64,
    tau: f64,
    radius: usize,
    words: &mut [u32],
    line: &mut [bool],
) -> Result<usize> {
    crate::error::require_pow2("marks side", n)?;
    require_len("marks", marks_words(n), words.len())?;
    require_len("marks line scratch", n, line.len())?;
    let total = n * n * n;
    let words = &mut words[..marks_words(n)];
    words.fill(0);
    for i in 0..total {
        if libm::fabs(value(i)) < tau {
            words[i >> 5] |= 1 << (i & 31);
        }
    }
    // Separable erosion: a sample stays marked if all samples within
    // `radius` along x, then y, then z are marked.
    let r = radius.min(n / 2);
    let stride = [1, n, n * n];
    for s in stride {
        for base in 0..total {
            // Visit each line once, from its first sample.
            if (base / s) % n != 0 {
                continue;
            }
            for (k, slot) in line[..n].iter_mut().enumerate() {
                let i = base + k * s;
                *slot = words[i >> 5] >> (i & 31) & 1 == 1;
            }
            for k in 0..n {
                let keep = (0..=2 * r).all(|o| line[(k + n + o - r) % n]);
                let i = base + k * s;
                if keep {
                    words[i >> 5] |= 1 << (i & 31);
                } else {
                    words[i >> 5] &= !(1 << (i & 31));
                }
            }
        }
    }
    Ok((0..total)
        .filter(|&i| words[i >> 5] >> (i & 31) & 1 == 1)
        .count())
}

/// One cheaper filter of an adaptive chain: its kernel, the marks of the
/// samples it may stand in for, and its DC gain correction
/// `ĥ_large(0)/ĥ_small(0)`.
#[derive(Clone, Copy, Debug)]
pub struct AdaptiveLevel<'k, 'm, T> {
    /// The cheaper kernel.
    pub kernel: &'k KernelTable<T>,
    /// Samples where it may be used.
    pub marks: Marks<'m>,
    /// Gain applied to its output. Gain 0 makes the level the zero
    /// filter: its points are 0 and read no taps (the kernel is unused).
    pub gain: T,
}

/// What an adaptive extraction did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AdaptiveStats {
    /// Slice samples inside the Nyquist cube (the others are zero).
    pub samples: u64,
    /// Samples per filter: index 0 the large filter, then the levels in
    /// order.
    pub per_filter: [u64; 1 + MAX_LEVELS],
    /// Filter taps read.
    pub taps: u64,
    /// Filter taps the large filter alone would have read.
    pub full_taps: u64,
}

/// Most cheaper filters in a chain.
pub const MAX_LEVELS: usize = 2;

/// [`crate::slice::extract_slice`] with adaptive filtering: at each slice
/// point, the spectrum sample nearest to it is looked up in each level's
/// marks (cheapest first); the first level that marks it filters the point,
/// otherwise the large `kernel` does.
///
/// # Errors
/// More than [`MAX_LEVELS`] levels, marks of another side than the
/// spectrum's, a kernel for another filter than the spectrum's, or a short
/// grid.
pub fn extract_slice_adaptive<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    kernel: &KernelTable<T>,
    levels: &[AdaptiveLevel<'_, '_, T>],
    frame: &Frame,
    grid: &mut [T],
) -> Result<AdaptiveStats> {
    let n = spec.n();
    if levels.len() > MAX_LEVELS {
        return Err(Error::TooMany {
            what: "adaptive filter levels",
            given: levels.len(),
            capacity: MAX_LEVELS,
        });
    }
    if kernel.filter() != spec.filter() {
        return Err(Error::FilterMismatch);
    }
    for level in levels {
        if level.marks.n() != n {
            return Err(mismatch("adaptive marks side", n, level.marks.n()));
        }
    }
    require_len("slice grid", n * n, grid.len())?;
    let r = frame.right.map(T::from_f64);
    let u = frame.up.map(T::from_f64);
    let nyquist = T::from_usize(n) * T::HALF;
    let mask = n - 1;
    let mut stats = AdaptiveStats::default();
    let w_large = kernel.filter().width() as u64;
    for (iy, row) in grid[..n * n].chunks_exact_mut(n).enumerate() {
        let ky = T::from_i32(signed_index(iy, n) as i32);
        for (ix, g) in row.iter_mut().enumerate() {
            let kx = T::from_i32(signed_index(ix, n) as i32);
            let q: [T; 3] = core::array::from_fn(|a| kx * r[a] + ky * u[a]);
            if q.iter().any(|&c| c > nyquist || -c > nyquist) {
                *g = T::ZERO;
                continue;
            }
            stats.samples += 1;
            stats.full_taps += w_large * w_large * w_large;
            let nearest: [usize; 3] =
                core::array::from_fn(|a| (q[a] + T::HALF).floor_i64() as usize & mask);
            let index = nearest[0] + n * (nearest[1] + n * nearest[2]);
            let (table, gain, slot) = levels
                .iter()
                .enumerate()
                .find(|(_, l)| l.marks.get(index))
                .map_or((kernel, T::ONE, 0), |(i, l)| (l.kernel, l.gain, i + 1));
            stats.per_filter[slot] += 1;
            // A level of gain 0 is the zero filter: it reads nothing.
            if gain == T::ZERO {
                *g = T::ZERO;
                continue;
            }
            let w = table.filter().width();
            stats.taps += (w * w * w) as u64;
            *g = gain * interpolate(spec, table, q, mask);
        }
    }
    Ok(stats)
}

/// The separable interpolation of `spec` at `q` with `table`'s kernel.
#[inline(always)]
fn interpolate<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    table: &KernelTable<T>,
    q: [T; 3],
    mask: usize,
) -> T {
    let n = spec.n();
    let w = table.filter().width();
    let mut wts = [[T::ZERO; MAX_WIDTH]; 3];
    let mut taps = [[0usize; MAX_WIDTH]; 3];
    for a in 0..3 {
        let first = table.taps(q[a], &mut wts[a]);
        for (t, slot) in taps[a][..w].iter_mut().enumerate() {
            *slot = (first + t as i64) as usize & mask;
        }
    }
    let mut acc = T::ZERO;
    for c in 0..w {
        let z = taps[2][c] * n * n;
        let mut acc_y = T::ZERO;
        for b in 0..w {
            let line = z + taps[1][b] * n;
            acc_y += wts[1][b] * spec.line_taps(line, &taps[0][..w], &wts[0][..w]);
        }
        acc += wts[2][c] * acc_y;
    }
    acc
}
