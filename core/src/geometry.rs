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
//!
//! # Physical units ([`Sampling`])
//!
//! With voxel spacing `Δ = (Δx, Δy, Δz)` and image pixel size `p` (both in
//! mm), the same contract holds in physical space:
//! - Voxel `(i, j, k)` sits at `(i·Δx, j·Δy, k·Δz)`; the rotation centre is
//!   `C = (nx·Δx/2, ny·Δy/2, nz·Δz/2)`.
//! - `d`, `r` and `u` are unit vectors in physical space (the frame above).
//! - Pixel `(col, row)` sits at `P = C + (col − W/2)·p·r + (H/2 − row)·p·u`
//!   (mm), and its value is `∫ f(P + t·d) dt` with `t` in mm: the image is
//!   in mm × (volume units).
//! - By the projection-slice theorem in physical frequencies, the slice
//!   sample at 2D index `(kx, ky)` lies at the 3D index frequency
//!   `kx·r' + ky·u'` with `r'_a = r_a·Δ_a/p` and `u'_a = u_a·Δ_a/p`
//!   ([`SliceAxes`], no longer orthonormal), and the index-space image is
//!   multiplied by `Δx·Δy·Δz/p²` ([`Sampling::gain`]).
//! - [`Sampling::UNIT`] (1 mm voxels and pixels) is the voxel-unit contract
//!   above, bit for bit.

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

/// The two step vectors of a slice in index-space frequency: the slice
/// sample at 2D frequency index `(kx, ky)` is the spectrum at
/// `kx·right + ky·up`. For voxel units they are the frame's orthonormal
/// `r` and `u` ([`Frame::slice_axes`]); with a [`Sampling`] they are scaled
/// per axis ([`Sampling::slice_axes`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SliceAxes {
    /// Index-space step per unit of `kx`.
    pub right: [f64; 3],
    /// Index-space step per unit of `ky`.
    pub up: [f64; 3],
}

/// Voxel spacing and image pixel size in mm (see the module docs): how an
/// index-space spectrum is sliced and scaled for an image in physical units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    spacing: [f64; 3],
    pixel_size: f64,
}

impl Sampling {
    /// 1 mm voxels and 1 mm pixels: voxel units.
    pub const UNIT: Sampling = Sampling {
        spacing: [1.0; 3],
        pixel_size: 1.0,
    };

    /// Voxels `spacing` mm apart along `i`, `j`, `k`, imaged at pixels
    /// `pixel_size` mm apart.
    ///
    /// # Errors
    /// [`Error::InvalidSpacing`] for a spacing that is zero, negative or not
    /// finite (the first such axis), [`Error::InvalidPixelSize`] likewise
    /// for the pixel size, and [`Error::SamplingOutOfRange`] when a ratio
    /// `Δ_a/p` or the gain `Δx·Δy·Δz/p²` is not a finite positive number.
    pub fn new(spacing: [f64; 3], pixel_size: f64) -> Result<Self> {
        if let Some(axis) = spacing.iter().position(|&s| !(s.is_finite() && s > 0.0)) {
            return Err(Error::InvalidSpacing {
                axis,
                value: spacing[axis],
            });
        }
        if !(pixel_size.is_finite() && pixel_size > 0.0) {
            return Err(Error::InvalidPixelSize { value: pixel_size });
        }
        let sampling = Self {
            spacing,
            pixel_size,
        };
        let ratios_ok = spacing.iter().all(|&s| {
            let q = s / pixel_size;
            q.is_finite() && q > 0.0
        });
        let gain = sampling.gain();
        if !(ratios_ok && gain.is_finite() && gain > 0.0) {
            return Err(Error::SamplingOutOfRange {
                spacing,
                pixel_size,
            });
        }
        Ok(sampling)
    }

    /// Voxel spacing `Δ` in mm along `i`, `j`, `k`.
    pub fn spacing(&self) -> [f64; 3] {
        self.spacing
    }

    /// Image pixel size `p` in mm.
    pub fn pixel_size(&self) -> f64 {
        self.pixel_size
    }

    /// `Some(Δ)` when all three spacings equal the pixel size `Δ`: then the
    /// slice axes are the frame's own and only the gain `Δ` differs from
    /// voxel units.
    pub fn uniform_pitch(&self) -> Option<f64> {
        let p = self.pixel_size;
        self.spacing.iter().all(|&s| s == p).then_some(p)
    }

