//! Turntable animations: one prepared spectrum, many views around an axis.
//!
//! The preprocessing (premultiplication, padding, 3D transform) is done
//! once; each frame is then one slice extraction and one 2D inverse
//! transform, reusing one set of per-view buffers ([`ViewRenderer`]).

use std::f64::consts::TAU;

use fvr_core::geometry::{Sampling, View};
use fvr_core::num::{Real, Sample};

use crate::render::view::ViewRenderer;
use crate::spectrum::{AnySpectrum, OwnedSpectrum};

/// The `frames` view directions of a full turn of `start` about `axis`
/// (right-handed, starting at `start`), each with `axis` as the up hint.
///
/// Frame `k` looks along `start` rotated by `2πk/frames` about `axis`
/// (Rodrigues' formula), so the camera circles the volume at a constant
/// elevation and the last frame leads smoothly back to the first.
///
/// # Errors
/// `frames` is 0; `start` or `axis` is zero or not finite, or they are
/// parallel (every frame would look along the axis).
pub fn orbit(start: [f64; 3], axis: [f64; 3], frames: usize) -> Result<Vec<View>, String> {
    if frames == 0 {
        return Err("a turntable needs at least 1 frame".into());
    }
    let first = View {
        dir: start,
        up: axis,
    };
    first.frame().map_err(|e| e.to_string())?;
    let norm = dot(axis, axis).sqrt();
    let u = axis.map(|c| c / norm);
    let cross = [
        u[1] * start[2] - u[2] * start[1],
        u[2] * start[0] - u[0] * start[2],
        u[0] * start[1] - u[1] * start[0],
    ];
    let along = dot(u, start);
    Ok((0..frames)
        .map(|k| {
            let theta = TAU * k as f64 / frames as f64;
            let (s, c) = theta.sin_cos();
            let dir = [0, 1, 2].map(|i| start[i] * c + cross[i] * s + u[i] * along * (1.0 - c));
            View { dir, up: axis }
        })
        .collect())
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Render every view of `views` at `width × height` in the physical units
/// of `sampling` ([`fvr_core::render::render_sampled`]; `Sampling::UNIT`
/// for voxel units), advancing `progress` by one per frame. Frames come
/// back in f64, row 0 at the top.
///
/// # Errors
/// As [`fvr_core::render::render`] (an image larger than the grid, ...).
pub fn render_views(
    spec: &AnySpectrum,
    views: &[View],
    sampling: &Sampling,
    width: usize,
    height: usize,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<Vec<f64>>, fvr_core::Error> {
    let mut frames = Vec::with_capacity(views.len());
    render_each(
        spec,
        views,
        sampling,
        (width, height),
        1,
        progress,
        |_, f| {
            frames.push(f.to_vec());
            Ok::<(), fvr_core::Error>(())
        },
    )?;
    Ok(frames)
}

/// Where [`render_each`] hands each frame: `(index, pixels)`.
pub type FrameSink<'a, E> = dyn FnMut(usize, &[f64]) -> Result<(), E> + 'a;

/// Render the views one by one like [`render_views`], handing each frame to
/// `each(index, pixels)` instead of keeping it: memory is one frame. With
/// `zoom` above 1 each frame is magnified as
/// [`AnySpectrum::render_zoomed`] magnifies a view: `zoom` times as many
/// pixels per side of the field of view of `size`.
///
/// # Errors
/// As [`render_views`], a zoom [`crate::image::zoom::zoomed_side`]
/// refuses, or the first error of `each`.
pub fn render_each<E: From<fvr_core::Error>>(
    spec: &AnySpectrum,
    views: &[View],
    sampling: &Sampling,
    size: (usize, usize),
    zoom: usize,
    progress: &(dyn Fn() + Sync),
    mut each: impl FnMut(usize, &[f64]) -> Result<(), E>,
) -> Result<(), E> {
    #[allow(clippy::too_many_arguments)]
    fn go<S: Sample, T: Real, E: From<fvr_core::Error>>(
        s: &OwnedSpectrum<S>,
        views: &[View],
        sampling: &Sampling,
        (w, h): (usize, usize),
        zoom: usize,
        progress: &(dyn Fn() + Sync),
        each: &mut FrameSink<'_, E>,
    ) -> Result<(), E> {
        let mut renderer = ViewRenderer::<T>::new(s.n(), s.filter()).with_zoom(zoom)?;
        let pixels = (w * zoom).saturating_mul(h * zoom);
        let mut out = vec![T::ZERO; pixels];
        let mut frame = vec![0.0f64; pixels];
        for (i, view) in views.iter().enumerate() {
            renderer.render_sampled_into(s, view, sampling, w, h, &mut out)?;
            for (f, v) in frame.iter_mut().zip(&out) {
                *f = v.to_f64();
            }
            each(i, &frame)?;
            progress();
        }
        Ok(())
    }
    match spec {
        AnySpectrum::F16(s) => go::<_, f32, E>(s, views, sampling, size, zoom, progress, &mut each),
        AnySpectrum::F32(s) => go::<_, f32, E>(s, views, sampling, size, zoom, progress, &mut each),
        AnySpectrum::F64(s) => go::<_, f64, E>(s, views, sampling, size, zoom, progress, &mut each),
    }
}
