//! Unit tests of the phantoms: sampling, analytic integrals, the mixture
//! generator.

use super::*;

fn random_unit(rng: &mut SplitMix64) -> [f64; 3] {
    let v = rng.in_unit_ball::<3>();
    let n = dot(v, v).sqrt();
    v.map(|x| x / n)
}

fn at(o: [f64; 3], d: [f64; 3], t: f64) -> [f64; 3] {
    [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]]
}

/// Composite Simpson of `f` on `[lo, hi]` with step about `h`.
fn simpson(f: impl Fn(f64) -> f64, lo: f64, hi: f64, h: f64) -> f64 {
    let m = (((hi - lo) / h / 2.0).ceil() as usize).max(1) * 2;
    let h = (hi - lo) / m as f64;
    let inner: f64 = (1..m)
        .map(|i| f(lo + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(lo) + f(hi) + inner) * h / 3.0
}

/// Midpoint count of an indicator-like density: `h · Σ f(t_k)`.
fn midpoint(f: impl Fn(f64) -> f64, lo: f64, hi: f64, h: f64) -> f64 {
    let m = ((hi - lo) / h).ceil() as usize;
    (0..m).map(|k| f(lo + (k as f64 + 0.5) * h)).sum::<f64>() * h
}

fn det(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

#[test]
fn splitmix64_reference_values() {
    // First outputs of Vigna's splitmix64.c from state 0.
    let mut rng = SplitMix64::new(0);
    assert_eq!(rng.next_u64(), 0xE220_A839_7B1D_CDAF);
    assert_eq!(rng.next_u64(), 0x6E78_9E6A_A1B9_65F4);
    let mut rng = SplitMix64::new(7);
    for _ in 0..10_000 {
        let x = rng.next_f64();
        assert!((0.0..1.0).contains(&x));
    }
}

#[test]
fn gaussian_line_integral_matches_quadrature() {
    let mixture = GaussianMixture::random(11, 64, 6);
    let mut rng = SplitMix64::new(99);
    for g in &mixture.components {
        let smax = g.sigmas.iter().cloned().fold(0.0, f64::max);
        for _ in 0..4 {
            // Origin within 2σ (whitened) of the centre; beyond |t| > T
            // every point is over 12σmax from μ: tails below e^-72.
            let u = rng.in_unit_ball::<3>();
            let off = mul(&g.rotation, [0, 1, 2].map(|a| 2.0 * g.sigmas[a] * u[a]));
            let o = [0, 1, 2].map(|a| g.center[a] + off[a]);
            let d = random_unit(&mut rng);
            let t = dot(off, off).sqrt() + 12.0 * smax;
            let numeric = simpson(|s| g.density(at(o, d, s)), -t, t, 0.01);
            let exact = g.line_integral(o, d);
            assert!(exact > 1e-3 * g.amplitude);
            let rel = (exact - numeric).abs() / exact;
            assert!(rel < 1e-9, "rel {rel:e}: {exact} vs {numeric}");
        }
    }
    // The mixture sums its components.
    let o = [30.0, 31.0, 33.0];
    let d = random_unit(&mut rng);
    let sum: f64 = mixture
        .components
        .iter()
        .map(|g| g.line_integral(o, d))
        .sum();
    assert_eq!(mixture.line_integral(o, d), sum);
}

#[test]
fn ellipsoid_chord_matches_quadrature_and_sphere() {
    let mut rng = SplitMix64::new(5);
    let h = 1e-3;
    let mut hits = 0;
    for _ in 0..20 {
        let rot = quaternion_to_matrix(rng.in_unit_ball::<4>());
        let axes = [(); 3].map(|_| rng.uniform(2.0, 9.0));
        let center = [(); 3].map(|_| rng.uniform(10.0, 20.0));
        let e = Ellipsoid::new(center, axes, rot, 0.7);
        let o = [0, 1, 2].map(|a| center[a] + rng.uniform(-6.0, 6.0));
        let d = random_unit(&mut rng);
        let numeric = midpoint(|t| e.density(at(o, d, t)), -30.0, 30.0, h);
        let exact = e.line_integral(o, d);
        hits += usize::from(exact > 0.0);
        assert!((exact - numeric).abs() <= 0.7 * h, "{exact} vs {numeric}");
    }
    assert!(hits > 10, "too few rays hit: {hits}");

    // An ellipsoid with equal axes, any rotation, is a sphere.
    for _ in 0..20 {
        let rot = quaternion_to_matrix(rng.in_unit_ball::<4>());
        let r = rng.uniform(1.0, 10.0);
        let center = [(); 3].map(|_| rng.uniform(-5.0, 5.0));
        let e = Ellipsoid::new(center, [r; 3], rot, 1.0);
        let s = Sphere {
            center,
            radius: r,
            density: 1.0,
        };
        let o = [0, 1, 2].map(|a| center[a] + rng.uniform(-1.2 * r, 1.2 * r));
        let d = random_unit(&mut rng);
        let w = sub(o, center);
        let dist2 = dot(w, w) - dot(w, d).powi(2);
        let formula = 2.0 * (r * r - dist2).max(0.0).sqrt();
        assert!((e.chord(o, d) - formula).abs() < 1e-9 * r);
        assert!((s.line_integral(o, d) - formula).abs() < 1e-9 * r);
    }
    // A ray through the centre and one that misses.
    let s = Sphere {
        center: [1.0, 2.0, 3.0],
        radius: 2.0,
        density: 3.0,
    };
    assert!((s.line_integral([1.0, 2.0, -40.0], [0.0, 0.0, 1.0]) - 12.0).abs() < 1e-12);
    assert_eq!(s.line_integral([1.0, 4.5, 3.0], [1.0, 0.0, 0.0]), 0.0);
}

#[test]
fn shepp_logan_line_integral_matches_quadrature() {
    let sl = SheppLogan::new([64, 48, 40]);
    let bound: f64 = MODIFIED_SHEPP_LOGAN_3D.iter().map(|r| r[0].abs()).sum();
    let mut rng = SplitMix64::new(17);
    let h = 1e-3;
    for _ in 0..6 {
        let o = [32.0, 24.0, 20.0].map(|c| c + rng.uniform(-8.0, 8.0));
        let d = random_unit(&mut rng);
        let numeric = midpoint(|t| sl.density(at(o, d, t)), -80.0, 80.0, h);
        let exact = sl.line_integral(o, d);
        assert!(exact > 1.0, "{exact}");
        assert!((exact - numeric).abs() <= bound * h, "{exact} vs {numeric}");
    }
}

/// A linear ramp with distinct values at every voxel, to check layout.
struct Ramp;
impl Phantom for Ramp {
    fn density(&self, p: [f64; 3]) -> f64 {
        p[0] + 10.0 * p[1] + 100.0 * p[2]
    }
    fn line_integral(&self, _: [f64; 3], _: [f64; 3]) -> f64 {
        f64::INFINITY
    }
}

#[test]
fn sample_layout() {
    let dims = [5, 7, 3];
    let v = sample(&Ramp, dims);
    assert_eq!(v.dims, dims);
    assert_eq!(v.data.len(), 5 * 7 * 3);
    assert_eq!(v.get(0, 0, 0), 0.0);
    assert_eq!(v.get(4, 0, 0), 4.0);
    assert_eq!(v.get(0, 6, 0), 60.0);
    assert_eq!(v.get(1, 2, 2), 221.0);
    assert_eq!(v.data[4 + 5 * (6 + 7 * 2)], 264.0);

    let g = Gaussian {
        amplitude: 0.8,
        center: [3.2, 1.7, 0.6],
        sigmas: [1.5, 2.5, 1.8],
        rotation: quaternion_to_matrix([0.9, 0.2, -0.3, 0.1]),
    };
    let v = sample(&g, dims);
    for (i, j, k) in [(0, 0, 0), (4, 6, 2), (1, 5, 0), (3, 2, 1)] {
        let want = g.density([i as f64, j as f64, k as f64]) as f32;
        assert_eq!(v.get(i, j, k), want);
    }
    assert_ne!(v.get(4, 0, 0), v.get(0, 4, 0));
}

#[test]
fn random_mixture_is_deterministic_and_valid() {
    let a = GaussianMixture::random(42, 64, 12);
    assert_eq!(a, GaussianMixture::random(42, 64, 12));
    assert_ne!(a, GaussianMixture::random(43, 64, 12));
    assert_eq!(a.components.len(), 12);
    for (n, seed) in [(64usize, 42u64), (32, 1), (128, 2), (8, 3)] {
        let nf = n as f64;
        let hi = (0.12 * nf).max(1.5);
        let c = [nf / 2.0; 3];
        for g in &GaussianMixture::random(seed, n, 20).components {
            let smax = g.sigmas.iter().cloned().fold(0.0, f64::max);
            assert!(g.sigmas.iter().all(|&s| (1.5..=hi).contains(&s)));
            assert!((0.3..=1.0).contains(&g.amplitude));
            let w = sub(g.center, c);
            let r = dot(w, w).sqrt();
            let allowed = 0.40 * nf - 4.0 * smax;
            if allowed < 0.0 {
                assert_eq!(g.center, c);
            } else {
                assert!(r <= allowed, "|μ-c| = {r} > {allowed}");
            }
            let m = &g.rotation;
            for p in 0..3 {
                for q in 0..3 {
                    let col = (0..3).map(|i| m[i][p] * m[i][q]).sum::<f64>();
                    let want = if p == q { 1.0 } else { 0.0 };
                    assert!((col - want).abs() < 1e-12);
                }
            }
            assert!((det(m) - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn sampled_sum_equals_integral() {
    // A mixture for a 16³ cube, moved to the centre of a 32³ volume:
    // every component is at least ~6.7σ from the volume's faces.
    let mut mixture = GaussianMixture::random(2024, 16, 5);
    for g in &mut mixture.components {
        g.center = g.center.map(|x| x + 8.0);
    }
    let v = sample(&mixture, [32; 3]);
    let sum: f64 = v.data.iter().map(|&x| x as f64).sum();
    let want: f64 = mixture
        .components
        .iter()
        .map(|g| {
            g.amplitude * (2.0 * std::f64::consts::PI).powf(1.5) * g.sigmas.iter().product::<f64>()
        })
        .sum();
    assert!((want - mixture.integral()).abs() < 1e-12 * want);
    let rel = (sum - want).abs() / want;
    assert!(rel < 1e-6, "rel {rel:e}");
}

/// Independent membership test in normalised coordinates from the table.
fn table_density(x: [f64; 3]) -> f64 {
    MODIFIED_SHEPP_LOGAN_3D
        .iter()
        .filter(|r| {
            let (s, c) = r[7].to_radians().sin_cos();
            let (dx, dy, dz) = (x[0] - r[4], x[1] - r[5], x[2] - r[6]);
            // Rotate by -φ into the ellipsoid's frame.
            let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
            (u / r[1]).powi(2) + (v / r[2]).powi(2) + (dz / r[3]).powi(2) <= 1.0
        })
        .map(|r| r[0])
        .sum()
}

#[test]
fn shepp_logan_matches_table() {
    for dims in [[64, 64, 64], [64, 48, 40], [5, 7, 3]] {
        let sl = SheppLogan::new(dims);
        let half = dims.map(|n| n as f64 / 2.0);
        // Centre: the sum of intensities of the ellipsoids containing 0.
        let centre = sl.density(half);
        assert!((centre - table_density([0.0; 3])).abs() < 1e-12);
        assert!(centre.abs() > 0.05);
        // Random points agree with the table (well inside [-1, 1]³).
        let mut rng = SplitMix64::new(3);
        let mut outside = 0;
        for _ in 0..20_000 {
            let x = [(); 3].map(|_| rng.uniform(-1.0, 1.0));
            let p = [0, 1, 2].map(|a| half[a] + half[a] * x[a]);
            let got = sl.density(p);
            assert!((got - table_density(x)).abs() < 1e-12, "at {x:?}");
            let outer = MODIFIED_SHEPP_LOGAN_3D[0];
            let q =
                (x[0] / outer[1]).powi(2) + (x[1] / outer[2]).powi(2) + (x[2] / outer[3]).powi(2);
            if q > 1.0 {
                outside += 1;
                assert_eq!(got, 0.0, "nonzero outside the skull at {x:?}");
            }
        }
        assert!(outside > 1000);
        let v = sample(&sl, dims);
        assert_eq!(v.get(0, 0, 0), 0.0);
        assert_eq!(v.get(dims[0] - 1, dims[1] - 1, dims[2] - 1), 0.0);
    }
    // The rotated ellipsoids really are rotated: φ = -18° leans ellipsoid
    // 3's long axis towards +x for +y.
    let sl = SheppLogan::new([200; 3]);
    let e3 = &sl.ellipsoids[2];
    let (s, c) = 18f64.to_radians().sin_cos();
    let tip = [0, 1, 2].map(|a| e3.center[a] + 100.0 * 0.30 * [s, c, 0.0][a]);
    assert!(e3.contains(tip));
    let mirrored = [e3.center[0] - 100.0 * 0.30 * s, tip[1], tip[2]];
    assert!(!e3.contains(mirrored));
}
