//! How x-lines are read by extractions that serve any storage (the
//! scene passes, the general extraction): plain, with one block exponent
//! per line, or tap by tap.

use crate::num::{BlockLayout, Real, Sample};
use crate::spectrum::{CubeSide, Spectrum};

/// How x-lines are read in the extraction's inner loops.
#[derive(Clone, Copy)]
pub(crate) enum LineReads<'a> {
    /// Plain coefficients.
    Plain,
    /// One block exponent per x-line.
    LineExponents(&'a [i8]),
    /// Anything else (bricks): through [`Spectrum::line_taps`].
    General,
}

impl<'a> LineReads<'a> {
    /// The reads for `spec`.
    pub(crate) fn of<S: Sample, Z: CubeSide>(spec: &Spectrum<'a, S, Z>) -> Self {
        match spec.blocks() {
            Some(b) if S::BLOCK_MANTISSA => match b.layout() {
                BlockLayout::Line => LineReads::LineExponents(b.exponents()),
                _ => LineReads::General,
            },
            _ => LineReads::Plain,
        }
    }

    /// Whether a run of `W` taps from `x0` can be read contiguously.
    #[inline(always)]
    pub(crate) fn contiguous<const W: usize>(self, x0: usize, n: usize) -> bool {
        x0 + W <= n && !matches!(self, LineReads::General)
    }

    /// The `W` coefficients from `line + x0` as one run, when `contiguous`
    /// (one bounds check for the run).
    #[inline(always)]
    fn run<'s, const W: usize, S: Sample, Z: CubeSide>(
        spec: &Spectrum<'s, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
    ) -> Option<&'s [S; W]> {
        if !contiguous {
            return None;
        }
        let start = line + x0;
        // As in `extract_lines`: for W ≤ 4 the tail's first chunk (no
        // overflow test of `start + W`).
        if W <= 4 {
            spec.data()
                .get(start..)
                .and_then(|rest| rest.first_chunk::<W>())
        } else {
            spec.data()
                .get(start..start + W)
                .and_then(|s| <&[S; W]>::try_from(s).ok())
        }
    }

    /// The block exponent's power of two for `line`, if lines carry one.
    #[inline(always)]
    fn line_scale<S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
    ) -> Option<T> {
        match self {
            LineReads::LineExponents(e) => Some(T::exp2i(e[line / spec.n()] as i32)),
            _ => None,
        }
    }

    /// `Σ_t w[t]·c[line + xs[t]]` with block exponents applied: one
    /// contiguous run from `x0` when `contiguous`, else through
    /// [`Spectrum::line_taps`] at the wrapped indices `xs`.
    #[inline(always)]
    pub(crate) fn sum<const W: usize, S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        weights: &[T; W],
    ) -> T {
        let Some(run) = Self::run::<W, S, Z>(spec, line, x0, contiguous) else {
            return spec.line_taps(line, xs, weights);
        };
        let mut sum = T::ZERO;
        for (wt, v) in weights.iter().zip(run) {
            sum += *wt * T::load(*v);
        }
        match self.line_scale::<S, Z, T>(spec, line) {
            Some(scale) => sum * scale,
            None => sum,
        }
    }

    /// [`LineReads::sum`] with raw widening ([`Real::load_raw`]): the
    /// weights must carry the `2^e` of [`Real::raw_exponent`]. Plain and
    /// per-line-exponent reads only (never [`LineReads::General`], whose
    /// per-tap exponents this does not apply).
    #[inline(always)]
    pub(crate) fn sum_raw<const W: usize, S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        weights: &[T; W],
    ) -> T {
        let mut sum = T::ZERO;
        match Self::run::<W, S, Z>(spec, line, x0, contiguous) {
            Some(run) => {
                for t in 0..W {
                    sum += weights[t] * T::load_raw(run[t]);
                }
            }
            None => {
                let data = spec.data();
                for t in 0..W {
                    let v = data.get(line + xs[t]).copied().unwrap_or_default();
                    sum += weights[t] * T::load_raw(v);
                }
            }
        }
        match self.line_scale::<S, Z, T>(spec, line) {
            Some(scale) => sum * scale,
            None => sum,
        }
    }

    /// [`LineReads::sum2`] with raw widening, as [`LineReads::sum_raw`]
    /// (both weight sets carry the `2^e`).
    #[inline(always)]
    pub(crate) fn sum2_raw<const W: usize, S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        first: &[T; W],
        second: &[T; W],
    ) -> (T, T) {
        let (mut a, mut b) = (T::ZERO, T::ZERO);
        match Self::run::<W, S, Z>(spec, line, x0, contiguous) {
            Some(run) => {
                for t in 0..W {
                    let v = T::load_raw(run[t]);
                    a += first[t] * v;
                    b += second[t] * v;
                }
            }
            None => {
                let data = spec.data();
                for t in 0..W {
                    let v = T::load_raw(data.get(line + xs[t]).copied().unwrap_or_default());
                    a += first[t] * v;
                    b += second[t] * v;
                }
            }
        }
        match self.line_scale::<S, Z, T>(spec, line) {
            Some(scale) => (a * scale, b * scale),
            None => (a, b),
        }
    }

    /// Two weighted sums over the same taps, each coefficient read once
    /// (the value and a derivative of [`LineReads::sum`]).
    #[inline(always)]
    pub(crate) fn sum2<const W: usize, S: Sample, Z: CubeSide, T: Real>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
        x0: usize,
        contiguous: bool,
        xs: &[usize; W],
        first: &[T; W],
        second: &[T; W],
    ) -> (T, T) {
        let Some(run) = Self::run::<W, S, Z>(spec, line, x0, contiguous) else {
            return (
                spec.line_taps(line, xs, first),
                spec.line_taps(line, xs, second),
            );
        };
        let (mut a, mut b) = (T::ZERO, T::ZERO);
        for t in 0..W {
            let v = T::load(run[t]);
            a += first[t] * v;
            b += second[t] * v;
        }
        match self.line_scale::<S, Z, T>(spec, line) {
            Some(scale) => (a * scale, b * scale),
            None => (a, b),
        }
    }
}
