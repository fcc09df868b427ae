//! The fixed-point true 3D DHT in place with one block exponent for the
//! whole cube, and its inverse (the device preparation's transform).

use super::line::stages;
use super::plane::transpose;
use super::{peak, round_shift, FixedSample, FixedTwiddles, Shift};
use crate::dht::line::for_each_bit_reversed_swap;
use crate::dht::neg_mod;
use crate::error::{check_len, Result};

/// True 3D DHT in place of an `nx × ny × nz` array stored with `x` fastest,
/// unnormalized: `H(u,v,w) = Σ f(x,y,z) cas(2π(ux/nx + vy/ny + wz/nz))`.
/// Returns the exponent `e`: the transform is `data · 2^e` in the input's
/// units (for a Q15 input `m/2^15`, the output is `m'/2^15 · 2^e`).
///
/// # Scaling: one exponent per stage, for the whole cube
/// Each radix-2 stage of each pass runs over the whole cube at once (the
/// x lines laid end to end, then the y and z lines with whole rows and
/// whole planes as the elements, see [`stages`]), so one scaling decision
/// per stage ([`Shift`]) covers every value and no scratch is needed. The
/// separable transform `T` is then corrected in place (Hao–Bracewell in
/// three dimensions) with its own shift check:
/// `H(u,v,w) = ½[T(−u,v,w) + T(u,−v,w) + T(u,v,−w) − T(−u,−v,−w)]`.
///
/// One exponent needs no table and no alignment: the cube and a few words
/// of stack. A volume's spectrum concentrates its energy with every pass,
/// and each stage's rounding noise scales with the cube's peak, so
/// [`super::dht_3d_lines`], which ends with one exponent per x-line, keeps
/// more there (a ball at 32³: 62.8 dB against 48.0 dB).
///
/// # Errors
/// A side not a power of two or longer than the table, or a `data` length
/// other than `nx·ny·nz`.
pub fn dht_3d<S: FixedSample>(
    data: &mut [S],
    [nx, ny, nz]: [usize; 3],
    tw: &FixedTwiddles<'_, S>,
) -> Result<i32> {
    check_cube(data, [nx, ny, nz], tw)?;
    let top = peak(data);
    let (x_exp, top) = if nx == ny && nx > 1 {
        // Square planes: the x pass as a pass over whole rows between two
        // transposes of every plane (the same butterflies on the same
        // values, so the same result), whose loops cost fewer instructions
        // per value than lines of stride 1.
        let plane = nx * ny;
        data.chunks_exact_mut(plane).for_each(|p| transpose(p, nx));
        let pass = axis_pass(data, ny, nx, top, tw);
        data.chunks_exact_mut(plane).for_each(|p| transpose(p, nx));
        pass
    } else {
        axis_pass(data, nx, 1, top, tw)
    };
    let (y_exp, top) = axis_pass(data, ny, nx, top, tw);
    let (z_exp, top) = axis_pass(data, nz, nx * ny, top, tw);
    Ok(x_exp + y_exp + z_exp + hao_bracewell_3d(data, [nx, ny, nz], top))
}

/// Inverse of [`dht_3d`]: the same transform with `log₂(nx·ny·nz)` taken
/// off the exponent (the `1/N` is exact in block floating point).
///
/// # Errors
/// As [`dht_3d`].
pub fn idht_3d<S: FixedSample>(
    data: &mut [S],
    dims: [usize; 3],
    tw: &FixedTwiddles<'_, S>,
) -> Result<i32> {
    let exp = dht_3d(data, dims, tw)?;
    let bits: u32 = dims.iter().map(|n| n.trailing_zeros()).sum();
    Ok(exp - bits as i32)
}

/// The checks of [`dht_3d`] and `dht_3d_lines`: every side a power of
/// two the table serves, and `data` of `nx·ny·nz` values.
pub(super) fn check_cube<S: FixedSample>(
    data: &[S],
    dims: [usize; 3],
    tw: &FixedTwiddles<'_, S>,
) -> Result<()> {
    for n in dims {
        tw.check(n)?;
    }
    let [nx, ny, nz] = dims;
    check_len(
        "3D array",
        nx.saturating_mul(ny).saturating_mul(nz),
        data.len(),
    )
}

/// The length-`n` transforms along one axis of every block of `n·w`
/// values in `data` (`w = 1`: lines laid end to end; `w` the row length:
/// the columns of every plane; `w` the plane size: the z lines of the
/// cube): each block's groups of `w` to bit-reversed order, then every
/// stage over all blocks at once. `top` is the peak of `data`; returns the
/// summed exponent and the final peak.
pub(super) fn axis_pass<S: FixedSample>(
    data: &mut [S],
    n: usize,
    w: usize,
    top: i64,
    tw: &FixedTwiddles<'_, S>,
) -> (i32, i64) {
    for block in data.chunks_exact_mut(n * w) {
        for_each_bit_reversed_swap(n, |i, j| {
            let (head, tail) = block.split_at_mut(j * w);
            head[i * w..(i + 1) * w].swap_with_slice(&mut tail[..w]);
        });
    }
    stages(data, n, w, top, tw)
}

/// The 3D correction in place on the separable transform `T` with peak
/// `top`; returns its exponent.
///
/// The eight points `(±u, ±v, ±w)` are loaded together and rewritten from
/// the loaded values: point `i` (bit 0, 1, 2 set for `−u`, `−v`, `−w`)
/// becomes `½(t[i^1] + t[i^2] + t[i^4] − t[i^7])`, one rounding by
/// `2^(1 + post)`. Where an index is its own negative (0 or the half
/// length) two of the eight coincide and get the same value, so a repeated
/// write is harmless; where all three are, the bracket is `2·t` and the
/// value stays (only the block shift applies). `|bracket| ≤ 4M`, the bound
/// of the 2D correction, so its limits ([`super::Limits`]) serve here.
fn hao_bracewell_3d<S: FixedSample>(data: &mut [S], [nx, ny, nz]: [usize; 3], top: i64) -> i32 {
    let shift = Shift::choose(top, S::LIMITS.hao_bracewell);
    let load = |v: S| v.widen() << shift.pre;
    let plane = nx * ny;
    for w in 0..=nz / 2 {
        let zs = [w, neg_mod(w, nz)].map(|z| z * plane);
        for v in 0..=ny / 2 {
            let ys = [v, neg_mod(v, ny)].map(|y| y * nx);
            for u in 0..=nx / 2 {
                let xs = [u, neg_mod(u, nx)];
                let idx: [usize; 8] =
                    core::array::from_fn(|i| xs[i & 1] + ys[(i >> 1) & 1] + zs[i >> 2]);
                let mut t = [S::Wide::from(0); 8];
                for (t, &k) in t.iter_mut().zip(&idx) {
                    *t = load(data[k]);
                }
                for (i, &k) in idx.iter().enumerate() {
                    let b = t[i ^ 1] + t[i ^ 2] + t[i ^ 4] - t[i ^ 7];
                    data[k] = S::narrow(round_shift(b, 1 + shift.post));
                }
            }
        }
    }
    shift.exponent()
}
