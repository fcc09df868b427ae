//! The firmware's scene: an analytic phantom, the filters whose spectra are
//! kept in flash, and the frames each program renders.
//!
//! This file is shared, verbatim, by `build.rs` (which samples the phantom
//! and runs the core on the host to make the flash tables) and by the
//! library (which renders the frames on the device, and on the host for the
//! bit-for-bit comparison). It depends on `fvr_core` and `libm` only.
//!
//! # Adding a frame
//! A [`FrameSpec`] names a stored filter, a view and what it computes
//! ([`Shading`]). A plain frame reads the density spectrum. A
//! [`Shading::Scene`] frame is rendered by `fvr_core::render::render` with a scene
//! and needs, besides the density spectrum:
//! - with a linear depth cue, the kernel-derivative table of its filter
//!   (paper eq. 5), listed in [`DERIVATIVES`]: `W·512 + 1` f32 (6 KiB for
//!   kb3);
//! - with a light, the `|∇f|` spectrum (paper §3.2, eq. 10), a
//!   [`StoredKind::GradientMagnitude`] in [`STORED`]: 512 KiB for a 64³ f16
//!   cube.
//!
//! A program names the tables it links (`src/bin/*.rs`); it must name
//! exactly those its frames read (`frame::check_linked_tables`, run on the
//! device before any frame), and `build.rs` checks each program's flash
//! budget from its frames. The buffers are sized from the frames too
//! ([`buffer_sizes`]).

use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;
use fvr_core::shading::{field_count_of, DepthCue, Light, Scene};

/// Side of the phantom's cube (voxels); also the padded spectrum side at
/// oversampling 1.
pub const SIDE: usize = 64;

/// Dimensions of the phantom volume.
pub const DIMS: [usize; 3] = [SIDE; 3];

/// Oversampling of every stored spectrum.
pub const OVERSAMPLE: u32 = 1;

/// Side of every rendered image (pixels), the spectrum's grid side.
pub const IMAGE_SIDE: usize = 64;

/// One anisotropic Gaussian blob:
/// `amplitude · exp(−½ |diag(1/σ) Rᵀ (p − center)|²)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blob {
    /// Peak density.
    pub amplitude: f64,
    /// Centre (voxel units).
    pub center: [f64; 3],
    /// Standard deviations along the principal axes (voxels).
    pub sigmas: [f64; 3],
    /// Rotation `R`; its columns are the principal axes.
    pub rotation: [[f64; 3]; 3],
}

const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// Rotations by the angles of the Pythagorean triples (3, 4, 5) and
/// (7, 24, 25), so that no trigonometry is needed to write them down.
const ROT_Z_3_4_5: [[f64; 3]; 3] = [[0.6, -0.8, 0.0], [0.8, 0.6, 0.0], [0.0, 0.0, 1.0]];
const ROT_X_7_24_25: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 0.28, -0.96], [0.0, 0.96, 0.28]];
const ROT_Y_4_3_5: [[f64; 3]; 3] = [[0.8, 0.0, 0.6], [0.0, 1.0, 0.0], [-0.6, 0.0, 0.8]];

/// A [`Blob`] in one line of the table below.
const fn blob(amplitude: f64, center: [f64; 3], sigmas: [f64; 3], rotation: [[f64; 3]; 3]) -> Blob {
    Blob {
        amplitude,
        center,
        sigmas,
        rotation,
    }
}

/// The phantom: six smooth blobs, each within `|μ − c| + 4σ_max ≤ 25.6`
/// voxels of the centre `c = 32` (the sphere of radius 0.4·n used by the
/// host's accuracy table), so Kaiser–Bessel at σ = 1 keeps its accuracy
/// (README, "Warning"). Hand-picked, not random, so the image has distinct
/// features at several scales and orientations.
pub const BLOBS: [Blob; 6] = [
    blob(1.0, [32.0, 32.0, 32.0], [6.0, 4.0, 3.0], ROT_Z_3_4_5),
    blob(0.6, [24.0, 38.0, 30.0], [3.0, 3.0, 3.5], ROT_X_7_24_25),
    blob(0.8, [40.0, 26.0, 36.0], [2.5, 3.5, 2.0], IDENTITY),
    blob(0.5, [30.0, 24.0, 22.0], [2.0, 2.0, 2.0], IDENTITY),
    blob(0.7, [37.0, 38.0, 37.0], [4.0, 2.0, 2.5], ROT_Y_4_3_5),
    blob(0.4, [28.0, 30.0, 42.0], [1.8, 3.0, 2.0], ROT_Z_3_4_5),
];

