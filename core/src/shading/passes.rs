//! The extraction passes of a scene: per slice point the value, the value
//! and a directional derivative, or the value at a point and its mirror,
//! accumulated into the fields of [`crate::render`]'s scene path.

use super::ViewPlan;
use crate::dht::{neg_mod, signed_index};
use crate::error::{Error, Result};
use crate::filter::{DerivativeTable, KernelTable, PhaseTable, MAX_WIDTH};
use crate::geometry::Frame;
use crate::num::{Real, Sample};
use crate::slice::{scaled, LineReads, XRun};
use crate::spectrum::{CubeSide, Spectrum};

const PI: f64 = core::f64::consts::PI;

/// What one extraction pass computes at each slice point.
mod mode {
    /// `X(p)`.
    pub const VALUE: u8 = 0;
    /// `X(p)` and `(d·∇X)(p)`.
    pub const VALUE_GRADIENT: u8 = 1;
    /// `X(p)` and `X(−p)`.
    pub const VALUE_MIRROR: u8 = 2;
}

/// A destination of a pass: `fields[field] += c0·r0 + c1·r1`.
#[derive(Clone, Copy)]
struct Target<T> {
    field: usize,
    c0: T,
    c1: T,
}

/// The tables a pass reads.
pub(crate) struct Tables<'k, T> {
    pub(crate) kernel: &'k KernelTable<T>,
    pub(crate) derivative: Option<&'k DerivativeTable<T>>,
}

/// Slice geometry in index units: `p = kx·r + ky·u + offset`.
struct PassGeometry<T> {
    right: [T; 3],
    up: [T; 3],
    dir: [T; 3],
    offset: [T; 3],
}

fn run_pass<S: Sample, Z: CubeSide, T: Real, const MODE: u8>(
    spec: &Spectrum<'_, S, Z>,
    tables: &Tables<'_, T>,
    geo: &PassGeometry<T>,
    fields: &mut [T],
    targets: &[Target<T>],
) -> Result<()> {
    if MODE == mode::VALUE_GRADIENT && tables.derivative.is_none() {
        return Err(Error::NoKernelDerivative);
    }
    match tables.kernel.filter().width() {
        1 => run_pass_width::<1, S, Z, T, MODE>(spec, tables, geo, fields, targets),
        2 => run_pass_width::<2, S, Z, T, MODE>(spec, tables, geo, fields, targets),
        3 => run_pass_width::<3, S, Z, T, MODE>(spec, tables, geo, fields, targets),
        4 => run_pass_width::<4, S, Z, T, MODE>(spec, tables, geo, fields, targets),
        5 => run_pass_width::<5, S, Z, T, MODE>(spec, tables, geo, fields, targets),
        _ => run_pass_width::<MAX_WIDTH, S, Z, T, MODE>(spec, tables, geo, fields, targets),
    }
    Ok(())
}

/// Per-axis taps of one sample point: weights, first index, wrapped
/// indices.
struct Axis<T, const W: usize> {
    weights: [T; W],
    derivative: [T; W],
    first: usize,
    index: [usize; W],
}

impl<T: Real, const W: usize> Axis<T, W> {
    /// The taps at `q` from the phase tables: weights from `phases`,
    /// derivative weights from `slopes` (zero without). One axis at a time,
    /// always inlined: through `core::array::from_fn` the per-axis closure
    /// stays out of line when its instance lands in another codegen unit.
    #[inline(always)]
    fn from_phases(
        phases: &PhaseTable<T, W>,
        slopes: Option<&PhaseTable<T, W>>,
        q: T,
        mask: usize,
    ) -> Self {
        let y = PhaseTable::<T, W>::fixed_position(q);
        let (j0, weights) = phases.taps_fixed_point(y);
        let derivative = match slopes {
            Some(table) => table.taps_fixed_point(y).1,
            None => [T::ZERO; W],
        };
        Axis {
            weights,
            derivative,
            first: j0 as usize & mask,
            index: core::array::from_fn(|t| (j0 + t as i32) as usize & mask),
        }
    }
}

