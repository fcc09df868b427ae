//! A [`Scene`]'s view: the cued and shaded spectra accumulated on the slice
//! ([`crate::shading`]), combined per channel, and each channel finished
//! into the interleaved image.
//!
//! Channel `c`'s slice is
//! `A_c·DC_f(k) + K_c·DC_|∇f|(k) + (2π/n)·(k·M_c)·DC_f(−k) + (d·M_c)·DC'_f(k)`
//! with `K_c = Σ_l ½D_{l,c}` and `M_c = Σ_l ½D_{l,c}·L_l` (all lights in one
//! moment; the terms are those of [`crate::shading`]'s module docs), and is
//! inverse-transformed like a plain projection.

use super::{Buffers, Request, Source};
use crate::dht::{neg_mod, signed_index};
use crate::error::{require_len, Error, Result};
use crate::image::{aux_len, check_image, finish, placement, Crop};
use crate::num::{Real, Sample};
use crate::shading::{
    accumulate_cue, fields_len, fold_partner, Accumulators, CueView, Scene, Tables, ViewPlan,
};
use crate::slice::extract_slice;
use crate::spectrum::CubeSide;

const PI: f64 = core::f64::consts::PI;

/// Render `scene` as [`super::render`] does: `grid` needs
/// [`fields_len`]`(scene, n)` elements, `aux` [`aux_len`]`(n)` and `out`
/// `channels·width·height`. Returns the number of channels written.
///
/// # Errors
/// As [`super::render`].
pub(super) fn render_scene<S: Sample, Z: CubeSide, T: Real>(
    source: &Source<'_, S, Z, T>,
    scene: &Scene,
    request: &Request<'_>,
    buffers: Buffers<'_, T>,
) -> Result<usize> {
    let Source {
        spectrum: density,
        gradient,
        kernel,
        derivative,
        twiddles: tw,
    } = *source;
    let (view, width, height) = (&request.view, request.width, request.height);
    let Buffers {
        grid: fields,
        aux,
        out,
    } = buffers;
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
    let cue = CueView {
        tables: Tables { kernel, derivative },
        plan: &plan,
        frame: &frame,
    };
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
            accumulate_cue(density, &cue, 1.0, density_acc, None, fields)?;
            fold_partner(fields, n, density_acc);
        }
        let crop = Crop {
            place,
            gain: gain * a,
            width,
            height,
            channels: 1,
            channel: 0,
        };
        finish(&mut fields[..nn], n, &crop, tw, aux, out)?;
        return Ok(1);
    }

    let output = take(1).own;
    let gradient_acc = gradient.map(|_| take(partner_slots));
    let derivative_acc = if scene.needs_cue_derivative_fields() {
        Some(take(partner_slots))
    } else {
        None
    };
    accumulate_cue(density, &cue, 1.0, density_acc, derivative_acc, fields)?;
    fold_partner(fields, n, density_acc);
    if let Some(d) = derivative_acc {
        fold_partner(fields, n, d);
    }
    if let (Some(g), Some(acc)) = (gradient, gradient_acc) {
        // Bring |∇f| to the density's scaled units.
        accumulate_cue(g, &cue, density.scale() / g.scale(), acc, None, fields)?;
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
        let crop = Crop {
            place,
            gain,
            width,
            height,
            channels,
            channel: c,
        };
        finish(
            &mut fields[output * nn..(output + 1) * nn],
            n,
            &crop,
            tw,
            aux,
            out,
        )?;
    }
    Ok(channels)
}
