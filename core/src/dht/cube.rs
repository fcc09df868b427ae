//! The true 3D DHT in place over a [`LineStore`], rounding to the
//! storage once per pass or after every stage.

use super::line::{dht_stages, dht_unchecked};
use super::store::{Elements, LineStore, Pass};
use super::{neg_mod, Twiddles};
use crate::error::{check_len, require_len, Error, Result};
use crate::num::{Real, Sample};

/// Where the 3D transform rounds to the storage format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rounding {
    /// Once per pass: after the x pass, the y pass and the fused z pass.
    PerPass,
    /// Also after every radix-2 butterfly stage of every line, as a
    /// transform computing in the storage format itself would.
    PerStage,
}

/// One line's transform, rounding through the storage after each stage if asked.
#[inline(always)]
fn line_dht<T: Real, L: LineStore<T>>(
    line: &mut [T],
    tw: &Twiddles<'_, T>,
    rounding: Rounding,
    store: &L,
) {
    match rounding {
        Rounding::PerPass => dht_unchecked(line, tw),
        Rounding::PerStage => dht_stages(line, tw, |l| store.round(l)),
    }
}

/// Scratch elements [`dht_3d`] needs for dims `[nx, ny, nz]`.
pub const fn dht_3d_scratch_len(dims: [usize; 3]) -> usize {
    let a = if dims[0] > dims[1] { dims[0] } else { dims[1] };
    let b = 4 * dims[2];
    if a > b {
        a
    } else {
        b
    }
}

/// True 3D DHT in place over stored samples, unnormalized:
/// `H(u,v,w) = Σ f(x,y,z) cas(2π(ux/nx + vy/ny + wz/nz))`, `x` fastest.
///
/// Lines are loaded into `scratch` in the arithmetic type `T`, transformed
/// and rounded back to `S`, to nearest even. There are three roundings:
/// after the x pass, after the y pass, and after the z pass fused with the
/// Hao–Bracewell correction
/// `H(u,v,w) = ½[T(−u,v,w) + T(u,−v,w) + T(u,v,−w) − T(−u,−v,−w)]`, which
/// loads the four z-lines `(±u, ±v)` together so that the correction works
/// on unrounded values. `scratch` needs [`dht_3d_scratch_len`] elements,
/// `4·nz` for a cube: O(n), however large the volume.
///
/// # Errors
/// A side not a power of two or longer than the table, a `data` length other
/// than `nx·ny·nz`, short scratch, or a value that overflows `S`
/// ([`Error::Overflow`]; the data is then partly transformed).
pub fn dht_3d<S: Sample, T: Real>(
    data: &mut [S],
    dims: [usize; 3],
    scratch: &mut [T],
    tw: &Twiddles<'_, T>,
) -> Result<()> {
    dht_3d_rounding(data, dims, scratch, tw, Rounding::PerPass)
}

/// [`dht_3d`] with a choice of where to round ([`Rounding`]). With
/// [`Rounding::PerStage`] every line is also rounded to `S` after each of its
/// `log₂n` stages, which models arithmetic in the storage format.
///
/// # Errors
/// As [`dht_3d`].
pub fn dht_3d_rounding<S: Sample, T: Real>(
    data: &mut [S],
    dims: [usize; 3],
    scratch: &mut [T],
    tw: &Twiddles<'_, T>,
    rounding: Rounding,
) -> Result<()> {
    let [nx, ny, nz] = dims;
    check_len("3D array", nx * ny * nz, data.len())?;
    dht_3d_store(&mut Elements(data), dims, scratch, tw, rounding)
}

/// [`dht_3d_rounding`] over any [`LineStore`] holding `nx·ny·nz` values.
///
/// # Errors
/// As [`dht_3d`] (the caller checks the storage's length).
pub fn dht_3d_store<T: Real, L: LineStore<T>>(
    store: &mut L,
    dims: [usize; 3],
    scratch: &mut [T],
    tw: &Twiddles<'_, T>,
    rounding: Rounding,
) -> Result<()> {
    let [nx, ny, nz] = dims;
    for n in dims {
        tw.check(n)?;
    }
    require_len(
        "3D transform scratch",
        dht_3d_scratch_len(dims),
        scratch.len(),
    )?;

    let mut finite = true;
    // x pass: contiguous lines.
    let line = &mut scratch[..nx];
    for row in 0..ny * nz {
        let base = row * nx;
        store.load(Pass::X, base, 1, line);
        line_dht(line, tw, rounding, store);
        finite &= store.store(Pass::X, base, 1, line);
    }
    overflow_check(finite, "x pass of the 3D transform")?;

    // y pass: lines of stride nx.
    let line = &mut scratch[..ny];
    for z in 0..nz {
        for x in 0..nx {
            let base = x + nx * ny * z;
            store.load(Pass::Y, base, nx, line);
            line_dht(line, tw, rounding, store);
            finite &= store.store(Pass::Y, base, nx, line);
        }
    }
    overflow_check(finite, "y pass of the 3D transform")?;

    // z pass fused with the correction, over groups of four z-lines.
    let plane = nx * ny;
    let lines = &mut scratch[..4 * nz];
    for v in 0..=ny / 2 {
        let vm = neg_mod(v, ny);
        for u in 0..=nx / 2 {
            let um = neg_mod(u, nx);
            // Slot s = a + 2b holds the line at (a ? −u : u, b ? −v : v).
            let bases = [u + nx * v, um + nx * v, u + nx * vm, um + nx * vm];
            for (slot, base) in bases.iter().enumerate() {
                let l = &mut lines[slot * nz..(slot + 1) * nz];
                store.load(Pass::Z, *base, plane, l);
                line_dht(l, tw, rounding, store);
            }
            for w in 0..=nz / 2 {
                let wm = neg_mod(w, nz);
                // t[a + 2b + 4c]: sign bits a, b, c for u, v, w.
                let mut t = [T::ZERO; 8];
                for (i, e) in t.iter_mut().enumerate() {
                    let z = if i & 4 == 0 { w } else { wm };
                    *e = lines[(i & 3) * nz + z];
                }
                for (i, _) in t.iter().enumerate() {
                    let h = T::HALF * (t[i ^ 1] + t[i ^ 2] + t[i ^ 4] - t[i ^ 7]);
                    let z = if i & 4 == 0 { w } else { wm };
                    lines[(i & 3) * nz + z] = h;
                }
            }
            for (slot, base) in bases.iter().enumerate() {
                let l = &lines[slot * nz..(slot + 1) * nz];
                finite &= store.store(Pass::Z, *base, plane, l);
            }
        }
    }
    overflow_check(finite, "z pass of the 3D transform")
}

pub(crate) fn overflow_check(finite: bool, stage: &'static str) -> Result<()> {
    if finite {
        Ok(())
    } else {
        Err(overflow(stage))
    }
}

#[cold]
fn overflow(stage: &'static str) -> Error {
    Error::Overflow { stage }
}
