//! The firmware's scene: an analytic phantom, the filters whose spectra are
//! kept in flash, and the frames each program renders.
//!
//! This file is shared, verbatim, by `build.rs` (which samples the phantom
//! and runs the core on the host to make the flash tables) and by the
//! library (which renders the frames on the device, and on the host for the
//! bit-for-bit comparison). It depends on `fvr_core` and `libm` only.
//!
//! # Adding a frame
//! A [`FrameSpec`] names a stored filter and a view. A depth-cued frame needs
//! no new table (it reads the same spectrum); a shaded frame with a
//! directional light needs the `|∇f|` spectrum (paper §3.2, eq. 10): one more
//! [`StoredKind`] and 512 KiB of flash for a 64³ f16 cube.

use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;

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

/// The phantom: six smooth blobs, each within `|μ − c| + 4σ_max ≤ 25.6`
/// voxels of the centre `c = 32` (the sphere of radius 0.4·n used by the
/// host's accuracy table), so Kaiser–Bessel at σ = 1 keeps its accuracy
/// (README, "Warning"). Hand-picked, not random, so the image has distinct
/// features at several scales and orientations.
pub const BLOBS: [Blob; 6] = [
    Blob {
        amplitude: 1.0,
        center: [32.0, 32.0, 32.0],
        sigmas: [6.0, 4.0, 3.0],
        rotation: ROT_Z_3_4_5,
    },
    Blob {
        amplitude: 0.6,
        center: [24.0, 38.0, 30.0],
        sigmas: [3.0, 3.0, 3.5],
        rotation: ROT_X_7_24_25,
    },
    Blob {
        amplitude: 0.8,
        center: [40.0, 26.0, 36.0],
        sigmas: [2.5, 3.5, 2.0],
        rotation: IDENTITY,
    },
    Blob {
        amplitude: 0.5,
        center: [30.0, 24.0, 22.0],
        sigmas: [2.0, 2.0, 2.0],
        rotation: IDENTITY,
    },
    Blob {
        amplitude: 0.7,
        center: [37.0, 38.0, 37.0],
        sigmas: [4.0, 2.0, 2.5],
        rotation: ROT_Y_4_3_5,
    },
    Blob {
        amplitude: 0.4,
        center: [28.0, 30.0, 42.0],
        sigmas: [1.8, 3.0, 2.0],
        rotation: ROT_Z_3_4_5,
    },
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

/// A spectrum kept in flash: the phantom premultiplied for one filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StoredKind {
    /// `F{f·p_m}`: the density, for X-ray and depth-cued views.
    Density(FilterKind),
}

/// Every spectrum `build.rs` makes. Each bin links only the ones its frames
/// use (the linker drops the rest), so each bin's flash budget is checked
/// on its own.
pub const STORED: [StoredKind; 3] = [
    StoredKind::Density(FilterKind::Kb3),
    StoredKind::Density(FilterKind::Kb4),
    StoredKind::Density(FilterKind::Kb6),
];

/// What a frame computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shading {
    /// The X-ray projection `∫ f dt` (paper eq. 1).
    Plain,
}

/// One image a program renders.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSpec {
    /// Short name, used in file names (`<program>-<name>.nrrd`).
    pub name: &'static str,
    /// The interpolation filter (and so the stored spectrum) it uses.
    pub filter: FilterKind,
    /// What it computes.
    pub shading: Shading,
    /// The view.
    pub view: View,
}

/// The view of every frame: oblique, along `(1, 0.3, 0.2)`, as in the host
/// benchmarks (README, "Speed").
pub const VIEW: View = View::along([1.0, 0.3, 0.2]);

/// The scene program (`fvr-scene`): the paper's 3³ filter. Depth-cued and
/// shaded frames of the same view join this list.
pub const SCENE_FRAMES: [FrameSpec; 1] = [FrameSpec {
    name: "plain-kb3",
    filter: FilterKind::Kb3,
    shading: Shading::Plain,
    view: VIEW,
}];

/// The filter benchmark (`fvr-filter-bench`): the same view with kb3, kb4
/// and kb6, for instruction counts.
pub const BENCH_FRAMES: [FrameSpec; 3] = [
    FrameSpec {
        name: "plain-kb3",
        filter: FilterKind::Kb3,
        shading: Shading::Plain,
        view: VIEW,
    },
    FrameSpec {
        name: "plain-kb4",
        filter: FilterKind::Kb4,
        shading: Shading::Plain,
        view: VIEW,
    },
    FrameSpec {
        name: "plain-kb6",
        filter: FilterKind::Kb6,
        shading: Shading::Plain,
        view: VIEW,
    },
];

/// The programs and their frames, for the host-side checks.
pub const PROGRAMS: [(&str, &[FrameSpec]); 2] = [
    ("fvr-scene", &SCENE_FRAMES),
    ("fvr-filter-bench", &BENCH_FRAMES),
];
