//! The true 2D DHT in place: batched row and column passes (square arrays
//! between two in-place transposes), then the Hao–Bracewell correction.

use super::line::butterfly_pair;
use super::line::{dht_unchecked, for_each_bit_reversed_swap};
use super::sparse::sparse_rows;
use super::Twiddles;
use crate::error::{check_len, require_len, Result};
use crate::num::Real;

/// True 2D DHT in place of an `nx × ny` array stored with `x` fastest,
/// unnormalized: `H(u,v) = Σ f(x,y) cas(2π(ux/nx + vy/ny))`.
///
/// Row and column passes give the separable `T = cas⊗cas` transform; the
/// Hao–Bracewell correction `H(u,v) = ½[T(u,v) + T(−u,v) + T(u,−v) − T(−u,−v)]`
/// then runs in place over each group of four symmetric points.
///
/// The column pass is *batched*: its radix-2 stages run over whole rows at
/// once (every butterfly of a stage applies one twiddle pair to `nx`
/// contiguous columns), so nothing is copied, each twiddle is looked up
/// once per row pair instead of once per column, and the inner loop
/// vectorizes. Square arrays get their row pass the same way, between two
/// in-place transposes. Every value goes through exactly the arithmetic of
/// [`dht_2d_lines`] (the same butterflies on the same operands), so the two
/// agree bit for bit. `column` (at least `ny` elements, the line path's
/// scratch) is not needed for that. A square array from side 128 whose
/// nonzero values lie on at most a quarter of its rows (an adaptive view's
/// slice) transforms only those rows in its row pass: batched, as the
/// lanes of one column transform in `column`, when `column` holds
/// [`dht_2d_sparse_len`](super::dht_2d_sparse_len) elements, else one by one.
///
/// # Errors
/// A side not a power of two or longer than the table, a `data` length other
/// than `nx·ny`, or short scratch.
#[inline(always)]
pub fn dht_2d<T: Real>(
    data: &mut [T],
    nx: usize,
    ny: usize,
    column: &mut [T],
    tw: &Twiddles<'_, T>,
) -> Result<()> {
    check_2d(data, nx, ny, column, tw)?;
    if nx == ny && (4..TILED_TRANSPOSE_FROM).contains(&nx) {
        dht_2d_square(data, nx, tw);
    } else {
        if nx == ny {
            if !sparse_rows(data, nx, column, tw) {
                transpose_square(data, nx);
                dht_columns(data, nx, ny, tw);
                transpose_square(data, nx);
            }
        } else {
            for row in data.chunks_exact_mut(nx) {
                dht_unchecked(row, tw);
            }
        }
        dht_columns(data, nx, ny, tw);
        hao_bracewell_2d(data, nx, ny);
    }
    Ok(())
}

/// The square path of [`dht_2d`] for `4 ≤ n < 128`. (Compiling it once per
/// side, with `n` a constant, took the M4F's 64 × 64 transform from 186 k
/// to 164 k instructions for about 25 KB of code with every side below 128,
/// or a special case of one size; not done.)
///
/// The first transpose also bit-reverses both indices: rows come out in
/// the order the column pass wants, and its output columns in the
/// bit-reversed row order the second pass wants after a plain transpose,
/// so no pass reorders rows on its own. Each transpose also does the first
/// two (untwiddled) stages of the pass after it.
#[inline]
fn dht_2d_square<T: Real>(data: &mut [T], n: usize, tw: &Twiddles<'_, T>) {
    transpose_square_bit_reversed_radix4(data, n);
    dht_columns_stages(data, n, n, 4, tw);
    transpose_square_plain_radix4(data, n);
    dht_columns_stages(data, n, n, 4, tw);
    hao_bracewell_2d(data, n, n);
}

/// [`dht_2d`] line by line: each row transformed in place, then each
/// column copied to `column` (`ny` elements), transformed and copied back.
/// The reference for the batched path and the smallest code.
///
/// # Errors
/// As [`dht_2d`].
pub fn dht_2d_lines<T: Real>(
    data: &mut [T],
    nx: usize,
    ny: usize,
    column: &mut [T],
    tw: &Twiddles<'_, T>,
) -> Result<()> {
    check_2d(data, nx, ny, column, tw)?;
    for row in data.chunks_exact_mut(nx) {
        dht_unchecked(row, tw);
    }
    let col = &mut column[..ny];
    for x in 0..nx {
        for (y, c) in col.iter_mut().enumerate() {
            *c = data[x + nx * y];
        }
        dht_unchecked(col, tw);
        for (y, c) in col.iter().enumerate() {
            data[x + nx * y] = *c;
        }
    }
    hao_bracewell_2d(data, nx, ny);
    Ok(())
}

