//! In-place radix-2 discrete Hartley transforms.
//!
//! # Normalization and order
//! The forward transform of a length-`N` sequence is
//! `H(k) = Σ_x f(x) cas(2πkx/N)`, with `cas θ = cos θ + sin θ`, unnormalized.
//! The DHT is its own inverse up to `1/N`: [`idht`] divides by `N`.
//! Output is in natural order, `H(0)` (DC) first; index `k ≥ N/2` holds the
//! signed frequency `k − N`.
//!
//! The 2D and 3D transforms are the *true* multidimensional DHT with kernel
//! `cas(2π(k·x)/N)` (not the separable `cas·cas` product): row-column passes
//! followed by the Hao–Bracewell correction.
//!
//! # Precision
//! Each radix-2 stage adds at most a few units of roundoff, so the relative
//! RMS error of a length-`N` transform grows like `ε·log₂N` (ε the unit
//! roundoff of the arithmetic type); the tests check this bound against a
//! naive O(N²) transform evaluated in f64.

use crate::error::{mismatch, require_len, require_pow2, Error, Result};
use crate::real::{Real, Sample};

/// Quarter-wave sine table for transforms of length up to `len`.
///
/// Holds `sin(2πk/len)` for `k = 0 ..= len/4` in a caller-provided buffer.
/// Any power-of-two length `n ≤ len` uses every `(len/n)`-th entry, so one
/// table built for the largest size serves all smaller ones.
///
/// # Provenance and accuracy
/// Entries are computed once by `libm::sin` in f64 (error below 1 ulp of
/// f64), then rounded to `T`: each entry is within 0.5 ulp of `T` of the true
/// value (plus < 1e-16 absolute). Cosines come from the same table by
/// quarter-wave symmetry, so `sin² + cos²` is 1 to that accuracy.
#[derive(Debug)]
pub struct Twiddles<'a, T> {
    len: usize,
    quarter: &'a [T],
}

impl<'a, T: Real> Twiddles<'a, T> {
    /// Entries a table for transforms of length up to `len` needs.
    pub const fn buffer_len(len: usize) -> usize {
        len / 4 + 1
    }

    /// Fill `buf` with the table for transform lengths up to `len`.
    ///
    /// # Errors
    /// `len` not a power of two, or `buf` shorter than
    /// [`Twiddles::buffer_len`]`(len)`.
    pub fn new(buf: &'a mut [T], len: usize) -> Result<Self> {
        require_pow2("twiddle table length", len)?;
        let entries = Self::buffer_len(len);
        require_len("twiddle buffer", entries, buf.len())?;
        let step = 2.0 * core::f64::consts::PI / len as f64;
        for (k, slot) in buf[..entries].iter_mut().enumerate() {
            // Exact symmetric values where the quarter-wave table is tight.
            *slot = if 4 * k == len {
                T::ONE
            } else {
                T::from_f64(libm::sin(step * k as f64))
            };
        }
        Ok(Self {
            len,
            quarter: &buf[..entries],
        })
    }

    /// Wrap a table filled earlier by [`Twiddles::new`] (or stored, e.g. in
    /// flash, from its output) for lengths up to `len`.
    ///
    /// # Errors
    /// `len` not a power of two, or `table` shorter than
    /// [`Twiddles::buffer_len`]`(len)`.
    pub fn from_table(table: &'a [T], len: usize) -> Result<Self> {
        require_pow2("twiddle table length", len)?;
        let entries = Self::buffer_len(len);
        require_len("twiddle table", entries, table.len())?;
        Ok(Self {
            len,
            quarter: &table[..entries],
        })
    }

    /// Largest transform length this table serves.
    pub fn len(&self) -> usize {
        self.len
    }

    /// `false`: a table always serves at least length 1.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// `(cos, sin)` of `2πk/len` for `k < len/2`.
    #[inline(always)]
    fn cos_sin(&self, k: usize) -> (T, T) {
        let q = self.len / 4;
        if k <= q {
            (self.quarter[q - k], self.quarter[k])
        } else {
            (-self.quarter[k - q], self.quarter[2 * q - k])
        }
    }

    pub(crate) fn check(&self, n: usize) -> Result<()> {
        require_pow2("transform length", n)?;
        if n > self.len {
            return Err(Error::TwiddlesTooShort {
                table_len: self.len,
                needed: n,
            });
        }
        Ok(())
    }
}

/// Forward DHT of `data` in place, unnormalized (see the module docs).
///
/// # Errors
/// The length is not a power of two, or exceeds the twiddle table's length.
pub fn dht<T: Real>(data: &mut [T], tw: &Twiddles<'_, T>) -> Result<()> {
    tw.check(data.len())?;
    dht_unchecked(data, tw);
    Ok(())
}

