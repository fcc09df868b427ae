//! The fixed-point true 3D DHT in place ending with one exponent per
//! x-line: the layout of the Q15 spectra the integer view reads, and the
//! precision of per-line exponents where the dynamic range is largest.

use super::cube::{axis_pass, check_cube};
use super::line::dht;
use super::{peak, round_shift, FixedSample, FixedTwiddles, Shift};
use crate::dht::neg_mod;
use crate::error::{check_len, Error, Result};

/// True 3D DHT in place of an `nx × ny × nz` array, `x` fastest, as
/// [`super::dht_3d`] computes it, but with one exponent per x-line at the
/// end: returns the cube's exponent `e` and leaves in `exponents` (`ny·nz`,
/// one per x-line, line `y + ny·z`) the line's own `e_l`, so that line `l`
/// is `data · 2^(e + e_l)` in the input's units.
///
/// # Order and scaling
/// - The z pass, then the y pass, each stage over the whole cube with one
///   scaling decision ([`axis_pass`]): exponent `e`.
/// - The x pass line by line ([`dht`]): each line scales for its own peak,
///   so a line far below the largest one (high `v`, `w`) shifts its
///   inputs left and keeps its rounding noise relative to itself.
/// - The correction, per group of the four x-lines `(±v, ±w)`, which it
///   combines: the four are aligned to the largest exponent among them
///   (rounded half to even), the group's shift is chosen from its aligned
///   peak, and the four share the result's exponent.
///
/// The spectrum of a volume concentrates its energy with every pass, and a
/// stage's rounding noise scales with the block's peak: so the last pass
/// is the one per-line exponents help most (the first two, with one
/// exponent for the cube, meet a smaller crest factor). Memory: the cube
/// and the exponents, nothing else.
///
/// # Errors
/// A side not a power of two or longer than the table, a `data` length
/// other than `nx·ny·nz`, or `exponents` not `ny·nz` long.
pub fn dht_3d_lines<S: FixedSample>(
    data: &mut [S],
    dims: [usize; 3],
    exponents: &mut [i8],
    tw: &FixedTwiddles<'_, S>,
) -> Result<i32> {
    let [nx, ny, nz] = dims;
    check_cube(data, dims, tw)?;
    check_len("x-line exponents", ny * nz, exponents.len())?;
    let top = peak(data);
    let (z_exp, top) = axis_pass(data, nz, nx * ny, top, tw);
    let (y_exp, _) = axis_pass(data, ny, nx, top, tw);
    for (line, e) in data.chunks_exact_mut(nx).zip(exponents.iter_mut()) {
        *e = to_i8(dht(line, tw)?)?;
    }
    hao_bracewell_lines(data, dims, exponents)?;
    Ok(z_exp + y_exp)
}

/// An exponent as `i8`. Line exponents lie in `[−(F + 2), 2·log₂n + 3]`,
/// so this fails only for lines longer than any table.
fn to_i8(e: i32) -> Result<i8> {
    i8::try_from(e).map_err(|_| Error::FixedPointRange {
        what: "x-line exponent (within i8)",
    })
}

/// The 3D correction of [`super::cube`]'s `hao_bracewell_3d`, on lines
/// with exponents of their own: per group of four x-lines, align, choose
/// the shift, rewrite the eight points `(±u, ±v, ±w)` for every `u`, and
/// give the four lines the group's exponent.
fn hao_bracewell_lines<S: FixedSample>(
    data: &mut [S],
    [nx, ny, nz]: [usize; 3],
    exponents: &mut [i8],
) -> Result<()> {
    // Beyond F + 2 bits every mantissa rounds to 0 alike.
    let max_align = S::FRAC_BITS + 2;
    for w in 0..=nz / 2 {
        let wm = neg_mod(w, nz);
        for v in 0..=ny / 2 {
            let vm = neg_mod(v, ny);
            // Slot b + 2c holds the line at (b ? −v : v, c ? −w : w).
            let lines = [v + ny * w, vm + ny * w, v + ny * wm, vm + ny * wm];
            let exps = lines.map(|l| exponents[l] as i32);
            let peaks = lines.map(|l| peak(&data[l * nx..(l + 1) * nx]));
            // A line of zeros has no say in the alignment.
            let group = (0..4)
                .filter(|&s| peaks[s] > 0)
                .map(|s| exps[s])
                .max()
                .unwrap_or(0);
            let align = exps.map(|e| (group.saturating_sub(e).max(0) as u32).min(max_align));
            let mut top = 0i64;
            for (p, a) in peaks.into_iter().zip(align) {
                // Rounding half to even never exceeds rounding half up.
                let aligned = if a == 0 {
                    p
                } else {
                    (p + (1i64 << (a - 1))) >> a
                };
                top = top.max(aligned);
            }
            let shift = Shift::choose(top, S::LIMITS.hao_bracewell);
            let load = |val: S, a: u32| round_shift(val.widen(), a) << shift.pre;
            for u in 0..=nx / 2 {
                let xs = [u, neg_mod(u, nx)];
                let idx: [usize; 8] = core::array::from_fn(|i| lines[i >> 1] * nx + xs[i & 1]);
                let mut t = [S::Wide::from(0); 8];
                for (i, t) in t.iter_mut().enumerate() {
                    *t = load(data[idx[i]], align[i >> 1]);
                }
                for (i, &k) in idx.iter().enumerate() {
                    let b = t[i ^ 1] + t[i ^ 2] + t[i ^ 4] - t[i ^ 7];
                    data[k] = S::narrow(round_shift(b, 1 + shift.post));
                }
            }
            let e = to_i8(group + shift.exponent())?;
            for l in lines {
                exponents[l] = e;
            }
        }
    }
    Ok(())
}
