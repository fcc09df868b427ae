//! Rendering a [`Scene`]: depth cues and shading applied on the slice.
//!
//! # Hartley forms of the paper's operators
//! Let `X(k) = Σ_x g(x)·cas(2πk·x/n)` be a stored spectrum (index units,
//! `x` the signed position from the transform origin) and `X(q)` its
//! interpolation at a real 3D index `q`. Differentiating under the sum,
//! `∂X/∂q_a (q) = (2π/n)·Σ x_a·g·cas(−2πq·x/n)`, hence:
//!
//! - **Linear ramp (eq. 4–5).** `H{(d·x)·g}(k) = (n/2π)·(d·∇X)(−k)`: the
//!   gradient filter `d·∇H` applied at the *mirrored* point `−k`. (In
//!   Fourier terms `F{(d·x)g} = (i/2π)·d·∇F`; the factor `i` becomes the
//!   mirror.) For a slice point `k` the cued sample is
//!   `C_avg·X(k) + C_cue·(n/2π)·(d·∇X)(−k)`.
//! - **Sinusoid (after eq. 5).** For `a` a 3D index offset,
//!   `H{cos(2πa·x/n)·g}(k) = ½[X(k − a) + X(k + a)]` and
//!   `H{sin(2πa·x/n)·g}(k) = ½[X(a − k) − X(−a − k)]`. All four values come
//!   from the one neighbourhood of `k + a`: `U(k) = X(k + a)` read
//!   directly and `V(k) = X(−(k + a))` read at the mirrored indices `−j`
//!   with the same weights (the kernel is even). Then `X(k − a) = V(−k)`
//!   and `X(a − k) = U(−k)`. This is the paper's "shifted H"; the Hartley
//!   spectrum needs the mirrored read where a complex one holds `F` and
//!   `F*` in one sample, so a sinusoid costs two reads per tap.
//! - **First moment (eq. 11).** `H{∂_L f}(k) = −(2π/n)·(k·L)·X(−k)`.
//! - **Both (eq. 12–14).** `∫w·∂_L f = ∫∂_L(w·f) − (d·L)·∫w'·f`: shading
//!   the cued spectrum misses `−(d·L)` times the projection cued by `w'`.
//!   For linear cueing `w' = C_cue` and the correction is eq. 14,
//!   `½·C_cue·C_dif·L_dif·f·(V·L)`; for sinusoids `w'` is another sinusoid
//!   read from the same neighbourhood, so it costs no extra reads.
//!
//! Terms that need the partner point `−k` are accumulated in a second grid
//! `Q` and folded in at the end: `DC(k) = P(k) + Q(−k)`.
//!
//! Then channel `c`'s slice is
//! `A_c·DC_f(k) + K_c·DC_|∇f|(k) + (2π/n)·(k·M_c)·DC_f(−k) + (d·M_c)·DC'_f(k)`
//! with `K_c = Σ_l ½D_{l,c}` and `M_c = Σ_l ½D_{l,c}·L_l` (all lights in one
//! moment), and is inverse-transformed like a plain projection.

use crate::dht::{neg_mod, Twiddles};
use crate::error::{require_len, Error, Result};
use crate::filter::{DerivativeTable, KernelTable, PhaseTable, MAX_WIDTH};
use crate::geometry::View;
use crate::real::{Real, Sample};
use crate::render::LineReads;
use crate::render::{aux_len, check_image, extract_slice, finish_channel, placement, signed_index};
use crate::scene::{Scene, ViewPlan};
use crate::spectrum::{CubeSide, Spectrum};

const PI: f64 = core::f64::consts::PI;

/// Scratch elements [`render_scene`] needs for `scene` on a spectrum of
/// side `n`: [`Scene::field_count`] slice grids of `n²`.
pub fn fields_len(scene: &Scene, n: usize) -> usize {
    scene.field_count() * n * n
}

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
struct Tables<'k, T> {
    kernel: &'k KernelTable<T>,
    derivative: Option<&'k DerivativeTable<T>>,
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

