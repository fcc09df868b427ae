//! The filters offered and their design: kernel, spatial response, and the
//! choice of a filter for a volume.

use super::special::{
    bessel_i0, bessel_i1_over_x, gauss_legendre_16, keys_cubic, keys_cubic_derivative, sinc,
};
use crate::error::{Error, Result};
use crate::volume::{GridOversampling, VoxelSource};

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
    pub(super) kind: FilterKind,
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
        let n = crate::volume::padded_size(volume.dims(), oversample)?;
        Self::fit_on(kind, oversample, oversample as f64, volume, n)
    }

    /// The filter `kind` for a grid oversampled by `grid`: integer
    /// oversampling [`GridOversampling::integer`], the Kaiser–Bessel shape
    /// designed for `σ = grid.factor()` (Beatty's β, as
    /// [`Filter::with_design_oversampling`]).
    ///
    /// # Errors
    /// None in practice (the factors are all supported).
    pub fn for_grid(kind: FilterKind, grid: GridOversampling) -> Result<Self> {
        Self::with_design_oversampling(kind, grid.integer(), grid.factor())
    }

    /// [`Filter::fit`] on the grid of `grid`: design oversamplings from
    /// `σ = grid.factor()` to 4, the energy profile taken on the cube of
    /// side [`GridOversampling::side`]. The same as [`Filter::fit`] for
    /// σ = 1 and 2.
    ///
    /// # Errors
    /// As [`Filter::fit`].
    pub fn fit_grid<V: VoxelSource>(
        kind: FilterKind,
        grid: GridOversampling,
        volume: &V,
    ) -> Result<(Self, f64)> {
        let n = grid.side(volume.dims())?;
        Self::fit_on(kind, grid.integer(), grid.factor(), volume, n)
    }

    /// [`Filter::fit`] with designs from `low` to 4 on a cube of side `n`.
    fn fit_on<V: VoxelSource>(
        kind: FilterKind,
        oversample: u32,
        low: f64,
        volume: &V,
        n: usize,
    ) -> Result<(Self, f64)> {
        if !kind.is_kaiser_bessel() {
            return Ok((Self::with_design_oversampling(kind, oversample, low)?, low));
        }
        Self::fit_profile(kind, oversample, low, &EnergyProfile::of(volume, n)?)
    }

    /// [`Filter::fit_grid`] from the volume's [`EnergyProfile`] on the
    /// grid's side, made once for every kind fitted on that grid: the same
    /// filter bit for bit.
    ///
    /// # Errors
    /// An unsupported oversampling.
    pub fn fit_grid_profile(
        kind: FilterKind,
        grid: GridOversampling,
        profile: &EnergyProfile,
    ) -> Result<(Self, f64)> {
        Self::fit_profile(kind, grid.integer(), grid.factor(), profile)
    }

    /// The design from `low` to 4 that minimizes the aliasing predicted
    /// on `energy` ([`Filter::fit`]).
    fn fit_profile(
        kind: FilterKind,
        oversample: u32,
        low: f64,
        energy: &EnergyProfile,
    ) -> Result<(Self, f64)> {
        let base = Self::with_design_oversampling(kind, oversample, low)?;
        if !kind.is_kaiser_bessel() {
            return Ok((base, low));
        }
        let mut best = (base, low, f64::INFINITY);
        for step in 0..=16 {
            let design = low * libm::pow(4.0 / low, step as f64 / 16.0);
            let f = Self::with_design_oversampling(kind, oversample, design)?;
            let mut cost = 0.0;
            for (b, e) in energy.0.iter().enumerate() {
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

/// Energy `Σ|f|²` of a volume binned by `|x_a|/n ∈ [0, ½]` on each axis,
/// `x_a` being the signed distance from the transform origin `⌊n_a/2⌋`:
/// what [`Filter::fit`] fits a design to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyProfile([f64; PROFILE_BINS]);

impl EnergyProfile {
    /// The profile of `volume` on the cube of side `n`.
    ///
    /// # Errors
    /// A NaN or infinite voxel (named).
    pub fn of<V: VoxelSource>(volume: &V, n: usize) -> Result<Self> {
        let dims = volume.dims();
        let mut energy = [0.0f64; PROFILE_BINS];
        let bin = |i: usize, axis: usize| {
            let x = (i as i64 - (dims[axis] / 2) as i64).unsigned_abs() as usize;
            (x * 2 * PROFILE_BINS / n).min(PROFILE_BINS - 1)
        };
        // A row's voxels in runs of one x bin (falling to bin 0, then
        // rising: at most 2·PROFILE_BINS runs), the same for every row.
        let mut runs = [(0usize, 0usize); 2 * PROFILE_BINS];
        let mut count = 0;
        for i in 0..dims[0] {
            let b = bin(i, 0);
            match runs[..count].last_mut() {
                Some((last, end)) if *last == b => *end = i + 1,
                _ => {
                    // Never full: bins fall, then rise, so 2·PROFILE_BINS − 1 runs at most.
                    if let Some(run) = runs.get_mut(count) {
                        *run = (b, i + 1);
                        count += 1;
                    }
                }
            }
        }
        for k in 0..dims[2] {
            let bz = bin(k, 2);
            for j in 0..dims[1] {
                let by = bin(j, 1);
                let mut row = 0.0;
                let mut start = 0;
                for &(b, end) in &runs[..count] {
                    // Four partial sums: the adds are not one dependent chain.
                    let (mut a, mut b4, mut c, mut d) = (0.0f64, 0.0, 0.0, 0.0);
                    let mut i = start;
                    while i + 4 <= end {
                        let e = |x| volume.finite_voxel(x, j, k).map(|v| v * v);
                        a += e(i)?;
                        b4 += e(i + 1)?;
                        c += e(i + 2)?;
                        d += e(i + 3)?;
                        i += 4;
                    }
                    for x in i..end {
                        let v = volume.finite_voxel(x, j, k)?;
                        a += v * v;
                    }
                    let run = (a + b4) + (c + d);
                    energy[b] += run;
                    row += run;
                    start = end;
                }
                energy[by] += row;
                energy[bz] += row;
            }
        }
        Ok(Self(energy))
    }
}

#[cfg(test)]
mod tests {
    use super::{EnergyProfile, PROFILE_BINS};
    use crate::volume::VoxelSource;

    /// A deterministic field of mixed signs and magnitudes.
    struct Field([usize; 3]);

    impl VoxelSource for Field {
        fn dims(&self) -> [usize; 3] {
            self.0
        }
        fn voxel(&self, i: usize, j: usize, k: usize) -> f64 {
            let h = (i * 7919 + j * 104_729 + k * 1_299_709) % 1000;
            (h as f64 / 500.0 - 1.0) * (1.0 + i as f64)
        }
    }

    #[test]
    fn the_profile_is_the_voxel_by_voxel_sum_to_rounding() {
        for (dims, n) in [
            ([37, 20, 9], 64),
            ([64, 64, 64], 64),
            ([33, 17, 40], 40),
            ([5, 3, 2], 4),
            ([200, 3, 2], 256),
        ] {
            let field = Field(dims);
            let got = EnergyProfile::of(&field, n).unwrap();
            let bin = |i: usize, axis: usize| {
                let x = (i as i64 - (dims[axis] / 2) as i64).unsigned_abs() as usize;
                (x * 2 * PROFILE_BINS / n).min(PROFILE_BINS - 1)
            };
            let (mut want, mut total) = ([0.0f64; PROFILE_BINS], 0.0);
            for k in 0..dims[2] {
                for j in 0..dims[1] {
                    for i in 0..dims[0] {
                        let v = field.voxel(i, j, k);
                        let e = v * v;
                        want[bin(i, 0)] += e;
                        want[bin(j, 1)] += e;
                        want[bin(k, 2)] += e;
                        total += e;
                    }
                }
            }
            // Each bin sums at most all voxels twice over in both orders:
            // a bound of 2·voxels·ε of the total.
            let voxels = (dims[0] * dims[1] * dims[2]) as f64;
            let bound = 2.0 * voxels * f64::EPSILON * 3.0 * total;
            for b in 0..PROFILE_BINS {
                assert!(
                    (got.0[b] - want[b]).abs() <= bound,
                    "{dims:?} n {n} bin {b}: {} against {}",
                    got.0[b],
                    want[b]
                );
            }
            assert!(want.iter().filter(|&&e| e > 0.0).count() > 1, "{dims:?}");
        }
    }
}
