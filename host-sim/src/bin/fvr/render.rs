//! `fvr render`: one view of a volume, X-ray, depth-cued or shaded.

use crate::args::{parse_vec3, prepare_with_progress, volume_help, FrameArgs, InputArgs, PngArgs};
use crate::scene::SCENE_HELP;
use crate::Error;
use fvr_engine::{Plan, Settings};
use std::path::{Path, PathBuf};
use std::time::Instant;

use fvr_core::filter::Filter;
use fvr_engine::render::shaded::SceneSpectra;
use fvr_engine::volume::Volume;
use fvr_host::image::{Image, ImageFiles};
use serde::Serialize;

use crate::adaptive_report::{AdaptiveJson, AdaptiveReport};
use crate::checks::{check_output, check_resample};

use clap::Args;
use fvr_core::geometry::{Sampling, View};
use fvr_core::shading::Scene;
use fvr_engine::render::shaded::SceneRenderer;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::slice::adaptive::{AdaptiveSettings, Bound, DEFAULT_PLAIN_BELOW, DEFAULT_PROBES};
use fvr_engine::spectrum::Precision;
use fvr_host::image::output::write_png;
use fvr_host::options::{parse_chain, parse_percent, parse_tolerance};
use fvr_host::reference::shaded::exact_scene_projection_sampled;
use fvr_host::reference::{exact_projection_sampled, snr_db};
use fvr_host::sources::phantom_by_name;

#[derive(Args, Clone)]
pub(crate) struct RenderArgs {
    /// A volume file, a raw file with --raw-dims, a data set, or a built-in phantom.
    #[arg(help = volume_help(), required_unless_present = "scene")]
    pub(crate) volume: Option<String>,
    /// Scene file (TOML) with any of the settings below; flags given on the
    /// command line override the scene's values.
    #[arg(long, value_name = "FILE.toml", long_help = SCENE_HELP)]
    pub(crate) scene: Option<PathBuf>,
    /// View direction X,Y,Z in the volume's frame (its i, j, k axes), from
    /// the eye into the scene. --view names a view in the patient's frame.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, required_unless_present_any = ["scene", "view"])]
    pub(crate) dir: Option<[f64; 3]>,
    /// Up hint X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,1")]
    pub(crate) up: [f64; 3],
    #[command(flatten)]
    pub(crate) frame: FrameArgs,
    #[command(flatten)]
    pub(crate) look: crate::look::LookArgs,
    /// Output file: .nrrd (float32; sizes W H, or 3 W H for RGB) or .png
    /// (grey: windowed, see --bits, --window/--level, --percentiles and
    /// --colormap; RGB: 8-bit, one percentile window over all channels).
    #[arg(long, required_unless_present = "scene")]
    pub(crate) out: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) png: PngArgs,
    #[command(flatten)]
    pub(crate) report: crate::stats::StatsArgs,
    /// Adaptive filtering (paper §4): use a cheaper filter wherever the
    /// spectrum is weak, keeping the image within DB decibels of the
    /// full-filter image (eq. 16). Plain X-ray views only.
    #[arg(long, value_name = "DB", value_parser = parse_tolerance, allow_hyphen_values = true)]
    pub(crate) adaptive: Option<f64>,
    /// The cheaper filters of --adaptive, cheapest first (1 or 2 of zero,
    /// nearest, linear, cubic, kb3, ...; each narrower than --filter).
    /// `zero` leaves a point out and reads nothing; `nearest` is the
    /// paper's 1³ filter.
    #[arg(long, default_value = DEFAULT_CHAIN)]
    pub(crate) adaptive_chain: String,
    /// Use this response difference h_d in eq. 16 instead of the one computed
    /// for the filter pair (the paper used 0.3); implies --adaptive-bound
    /// paper. A smaller value than the filters' own voids the guarantee;
    /// --stats then shows the SNR reached.
    #[arg(long, value_name = "H")]
    pub(crate) adaptive_hd: Option<f64>,
    /// How --adaptive turns decibels into a magnitude threshold: `exact`
    /// measures the error field of eq. 15 (one 3D inverse transform per
    /// candidate threshold, about 8, once per volume); `parseval` bounds
    /// that field's energy by Parseval's theorem (no transform, a smaller
    /// threshold), then raises it by --adaptive-probes evaluations of the
    /// field; `paper` uses eq. 16 with the worst-case response difference
    /// h_d (instant, but loose).
    /// Default: `parseval`, or `paper` when --adaptive-hd is given.
    #[arg(long, value_name = "BOUND", value_parser = Bound::from_name)]
    pub(crate) adaptive_bound: Option<Bound>,
    /// Render a view with the plain walk and the full filter (its image
    /// exactly) when the marks of --adaptive would move fewer than PCT
    /// percent of its samples to the cheaper filters: below that share the
    /// adaptive walk is slower than the plain one. 0 always walks
    /// adaptively.
    #[arg(long, value_name = "PCT", value_parser = parse_percent,
          default_value_t = 100.0 * DEFAULT_PLAIN_BELOW)]
    pub(crate) adaptive_plain_below: f64,
    /// With --adaptive-bound parseval: at most N 3D inverse transforms
    /// (each about one preparation's time) that evaluate the error field
    /// of eq. 15 above Parseval's threshold and raise the threshold where
    /// the field allows, for faster views. 0 keeps Parseval's bound alone.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_PROBES)]
    pub(crate) adaptive_probes: usize,
    /// For a built-in phantom, also print the SNR against its exact line integrals.
    #[arg(long)]
    pub(crate) exact: bool,
    #[command(flatten)]
    pub(crate) input: InputArgs,
    #[command(flatten)]
    pub(crate) zoom: crate::zoom::ZoomArgs,
    #[command(flatten)]
    pub(crate) anatomy: crate::anatomy::AnatomyArgs,
}

