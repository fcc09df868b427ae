//! The f64 reference ladder and the agreement metric.
//!
//! 1. [`naive_dht`], [`naive_dht_2d`], [`naive_dht_3d`]: O(N²) sums with
//!    exactly reduced angles, against which the fast transforms are tested.
//! 2. [`exact_projection`]: exact line integrals of analytic phantoms.
//! 3. [`ideal_projection`]: the volume's DFT evaluated directly on the slice
//!    points (the ideal interpolation filter), for small volumes.
//! 4. The full pipeline in f64: [`fvr_engine::spectrum::Precision::F64`].
//! 5. [`spatial_projection`]: a spatial-domain ray integrator.
//! 6. [`axis::axis_projection`]: the exact image of the band-limited
//!    interpolant for views along an axis with pixels on voxels.
//! 7. [`slice_dft::slice_dft_projection`]: [`ideal_projection`] threaded,
//!    on a slice of any power-of-two side, for any view of volumes up to
//!    about 64³.

pub mod axis;
pub mod raycast;
pub mod shaded;
pub mod slice_dft;

use std::f64::consts::PI;

use fvr_core::dht::signed_index;
use fvr_core::dht::Twiddles;
use fvr_core::geometry::{center, Frame, Sampling, View};
use fvr_core::image::{check_image, finish, placement, Crop};
use fvr_core::volume::padded_size;

use fvr_engine::volume::phantom::Phantom;
use fvr_engine::volume::Volume;

pub use fvr_engine::image::{max_abs_error, snr_db};

fn cas_exact(k: usize, x: usize, n: usize) -> f64 {
    // Reduce k·x modulo n in integers so the angle is exact to f64 rounding.
    let a = 2.0 * PI * ((k * x) % n) as f64 / n as f64;
    a.cos() + a.sin()
}

/// `H(k) = Σ x(j) cas(2πkj/N)`, unnormalized, by direct summation.
pub fn naive_dht(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            x.iter()
                .enumerate()
                .map(|(j, v)| v * cas_exact(k, j, n))
                .sum()
        })
        .collect()
}

/// True 2D DHT by direct summation, `x` fastest.
pub fn naive_dht_2d(data: &[f64], nx: usize, ny: usize) -> Vec<f64> {
    let mut out = vec![0.0; nx * ny];
    for v in 0..ny {
        for u in 0..nx {
            let mut s = 0.0;
            for y in 0..ny {
                for x in 0..nx {
                    // cas(2π(ux/nx + vy/ny)) with the phase reduced exactly.
                    let num = (u * x % nx) * ny + (v * y % ny) * nx;
                    let a = 2.0 * PI * (num % (nx * ny)) as f64 / (nx * ny) as f64;
                    s += data[x + nx * y] * (a.cos() + a.sin());
                }
            }
            out[u + nx * v] = s;
        }
    }
    out
}

/// True 3D DHT by direct summation, `x` fastest.
pub fn naive_dht_3d(data: &[f64], dims: [usize; 3]) -> Vec<f64> {
    let [nx, ny, nz] = dims;
    let total = nx * ny * nz;
    let mut out = vec![0.0; total];
    for w in 0..nz {
        for v in 0..ny {
            for u in 0..nx {
                let mut s = 0.0;
                for z in 0..nz {
                    for y in 0..ny {
                        for x in 0..nx {
                            let num = (u * x % nx) * ny * nz
                                + (v * y % ny) * nx * nz
                                + (w * z % nz) * nx * ny;
                            let a = 2.0 * PI * (num % total) as f64 / total as f64;
                            s += data[x + nx * (y + ny * z)] * (a.cos() + a.sin());
                        }
                    }
                }
                out[u + nx * (v + ny * w)] = s;
            }
        }
    }
    out
}

/// Exact X-ray image of an analytic phantom under the geometry contract
/// (`fvr_core::geometry`), for a volume of `dims`.
///
/// # Errors
/// Bad view vectors.
pub fn exact_projection(
    phantom: &dyn Phantom,
    dims: [usize; 3],
    view: &View,
    width: usize,
    height: usize,
) -> Result<Vec<f64>, fvr_core::Error> {
    exact_projection_sampled(phantom, dims, view, &Sampling::UNIT, width, height)
}

/// Exact X-ray image in physical units of a phantom given in mm, for a
/// volume of `dims` sampled at `sampling.spacing()` and imaged at
/// `sampling.pixel_size()` (the physical contract of `fvr_core::geometry`:
/// pixel positions in mm around `C = (n/2)·Δ`, `∫ f dt` with `t` in mm).
/// [`Sampling::UNIT`] gives [`exact_projection`].
///
/// # Errors
/// Bad view vectors.
pub fn exact_projection_sampled(
    phantom: &dyn Phantom,
    dims: [usize; 3],
    view: &View,
    sampling: &Sampling,
    width: usize,
    height: usize,
) -> Result<Vec<f64>, fvr_core::Error> {
    let frame = view.frame()?;
    let mut out = Vec::with_capacity(width * height);
    for row in 0..height {
        for col in 0..width {
            let p = sampling.pixel_position(&frame, dims, width, height, col as f64, row as f64);
            out.push(phantom.line_integral(p, frame.dir));
        }
    }
    Ok(out)
}