impl<T, const W: usize> Axis<T, W> {
    /// The x-taps as one read ([`XRun`]).
    #[inline(always)]
    fn run(&self, reads: LineReads<'_>, n: usize) -> XRun<'_, W> {
        XRun {
            first: self.first,
            contiguous: reads.contiguous::<W>(self.first, n),
            index: &self.index,
        }
    }
}

/// One pass over the `n × n` slice for filter width `W`. Plain and
/// per-line-exponent spectra take their weights from phase tables
/// ([`PhaseTable`], an odd one for `k'`) and widen raw, with the `2^e` of
/// [`Real::load_raw`] folded into the x-weights (exact: a power of two moved
/// between the factors of each product), as the plain extraction does;
/// other storage reads through the kernel tables and [`LineReads::sums`].
/// Not inlined, so that only one width's tables are on the stack.
#[inline(never)]
fn run_pass_width<const W: usize, S: Sample, Z: CubeSide, T: Real, const MODE: u8>(
    spec: &Spectrum<'_, S, Z>,
    tables: &Tables<'_, T>,
    geo: &PassGeometry<T>,
    fields: &mut [T],
    targets: &[Target<T>],
) {
    let reads = LineReads::of(spec);
    if !matches!(reads, LineReads::General) {
        let mut phases = PhaseTable::<T, W>::zeroed();
        let filled = phases.fill(tables.kernel).is_ok();
        let slopes = match (MODE == mode::VALUE_GRADIENT, tables.derivative) {
            (true, Some(d)) => {
                let mut slopes = PhaseTable::<T, W>::zeroed();
                slopes.fill_derivative(d).ok().map(|()| slopes)
            }
            _ => None,
        };
        if filled && (MODE != mode::VALUE_GRADIENT || slopes.is_some()) {
            let raw_gain = T::exp2i(T::raw_exponent::<S>());
            let mask = spec.n() - 1;
            let slopes = slopes.as_ref();
            for_each_point::<W, S, Z, T, MODE, true>(spec, reads, geo, fields, targets, |q| {
                let mut axes: [Axis<T, W>; 3] = [
                    Axis::from_phases(&phases, slopes, q[0], mask),
                    Axis::from_phases(&phases, slopes, q[1], mask),
                    Axis::from_phases(&phases, slopes, q[2], mask),
                ];
                axes[0].weights = scaled(axes[0].weights, raw_gain);
                axes[0].derivative = scaled(axes[0].derivative, raw_gain);
                axes
            });
            return;
        }
    }
    let mask = spec.n() - 1;
    for_each_point::<W, S, Z, T, MODE, false>(spec, reads, geo, fields, targets, |q| {
        core::array::from_fn(|a| {
            let mut weights = [T::ZERO; W];
            let j0 = tables.kernel.taps_fixed(q[a], &mut weights);
            let mut derivative = [T::ZERO; W];
            if MODE == mode::VALUE_GRADIENT {
                if let Some(table) = tables.derivative {
                    table.taps_fixed(q[a], &mut derivative);
                }
            }
            Axis {
                weights,
                derivative,
                first: j0 as usize & mask,
                index: core::array::from_fn(|t| (j0 + t as i64) as usize & mask),
            }
        })
    });
}

/// The pass's loop over the slice points inside the Nyquist cube: `taps`
/// gives the per-axis taps of a point `q`, `RAW` says whether their
/// x-weights carry the `2^e` of raw widening.
#[inline(always)]
fn for_each_point<
    const W: usize,
    S: Sample,
    Z: CubeSide,
    T: Real,
    const MODE: u8,
    const RAW: bool,
>(
    spec: &Spectrum<'_, S, Z>,
    reads: LineReads<'_>,
    geo: &PassGeometry<T>,
    fields: &mut [T],
    targets: &[Target<T>],
    taps: impl Fn([T; 3]) -> [Axis<T, W>; 3],
) {
    let n = spec.n();
    let nn = n * n;
    let nyquist = T::from_usize(n) * T::HALF;
    for iy in 0..n {
        let ky = T::from_i32(signed_index(iy, n) as i32);
        for ix in 0..n {
            let kx = T::from_i32(signed_index(ix, n) as i32);
            let q: [T; 3] =
                core::array::from_fn(|a| kx * geo.right[a] + ky * geo.up[a] + geo.offset[a]);
            if q.iter().any(|&c| c > nyquist || -c > nyquist) {
                continue;
            }
            let axes = taps(q);
            let (r0, r1) = match MODE {
                mode::VALUE_GRADIENT => {
                    value_gradient::<W, RAW, S, Z, T>(spec, reads, &axes, geo.dir)
                }
                mode::VALUE_MIRROR => value_mirror::<W, RAW, S, Z, T>(spec, reads, &axes),
                _ => (value::<W, RAW, S, Z, T>(spec, reads, &axes), T::ZERO),
            };
            let i = iy * n + ix;
            for t in targets {
                fields[t.field * nn + i] += t.c0 * r0 + t.c1 * r1;
            }
        }
    }
}

#[inline(always)]
fn value<const W: usize, const RAW: bool, S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    reads: LineReads<'_>,
    axes: &[Axis<T, W>; 3],
) -> T {
    let n = spec.n();
    let [x, y, z] = axes;
    let run = x.run(reads, n);
    let mut acc = T::ZERO;
    for c in 0..W {
        let plane = z.index[c] * n * n;
        let mut acc_y = T::ZERO;
        for b in 0..W {
            let line = plane + y.index[b] * n;
            let [v] = reads.sums::<W, 1, RAW, S, Z, T>(spec, line, &run, [&x.weights]);
            acc_y += y.weights[b] * v;
        }
        acc += z.weights[c] * acc_y;
    }
    acc
}