impl RenderArgs {
    pub(crate) fn volume_spec(&self) -> Result<&str, Error> {
        self.volume.as_deref().ok_or_else(|| {
            "no volume: give VOLUME, or `volume.path` or `volume.builtin` in the scene".into()
        })
    }

    pub(crate) fn view(&self) -> Result<View, Error> {
        if self.anatomy.view.is_some() {
            // Stands in for the named view until the volume's orientation
            // is read ([`crate::anatomy`]).
            return Ok(View::along([1.0, 0.0, 0.0]));
        }
        let dir = self.dir.ok_or_else(|| {
            "no view direction: give --dir, or `camera.dir` in the scene".to_string()
        })?;
        Ok(View { dir, up: self.up })
    }

    pub(crate) fn out_path(&self) -> Result<&Path, Error> {
        self.out
            .as_deref()
            .ok_or_else(|| "no output file: give --out, or `output.path` in the scene".into())
    }
}

/// What a render builds from its volume ([`crate::args::plan_job`]).
fn declare_job(args: &RenderArgs, scene: &Scene) {
    let size = args.frame.size;
    let zoom = args.zoom.zoom as u64;
    crate::args::plan_job(
        &args.frame.spectrum,
        args.look.resample,
        crate::args::spectra(scene),
        // Per-view grids (slice, scratch, output) and the RGB image.
        ("view buffers and image", move |n, side| {
            // A size beyond the grid is refused later, by name.
            let (w, h) = size.map_or((side, side), |(w, h)| {
                ((w as u64).min(n), (h as u64).min(n))
            });
            // Per cell at f64: slice, column walk's sums (2), a mixed
            // side's transposed grid and the output.
            // With --zoom, the padded grid and its transposed copy at f64.
            let m = n.saturating_mul(zoom);
            let zoomed = if zoom > 1 {
                m.saturating_mul(m).saturating_mul(16)
            } else {
                0
            };
            n.saturating_mul(n)
                .saturating_mul(40)
                .saturating_add(zoomed)
                .saturating_add(
                    w.saturating_mul(h)
                        .saturating_mul(32)
                        .saturating_mul(zoom * zoom),
                )
        }),
        "use a smaller --resample, --size or --zoom, --precision f16 or --oversample 1",
    );
}

