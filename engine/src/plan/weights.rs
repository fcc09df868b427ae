//! The interpolation weights along one axis of the padded grid, and which
//! positions count towards the edge term.

use std::f64::consts::PI;

use fvr_core::filter::Filter;

/// The weights' leak `|c − 1| + |s|` above which an axis position counts
/// towards the edge term (−40 dB), if it is also [`EDGE_OVER_CENTRE`] times
/// the leak at the centre (even-width kernels have one more tap on one side,
/// which alone errs by about 2% everywhere at oversampling 1).
pub const EDGE_LEAK: f64 = 0.01;

/// See [`EDGE_LEAK`].
pub const EDGE_OVER_CENTRE: f64 = 2.0;

/// One axis of the padded grid: the interpolation weights at each grid index
/// (signed distance `x` from the transform origin, `x ∈ [−n/2, n/2)`).
pub(super) struct AxisWeights {
    pub(super) c: Vec<f64>,
    pub(super) s: Vec<f64>,
    pub(super) p: Vec<f64>,
    pub(super) edge: Vec<bool>,
}

fn signed(idx: usize, n: usize) -> i64 {
    if idx < n / 2 || n == 1 {
        idx as i64
    } else {
        idx as i64 - n as i64
    }
}

pub(super) fn axis_weights(filter: &Filter, n: usize) -> AxisWeights {
    let w = filter.width() as i64;
    // First tap of a sample at integer index q: j0 = ⌊q − W/2⌋ + 1; offsets q − j.
    let j0 = (-(w as f64) / 2.0).floor() as i64 + 1;
    let taps: Vec<(f64, f64)> = (0..w)
        .map(|m| {
            let t = (-j0 - m) as f64;
            (t, filter.kernel(t))
        })
        .collect();
    let mut out = AxisWeights {
        c: vec![0.0; n],
        s: vec![0.0; n],
        p: vec![0.0; n],
        edge: vec![false; n],
    };
    for idx in 0..n {
        let nu = signed(idx, n) as f64 / n as f64;
        let p = 1.0 / filter.response(nu);
        let (mut c, mut s) = (0.0, 0.0);
        for &(t, k) in &taps {
            c += k * (2.0 * PI * t * nu).cos();
            s += k * (2.0 * PI * t * nu).sin();
        }
        out.c[idx] = c * p;
        out.s[idx] = s * p;
        out.p[idx] = p;
    }
    let leak = |idx: usize| (out.c[idx] - 1.0).abs() + out.s[idx].abs();
    let threshold = EDGE_LEAK.max(EDGE_OVER_CENTRE * leak(0));
    for idx in 0..n {
        out.edge[idx] = leak(idx) > threshold;
    }
    out
}

/// The in-plane axes of the view along axis `a`, lower first.
pub(super) fn in_plane(a: usize) -> (usize, usize) {
    match a {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}
