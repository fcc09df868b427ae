//! The true 3D DHT of a real cube through FFTs, on all cores, rounding once
//! to the storage format: the host's fast alternative to the core's in-place
//! transform ([`fvr_core::dht::dht_3d`]), with the same normalization and
//! index order.
//!
//! With the DFT `F(k) = Σ f(x) e^{−2πi k·x/n}`, the DHT
//! `H(k) = Σ f(x) cas(2π k·x/n)` is `Re F(k) − Im F(k)`. Since `f` is real,
//! `F(−k) = conj F(k)`, so the half spectrum `u ≤ n/2` determines all of
//! `H`: for `u > n/2`, `H(u, v, w) = Re F(n−u, −v, −w) + Im F(n−u, −v, −w)`.
//!
//! Three passes over a complex half spectrum laid out `[z][y][u]`:
//! 1. real FFT along x of every row that holds data (rows left zero by the
//!    padding stay zero and are skipped);
//! 2. FFT along y of every z-plane that holds data, a plane at a time;
//! 3. FFT along z, one pair of y-columns `{v, −v}` at a time, fused with the
//!    Hartley map and the rounding to `S`, written straight to the output.
//!
//! Strided columns are gathered into a contiguous tile (one line per column),
//! transformed together and, for pass 2, scattered back.

use fvr_core::error::Error;
use fvr_core::num::{Real, Sample};
use rayon::prelude::*;
use realfft::RealFftPlanner;
use rustfft::num_complex::Complex;
use rustfft::{FftNum, FftPlanner};

/// Arithmetic the fast transform runs in: f32 or f64.
pub trait FastReal: Real + FftNum {}
impl<T: Real + FftNum> FastReal for T {}

/// A real cube of side `n` (a power of two, at least 2) that is zero except
/// on the rows `(y, z)` with `rows_y[y] && planes_z[z]`, whose x-lines
/// `fill(y, z, line)` writes (all `n` values).
pub struct SparseCube<'a, T> {
    /// Side of the cube.
    pub n: usize,
    /// Which `y` hold data.
    pub rows_y: &'a [bool],
    /// Which `z` hold data.
    pub planes_z: &'a [bool],
    /// Writes the x-line at `(y, z)`.
    pub fill: &'a (dyn Fn(usize, usize, &mut [T]) + Sync),
}

/// Bytes of the transient complex half spectrum for side `n` in `T`:
/// `(n/2 + 1)·n²` complex values, about `4n³` bytes in f32.
pub fn half_spectrum_bytes<T>(n: usize) -> u64 {
    let h = (n / 2 + 1) as u64;
    let n = n as u64;
    h.saturating_mul(n)
        .saturating_mul(n)
        .saturating_mul(2 * std::mem::size_of::<T>() as u64)
}

/// Bytes of one thread's tiles in pass 3 (two y-columns of the half
/// spectrum, `2·(n/2 + 1)·n` complex values) and FFT scratch (at most `n`).
pub fn tile_bytes<T>(n: usize) -> u64 {
    let complex = 2 * std::mem::size_of::<T>() as u64;
    ((2 * (n / 2 + 1) * n + 2 * n) as u64).saturating_mul(complex)
}