/// Density of the phantom at `p` (voxel units), in f64.
pub fn density(p: [f64; 3]) -> f64 {
    BLOBS
        .iter()
        .map(|b| {
            let d = [p[0] - b.center[0], p[1] - b.center[1], p[2] - b.center[2]];
            let mut q = 0.0;
            for axis in 0..3 {
                let r = &b.rotation;
                let y = r[0][axis] * d[0] + r[1][axis] * d[1] + r[2][axis] * d[2];
                let w = y / b.sigmas[axis];
                q += w * w;
            }
            b.amplitude * libm::exp(-0.5 * q)
        })
        .sum()
}

/// A spectrum kept in flash: the phantom, or its gradient magnitude,
/// premultiplied for one filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StoredKind {
    /// `F{f·p_m}`: the density, for every frame.
    Density(FilterKind),
    /// `F{|∇f|·p_m}`: the gradient magnitude of the band-limited interpolant
    /// (`fvr_core::shading::gradient::gradient_magnitude`), for frames with a light.
    /// It is premultiplied for the same filter (the same β) as the density.
    GradientMagnitude(FilterKind),
}

impl StoredKind {
    /// The interpolation filter it was premultiplied for.
    pub const fn filter(self) -> FilterKind {
        match self {
            StoredKind::Density(kind) | StoredKind::GradientMagnitude(kind) => kind,
        }
    }

    /// What was transformed, in file and static names: `density` or
    /// `gradient`.
    pub const fn prefix(self) -> &'static str {
        match self {
            StoredKind::Density(_) => "density",
            StoredKind::GradientMagnitude(_) => "gradient",
        }
    }
}

/// Every spectrum `build.rs` makes. Each bin links only the ones its frames
/// use (the linker drops the rest), so each bin's flash budget is checked
/// on its own.
pub const STORED: [StoredKind; 4] = [
    StoredKind::Density(FilterKind::Kb3),
    StoredKind::Density(FilterKind::Kb4),
    StoredKind::Density(FilterKind::Kb6),
    StoredKind::GradientMagnitude(FilterKind::Kb3),
];

/// The filters whose kernel-derivative tables `build.rs` makes (for frames
/// with a linear depth cue).
pub const DERIVATIVES: [FilterKind; 1] = [FilterKind::Kb3];

/// A depth cue a frame uses: the part of `fvr_core::shading::DepthCue` this
/// scene needs, in a form that can be a constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cue {
    /// No cue: `w = 1`.
    None,
    /// `w(t)` linear from `front` at `t = −R` to `back` at `t = +R` (eq. 3).
    Linear {
        /// Weight at the front.
        front: f64,
        /// Weight at the back.
        back: f64,
    },
}

/// A depth-cued and/or shaded view's scene (the core's
/// `fvr_core::shading::Scene`, as a constant).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneSpec {
    /// The depth cue.
    pub cue: Cue,
    /// Ambient colour `A_c` (linear RGB).
    pub ambient: [f64; 3],
    /// Directional lights.
    pub lights: &'static [Light],
}

impl SceneSpec {
    /// The core's scene.
    ///
    /// # Errors
    /// As `Scene::add_light` and `Scene::validate`: too many lights, a zero
    /// light vector, a negative or non-finite colour or weight.
    pub fn scene(&self) -> Result<Scene, fvr_core::Error> {
        let mut scene = Scene {
            cue: match self.cue {
                Cue::None => DepthCue::None,
                Cue::Linear { front, back } => DepthCue::Linear { front, back },
            },
            ambient: self.ambient,
            ..Scene::xray()
        };
        for light in self.lights {
            scene.add_light(*light)?;
        }
        scene.validate()?;
        Ok(scene)
    }