/// The checks of [`dht_2d`] and [`dht_2d_lines`].
#[inline(always)]
fn check_2d<T: Real>(
    data: &[T],
    nx: usize,
    ny: usize,
    column: &[T],
    tw: &Twiddles<'_, T>,
) -> Result<()> {
    tw.check(nx)?;
    tw.check(ny)?;
    check_len("2D array", nx * ny, data.len())?;
    require_len("column scratch", ny, column.len())
}

/// `H(u,v) = ½[T(u,v) + T(−u,v) + T(u,−v) − T(−u,−v)]` in place.
///
/// Where `u ≡ −u` (`u = 0`, `nx/2`) or `v ≡ −v` the bracket is `2·T(u,v)`
/// exactly, so those rows and columns stay as they are. Every other group
/// of four points shares `S = ½[T(u,v) + T(−u,v) + T(u,−v) + T(−u,−v)]`,
/// and each point's value is `S` minus the point diagonally opposite
/// (`H(u,v) = S − T(−u,−v)`, …): 8 operations instead of 16. Rows `v` and
/// `ny − v` go together, with `u` and `nx − u` walked from both ends.
#[inline]
fn hao_bracewell_2d<T: Real>(data: &mut [T], nx: usize, ny: usize) {
    if nx <= 2 || ny <= 2 {
        return;
    }
    let h = nx / 2;
    for v in 1..ny / 2 {
        let (top, bottom) = data.split_at_mut((ny - v) * nx);
        let (lo_v, hi_v) = split_row(&mut top[v * nx..(v + 1) * nx], h);
        let (lo_m, hi_m) = split_row(&mut bottom[..nx], h);
        // Four groups at a time: `u` ascending in chunks from the front of
        // `lo_*`, `nx − u` descending in chunks from the back of `hi_*`.
        let mut streams = [lo_v, hi_v, lo_m, hi_m];
        for _ in 0..streams[0].len() / 4 {
            let [lo_v, hi_v, lo_m, hi_m] = &mut streams;
            let (lo_v, hi_v) = (take_first4(lo_v), take_last4(hi_v));
            let (lo_m, hi_m) = (take_first4(lo_m), take_last4(hi_m));
            for k in 0..4 {
                hao_bracewell_group(
                    &mut lo_v[k],
                    &mut hi_v[3 - k],
                    &mut lo_m[k],
                    &mut hi_m[3 - k],
                );
            }
        }
        let [lo_v, hi_v, lo_m, hi_m] = streams;
        let rest = lo_v.len();
        let (hi_v, lo_m, hi_m) = (&mut hi_v[..rest], &mut lo_m[..rest], &mut hi_m[..rest]);
        for j in 0..rest {
            let r = rest - 1 - j;
            hao_bracewell_group(&mut lo_v[j], &mut hi_v[r], &mut lo_m[j], &mut hi_m[r]);
        }
    }
}

/// The first four values of `*s`, which then starts after them.
#[inline(always)]
fn take_first4<'a, T>(s: &mut &'a mut [T]) -> &'a mut [T; 4] {
    match core::mem::take(s).split_first_chunk_mut::<4>() {
        Some((chunk, tail)) => {
            *s = tail;
            chunk
        }
        None => chunk_out_of_range(),
    }
}

/// The last four values of `*s`, which then ends before them.
#[inline(always)]
fn take_last4<'a, T>(s: &mut &'a mut [T]) -> &'a mut [T; 4] {
    match core::mem::take(s).split_last_chunk_mut::<4>() {
        Some((head, chunk)) => {
            *s = head;
            chunk
        }
        None => chunk_out_of_range(),
    }
}

#[cold]
fn chunk_out_of_range() -> ! {
    panic!("chunk of four past the end of its slice")
}

