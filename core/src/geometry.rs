//! The geometry contract shared by the core, the references and the CLI.
//!
//! - Voxel `(i, j, k)` sits at the point `(i, j, k)`; `i` is the fastest axis
//!   in memory and in files. The rotation centre is `c = (nx/2, ny/2, nz/2)`.
//! - The camera direction `d` points from the eye into the scene. With the up
//!   hint `u0` (default `(0, 0, 1)`): right `r = normalize(d × u0)`, up
//!   `u = r × d`.
//! - Pixel `(col, row)`, row 0 at the top, of a `W × H` image sits at
//!   `p = c + (col − W/2)·r + (H/2 − row)·u`.
//! - Its value is `∫ f(p + t·d) dt` in voxel units, `f` being the
//!   band-limited interpolant of the samples.
//! - A zero `d` or `u0`, or `u0` parallel to `d`, is an error naming both.

use crate::error::{Error, Result};

/// A view as given by the user.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Direction from the eye into the scene (any length but zero).
    pub dir: [f64; 3],
    /// Up hint (any length but zero, not parallel to `dir`).
    pub up: [f64; 3],
}

/// The default up hint, `+z`.
pub const DEFAULT_UP: [f64; 3] = [0.0, 0.0, 1.0];

/// Orthonormal camera frame derived from a [`View`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Unit vector to the right of the image.
    pub right: [f64; 3],
    /// Unit vector to the top of the image.
    pub up: [f64; 3],
    /// Unit viewing direction.
    pub dir: [f64; 3],
}

impl View {
    /// A view along `dir` with the default up hint.
    pub const fn along(dir: [f64; 3]) -> Self {
        Self {
            dir,
            up: DEFAULT_UP,
        }
    }

    /// The camera frame.
    ///
    /// # Errors
    /// A non-finite component, a zero vector, or `up` parallel to `dir`
    /// (within 1e-9 rad).
    pub fn frame(&self) -> Result<Frame> {
        let (d, u0) = (self.dir, self.up);
        let err_fields = (d, u0);
        if d.iter().chain(u0.iter()).any(|v| !v.is_finite()) {
            return Err(Error::NonFiniteViewVector {
                dir: err_fields.0,
                up: err_fields.1,
            });
        }
        let (dn, un) = (norm(d), norm(u0));
        if dn == 0.0 || un == 0.0 {
            return Err(Error::ZeroViewVector { dir: d, up: u0 });
        }
        let r = cross(d, u0);
        if norm(r) <= 1e-9 * dn * un {
            return Err(Error::ParallelViewVectors { dir: d, up: u0 });
        }
        let dir = scale(d, 1.0 / dn);
        let right = scale(r, 1.0 / norm(r));
        let up = cross(right, dir);
        Ok(Frame { right, up, dir })
    }
}

impl Frame {
    /// Position of pixel `(col, row)` of a `width × height` image of a volume
    /// with centre `center` (see the module docs).
    pub fn pixel_position(
        &self,
        center: [f64; 3],
        width: usize,
        height: usize,
        col: f64,
        row: f64,
    ) -> [f64; 3] {
        let a = col - width as f64 / 2.0;
        let b = height as f64 / 2.0 - row;
        core::array::from_fn(|i| center[i] + a * self.right[i] + b * self.up[i])
    }
}

/// The rotation centre `c = (nx/2, ny/2, nz/2)` of a volume.
pub fn center(dims: [usize; 3]) -> [f64; 3] {
    dims.map(|n| n as f64 / 2.0)
}

/// Dot product.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    libm::sqrt(dot(a, a))
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    a.map(|v| v * s)
}
