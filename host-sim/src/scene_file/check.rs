//! Checking a parsed scene table key by key: types, ranges, unknown keys
//! with the closest valid one, every problem collected.

use std::path::{Path, PathBuf};

use fvr_core::filter::FilterKind;
use fvr_core::shading::{Light, MAX_LIGHTS};
use fvr_core::volume::GridOversampling;
use toml::{Table, Value};

use crate::image::output::{Bits, Colormap, Window};
use crate::io::nrrd::SampleType;
use crate::options::parse_depth_cue;
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::render::shaded::DEFAULT_PROFILE_HARMONICS;
use fvr_engine::spectrum::Precision;
use fvr_engine::volume::RESAMPLE_RANGE;

use super::{
    parse_endian, CameraSection, OutputSection, SceneFile, ShadingSection, SpectrumSection,
    TurntableSection, VolumeSection, CAMERA_KEYS, LIGHT_KEYS, LIGHT_RING_KEYS, MAX_FPS, MAX_FRAMES,
    OUTPUT_KEYS, SHADING_KEYS, SPECTRUM_KEYS, TOP_KEYS, TURNTABLE_KEYS, VOLUME_KEYS,
};

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
        Value::Float(x) => crate::text::num(*x),
        Value::Boolean(b) => b.to_string(),
        _ => return v.type_str().to_string(),
    };
    format!("{} {shown}", v.type_str())
}

pub(super) struct Checker<'a> {
    pub(super) base: &'a Path,
    pub(super) errors: Vec<String>,
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

    /// `oversample`: one of the grid factors, as an integer or a float.
    fn oversample(&mut self, t: &Table, prefix: &str) -> Option<GridOversampling> {
        let path = join(prefix, "oversample");
        let v = t.get("oversample")?;
        let found =
            as_number(v).and_then(|x| GridOversampling::ALL.into_iter().find(|g| g.factor() == x));
        if found.is_none() {
            self.wrong(&path, "1, 1.25, 1.5 or 2", v);
        }
        found
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

    /// An input path: inside the scene's directory ([`Self::inside`]), so
    /// that a shared scene reads no file elsewhere; a volume elsewhere is
    /// given on the command line, where it replaces the scene's.
    fn input_path(&mut self, t: &Table, prefix: &str, key: &str) -> Option<PathBuf> {
        self.inside(
            t,
            prefix,
            key,
            "give a volume elsewhere as VOLUME on the command line",
        )
    }

    /// An output path: inside the scene's directory ([`Self::inside`]), so
    /// that a shared scene cannot write over files elsewhere.
    fn output_path(&mut self, t: &Table, prefix: &str, key: &str) -> Option<PathBuf> {
        self.inside(t, prefix, key, "give other outputs with --out")
    }

    /// A relative path that stays inside the scene's directory, made
    /// relative to it; otherwise an error that ends with `elsewhere`.
    fn inside(&mut self, t: &Table, prefix: &str, key: &str, elsewhere: &str) -> Option<PathBuf> {
        let s = self.string(t, prefix, key)?;
        let inside = crate::io::paths::inside(self.base, Path::new(s));
        if inside.is_none() || s.is_empty() {
            self.bad(
                &join(prefix, key),
                format!("must be a path inside the scene's directory ({elsewhere})"),
            );
        }
        inside.filter(|_| !s.is_empty())
    }

    pub(super) fn scene(&mut self, top: &Table) -> SceneFile {
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
                path: self.output_path(t, p, "path"),
            };
        }
        scene
    }

    fn volume(&mut self, t: &Table) -> VolumeSection {
        let p = "volume";
        let path = self.input_path(t, p, "path");
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
            resample: self
                .integer(
                    t,
                    p,
                    "resample",
                    *RESAMPLE_RANGE.start() as i64,
                    *RESAMPLE_RANGE.end() as i64,
                )
                .map(|v| v as usize),
            taper: self.integer(t, p, "taper", 1, 4096).map(|v| v as usize),
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
            oversample: self.oversample(t, p),
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
            accuracy: self.number(t, p, "accuracy").and_then(|v| {
                if v > 0.0 {
                    Some(v)
                } else {
                    self.bad("spectrum.accuracy", format!("must be a positive number of decibels, got {}", crate::text::num(v)));
                    None
                }
            }),
        }
    }

    fn shading(&mut self, t: &Table) -> ShadingSection {
        let p = "shading";
        let harmonics = self
            .integer(t, p, "cue_harmonics", 1, 16)
            .map(|v| v as usize);
        let depth_cue = self.string(t, p, "depth_cue").and_then(|s| {
            let s = match s.strip_prefix("profile:@") {
                // Confined like the outputs: a shared scene reads no file elsewhere.
                Some(file) => match crate::io::paths::inside(self.base, Path::new(file)) {
                    Some(path) if !file.is_empty() => format!("profile:@{}", path.display()),
                    _ => {
                        self.bad(
                            "shading.depth_cue",
                            "profile:@FILE must name a file inside the scene's directory".into(),
                        );
                        return None;
                    }
                },
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
            path: self.output_path(t, p, "path"),
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