/// The correction on one group: `a, b, c, d` at `(u, v)`, `(−u, v)`,
/// `(u, −v)`, `(−u, −v)`.
#[inline(always)]
fn hao_bracewell_group<T: Real>(a: &mut T, b: &mut T, c: &mut T, d: &mut T) {
    let s = T::HALF * ((*a + *b) + (*c + *d));
    (*a, *b, *c, *d) = (s - *d, s - *c, s - *b, s - *a);
}

/// Columns `1..h` and `h+1..2h` of a row of `2h`.
#[inline(always)]
fn split_row<T>(row: &mut [T], h: usize) -> (&mut [T], &mut [T]) {
    let (lo, hi) = row.split_at_mut(h);
    (&mut lo[1..], &mut hi[1..])
}

/// Side from which [`transpose_square`] works in tiles.
const TILED_TRANSPOSE_FROM: usize = 128;

/// Transpose an `n × n` array in place: row by row below `n = 128`, in
/// tiles of 16 × 16 from there (a row-by-row transpose walks one side with
/// a stride of `n` and misses the cache on every element once rows outgrow
/// it; on a cacheless core the plain loop costs fewer instructions).
#[inline]
fn transpose_square<T>(data: &mut [T], n: usize) {
    const TILE: usize = 16;
    if n < TILED_TRANSPOSE_FROM || n % TILE != 0 {
        swap_across_diagonal(data, n, |i| i);
        return;
    }
    for bi in (0..n).step_by(TILE) {
        for bj in (bi..n).step_by(TILE) {
            for i in bi..bi + TILE {
                let first = if bi == bj { i + 1 } else { bj };
                for j in first..bj + TILE {
                    data.swap(i * n + j, j * n + i);
                }
            }
        }
    }
}

/// `data[r][c] ← data[rev c][rev r]` in place for an `n × n` array (`n` a
/// power of two, at least 4, `rev` reversing `log₂n` bits), then the first
/// two (untwiddled) stages of [`dht_columns_stages`] on every group of
/// four rows `4t .. 4t+3`.
///
/// The permutation is a transpose that also puts rows and columns in
/// bit-reversed order. The groups of four rows are closed under it in
/// 4 × 4 tiles (`rev(4t + j) = rev(4t) + rev(j)` for `j < 4`), so each
/// value is loaded and stored once for both. Since `rev(4t) < n/4` and
/// `rev(j)` is a whole number of quarters, a tile's values sit at one
/// index of sixteen quarter rows, and one bounds check covers them all.
#[inline]
fn transpose_square_bit_reversed_radix4<T: Real>(data: &mut [T], n: usize) {
    const B: usize = 4;
    // Quarter holding column rev(4t) + rev(j): rev(j) = QUARTER_OF[j]·n/4.
    const QUARTER_OF: [usize; B] = [0, 2, 1, 3];
    let quarter = n / B;
    let shift = usize::BITS - quarter.trailing_zeros();
    let rev4 = |t: usize| t.reverse_bits().checked_shr(shift).unwrap_or(0);
    for rt in 0..n / B {
        let (above, below) = data.split_at_mut(B * rt * n);
        let band = quarters(&mut below[..B * n], n);
        let pr = rev4(rt);
        if pr >= quarter {
            return;
        }
        let tile: [[T; B]; B] =
            core::array::from_fn(|i| core::array::from_fn(|j| band[i][QUARTER_OF[j]][pr]));
        for (j, column) in tile.iter().enumerate() {
            for (i, v) in radix4_plain(*column).into_iter().enumerate() {
                band[i][QUARTER_OF[j]][pr] = v;
            }
        }
        for (st, other) in above.chunks_exact_mut(B * n).enumerate() {
            let ps = rev4(st);
            if ps >= quarter {
                return;
            }
            let other = quarters(other, n);
            let saved: [[T; B]; B] =
                core::array::from_fn(|i| core::array::from_fn(|j| band[i][QUARTER_OF[j]][ps]));
            for j in 0..B {
                let theirs: [T; B] = core::array::from_fn(|i| other[j][QUARTER_OF[i]][pr]);
                for (i, v) in radix4_plain(theirs).into_iter().enumerate() {
                    band[i][QUARTER_OF[j]][ps] = v;
                }
            }
            for (i, row) in saved.iter().enumerate() {
                for (j, v) in radix4_plain(*row).into_iter().enumerate() {
                    other[j][QUARTER_OF[i]][pr] = v;
                }
            }
        }
    }
}

