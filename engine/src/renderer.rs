//! The one entry point: a [`Renderer`] plans (chooses filter, grid and
//! precision for an accuracy target), prepares the spectra once, and renders
//! any number of views. Every front end (the `fvr` program, its tests and
//! benches) goes through it:
//!
//! ```text
//! Settings ──plan──▶ Plan ──prepare──▶ Renderer ──render(view)──▶ Image + ViewReport
//! ```
//!
//! Planning and preparing are separate steps so that a program can check
//! the chosen configuration against its memory budget before it pays for
//! the preparation; [`Renderer::new`] does both.

use std::sync::OnceLock;
use std::time::Duration;

use crate::clock::Instant;

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::{Sampling, View};
use fvr_core::num::{Real, Sample};
use fvr_core::shading::Scene;
use fvr_core::slice::adaptive::AdaptiveStats;
use fvr_core::volume::GridOversampling;

use crate::error::PipelineError;
use crate::image::Image;
use crate::plan::filter::KbDesign;
use crate::plan::{
    choose_among, grid_filter, image_side, predict_grid, Candidate, Constraints, Prediction,
    ALL_GRIDS, POW2_GRIDS,
};
use crate::render::adaptive::{AdaptiveRenderer, Walked};
use crate::render::shaded::SceneSpectra;
use crate::slice::adaptive::{AdaptiveMarks, AdaptiveSettings};
use crate::spectrum::{AnySpectrum, OwnedSpectrum, Precision};
use crate::volume::Volume;

/// The accuracy target without one given, in dB.
pub const DEFAULT_ACCURACY_DB: f64 = 50.0;

/// Below this prediction, settings given without a target draw a warning.
pub const PREDICTION_WARNING_DB: f64 = 40.0;

/// Below this estimated storage SNR the preparation warns (see
/// [`OwnedSpectrum::storage_snr_estimate_db`]).
pub const STORAGE_SNR_WARNING_DB: f64 = 50.0;

/// How voxels and pixels map to physical units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Units {
    /// Voxel units: 1 mm voxels and pixels whatever the volume's spacing.
    pub ignore_spacing: bool,
    /// The pixel size in mm; by default the finest spacing, raised so that
    /// the longest physical side fits the default image.
    pub pixel_size: Option<f64>,
}

/// What a renderer is asked for. Settings left `None` are the planner's to
/// choose.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Target SNR in dB against the exact projection ([`DEFAULT_ACCURACY_DB`]
    /// when none is given, unless filter, grid and precision all are).
    pub accuracy_db: Option<f64>,
    /// The interpolation filter, if fixed.
    pub filter: Option<FilterKind>,
    /// The grid's oversampling, if fixed.
    pub oversample: Option<GridOversampling>,
    /// Storage and arithmetic, if fixed.
    pub precision: Option<Precision>,
    /// How the Kaiser–Bessel shape is chosen.
    pub kb_design: KbDesign,
    /// Depth cue, ambient colour and lights (paper §3).
    pub scene: Scene,
    /// Adaptive filtering (paper §4), for plain X-ray views.
    pub adaptive: Option<AdaptiveSettings>,
    /// Progressive preview level (0: full resolution), plain X-ray views.
    pub preview_level: u32,
    /// Physical units.
    pub units: Units,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            accuracy_db: None,
            filter: None,
            oversample: None,
            precision: None,
            kb_design: KbDesign::Auto,
            scene: Scene::xray(),
            adaptive: None,
            preview_level: 0,
            units: Units::default(),
        }
    }
}

impl Settings {
    /// Whether views are plain X-ray projections (one channel, no cue or
    /// light terms), the only ones mixed-radix grids, previews and adaptive
    /// filtering serve.
    pub fn plain(&self) -> bool {
        self.scene.channels() == 1 && !self.scene.has_partner_terms()
    }

