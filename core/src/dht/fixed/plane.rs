//! The fixed-point true 2D DHT in place with one block exponent for the
//! whole array, and its inverse (the per-view image transform).

use super::cube::axis_pass;
use super::line::stages;
use super::{peak, round_shift, FixedSample, FixedTwiddles, Shift};
use crate::dht::line::for_each_bit_reversed_swap;
use crate::error::{check_len, Result};

/// True 2D DHT in place of an `nx × ny` array stored with `x` fastest,
/// unnormalized: `H(u,v) = Σ f(x,y) cas(2π(ux/nx + vy/ny))`. Returns the
/// exponent `e`: the transform is `data · 2^e` in the input's units.
///
/// The row pass runs stage by stage over all rows at once and the column
/// pass over whole rows (rows are the elements), so one scaling decision
/// per stage covers the whole block and no scratch is needed. The
/// Hao–Bracewell correction
/// `H(u,v) = ½[T(u,v) + T(−u,v) + T(u,−v) − T(−u,−v)]` follows, with its
/// own shift check.
///
/// # Errors
/// A side not a power of two or longer than the table, or a `data` length
/// other than `nx·ny`.
pub fn dht_2d<S: FixedSample>(
    data: &mut [S],
    nx: usize,
    ny: usize,
    tw: &FixedTwiddles<'_, S>,
) -> Result<i32> {
    tw.check(nx)?;
    tw.check(ny)?;
    check_len("2D array", nx.saturating_mul(ny), data.len())?;
    let top = peak(data);
    let (rows_exp, top) = if nx == ny && nx > 1 {
        // Square: the row pass as a column pass between two transposes
        // (the same butterflies on the same values, so the same result),
        // whose loops over whole rows cost fewer instructions per value.
        transpose(data, nx);
        let pass = columns(data, nx, nx, top, tw);
        transpose(data, nx);
        pass
    } else {
        for row in data.chunks_exact_mut(nx) {
            for_each_bit_reversed_swap(nx, |i, j| row.swap(i, j));
        }
        stages(data, nx, 1, top, tw)
    };
    let (columns_exp, top) = columns(data, nx, ny, top, tw);
    Ok(rows_exp + columns_exp + hao_bracewell(data, nx, ny, top))
}

/// The transforms of all `nx` columns of an `nx × ny` array, rows being
/// the elements: rows to bit-reversed order, then every stage.
fn columns<S: FixedSample>(
    data: &mut [S],
    nx: usize,
    ny: usize,
    top: i64,
    tw: &FixedTwiddles<'_, S>,
) -> (i32, i64) {
    axis_pass(&mut data[..nx * ny], ny, nx, top, tw)
}

/// Transpose an `n × n` array in place.
pub(super) fn transpose<S: Copy>(data: &mut [S], n: usize) {
    for r in 1..n {
        let (above, row) = data.split_at_mut(r * n);
        for (c, v) in row[..r].iter_mut().enumerate() {
            core::mem::swap(v, &mut above[c * n + r]);
        }
    }
}

/// Inverse of [`dht_2d`]: the same transform with `log₂(nx·ny)` taken off
/// the exponent.
///
/// # Errors
/// As [`dht_2d`].
pub fn idht_2d<S: FixedSample>(
    data: &mut [S],
    nx: usize,
    ny: usize,
    tw: &FixedTwiddles<'_, S>,
) -> Result<i32> {
    let exp = dht_2d(data, nx, ny, tw)?;
    Ok(exp - (nx.trailing_zeros() + ny.trailing_zeros()) as i32)
}

/// The correction in place on the separable transform `T` with peak
/// `top`; returns its exponent.
///
/// Where `u ≡ −u` (`u = 0`, `nx/2`) or `v ≡ −v` the bracket is `2·T(u,v)`
/// and the value stays (only the block shift applies); every other group
/// of four takes `½(a + b + c − d)` with `d` the point diagonally opposite,
/// one rounding by `2^(1 + post)`.
fn hao_bracewell<S: FixedSample>(data: &mut [S], nx: usize, ny: usize, top: i64) -> i32 {
    if nx <= 2 || ny <= 2 {
        return 0;
    }
    let shift = Shift::choose(top, S::LIMITS.hao_bracewell);
    let load = |v: S| v.widen() << shift.pre;
    if shift.exponent() != 0 {
        for v in [0, ny / 2] {
            for p in &mut data[v * nx..(v + 1) * nx] {
                *p = S::narrow(round_shift(load(*p), shift.post));
            }
        }
        for v in (1..ny).filter(|&v| v != ny / 2) {
            for u in [0, nx / 2] {
                let p = &mut data[v * nx + u];
                *p = S::narrow(round_shift(load(*p), shift.post));
            }
        }
    }
    let bracket = |a: S, b: S, c: S, d: S| {
        let v = load(a) + load(b) + load(c) - load(d);
        S::narrow(round_shift(v, 1 + shift.post))
    };
    for v in 1..ny / 2 {
        for u in 1..nx / 2 {
            let idx = [
                v * nx + u,
                v * nx + nx - u,
                (ny - v) * nx + u,
                (ny - v) * nx + nx - u,
            ];
            let [a, b, c, d] = [data[idx[0]], data[idx[1]], data[idx[2]], data[idx[3]]];
            data[idx[0]] = bracket(a, b, c, d);
            data[idx[1]] = bracket(b, a, d, c);
            data[idx[2]] = bracket(c, d, a, b);
            data[idx[3]] = bracket(d, c, b, a);
        }
    }
    shift.exponent()
}
