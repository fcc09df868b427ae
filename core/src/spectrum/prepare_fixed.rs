//! Preparation in integers, for cores without an FPU: premultiply an
//! integer volume with a fixed-point table, pad, and take the Q15 3D DHT
//! ([`crate::dht::fixed::dht_3d_lines`]) in place, ending in the Q15 format with
//! one exponent per x-line that the integer view reads.

use super::prepare::{cube_for, premultiplier};
use super::Spectrum;
use crate::dht::fixed::{dht_3d_lines, FixedTwiddles};
use crate::error::{require_len, Error, Result};
use crate::filter::Filter;
use crate::num::{BlockExponents, BlockLayout, Q15};
use crate::volume::DenseVolume;

/// Largest magnitude of a fixed-point premultiplier (and of a Q15
/// mantissa).
const MAX_Q15: i64 = i16::MAX as i64;

/// Where [`Spectrum::prepare_q15`] works and leaves its result.
#[derive(Debug)]
pub struct Q15Storage<'a, 's> {
    /// The cube, `n³`: the padded volume, then the spectrum's mantissas.
    pub mantissas: &'a mut [Q15],
    /// One exponent per x-line of the spectrum, `n²`.
    pub exponents: &'a mut [i8],
    /// The fixed-point premultipliers, `n`.
    pub premul: &'s mut [i32],
}

impl Q15Storage<'_, '_> {
    /// The same buffers, borrowed again for one [`Spectrum::prepare_q15`]
    /// (which takes them by value).
    pub fn reborrow(&mut self) -> Q15Storage<'_, '_> {
        Q15Storage {
            mantissas: self.mantissas,
            exponents: self.exponents,
            premul: self.premul,
        }
    }
}

impl<'a> Spectrum<'a, Q15> {
    /// Premultiply `volume` for `filter`, zero-pad it into the cube of side
    /// [`padded_size`](crate::volume::padded_size)`(dims, filter.oversample())`
    /// (circularly shifted as in [`Spectrum::prepare`]) and take its Q15 3D
    /// DHT in place, all in integers but for the `n` premultipliers.
    ///
    /// # Arithmetic
    /// - *Premultipliers*: `1/ĥ(x/n)` for the `n` signed positions, in f64
    ///   (soft float on a core without an FPU: `2n` filter responses, the
    ///   table computed twice rather than held in f64), then
    ///   `p[x] = round(2^F/ĥ)` with the one `F` for which the largest is in
    ///   `[2^14, 2^15)`: 16-bit signed, within `2^−15` of the largest.
    /// - *Per voxel*, exactly: `P = v·p[x]·(p[y]·p[z])` in `i64` (`v` below
    ///   `2^16`, so `|P| < 2^61`); one pass finds `max|P|`, a second stores
    ///   `q = (P + 2^(k−1)) >> k` (rounded half up) with the smallest `k`
    ///   that keeps `|q| ≤ 2^15 − 1`. So the input is the premultiplied
    ///   volume times `2^(3F−k)`, rounded once to Q15 at full scale.
    /// - *Transform*: [`dht_3d_lines`], exponent `e` for the cube and `e_l`
    ///   for each x-line.
    /// - *Storage*: every x-line shifted left by the most bits that keep it
    ///   within `±(2^15 − 1)` (exact), its exponent lowered as much, as
    ///   [`crate::num::encode_blocks`] would choose it (`−128` for a line of
    ///   zeros). The scale `s = 2^σ` absorbs the rest of the exponent, so
    ///   that the largest line's exponent is near 0: coefficient `i` is
    ///   `m·2^(e_line)/2^15 = s·H`, as [`Spectrum::from_blocks`] reads it.
    ///
    /// `storage.mantissas` needs `n³` elements, `storage.exponents` `n²`,
    /// `storage.premul` `n`; `tw` must serve length `n`. The same code on
    /// the host and on a device gives the same bits.
    ///
    /// # Errors
    /// Short buffers, a twiddle table too short, or a filter response whose
    /// reciprocal is not finite ([`Error::FixedPointRange`]).
    pub fn prepare_q15<V: Copy + Into<f64> + Into<u16>>(
        volume: &DenseVolume<'_, V>,
        filter: Filter,
        storage: Q15Storage<'a, '_>,
        tw: &FixedTwiddles<'_, Q15>,
    ) -> Result<Self> {
        let Q15Storage {
            mantissas,
            exponents,
            premul,
        } = storage;
        let (dims, n, cube) = cube_for(volume, &filter, mantissas.len())?;
        require_len("block exponents", n * n, exponents.len())?;
        require_len("premultiplier table", n, premul.len())?;
        let (mantissas, exponents, premul) = (
            &mut mantissas[..cube],
            &mut exponents[..n * n],
            &mut premul[..n],
        );
        let frac = fixed_premultipliers(&filter, n, premul)?;

        let products = Products {
            voxels: volume.samples(),
            dims,
            n,
            premul,
        };
        let mut top = 0i64;
        products.for_each(|_, p| top = top.max(p.abs()));
        let mut k = 0u32;
        while round_half_up(top, k) > MAX_Q15 {
            k += 1;
        }
        mantissas.fill(Q15(0));
        products.for_each(|i, p| mantissas[i] = Q15(round_half_up(p, k) as i16));

        let e = dht_3d_lines(&mut *mantissas, [n; 3], &mut *exponents, tw)?;
        // The input is `q = g·2^(3F−k)`, so `g = q/2^15 · 2^(k−3F+15)` and
        // line `l` of `H` is `m/2^15 · 2^(whole + e_l)`; `s = 2^σ` brings
        // the largest line's exponent near 0.
        let whole = e + k as i32 - 3 * frac + 15;
        let largest = exponents.iter().map(|&x| x as i32).max().unwrap_or(0);
        let sigma = (-(whole + largest)).clamp(-30, 30);
        let base = whole + sigma;
        for (line, exp) in mantissas.chunks_exact_mut(n).zip(exponents.iter_mut()) {
            *exp = normalize_line(line, base + *exp as i32)?;
        }
        let exponents: &'a [i8] = exponents;
        let blocks = BlockExponents::new(BlockLayout::Line, exponents, n)?;
        Spectrum::from_blocks(mantissas, blocks, n, libm::scalbn(1.0, sigma), filter, dims)
    }
}