/// The projection with an ideal interpolation filter: the DFT of the
/// (unpremultiplied) volume evaluated directly at every slice point inside
/// the Nyquist cube, then the same shift, inverse DHT and crop as the
/// pipeline. O(n⁵): for volumes up to about 32³.
///
/// # Errors
/// Bad view vectors or image size.
pub fn ideal_projection(
    volume: &Volume,
    view: &View,
    width: usize,
    height: usize,
) -> Result<Vec<f64>, fvr_core::Error> {
    let frame = view.frame()?;
    let dims = volume.dims;
    let n = padded_size(dims, 1)?;
    check_image(width, height, n)?;
    let pos: Vec<Vec<f64>> = (0..3)
        .map(|a| {
            (0..dims[a])
                .map(|i| (i as f64) - (dims[a] / 2) as f64)
                .collect()
        })
        .collect();
    let mut grid = vec![0.0f64; n * n];
    let half = n as f64 / 2.0;
    for iy in 0..n {
        let ky = signed_index(iy, n) as f64;
        for ix in 0..n {
            let kx = signed_index(ix, n) as f64;
            let q: [f64; 3] = std::array::from_fn(|a| kx * frame.right[a] + ky * frame.up[a]);
            if q.iter().any(|c| c.abs() > half) {
                continue;
            }
            // Separable phases e^{−i2π q_a x_a / n}.
            let ph: Vec<Vec<(f64, f64)>> = (0..3)
                .map(|a| {
                    pos[a]
                        .iter()
                        .map(|x| {
                            let t = -2.0 * PI * q[a] * x / n as f64;
                            (t.cos(), t.sin())
                        })
                        .collect()
                })
                .collect();
            let (mut re, mut im) = (0.0, 0.0);
            for k in 0..dims[2] {
                for j in 0..dims[1] {
                    let (cy, sy) = ph[1][j];
                    let (cz, sz) = ph[2][k];
                    let (cyz, syz) = (cy * cz - sy * sz, cy * sz + sy * cz);
                    let (mut lr, mut li) = (0.0, 0.0);
                    for i in 0..dims[0] {
                        let v = volume.get(i, j, k) as f64;
                        lr += v * ph[0][i].0;
                        li += v * ph[0][i].1;
                    }
                    re += lr * cyz - li * syz;
                    im += lr * syz + li * cyz;
                }
            }
            grid[iy * n + ix] = re - im;
        }
    }
    finish_f64(&mut grid, n, dims, &frame, width, height)
}

/// The pipeline's finish in f64: the `n × n` Hartley slice `grid` shifted,
/// inverse 2D DHT'd and cropped to the `width × height` image of a volume
/// of `dims` seen in `frame`.
///
/// # Errors
/// Bad `n` or image size.
pub(crate) fn finish_f64(
    grid: &mut [f64],
    n: usize,
    dims: [usize; 3],
    frame: &Frame,
    width: usize,
    height: usize,
) -> Result<Vec<f64>, fvr_core::Error> {
    let mut tw_buf = vec![0.0f64; Twiddles::<f64>::buffer_len(n)];
    let tw = Twiddles::new(&mut tw_buf, n)?;
    let mut aux = vec![0.0f64; 4 * n];
    let mut out = vec![0.0f64; width * height];
    let place = placement(dims, frame, width, height);
    finish(
        grid,
        n,
        &Crop::new(place, 1.0, width, height),
        &tw,
        &mut aux,
        &mut out,
    )?;
    Ok(out)
}

/// Spatial-domain X-ray image in f64: each ray `p + t·d` is integrated with
/// the midpoint rule at `step` voxels over the volume's bounding box, the
/// volume being reconstructed by **trilinear** interpolation (zero outside).
/// It therefore integrates a different interpolant than the band-limited
/// one of the frequency-domain path; on smooth volumes the two agree to the
/// trilinear interpolation error.
///
/// # Errors
/// Bad view vectors.
pub fn spatial_projection(
    volume: &Volume,
    view: &View,
    width: usize,
    height: usize,
    step: f64,
) -> Result<Vec<f64>, fvr_core::Error> {
    let frame = view.frame()?;
    let dims = volume.dims;
    let c = center(dims);
    let reach =
        0.5 * ((dims[0] * dims[0] + dims[1] * dims[1] + dims[2] * dims[2]) as f64).sqrt() + 1.0;
    let steps = (2.0 * reach / step).ceil() as usize;
    let mut out = Vec::with_capacity(width * height);
    for row in 0..height {
        for col in 0..width {
            let p = frame.pixel_position(c, width, height, col as f64, row as f64);
            let mut sum = 0.0;
            for s in 0..steps {
                let t = -reach + (s as f64 + 0.5) * step;
                let q: [f64; 3] = std::array::from_fn(|a| p[a] + t * frame.dir[a]);
                sum += trilinear(volume, q);
            }
            out.push(sum * step);
        }
    }
    Ok(out)
}

/// Trilinear interpolation of `volume` at `p`, zero outside the samples.
pub fn trilinear(volume: &Volume, p: [f64; 3]) -> f64 {
    let d = volume.dims;
    let f = p.map(f64::floor);
    let mut acc = 0.0;
    for corner in 0..8 {
        let mut w = 1.0;
        let mut idx = [0usize; 3];
        let mut inside = true;
        for a in 0..3 {
            let bit = (corner >> a) & 1;
            let i = f[a] as i64 + bit as i64;
            let frac = p[a] - f[a];
            w *= if bit == 1 { frac } else { 1.0 - frac };
            if i < 0 || i >= d[a] as i64 {
                inside = false;
            } else {
                idx[a] = i as usize;
            }
        }
        if inside && w != 0.0 {
            acc += w * volume.get(idx[0], idx[1], idx[2]) as f64;
        }
    }
    acc
}