/// Four rows of `n` as four quarter rows each.
#[inline(always)]
fn quarters<T>(rows: &mut [T], n: usize) -> [[&mut [T]; 4]; 4] {
    // Explicit arrays rather than `[_; 4]::map`, and every function of the
    // 2D transform `#[inline]`: in the 2D module's own codegen unit the
    // std array helpers (`try_map`, `try_from_fn`) were left out of line
    // on the M4F, which cost its 64 × 64 transform 150 k instructions.
    let [r0, r1, r2, r3] = rows_mut(rows, n, [0, 1, 2, 3]);
    let quarter = |row| rows_mut(row, n / 4, [0, 1, 2, 3]);
    [quarter(r0), quarter(r1), quarter(r2), quarter(r3)]
}

/// [`transpose_square_bit_reversed_radix4`] without the bit reversal: the
/// plain transpose, then the two untwiddled stages on every group of four
/// rows. Written over row segments of four, which the M4F addresses with
/// immediate offsets from one pointer per segment.
#[inline]
fn transpose_square_plain_radix4<T: Real>(data: &mut [T], n: usize) {
    const B: usize = 4;
    for rt in 0..n / B {
        let (above, below) = data.split_at_mut(B * rt * n);
        let band = &mut below[..B * n];
        let c = B * rt;
        let tile: [[T; B]; B] = core::array::from_fn(|i| *segment(band, i * n + c));
        for (j, column) in tile.iter().enumerate() {
            for (i, v) in radix4_plain(*column).into_iter().enumerate() {
                segment(band, i * n + c)[j] = v;
            }
        }
        for (st, other) in above.chunks_exact_mut(B * n).enumerate() {
            let cs = B * st;
            let [b0, b1, b2, b3] = rows_mut(band, n, [0, 1, 2, 3]);
            let mine = [
                segment(b0, cs),
                segment(b1, cs),
                segment(b2, cs),
                segment(b3, cs),
            ];
            let [o0, o1, o2, o3] = rows_mut(other, n, [0, 1, 2, 3]);
            let theirs = [
                segment(o0, c),
                segment(o1, c),
                segment(o2, c),
                segment(o3, c),
            ];
            let saved: [[T; B]; B] = core::array::from_fn(|i| *mine[i]);
            for (j, row) in theirs.iter().enumerate() {
                for (i, v) in radix4_plain(**row).into_iter().enumerate() {
                    mine[i][j] = v;
                }
            }
            for (i, row) in saved.iter().enumerate() {
                for (j, v) in radix4_plain(*row).into_iter().enumerate() {
                    theirs[j][i] = v;
                }
            }
        }
    }
}

/// The four values of `row` from `start` on, as an array.
#[inline(always)]
fn segment<T>(row: &mut [T], start: usize) -> &mut [T; 4] {
    let (_, tail) = row.split_at_mut(start);
    match tail.first_chunk_mut::<4>() {
        Some(s) => s,
        None => chunk_out_of_range(),
    }
}

/// Swap `data[r·n + p(s)]` with `data[s·n + p(r)]` for all `s < r < n`,
/// `p` a permutation of `0..n` with `p(4t + j) = p(4t) + p(j)` for `j < 4`
/// (an involution of the array: the identity gives the transpose).
///
/// Works in 4 × 4 tiles, so that one tile's sixteen swaps share their
/// row and column offsets.
#[inline(always)]
fn swap_across_diagonal<T, P: Fn(usize) -> usize>(data: &mut [T], n: usize, p: P) {
    const B: usize = 4;
    if n % B != 0 {
        for r in 1..n {
            for s in 0..r {
                data.swap(r * n + p(s), s * n + p(r));
            }
        }
        return;
    }
    let q: [usize; B] = core::array::from_fn(&p);
    for rt in 0..n / B {
        let (above, below) = data.split_at_mut(B * rt * n);
        let band = &mut below[..B * n];
        let pr = p(B * rt);
        for i in 1..B {
            for j in 0..i {
                band.swap(i * n + pr + q[j], j * n + pr + q[i]);
            }
        }
        for (st, other) in above.chunks_exact_mut(B * n).enumerate() {
            let ps = p(B * st);
            for i in 0..B {
                for j in 0..B {
                    core::mem::swap(&mut band[i * n + ps + q[j]], &mut other[j * n + pr + q[i]]);
                }
            }
        }
    }
}

