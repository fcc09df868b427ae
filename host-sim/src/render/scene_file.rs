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
//! filter = "kb4"                # oversample = 2, precision = "f16", kb_design = "auto"
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

use std::path::{Path, PathBuf};

use fvr_core::filter::FilterKind;
use fvr_core::scene::{Light, MAX_LIGHTS};
use toml::{Table, Value};

use crate::image::output::{Bits, Colormap, Window};
use crate::io::nrrd::{Endian, SampleType};
use crate::render::shaded::{parse_depth_cue, DEFAULT_PROFILE_HARMONICS};
use crate::render::spectrum::{KbDesign, Precision};

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
    /// Oversampling, 1 or 2.
    pub oversample: Option<u32>,
    /// Storage and arithmetic.
    pub precision: Option<Precision>,
    /// Kaiser–Bessel design.
    pub kb_design: Option<KbDesign>,
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

const TOP_KEYS: &[&str] = &[
    "volume",
    "camera",
    "spectrum",
    "shading",
    "light_ring",
    "lights",
    "output",
    "turntable",
];
const VOLUME_KEYS: &[&str] = &[
    "path",
    "builtin",
    "raw_dims",
    "raw_type",
    "raw_endian",
    "background",
    "resample",
    "ignore_spacing",
];
const CAMERA_KEYS: &[&str] = &["dir", "up", "size", "pixel_size"];
const SPECTRUM_KEYS: &[&str] = &["filter", "oversample", "precision", "kb_design"];
const SHADING_KEYS: &[&str] = &["ambient", "depth_cue", "cue_harmonics", "cue_correction"];
const LIGHT_RING_KEYS: &[&str] = &["count", "tilt"];
const LIGHT_KEYS: &[&str] = &["direction", "color"];
const OUTPUT_KEYS: &[&str] = &["path", "bits", "window", "level", "percentiles", "colormap"];
const TURNTABLE_KEYS: &[&str] = &["frames", "fps", "path"];

impl SceneFile {
    /// Read and check the scene file at `path`.
    ///
    /// # Errors
    /// The file cannot be read, is not TOML, or has unknown keys, values of
    /// the wrong type or out of range; every problem is reported, one per
    /// line, each naming the file and the key.
    pub fn load(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read scene file `{}`: {e}", path.display()))?;
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
            .map_err(|e: toml::de::Error| format!("{origin}: not valid TOML: {e}"))?;
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

/// Levenshtein distance between `a` and `b` (insertions, deletions and
/// substitutions of characters, each costing 1), in one row of the table.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitute = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(diagonal + 1);
        }
    }
    row[b.len()]
}

/// The valid key closest to `key` by [`edit_distance`] (the first of ties).
pub fn closest_key<'a>(key: &str, valid: &[&'a str]) -> Option<&'a str> {
    valid.iter().copied().min_by_key(|v| edit_distance(key, v))
}

/// `prefix.key`, or `key` at the top.
fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

/// A TOML value's type, as the TOML specification names it, with the value
/// when short.
fn describe(v: &Value) -> String {
    let shown = match v {
        Value::String(s) if s.len() <= 40 => format!("{s:?}"),
        Value::Integer(i) => i.to_string(),
        Value::Float(x) => x.to_string(),
        Value::Boolean(b) => b.to_string(),
        _ => return v.type_str().to_string(),
    };
    format!("{} {shown}", v.type_str())
}

struct Checker<'a> {
    base: &'a Path,
    errors: Vec<String>,
}