    /// The grids the planner may choose: every one for plain views without
    /// adaptive filtering, the power-of-two ones otherwise.
    pub fn grids(&self) -> &'static [GridOversampling] {
        if self.plain() && self.adaptive.is_none() {
            &ALL_GRIDS
        } else {
            &POW2_GRIDS
        }
    }

    /// Refuse combinations no view can render, before any work.
    ///
    /// # Errors
    /// A one-line message naming the options.
    pub fn check(&self) -> Result<(), PipelineError> {
        if (self.preview_level > 0 || self.adaptive.is_some()) && !self.plain() {
            return Err(settings(
                "--preview-level and --adaptive work on plain X-ray views: leave out \
                 --depth-cue, --light, --light-ring and a coloured --ambient",
            ));
        }
        if self.preview_level > 0 && self.adaptive.is_some() {
            return Err(settings(
                "--preview-level and --adaptive cannot be combined: choose one",
            ));
        }
        Ok(())
    }
}

fn settings(message: &str) -> PipelineError {
    PipelineError::Settings(message.into())
}

/// The configuration a renderer uses, and why.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The interpolation filter.
    pub filter: FilterKind,
    /// The grid's oversampling.
    pub grid: GridOversampling,
    /// Storage and arithmetic.
    pub precision: Precision,
    /// The target the configuration was chosen for (none when every setting
    /// was given).
    pub target_db: Option<f64>,
    /// Whether the target was given rather than the default.
    pub explicit: bool,
    /// The prediction for the configuration used.
    pub prediction: Prediction,
    /// Warnings for the user, one line each (a low prediction, a target
    /// out of reach).
    pub warnings: Vec<String>,
    /// Time spent planning.
    pub time: Duration,
}

impl Plan {
    /// Choose the configuration for `volume`: the cheapest predicted to
    /// reach the target among the settings left open, or, with filter, grid
    /// and precision all given and no target, those, with their prediction.
    ///
    /// # Errors
    /// A mixed-radix grid where views need a power of two, a volume too
    /// thin for the grid, or the planner's errors.
    pub fn choose(volume: &Volume, settings: &Settings) -> Result<Self, PipelineError> {
        let t0 = Instant::now();
        let grids = settings.grids();
        if let Some(grid) = settings.oversample {
            if !grid.is_pow2() && grids.len() == POW2_GRIDS.len() {
                return Err(PipelineError::Settings(format!(
                    "--oversample {} works on plain X-ray views: depth cues, lights and \
                     --adaptive need --oversample 1 or 2",
                    grid.name()
                )));
            }
        }
        // A volume too thin for the smallest grid allowed gets its own
        // message before any prediction.
        let least = settings.oversample.unwrap_or(GridOversampling::X1);
        crate::volume::check_padding(volume.dims, least.side(volume.dims)?)
            .map_err(PipelineError::Settings)?;
        let explicit = settings.accuracy_db.is_some();
        let target = settings.accuracy_db.unwrap_or(DEFAULT_ACCURACY_DB);
        let mut warnings = Vec::new();
        if let (false, Some(filter), Some(grid), Some(precision)) = (
            explicit,
            settings.filter,
            settings.oversample,
            settings.precision,
        ) {
            // Everything fixed by the user: nothing to choose, only to predict.
            let candidate = Candidate {
                filter,
                oversample: grid.integer(),
                precision,
            };
            let prediction = predict_grid(volume, candidate, grid, settings.kb_design)?;
            warnings.extend(low_prediction(&prediction));
            return Ok(Self {
                filter,
                grid,
                precision,
                target_db: None,
                explicit: false,
                prediction,
                warnings,
                time: t0.elapsed(),
            });
        }
        let constraints = Constraints {
            filter: settings.filter,
            oversample: settings.oversample,
            precision: settings.precision,
        };
        let plan = choose_among(volume, settings.kb_design, target, constraints, grids)?;
        let p = plan.prediction;
        if !explicit && constraints != Constraints::default() {
            // The default target with some settings given: they win, and only
            // a prediction below the warning level is worth a line.
            warnings.extend(low_prediction(&p));
        } else if !plan.met {
            warnings.push(format!(
                "no configuration is predicted to reach {target} dB{}; using the best, {}, \
                 predicted at {:.1} dB ({}).",
                if constraints == Constraints::default() {
                    ""
                } else {
                    " with the settings given"
                },
                describe(&p),
                p.db,
                p.dominant().why()
            ));
        }
        Ok(Self {
            filter: p.candidate.filter,
            grid: p.grid,
            precision: p.candidate.precision,
            target_db: Some(target),
            explicit,
            prediction: p,
            warnings,
            time: t0.elapsed(),
        })
    }
}