/// `X(p)` and `(d·∇X)(p)` from one neighbourhood: the separable gradient
/// `∂_x = k'⊗k⊗k`, `∂_y = k⊗k'⊗k`, `∂_z = k⊗k⊗k'`.
#[inline(always)]
fn value_gradient<const W: usize, const RAW: bool, S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    reads: LineReads<'_>,
    axes: &[Axis<T, W>; 3],
    dir: [T; 3],
) -> (T, T) {
    let n = spec.n();
    let [x, y, z] = axes;
    let run = x.run(reads, n);
    let (mut value, mut grad) = (T::ZERO, T::ZERO);
    for c in 0..W {
        let plane = z.index[c] * n * n;
        let (mut v_y, mut gx_y, mut gy_y) = (T::ZERO, T::ZERO, T::ZERO);
        for b in 0..W {
            let line = plane + y.index[b] * n;
            let [v_x, gx_x] =
                reads.sums::<W, 2, RAW, S, Z, T>(spec, line, &run, [&x.weights, &x.derivative]);
            v_y += y.weights[b] * v_x;
            gx_y += y.weights[b] * gx_x;
            gy_y += y.derivative[b] * v_x;
        }
        value += z.weights[c] * v_y;
        grad += z.weights[c] * (dir[0] * gx_y + dir[1] * gy_y) + dir[2] * z.derivative[c] * v_y;
    }
    (value, grad)
}

/// `X(p)` and `X(−p)`: the same weights on the taps `j` and `−j`.
#[inline(always)]
fn value_mirror<const W: usize, const RAW: bool, S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    reads: LineReads<'_>,
    axes: &[Axis<T, W>; 3],
) -> (T, T) {
    let n = spec.n();
    let mask = n - 1;
    let [x, y, z] = axes;
    // The mirrored x-taps run backwards: −j for j = j0 … j0+W−1. Reversed
    // weights read them forwards from −(j0+W−1).
    let mut mirror_index = [0usize; W];
    let mut mirror_weights = [T::ZERO; W];
    for t in 0..W {
        mirror_index[t] = (n - x.index[W - 1 - t]) & mask;
        mirror_weights[t] = x.weights[W - 1 - t];
    }
    let mirror_first = mirror_index[0];
    let run = x.run(reads, n);
    let mirror_run = XRun {
        first: mirror_first,
        contiguous: reads.contiguous::<W>(mirror_first, n)
            && mirror_index[W - 1] == mirror_first + W - 1,
        index: &mirror_index,
    };
    let (mut direct, mut mirror) = (T::ZERO, T::ZERO);
    for c in 0..W {
        let zi = z.index[c];
        let (plane, plane_m) = (zi * n * n, ((n - zi) & mask) * n * n);
        let (mut d_y, mut m_y) = (T::ZERO, T::ZERO);
        for b in 0..W {
            let yi = y.index[b];
            let (line, line_m) = (plane + yi * n, plane_m + ((n - yi) & mask) * n);
            let [d] = reads.sums::<W, 1, RAW, S, Z, T>(spec, line, &run, [&x.weights]);
            let [m] =
                reads.sums::<W, 1, RAW, S, Z, T>(spec, line_m, &mirror_run, [&mirror_weights]);
            d_y += y.weights[b] * d;
            m_y += y.weights[b] * m;
        }
        direct += z.weights[c] * d_y;
        mirror += z.weights[c] * m_y;
    }
    (direct, mirror)
}