impl Checker<'_> {
    fn unknown_keys(&mut self, table: &Table, prefix: &str, valid: &[&str]) {
        for key in table.keys() {
            if valid.contains(&key.as_str()) {
                continue;
            }
            let place = if prefix.is_empty() {
                "at the top level".to_string()
            } else {
                format!("in `{prefix}`")
            };
            let hint = closest_key(key, valid)
                .map(|k| format!("; the closest valid key is `{}`", join(prefix, k)))
                .unwrap_or_default();
            self.errors.push(format!(
                "unknown key `{}`{hint} (valid keys {place}: {})",
                join(prefix, key),
                valid.join(", ")
            ));
        }
    }

    fn wrong(&mut self, path: &str, expected: &str, got: &Value) {
        self.errors.push(format!(
            "`{path}` must be {expected}, got {}",
            describe(got)
        ));
    }

    fn bad(&mut self, path: &str, problem: String) {
        self.errors.push(format!("`{path}`: {problem}"));
    }

    /// The sub-table `key` of `table`, checked for unknown keys.
    fn section<'t>(&mut self, table: &'t Table, key: &str, valid: &[&str]) -> Option<&'t Table> {
        match table.get(key)? {
            Value::Table(t) => {
                self.unknown_keys(t, key, valid);
                Some(t)
            }
            other => {
                self.wrong(key, "a table", other);
                None
            }
        }
    }

    fn number(&mut self, t: &Table, prefix: &str, key: &str) -> Option<f64> {
        let path = join(prefix, key);
        let v = t.get(key)?;
        match as_number(v) {
            Some(x) if x.is_finite() => Some(x),
            Some(_) => {
                self.bad(&path, "must be finite".into());
                None
            }
            None => {
                self.wrong(&path, "a number", v);
                None
            }
        }
    }

    fn integer(&mut self, t: &Table, prefix: &str, key: &str, lo: i64, hi: i64) -> Option<i64> {
        let path = join(prefix, key);
        match t.get(key)? {
            Value::Integer(i) if (lo..=hi).contains(i) => Some(*i),
            Value::Integer(i) => {
                self.bad(&path, format!("must be from {lo} to {hi}, got {i}"));
                None
            }
            other => {
                self.wrong(&path, &format!("an integer from {lo} to {hi}"), other);
                None
            }
        }
    }

    fn boolean(&mut self, t: &Table, prefix: &str, key: &str) -> Option<bool> {
        match t.get(key)? {
            Value::Boolean(b) => Some(*b),
            other => {
                self.wrong(&join(prefix, key), "true or false", other);
                None
            }
        }
    }

    fn string<'t>(&mut self, t: &'t Table, prefix: &str, key: &str) -> Option<&'t str> {
        match t.get(key)? {
            Value::String(s) => Some(s),
            other => {
                self.wrong(&join(prefix, key), "a string", other);
                None
            }
        }
    }

    /// A string parsed by `parse`, whose error is reported against the key.
    fn parsed<T, E: std::fmt::Display>(
        &mut self,
        t: &Table,
        prefix: &str,
        key: &str,
        parse: impl FnOnce(&str) -> Result<T, E>,
    ) -> Option<T> {
        let s = self.string(t, prefix, key)?;
        match parse(s) {
            Ok(v) => Some(v),
            Err(e) => {
                self.bad(&join(prefix, key), e.to_string());
                None
            }
        }
    }

    /// An array of exactly `N` finite numbers.
    fn numbers<const N: usize>(&mut self, t: &Table, prefix: &str, key: &str) -> Option<[f64; N]> {
        let path = join(prefix, key);
        let v = t.get(key)?;
        let expected = format!("an array of {N} numbers");
        let Value::Array(items) = v else {
            self.wrong(&path, &expected, v);
            return None;
        };
        if items.len() != N {
            self.bad(
                &path,
                format!("must be {expected}, got {} elements", items.len()),
            );
            return None;
        }
        let mut out = [0.0; N];
        for (i, (slot, item)) in out.iter_mut().zip(items).enumerate() {
            match as_number(item) {
                Some(x) if x.is_finite() => *slot = x,
                _ => {
                    self.wrong(&format!("{path}[{i}]"), "a finite number", item);
                    return None;
                }
            }
        }
        Some(out)
    }

    /// One grey value or an `[r, g, b]` array, each finite and `>= 0`.
    fn color(&mut self, t: &Table, prefix: &str, key: &str) -> Option<[f64; 3]> {
        let path = join(prefix, key);
        let rgb = match t.get(key)? {
            Value::Array(_) => self.numbers::<3>(t, prefix, key)?,
            v => match as_number(v) {
                Some(g) if g.is_finite() => [g; 3],
                _ => {
                    self.wrong(&path, "a number or an array [r, g, b]", v);
                    return None;
                }
            },
        };
        if rgb.iter().any(|&c| c < 0.0) {
            self.bad(&path, format!("colours must be >= 0, got {rgb:?}"));
            return None;
        }
        Some(rgb)
    }

    /// A nonzero direction.
    fn direction(&mut self, t: &Table, prefix: &str, key: &str) -> Option<[f64; 3]> {
        let v = self.numbers::<3>(t, prefix, key)?;
        if v == [0.0; 3] {
            self.bad(&join(prefix, key), "must not be the zero vector".into());
            return None;
        }
        Some(v)
    }

    /// A relative path made relative to the scene's directory.
    fn path(&mut self, t: &Table, prefix: &str, key: &str) -> Option<PathBuf> {
        let s = self.string(t, prefix, key)?;
        if s.is_empty() {
            self.bad(&join(prefix, key), "must not be empty".into());
            return None;
        }
        Some(self.base.join(s))
    }

    fn scene(&mut self, top: &Table) -> SceneFile {
        self.unknown_keys(top, "", TOP_KEYS);
        let mut scene = SceneFile::default();
        if let Some(t) = self.section(top, "volume", VOLUME_KEYS) {
            scene.volume = self.volume(t);
        }
        if let Some(t) = self.section(top, "camera", CAMERA_KEYS) {
            scene.camera = self.camera(t);
        }
        if let Some(t) = self.section(top, "spectrum", SPECTRUM_KEYS) {
            scene.spectrum = self.spectrum(t);
        }
        if let Some(t) = self.section(top, "shading", SHADING_KEYS) {
            scene.shading = self.shading(t);
        }
        if let Some(t) = self.section(top, "light_ring", LIGHT_RING_KEYS) {
            let p = "light_ring";
            match self.integer(t, p, "count", 1, MAX_LIGHTS as i64) {
                Some(count) => {
                    let tilt = self.number(t, p, "tilt").unwrap_or(30.0);
                    scene.light_ring = Some((count as usize, tilt));
                }
                None if !t.contains_key("count") => self.bad(p, "needs a `count`".into()),
                None => {}
            }
        }
        if scene.camera.pixel_size.is_some() && scene.volume.ignore_spacing == Some(true) {
            self.bad(
                "camera.pixel_size",
                "conflicts with `volume.ignore_spacing = true` (voxel units have no mm): \
                 remove one"
                    .into(),
            );
        }
        scene.lights = self.lights(top);
        let ring = scene.light_ring.map_or(0, |r| r.0);
        let listed = scene.lights.as_ref().map_or(0, Vec::len);
        if ring + listed > MAX_LIGHTS {
            self.errors.push(format!(
                "{listed} [[lights]] and a light ring of {ring} make {} lights, but a scene holds \
                 at most {MAX_LIGHTS}",
                ring + listed
            ));
        }
        if let Some(t) = self.section(top, "output", OUTPUT_KEYS) {
            scene.output = self.output(t);
        }
        if let Some(t) = self.section(top, "turntable", TURNTABLE_KEYS) {
            let p = "turntable";
            scene.turntable = TurntableSection {
                frames: self
                    .integer(t, p, "frames", 1, MAX_FRAMES as i64)
                    .map(|v| v as u32),
                fps: self
                    .integer(t, p, "fps", 1, MAX_FPS as i64)
                    .map(|v| v as u16),
                path: self.path(t, p, "path"),
            };
        }
        scene
    }

    fn volume(&mut self, t: &Table) -> VolumeSection {
        let p = "volume";
        let path = self.path(t, p, "path");
        let builtin = self.string(t, p, "builtin").map(str::to_string);
        let spec = match (path, builtin) {
            (Some(_), Some(_)) => {
                self.bad(
                    p,
                    "give `path` (a file) or `builtin` (a phantom or data set name), not both"
                        .into(),
                );
                None
            }
            (Some(file), None) => Some(file.to_string_lossy().into_owned()),
            (None, name) => name,
        };
        let raw_dims = self.numbers::<3>(t, p, "raw_dims").and_then(|d| {
            if d.iter().all(|&x| x >= 1.0 && x.fract() == 0.0 && x <= 1e9) {
                Some(d.map(|x| x as usize))
            } else {
                self.bad(
                    "volume.raw_dims",
                    format!("must be three positive integers, got {d:?}"),
                );
                None
            }
        });
        VolumeSection {
            spec,
            raw_dims,
            raw_type: self.parsed(t, p, "raw_type", str::parse::<SampleType>),
            raw_endian: self.parsed(t, p, "raw_endian", parse_endian),
            background: self.number(t, p, "background"),
            resample: self.integer(t, p, "resample", 2, 4096).map(|v| v as usize),
            ignore_spacing: self.boolean(t, p, "ignore_spacing"),
        }
    }

    fn camera(&mut self, t: &Table) -> CameraSection {
        let p = "camera";
        let size = match t.get("size") {
            None => None,
            Some(Value::Integer(_)) => self
                .integer(t, p, "size", 1, 1 << 16)
                .map(|s| (s as usize, s as usize)),
            Some(Value::Array(_)) => self.numbers::<2>(t, p, "size").and_then(|[w, h]| {
                if [w, h]
                    .iter()
                    .all(|&x| x >= 1.0 && x.fract() == 0.0 && x <= 65536.0)
                {
                    Some((w as usize, h as usize))
                } else {
                    self.bad(
                        "camera.size",
                        format!("must be positive integers [width, height], got [{w}, {h}]"),
                    );
                    None
                }
            }),
            Some(other) => {
                self.wrong(
                    "camera.size",
                    "an integer or an array [width, height]",
                    other,
                );
                None
            }
        };
        CameraSection {
            dir: self.direction(t, p, "dir"),
            up: self.direction(t, p, "up"),
            size,
            pixel_size: self.number(t, p, "pixel_size"),
        }
    }

    fn spectrum(&mut self, t: &Table) -> SpectrumSection {
        let p = "spectrum";
        SpectrumSection {
            filter: self.parsed(t, p, "filter", |s| {
                FilterKind::from_name(s).ok_or_else(|| {
                    format!(
                        "unknown filter `{s}`: expected nearest, linear, cubic, kb3, kb4, kb5 or kb6"
                    )
                })
            }),
            oversample: self.integer(t, p, "oversample", 1, 2).map(|v| v as u32),
            precision: self.parsed(t, p, "precision", str::parse::<Precision>),
            kb_design: match t.get("kb_design") {
                Some(v @ (Value::Integer(_) | Value::Float(_))) => {
                    let text = as_number(v).unwrap_or(f64::NAN).to_string();
                    match text.parse::<KbDesign>() {
                        Ok(d) => Some(d),
                        Err(e) => {
                            self.bad("spectrum.kb_design", e);
                            None
                        }
                    }
                }
                _ => self.parsed(t, p, "kb_design", str::parse::<KbDesign>),
            },
        }
    }

    fn shading(&mut self, t: &Table) -> ShadingSection {
        let p = "shading";
        let harmonics = self
            .integer(t, p, "cue_harmonics", 1, 16)
            .map(|v| v as usize);
        let depth_cue = self.string(t, p, "depth_cue").and_then(|s| {
            let s = match s.strip_prefix("profile:@") {
                Some(file) => format!("profile:@{}", self.base.join(file).display()),
                None => s.to_string(),
            };
            match parse_depth_cue(&s, harmonics.unwrap_or(DEFAULT_PROFILE_HARMONICS)) {
                Ok(_) => Some(s),
                Err(e) => {
                    self.bad("shading.depth_cue", e);
                    None
                }
            }
        });
        ShadingSection {
            ambient: self.color(t, p, "ambient"),
            depth_cue,
            cue_harmonics: harmonics,
            cue_correction: self.boolean(t, p, "cue_correction"),
        }
    }

    fn lights(&mut self, top: &Table) -> Option<Vec<Light>> {
        let v = top.get("lights")?;
        let Value::Array(items) = v else {
            self.wrong(
                "lights",
                "an array of tables ([[lights]] with direction and color)",
                v,
            );
            return None;
        };
        let mut lights = Vec::new();
        for (i, item) in items.iter().enumerate() {
            let p = format!("lights[{i}]");
            let Value::Table(t) = item else {
                self.wrong(&p, "a table with direction and color", item);
                continue;
            };
            self.unknown_keys(t, &p, LIGHT_KEYS);
            for key in LIGHT_KEYS {
                if !t.contains_key(*key) {
                    self.bad(&p, format!("needs a `{key}`"));
                }
            }
            if let (Some(towards), Some(color)) = (
                self.direction(t, &p, "direction"),
                self.color(t, &p, "color"),
            ) {
                lights.push(Light { towards, color });
            }
        }
        Some(lights)
    }

    fn output(&mut self, t: &Table) -> OutputSection {
        let p = "output";
        let bits = match t.get("bits") {
            Some(Value::Integer(8)) => Some(Bits::Eight),
            Some(Value::Integer(16)) => Some(Bits::Sixteen),
            Some(other) => {
                self.wrong("output.bits", "8 or 16", other);
                None
            }
            None => None,
        };
        let window = self.number(t, p, "window");
        let level = self.number(t, p, "level");
        if window.is_some() != level.is_some() {
            self.bad(
                p,
                "`window` and `level` go together: give both or neither".into(),
            );
        }
        if let (Some(w), Some(l)) = (window, level) {
            if let Err(e) = Window::from_width_level(w, l) {
                self.bad("output.window", e);
            }
        }
        let percentiles = self.numbers::<2>(t, p, "percentiles").and_then(|[lo, hi]| {
            match Window::from_percentiles(lo, hi) {
                Ok(_) => Some((lo, hi)),
                Err(e) => {
                    self.bad("output.percentiles", e);
                    None
                }
            }
        });
        if percentiles.is_some() && window.is_some() {
            self.bad(p, "give `window`/`level` or `percentiles`, not both".into());
        }
        OutputSection {
            path: self.path(t, p, "path"),
            bits,
            window,
            level,
            percentiles,
            colormap: self.parsed(t, p, "colormap", str::parse::<Colormap>),
        }
    }
}