/// The warning for settings given that are predicted below
/// [`PREDICTION_WARNING_DB`].
fn low_prediction(prediction: &Prediction) -> Option<String> {
    (prediction.db < PREDICTION_WARNING_DB).then(|| {
        format!(
            "{} is predicted to reach only {:.1} dB on this volume ({}); --accuracy 50 chooses \
             a configuration predicted to reach 50 dB.",
            describe(prediction),
            prediction.db,
            prediction.dominant().why()
        )
    })
}

/// The flags that select `p`'s configuration.
pub fn describe(p: &Prediction) -> String {
    format!(
        "--filter {} --oversample {} --precision {}",
        p.candidate.filter.name(),
        p.grid.name(),
        p.candidate.precision
    )
}

/// What one view cost and did.
#[derive(Clone, Debug)]
pub struct ViewReport {
    /// Time spent on the view (the adaptive walk alone, without its marks).
    pub time: Duration,
    /// With adaptive filtering: how the view was walked.
    pub adaptive: Option<AdaptiveView>,
}

/// How an adaptive view went.
#[derive(Clone, Debug)]
pub struct AdaptiveView {
    /// Samples per filter.
    pub stats: AdaptiveStats,
    /// Whether the adaptive walk ran or the plain one did.
    pub walked: Walked,
    /// Time spent building the marks, if this view built them.
    pub mark_time: Option<Duration>,
}

/// A prepared volume, ready to render views of.
#[derive(Debug)]
pub struct Renderer {
    settings: Settings,
    plan: Plan,
    spectra: SceneSpectra,
    filter: Filter,
    dims: [usize; 3],
    default_side: usize,
    sampling: Sampling,
    storage_snr_db: f64,
    warnings: Vec<String>,
    prepare_time: Duration,
    marks: OnceLock<AdaptiveMarks>,
}

impl Renderer {
    /// Plan and prepare: [`Plan::choose`] then [`Renderer::prepare`].
    ///
    /// # Errors
    /// As those.
    pub fn new(volume: &Volume, settings: Settings) -> Result<Self, PipelineError> {
        settings.check()?;
        let plan = Plan::choose(volume, &settings)?;
        Self::prepare(volume, settings, plan, &|_| {})
    }

    /// Prepare `volume` for `plan`: fit the filter, transform the volume
    /// (and its gradient magnitude, for lights) and store the spectra.
    /// `stage` is told what runs next ("fitting filter", "preprocess").
    ///
    /// # Errors
    /// Bad settings, a volume the grid cannot hold, memory beyond the limit,
    /// or the core's refusals.
    pub fn prepare(
        volume: &Volume,
        settings: Settings,
        plan: Plan,
        stage: &dyn Fn(&str),
    ) -> Result<Self, PipelineError> {
        settings.check()?;
        let t0 = Instant::now();
        stage("fitting filter");
        let grid = plan.grid;
        crate::volume::check_padding(volume.dims, grid.side(volume.dims)?)
            .map_err(PipelineError::Settings)?;
        let filter = grid_filter(volume, plan.filter, grid, settings.kb_design)?;
        let gradient = settings.scene.needs_gradient_spectrum();
        stage(if gradient {
            "preprocess (density and |grad f| spectra)"
        } else {
            "preprocess"
        });
        let spectra = if grid.is_pow2() {
            SceneSpectra::prepare(volume, filter, plan.precision, &settings.scene)?
        } else if gradient {
            return Err(PipelineError::Settings(format!(
                "--oversample {} works on plain X-ray views: lights need --oversample 1 or 2",
                grid.name()
            )));
        } else {
            SceneSpectra {
                density: AnySpectrum::prepare_grid(volume, filter, plan.precision, grid)?,
                gradient: None,
            }
        };
        let prepare_time = t0.elapsed();
        let mut warnings = Vec::new();
        let volume_sum: f64 = volume.data.iter().map(|&v| v as f64).sum();
        let storage_snr_db = spectra.density.storage_snr_estimate_db(volume_sum);
        if storage_snr_db < STORAGE_SNR_WARNING_DB {
            warnings.push(format!(
                "premultiplying for {} at oversample {} amplifies this volume's edges; the {} \
                 spectrum is estimated to hold only {storage_snr_db:.1} dB. Use --oversample 2, \
                 --filter cubic, or --precision f32.",
                plan.filter.name(),
                grid.name(),
                plan.precision
            ));
        }
        let n = spectra.density.n();
        let default_side = image_side(volume.dims, n)?;
        let sampling = sampling(volume, settings.units, n, default_side, &mut warnings)?;
        if settings.adaptive.is_some() && sampling.uniform_pitch().is_none() {
            let s = sampling.spacing();
            return Err(PipelineError::Settings(format!(
                "--adaptive needs cubic voxels imaged at their own size (or voxel units), and \
                 this render uses {} x {} x {} mm voxels and {} mm pixels: add --resample N, \
                 drop --pixel-size, or add --ignore-spacing",
                s[0],
                s[1],
                s[2],
                sampling.pixel_size()
            )));
        }
        Ok(Self {
            settings,
            plan,
            spectra,
            filter,
            dims: volume.dims,
            default_side,
            sampling,
            storage_snr_db,
            warnings,
            prepare_time,
            marks: OnceLock::new(),
        })
    }

