//! `Renderer(...)` keywords to the engine's [`Settings`], parsed by the
//! CLI's own parsers so that values and messages are the CLI's.

use fvr_core::filter::FilterKind;
use fvr_core::shading::{Light, Scene, MAX_LIGHTS};
use fvr_core::volume::GridOversampling;
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::slice::adaptive::{
    AdaptiveSettings, Bound as AdaptiveBound, DEFAULT_PLAIN_BELOW, DEFAULT_PROBES,
};
use fvr_engine::spectrum::Precision;
use fvr_engine::{Settings, Units};
use pyo3::prelude::*;

use crate::errors::{type_error, value};

/// The keywords of `Renderer(...)` that shape the settings.
pub(crate) struct Options<'py> {
    pub(crate) accuracy_db: Option<f64>,
    pub(crate) filter: Option<String>,
    pub(crate) oversample: Option<f64>,
    pub(crate) precision: Option<String>,
    pub(crate) depth_cue: Option<String>,
    pub(crate) ambient: Option<Bound<'py, PyAny>>,
    pub(crate) lights: Option<Bound<'py, PyAny>>,
    pub(crate) ignore_spacing: bool,
    pub(crate) pixel_size: Option<f64>,
    pub(crate) preview_level: u32,
    pub(crate) adaptive_db: Option<f64>,
}

/// The cosine harmonics of a `profile:` cue, as the CLI's default.
const CUE_HARMONICS: usize = fvr_engine::render::shaded::DEFAULT_PROFILE_HARMONICS;

/// The CLI's `--adaptive-chain` default.
const ADAPTIVE_CHAIN: &str = "zero";

impl Options<'_> {
    /// The engine's settings, as `fvr render` builds them from the same
    /// flags.
    pub(crate) fn settings(&self) -> PyResult<Settings> {
        if let Some(db) = self.accuracy_db {
            if !(db.is_finite() && db > 0.0) {
                return Err(value(format!(
                    "accuracy_db: expected a positive number of decibels, got {db}"
                )));
            }
        }
        let filter = self
            .filter
            .as_deref()
            .map(|s| {
                FilterKind::from_name(s).ok_or_else(|| {
                    value(format!(
                        "unknown filter `{s}`: expected nearest, linear, cubic, kb3, kb4, kb5 or kb6"
                    ))
                })
            })
            .transpose()?;
        let oversample = self
            .oversample
            .map(|x| {
                GridOversampling::ALL
                    .into_iter()
                    .find(|g| g.factor() == x)
                    .ok_or_else(|| {
                        value(format!("oversample: expected 1, 1.25, 1.5 or 2, got {x}"))
                    })
            })
            .transpose()?;
        let precision = self
            .precision
            .as_deref()
            .map(|s| s.parse::<Precision>().map_err(value))
            .transpose()?;
        let adaptive = match self.adaptive_db {
            Some(db) if db.is_finite() && db > 0.0 => Some(AdaptiveSettings {
                tolerance_db: db,
                chain: fvr_host::options::parse_chain(ADAPTIVE_CHAIN).map_err(value)?,
                h_d: None,
                bound: AdaptiveBound::Parseval,
                plain_below: DEFAULT_PLAIN_BELOW,
                probes: DEFAULT_PROBES,
            }),
            Some(db) => {
                return Err(value(format!(
                    "adaptive: expected a positive number of decibels, got {db}"
                )))
            }
            None => None,
        };
        if let Some(p) = self.pixel_size {
            if self.ignore_spacing {
                return Err(value(
                    "pixel_size and ignore_spacing cannot be combined: choose one",
                ));
            }
            if !(p.is_finite() && p > 0.0) {
                return Err(value(format!(
                    "pixel_size: expected a positive size in mm, got {p}"
                )));
            }
        }
        let settings = Settings {
            accuracy_db: self.accuracy_db,
            filter,
            oversample,
            precision,
            kb_design: KbDesign::Auto,
            scene: self.scene()?,
            adaptive,
            preview_level: self.preview_level,
            units: Units {
                ignore_spacing: self.ignore_spacing,
                pixel_size: self.pixel_size,
            },
        };
        settings.check().map_err(crate::errors::pipeline)?;
        Ok(settings)
    }

    /// The scene: cue, ambient and lights, with the CLI's defaults (ambient
    /// 1 without lights, 0.2 with).
    fn scene(&self) -> PyResult<Scene> {
        let cue = fvr_host::options::parse_depth_cue(
            self.depth_cue.as_deref().unwrap_or("none"),
            CUE_HARMONICS,
        )
        .map_err(value)?;
        let lights = match &self.lights {
            Some(l) if !l.is_none() => parse_lights(l)?,
            _ => Vec::new(),
        };
        let default_ambient = Scene::default_ambient(!lights.is_empty());
        let ambient = match &self.ambient {
            Some(a) if !a.is_none() => parse_rgb(a, "ambient")?,
            _ => [default_ambient; 3],
        };
        let mut scene = Scene {
            cue,
            ambient,
            ..Scene::xray()
        };
        if lights.len() > MAX_LIGHTS {
            return Err(value(format!(
                "{} lights given, but a scene holds at most {MAX_LIGHTS}",
                lights.len()
            )));
        }
        for light in lights {
            scene.add_light(light).map_err(|e| value(e.to_string()))?;
        }
        scene.validate().map_err(|e| value(e.to_string()))?;
        Ok(scene)
    }
}

/// A colour: one grey number, three numbers, or the CLI's `R,G,B` text.
fn parse_rgb(x: &Bound<'_, PyAny>, what: &str) -> PyResult<[f64; 3]> {
    if let Ok(text) = x.extract::<String>() {
        return fvr_host::options::parse_rgb(&text).map_err(|e| value(format!("{what}: {e}")));
    }
    if let Ok(grey) = x.extract::<f64>() {
        return Ok([grey; 3]);
    }
    match x.extract::<Vec<f64>>() {
        Ok(v) if v.len() == 3 => Ok([v[0], v[1], v[2]]),
        Ok(v) => Err(value(format!(
            "{what}: expected one grey value or three (R, G, B), got {} values",
            v.len()
        ))),
        Err(_) => Err(type_error(format!(
            "{what}: expected a number, three numbers or `R,G,B`"
        ))),
    }
}

/// Lights: each the CLI's `X,Y,Z:R,G,B` text, or a pair
/// `((x, y, z), colour)` with the colour as [`parse_rgb`] takes it.
fn parse_lights(x: &Bound<'_, PyAny>) -> PyResult<Vec<Light>> {
    if x.extract::<String>().is_ok() {
        return Err(type_error(
            "lights: expected a list of lights, each `X,Y,Z:R,G,B` or ((x, y, z), colour)",
        ));
    }
    let mut lights = Vec::new();
    for item in x.try_iter()? {
        let item = item?;
        if let Ok(text) = item.extract::<String>() {
            lights.push(fvr_host::options::parse_light(&text).map_err(value)?);
            continue;
        }
        let (towards, color): (Vec<f64>, Bound<'_, PyAny>) = item.extract().map_err(|_| {
            type_error("lights: expected each light as `X,Y,Z:R,G,B` or ((x, y, z), colour)")
        })?;
        if towards.len() != 3 {
            return Err(value(format!(
                "lights: a light's direction has 3 components, got {}",
                towards.len()
            )));
        }
        lights.push(Light {
            towards: [towards[0], towards[1], towards[2]],
            color: parse_rgb(&color, "a light's colour")?,
        });
    }
    Ok(lights)
}