/// Inverse DHT in place: the forward transform divided by `N`.
///
/// # Errors
/// As [`dht`].
pub fn idht<T: Real>(data: &mut [T], tw: &Twiddles<'_, T>) -> Result<()> {
    dht(data, tw)?;
    let inv = T::from_f64(1.0 / data.len() as f64);
    for v in data.iter_mut() {
        *v *= inv;
    }
    Ok(())
}

fn bit_reverse<T>(data: &mut [T]) {
    for_each_bit_reversed_swap(data.len(), |i, j| data.swap(i, j));
}

/// Calls `swap(i, j)` for every pair `i < j` with `j` the bit reversal of
/// `i` among `0 … n − 1` (`n` a power of two): the swaps that put a
/// sequence of `n` (elements or rows) in bit-reversed order.
#[inline(always)]
fn for_each_bit_reversed_swap(n: usize, mut swap: impl FnMut(usize, usize)) {
    let mut j = 0usize;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            swap(i, j);
        }
    }
}

/// Radix-2 decimation in time. A block of length `2m` combines the DHTs `X`
/// (even samples) and `Y` (odd samples) of length `m`:
/// `H(k) = X(k) + cos(πk/m)·Y(k) + sin(πk/m)·Y(m−k)` and
/// `H(k+m) = X(k) − (same)`, with `Y(m) ≡ Y(0)`.
pub(crate) fn dht_unchecked<T: Real>(data: &mut [T], tw: &Twiddles<'_, T>) {
    dht_stages(data, tw, |_| {});
}

/// [`dht_unchecked`] calling `after_stage` on the whole line after every
/// butterfly stage (a no-op closure compiles away).
#[inline(always)]
fn dht_stages<T: Real, F: FnMut(&mut [T])>(
    data: &mut [T],
    tw: &Twiddles<'_, T>,
    mut after_stage: F,
) {
    let n = data.len();
    if n <= 1 {
        return;
    }
    bit_reverse(data);
    let mut m = 1;
    while m < n {
        let stride = tw.len / (2 * m);
        for block in data.chunks_exact_mut(2 * m) {
            let (x, y) = block.split_at_mut(m);
            butterfly_pair(&mut x[0], &mut y[0]);
            if m >= 2 {
                let h = m / 2;
                butterfly_pair(&mut x[h], &mut y[h]);
                for k in 1..h {
                    let (c, s) = tw.cos_sin(k * stride);
                    let (yk, ymk) = (y[k], y[m - k]);
                    let t1 = c * yk + s * ymk;
                    let t2 = s * yk - c * ymk;
                    let (xk, xmk) = (x[k], x[m - k]);
                    x[k] = xk + t1;
                    y[k] = xk - t1;
                    x[m - k] = xmk + t2;
                    y[m - k] = xmk - t2;
                }
            }
        }
        after_stage(data);
        m *= 2;
    }
}

/// Where the 3D transform rounds to the storage format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rounding {
    /// Once per pass: after the x pass, the y pass and the fused z pass.
    PerPass,
    /// Also after every radix-2 butterfly stage of every line, as a
    /// transform computing in the storage format itself would.
    PerStage,
}

/// The pass of the 3D transform a line is loaded or stored in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    /// Lines along x (contiguous); also the placement of the input.
    X,
    /// Lines along y.
    Y,
    /// Lines along z, fused with the Hao–Bracewell correction.
    Z,
}

/// Storage that the 3D transform reads and writes one line at a time.
///
/// Element formats ([`Elements`]) round each value on its own; block
/// floating point ([`crate::format::LineBlocks`]) gives each stored line a
/// shared exponent, which is why a whole line is stored at once.
pub trait LineStore<T: Real> {
    /// Load the values at `base + i·stride`, `i < out.len()`, as `pass` reads them.
    fn load(&self, pass: Pass, base: usize, stride: usize, out: &mut [T]);
    /// Round `line` to the storage and write it at `base + i·stride`;
    /// `false` if a value overflowed.
    fn store(&mut self, pass: Pass, base: usize, stride: usize, line: &[T]) -> bool;
    /// Round `line` in place exactly as storing and reloading it would.
    fn round(&self, line: &mut [T]);
}

/// Element-wise storage in format `S`.
#[derive(Debug)]
pub struct Elements<'a, S>(pub &'a mut [S]);