    /// The image size for `size` (the default image, as wide as the
    /// volume's longest side, when `None`), checked against the grid.
    ///
    /// # Errors
    /// A size beyond the grid.
    pub fn image_size(
        &self,
        size: Option<(usize, usize)>,
    ) -> Result<(usize, usize), PipelineError> {
        let (w, h) = size.unwrap_or((self.default_side, self.default_side));
        fvr_core::image::check_image(w, h, self.n())?;
        Ok((w, h))
    }

    /// Render `view` at `size` ([`Renderer::image_size`]): the X-ray
    /// projection, cued and lit as the scene says, at the preview level or
    /// adaptively filtered as the settings say, in physical units.
    ///
    /// # Errors
    /// A bad view or size, the adaptive marks' errors, or an image that
    /// overflows `f32` ([`PipelineError::Overflow`]).
    pub fn render(
        &self,
        view: &View,
        size: Option<(usize, usize)>,
    ) -> Result<(Image, ViewReport), PipelineError> {
        let (image, report) = self.render_unchecked(view, size)?;
        crate::image::finite::check_image(&image.data, &self.settings.scene)?;
        Ok((image, report))
    }

    /// [`Renderer::render`] before the image is checked for overflow.
    fn render_unchecked(
        &self,
        view: &View,
        size: Option<(usize, usize)>,
    ) -> Result<(Image, ViewReport), PipelineError> {
        let (w, h) = self.image_size(size)?;
        let ambient = self.settings.scene.ambient[0];
        let density = &self.spectra.density;
        let t0 = Instant::now();
        if self.settings.preview_level > 0 {
            let level = self.settings.preview_level;
            let (pw, ph) = fvr_core::render::preview_size(w, h, level);
            let data = density.render_level_sampled(view, &self.sampling, pw, ph, level)?;
            let image = grey(pw, ph, data.into_iter().map(|v| v * ambient).collect());
            return Ok((image, plain_report(t0)));
        }
        if let Some(adaptive) = &self.settings.adaptive {
            let mut mark_time = None;
            let marks = match self.marks.get() {
                Some(marks) => marks,
                None => {
                    let t = Instant::now();
                    let built = build_marks(density, adaptive)?;
                    mark_time = Some(t.elapsed());
                    self.marks.get_or_init(|| built)
                }
            };
            let t1 = Instant::now();
            let (data, stats, walked) = adaptive_view(density, marks, view, w, h)?;
            let time = t1.elapsed();
            let gain = self.sampling.gain() * ambient;
            let image = grey(w, h, data.iter().map(|v| v * gain).collect());
            let report = ViewReport {
                time,
                adaptive: Some(AdaptiveView {
                    stats,
                    walked,
                    mark_time,
                }),
            };
            return Ok((image, report));
        }
        let image = self
            .spectra
            .render_sampled(&self.settings.scene, view, &self.sampling, w, h)
            .map_err(PipelineError::Settings)?;
        Ok((image, plain_report(t0)))
    }

    /// The settings the renderer was made with.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The configuration used, its prediction and the planning time.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The prepared spectra.
    pub fn spectra(&self) -> &SceneSpectra {
        &self.spectra
    }

