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

    /// `K` weighted sums `Σ_t w_k[t]·c[line + x.index[t]]` over the same
    /// `W` taps of one x-line, each coefficient read once, with block
    /// exponents applied: one contiguous run from `x.first` when
    /// `x.contiguous`, else tap by tap at the wrapped indices.
    ///
    /// `RAW`: widen with [`Real::load_raw`]; the weights must carry the
    /// `2^e` of [`Real::raw_exponent`]. Plain and per-line-exponent reads
    /// only (never [`LineReads::General`], whose per-tap exponents raw
    /// reads do not apply). Otherwise widen fully, and read taps that do
    /// not form a run through [`Spectrum::line_taps`].
    #[inline(always)]
    pub(crate) fn sums<const W: usize, const K: usize, const RAW: bool, S, Z, T>(
        self,
        spec: &Spectrum<'_, S, Z>,
        line: usize,
        x: &XRun<'_, W>,
        weights: [&[T; W]; K],
    ) -> [T; K]
    where
        S: Sample,
        Z: CubeSide,
        T: Real,
    {
        let run = Self::run::<W, S, Z>(spec, line, x.first, x.contiguous);
        let mut sums = [T::ZERO; K];
        if !RAW && run.is_none() {
            for k in 0..K {
                sums[k] = spec.line_taps(line, x.index, weights[k]);
            }
            return sums;
        }
        let load = |v: S| if RAW { T::load_raw(v) } else { T::load(v) };
        if K == 2 {
            // The value and a derivative (K = 2) in two scalar
            // accumulators, as the old `sum2_raw`: the same products and
            // sums in the same order, but with the `[T; K]` array the
            // M4F's linear cue pass took 16 k more instructions.
            let (mut a, mut b) = (T::ZERO, T::ZERO);
            match run {
                Some(run) => {
                    for t in 0..W {
                        let v = load(run[t]);
                        a += weights[0][t] * v;
                        b += weights[1][t] * v;
                    }
                }
                None => {
                    let data = spec.data();
                    for t in 0..W {
                        let v = load(data.get(line + x.index[t]).copied().unwrap_or_default());
                        a += weights[0][t] * v;
                        b += weights[1][t] * v;
                    }
                }
            }
            let (a, b) = match self.line_scale::<S, Z, T>(spec, line) {
                Some(scale) => (a * scale, b * scale),
                None => (a, b),
            };
            sums[0] = a;
            sums[1] = b;
            return sums;
        }
        match run {
            Some(run) => {
                for t in 0..W {
                    let v = load(run[t]);
                    for k in 0..K {
                        sums[k] += weights[k][t] * v;
                    }
                }
            }
            None => {
                let data = spec.data();
                for t in 0..W {
                    let v = load(data.get(line + x.index[t]).copied().unwrap_or_default());
                    for k in 0..K {
                        sums[k] += weights[k][t] * v;
                    }
                }
            }
        }
        if let Some(scale) = self.line_scale::<S, Z, T>(spec, line) {
            for s in sums.iter_mut() {
                *s *= scale;
            }
        }
        sums
    }
}

/// The x-taps of one sample point: the first index, whether the `W` taps
/// run contiguously from it ([`LineReads::contiguous`]), and the wrapped
/// indices.
#[derive(Clone, Copy)]
pub(crate) struct XRun<'a, const W: usize> {
    /// Index of the first tap on the x-line.
    pub(crate) first: usize,
    /// Whether the taps are `first .. first + W`, read as one run.
    pub(crate) contiguous: bool,
    /// The taps' indices, wrapped around the line.
    pub(crate) index: &'a [usize; W],
}

/// `w` with every weight times `gain` (the `2^e` of [`Real::load_raw`]
/// folded into the x-weights): the same products as `w.map(|w| w * gain)`,
/// as a loop that is always inlined, since `[_; N]::map` (through
/// `try_map`) stays out of line when its instance lands in another codegen
/// unit than the per-point loop.
#[inline(always)]
pub(crate) fn scaled<T: Real, const W: usize>(mut w: [T; W], gain: T) -> [T; W] {
    for v in w.iter_mut() {
        *v *= gain;
    }
    w
}