/// `H(u, v, w) = Σ f(x, y, z) cas(2π(ux + vy + wz)/n)`, unnormalized, into
/// `out` (`n³` values, x fastest), each rounded once from `T` to `S`.
///
/// Allocates the half spectrum ([`half_spectrum_bytes`]) and per-thread
/// tiles ([`tile_bytes`]); the caller checks them against the memory budget.
///
/// # Errors
/// A coefficient not finite in `S` ([`Error::Overflow`]).
///
/// # Panics
/// If `n` is not a power of two at least 2, or `out` or the row masks have
/// the wrong length.
pub fn dht_3d_real<T: FastReal, S: Sample>(
    cube: &SparseCube<'_, T>,
    out: &mut [S],
) -> Result<(), Error> {
    let n = cube.n;
    assert!(n >= 2 && n.is_power_of_two(), "side {n}");
    assert_eq!(out.len(), n * n * n);
    assert_eq!(cube.rows_y.len(), n);
    assert_eq!(cube.planes_z.len(), n);
    let h = n / 2 + 1;
    let zero = Complex::new(T::ZERO, T::ZERO);
    let mut half = vec![zero; h * n * n];

    let r2c = RealFftPlanner::<T>::new().plan_fft_forward(n);
    let fft = FftPlanner::<T>::new().plan_fft_forward(n);
    let fft_scratch = fft.get_inplace_scratch_len();
    let r2c_scratch = r2c.get_scratch_len();

    // Passes 1 and 2, a z-plane at a time.
    half.par_chunks_mut(h * n)
        .enumerate()
        .filter(|(z, _)| cube.planes_z[*z])
        .for_each_init(
            || {
                (
                    vec![T::ZERO; n],
                    vec![zero; r2c_scratch.max(fft_scratch)],
                    vec![zero; h * n],
                )
            },
            |(line, scratch, tile), (z, plane)| {
                for (y, row) in plane.chunks_exact_mut(h).enumerate() {
                    if cube.rows_y[y] {
                        (cube.fill)(y, z, line);
                        r2c.process_with_scratch(line, row, &mut scratch[..r2c_scratch])
                            .expect("lengths come from the plan");
                    }
                }
                // tile[u·n + y] = plane[y·h + u]: one line per column u.
                for (y, row) in plane.chunks_exact(h).enumerate() {
                    for (u, &c) in row.iter().enumerate() {
                        tile[u * n + y] = c;
                    }
                }
                fft.process_with_scratch(tile, &mut scratch[..fft_scratch]);
                for (y, row) in plane.chunks_exact_mut(h).enumerate() {
                    for (u, c) in row.iter_mut().enumerate() {
                        *c = tile[u * n + y];
                    }
                }
            },
        );

    // Pass 3. Output rows grouped by v (row index v + n·w), in w order.
    let mut by_v: Vec<Vec<&mut [S]>> = (0..n).map(|_| Vec::with_capacity(n)).collect();
    for (r, row) in out.chunks_exact_mut(n).enumerate() {
        by_v[r % n].push(row);
    }
    let mut pairs = Vec::with_capacity(h);
    for v in 0..h {
        let vm = (n - v) % n;
        let rows = std::mem::take(&mut by_v[v]);
        let rows_m = if vm == v {
            Vec::new()
        } else {
            std::mem::take(&mut by_v[vm])
        };
        pairs.push((v, rows, rows_m));
    }
    let half = &half;
    let finite = pairs
        .into_par_iter()
        .map_init(
            || (vec![zero; 2 * h * n], vec![zero; fft_scratch]),
            |(tiles, scratch), (v, mut rows, mut rows_m)| {
                let vm = (n - v) % n;
                let (tile, tile_m) = tiles.split_at_mut(h * n);
                let columns = |t: &mut [Complex<T>], y: usize| {
                    // t[u·n + z] = F(u, y, z) after the FFT along z.
                    for z in 0..n {
                        let row = &half[(z * n + y) * h..(z * n + y + 1) * h];
                        for (u, &c) in row.iter().enumerate() {
                            t[u * n + z] = c;
                        }
                    }
                };
                columns(tile, v);
                fft.process_with_scratch(tile, scratch);
                let tile_m: &[Complex<T>] = if vm == v {
                    tile
                } else {
                    columns(tile_m, vm);
                    fft.process_with_scratch(tile_m, scratch);
                    tile_m
                };
                let mut ok = hartley_rows(tile, tile_m, &mut rows, n);
                if vm != v {
                    ok &= hartley_rows(tile_m, tile, &mut rows_m, n);
                }
                ok
            },
        )
        .reduce(|| true, |a, b| a && b);
    if finite {
        Ok(())
    } else {
        Err(Error::Overflow {
            stage: "rounding the fast 3D transform to the storage format",
        })
    }
}

/// Output rows `(·, v, w)` for every `w` from the z-transformed columns at
/// `v` (`tile`) and at `−v` (`tile_m`), each `tile[u·n + w] = F(u, ±v, w)`.
/// `false` if a value is not finite in `S`.
fn hartley_rows<T: FastReal, S: Sample>(
    tile: &[Complex<T>],
    tile_m: &[Complex<T>],
    rows: &mut [&mut [S]],
    n: usize,
) -> bool {
    let half = n / 2;
    let mut finite = true;
    for (w, row) in rows.iter_mut().enumerate() {
        let wm = (n - w) % n;
        for u in 0..=half {
            let c = tile[u * n + w];
            let s: S = (c.re - c.im).store();
            finite &= s.is_finite();
            row[u] = s;
        }
        for u in half + 1..n {
            let c = tile_m[(n - u) * n + wm];
            let s: S = (c.re + c.im).store();
            finite &= s.is_finite();
            row[u] = s;
        }
    }
    finite
}
