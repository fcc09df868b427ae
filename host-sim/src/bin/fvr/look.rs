//! What a view looks like beyond the X-ray projection: depth cue, ambient,
//! lights, resampling and preview level. One argument group, flattened into
//! `fvr render` and `fvr turntable`, so both accept the same flags and a
//! scene file's `[shading]`, `[[lights]]` and `[light_ring]` alike.

use clap::Args;
use fvr_core::geometry::View;
use fvr_core::shading::{CueTerms, DepthCue, Light, Scene, MAX_LIGHTS};
use fvr_engine::render::shaded::{light_ring, DEFAULT_PROFILE_HARMONICS};
use fvr_host::options::{
    parse_depth_cue, parse_light, parse_light_ring, parse_rgb, DEPTH_CUE_HELP,
};
use fvr_host::scene_file::SceneFile;

use crate::scene::fill;
use crate::taper::TaperArgs;
use crate::Error;

/// Depth cue, ambient, lights, resampling and preview level (render and
/// turntable).
#[derive(Args, Clone)]
pub(crate) struct LookArgs {
    /// Depth cue: none, linear:FRONT,BACK, sine:FRONT,BACK, profile:W0,W1,...,
    /// profile:@FILE or profile:gauss:C,S (details with --help). A PNG of a
    /// cued view is windowed like the uncued view (scaled by the cue's
    /// largest weight) unless --window/--level are given, so that near
    /// content stays brighter than far content.
    #[arg(long, default_value = "none", long_help = DEPTH_CUE_HELP)]
    pub(crate) depth_cue: String,
    /// Cosine harmonics fitted to a profile depth cue (1 to 16).
    #[arg(long, default_value_t = DEFAULT_PROFILE_HARMONICS)]
    pub(crate) cue_harmonics: usize,
    /// Ambient colour R,G,B or one grey value (paper eq. 7). Default: 1 without
    /// lights, 0.2 with.
    #[arg(long, value_parser = parse_rgb, allow_hyphen_values = true)]
    pub(crate) ambient: Option<[f64; 3]>,
    /// A directional light X,Y,Z:R,G,B: the direction towards the light and
    /// its colour (or one grey value). Repeatable, up to 8. Surfaces of denser
    /// structures that face a light are lit (hemispherical model, eq. 8-11).
    #[arg(long = "light", value_parser = parse_light, allow_hyphen_values = true)]
    pub(crate) lights: Vec<Light>,
    /// N lights evenly spaced around the view axis (as in the paper's figure
    /// 8), saturated colours evenly spaced in hue (3: red at the top, green,
    /// blue), tilted TILT degrees towards the eye (default 30). Added to any
    /// --light. A turntable places them about its first view; they stay
    /// fixed while the camera turns.
    #[arg(long, value_name = "N[:TILT]", value_parser = parse_light_ring)]
    pub(crate) light_ring: Option<(usize, f64)>,
    /// Leave out the eq. 14 correction when depth cueing and shading are
    /// combined (only to see what it fixes).
    #[arg(long)]
    pub(crate) no_cue_correction: bool,
    /// Resample to cubic voxels with N samples along the longest physical
    /// side (trilinear) before rendering. X-ray views of anisotropic data
    /// such as CT (0.957 x 0.957 x 1.5 mm) are exact without it; depth cues
    /// and lights need it.
    #[arg(long, value_name = "N")]
    pub(crate) resample: Option<usize>,
    #[command(flatten)]
    pub(crate) taper: TaperArgs,
    /// Progressive preview level: 0 full resolution; L renders the image at
    /// 1/2^L of the size from the central 1/4^L of the slice (4^L times fewer
    /// interpolations). Plain X-ray views only. (`--level` is the PNG
    /// window level, as in radiology viewers.)
    #[arg(long, value_name = "L", default_value_t = 0)]
    pub(crate) preview_level: u32,
}

impl Default for LookArgs {
    fn default() -> Self {
        Self {
            depth_cue: "none".into(),
            cue_harmonics: DEFAULT_PROFILE_HARMONICS,
            ambient: None,
            lights: Vec::new(),
            light_ring: None,
            no_cue_correction: false,
            resample: None,
            taper: TaperArgs::default(),
            preview_level: 0,
        }
    }
}

impl LookArgs {
    /// Refuse bad light directions and resample counts before any work.
    pub(crate) fn check(&self) -> Result<(), Error> {
        crate::checks::check_resample_count(self.resample)?;
        self.taper.check()?;
        for light in &self.lights {
            crate::checks::check_direction("--light (a scene light's direction)", light.towards)?;
        }
        Ok(())
    }