/// Put the rows of an `nx × ny` array in bit-reversed order.
#[inline]
fn bit_reverse_rows<T>(data: &mut [T], nx: usize, ny: usize) {
    for_each_bit_reversed_swap(ny, |i, j| {
        let (head, tail) = data.split_at_mut(j * nx);
        head[i * nx..(i + 1) * nx].swap_with_slice(&mut tail[..nx]);
    });
}

/// [`bit_reverse_rows`] then every stage of the column transform, one
/// radix-2 stage at a time: the path for large and non-square arrays on
/// cached hosts, where the four-row butterfly loops vectorize and the
/// radix-2² kernels (eight rows, six twiddles) run out of SIMD registers.
#[inline]
pub(super) fn dht_columns<T: Real>(data: &mut [T], nx: usize, ny: usize, tw: &Twiddles<'_, T>) {
    bit_reverse_rows(data, nx, ny);
    let mut m = 1;
    while m < ny {
        radix2_columns_stage(data, nx, m, tw);
        m *= 2;
    }
}

/// The radix-2 DHT of [`dht_unchecked`] along `y` for all `nx` columns at
/// once, from the stage of half-length `m` on (rows already in bit-reversed
/// order, the stages below `m` done): rows take the place of elements, so
/// every butterfly is a loop over `nx` contiguous values with one twiddle
/// pair.
///
/// Stages go two at a time (radix 2²): the stages of half-lengths `m` and
/// `2m` touch the rows `k, m−k, m+k, 2m−k` and those `2m` further on
/// together, eight rows closed under both stages, so each value is loaded
/// and stored once per two stages. The butterflies and their operands are
/// those of [`dht_stages`], in the same order, so the result is the same to
/// the bit; a single radix-2 stage finishes odd `log₂ny`.
#[inline]
fn dht_columns_stages<T: Real>(
    data: &mut [T],
    nx: usize,
    ny: usize,
    mut m: usize,
    tw: &Twiddles<'_, T>,
) {
    while 4 * m <= ny {
        let stride1 = tw.len / (2 * m);
        let stride2 = tw.len / (4 * m);
        for block in data.chunks_exact_mut(4 * m * nx) {
            let [r0, r1, r2, r3] = rows_mut(block, nx, [0, m, 2 * m, 3 * m]);
            radix4_rows_plain(r0, r1, r2, r3);
            if m >= 2 {
                let h = m / 2;
                let [r0, r1, r2, r3] = rows_mut(block, nx, [h, 3 * h, 5 * h, 7 * h]);
                let (c, s) = tw.cos_sin(h * stride2);
                radix4_rows_half(r0, r1, r2, r3, c, s);
                for k in 1..h {
                    let rows = rows_mut8(
                        block,
                        nx,
                        [
                            k,
                            m - k,
                            m + k,
                            2 * m - k,
                            2 * m + k,
                            3 * m - k,
                            3 * m + k,
                            4 * m - k,
                        ],
                    );
                    let first = tw.cos_sin(k * stride1);
                    let second = [tw.cos_sin(k * stride2), tw.cos_sin((m - k) * stride2)];
                    radix4_rows_twiddled(rows, first, second);
                }
            }
        }
        m *= 4;
    }
    if m < ny {
        radix2_columns_stage(data, nx, m, tw);
    }
}

/// One radix-2 stage of half-length `m` of [`dht_columns`].
#[inline]
fn radix2_columns_stage<T: Real>(data: &mut [T], nx: usize, m: usize, tw: &Twiddles<'_, T>) {
    let stride = tw.len / (2 * m);
    for block in data.chunks_exact_mut(2 * m * nx) {
        let (x, y) = block.split_at_mut(m * nx);
        butterfly_rows(&mut x[..nx], &mut y[..nx]);
        if m >= 2 {
            let h = m / 2;
            butterfly_rows(&mut x[h * nx..(h + 1) * nx], &mut y[h * nx..(h + 1) * nx]);
            for k in 1..h {
                let (c, s) = tw.cos_sin(k * stride);
                let (x_low, x_high) = x.split_at_mut((m - k) * nx);
                let (y_low, y_high) = y.split_at_mut((m - k) * nx);
                butterfly_rows_twiddled(
                    &mut x_low[k * nx..(k + 1) * nx],
                    &mut x_high[..nx],
                    &mut y_low[k * nx..(k + 1) * nx],
                    &mut y_high[..nx],
                    c,
                    s,
                );
            }
        }
    }
}