    /// `Scene::needs_gradient_spectrum`, as a constant.
    pub const fn needs_gradient_spectrum(&self) -> bool {
        let mut i = 0;
        while i < self.lights.len() {
            let c = self.lights[i].color;
            if c[0] != 0.0 || c[1] != 0.0 || c[2] != 0.0 {
                return true;
            }
            i += 1;
        }
        false
    }

    /// `Scene::needs_kernel_derivative`, as a constant.
    pub const fn needs_kernel_derivative(&self) -> bool {
        matches!(self.cue, Cue::Linear { front, back } if front != back)
    }

    /// `Scene::channels`, as a constant (the image buffers are sized by it).
    pub const fn channels(&self) -> usize {
        let a = self.ambient;
        if self.needs_gradient_spectrum() || a[0] != a[1] || a[1] != a[2] {
            3
        } else {
            1
        }
    }

    /// `Scene::field_count`, as a constant (the slice-sized scratch grids
    /// `render_scene` needs; the field buffer is sized by it).
    pub const fn field_count(&self) -> usize {
        // A depth-varying cue has terms at the partner point −k; the eq. 14
        // correction (on in `Scene::xray()`) adds the cue-derivative fields
        // where there are both.
        let partner = self.needs_kernel_derivative();
        let gradient = self.needs_gradient_spectrum();
        field_count_of(partner, self.channels(), gradient, gradient && partner)
    }
}

/// What a frame computes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shading {
    /// The X-ray projection `∫ f dt` (paper eq. 1), by
    /// `fvr_core::render::render`.
    Plain,
    /// A depth-cued and/or shaded image (paper §3), by
    /// `fvr_core::render::render` with a scene.
    Scene(SceneSpec),
}

impl Shading {
    /// Channels of the image: 1 (grey) or 3 (RGB, channel fastest).
    pub const fn channels(&self) -> usize {
        match self {
            Shading::Plain => 1,
            Shading::Scene(s) => s.channels(),
        }
    }

    /// Slice-sized grids of scratch the frame needs (the plain render's
    /// slice grid is one).
    pub const fn field_count(&self) -> usize {
        match self {
            Shading::Plain => 1,
            Shading::Scene(s) => s.field_count(),
        }
    }

    /// `true` if the frame reads the `|∇f|` spectrum.
    pub const fn needs_gradient_spectrum(&self) -> bool {
        match self {
            Shading::Plain => false,
            Shading::Scene(s) => s.needs_gradient_spectrum(),
        }
    }

    /// `true` if the frame reads the kernel-derivative table.
    pub const fn needs_kernel_derivative(&self) -> bool {
        match self {
            Shading::Plain => false,
            Shading::Scene(s) => s.needs_kernel_derivative(),
        }
    }
}

/// One image a program renders.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSpec {
    /// Short name, used in file names (`<program>-<name>.nrrd`).
    pub name: &'static str,
    /// The interpolation filter (and so the stored spectra) it uses.
    pub filter: FilterKind,
    /// What it computes.
    pub shading: Shading,
    /// The view.
    pub view: View,
}

impl FrameSpec {
    /// The stored spectra the frame reads: the density, and the `|∇f|`
    /// spectrum if it has a light.
    pub const fn spectra(&self) -> (StoredKind, Option<StoredKind>) {
        let gradient = if self.shading.needs_gradient_spectrum() {
            Some(StoredKind::GradientMagnitude(self.filter))
        } else {
            None
        };
        (StoredKind::Density(self.filter), gradient)
    }
}

/// Sizes of the buffers a program's frames render into, in f32 elements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BufferSizes {
    /// Slice-sized scratch grids: the largest [`Shading::field_count`],
    /// times `IMAGE_SIDE²`.
    pub fields: usize,
    /// An image of the most channels: `channels·IMAGE_SIDE²`.
    pub image: usize,
}

