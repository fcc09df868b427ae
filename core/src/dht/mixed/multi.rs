//! True 2D and 3D DHTs in place on per-axis mixed-radix sizes: row–column
//! passes (strided lines gathered into scratch), then the Hao–Bracewell
//! correction.

use super::line::dht_mixed_unchecked;
use super::plan::{mixed_scratch_len, MixedPlan};
use crate::dht::cube::overflow_check;
use crate::dht::store::{Elements, LineStore, Pass};
use crate::error::{check_len, require_len, Error, Result};
use crate::num::{Real, Sample};

/// Index of `−k` modulo `n`, for any `n ≥ 1` and `k < n`.
#[inline(always)]
pub(crate) fn neg_mod_any(k: usize, n: usize) -> usize {
    if k == 0 {
        0
    } else {
        n - k
    }
}

const fn max(a: usize, b: usize) -> usize {
    if a > b {
        a
    } else {
        b
    }
}

/// Scratch elements [`dht_2d_mixed`] needs for an `nx × ny` array
/// (saturating).
pub const fn dht_2d_mixed_scratch_len(nx: usize, ny: usize) -> usize {
    max(
        mixed_scratch_len(nx),
        ny.saturating_add(mixed_scratch_len(ny)),
    )
}

/// Scratch elements [`dht_3d_mixed`] needs for dims `[nx, ny, nz]`: one
/// line and its transform scratch for the x and y passes, four z-lines and
/// one transform scratch for the z pass (saturating).
pub const fn dht_3d_mixed_scratch_len(dims: [usize; 3]) -> usize {
    let [nx, ny, nz] = dims;
    max(
        max(
            nx.saturating_add(mixed_scratch_len(nx)),
            ny.saturating_add(mixed_scratch_len(ny)),
        ),
        nz.saturating_mul(4).saturating_add(mixed_scratch_len(nz)),
    )
}

/// `Ok` if the product of `dims` is `got`; [`Error::LengthMismatch`]
/// otherwise, with `expected` saturated to `usize::MAX` if the product
/// overflows.
fn volume(what: &'static str, dims: &[usize], got: usize) -> Result<()> {
    let v = dims
        .iter()
        .try_fold(1usize, |v, &d| v.checked_mul(d))
        .unwrap_or(usize::MAX);
    check_len(what, v, got)
}

