//! Where the 3D transform's lines live: element-wise storage in any
//! format, or block floating point with one exponent per line.

use crate::error::{Error, Result};
use crate::num::{block_exponent, Real, Sample};

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
/// floating point ([`crate::dht::LineBlocks`]) gives each stored line a
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

/// Block floating point with one exponent per line, for the in-place 3D
/// transform ([`crate::dht::dht_3d_store`]), as fixed-point DSPs run FFTs.
///
/// Every stored line is one block: its exponent is chosen from the line's
/// largest value when it is stored (as in [`crate::num::encode_blocks`]). The transform's
/// passes run along x, y and z in turn, so the blocks follow them: two
/// tables of `n²` exponents alternate — x-lines (and the input) in `a`,
/// y-lines in `b`, z-lines in `a` again — and [`LineBlocks::finish`]
/// re-blocks the spectrum into x-lines in `b`, the layout slice extraction
/// reads ([`crate::num::BlockLayout::Line`]). Each value is read once and written once
/// per pass, so a pass never mixes exponents of two layouts. The cost is
/// one more rounding (the re-blocking) than element formats have.
#[derive(Debug)]
pub struct LineBlocks<'a, M> {
    mantissas: &'a mut [M],
    a: &'a mut [i8],
    b: &'a mut [i8],
    n: usize,
    reblocking: bool,
}

impl<'a, M: Sample> LineBlocks<'a, M> {
    /// Wrap zeroed mantissas (`n³`) and two exponent tables (`n²` each).
    ///
    /// # Errors
    /// `M` is not a block mantissa, or a length does not match `n`.
    pub fn new(mantissas: &'a mut [M], a: &'a mut [i8], b: &'a mut [i8], n: usize) -> Result<Self> {
        if !M::BLOCK_MANTISSA {
            return Err(Error::UnsupportedFormat {
                format: M::NAME,
                reason: "block exponents need an integer mantissa format (q15 or q7)",
            });
        }
        let plane = n.checked_mul(n).ok_or(Error::VolumeTooLarge {
            dims: [n; 3],
            grid: n,
        })?;
        let cube = plane.checked_mul(n).ok_or(Error::VolumeTooLarge {
            dims: [n; 3],
            grid: n,
        })?;
        crate::error::require_len("block mantissas", cube, mantissas.len())?;
        crate::error::require_len("block exponents", plane, a.len())?;
        crate::error::require_len("block exponent scratch", plane, b.len())?;
        Ok(Self {
            mantissas: &mut mantissas[..cube],
            a: &mut a[..plane],
            b: &mut b[..plane],
            n,
            reblocking: false,
        })
    }

    /// The exponent a value at index `p` is read with during `pass`.
    #[inline(always)]
    fn read_exponent(&self, pass: Pass, p: usize) -> i8 {
        let n = self.n;
        let (x, y, z) = (p % n, (p / n) % n, p / (n * n));
        match (pass, self.reblocking) {
            (_, true) => self.a[x + n * y],
            (Pass::X | Pass::Y, false) => self.a[y + n * z],
            (Pass::Z, false) => self.b[x + n * z],
        }
    }

    /// Re-block the finished spectrum into x-lines: each x-line is read with
    /// its z-line exponents and stored with a new one in the second table.
    /// `line` is scratch of `n` values. The final exponents are then in the
    /// second table (`b` of [`LineBlocks::new`]).
    ///
    /// # Errors
    /// [`Error::Overflow`] beyond the exponent range.
    pub fn finish<T: Real>(mut self, line: &mut [T]) -> Result<()> {
        let n = self.n;
        crate::error::require_len("re-blocking scratch", n, line.len())?;
        let line = &mut line[..n];
        self.reblocking = true;
        let mut finite = true;
        for row in 0..n * n {
            LineStore::<T>::load(&self, Pass::X, row * n, 1, line);
            finite &= self.store(Pass::X, row * n, 1, line);
        }
        if !finite {
            return Err(Error::Overflow {
                stage: "re-blocking the spectrum into x-lines",
            });
        }
        Ok(())
    }
}

impl<M: Sample, T: Real> LineStore<T> for LineBlocks<'_, M> {
    #[inline]
    fn load(&self, pass: Pass, base: usize, stride: usize, out: &mut [T]) {
        for (i, o) in out.iter_mut().enumerate() {
            let p = base + i * stride;
            let e = self.read_exponent(pass, p);
            *o = T::load(self.mantissas[p]) * T::exp2i(e as i32);
        }
    }

    fn store(&mut self, pass: Pass, base: usize, stride: usize, line: &[T]) -> bool {
        let n = self.n;
        let max = line
            .iter()
            .fold(0.0f64, |m, v| m.max(libm::fabs(v.to_f64())));
        let Ok(e) = block_exponent::<M>(max) else {
            return false;
        };
        let (x, y, z) = (base % n, (base / n) % n, base / (n * n));
        match (pass, self.reblocking) {
            (_, true) => self.b[y + n * z] = e,
            (Pass::X, false) => self.a[y + n * z] = e,
            (Pass::Y, false) => self.b[x + n * z] = e,
            (Pass::Z, false) => self.a[x + n * y] = e,
        }
        let k = libm::scalbn(1.0, -(e as i32));
        let mut finite = true;
        for (i, v) in line.iter().enumerate() {
            let m = M::from_f64(v.to_f64() * k);
            finite &= m.is_finite();
            self.mantissas[base + i * stride] = m;
        }
        finite
    }

    fn round(&self, line: &mut [T]) {
        let max = line
            .iter()
            .fold(0.0f64, |m, v| m.max(libm::fabs(v.to_f64())));
        let e = block_exponent::<M>(max).unwrap_or(i8::MAX) as i32;
        let (down, up) = (libm::scalbn(1.0, -e), libm::scalbn(1.0, e));
        for v in line.iter_mut() {
            let m = M::from_f64(v.to_f64() * down);
            // Keep an overflow visible: the reserved pattern decodes as −1.
            *v = T::from_f64(if m.is_finite() {
                m.to_f64() * up
            } else {
                f64::NAN
            });
        }
    }
}
