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
use fvr_core::num::Real;
use rayon::prelude::*;
use realfft::RealFftPlanner;
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

use crate::dht::real::FftReal;
use crate::dht::store::StoreFormat;

/// A real cube of even side `n` (a power of two or any even length rustfft
/// plans, e.g. `2^a·3^b·5^c`) that is zero except
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
/// spectrum, each in two layouts: `4·(n/2 + 1)·n` complex values) and FFT
/// scratch (at most `2n`) and a line of `n` values.
pub fn tile_bytes<T>(n: usize) -> u64 {
    let complex = 2 * std::mem::size_of::<T>() as u64;
    ((4 * (n / 2 + 1) * n + 3 * n) as u64).saturating_mul(complex)
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
/// If `n` is odd or below 2, or `out` or the row masks have the wrong
/// length.
pub fn dht_3d_real<T: FftReal, S: StoreFormat>(
    cube: &SparseCube<'_, T>,
    out: &mut [S],
) -> Result<(), Error> {
    let n = cube.n;
    assert!(n >= 2 && n % 2 == 0, "side {n}");
    assert_eq!(out.len(), n * n * n);
    assert_eq!(cube.rows_y.len(), n);
    assert_eq!(cube.planes_z.len(), n);
    let h = n / 2 + 1;
    let zero = Complex::new(T::ZERO, T::ZERO);

    let r2c = RealFftPlanner::<T>::new().plan_fft_forward(n);
    let fft = FftPlanner::<T>::new().plan_fft_forward(n);
    let fft_scratch = fft.get_inplace_scratch_len();
    let r2c_scratch = r2c.get_scratch_len();

    // Passes 1 and 2, a z-plane at a time, each plane allocated and written
    // by the thread that transforms it: no separate pass zeroes the half
    // spectrum, and planes the padding leaves zero are not stored.
    let planes: Vec<Vec<Complex<T>>> = (0..n)
        .into_par_iter()
        .map_init(
            || {
                (
                    vec![T::ZERO; n],
                    vec![zero; r2c_scratch.max(fft_scratch)],
                    vec![zero; h * n],
                )
            },
            |(line, scratch, tile), z| {
                if !cube.planes_z[z] {
                    return Vec::new();
                }
                let mut plane = vec![zero; h * n];
                for (y, row) in plane.chunks_exact_mut(h).enumerate() {
                    if cube.rows_y[y] {
                        (cube.fill)(y, z, line);
                        r2c.process_with_scratch(line, row, &mut scratch[..r2c_scratch])
                            .expect("lengths come from the plan");
                    }
                }
                // One line per column u: tile[u·n + y] = plane[y·h + u].
                transpose(|y| &plane[y * h..], n, h, tile, n);
                fft.process_with_scratch(tile, &mut scratch[..fft_scratch]);
                transpose(|u| &tile[u * n..], h, n, &mut plane, h);
                plane
            },
        )
        .collect();
    let zero_row = vec![zero; h];
    // Row y of plane z of the half spectrum, `h` values.
    let half_row = |z: usize, y: usize| -> &[Complex<T>] {
        match planes[z].get(y * h..(y + 1) * h) {
            Some(row) => row,
            None => &zero_row,
        }
    };

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
    let half_row = &half_row;
    let finite = pairs
        .into_par_iter()
        .map_init(
            || {
                (
                    vec![zero; 4 * h * n],
                    vec![zero; fft_scratch],
                    vec![<T as Real>::ZERO; n],
                )
            },
            |(tiles, scratch, line), (v, mut rows, mut rows_m)| {
                let vm = (n - v) % n;
                let (tile, rest) = tiles.split_at_mut(h * n);
                let (tile_m, rest) = rest.split_at_mut(h * n);
                let (rows_v, rows_vm) = rest.split_at_mut(h * n);
                // tile[u·n + z] = F(u, y, z) after the FFT along z, then
                // rows_y[z·h + u] = the same (row by row for the output).
                let mut columns = |tile: &mut [Complex<T>], out: &mut [Complex<T>], y: usize| {
                    transpose(|z| half_row(z, y), n, h, tile, n);
                    fft.process_with_scratch(tile, scratch);
                    transpose(|u| &tile[u * n..], h, n, out, h);
                };
                columns(tile, rows_v, v);
                let rows_vm: &[Complex<T>] = if vm == v {
                    rows_v
                } else {
                    columns(tile_m, rows_vm, vm);
                    rows_vm
                };
                let mut ok = hartley_rows(rows_v, rows_vm, &mut rows, line, n);
                if vm != v {
                    ok &= hartley_rows(rows_vm, rows_v, &mut rows_m, line, n);
                }
                ok
            },
        )
        .reduce(|| true, |a, b| a && b);
    // Freed on all cores: unmapping the planes is a large part too.
    planes.into_par_iter().for_each(drop);
    if finite {
        Ok(())
    } else {
        Err(Error::Overflow {
            stage: "fast 3D transform's rounding to the storage format",
        })
    }
}

/// Output rows `(·, v, w)` for every `w` from the z-transformed columns at
/// `v` (`at`) and at `−v` (`at_m`), each `at[w·h + u] = F(u, ±v, w)` with
/// `h = n/2 + 1`. `false` if a value is not finite in `S`.
fn hartley_rows<T: FftReal, S: StoreFormat>(
    at: &[Complex<T>],
    at_m: &[Complex<T>],
    rows: &mut [&mut [S]],
    line: &mut [T],
    n: usize,
) -> bool {
    let h = n / 2 + 1;
    let mut finite = true;
    for (w, row) in rows.iter_mut().enumerate() {
        let (low, high) = line.split_at_mut(h);
        for (o, c) in low.iter_mut().zip(&at[w * h..(w + 1) * h]) {
            *o = c.re - c.im;
        }
        // u = h + i takes F(n − u, −v, −w): index h − 2 − i of row −w.
        let wm = (n - w) % n;
        let mirror = &at_m[wm * h + 1..wm * h + h - 1];
        for (o, c) in high.iter_mut().zip(mirror.iter().rev()) {
            *o = c.re + c.im;
        }
        finite &= S::store_row(line, row);
    }
    finite
}

/// Rows and columns of the blocks [`transpose`] moves at a time: a block's
/// row of complex f32 values is one 64-byte cache line.
const BLOCK: usize = 8;

/// `dst[c·dst_stride + r] = row(r)[c]` for `r < rows`, `c < cols`, a
/// `BLOCK × BLOCK` block at a time held in registers, so that each side is
/// read and written a line of `BLOCK` values at a time.
fn transpose<'a, C: Copy + 'a>(
    row: impl Fn(usize) -> &'a [C],
    rows: usize,
    cols: usize,
    dst: &mut [C],
    dst_stride: usize,
) {
    let (rows_b, cols_b) = (rows - rows % BLOCK, cols - cols % BLOCK);
    for r0 in (0..rows_b).step_by(BLOCK) {
        let src: [&[C]; BLOCK] = std::array::from_fn(|k| &row(r0 + k)[..cols]);
        for c0 in (0..cols_b).step_by(BLOCK) {
            let block: [[C; BLOCK]; BLOCK] =
                std::array::from_fn(|k| std::array::from_fn(|c| src[k][c0 + c]));
            for c in 0..BLOCK {
                let column: [C; BLOCK] = std::array::from_fn(|k| block[k][c]);
                dst[(c0 + c) * dst_stride + r0..][..BLOCK].copy_from_slice(&column);
            }
        }
        for c in cols_b..cols {
            for (k, line) in src.iter().enumerate() {
                dst[c * dst_stride + r0 + k] = line[c];
            }
        }
    }
    for r in rows_b..rows {
        for (c, &v) in row(r)[..cols].iter().enumerate() {
            dst[c * dst_stride + r] = v;
        }
    }
}