impl<S: Sample, T: Real> LineStore<T> for Elements<'_, S> {
    #[inline(always)]
    fn load(&self, _: Pass, base: usize, stride: usize, out: &mut [T]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = T::load(self.0[base + i * stride]);
        }
    }
    #[inline(always)]
    fn store(&mut self, _: Pass, base: usize, stride: usize, line: &[T]) -> bool {
        let mut finite = true;
        for (i, l) in line.iter().enumerate() {
            let s: S = l.store();
            finite &= s.is_finite();
            self.0[base + i * stride] = s;
        }
        finite
    }
    #[inline(always)]
    fn round(&self, line: &mut [T]) {
        for v in line.iter_mut() {
            *v = T::load(v.store::<S>());
        }
    }
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

#[inline(always)]
fn butterfly_pair<T: Real>(a: &mut T, b: &mut T) {
    let (x, y) = (*a, *b);
    *a = x + y;
    *b = x - y;
}

/// Index of `−k` modulo `n` (a power of two).
#[inline(always)]
pub(crate) fn neg_mod(k: usize, n: usize) -> usize {
    (n - k) & (n - 1)
}

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
/// agree bit for bit. `column` is not needed here; it is checked for the
/// signature's sake (the line path's scratch).
///
/// # Errors
/// A side not a power of two or longer than the table, a `data` length other
/// than `nx·ny`, or short scratch.
pub fn dht_2d<T: Real>(
    data: &mut [T],
    nx: usize,
    ny: usize,
    column: &mut [T],
    tw: &Twiddles<'_, T>,
) -> Result<()> {
    tw.check(nx)?;
    tw.check(ny)?;
    check_len("2D array", nx * ny, data.len())?;
    require_len("column scratch", ny, column.len())?;
    if nx == ny && (4..TILED_TRANSPOSE_FROM).contains(&nx) {
        dht_2d_square(data, nx, tw);
    } else {
        if nx == ny {
            transpose_square(data, nx);
            dht_columns(data, nx, ny, tw);
            transpose_square(data, nx);
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
    tw.check(nx)?;
    tw.check(ny)?;
    check_len("2D array", nx * ny, data.len())?;
    require_len("column scratch", ny, column.len())?;
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

/// `H(u,v) = ½[T(u,v) + T(−u,v) + T(u,−v) − T(−u,−v)]` in place.
///
/// Where `u ≡ −u` (`u = 0`, `nx/2`) or `v ≡ −v` the bracket is `2·T(u,v)`
/// exactly, so those rows and columns stay as they are. Every other group
/// of four points shares `S = ½[T(u,v) + T(−u,v) + T(u,−v) + T(−u,−v)]`,
/// and each point's value is `S` minus the point diagonally opposite
/// (`H(u,v) = S − T(−u,−v)`, …): 8 operations instead of 16. Rows `v` and
/// `ny − v` go together, with `u` and `nx − u` walked from both ends.
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
    rows_mut(rows, n, [0, 1, 2, 3]).map(|row| rows_mut(row, n / 4, [0, 1, 2, 3]))
}

/// [`transpose_square_bit_reversed_radix4`] without the bit reversal: the
/// plain transpose, then the two untwiddled stages on every group of four
/// rows. Written over row segments of four, which the M4F addresses with
/// immediate offsets from one pointer per segment.
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
            let mine = [b0, b1, b2, b3].map(|row| segment(row, cs));
            let [o0, o1, o2, o3] = rows_mut(other, n, [0, 1, 2, 3]);
            let theirs = [o0, o1, o2, o3].map(|row| segment(row, c));
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
fn dht_columns<T: Real>(data: &mut [T], nx: usize, ny: usize, tw: &Twiddles<'_, T>) {
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
                    let rows = rows_mut(
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

/// Rows `idx[0] < idx[1] < …` (each `nx` long) of `block`, borrowed apart.
#[inline(always)]
fn rows_mut<T, const K: usize>(block: &mut [T], nx: usize, idx: [usize; K]) -> [&mut [T]; K] {
    let mut rest = block;
    let mut next = 0;
    core::array::from_fn(|j| {
        let (_, tail) = core::mem::take(&mut rest).split_at_mut((idx[j] - next) * nx);
        let (row, tail) = tail.split_at_mut(nx);
        rest = tail;
        next = idx[j] + 1;
        row
    })
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
    let mut rest = rows.map(|r| &mut r[..len]);
    for _ in 0..len / 4 {
        let mut chunks = rest.each_mut().map(take_first4);
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

fn check_len(what: &'static str, expected: usize, got: usize) -> Result<()> {
    if expected == got {
        Ok(())
    } else {
        Err(mismatch(what, expected, got))
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

fn overflow_check(finite: bool, stage: &'static str) -> Result<()> {
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