/// True 2D DHT in place of an `nx × ny` array stored with `x` fastest,
/// unnormalized: `H(u,v) = Σ f(x,y) cas(2π(ux/nx + vy/ny))`, each side any
/// `2^a·3^b·5^c`. `plans[0]` is for `nx`, `plans[1]` for `ny` (one plan
/// may serve both).
///
/// Rows are transformed in place, columns gathered into `scratch`; then the
/// correction `H(u,v) = ½[T(u,v) + T(−u,v) + T(u,−v) − T(−u,−v)]` on the
/// separable transform `T`. `scratch` needs
/// [`dht_2d_mixed_scratch_len`]`(nx, ny)` elements.
///
/// # Errors
/// A plan for another length than its axis, a `data` length other than
/// `nx·ny`, or short scratch.
pub fn dht_2d_mixed<T: Real>(
    data: &mut [T],
    nx: usize,
    ny: usize,
    scratch: &mut [T],
    plans: [&MixedPlan<'_, T>; 2],
) -> Result<()> {
    plans[0].check("x-axis plan of the 2D transform", nx)?;
    plans[1].check("y-axis plan of the 2D transform", ny)?;
    volume("2D array", &[nx, ny], data.len())?;
    require_len(
        "2D transform scratch",
        dht_2d_mixed_scratch_len(nx, ny),
        scratch.len(),
    )?;
    for row in data.chunks_exact_mut(nx) {
        dht_mixed_unchecked(row, scratch, plans[0]);
    }
    let (col, rest) = scratch.split_at_mut(ny);
    for x in 0..nx {
        for (c, v) in col.iter_mut().zip(data[x..].iter().step_by(nx)) {
            *c = *v;
        }
        dht_mixed_unchecked(col, rest, plans[1]);
        for (c, v) in col.iter().zip(data[x..].iter_mut().step_by(nx)) {
            *v = *c;
        }
    }
    hao_bracewell_2d(data, nx, ny);
    Ok(())
}

/// The 2D correction in place. Where `u ≡ −u` or `v ≡ −v` the bracket is
/// `2·T(u,v)`, so those points stay; every other group of four shares
/// `S = ½[T(u,v) + T(−u,v) + T(u,−v) + T(−u,−v)]` and each point becomes
/// `S` minus the point diagonally opposite.
fn hao_bracewell_2d<T: Real>(data: &mut [T], nx: usize, ny: usize) {
    for v in 1..ny.div_ceil(2) {
        let vm = ny - v;
        for u in 1..nx.div_ceil(2) {
            let um = nx - u;
            let idx = [u + nx * v, um + nx * v, u + nx * vm, um + nx * vm];
            let [a, b, c, d] = idx.map(|i| data[i]);
            let s = T::HALF * ((a + b) + (c + d));
            for (i, h) in idx.into_iter().zip([s - d, s - c, s - b, s - a]) {
                data[i] = h;
            }
        }
    }
}

/// True 3D DHT in place over stored samples, unnormalized:
/// `H(u,v,w) = Σ f(x,y,z) cas(2π(ux/nx + vy/ny + wz/nz))`, `x` fastest,
/// each side any `2^a·3^b·5^c`, `plans[i]` for `dims[i]`.
///
/// Lines are loaded into `scratch` in `T`, transformed and rounded back to
/// `S` once per pass, as [`crate::dht::dht_3d`] does with
/// [`crate::dht::Rounding::PerPass`]: after the x pass, after the y pass,
/// and after the z pass fused with the Hao–Bracewell correction
/// `H(u,v,w) = ½[T(−u,v,w) + T(u,−v,w) + T(u,v,−w) − T(−u,−v,−w)]` over the
/// four z-lines `(±u, ±v)`. `scratch` needs
/// [`dht_3d_mixed_scratch_len`]`(dims)` elements.
///
/// # Errors
/// A plan for another length than its axis, a `data` length other than
/// `nx·ny·nz`, short scratch, or a value that overflows `S`
/// ([`Error::Overflow`]; the data is then partly transformed).
pub fn dht_3d_mixed<S: Sample, T: Real>(
    data: &mut [S],
    dims: [usize; 3],
    scratch: &mut [T],
    plans: [&MixedPlan<'_, T>; 3],
) -> Result<()> {
    volume("3D array", &dims, data.len())?;
    dht_3d_mixed_store(&mut Elements(data), dims, scratch, plans)
}

/// [`dht_3d_mixed`] over any [`LineStore`] holding `nx·ny·nz` values.
///
/// # Errors
/// As [`dht_3d_mixed`] (the caller checks the storage's length).
pub fn dht_3d_mixed_store<T: Real, L: LineStore<T>>(
    store: &mut L,
    dims: [usize; 3],
    scratch: &mut [T],
    plans: [&MixedPlan<'_, T>; 3],
) -> Result<()> {
    let [nx, ny, nz] = dims;
    if nx.checked_mul(ny).and_then(|p| p.checked_mul(nz)).is_none() {
        return Err(Error::LengthMismatch {
            what: "3D store (nx·ny·nz overflows)",
            expected: usize::MAX,
            got: 0,
        });
    }
    plans[0].check("x-axis plan of the 3D transform", nx)?;
    plans[1].check("y-axis plan of the 3D transform", ny)?;
    plans[2].check("z-axis plan of the 3D transform", nz)?;
    require_len(
        "3D transform scratch",
        dht_3d_mixed_scratch_len(dims),
        scratch.len(),
    )?;

    let mut finite = true;
    // x pass: contiguous lines.
    let (line, rest) = scratch.split_at_mut(nx);
    for row in 0..ny * nz {
        let base = row * nx;
        store.load(Pass::X, base, 1, line);
        dht_mixed_unchecked(line, rest, plans[0]);
        finite &= store.store(Pass::X, base, 1, line);
    }
    overflow_check(finite, "x pass of the 3D transform")?;

    // y pass: lines of stride nx.
    let (line, rest) = scratch.split_at_mut(ny);
    for z in 0..nz {
        for x in 0..nx {
            let base = x + nx * ny * z;
            store.load(Pass::Y, base, nx, line);
            dht_mixed_unchecked(line, rest, plans[1]);
            finite &= store.store(Pass::Y, base, nx, line);
        }
    }
    overflow_check(finite, "y pass of the 3D transform")?;

    // z pass fused with the correction, over groups of four z-lines.
    let plane = nx * ny;
    let (lines, rest) = scratch.split_at_mut(4 * nz);
    for v in 0..=ny / 2 {
        let vm = neg_mod_any(v, ny);
        for u in 0..=nx / 2 {
            let um = neg_mod_any(u, nx);
            // Slot a + 2b holds the line at (a ? −u : u, b ? −v : v); where
            // u ≡ −u or v ≡ −v two slots hold the same line.
            let bases = [u + nx * v, um + nx * v, u + nx * vm, um + nx * vm];
            for (l, base) in lines.chunks_exact_mut(nz).zip(bases) {
                store.load(Pass::Z, base, plane, l);
                dht_mixed_unchecked(l, rest, plans[2]);
            }
            correct_z_lines(lines, nz);
            for (l, base) in lines.chunks_exact(nz).zip(bases) {
                finite &= store.store(Pass::Z, base, plane, l);
            }
        }
    }
    overflow_check(finite, "z pass of the 3D transform")
}

/// The correction on four transformed z-lines (slots as in
/// [`dht_3d_mixed_store`]), for every pair `w`, `−w`: with `t[a + 2b + 4c]`
/// the value at sign bits `a, b, c` for `u, v, w`, each becomes
/// `½[t(i^1) + t(i^2) + t(i^4) − t(i^7)]`. Where two slots or `w ≡ −w`
/// coincide, they receive the same value.
fn correct_z_lines<T: Real>(lines: &mut [T], nz: usize) {
    for w in 0..=nz / 2 {
        let wm = neg_mod_any(w, nz);
        let at = |i: usize| (i & 3) * nz + if i & 4 == 0 { w } else { wm };
        let t: [T; 8] = core::array::from_fn(|i| lines[at(i)]);
        for i in 0..8 {
            lines[at(i)] = T::HALF * (t[i ^ 1] + t[i ^ 2] + t[i ^ 4] - t[i ^ 7]);
        }
    }
}