/// The buffers `frames` need (for statics sized at compile time).
pub const fn buffer_sizes(frames: &[FrameSpec]) -> BufferSizes {
    let (mut fields, mut channels) = (1, 1);
    let mut i = 0;
    while i < frames.len() {
        let s = frames[i].shading;
        if s.field_count() > fields {
            fields = s.field_count();
        }
        if s.channels() > channels {
            channels = s.channels();
        }
        i += 1;
    }
    let grid = IMAGE_SIDE * IMAGE_SIDE;
    BufferSizes {
        fields: fields * grid,
        image: channels * grid,
    }
}

/// The view of every frame: oblique, along `(1, 0.3, 0.2)`, as in the host
/// benchmarks (README, "Speed").
pub const VIEW: View = View::along([1.0, 0.3, 0.2]);

/// Three coloured lights (linear RGB), none perpendicular to [`VIEW`]
/// (`d·L/|L|` = 0.24, −0.61 and −0.07 with `d` the unit view direction): red
/// from above and behind, green from the eye's side (the eq. 14 correction
/// matters most for it), blue from below, nearly grazing.
pub const LIGHTS: [Light; 3] = [
    Light {
        towards: [0.0, 0.2, 1.0],
        color: [1.0, 0.2, 0.1],
    },
    Light {
        towards: [-0.8, 0.6, -0.3],
        color: [0.15, 0.9, 0.2],
    },
    Light {
        towards: [0.3, -1.0, -0.4],
        color: [0.1, 0.3, 1.0],
    },
];

/// The linear depth cue of the cued frames: full weight at the front,
/// 0.2 at the back (a positive weight everywhere inside the volume on this
/// view, checked by the host tests).
pub const LINEAR_CUE: Cue = Cue::Linear {
    front: 1.0,
    back: 0.2,
};

/// The ambient colour of the lit frames.
pub const AMBIENT: [f64; 3] = [0.15, 0.15, 0.2];

/// A frame of [`VIEW`] in one line of the tables below.
const fn frame(name: &'static str, filter: FilterKind, shading: Shading) -> FrameSpec {
    FrameSpec {
        name,
        filter,
        shading,
        view: VIEW,
    }
}

/// A cued or shaded frame's [`Shading`].
const fn lit(cue: Cue, ambient: [f64; 3], lights: &'static [Light]) -> Shading {
    Shading::Scene(SceneSpec {
        cue,
        ambient,
        lights,
    })
}

/// The scene program (`fvr-scene`): the paper's 3³ filter, the plain
/// X-ray view, a depth-cued one (paper fig. 6b), a shaded one with three
/// coloured lights (fig. 8) and both (fig. 6d).
pub const SCENE_FRAMES: [FrameSpec; 4] = [
    frame("plain-kb3", FilterKind::Kb3, Shading::Plain),
    frame("cued-kb3", FilterKind::Kb3, lit(LINEAR_CUE, [1.0; 3], &[])),
    frame("lit-kb3", FilterKind::Kb3, lit(Cue::None, AMBIENT, &LIGHTS)),
    frame(
        "lit-cued-kb3",
        FilterKind::Kb3,
        lit(LINEAR_CUE, AMBIENT, &LIGHTS),
    ),
];
/// The filter benchmark (`fvr-filter-bench`): the same view with kb3, kb4
/// and kb6, for instruction counts.
pub const BENCH_FRAMES: [FrameSpec; 3] = [
    frame("plain-kb3", FilterKind::Kb3, Shading::Plain),
    frame("plain-kb4", FilterKind::Kb4, Shading::Plain),
    frame("plain-kb6", FilterKind::Kb6, Shading::Plain),
];

/// The programs and their frames, for the host-side checks.
pub const PROGRAMS: [(&str, &[FrameSpec]); 2] = [
    ("fvr-scene", &SCENE_FRAMES),
    ("fvr-filter-bench", &BENCH_FRAMES),
];