/// Where each accumulator lives in the fields buffer.
#[derive(Clone, Copy)]
pub(crate) struct Accumulators {
    /// Own-point part `P`.
    pub(crate) own: usize,
    /// Partner part `Q` (folded in as `Q(−k)`), if the cue has one.
    pub(crate) partner: Option<usize>,
}

/// What every cue pass of one view shares.
pub(crate) struct CueView<'p, T> {
    /// The kernel (and derivative) tables.
    pub(crate) tables: Tables<'p, T>,
    /// The view's resolved cue and channels.
    pub(crate) plan: &'p ViewPlan,
    /// The view's camera frame.
    pub(crate) frame: &'p Frame,
}

/// Accumulate the cued spectrum `spec` (times `gain`) into `acc`, and the
/// `w'`-cued one into `acc_derivative` if given.
pub(crate) fn accumulate_cue<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    view: &CueView<'_, T>,
    gain: f64,
    acc: Accumulators,
    acc_derivative: Option<Accumulators>,
    fields: &mut [T],
) -> Result<()> {
    let CueView {
        tables,
        plan,
        frame,
    } = view;
    let n = spec.n() as f64;
    let mut geo = PassGeometry {
        right: frame.right.map(T::from_f64),
        up: frame.up.map(T::from_f64),
        dir: frame.dir.map(T::from_f64),
        offset: [T::ZERO; 3],
    };
    let mut targets: heapless::Vec<Target<T>, 4> = heapless::Vec::new();
    let push = |targets: &mut heapless::Vec<Target<T>, 4>, field, c0: f64, c1: f64| {
        if c0 != 0.0 || c1 != 0.0 {
            // At most 4 targets per pass: P, Q, P', Q'.
            let _ = targets.push(Target {
                field,
                c0: T::from_f64(gain * c0),
                c1: T::from_f64(gain * c1),
            });
        }
    };
    if plan.slope != 0.0 {
        let partner = acc.partner.ok_or(Error::GradientSpectrum {
            problem: "internal: no partner accumulator for a sloped cue",
        })?;
        push(&mut targets, acc.own, plan.base, 0.0);
        push(&mut targets, partner, 0.0, plan.slope * n / (2.0 * PI));
        if let Some(d) = acc_derivative {
            push(&mut targets, d.own, plan.slope, 0.0);
        }
        run_pass::<S, Z, T, { mode::VALUE_GRADIENT }>(spec, tables, &geo, fields, &targets)?;
    } else if plan.base != 0.0 {
        push(&mut targets, acc.own, plan.base, 0.0);
        run_pass::<S, Z, T, { mode::VALUE }>(spec, tables, &geo, fields, &targets)?;
    }
    for wave in plan.waves.iter() {
        let Some(partner) = acc.partner else {
            return Err(Error::GradientSpectrum {
                problem: "internal: no partner accumulator for a sinusoidal cue",
            });
        };
        targets.clear();
        let shift = wave.nu * n;
        geo.offset = frame.dir.map(|c| T::from_f64(c * shift));
        let (s, c) = (libm::sin(wave.phase), libm::cos(wave.phase));
        let half = 0.5 * wave.amplitude;
        push(&mut targets, acc.own, half * s, -half * c);
        push(&mut targets, partner, half * c, half * s);
        if let Some(d) = acc_derivative {
            // w' = 2πν·A·sin(2πντ + φ + π/2): sin → cos, cos → −sin.
            let half_d = half * 2.0 * PI * wave.nu;
            push(&mut targets, d.own, half_d * c, half_d * s);
            if let Some(dp) = d.partner {
                push(&mut targets, dp, -half_d * s, half_d * c);
            }
        }
        run_pass::<S, Z, T, { mode::VALUE_MIRROR }>(spec, tables, &geo, fields, &targets)?;
    }
    Ok(())
}

/// `P(k) += Q(−k)` over the `n × n` slice. Always inlined into the scene
/// render (a per-element loop; out of line it cost the M4F's linear-cue
/// frame 18 k instructions).
#[inline(always)]
pub(crate) fn fold_partner<T: Real>(fields: &mut [T], n: usize, acc: Accumulators) {
    let Some(q) = acc.partner else { return };
    let nn = n * n;
    for iy in 0..n {
        let my = neg_mod(iy, n);
        for ix in 0..n {
            let partner = fields[q * nn + my * n + neg_mod(ix, n)];
            fields[acc.own * nn + iy * n + ix] += partner;
        }
    }
}
