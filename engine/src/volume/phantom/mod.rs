//! Analytic phantoms with exact line integrals.
//!
//! Everything is in voxel units: voxel `(i, j, k)` sits at the point
//! `(i, j, k)`, and the centre of a volume of dims `n` is `n / 2` per axis
//! (real-valued). Sampled with a spacing `Δ` ([`sample_spaced`]), the same
//! phantom is in mm instead: voxel `(i, j, k)` sits at `(i·Δx, j·Δy, k·Δz)`
//! (the physical contract of `fvr_core::geometry`). Each phantom gives its density at any point and the exact
//! integral of that density along any line, so renderers can be checked
//! against references that carry no discretisation error of their own.

use crate::volume::Volume;

/// A continuous 3D density with exact line integrals. All f64.
pub trait Phantom {
    /// Density at point `p` (voxel units).
    fn density(&self, p: [f64; 3]) -> f64;
    /// Exact `∫ density(origin + t·dir) dt` over the whole line, for a
    /// **unit** vector `dir`.
    fn line_integral(&self, origin: [f64; 3], dir: [f64; 3]) -> f64;
    /// The phantom as a Gaussian mixture, if it is one (shading references
    /// have closed forms for mixtures only).
    fn as_gaussian_mixture(&self) -> Option<&GaussianMixture> {
        None
    }
}

/// Sample the density at every voxel centre `(i, j, k)` into a [`Volume`].
pub fn sample(phantom: &dyn Phantom, dims: [usize; 3]) -> Volume {
    let mut volume = Volume::zeros(dims);
    let mut idx = 0;
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                volume.data[idx] = phantom.density([i as f64, j as f64, k as f64]) as f32;
                idx += 1;
            }
        }
    }
    volume
}

/// Sample a phantom given in mm at the voxel centres `(i·Δx, j·Δy, k·Δz)`
/// into a [`Volume`] of spacing `spacing`. A spacing of 1 mm gives
/// [`sample`]'s samples.
///
/// # Errors
/// A spacing that is zero, negative or not finite.
pub fn sample_spaced(
    phantom: &dyn Phantom,
    dims: [usize; 3],
    spacing: [f64; 3],
) -> Result<Volume, crate::volume::SpacingError> {
    let mut volume = Volume::zeros(dims).with_spacing(spacing)?;
    let mut idx = 0;
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = [
                    i as f64 * spacing[0],
                    j as f64 * spacing[1],
                    k as f64 * spacing[2],
                ];
                volume.data[idx] = phantom.density(p) as f32;
                idx += 1;
            }
        }
    }
    Ok(volume)
}