    /// The slice's index-space step vectors for `frame`:
    /// `r'_a = r_a·(Δ_a/p)`, `u'_a = u_a·(Δ_a/p)`. A ratio of exactly 1
    /// leaves a component bit-identical.
    pub fn slice_axes(&self, frame: &Frame) -> SliceAxes {
        let ratio: [f64; 3] = core::array::from_fn(|a| self.spacing[a] / self.pixel_size);
        SliceAxes {
            right: core::array::from_fn(|a| frame.right[a] * ratio[a]),
            up: core::array::from_fn(|a| frame.up[a] * ratio[a]),
        }
    }

    /// The factor from the index-space image to the physical one:
    /// `Δx·Δy·Δz/p²` (a line integral in mm over a pixel of `p²`, against
    /// index-space frequencies of `1/(n·Δ_a)`). Exactly 1 for
    /// [`Sampling::UNIT`].
    pub fn gain(&self) -> f64 {
        let [x, y, z] = self.spacing;
        let p = self.pixel_size;
        (x * y * z) / (p * p)
    }

    /// The rotation centre `C = (n/2)·Δ` in mm of a volume of `dims`.
    pub fn center(&self, dims: [usize; 3]) -> [f64; 3] {
        core::array::from_fn(|a| dims[a] as f64 / 2.0 * self.spacing[a])
    }

    /// Position in mm of pixel `(col, row)` of a `width × height` image of
    /// a volume of `dims` seen in `frame` (see the module docs).
    pub fn pixel_position(
        &self,
        frame: &Frame,
        dims: [usize; 3],
        width: usize,
        height: usize,
        col: f64,
        row: f64,
    ) -> [f64; 3] {
        let c = self.center(dims);
        let p = self.pixel_size;
        let a = (col - width as f64 / 2.0) * p;
        let b = (height as f64 / 2.0 - row) * p;
        core::array::from_fn(|i| c[i] + a * frame.right[i] + b * frame.up[i])
    }
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
    /// A non-finite component, a zero vector, one too short to normalise
    /// ([`too_short`]), or `up` parallel to `dir`
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
        if too_short(d) || too_short(u0) {
            return Err(Error::ShortViewVector {
                dir: err_fields.0,
                up: err_fields.1,
            });
        }
        // Components near the ends of the f64 range (1e±300) would make the
        // norms and the cross product overflow or vanish: scale such a vector
        // by its largest component first, which keeps its direction.
        let (d, u0) = (fit_range(d), fit_range(u0));
        let (dn, un) = (norm(d), norm(u0));
        if dn == 0.0 || un == 0.0 {
            return Err(Error::ZeroViewVector {
                dir: err_fields.0,
                up: err_fields.1,
            });
        }
        let r = cross(d, u0);
        if norm(r) <= 1e-9 * dn * un {
            return Err(Error::ParallelViewVectors {
                dir: err_fields.0,
                up: err_fields.1,
            });
        }
        let dir = scale(d, 1.0 / dn);
        let right = scale(r, 1.0 / norm(r));
        let up = cross(right, dir);
        Ok(Frame { right, up, dir })
    }
}

impl Frame {
    /// The slice axes in voxel units: `r` and `u` themselves.
    pub fn slice_axes(&self) -> SliceAxes {
        SliceAxes {
            right: self.right,
            up: self.up,
        }
    }

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

/// Whether `a` is not zero but too short to normalise: every component
/// subnormal (below `2^−1022`), so that dividing by its largest one
/// overflows. Front ends refuse such vectors with this rule before any
/// work, naming their option; [`View::frame`] and the scene's validation
/// refuse them too.
pub fn too_short(a: [f64; 3]) -> bool {
    let largest = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    largest > 0.0 && largest < f64::MIN_POSITIVE
}

/// `a` itself when its norm is comfortably inside the f64 range, else `a`
/// divided by its largest absolute component.
pub(crate) fn fit_range(a: [f64; 3]) -> [f64; 3] {
    let n = norm(a);
    if (1e-150..1e150).contains(&n) {
        return a;
    }
    let m = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if m > 0.0 {
        scale(a, 1.0 / m)
    } else {
        a
    }
}

fn norm(a: [f64; 3]) -> f64 {
    libm::sqrt(dot(a, a))
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    a.map(|v| v * s)
}