/// Rows `idx[0] < idx[1] < idx[2] < idx[3]` (each `nx` long) of `block`,
/// borrowed apart. An explicit array of four, not `core::array::from_fn`:
/// `from_fn`'s `try_from_fn` is not `#[inline]`, and whenever its instance
/// lands in another codegen unit than the 2D transform it is called out of
/// line at every use (+150 k instructions on the M4F's 64 × 64 transform).
macro_rules! rows_mut {
    ($name:ident, $k:literal, $($i:literal)+) => {
        #[inline(always)]
        fn $name<T>(block: &mut [T], nx: usize, idx: [usize; $k]) -> [&mut [T]; $k] {
            let mut rows = RowTaker {
                rest: block,
                next: 0,
                nx,
            };
            [$(rows.take(idx[$i])),+]
        }
    };
}
rows_mut!(rows_mut, 4, 0 1 2 3);
// Eight rows, for the two radix-4 stages fused in one pass.
rows_mut!(rows_mut8, 8, 0 1 2 3 4 5 6 7);

/// Rows of `nx` borrowed one after another from what is left of a block:
/// `next` is the index of the first row of `rest`.
struct RowTaker<'a, T> {
    rest: &'a mut [T],
    next: usize,
    nx: usize,
}

impl<'a, T> RowTaker<'a, T> {
    /// Row `i` (at least `next`), leaving the rows after it.
    #[inline(always)]
    fn take(&mut self, i: usize) -> &'a mut [T] {
        let (_, tail) = core::mem::take(&mut self.rest).split_at_mut((i - self.next) * self.nx);
        let (row, tail) = tail.split_at_mut(self.nx);
        self.rest = tail;
        self.next = i + 1;
        row
    }
}

/// The twiddled butterfly of [`dht_stages`] on one set of operands:
/// `(x[k], x[m−k], y[k], y[m−k])` in, the same four out.
#[inline(always)]
fn twiddled<T: Real>(xk: T, xmk: T, yk: T, ymk: T, c: T, s: T) -> [T; 4] {
    let t1 = c * yk + s * ymk;
    let t2 = s * yk - c * ymk;
    [xk + t1, xmk + t2, xk - t1, xmk - t2]
}

/// Radix-2² on rows `0, m, 2m, 3m` of a block: both stages untwiddled
/// (`k = 0` of each, and the middle `k = m` of the second).
#[inline(always)]
fn radix4_rows_plain<T: Real>(r0: &mut [T], r1: &mut [T], r2: &mut [T], r3: &mut [T]) {
    for_each_column([r0, r1, r2, r3], radix4_plain);
}

/// Both untwiddled stages on four values in bit-reversed order: the pairs
/// `(0, 1)` and `(2, 3)`, then `(0, 2)` and `(1, 3)`.
#[inline(always)]
fn radix4_plain<T: Real>([r0, r1, r2, r3]: [T; 4]) -> [T; 4] {
    let (a, b) = (r0 + r1, r0 - r1);
    let (c, d) = (r2 + r3, r2 - r3);
    [a + c, b + d, a - c, b - d]
}

/// Radix-2² on rows `h, 3h, 5h, 7h` (`h = m/2`): the middle butterflies of
/// the first stage, then the twiddled one of the second at `k = h`.
#[inline(always)]
fn radix4_rows_half<T: Real>(r0: &mut [T], r1: &mut [T], r2: &mut [T], r3: &mut [T], c: T, s: T) {
    for_each_column([r0, r1, r2, r3], |[r0, r1, r2, r3]| {
        let (a, b) = (r0 + r1, r0 - r1);
        let (y, ym) = (r2 + r3, r2 - r3);
        twiddled(a, b, y, ym, c, s)
    });
}