/// The engine's settings for `args` and `scene`: the spectrum flags given,
/// the scene, adaptive filtering, the preview level and the units.
fn settings(args: &RenderArgs, scene: Scene) -> Result<Settings, Error> {
    let adaptive = match args.adaptive {
        Some(tolerance_db) => Some(AdaptiveSettings {
            tolerance_db,
            chain: parse_chain(&args.adaptive_chain)?,
            h_d: args.adaptive_hd,
            bound: args.adaptive_bound.unwrap_or(match args.adaptive_hd {
                Some(_) => Bound::Paper,
                None => Bound::Parseval,
            }),
            plain_below: args.adaptive_plain_below,
            probes: args.adaptive_probes,
        }),
        None => None,
    };
    Ok(Settings {
        scene,
        adaptive,
        preview_level: args.look.preview_level,
        units: args.frame.units.units(),
        ..crate::plan::settings(&args.frame.spectrum)
    })
}

/// The chain of `--adaptive` by default: the zero filter, which reads
/// nothing. On `gaussians@256` with kb6 at 40 dB its views take about half
/// the time of the 1³ filter's (docs/adaptive.md).
pub(crate) const DEFAULT_CHAIN: &str = "zero";

pub(crate) fn render(args: &RenderArgs) -> Result<(), Error> {
    let out = args.out_path()?;
    let volume_spec = args.volume_spec()?;
    // Case-insensitive (`x.PNG`, `x.Nrrd`); the file keeps the given name.
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext != "png" && ext != "nrrd" {
        return Err(format!("output `{}` must end in .png or .nrrd", out.display()).into());
    }
    let mut others: Vec<&Path> = args.scene.iter().map(|p| p.as_path()).collect();
    if let Some(profile) = args.look.depth_cue.strip_prefix("profile:@") {
        others.push(Path::new(profile));
    }
    check_output(out, &["png", "nrrd"], volume_spec, &others)?;
    let view = args.view()?;
    crate::checks::check_direction("--dir (camera.dir in a scene)", view.dir)?;
    crate::checks::check_direction("--up (camera.up in a scene)", view.up)?;
    args.look.check()?;
    view.frame()?;
    let style = args.png.style()?;
    if crate::prepared::is_prepared(volume_spec) {
        if args.zoom.zoom > 1 || args.anatomy.view.is_some() {
            return Err("--zoom and --view need the volume (its grid and orientation), not a                         prepared .fvrs spectrum: give the volume, or --dir and no --zoom"
                .into());
        }
        return crate::prepared::render(args, volume_spec, out, &ext, &view, style);
    }
    let scene = build_scene(args)?;
    declare_job(args, &scene);
    let t0 = Instant::now();
    let mut volume = args.input.load(volume_spec)?;
    crate::checks::check_not_input(out)?;
    let mut _volume = fvr_host::budget::hold(volume.data.len() as u64 * 4);
    let taper = args.look.taper.apply(&mut volume)?;
    if let Some(largest) = args.look.resample {
        check_resample(&volume, largest)?;
        volume = volume.resample_isotropic(largest)?;
        _volume = fvr_host::budget::hold(volume.data.len() as u64 * 4);
    }
    fvr_host::budget::check_plan(volume.dims)?;
    let view = match args.anatomy.view {
        Some(named) => named.view_of(&mut volume, volume_spec),
        None => view,
    };
    let t_load = t0.elapsed();
    let settings = settings(args, scene.clone())?;
    settings.check()?;
    let plan = Plan::choose(&volume, &settings)?;
    let mut planned = args.clone();
    crate::plan::apply(&mut planned.frame.spectrum, &plan);
    let args = &planned;
    // The planner may have changed the spectrum's settings.
    declare_job(args, &scene);
    fvr_host::budget::check_plan(volume.dims)?;
    let renderer = prepare_with_progress(&volume, settings, plan)?;
    for w in renderer.warnings() {
        eprintln!("fvr: warning: {w}");
    }
    crate::look::warn_negative_cue(&volume, &scene, &view)?;
    let (w, h) = renderer.image_size(args.frame.size)?;
    // The engine refuses an image that overflows f32; the message names
    // the command line's options.
    let (image, view_report) = renderer
        .render_zoomed(&view, Some((w, h)), args.zoom.zoom)
        .map_err(|e| match e {
            fvr_engine::PipelineError::Overflow { value, .. } => Error::from(format!(
                "the image has non-finite pixels once stored as f32 (the first is {value}): {}",
                args.look.overflow_cause()
            )),
            other => other.into(),
        })?;
    let (w, h) = (image.width, image.height);
    let adaptive_report = match &view_report.adaptive {
        Some(a) => Some(AdaptiveReport::new(
            &renderer,
            a,
            &view,
            &view_report,
            &image,
        )?),
        None => None,
    };
    let t_view = view_report.time;
    // A cued view keeps the window of its uncued view (look::cue_window).
    let cued = match ext.as_str() {
        "png" => crate::look::cue_window(&renderer, &scene, &view, (w, h), &style.window)?,
        _ => None,
    };
    let mut window = None;
    let film = match ext.as_str() {
        "png" => crate::film::film_png(&args.png, &image.data, image.channels)?,
        _ => None,
    };
    if let Some((shown, range)) = &film {
        window = Some(*range);
        let style = fvr_host::image::output::Style {
            window: fvr_host::image::output::Window::Range(range.0, range.1),
            ..style
        };
        write_png(out, w, h, shown, &style)?;
    } else if ext == "png" {
        let range = match cued {
            Some(range) => range,
            None if image.channels == 1 => style.window.resolve(&image.data),
            None => {
                let (lo, hi) = fvr_host::image::AUTO_WINDOW_PERCENTILES;
                fvr_host::image::output::percentile_range(&image.data, lo, hi)
            }
        };
        window = Some(range);
        if image.channels == 1 {
            let style = fvr_host::image::output::Style {
                window: fvr_host::image::output::Window::Range(range.0, range.1),
                ..style
            };
            write_png(out, w, h, &image.data, &style)?;
        } else {
            image.write_png_window(out, range)?;
        }
    } else {
        // The image's pixel pitch: the pixel size, over the zoom, times a
        // preview level's 2^L.
        let pitch = renderer.zoomed_sampling(args.zoom.zoom)?.pixel_size()
            * (1u64 << args.look.preview_level.min(62)) as f64;
        fvr_host::image::nrrd_image::write_image_nrrd(out, &image, Some(pitch))?;
    }
    if !args.report.stats_json {
        let kind = crate::stats::kind(image.channels);
        say!("wrote {} ({w}x{h} {kind})", out.display());
    }
    let job = crate::stats::Job {
        command: "render",
        volume_spec,
        volume: &volume,
        renderer: &renderer,
        frame: &args.frame,
        image: [w, h, image.channels],
        load: t_load,
        views: 1,
        views_time: t_view,
        output: out,
        zoom: args.zoom.zoom,
        taper,
    };
    let rendered = Rendered {
        args,
        volume_spec,
        volume: &volume,
        view,
        scene,
        sampling: renderer.zoomed_sampling(args.zoom.zoom)?,
        n: renderer.n(),
        filter: renderer.filter(),
        spectra: renderer.spectra(),
        image,
        w,
        h,
        adaptive_report,
    };
    let exact = if args.exact {
        Some(rendered.exact()?)
    } else {
        None
    };
    if args.report.stats_json {
        job.print_json(&RenderExtra {
            preview_level: args.look.preview_level,
            window: window.map(|(lo, hi)| [lo, hi]),
            cue_window: cued.is_some(),
            adaptive: rendered.adaptive_report.as_ref().map(AdaptiveReport::json),
            exact_snr_db: exact.as_ref().map(|e| e.as_ref().ok().copied()),
        });
        return Ok(());
    }
    if args.report.stats {
        job.print_human();
        rendered.print_human()?;
        if let Some((lo, hi)) = window {
            say!(
                "  window        {lo} to {hi}{}",
                if cued.is_some() {
                    " (the uncued view's window times the cue's largest weight)"
                } else {
                    ""
                }
            );
        }
    }
    match exact {
        Some(Ok(db)) => say!("  SNR vs exact  {db:.2} dB"),
        Some(Err(why)) => say!("  SNR vs exact  n/a ({why})"),
        None => {}
    }
    Ok(())
}

