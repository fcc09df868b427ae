//! The spatial-domain peer: an f32 ray caster for X-ray line integrals,
//! built to be a fair opponent for the frequency-domain path (paper §5
//! compares against its own spatial renderer).
//!
//! - Trilinear reconstruction, the usual choice of spatial renderers.
//! - Each ray is clipped to the box where trilinear interpolation is
//!   non-zero, `[0, n_a − 1]` per axis (slab test), so no step is spent
//!   outside the data.
//! - Samples at a fixed `step` along the ray, with the midpoint rule; the
//!   position advances by adding the step vector (no per-sample matrix).
//! - Rays are independent; image rows are split across threads, and each
//!   thread walks its rows in order, so neighbouring rays touch the same
//!   cache lines.
//! - The volume is held as f32 (4 bytes a voxel; the frequency path holds 2).
//!
//! Same geometry contract as the core ([`fvr_core::geometry`]).

use fvr_core::geometry::{center, View};
use fvr_engine::volume::Volume;

/// A volume ready for ray casting.
#[derive(Clone, Debug)]
pub struct RayCaster {
    dims: [usize; 3],
    data: Vec<f32>,
}

impl RayCaster {
    /// Copy `volume` for casting.
    pub fn new(volume: &Volume) -> Self {
        Self {
            dims: volume.dims,
            data: volume.data.clone(),
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.data.as_slice())
    }

    /// The X-ray image along `view` (`width × height`, row 0 at the top,
    /// voxel units), sampling every `step` voxels, on `threads` threads
    /// (0: all available).
    ///
    /// # Errors
    /// Bad view vectors, or a step that is not a positive finite number.
    pub fn project(
        &self,
        view: &View,
        width: usize,
        height: usize,
        step: f32,
        threads: usize,
    ) -> Result<Vec<f32>, String> {
        let frame = view.frame().map_err(|e| e.to_string())?;
        if !(step.is_finite() && step > 0.0) {
            return Err(format!("ray step must be a positive number, got {step}"));
        }
        let threads = if threads == 0 {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        } else {
            threads
        };
        let c = center(self.dims);
        let mut out = vec![0.0f32; width * height];
        let rows_per = height.div_ceil(threads.max(1)).max(1);
        std::thread::scope(|scope| {
            for (chunk, rows) in out.chunks_mut(rows_per * width).enumerate() {
                let frame = &frame;
                scope.spawn(move || {
                    for (r, line) in rows.chunks_mut(width).enumerate() {
                        let row = chunk * rows_per + r;
                        for (col, o) in line.iter_mut().enumerate() {
                            let p = frame.pixel_position(c, width, height, col as f64, row as f64);
                            *o = self.cast(p, frame.dir, step);
                        }
                    }
                });
            }
        });
        Ok(out)
    }

    /// `∫ f(p + t·d) dt` by the midpoint rule over the clipped segment.
    fn cast(&self, p: [f64; 3], d: [f64; 3], step: f32) -> f32 {
        let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
        for a in 0..3 {
            let hi = (self.dims[a] - 1) as f64;
            if d[a].abs() < 1e-12 {
                if p[a] < 0.0 || p[a] > hi {
                    return 0.0;
                }
            } else {
                let (a0, a1) = ((0.0 - p[a]) / d[a], (hi - p[a]) / d[a]);
                t0 = t0.max(a0.min(a1));
                t1 = t1.min(a0.max(a1));
            }
        }
        if t1 <= t0 {
            return 0.0;
        }
        // Midpoints on a grid of `step` anchored at the plane t = 0 through
        // the centre, so the sampling does not shift with the clipping.
        let h = step as f64;
        let first = ((t0 / h) - 0.5).ceil();
        let last = ((t1 / h) - 0.5).floor();
        if last < first {
            return 0.0;
        }
        let count = (last - first) as usize + 1;
        let t = (first + 0.5) * h;
        let mut x = [
            (p[0] + t * d[0]) as f32,
            (p[1] + t * d[1]) as f32,
            (p[2] + t * d[2]) as f32,
        ];
        let dx = [(h * d[0]) as f32, (h * d[1]) as f32, (h * d[2]) as f32];
        let (nx, ny) = (self.dims[0], self.dims[1]);
        let plane = nx * ny;
        let max = [
            (self.dims[0] - 1) as f32,
            (self.dims[1] - 1) as f32,
            (self.dims[2] - 1) as f32,
        ];
        let mut sum = 0.0f32;
        for _ in 0..count {
            // Clamp against rounding at the box faces; a sample exactly on
            // the last face uses the cell below it with weight 1.
            let q = [
                x[0].clamp(0.0, max[0]),
                x[1].clamp(0.0, max[1]),
                x[2].clamp(0.0, max[2]),
            ];
            let i = [
                (q[0] as usize).min(self.dims[0].saturating_sub(2)),
                (q[1] as usize).min(self.dims[1].saturating_sub(2)),
                (q[2] as usize).min(self.dims[2].saturating_sub(2)),
            ];
            let f = [q[0] - i[0] as f32, q[1] - i[1] as f32, q[2] - i[2] as f32];
            let base = i[0] + nx * i[1] + plane * i[2];
            let (sx, sy, sz) = (
                usize::from(self.dims[0] > 1),
                if self.dims[1] > 1 { nx } else { 0 },
                if self.dims[2] > 1 { plane } else { 0 },
            );
            let v = |o: usize| self.data[base + o];
            let c00 = v(0) + f[0] * (v(sx) - v(0));
            let c10 = v(sy) + f[0] * (v(sy + sx) - v(sy));
            let c01 = v(sz) + f[0] * (v(sz + sx) - v(sz));
            let c11 = v(sz + sy) + f[0] * (v(sz + sy + sx) - v(sz + sy));
            let c0 = c00 + f[1] * (c10 - c00);
            let c1 = c01 + f[1] * (c11 - c01);
            sum += c0 + f[2] * (c1 - c0);
            x[0] += dx[0];
            x[1] += dx[1];
            x[2] += dx[2];
        }
        sum * step
    }
}
