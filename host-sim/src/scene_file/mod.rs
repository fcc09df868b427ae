//! TOML scene files: everything `fvr render` (and `fvr turntable`) needs,
//! in one shareable file.
//!
//! A scene file mirrors the command line: each key is the long flag of the
//! same name, with `-` written `_`, grouped into tables. Every key is
//! optional; a value given on the command line overrides the scene's, and a
//! value in neither falls back to the flag's default (precedence: flags, then
//! scene, then defaults).
//!
//! ```toml
//! [volume]
//! builtin = "teapot@128"        # a phantom or data set name; or:
//! # path = "head.nii.gz"        # a file, relative to this scene file
//! # raw_dims = [256, 256, 108]  # raw_type = "u16", raw_endian = "little"
//! # background = -1024          # resample = 128
//! # ignore_spacing = false      # true: voxel units, as if the voxels were 1 mm cubes
//!
//! [camera]
//! dir = [1, 0.45, -0.3]         # from the eye into the scene
//! up = [0, 0, 1]
//! size = 256                    # or [width, height]
//! # pixel_size = 0.8            # mm; default: the smallest spacing
//!
//! [spectrum]
//! accuracy = 50                 # dB: the planner chooses what is not given below
//! # filter = "kb4"              # oversample = 1.25, precision = "f16", kb_design = "auto"
//!
//! [shading]
//! ambient = 0.05                # or [r, g, b]
//! depth_cue = "linear:1,0.3"    # cue_harmonics = 8, cue_correction = true
//!
//! [light_ring]                  # lights evenly spaced around the view
//! count = 3
//! tilt = 30
//!
//! [[lights]]                    # any number of these, up to 8 lights in all
//! direction = [0, 1, 0]         # towards the light
//! color = [1, 0.2, 0.1]         # or one grey value
//!
//! [output]
//! path = "teapot.png"           # relative to this scene file
//! bits = 8                      # window = 1.0, level = 0.5, percentiles = [0.5, 99.5]
//! colormap = "gray"
//!
//! [turntable]                   # used by `fvr turntable --scene` only
//! frames = 72
//! fps = 24
//! path = "spin.apng"
//! ```
//!
//! Relative paths in a scene (`volume.path`, `output.path`,
//! `turntable.path`, and the file of a `profile:@FILE` depth cue) are
//! relative to the directory of the scene file, so a scene and its data can
//! move together. Paths given on the command line stay relative to the
//! working directory.
//!
//! Unknown keys are errors that name the file, the key's path (such as
//! `lights[1].colr`) and the closest valid key; a value of the wrong type
//! names the key and the type expected. All problems of a file are reported
//! together, one per line.

mod check;
#[cfg(test)]
mod tests;

use check::Checker;
pub use check::{closest_key, edit_distance};

use std::path::{Path, PathBuf};

use fvr_core::filter::FilterKind;
use fvr_core::shading::Light;
use fvr_core::volume::GridOversampling;
use toml::Table;

use crate::image::output::{Bits, Colormap};
use crate::io::nrrd::{Endian, SampleType};
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::spectrum::Precision;

/// Largest number of turntable frames (as `fvr turntable --frames`).
pub const MAX_FRAMES: u32 = 3600;
/// Largest turntable frame rate (as `fvr turntable --fps`).
pub const MAX_FPS: u16 = 1000;

/// The `[volume]` table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VolumeSection {
    /// The volume: a built-in name as given, or a file path resolved against
    /// the scene's directory.
    pub spec: Option<String>,
    /// Sizes of a headerless raw file.
    pub raw_dims: Option<[usize; 3]>,
    /// Sample type of a raw file.
    pub raw_type: Option<SampleType>,
    /// Byte order of a raw file.
    pub raw_endian: Option<Endian>,
    /// Value of empty space.
    pub background: Option<f64>,
    /// Resample to cubic voxels with this many along the longest side.
    pub resample: Option<usize>,
    /// Fade content cut by the box over this many voxels (`--taper`).
    pub taper: Option<usize>,
    /// Render in voxel units, ignoring the volume's spacing.
    pub ignore_spacing: Option<bool>,
}

/// The `[camera]` table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraSection {
    /// View direction, from the eye into the scene.
    pub dir: Option<[f64; 3]>,
    /// Up hint.
    pub up: Option<[f64; 3]>,
    /// Image width and height in pixels.
    pub size: Option<(usize, usize)>,
    /// Pixel size in mm.
    pub pixel_size: Option<f64>,
}

/// The `[spectrum]` table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpectrumSection {
    /// Interpolation filter.
    pub filter: Option<FilterKind>,
    /// Grid oversampling σ: 1, 1.25, 1.5 or 2.
    pub oversample: Option<GridOversampling>,
    /// Storage and arithmetic.
    pub precision: Option<Precision>,
    /// Kaiser–Bessel design.
    pub kb_design: Option<KbDesign>,
    /// Target SNR in dB against the exact projection (`--accuracy`).
    pub accuracy: Option<f64>,
}

