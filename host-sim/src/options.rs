//! Parsers for the values of render options (`--depth-cue`, `--light`,
//! `--light-ring`, `--adaptive-chain`, ...), shared by the command line and
//! scene files. Each returns a one-line message naming what is wrong.

use fvr_core::filter::FilterKind;
use fvr_core::shading::{DepthCue, Light, MAX_PROFILE_POINTS};
use fvr_core::slice::adaptive::MAX_LEVELS;
use fvr_engine::slice::adaptive::Cheaper;

/// Points a `profile:gauss:CENTER,WIDTH` formula is sampled at.
const FORMULA_POINTS: usize = 33;

/// Text for `--depth-cue` help.
pub const DEPTH_CUE_HELP: &str = "\
Depth cue, with t the depth from the volume's centre along the view and R half its largest \
dimension; FRONT applies at t = -R, BACK at t = +R:
  linear:FRONT,BACK   w = C_avg + C_cue t (paper eq. 3-5; the gradient filter)
  sine:FRONT,BACK     DC-free sine through FRONT and BACK, crest at the brighter end (one shifted \
filter; departs from linear by up to 0.21 for 1,0)
  profile:W0,W1,...   weights at equally spaced depths from front to back, joined linearly \
(2 to 64 points)
  profile:@FILE       the same weights read from FILE (numbers separated by commas, spaces or \
newlines; # starts a comment)
  profile:gauss:C,S   a Gaussian bump exp(-((t/R - C)/S)^2/2), e.g. gauss:0,0.4 highlights the \
middle
Profiles are fitted with --cue-harmonics cosine terms (default 8), each costing about two plain \
extractions. Weights must be finite and >= 0 (negative ones are refused).";

fn parse_numbers(text: &str) -> Result<Vec<f64>, String> {
    text.lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .flat_map(|l| l.split([',', ' ', '\t', ';']))
        .filter(|t| !t.trim().is_empty())
        .map(|t| {
            t.trim()
                .parse::<f64>()
                .map_err(|_| format!("`{t}` is not a number"))
        })
        .collect()
}

/// Parse a `--depth-cue` value (see [`DEPTH_CUE_HELP`]).
///
/// # Errors
/// An unknown form, a malformed number, an unreadable file, or a profile
/// outside 2–64 points. Range checks (non-negative weights) are the
/// scene's: [`Scene::validate`].
pub fn parse_depth_cue(spec: &str, harmonics: usize) -> Result<DepthCue, String> {
    let pair = |rest: &str, kind: &str| -> Result<(f64, f64), String> {
        match parse_numbers(rest)?.as_slice() {
            [f, b] => Ok((*f, *b)),
            _ => Err(format!(
                "`{kind}:` needs two weights FRONT,BACK, got `{rest}`"
            )),
        }
    };
    let weights = |values: Vec<f64>| -> Result<DepthCue, String> {
        if values.len() < 2 || values.len() > MAX_PROFILE_POINTS {
            return Err(format!(
                "a depth profile needs 2 to {MAX_PROFILE_POINTS} weights, got {}",
                values.len()
            ));
        }
        Ok(DepthCue::Profile {
            weights: values.into_iter().collect(),
            harmonics,
        })
    };
    if spec == "none" {
        Ok(DepthCue::None)
    } else if let Some(rest) = spec.strip_prefix("linear:") {
        let (front, back) = pair(rest, "linear")?;
        Ok(DepthCue::Linear { front, back })
    } else if let Some(rest) = spec.strip_prefix("sine:") {
        let (front, back) = pair(rest, "sine")?;
        Ok(DepthCue::Sine { front, back })
    } else if let Some(path) = spec.strip_prefix("profile:@") {
        let text =
            crate::io::read_small_text(std::path::Path::new(path), "depth profile", 1 << 20)?;
        // The file's text is never quoted (it may be any file, even secrets).
        weights(parse_numbers(&text).map_err(|_| {
            format!(
                "depth profile `{path}`: not a list of numbers (separated by commas, spaces or \
                 newlines; # starts a comment)"
            )
        })?)
    } else if let Some(rest) = spec.strip_prefix("profile:gauss:") {
        let (c, s) = pair(rest, "profile:gauss")?;
        if !(s.is_finite() && s > 0.0 && c.is_finite()) {
            return Err(format!(
                "profile:gauss:C,S needs a finite centre and a width > 0, got `{rest}`"
            ));
        }
        weights(
            (0..FORMULA_POINTS)
                .map(|i| {
                    let t = -1.0 + 2.0 * i as f64 / (FORMULA_POINTS - 1) as f64;
                    (-0.5 * ((t - c) / s).powi(2)).exp()
                })
                .collect(),
        )
    } else if let Some(rest) = spec.strip_prefix("profile:") {
        weights(parse_numbers(rest)?)
    } else {
        Err(format!(
            "unknown depth cue `{spec}`: expected none, linear:FRONT,BACK, sine:FRONT,BACK, \
             profile:W0,W1,..., profile:@FILE or profile:gauss:C,S"
        ))
    }
}

/// Parse a colour `R,G,B` or a single grey value.
///
/// # Errors
/// Not one or three numbers.
pub fn parse_rgb(s: &str) -> Result<[f64; 3], String> {
    match parse_numbers(s)?.as_slice() {
        [g] => Ok([*g; 3]),
        [r, g, b] => Ok([*r, *g, *b]),
        _ => Err(format!(
            "expected a colour R,G,B or one grey value, got `{s}`"
        )),
    }
}

/// Parse a `--light X,Y,Z:R,G,B` (direction towards the light, colour).
///
/// # Errors
/// A malformed direction or colour. Zero directions and negative colours
/// are the scene's to refuse ([`Scene::validate`]).
pub fn parse_light(s: &str) -> Result<Light, String> {
    let (dir, color) = s
        .split_once(':')
        .ok_or_else(|| format!("expected a light X,Y,Z:R,G,B, got `{s}`"))?;
    let towards = match parse_numbers(dir)?.as_slice() {
        [x, y, z] => [*x, *y, *z],
        _ => return Err(format!("light direction must be X,Y,Z, got `{dir}`")),
    };
    Ok(Light {
        towards,
        color: parse_rgb(color)?,
    })
}

/// Parse `--light-ring N[:TILT]`.
///
/// # Errors
/// Not a count from 1 to 8 and an optional finite angle.
pub fn parse_light_ring(s: &str) -> Result<(usize, f64), String> {
    let (count, tilt) = match s.split_once(':') {
        Some((c, t)) => (c, Some(t)),
        None => (s, None),
    };
    let count: usize = count
        .trim()
        .parse()
        .ok()
        .filter(|c| (1..=fvr_core::shading::MAX_LIGHTS).contains(c))
        .ok_or_else(|| format!("light ring needs a count from 1 to 8, got `{s}`"))?;
    let tilt = match tilt {
        Some(t) => t
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|t| t.is_finite())
            .ok_or_else(|| format!("light ring tilt must be degrees, got `{s}`"))?,
        None => 30.0,
    };
    Ok((count, tilt))
}

