//! The ideal projection by the Fourier slice theorem, evaluated exactly:
//! the direct DFT of the samples at every (non-grid) slice point, then the
//! pipeline's shift, inverse 2D DHT and crop on an `m × m` slice.
//!
//! At slice point `k = (kx, ky)` (integers in `[−m/2, m/2)`) the 3D
//! frequency is `q = kx·r + ky·u` in cycles per `m` voxels, and
//! `F(q) = Σ_x f(x) e^{−i2π q·(x − c)/m}`: the Fourier transform of the
//! band-limited (sinc) interpolant of the samples, zero outside the Nyquist
//! cube `|q_a| ≤ m/2`. The image is therefore the exact projection of that
//! interpolant, low-passed to the pixel band and repeated every `m` pixels.
//! For views along an axis with pixels on voxels it is the voxel sums
//! ([`super::axis::axis_projection`]) for any `m` larger than the volume
//! along the image axes (at `m` equal to a side, the pixel just beyond the
//! volume wraps onto its first voxel); for oblique views `m` at twice the
//! volume keeps the repeats off the box's shadow, as the 2× pipeline does.
//!
//! Cost `O(m²·N³)` multiply-adds, halved by the Hermitian symmetry of real
//! samples and spread over threads with rayon: 64³ volumes at `m = 128`
//! and `256` are practical in release builds.

use std::f64::consts::PI;

use rayon::prelude::*;

use fvr_core::dht::signed_index;
use fvr_core::geometry::View;
use fvr_core::image::check_image;
use fvr_core::volume::padded_size;

use super::finish_f64;
use fvr_engine::volume::Volume;

/// The ideal `width × height` projection of `volume` along `view` on an
/// `m × m` slice (`m` a power of two at least the volume's power-of-two
/// side, [`padded_size`] at 1).
///
/// # Errors
/// Bad view vectors, image size, or `m`.
pub fn slice_dft_projection(
    volume: &Volume,
    view: &View,
    width: usize,
    height: usize,
    m: usize,
) -> Result<Vec<f64>, fvr_core::Error> {
    let frame = view.frame()?;
    let dims = volume.dims;
    let n1 = padded_size(dims, 1)?;
    if !m.is_power_of_two() {
        return Err(fvr_core::Error::NotPowerOfTwo {
            what: "ideal slice side",
            len: m,
        });
    }
    if m < n1 {
        return Err(fvr_core::Error::VolumeTooLarge { dims, grid: m });
    }
    check_image(width, height, m)?;
    let data: Vec<f64> = volume.data.iter().map(|&v| f64::from(v)).collect();
    let signed = |i: usize| signed_index(i, m);
    // One of each pair ±k (real samples: F(−q) = F(q)*), plus the points
    // whose negation is off the slice (a coordinate at −m/2).
    let points: Vec<usize> = (0..m * m)
        .filter(|&p| {
            let (ix, iy) = (p % m, p / m);
            let mirror = ((m - iy) % m) * m + (m - ix) % m;
            !mirrors(ix, iy, m) || p <= mirror
        })
        .collect();
    let values: Vec<(usize, f64, f64)> = points
        .par_iter()
        .map(|&p| {
            let (kx, ky) = (signed(p % m) as f64, signed(p / m) as f64);
            let q: [f64; 3] = std::array::from_fn(|a| kx * frame.right[a] + ky * frame.up[a]);
            let (re, im) = dtft(&data, dims, q, m);
            (p, re, im)
        })
        .collect();
    let mut grid = vec![0.0f64; m * m];
    for (p, re, im) in values {
        let (ix, iy) = (p % m, p / m);
        // Hartley value H = Re F − Im F; at −k, Re F + Im F.
        grid[p] = re - im;
        if mirrors(ix, iy, m) {
            grid[((m - iy) % m) * m + (m - ix) % m] = re + im;
        }
    }
    finish_f64(&mut grid, m, dims, &frame, width, height)
}

/// Whether slice point `(ix, iy)`'s negation is on the slice too: neither
/// coordinate is `−m/2`.
fn mirrors(ix: usize, iy: usize, m: usize) -> bool {
    ix != m / 2 && iy != m / 2
}

/// `(Re F(q), Im F(q))` by direct summation, zero outside the Nyquist cube;
/// separable: the phase tables per axis, x innermost.
fn dtft(data: &[f64], dims: [usize; 3], q: [f64; 3], m: usize) -> (f64, f64) {
    if q.iter().any(|c| c.abs() > m as f64 / 2.0) {
        return (0.0, 0.0);
    }
    let table = |a: usize| -> (Vec<f64>, Vec<f64>) {
        (0..dims[a])
            .map(|i| {
                let x = i as f64 - (dims[a] / 2) as f64;
                let (s, c) = (-2.0 * PI * q[a] * x / m as f64).sin_cos();
                (c, s)
            })
            .unzip()
    };
    let (cx, sx) = table(0);
    let (cy, sy) = table(1);
    let (cz, sz) = table(2);
    let (nx, ny) = (dims[0], dims[1]);
    let (mut re, mut im) = (0.0, 0.0);
    for k in 0..dims[2] {
        let (mut zr, mut zi) = (0.0, 0.0);
        for j in 0..ny {
            let row = &data[nx * (j + ny * k)..][..nx];
            let (lr, li) = dot2(row, &cx, &sx);
            // (lr + i·li)·(cy + i·sy)
            zr += lr * cy[j] - li * sy[j];
            zi += lr * sy[j] + li * cy[j];
        }
        re += zr * cz[k] - zi * sz[k];
        im += zr * sz[k] + zi * cz[k];
    }
    (re, im)
}

/// `(Σ v·c, Σ v·s)` with four partial sums each, so that the compiler can
/// vectorize the reduction.
fn dot2(v: &[f64], c: &[f64], s: &[f64]) -> (f64, f64) {
    let (mut ar, mut ai) = ([0.0f64; 4], [0.0f64; 4]);
    let mut vc = v.chunks_exact(4);
    let mut cc = c.chunks_exact(4);
    let mut sc = s.chunks_exact(4);
    for ((v4, c4), s4) in (&mut vc).zip(&mut cc).zip(&mut sc) {
        for l in 0..4 {
            ar[l] += v4[l] * c4[l];
            ai[l] += v4[l] * s4[l];
        }
    }
    let (mut r, mut i) = (
        (ar[0] + ar[1]) + (ar[2] + ar[3]),
        (ai[0] + ai[1]) + (ai[2] + ai[3]),
    );
    for ((v, c), s) in vc
        .remainder()
        .iter()
        .zip(cc.remainder())
        .zip(sc.remainder())
    {
        r += v * c;
        i += v * s;
    }
    (r, i)
}