/// SplitMix64 (Steele, Lea & Flood 2014; Vigna's reference constants): a tiny,
/// platform-independent PRNG for reproducible phantoms.
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform f64 in `[0, 1)` (53 random bits).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform f64 in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// A point uniform in the open unit `N`-ball, by rejection from the cube.
    /// Only `+ - * /` are used, so results are bit-identical on every platform.
    /// Points of norm below `1e-3` are rejected too (so they can be normalised).
    fn in_unit_ball<const N: usize>(&mut self) -> [f64; N] {
        loop {
            let mut v = [0.0; N];
            for x in &mut v {
                *x = self.uniform(-1.0, 1.0);
            }
            let r2: f64 = v.iter().map(|x| x * x).sum();
            if r2 < 1.0 && r2 > 1e-6 {
                return v;
            }
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `Mᵀ v`.
fn mul_transpose(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

/// `M v`.
fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// Rotation matrix of the unit quaternion `(w, x, y, z)` (normalised here).
fn quaternion_to_matrix(q: [f64; 4]) -> [[f64; 3]; 3] {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// One anisotropic 3D Gaussian:
/// `amplitude · exp(-½ (p-μ)ᵀ Σ⁻¹ (p-μ))` with `Σ = R diag(σ²) Rᵀ`.
#[derive(Clone, Debug, PartialEq)]
pub struct Gaussian {
    /// Peak value.
    pub amplitude: f64,
    /// Centre `μ` (voxel units).
    pub center: [f64; 3],
    /// Standard deviations along the principal axes (voxel units, > 0).
    pub sigmas: [f64; 3],
    /// Rotation `R`; its columns are the principal axes.
    pub rotation: [[f64; 3]; 3],
}

impl Gaussian {
    /// A component from its amplitude, centre, principal sigmas and rotation.
    pub fn new(
        amplitude: f64,
        center: [f64; 3],
        sigmas: [f64; 3],
        rotation: [[f64; 3]; 3],
    ) -> Self {
        Self {
            amplitude,
            center,
            sigmas,
            rotation,
        }
    }

    /// `Rᵀ v / σ`: coordinates of `v` in the whitened principal frame.
    pub fn whiten(&self, v: [f64; 3]) -> [f64; 3] {
        let y = mul_transpose(&self.rotation, v);
        [
            y[0] / self.sigmas[0],
            y[1] / self.sigmas[1],
            y[2] / self.sigmas[2],
        ]
    }

    /// Total mass `amplitude · (2π)^{3/2} σ₁σ₂σ₃`.
    pub fn integral(&self) -> f64 {
        let s = self.sigmas;
        self.amplitude * (2.0 * std::f64::consts::PI).powf(1.5) * s[0] * s[1] * s[2]
    }
}

impl Phantom for Gaussian {
    fn density(&self, p: [f64; 3]) -> f64 {
        let w = self.whiten(sub(p, self.center));
        self.amplitude * (-0.5 * dot(w, w)).exp()
    }

    fn line_integral(&self, origin: [f64; 3], dir: [f64; 3]) -> f64 {
        // With A = Σ⁻¹, w = A^{1/2}-whitened (o-μ) and v = whitened d:
        // a = |v|², b = w·v, c0 = |w|², and c0 - b²/a = |w - (b/a) v|²,
        // evaluated as a residual norm to avoid cancellation.
        let w = self.whiten(sub(origin, self.center));
        let v = self.whiten(dir);
        let a = dot(v, v);
        let s = dot(w, v) / a;
        let r = [w[0] - s * v[0], w[1] - s * v[1], w[2] - s * v[2]];
        self.amplitude * (2.0 * std::f64::consts::PI / a).sqrt() * (-0.5 * dot(r, r)).exp()
    }
}

/// A sum of Gaussians.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussianMixture {
    /// The components.
    pub components: Vec<Gaussian>,
}

impl GaussianMixture {
    /// `count` random anisotropic Gaussians for a cube of side `n`, from `seed`.
    ///
    /// Per component, in this draw order: three sigmas uniform in
    /// `[1.5, max(1.5, 0.12·n)]`; a rotation uniform on SO(3) (a uniform unit
    /// quaternion, by rejection from the 4-cube); an amplitude uniform in
    /// `[0.3, 1.0]`; a centre uniform in the ball `|μ - c| ≤ 0.40·n - 4·σmax`
    /// around `c = n/2` (or `μ = c` if that radius is negative), so that
    /// `μ ± 4σmax` stays inside the sphere of radius `0.40·n`.
    ///
    /// Only IEEE-exact operations (`+ - * / sqrt`) touch the random numbers,
    /// so a seed gives the same mixture on every platform.
    pub fn random(seed: u64, n: usize, count: usize) -> Self {
        Self::random_with(seed, n, count, 0.12)
    }

    /// As [`GaussianMixture::random`] with sigmas in
    /// `[1.5, max(1.5, sigma_fraction·n)]`.
    pub fn random_with(seed: u64, n: usize, count: usize, sigma_fraction: f64) -> Self {
        let nf = n as f64;
        Self::random_in(seed, nf, count, 1.5, (sigma_fraction * nf).max(1.5))
    }

    /// As [`GaussianMixture::random`] for a cube of side `side` (any unit,
    /// e.g. mm) with sigmas uniform in `[sigma_lo, sigma_hi]`: centres in the
    /// ball `|μ − c| ≤ 0.40·side − 4·σmax` around `c = side/2`. For a volume
    /// of spacing `Δ`, `sigma_lo ≥ 1.5·max Δ` keeps every component at least
    /// 1.5 samples wide along every axis, as [`GaussianMixture::random`] is.
    /// `random_with(seed, n, count, f)` is
    /// `random_in(seed, n, count, 1.5, max(1.5, f·n))`, draw for draw.
    pub fn random_in(seed: u64, side: f64, count: usize, sigma_lo: f64, sigma_hi: f64) -> Self {
        let mut rng = SplitMix64::new(seed);
        let nf = side;
        let c = nf / 2.0;
        let components = (0..count)
            .map(|_| {
                let sigmas = [(); 3].map(|_| rng.uniform(sigma_lo, sigma_hi));
                let rotation = quaternion_to_matrix(rng.in_unit_ball::<4>());
                let amplitude = rng.uniform(0.3, 1.0);
                let sigma_max = sigmas[0].max(sigmas[1]).max(sigmas[2]);
                let radius = 0.40 * nf - 4.0 * sigma_max;
                let center = if radius > 0.0 {
                    rng.in_unit_ball::<3>().map(|u| c + radius * u)
                } else {
                    [c; 3]
                };
                Gaussian {
                    amplitude,
                    center,
                    sigmas,
                    rotation,
                }
            })
            .collect();
        Self { components }
    }

    /// Total mass: the sum of the components' integrals.
    pub fn integral(&self) -> f64 {
        self.components.iter().map(Gaussian::integral).sum()
    }
}

impl Phantom for GaussianMixture {
    fn density(&self, p: [f64; 3]) -> f64 {
        self.components.iter().map(|g| g.density(p)).sum()
    }

    fn as_gaussian_mixture(&self) -> Option<&GaussianMixture> {
        Some(self)
    }

    fn line_integral(&self, origin: [f64; 3], dir: [f64; 3]) -> f64 {
        self.components
            .iter()
            .map(|g| g.line_integral(origin, dir))
            .sum()
    }
}

/// A uniform solid ellipsoid `{p : |M (p - center)| ≤ 1}`.
///
/// `M` maps the ellipsoid onto the unit ball; for semi-axes `s` along the
/// columns of a rotation `R`, `M = diag(1/s) Rᵀ`. A general `M` also covers
/// ellipsoids sheared by anisotropic scaling (as in [`SheppLogan`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Ellipsoid {
    /// Centre (voxel units).
    pub center: [f64; 3],
    /// The map `M` onto the unit ball (invertible).
    pub to_unit: [[f64; 3]; 3],
    /// Density inside.
    pub density: f64,
}

impl Ellipsoid {
    /// An ellipsoid with the given semi-axes along the columns of `rotation`.
    pub fn new(
        center: [f64; 3],
        semi_axes: [f64; 3],
        rotation: [[f64; 3]; 3],
        density: f64,
    ) -> Self {
        let mut to_unit = [[0.0; 3]; 3];
        for (i, row) in to_unit.iter_mut().enumerate() {
            for (j, m) in row.iter_mut().enumerate() {
                *m = rotation[j][i] / semi_axes[i];
            }
        }
        Self {
            center,
            to_unit,
            density,
        }
    }

    /// Whether `p` is inside (boundary included).
    pub fn contains(&self, p: [f64; 3]) -> bool {
        let u = mul(&self.to_unit, sub(p, self.center));
        dot(u, u) <= 1.0
    }

    /// Length of the chord cut by the line `origin + t·dir` (`dir` unit), 0
    /// if it misses.
    pub fn chord(&self, origin: [f64; 3], dir: [f64; 3]) -> f64 {
        // |u + t v|² = 1  ⇔  |v|² t² + 2 (u·v) t + |u|² - 1 = 0.
        let u = mul(&self.to_unit, sub(origin, self.center));
        let v = mul(&self.to_unit, dir);
        let a = dot(v, v);
        let s = dot(u, v) / a;
        // Discriminant / a² = (1 - |u - s v|²) / a, computed as a residual.
        let r = [u[0] - s * v[0], u[1] - s * v[1], u[2] - s * v[2]];
        let disc = (1.0 - dot(r, r)) / a;
        if disc > 0.0 {
            2.0 * disc.sqrt()
        } else {
            0.0
        }
    }
}

impl Phantom for Ellipsoid {
    fn density(&self, p: [f64; 3]) -> f64 {
        if self.contains(p) {
            self.density
        } else {
            0.0
        }
    }

    fn line_integral(&self, origin: [f64; 3], dir: [f64; 3]) -> f64 {
        self.density * self.chord(origin, dir)
    }
}

/// The modified 3D Shepp–Logan table, in the normalised cube `[-1, 1]³`.
///
/// Columns: intensity, semi-axes `a b c`, centre `x0 y0 z0`, rotation `φ` in
/// degrees about the z axis (counter-clockwise in the x-y plane, about the
/// ellipsoid's own centre).
///
/// Source: the `modified_shepp_logan` table of M. Schabel's `phantom3d.m`
/// (MATLAB Central File Exchange, 2005), whose intensities are Toft's
/// high-contrast ones (P. Toft, *The Radon Transform: Theory and
/// Implementation*, PhD thesis, DTU 1996, pp. 199–200) on the 3D extension of
/// the Shepp & Logan (1974) head. Its `θ` column is zero throughout; its `ψ`
/// column (10° for ellipsoids 3 and 4, which `phantom3d.m` applies about the
/// origin) is not used here, so the z = 0 slice is the usual 2D modified
/// Shepp–Logan. Kak & Slaney's own 3D table (*Principles of Computerized
/// Tomographic Imaging*, ch. 3) has a different geometry and grey levels.
pub const MODIFIED_SHEPP_LOGAN_3D: [[f64; 8]; 10] = [
    [1.0, 0.6900, 0.920, 0.810, 0.0, 0.0, 0.0, 0.0],
    [-0.8, 0.6624, 0.874, 0.780, 0.0, -0.0184, 0.0, 0.0],
    [-0.2, 0.1100, 0.310, 0.220, 0.22, 0.0, 0.0, -18.0],
    [-0.2, 0.1600, 0.410, 0.280, -0.22, 0.0, 0.0, 18.0],
    [0.1, 0.2100, 0.250, 0.410, 0.0, 0.35, -0.15, 0.0],
    [0.1, 0.0460, 0.046, 0.050, 0.0, 0.1, 0.25, 0.0],
    [0.1, 0.0460, 0.046, 0.050, 0.0, -0.1, 0.25, 0.0],
    [0.1, 0.0460, 0.023, 0.050, -0.08, -0.605, 0.0, 0.0],
    [0.1, 0.0230, 0.023, 0.020, 0.0, -0.606, 0.0, 0.0],
    [0.1, 0.0230, 0.046, 0.020, 0.06, -0.605, 0.0, 0.0],
];

/// The 3D modified Shepp–Logan head ([`MODIFIED_SHEPP_LOGAN_3D`]), mapped
/// into voxel coordinates by `p = c + (n/2)·x` per axis, `c = n/2`.
/// The density is the sum of the intensities of all ellipsoids containing `p`.
#[derive(Clone, Debug, PartialEq)]
pub struct SheppLogan {
    /// The ten ellipsoids in voxel coordinates, in table order.
    pub ellipsoids: Vec<Ellipsoid>,
}

impl SheppLogan {
    /// The phantom for a volume of `dims` (anisotropic dims stretch it).
    pub fn new(dims: [usize; 3]) -> Self {
        let half = dims.map(|n| n as f64 / 2.0);
        let ellipsoids = MODIFIED_SHEPP_LOGAN_3D
            .iter()
            .map(|row| {
                let (sin, cos) = row[7].to_radians().sin_cos();
                // Rotation about z: columns are the rotated x, y, z axes.
                let r = [[cos, -sin, 0.0], [sin, cos, 0.0], [0.0, 0.0, 1.0]];
                // In normalised coordinates M₀ = diag(1/abc) Rᵀ; with
                // x = (p - c) / half, M = M₀ diag(1/half).
                let unit = Ellipsoid::new([0.0; 3], [row[1], row[2], row[3]], r, row[0]);
                let mut to_unit = unit.to_unit;
                for m in &mut to_unit {
                    for (a, e) in m.iter_mut().enumerate() {
                        *e /= half[a];
                    }
                }
                let center = [0, 1, 2].map(|a| half[a] + half[a] * row[4 + a]);
                Ellipsoid {
                    center,
                    to_unit,
                    density: row[0],
                }
            })
            .collect();
        Self { ellipsoids }
    }
}

impl Phantom for SheppLogan {
    fn density(&self, p: [f64; 3]) -> f64 {
        self.ellipsoids.iter().map(|e| e.density(p)).sum()
    }

    fn line_integral(&self, origin: [f64; 3], dir: [f64; 3]) -> f64 {
        self.ellipsoids
            .iter()
            .map(|e| e.line_integral(origin, dir))
            .sum()
    }
}

/// A uniform ball.
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    /// Centre (voxel units).
    pub center: [f64; 3],
    /// Radius (voxel units).
    pub radius: f64,
    /// Density inside.
    pub density: f64,
}

impl Phantom for Sphere {
    fn density(&self, p: [f64; 3]) -> f64 {
        let w = sub(p, self.center);
        if dot(w, w) <= self.radius * self.radius {
            self.density
        } else {
            0.0
        }
    }

    fn line_integral(&self, origin: [f64; 3], dir: [f64; 3]) -> f64 {
        // Chord 2·sqrt(r² - d²), d = distance from the centre to the line.
        let w = sub(origin, self.center);
        let s = dot(w, dir);
        let r = [w[0] - s * dir[0], w[1] - s * dir[1], w[2] - s * dir[2]];
        let h2 = self.radius * self.radius - dot(r, r);
        if h2 > 0.0 {
            self.density * 2.0 * h2.sqrt()
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests;