/// The scene from the command line: cue, ambient, lights.
pub(crate) fn build_scene(args: &RenderArgs) -> Result<Scene, Error> {
    args.look.scene(&args.view()?)
}

/// `fvr render --stats-json`: its members after the common ones.
#[derive(Serialize)]
struct RenderExtra {
    preview_level: u32,
    /// The PNG window `[low, high]` (null for NRRD).
    window: Option<[f64; 2]>,
    /// Whether the window is the cue-aware one (look::cue_window).
    cue_window: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    adaptive: Option<AdaptiveJson>,
    /// With --exact: the SNR against the exact image, null where there is
    /// none.
    #[serde(skip_serializing_if = "Option::is_none")]
    exact_snr_db: Option<Option<f64>>,
}

/// A finished render and what `--stats` and `--exact` report of it
/// beyond the common lines ([`crate::stats`]).
struct Rendered<'a> {
    args: &'a RenderArgs,
    volume_spec: &'a str,
    volume: &'a Volume,
    view: View,
    scene: Scene,
    sampling: Sampling,
    spectra: &'a SceneSpectra,
    filter: Filter,
    image: Image,
    w: usize,
    h: usize,
    n: usize,
    adaptive_report: Option<AdaptiveReport<'a>>,
}

impl Rendered<'_> {
    /// `--stats`: memory per view, the preview level and adaptive
    /// filtering, one per line.
    fn print_human(&self) -> Result<(), Error> {
        let &Rendered {
            args,
            ref scene,
            ref sampling,
            spectra,
            filter,
            w,
            h,
            n,
            ref adaptive_report,
            ..
        } = self;
        // Plain X-ray views go through the view renderer (any grid side).
        let plain = scene.channels() == 1 && !scene.has_partner_terms();
        let working = match (args.frame.spectrum.precision, plain) {
            (Precision::F64, true) => ViewRenderer::<f64>::new(n, filter)
                .with_zoom(args.zoom.zoom)?
                .bytes(),
            (_, true) => ViewRenderer::<f32>::new(n, filter)
                .with_zoom(args.zoom.zoom)?
                .bytes(),
            (Precision::F64, false) => SceneRenderer::<f64>::new(n, filter, scene)?.bytes(),
            (_, false) => SceneRenderer::<f32>::new(n, filter, scene)?.bytes(),
        };
        say!(
            "  per view      {working} bytes ({} slice fields, tables, twiddles)",
            scene.field_count()
        );
        say!("  held          {} bytes in all", spectra.bytes() + working);
        if args.look.preview_level > 0 {
            say!(
                "  level         {} ({w}x{h} at pitch {} {}, central 1/{} of the slice)",
                args.look.preview_level,
                (1u64 << args.look.preview_level) as f64 * sampling.pixel_size(),
                if *sampling == Sampling::UNIT {
                    "voxels"
                } else {
                    "mm"
                },
                1u64 << (2 * args.look.preview_level)
            );
        }
        if let Some(r) = &adaptive_report {
            r.print_human();
        }
        Ok(())
    }

    /// `--exact`: the SNR against the phantom's exact image, or why there
    /// is none.
    fn exact(&self) -> Result<Result<f64, &'static str>, Error> {
        let &Rendered {
            volume_spec,
            volume,
            ref view,
            ref scene,
            ref sampling,
            ref image,
            w,
            h,
            ..
        } = self;
        let plain = scene.channels() == 1 && !scene.has_partner_terms();
        Ok(match phantom_by_name(volume_spec) {
            Some(Ok(p)) if plain => {
                let exact = exact_projection_sampled(
                    p.phantom.as_ref(),
                    volume.dims,
                    view,
                    sampling,
                    w,
                    h,
                )?;
                let ambient = scene.ambient[0];
                let exact: Vec<f64> = exact.iter().map(|v| v * ambient).collect();
                Ok(snr_db(&exact, &image.data))
            }
            Some(Ok(p)) => match p.phantom.as_gaussian_mixture() {
                Some(mixture) => {
                    let exact = exact_scene_projection_sampled(
                        mixture,
                        volume.dims,
                        sampling,
                        scene,
                        view,
                        (w, h),
                        0.05,
                    )?;
                    Ok(snr_db(&exact.data, &image.data))
                }
                None => Err("cued or shaded references exist for gaussians only"),
            },
            _ => Err("not a built-in phantom"),
        })
    }
}