    /// The scene: cue, ambient and lights, a light ring placed about `view`.
    pub(crate) fn scene(&self, view: &View) -> Result<Scene, Error> {
        let cue = parse_depth_cue(&self.depth_cue, self.cue_harmonics)?;
        let mut lights = self.lights.clone();
        if let Some((count, tilt)) = self.light_ring {
            lights.extend(light_ring(view, count, tilt)?);
        }
        let default_ambient = Scene::default_ambient(!lights.is_empty());
        let mut scene = Scene {
            cue,
            ambient: self.ambient.unwrap_or([default_ambient; 3]),
            correct_cue_shading: !self.no_cue_correction,
            ..Scene::xray()
        };
        if lights.len() > MAX_LIGHTS {
            return Err(format!(
                "{} lights given, but a scene holds at most {MAX_LIGHTS}",
                lights.len()
            )
            .into());
        }
        for light in &lights {
            scene.add_light(*light)?;
        }
        scene.validate()?;
        Ok(scene)
    }

    /// What to blame for non-finite pixels.
    pub(crate) fn overflow_cause(&self) -> String {
        crate::checks::overflow_cause(
            self.ambient.is_some(),
            !self.lights.is_empty() || self.light_ring.is_some(),
            self.depth_cue != "none",
        )
    }
}

/// Fill the look settings the command line did not give from the scene.
pub(crate) fn apply_scene_to_look(
    look: &mut LookArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    fill(
        given,
        "resample",
        &mut look.resample,
        scene.volume.resample.map(Some),
    );
    fill(
        given,
        "taper",
        &mut look.taper.taper,
        scene.volume.taper.map(Some),
    );
    let sh = &scene.shading;
    fill(
        given,
        "depth_cue",
        &mut look.depth_cue,
        sh.depth_cue.clone(),
    );
    fill(
        given,
        "cue_harmonics",
        &mut look.cue_harmonics,
        sh.cue_harmonics,
    );
    fill(given, "ambient", &mut look.ambient, sh.ambient.map(Some));
    fill(
        given,
        "no_cue_correction",
        &mut look.no_cue_correction,
        sh.cue_correction.map(|on| !on),
    );
    fill(given, "lights", &mut look.lights, scene.lights.clone());
    fill(
        given,
        "light_ring",
        &mut look.light_ring,
        scene.light_ring.map(Some),
    );
}

/// The cue-aware window: the largest weight the cue gives between the
/// front and the back of the volume (at least 1e-12), by which the window
/// of the uncued view is scaled; `None` without a cue.
pub(crate) fn cue_gain(cue: &DepthCue) -> Result<Option<f64>, Error> {
    if *cue == DepthCue::None {
        return Ok(None);
    }
    let terms = CueTerms::new(cue, 1.0)?;
    let steps = 256;
    let largest = (0..=steps)
        .map(|i| terms.weight(-1.0 + 2.0 * i as f64 / steps as f64))
        .fold(f64::MIN, f64::max);
    Ok(Some(largest.max(1e-12)))
}

/// `scene` without its depth cue: the view whose window a cued view takes.
pub(crate) fn uncued(scene: &Scene) -> Scene {
    Scene {
        cue: DepthCue::None,
        ..scene.clone()
    }
}

/// Above this share of negatively weighted density (−30 dB) a depth cue
/// warns (see `negative_cue_share`).
pub(crate) const NEGATIVE_CUE_WARNING_SHARE: f64 = 1e-3;

/// Warn when the depth cue, extrapolated into the volume's corners on
/// `view`, weights a noticeable share of the density negatively.
pub(crate) fn warn_negative_cue(
    volume: &fvr_engine::volume::Volume,
    scene: &Scene,
    view: &View,
) -> Result<(), Error> {
    let (lowest, share) = fvr_engine::render::shaded::negative_cue_share(volume, scene, view)?;
    if share > NEGATIVE_CUE_WARNING_SHARE {
        eprintln!(
            "fvr: warning: the depth cue is given between t = -R and +R; extrapolated beyond, \
             into the volume's corners on this view, it falls to {}, and {:.2}% of the \
             weighted density counts negatively. Raise the smaller of FRONT and BACK to avoid it.",
            fvr_host::text::num3(lowest),
            100.0 * share
        );
    }
    Ok(())
}

/// The cue-aware default window of a PNG: for a depth-cued view and an
/// automatic (`--percentiles`) window, the percentile window of the same
/// view without its cue, times the cue's largest weight ([`cue_gain`]).
/// The automatic window of the cued image itself would stretch it back to
/// full range and hide the cue. `None` without a cue or with an explicit
/// `--window/--level`.
pub(crate) fn cue_window(
    renderer: &fvr_engine::Renderer,
    scene: &Scene,
    view: &View,
    (width, height): (usize, usize),
    window: &fvr_host::image::output::Window,
) -> Result<Option<(f64, f64)>, Error> {
    use fvr_host::image::output::Window;
    if matches!(window, Window::Range(..)) {
        return Ok(None);
    }
    let Some(gain) = cue_gain(&scene.cue)? else {
        return Ok(None);
    };
    let plain = renderer.spectra().render_sampled(
        &uncued(scene),
        view,
        renderer.sampling(),
        width,
        height,
    )?;
    let (lo, hi) = window.resolve(&plain.data);
    Ok(Some((lo * gain, hi * gain)))
}