/// Every voxel's product `v·p[x]·p[y]·p[z]` with its index in the cube
/// (zero-padded and circularly shifted as in [`Spectrum::prepare`]), in
/// the order of the volume.
struct Products<'v, V> {
    voxels: &'v [V],
    dims: [usize; 3],
    n: usize,
    premul: &'v [i32],
}

impl<V: Copy + Into<u16>> Products<'_, V> {
    /// `f(index, product)` for every voxel; generic, so each pass compiles
    /// to its own loop with `f` inlined.
    #[inline(always)]
    fn for_each(&self, mut f: impl FnMut(usize, i64)) {
        let Self {
            voxels,
            dims,
            n,
            premul,
        } = *self;
        let mask = n - 1;
        let offs = dims.map(|d| d / 2);
        let mut idx = 0;
        for k in 0..dims[2] {
            let pz = (k + n - offs[2]) & mask;
            for j in 0..dims[1] {
                let py = (j + n - offs[1]) & mask;
                let pyz = (premul[py] * premul[pz]) as i64;
                let row = n * (py + n * pz);
                for i in 0..dims[0] {
                    let px = (i + n - offs[0]) & mask;
                    let v: u16 = voxels[idx].into();
                    f(row + px, (v as i32 * premul[px]) as i64 * pyz);
                    idx += 1;
                }
            }
        }
    }
}

/// `(v + 2^(k−1)) >> k`, or `v` for `k = 0`.
#[inline(always)]
fn round_half_up(v: i64, k: u32) -> i64 {
    if k == 0 {
        v
    } else {
        (v + (1 << (k - 1))) >> k
    }
}

/// Fill `out` with `round(2^F/ĥ)` for the `n` signed positions (the table
/// of [`super::premultiplier_table`]) and return `F`, the one for which
/// the largest magnitude is in `[2^14, 2^15)` (rounding clamped to
/// `2^15 − 1`).
fn fixed_premultipliers(filter: &Filter, n: usize, out: &mut [i32]) -> Result<i32> {
    let range = Error::FixedPointRange {
        what: "premultiplier 1/ĥ (finite and within 2^±60)",
    };
    let mut largest = 0.0f64;
    for i in 0..n {
        // One entry at a time (no f64 buffer of `n`), twice: the soft-float
        // cost is `2n` responses, once per volume.
        let p = premultiplier(filter, n, i);
        if !p.is_finite() {
            return Err(range);
        }
        largest = libm::fmax(largest, libm::fabs(p));
    }
    let (_, exp) = libm::frexp(largest);
    // largest = m·2^exp, m ∈ [½, 1): 2^(15 − exp) puts it in [2^14, 2^15).
    let frac = 15 - exp;
    if !(-60..=60).contains(&frac) {
        return Err(range);
    }
    for (i, o) in out.iter_mut().enumerate() {
        let q = libm::round(libm::scalbn(premultiplier(filter, n, i), frac));
        *o = q.clamp(-MAX_Q15 as f64, MAX_Q15 as f64) as i32;
    }
    Ok(frac)
}

/// Shift `line` left by the most bits that keep its peak within
/// `±(2^15 − 1)` and return its exponent `base − shift` (−128 for zeros).
///
/// # Errors
/// An exponent beyond `i8` ([`Error::FixedPointRange`]).
fn normalize_line(line: &mut [Q15], base: i32) -> Result<i8> {
    let top = line.iter().map(|m| (m.0 as i32).abs()).max().unwrap_or(0);
    if top == 0 {
        return Ok(i8::MIN);
    }
    let shift = (top as u32).leading_zeros() - 17;
    for m in line.iter_mut() {
        m.0 <<= shift;
    }
    i8::try_from(base - shift as i32).map_err(|_| Error::FixedPointRange {
        what: "block exponent (within i8)",
    })
}