/// One pass over the `n × n` slice for filter width `W`. Plain and
/// per-line-exponent spectra take their weights from phase tables
/// ([`PhaseTable`], an odd one for `k'`) and widen raw, with the `2^e` of
/// [`Real::load_raw`] folded into the x-weights (exact: a power of two moved
/// between the factors of each product), as the plain extraction does;
/// other storage reads through the kernel tables and [`LineReads::sum`].
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
            for_each_point::<W, S, Z, T, MODE, true>(spec, reads, geo, fields, targets, |q| {
                let mut axes: [Axis<T, W>; 3] = core::array::from_fn(|a| {
                    let y = PhaseTable::<T, W>::fixed_position(q[a]);
                    let (j0, weights) = phases.taps_fixed_point(y);
                    let derivative = match &slopes {
                        Some(table) => table.taps_fixed_point(y).1,
                        None => [T::ZERO; W],
                    };
                    Axis {
                        weights,
                        derivative,
                        first: j0 as usize & mask,
                        index: core::array::from_fn(|t| (j0 + t as i32) as usize & mask),
                    }
                });
                axes[0].weights = axes[0].weights.map(|w| w * raw_gain);
                axes[0].derivative = axes[0].derivative.map(|w| w * raw_gain);
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

/// One x-line's weighted sum, raw or fully widened ([`LineReads::sum_raw`],
/// [`LineReads::sum`]).
#[inline(always)]
fn line_sum<const W: usize, const RAW: bool, S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    reads: LineReads<'_>,
    line: usize,
    x: (usize, bool, &[usize; W]),
    weights: &[T; W],
) -> T {
    let (first, contiguous, index) = x;
    if RAW {
        reads.sum_raw(spec, line, first, contiguous, index, weights)
    } else {
        reads.sum(spec, line, first, contiguous, index, weights)
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
    let contiguous = reads.contiguous::<W>(x.first, n);
    let mut acc = T::ZERO;
    for c in 0..W {
        let plane = z.index[c] * n * n;
        let mut acc_y = T::ZERO;
        for b in 0..W {
            let line = plane + y.index[b] * n;
            acc_y += y.weights[b]
                * line_sum::<W, RAW, S, Z, T>(
                    spec,
                    reads,
                    line,
                    (x.first, contiguous, &x.index),
                    &x.weights,
                );
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
    let contiguous = reads.contiguous::<W>(x.first, n);
    let (mut value, mut grad) = (T::ZERO, T::ZERO);
    for c in 0..W {
        let plane = z.index[c] * n * n;
        let (mut v_y, mut gx_y, mut gy_y) = (T::ZERO, T::ZERO, T::ZERO);
        for b in 0..W {
            let line = plane + y.index[b] * n;
            let (v_x, gx_x) = if RAW {
                reads.sum2_raw(
                    spec,
                    line,
                    x.first,
                    contiguous,
                    &x.index,
                    &x.weights,
                    &x.derivative,
                )
            } else {
                reads.sum2(
                    spec,
                    line,
                    x.first,
                    contiguous,
                    &x.index,
                    &x.weights,
                    &x.derivative,
                )
            };
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
    let contiguous = reads.contiguous::<W>(x.first, n);
    let mirror_contiguous =
        reads.contiguous::<W>(mirror_first, n) && mirror_index[W - 1] == mirror_first + W - 1;
    let (mut direct, mut mirror) = (T::ZERO, T::ZERO);
    for c in 0..W {
        let zi = z.index[c];
        let (plane, plane_m) = (zi * n * n, ((n - zi) & mask) * n * n);
        let (mut d_y, mut m_y) = (T::ZERO, T::ZERO);
        for b in 0..W {
            let yi = y.index[b];
            let (line, line_m) = (plane + yi * n, plane_m + ((n - yi) & mask) * n);
            d_y += y.weights[b]
                * line_sum::<W, RAW, S, Z, T>(
                    spec,
                    reads,
                    line,
                    (x.first, contiguous, &x.index),
                    &x.weights,
                );
            m_y += y.weights[b]
                * line_sum::<W, RAW, S, Z, T>(
                    spec,
                    reads,
                    line_m,
                    (mirror_first, mirror_contiguous, &mirror_index),
                    &mirror_weights,
                );
        }
        direct += z.weights[c] * d_y;
        mirror += z.weights[c] * m_y;
    }
    (direct, mirror)
}

/// Where each accumulator lives in the fields buffer.
#[derive(Clone, Copy)]
struct Accumulators {
    /// Own-point part `P`.
    own: usize,
    /// Partner part `Q` (folded in as `Q(−k)`), if the cue has one.
    partner: Option<usize>,
}

/// Accumulate the cued spectrum `spec` (times `gain`) into `acc`, and the
/// `w'`-cued one into `acc_derivative` if given.
fn accumulate_cue<S: Sample, Z: CubeSide, T: Real>(
    spec: &Spectrum<'_, S, Z>,
    tables: &Tables<'_, T>,
    plan: &ViewPlan,
    frame: &crate::geometry::Frame,
    gain: f64,
    acc: Accumulators,
    acc_derivative: Option<Accumulators>,
    fields: &mut [T],
) -> Result<()> {
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

/// `P(k) += Q(−k)` over the `n × n` slice.
fn fold_partner<T: Real>(fields: &mut [T], n: usize, acc: Accumulators) {
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

/// Render `scene` seen along `view` into `out`: `width × height` pixels of
/// [`Scene::channels`] interleaved channels (channel fastest), row 0 at the
/// top, in the units of the module docs' integral.
///
/// - `gradient` is the `|∇f|` spectrum ([`crate::gradient`]), required iff
///   [`Scene::needs_gradient_spectrum`], with the same side, filter and
///   volume dims as `density`;
/// - `derivative` is required iff [`Scene::needs_kernel_derivative`];
/// - `fields` needs [`fields_len`]`(scene, n)` elements and `aux`
///   [`aux_len`]`(n)`; `out` needs `channels·width·height`.
///
/// Returns the number of channels written.
///
/// # Errors
/// As [`crate::render::render`], plus invalid scene values
/// ([`Scene::validate`]), a missing or mismatched gradient spectrum, and a
/// missing derivative table.
pub fn render_scene<S: Sample, Z: CubeSide, T: Real>(
    density: &Spectrum<'_, S, Z>,
    gradient: Option<&Spectrum<'_, S, Z>>,
    kernel: &KernelTable<T>,
    derivative: Option<&DerivativeTable<T>>,
    scene: &Scene,
    view: &View,
    width: usize,
    height: usize,
    tw: &Twiddles<'_, T>,
    fields: &mut [T],
    aux: &mut [T],
    out: &mut [T],
) -> Result<usize> {
    let frame = view.frame()?;
    let n = density.n();
    let nn = n * n;
    check_image(width, height, n)?;
    if kernel.filter() != density.filter() {
        return Err(Error::FilterMismatch);
    }
    let plan = ViewPlan::new(scene, &frame, density.dims())?;
    let channels = plan.channels.len();
    require_len("scene fields", fields_len(scene, n), fields.len())?;
    require_len("auxiliary scratch", aux_len(n), aux.len())?;
    require_len("output image", channels * width * height, out.len())?;
    tw.check(n)?;
    if plan.slope != 0.0 {
        match derivative {
            None => return Err(Error::NoKernelDerivative),
            Some(d) if d.filter() != density.filter() => return Err(Error::FilterMismatch),
            Some(_) => {}
        }
    }
    let gradient = if scene.needs_gradient_spectrum() {
        let g = gradient.ok_or(Error::GradientSpectrum {
            problem: "the scene has lights but none was given",
        })?;
        if g.n() != n || g.filter() != density.filter() || g.dims() != density.dims() {
            return Err(Error::GradientSpectrum {
                problem: "its side, filter or volume dims differ from the density spectrum's",
            });
        }
        Some(g)
    } else {
        None
    };
    let place = placement(density.dims(), &frame, width, height);
    let gain = 1.0 / density.scale();
    let tables = Tables { kernel, derivative };
    let fields = &mut fields[..fields_len(scene, n)];
    fields.fill(T::ZERO);

    // Field layout, matching Scene::field_count.
    let partner = scene.has_partner_terms();
    let partner_slots = if partner { 2 } else { 1 };
    let mut next = 0;
    let mut take = |slots: usize| {
        let acc = Accumulators {
            own: next,
            partner: if slots == 2 { Some(next + 1) } else { None },
        };
        next += slots;
        acc
    };
    let density_acc = take(partner_slots);

    if channels == 1 {
        let a = plan.channels[0].ambient;
        if !partner {
            // The plain path: one extraction, no accumulators.
            extract_slice(density, kernel, &frame, &mut fields[..nn]);
        } else {
            accumulate_cue(
                density,
                &tables,
                &plan,
                &frame,
                1.0,
                density_acc,
                None,
                fields,
            )?;
            fold_partner(fields, n, density_acc);
        }
        finish_channel(
            &mut fields[..nn],
            n,
            &place,
            gain * a,
            width,
            height,
            tw,
            aux,
            out,
            1,
            0,
        )?;
        return Ok(1);
    }

    let output = take(1).own;
    let gradient_acc = gradient.map(|_| take(partner_slots));
    let derivative_acc = if scene.needs_cue_derivative_fields() {
        Some(take(partner_slots))
    } else {
        None
    };
    accumulate_cue(
        density,
        &tables,
        &plan,
        &frame,
        1.0,
        density_acc,
        derivative_acc,
        fields,
    )?;
    fold_partner(fields, n, density_acc);
    if let Some(d) = derivative_acc {
        fold_partner(fields, n, d);
    }
    if let (Some(g), Some(acc)) = (gradient, gradient_acc) {
        // Bring |∇f| to the density's scaled units.
        accumulate_cue(
            g,
            &tables,
            &plan,
            &frame,
            density.scale() / g.scale(),
            acc,
            None,
            fields,
        )?;
        fold_partner(fields, n, acc);
    }
    let moment_unit = 2.0 * PI / n as f64;
    for (c, ch) in plan.channels.iter().enumerate() {
        let (a, k) = (T::from_f64(ch.ambient), T::from_f64(ch.gradient));
        let mr = T::from_f64(ch.moment[0] * moment_unit);
        let mu = T::from_f64(ch.moment[1] * moment_unit);
        let along = T::from_f64(ch.along_view);
        for iy in 0..n {
            let ky = T::from_i32(signed_index(iy, n) as i32);
            let my = neg_mod(iy, n);
            for ix in 0..n {
                let kx = T::from_i32(signed_index(ix, n) as i32);
                let i = iy * n + ix;
                let mirror = my * n + neg_mod(ix, n);
                let f = &*fields;
                let mut s = a * f[density_acc.own * nn + i]
                    + (kx * mr + ky * mu) * f[density_acc.own * nn + mirror];
                if let Some(g) = gradient_acc {
                    s += k * f[g.own * nn + i];
                }
                if let Some(d) = derivative_acc {
                    s += along * f[d.own * nn + i];
                }
                fields[output * nn + i] = s;
            }
        }
        finish_channel(
            &mut fields[output * nn..(output + 1) * nn],
            n,
            &place,
            gain,
            width,
            height,
            tw,
            aux,
            out,
            channels,
            c,
        )?;
    }
    Ok(channels)
}