/// Radix-2² on the rows `k, m−k, m+k, 2m−k, 2m+k, 3m−k, 3m+k, 4m−k`
/// (`0 < k < m/2`): the first stage's twiddled butterflies at `k` in both
/// halves (`first`), then the second's at `k` and `m − k` (`second`).
#[inline(always)]
fn radix4_rows_twiddled<T: Real>(rows: [&mut [T]; 8], first: (T, T), second: [(T, T); 2]) {
    let (c1, s1) = first;
    let [(c2, s2), (c3, s3)] = second;
    for_each_column(rows, |[r0, r1, r2, r3, r4, r5, r6, r7]| {
        // First stage, half-length m: blocks [0, 2m) and [2m, 4m).
        let [a0, a1, a2, a3] = twiddled(r0, r1, r2, r3, c1, s1);
        let [b0, b1, b2, b3] = twiddled(r4, r5, r6, r7, c1, s1);
        // Second stage, half-length 2m: k pairs rows k, 2m−k with 2m+k,
        // 4m−k; m−k pairs rows m−k, m+k with 3m−k, 3m+k.
        let [k0, k1, k2, k3] = twiddled(a0, a3, b0, b3, c2, s2);
        let [j0, j1, j2, j3] = twiddled(a1, a2, b1, b2, c3, s3);
        [k0, j0, j1, k1, k2, j2, j3, k3]
    });
}

/// Apply `f` to every column of `R` equal-length rows: the values of the
/// column in, its new values out. Runs over chunks of four columns
/// (`[T; 4]`), which the M4F addresses with immediate offsets from one
/// pointer per row, then over the rest.
#[inline(always)]
fn for_each_column<T: Copy, const R: usize>(
    rows: [&mut [T]; R],
    mut f: impl FnMut([T; R]) -> [T; R],
) {
    let len = rows.iter().map(|r| r.len()).min().unwrap_or(0);
    // `from_fn` rather than `[_; R]::map` (see `quarters`).
    let mut rows = rows;
    let mut rest: [&mut [T]; R] =
        core::array::from_fn(|r| &mut core::mem::take(&mut rows[r])[..len]);
    for _ in 0..len / 4 {
        let mut chunks: [&mut [T; 4]; R] = core::array::from_fn(|r| take_first4(&mut rest[r]));
        for k in 0..4 {
            let out = f(core::array::from_fn(|r| chunks[r][k]));
            for (chunk, v) in chunks.iter_mut().zip(out) {
                chunk[k] = v;
            }
        }
    }
    for k in 0..len % 4 {
        let out = f(core::array::from_fn(|r| rest[r][k]));
        for (row, v) in rest.iter_mut().zip(out) {
            row[k] = v;
        }
    }
}

/// The twiddled butterfly of [`dht_stages`] over whole rows: `xk`, `yk`
/// hold index `k` and `xmk`, `ymk` index `m − k` of every column. Written
/// over equal-length slices indexed in step, so that it vectorizes.
#[inline(always)]
fn butterfly_rows_twiddled<T: Real>(
    xk: &mut [T],
    xmk: &mut [T],
    yk: &mut [T],
    ymk: &mut [T],
    c: T,
    s: T,
) {
    let len = xk.len();
    let (xmk, yk, ymk) = (&mut xmk[..len], &mut yk[..len], &mut ymk[..len]);
    for i in 0..len {
        [xk[i], xmk[i], yk[i], ymk[i]] = twiddled(xk[i], xmk[i], yk[i], ymk[i], c, s);
    }
}

/// [`butterfly_pair`] over two rows.
#[inline(always)]
fn butterfly_rows<T: Real>(x: &mut [T], y: &mut [T]) {
    for (a, b) in x.iter_mut().zip(y.iter_mut()) {
        butterfly_pair(a, b);
    }
}

/// Inverse of [`dht_2d`]: the same transform divided by `nx·ny`.
///
/// # Errors
/// As [`dht_2d`].
pub fn idht_2d<T: Real>(
    data: &mut [T],
    nx: usize,
    ny: usize,
    column: &mut [T],
    tw: &Twiddles<'_, T>,
) -> Result<()> {
    dht_2d(data, nx, ny, column, tw)?;
    let inv = T::from_f64(1.0 / (nx * ny) as f64);
    for v in data.iter_mut() {
        *v *= inv;
    }
    Ok(())
}