/// The cheaper filters tried, cheapest first, as the user names them
/// (`zero` or a filter's name).
pub fn parse_chain(s: &str) -> Result<Vec<Cheaper>, String> {
    let kinds: Vec<Cheaper> = s
        .split(',')
        .map(|name| match name.trim() {
            "zero" => Ok(Cheaper::Zero),
            other => FilterKind::from_name(other)
                .map(Cheaper::Filter)
                .ok_or_else(|| {
                    format!(
                        "unknown filter `{name}` in the adaptive chain: expected zero, nearest, \
                         linear, cubic, kb3, kb4 or kb5"
                    )
                }),
        })
        .collect::<Result<_, _>>()?;
    if kinds.is_empty() || kinds.len() > MAX_LEVELS {
        return Err(format!(
            "an adaptive chain names 1 to {MAX_LEVELS} cheaper filters, got `{s}`"
        ));
    }
    Ok(kinds)
}

/// Parse a tolerance in dB: a finite number above 0.
pub fn parse_tolerance(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "adaptive tolerance must be a positive number of dB (e.g. 40), got `{s}`"
        )),
    }
}

/// Parse a share in percent (0 to 100) into a fraction.
pub fn parse_percent(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if (0.0..=100.0).contains(&v) => Ok(v / 100.0),
        _ => Err(format!("expected a percentage from 0 to 100, got `{s}`")),
    }
}
