//! One volume in the browser: load it, plan and prepare it for the page's
//! options, render views. The page's worker holds one [`Session`]; every
//! call returns a one-line message on failure, never panics on bad input.

use fvr_core::geometry::{Sampling, View};
use fvr_core::shading::{DepthCue, Scene};
use fvr_engine::image::Image;
use fvr_engine::render::shaded::light_ring;
use fvr_engine::volume::Volume;
use fvr_engine::{Renderer, Settings};

/// The depth cue the page offers: none, or the paper's linear ramp or
/// DC-free sine (§3.1), from full weight at the front to [`CUE_BACK`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cue {
    /// No cue.
    None,
    /// `w(t)` linear in depth.
    Linear,
    /// `w(t)` a sine through the same end weights.
    Sine,
}

/// The cue's weight at the back of the volume (1 at the front).
pub const CUE_BACK: f64 = 0.2;

/// Lights in the page's ring: the paper's three coloured lights, red, green
/// and blue, 120° apart around the view direction.
pub const LIGHTS: usize = 3;

/// Their tilt towards the viewer in degrees (`fvr render --light-ring 3`).
pub const LIGHT_TILT: f64 = 30.0;

/// What the page asks a preparation for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// The accuracy target in dB (the planner picks filter, grid and
    /// precision predicted to reach it).
    pub accuracy_db: f64,
    /// Depth cue.
    pub cue: Cue,
    /// The three coloured lights.
    pub lights: bool,
}

/// One view as the page asks for it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ask {
    /// The view direction and up hint.
    pub view: View,
    /// Magnification: the pixel size is the default one over `zoom`.
    pub zoom: f64,
    /// Progressive preview level (0: full quality).
    pub level: u32,
}

/// A volume, and once prepared, its renderer.
#[derive(Debug, Default)]
pub struct Session {
    volume: Option<Volume>,
    renderer: Option<Renderer>,
    options: Option<Options>,
}

impl Session {
    /// An empty session.
    pub fn new() -> Self {
        Self::default()
    }

    /// Hold `volume` (dropping any previous one and its renderer).
    pub fn set_volume(&mut self, volume: Volume) {
        self.renderer = None;
        self.volume = Some(volume);
    }

    /// The volume held.
    pub fn volume(&self) -> Option<&Volume> {
        self.volume.as_ref()
    }

    /// The renderer, once prepared.
    pub fn renderer(&self) -> Option<&Renderer> {
        self.renderer.as_ref()
    }

    /// Plan and prepare the volume for `options` (the old renderer is
    /// dropped first, so that its memory is free for the new one).
    ///
    /// # Errors
    /// No volume, a target that is not a finite number, or the engine's
    /// refusals (memory, a volume too thin for the grid).
    pub fn prepare(&mut self, options: Options) -> Result<(), String> {
        let volume = self.volume.as_ref().ok_or("no volume is loaded")?;
        if !(options.accuracy_db.is_finite() && options.accuracy_db > 0.0) {
            return Err(format!(
                "the accuracy target must be a positive number of dB, got {}",
                options.accuracy_db
            ));
        }
        self.renderer = None;
        let settings = Settings {
            accuracy_db: Some(options.accuracy_db),
            scene: scene(options, &View::along([0.0, 1.0, 0.0]))?,
            ..Settings::default()
        };
        self.renderer = Some(Renderer::new(volume, settings).map_err(|e| e.to_string())?);
        self.options = Some(options);
        Ok(())
    }

    /// Render `ask` at the default image size (shrunk by the preview
    /// level). Plain X-ray views at zoom 1 and level 0 are
    /// [`Renderer::render`]'s image, as `fvr render` draws it; previews are
    /// the engine's progressive levels; cued or lit views cannot be
    /// previewed or zoomed in physical units and are rendered full (the page
    /// scales them).
    ///
    /// # Errors
    /// Nothing prepared, a bad view, or the engine's refusals.
    pub fn render(&self, ask: &Ask) -> Result<Image, String> {
        let (renderer, options) = match (&self.renderer, self.options) {
            (Some(r), Some(o)) => (r, o),
            _ => return Err("no volume is prepared".into()),
        };
        if !(ask.zoom.is_finite() && ask.zoom > 0.0) {
            return Err(format!("zoom must be positive, got {}", ask.zoom));
        }
        let plain = renderer.settings().plain();
        if !plain {
            let scene = scene(options, &ask.view)?;
            return renderer
                .spectra()
                .render_sampled(
                    &scene,
                    &ask.view,
                    renderer.sampling(),
                    side(renderer),
                    side(renderer),
                )
                .map_err(|e| e.to_string());
        }
        if ask.zoom == 1.0 && ask.level == 0 {
            return renderer
                .render(&ask.view, None)
                .map(|(image, _)| image)
                .map_err(|e| e.to_string());
        }
        let base = renderer.sampling();
        let sampling = Sampling::new(base.spacing(), base.pixel_size() / ask.zoom)
            .map_err(|e| e.to_string())?;
        let (w, h) = fvr_core::render::preview_size(side(renderer), side(renderer), ask.level);
        let density = &renderer.spectra().density;
        let data = if ask.level == 0 {
            density.render_sampled(&ask.view, &sampling, w, h)
        } else {
            density.render_level_sampled(&ask.view, &sampling, w, h, ask.level)
        }
        .map_err(|e| e.to_string())?;
        Ok(Image {
            channels: 1,
            width: w,
            height: h,
            data,
        })
    }
}

fn side(renderer: &Renderer) -> usize {
    renderer.default_side()
}

/// The scene for `options` seen along `view`: the light ring turns with
/// the view, as `fvr render --light-ring 3` places it.
fn scene(options: Options, view: &View) -> Result<Scene, String> {
    let mut scene = Scene {
        cue: match options.cue {
            Cue::None => DepthCue::None,
            Cue::Linear => DepthCue::Linear {
                front: 1.0,
                back: CUE_BACK,
            },
            Cue::Sine => DepthCue::Sine {
                front: 1.0,
                back: CUE_BACK,
            },
        },
        ..Scene::xray()
    };
    if options.lights {
        scene.ambient = [0.2; 3];
        for light in light_ring(view, LIGHTS, LIGHT_TILT).map_err(|e| e.to_string())? {
            scene.add_light(light).map_err(|e| e.to_string())?;
        }
    }
    Ok(scene)
}

#[cfg(test)]
mod tests;