    /// The filter fitted to the volume.
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// The grid's side.
    pub fn n(&self) -> usize {
        self.spectra.density.n()
    }

    /// The volume's dims.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The default image side: the volume's longest side, within the grid.
    pub fn default_side(&self) -> usize {
        self.default_side
    }

    /// Voxel spacing and pixel size.
    pub fn sampling(&self) -> &Sampling {
        &self.sampling
    }

    /// The estimated SNR of the stored spectrum in dB.
    pub fn storage_snr_db(&self) -> f64 {
        self.storage_snr_db
    }

    /// The preparation's warnings, one line each.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Time spent preparing (filter fit and transforms).
    pub fn prepare_time(&self) -> Duration {
        self.prepare_time
    }

    /// The adaptive marks, once a view has built them.
    pub fn marks(&self) -> Option<&AdaptiveMarks> {
        self.marks.get()
    }
}

fn grey(width: usize, height: usize, data: Vec<f64>) -> Image {
    Image {
        channels: 1,
        width,
        height,
        data,
    }
}

fn plain_report(t0: Instant) -> ViewReport {
    ViewReport {
        time: t0.elapsed(),
        adaptive: None,
    }
}

/// The voxel spacing and pixel size: the volume's spacing, or 1 mm in
/// voxel units; the pixel size given, or the finest spacing, raised if need
/// be so that the longest physical side fits `default_side` pixels. Warns
/// when the longest side exceeds the image grid's period `n·p`.
fn sampling(
    volume: &Volume,
    units: Units,
    n: usize,
    default_side: usize,
    warnings: &mut Vec<String>,
) -> Result<Sampling, PipelineError> {
    if units.ignore_spacing {
        return Ok(Sampling::UNIT);
    }
    let spacing = volume.spacing;
    let longest = (0..3)
        .map(|a| volume.dims[a] as f64 * spacing[a])
        .fold(0.0, f64::max);
    let pixel_size = match units.pixel_size {
        Some(p) => p,
        None => {
            let finest = spacing.iter().copied().fold(f64::INFINITY, f64::min);
            finest.max(longest / default_side.max(1) as f64)
        }
    };
    let sampling = Sampling::new(spacing, pixel_size)
        .map_err(|e| PipelineError::Settings(format!("--pixel-size: {e}")))?;
    let period = n as f64 * pixel_size;
    if longest > period {
        warnings.push(format!(
            "the volume's longest side ({longest:.1} mm) exceeds the image grid's period ({n} \
             pixels of {pixel_size} mm = {period:.1} mm): views across it wrap around. Use a \
             larger --pixel-size or --oversample 2."
        ));
    }
    Ok(sampling)
}

fn build_marks(
    spec: &AnySpectrum,
    settings: &AdaptiveSettings,
) -> Result<AdaptiveMarks, PipelineError> {
    let built = match spec {
        AnySpectrum::F16(s) => AdaptiveMarks::build(s, settings),
        AnySpectrum::F32(s) => AdaptiveMarks::build(s, settings),
        AnySpectrum::F64(s) => AdaptiveMarks::build(s, settings),
    };
    built.map_err(PipelineError::Settings)
}

fn adaptive_view(
    spec: &AnySpectrum,
    marks: &AdaptiveMarks,
    view: &View,
    w: usize,
    h: usize,
) -> Result<(Vec<f64>, AdaptiveStats, Walked), PipelineError> {
    fn go<S: Sample, T: Real>(
        spec: &OwnedSpectrum<S>,
        marks: &AdaptiveMarks,
        view: &View,
        w: usize,
        h: usize,
    ) -> Result<(Vec<f64>, AdaptiveStats, Walked), PipelineError> {
        let mut renderer = AdaptiveRenderer::<T>::new(marks, spec)?;
        let mut out = vec![T::ZERO; w * h];
        let stats = renderer.render_into(spec, view, w, h, &mut out)?;
        let image = out.into_iter().map(T::to_f64).collect();
        Ok((image, stats, renderer.walked()))
    }
    match spec {
        AnySpectrum::F16(s) => go::<_, f32>(s, marks, view, w, h),
        AnySpectrum::F32(s) => go::<_, f32>(s, marks, view, w, h),
        AnySpectrum::F64(s) => go::<_, f64>(s, marks, view, w, h),
    }
}