/// The `[shading]` table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShadingSection {
    /// Ambient colour.
    pub ambient: Option<[f64; 3]>,
    /// Depth cue, in the `--depth-cue` syntax (a profile file made absolute).
    pub depth_cue: Option<String>,
    /// Harmonics of a profile depth cue.
    pub cue_harmonics: Option<usize>,
    /// Whether the eq. 14 correction is applied (`--no-cue-correction` is
    /// `cue_correction = false`).
    pub cue_correction: Option<bool>,
}

/// The `[output]` table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputSection {
    /// Image file, resolved against the scene's directory.
    pub path: Option<PathBuf>,
    /// PNG bits per channel.
    pub bits: Option<Bits>,
    /// Window width.
    pub window: Option<f64>,
    /// Window level.
    pub level: Option<f64>,
    /// Automatic window percentiles.
    pub percentiles: Option<(f64, f64)>,
    /// Colormap of grey images.
    pub colormap: Option<Colormap>,
}

/// The `[turntable]` table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TurntableSection {
    /// Frames in the turn.
    pub frames: Option<u32>,
    /// Frames per second.
    pub fps: Option<u16>,
    /// Animation file, resolved against the scene's directory.
    pub path: Option<PathBuf>,
}

/// A parsed and checked scene file. `None` everywhere means "not set".
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneFile {
    /// `[volume]`.
    pub volume: VolumeSection,
    /// `[camera]`.
    pub camera: CameraSection,
    /// `[spectrum]`.
    pub spectrum: SpectrumSection,
    /// `[shading]`.
    pub shading: ShadingSection,
    /// `[light_ring]`: count and tilt in degrees.
    pub light_ring: Option<(usize, f64)>,
    /// `[[lights]]`, in file order.
    pub lights: Option<Vec<Light>>,
    /// `[output]`.
    pub output: OutputSection,
    /// `[turntable]`.
    pub turntable: TurntableSection,
}

pub(crate) const TOP_KEYS: &[&str] = &[
    "volume",
    "camera",
    "spectrum",
    "shading",
    "light_ring",
    "lights",
    "output",
    "turntable",
];
pub(crate) const VOLUME_KEYS: &[&str] = &[
    "path",
    "builtin",
    "raw_dims",
    "raw_type",
    "raw_endian",
    "background",
    "resample",
    "taper",
    "ignore_spacing",
];
pub(crate) const CAMERA_KEYS: &[&str] = &["dir", "up", "size", "pixel_size"];
pub(crate) const SPECTRUM_KEYS: &[&str] =
    &["filter", "oversample", "precision", "kb_design", "accuracy"];
pub(crate) const SHADING_KEYS: &[&str] =
    &["ambient", "depth_cue", "cue_harmonics", "cue_correction"];
pub(crate) const LIGHT_RING_KEYS: &[&str] = &["count", "tilt"];
pub(crate) const LIGHT_KEYS: &[&str] = &["direction", "color"];
pub(crate) const OUTPUT_KEYS: &[&str] =
    &["path", "bits", "window", "level", "percentiles", "colormap"];
pub(crate) const TURNTABLE_KEYS: &[&str] = &["frames", "fps", "path"];

/// The largest scene file read (1 MiB).
pub const SCENE_MAX_BYTES: u64 = 1 << 20;

impl SceneFile {
    /// Read and check the scene file at `path`.
    ///
    /// # Errors
    /// The file cannot be read, is not TOML, or has unknown keys, values of
    /// the wrong type or out of range; every problem is reported, one per
    /// line, each naming the file and the key.
    pub fn load(path: &Path) -> Result<Self, String> {
        let text = crate::io::read_small_text(path, "scene file", SCENE_MAX_BYTES)?;
        let base = path.parent().unwrap_or(Path::new(""));
        Self::parse(&text, &path.display().to_string(), base)
    }

    /// Check the scene `text`; `origin` names it in messages and relative
    /// paths are resolved against `base`.
    ///
    /// # Errors
    /// As [`SceneFile::load`], for text.
    pub fn parse(text: &str, origin: &str, base: &Path) -> Result<Self, String> {
        let table: Table = text
            .parse()
            .map_err(|e: toml::de::Error| toml_error(text, origin, &e))?;
        let mut c = Checker {
            base,
            errors: Vec::new(),
        };
        let scene = c.scene(&table);
        if c.errors.is_empty() {
            Ok(scene)
        } else {
            Err(c
                .errors
                .iter()
                .map(|e| format!("{origin}: {e}"))
                .collect::<Vec<_>>()
                .join("\n"))
        }
    }
}

/// Parse a byte order name: `little` or `big`.
///
/// # Errors
/// Any other name.
pub fn parse_endian(s: &str) -> Result<Endian, String> {
    match s {
        "little" => Ok(Endian::Little),
        "big" => Ok(Endian::Big),
        _ => Err(format!("unknown byte order `{s}`: expected little or big")),
    }
}

/// One line for a TOML syntax error: where, and what (the parser's own
/// display quotes the whole offending line, however long).
fn toml_error(text: &str, origin: &str, e: &toml::de::Error) -> String {
    let place = e
        .span()
        .map(|span| {
            let before = text.get(..span.start).unwrap_or(text);
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
            format!(" at line {line}, column {column}")
        })
        .unwrap_or_default();
    let what = e.message().lines().next().unwrap_or("").trim();
    format!(
        "{origin}: not valid TOML{place}: {}",
        crate::text::bounded(what)
    )
}