fn as_number(v: &Value) -> Option<f64> {
    match v {
        Value::Integer(i) => Some(*i as f64),
        Value::Float(x) => Some(*x),
        _ => None,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<SceneFile, String> {
        SceneFile::parse(text, "s.toml", Path::new("/scenes"))
    }

    #[test]
    fn edit_distance_counts_insertions_deletions_and_substitutions() {
        assert_eq!(edit_distance("", ""), 0);
        assert_eq!(edit_distance("color", "color"), 0);
        assert_eq!(edit_distance("colr", "color"), 1);
        assert_eq!(edit_distance("colour", "color"), 1);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("abc", ""), 3);
        assert_eq!(closest_key("dirn", CAMERA_KEYS), Some("dir"));
        assert_eq!(closest_key("colour", LIGHT_KEYS), Some("color"));
    }

    #[test]
    fn full_scene_parses_every_key() {
        let s = parse(
            r#"
            [volume]
            path = "head.nii.gz"
            raw_dims = [4, 5, 6]
            raw_type = "u16"
            raw_endian = "big"
            background = -1024
            resample = 128
            ignore_spacing = false
            [camera]
            dir = [1, 0.5, -0.25]
            up = [0, 0, 1]
            size = [64, 32]
            pixel_size = 0.75
            [spectrum]
            filter = "cubic"
            oversample = 2
            precision = "f32"
            kb_design = 1.5
            [shading]
            ambient = 0.1
            depth_cue = "linear:1,0.3"
            cue_harmonics = 6
            cue_correction = false
            [light_ring]
            count = 3
            [[lights]]
            direction = [0, 1, 0]
            color = [1, 0, 0]
            [output]
            path = "out/a.png"
            bits = 16
            window = 2.0
            level = 1
            colormap = "bone"
            [turntable]
            frames = 12
            fps = 6
            path = "spin.apng"
            "#,
        )
        .unwrap();
        assert_eq!(s.volume.spec.as_deref(), Some("/scenes/head.nii.gz"));
        assert_eq!(s.volume.raw_dims, Some([4, 5, 6]));
        assert_eq!(s.volume.raw_type, Some(SampleType::U16));
        assert_eq!(s.volume.raw_endian, Some(Endian::Big));
        assert_eq!(s.volume.background, Some(-1024.0));
        assert_eq!(s.volume.resample, Some(128));
        assert_eq!(s.camera.dir, Some([1.0, 0.5, -0.25]));
        assert_eq!(s.camera.size, Some((64, 32)));
        assert_eq!(s.camera.pixel_size, Some(0.75));
        assert_eq!(s.volume.ignore_spacing, Some(false));
        assert_eq!(s.spectrum.filter, Some(FilterKind::Cubic));
        assert_eq!(s.spectrum.oversample, Some(2));
        assert_eq!(s.spectrum.precision, Some(Precision::F32));
        assert_eq!(s.spectrum.kb_design, Some(KbDesign::Sigma(1.5)));
        assert_eq!(s.shading.ambient, Some([0.1; 3]));
        assert_eq!(s.shading.depth_cue.as_deref(), Some("linear:1,0.3"));
        assert_eq!(s.shading.cue_harmonics, Some(6));
        assert_eq!(s.shading.cue_correction, Some(false));
        assert_eq!(s.light_ring, Some((3, 30.0)));
        assert_eq!(
            s.lights,
            Some(vec![Light {
                towards: [0.0, 1.0, 0.0],
                color: [1.0, 0.0, 0.0]
            }])
        );
        assert_eq!(s.output.path, Some(PathBuf::from("/scenes/out/a.png")));
        assert_eq!(s.output.bits, Some(Bits::Sixteen));
        assert_eq!((s.output.window, s.output.level), (Some(2.0), Some(1.0)));
        assert_eq!(s.output.colormap, Some(Colormap::Bone));
        assert_eq!(s.turntable.frames, Some(12));
        assert_eq!(s.turntable.path, Some(PathBuf::from("/scenes/spin.apng")));
    }

    #[test]
    fn empty_scene_sets_nothing_and_builtin_names_stay_names() {
        assert_eq!(parse("").unwrap(), SceneFile::default());
        let s = parse("[volume]\nbuiltin = \"teapot@64\"\n[camera]\nsize = 48\n").unwrap();
        assert_eq!(s.volume.spec.as_deref(), Some("teapot@64"));
        assert_eq!(s.camera.size, Some((48, 48)));
    }

    #[test]
    fn unknown_keys_name_the_path_and_the_closest_key() {
        let e = parse(
            "[[lights]]\ndirection = [0,1,0]\ncolor = 1\n[[lights]]\ndirection = [1,0,0]\ncolr = [1,0,0]\n",
        )
        .unwrap_err();
        assert!(e.contains("s.toml: unknown key `lights[1].colr`"), "{e}");
        assert!(e.contains("closest valid key is `lights[1].color`"), "{e}");
        assert!(e.contains("`lights[1]`: needs a `color`"), "{e}");
        let e = parse("[camera]\ndirection = [1,0,0]\n").unwrap_err();
        assert!(e.contains("unknown key `camera.direction`"), "{e}");
        assert!(e.contains("`camera.dir`"), "{e}");
        let e = parse("[ouput]\npath = \"a.png\"\n").unwrap_err();
        assert!(e.contains("unknown key `ouput`"), "{e}");
        assert!(e.contains("closest valid key is `output`"), "{e}");
    }

    #[test]
    fn every_problem_is_reported_once_per_line() {
        let e = parse("[camera]\ndir = \"x\"\nup = [0, 0]\n[spectrum]\nfilter = \"kb9\"\n")
            .unwrap_err();
        let lines: Vec<&str> = e.lines().collect();
        assert_eq!(lines.len(), 3, "{e}");
        assert!(lines.iter().all(|l| l.starts_with("s.toml: ")), "{e}");
        assert!(
            e.contains("`camera.dir` must be an array of 3 numbers, got string \"x\""),
            "{e}"
        );
        assert!(e.contains("`camera.up`: must be an array of 3 numbers, got 2 elements"));
        assert!(e.contains("`spectrum.filter`: unknown filter `kb9`"), "{e}");
    }

    #[test]
    fn wrong_types_name_the_key_and_the_expected_type() {
        for (text, needle) in [
            (
                "[spectrum]\noversample = \"2\"",
                "`spectrum.oversample` must be an integer from 1 to 2, got string \"2\"",
            ),
            (
                "[spectrum]\noversample = 3",
                "`spectrum.oversample`: must be from 1 to 2, got 3",
            ),
            (
                "[output]\nbits = 12",
                "`output.bits` must be 8 or 16, got integer 12",
            ),
            (
                "[shading]\ncue_correction = 1",
                "`shading.cue_correction` must be true or false",
            ),
            (
                "[volume]\nignore_spacing = true\n[camera]\npixel_size = 0.5",
                "`camera.pixel_size`: conflicts with `volume.ignore_spacing = true`",
            ),
            (
                "[shading]\nambient = [1, \"a\", 0]",
                "`shading.ambient[1]` must be a finite number",
            ),
            (
                "[shading]\nambient = -1",
                "`shading.ambient`: colours must be >= 0",
            ),
            ("volume = 3", "`volume` must be a table, got integer 3"),
            ("lights = 3", "`lights` must be an array of tables"),
            (
                "[camera]\ndir = [0, 0, 0]",
                "`camera.dir`: must not be the zero vector",
            ),
            (
                "[camera]\nsize = [64, 0]",
                "`camera.size`: must be positive integers",
            ),
            (
                "[camera]\nsize = 1.5",
                "`camera.size` must be an integer or an array",
            ),
            ("[volume]\npath = \"a\"\nbuiltin = \"b\"", "not both"),
            ("[output]\nwindow = 1", "`window` and `level` go together"),
            ("[output]\npercentiles = [50, 10]", "`output.percentiles`"),
            ("[shading]\ndepth_cue = \"linear:1\"", "`shading.depth_cue`"),
            ("[light_ring]\ntilt = 10", "`light_ring`: needs a `count`"),
            (
                "[light_ring]\ncount = 9",
                "`light_ring.count`: must be from 1 to 8",
            ),
            (
                "[volume]\nraw_endian = \"middle\"",
                "`volume.raw_endian`: unknown byte order",
            ),
        ] {
            let e = parse(text).unwrap_err();
            assert!(e.contains(needle), "{text}: `{needle}` not in {e}");
        }
    }

    #[test]
    fn too_many_lights_and_bad_toml_are_errors() {
        let mut text = String::from("[light_ring]\ncount = 3\n");
        for _ in 0..6 {
            text.push_str("[[lights]]\ndirection = [0,1,0]\ncolor = 1\n");
        }
        let e = parse(&text).unwrap_err();
        assert!(e.contains("make 9 lights"), "{e}");
        let e = parse("[camera\n").unwrap_err();
        assert!(e.starts_with("s.toml: not valid TOML"), "{e}");
    }

    #[test]
    fn missing_file_names_it() {
        let e = SceneFile::load(Path::new("/nonexistent/scene.toml")).unwrap_err();
        assert!(
            e.contains("cannot read scene file `/nonexistent/scene.toml`"),
            "{e}"
        );
    }

    #[test]
    fn profile_cue_file_is_relative_to_the_scene() {
        let dir = std::env::temp_dir().join(format!("fvr-scene-profile-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("w.txt"), "1, 0.5\n").unwrap();
        let s = SceneFile::parse(
            "[shading]\ndepth_cue = \"profile:@w.txt\"\n",
            "s.toml",
            &dir,
        )
        .unwrap();
        assert_eq!(
            s.shading.depth_cue,
            Some(format!("profile:@{}", dir.join("w.txt").display()))
        );
        assert!(parse("[shading]\ndepth_cue = \"profile:@w.txt\"\n").is_err());
    }
}
