//! `fvr render`: one view of a volume, X-ray, depth-cued or shaded.

use crate::args::{parse_vec3, prepare_with_progress, volume_help, FrameArgs, InputArgs, PngArgs};
use crate::scene::SCENE_HELP;
use crate::Error;
use fvr_engine::{Plan, Settings};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use fvr_core::filter::Filter;
use fvr_engine::render::shaded::SceneSpectra;
use fvr_engine::volume::Volume;
use fvr_host::image::{Image, ImageFiles};
use serde::Serialize;
use serde_json::value::RawValue;

use crate::adaptive_report::{AdaptiveJson, AdaptiveReport};
use crate::checks::{check_finite, check_output, check_resample};
use crate::json::{debug_triple, one_line};

use clap::Args;
use fvr_core::geometry::{Sampling, View};
use fvr_core::shading::{Light, Scene, MAX_LIGHTS};
use fvr_engine::render::shaded::{
    light_ring, negative_cue_share, SceneRenderer, DEFAULT_PROFILE_HARMONICS,
};
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::slice::adaptive::{AdaptiveSettings, Bound, DEFAULT_PLAIN_BELOW, DEFAULT_PROBES};
use fvr_engine::spectrum::Precision;
use fvr_host::image::output::write_png;
use fvr_host::options::{parse_chain, parse_percent, parse_tolerance};
use fvr_host::options::{
    parse_depth_cue, parse_light, parse_light_ring, parse_rgb, DEPTH_CUE_HELP,
};
use fvr_host::reference::shaded::exact_scene_projection_sampled;
use fvr_host::reference::{exact_projection_sampled, snr_db};
use fvr_host::sources::phantom_by_name;

/// Above this share of negatively weighted density (−30 dB) a depth cue
/// warns (see `negative_cue_share`).
pub(crate) const NEGATIVE_CUE_WARNING_SHARE: f64 = 1e-3;

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
    /// Depth cue: none, linear:FRONT,BACK, sine:FRONT,BACK, profile:W0,W1,...,
    /// profile:@FILE or profile:gauss:C,S (details with --help).
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
    /// --light.
    #[arg(long, value_name = "N[:TILT]", value_parser = parse_light_ring)]
    pub(crate) light_ring: Option<(usize, f64)>,
    /// Leave out the eq. 14 correction when depth cueing and shading are
    /// combined (only to see what it fixes).
    #[arg(long)]
    pub(crate) no_cue_correction: bool,
    /// Output file: .nrrd (float32; sizes W H, or 3 W H for RGB) or .png
    /// (grey: windowed, see --bits, --window/--level, --percentiles and
    /// --colormap; RGB: 8-bit, one percentile window over all channels).
    #[arg(long, required_unless_present = "scene")]
    pub(crate) out: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) png: PngArgs,
    /// Print timing, memory and filter details.
    #[arg(long)]
    pub(crate) stats: bool,
    /// Resample to cubic voxels with N samples along the longest physical
    /// side (trilinear) before rendering. X-ray views of anisotropic data
    /// such as CT (0.957 x 0.957 x 1.5 mm) are exact without it; depth cues
    /// and lights need it.
    #[arg(long, value_name = "N")]
    pub(crate) resample: Option<usize>,
    /// Print the statistics as one JSON object instead (implies --stats).
    #[arg(long)]
    pub(crate) stats_json: bool,
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
    /// Progressive preview level: 0 full resolution; L renders the image at
    /// 1/2^L of the size from the central 1/4^L of the slice (4^L times fewer
    /// interpolations). Plain X-ray views only. (`--level` is the PNG
    /// window level, as in radiology viewers.)
    #[arg(long, value_name = "L", default_value_t = 0)]
    pub(crate) preview_level: u32,
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
        args.resample,
        if scene.needs_gradient_spectrum() {
            2
        } else {
            1
        },
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
        preview_level: args.preview_level,
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
    if let Some(profile) = args.depth_cue.strip_prefix("profile:@") {
        others.push(Path::new(profile));
    }
    check_output(out, &["png", "nrrd"], volume_spec, &others)?;
    let view = args.view()?;
    crate::checks::check_resample_count(args.resample)?;
    crate::checks::check_direction("--dir (camera.dir in a scene)", view.dir)?;
    crate::checks::check_direction("--up (camera.up in a scene)", view.up)?;
    for light in &args.lights {
        crate::checks::check_direction("--light (a scene light's direction)", light.towards)?;
    }
    view.frame()?;
    let style = args.png.style()?;
    let scene = build_scene(args)?;
    declare_job(args, &scene);
    let t0 = Instant::now();
    let mut volume = args.input.load(volume_spec)?;
    crate::checks::check_not_input(out)?;
    let mut _volume = fvr_host::budget::hold(volume.data.len() as u64 * 4);
    if let Some(largest) = args.resample {
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
    let (lowest, share) = negative_cue_share(&volume, &scene, &view)?;
    if share > NEGATIVE_CUE_WARNING_SHARE {
        eprintln!(
            "fvr: warning: the depth cue is given between t = -R and +R; extrapolated beyond, \
             into the volume's corners on this view, it falls to {}, and {:.2}% of the \
             weighted density counts negatively. Raise the smaller of FRONT and BACK to avoid it.",
            fvr_host::text::num3(lowest),
            100.0 * share
        );
    }
    let (w, h) = renderer.image_size(args.frame.size)?;
    let (image, view_report) = renderer.render_zoomed(&view, Some((w, h)), args.zoom.zoom)?;
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
    check_finite(
        &image.data,
        &crate::checks::overflow_cause(
            args.ambient.is_some(),
            !args.lights.is_empty() || args.light_ring.is_some(),
            args.depth_cue != "none",
        ),
    )?;
    if ext == "png" {
        if image.channels == 1 {
            write_png(out, w, h, &image.data, &style)?;
        } else {
            image.write_png(out)?;
        }
    } else {
        // The image's pixel pitch: the pixel size, over the zoom, times a
        // preview level's 2^L.
        let pitch = renderer.zoomed_sampling(args.zoom.zoom)?.pixel_size()
            * (1u64 << args.preview_level.min(62)) as f64;
        fvr_host::image::nrrd_image::write_image_nrrd(out, &image, Some(pitch))?;
    }
    let kind = if image.channels == 1 { "grey" } else { "RGB" };
    say!("wrote {} ({w}x{h} {kind})", out.display());
    let rendered = Rendered {
        args,
        volume_spec,
        volume,
        view,
        scene,
        sampling: renderer.zoomed_sampling(args.zoom.zoom)?,
        n: renderer.n(),
        filter: renderer.filter(),
        storage_snr: renderer.storage_snr_db(),
        t_plan: renderer.plan().time,
        t_prep: renderer.prepare_time(),
        spectra: renderer.spectra(),
        image,
        w,
        h,
        t_load,
        t_view,
        adaptive_report,
    };
    if args.stats && !args.stats_json {
        rendered.print_human()?;
    }
    if args.stats_json {
        rendered.print_json();
    }
    if args.exact {
        rendered.print_exact()?;
    }
    Ok(())
}

/// The scene from the command line: cue, ambient, lights.
pub(crate) fn build_scene(args: &RenderArgs) -> Result<Scene, Error> {
    let cue = parse_depth_cue(&args.depth_cue, args.cue_harmonics)?;
    let mut lights = args.lights.clone();
    if let Some((count, tilt)) = args.light_ring {
        lights.extend(light_ring(&args.view()?, count, tilt)?);
    }
    let default_ambient = if lights.is_empty() { 1.0 } else { 0.2 };
    let mut scene = Scene {
        cue,
        ambient: args.ambient.unwrap_or([default_ambient; 3]),
        correct_cue_shading: !args.no_cue_correction,
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

/// `fvr render --stats-json`, in the order printed.
#[derive(Serialize)]
struct RenderStats<'a> {
    volume: &'a str,
    dims: [usize; 3],
    spacing_mm: Box<RawValue>,
    pixel_size: f64,
    ignore_spacing: bool,
    image: [usize; 3],
    spectrum_side: usize,
    precision: &'a str,
    spectrum_bytes: usize,
    gradient_spectrum_bytes: Option<usize>,
    filter: &'a str,
    oversample: serde_json::Value,
    storage_snr_db: f64,
    load_ms: f64,
    plan_ms: f64,
    preprocess_ms: f64,
    view_ms: f64,
    preview_level: u32,
    accuracy: Option<crate::plan::AccuracyJson>,
    #[serde(skip_serializing_if = "Option::is_none")]
    adaptive: Option<AdaptiveJson>,
}

/// A finished render and what `--stats`, `--stats-json` and `--exact`
/// report of it.
struct Rendered<'a> {
    args: &'a RenderArgs,
    volume_spec: &'a str,
    volume: Volume,
    view: View,
    scene: Scene,
    sampling: Sampling,
    spectra: &'a SceneSpectra,
    filter: Filter,
    storage_snr: f64,
    image: Image,
    w: usize,
    h: usize,
    n: usize,
    t_load: Duration,
    t_plan: Duration,
    t_prep: Duration,
    t_view: Duration,
    adaptive_report: Option<AdaptiveReport<'a>>,
}

impl Rendered<'_> {
    /// `--stats`: sizes, memory, filter and timings, one per line.
    fn print_human(&self) -> Result<(), Error> {
        let &Rendered {
            args,
            volume_spec,
            ref volume,
            ref scene,
            ref sampling,
            spectra,
            filter,
            storage_snr,
            w,
            h,
            n,
            t_load,
            t_plan,
            t_prep,
            t_view,
            ref adaptive_report,
            ..
        } = self;
        let d = volume.dims;
        say!(
            "  volume        {}x{}x{} ({})",
            d[0],
            d[1],
            d[2],
            volume_spec
        );
        let [dx, dy, dz] = volume.spacing;
        say!(
            "  spacing       {dx} x {dy} x {dz} mm{}",
            if args.frame.units.ignore_spacing {
                " (ignored: --ignore-spacing, voxel units)"
            } else {
                ""
            }
        );
        say!(
            "  pixel size    {} {}",
            sampling.pixel_size(),
            if args.frame.units.ignore_spacing {
                "voxel"
            } else {
                "mm (values in mm x volume units)"
            }
        );
        say!(
            "  spectrum      {n}^3 {} = {} bytes ({} bytes/voxel)",
            args.frame.spectrum.precision,
            spectra.density.bytes(),
            args.frame.spectrum.precision.bytes()
        );
        match &spectra.gradient {
            Some(g) => say!(
                "  |grad f|      {} bytes (second spectrum, for the lights)",
                g.bytes()
            ),
            None => say!("  |grad f|      not built (no light needs it)"),
        }
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
        let f = spectra.density.filter();
        if f.kind().is_kaiser_bessel() {
            say!(
                "  filter        {} (oversample {}, beta {:.3})",
                f.kind().name(),
                args.frame.spectrum.oversample.name(),
                f.beta()
            );
        } else {
            say!(
                "  filter        {} (oversample {})",
                f.kind().name(),
                args.frame.spectrum.oversample.name()
            );
        }
        say!("  storage SNR   {storage_snr:.1} dB (estimate, against the f64 pipeline)");
        crate::plan::print_human(&args.frame.spectrum);
        say!("  load          {:.1} ms", t_load.as_secs_f64() * 1e3);
        say!("  plan          {:.1} ms", t_plan.as_secs_f64() * 1e3);
        say!("  preprocess    {:.1} ms", t_prep.as_secs_f64() * 1e3);
        say!("  view          {:.2} ms", t_view.as_secs_f64() * 1e3);
        if args.preview_level > 0 {
            say!(
                "  level         {} ({w}x{h} at pitch {} {}, central 1/{} of the slice)",
                args.preview_level,
                (1u64 << args.preview_level) as f64 * sampling.pixel_size(),
                if *sampling == Sampling::UNIT {
                    "voxels"
                } else {
                    "mm"
                },
                1u64 << (2 * args.preview_level)
            );
        }
        if let Some(r) = &adaptive_report {
            r.print_human();
        }
        Ok(())
    }

    /// `--stats-json`: the same as one JSON object.
    fn print_json(&self) {
        let &Rendered {
            args,
            volume_spec,
            ref volume,
            ref sampling,
            spectra,
            filter,
            storage_snr,
            ref image,
            w,
            h,
            n,
            t_load,
            t_plan,
            t_prep,
            t_view,
            ref adaptive_report,
            ..
        } = self;
        let stats = RenderStats {
            volume: volume_spec,
            dims: volume.dims,
            spacing_mm: debug_triple(volume.spacing),
            pixel_size: sampling.pixel_size(),
            ignore_spacing: args.frame.units.ignore_spacing,
            image: [w, h, image.channels],
            spectrum_side: n,
            precision: args.frame.spectrum.precision.name(),
            spectrum_bytes: spectra.density.bytes(),
            gradient_spectrum_bytes: spectra.gradient.as_ref().map(|g| g.bytes()),
            filter: filter.kind().name(),
            oversample: crate::plan::oversample_json(args.frame.spectrum.oversample),
            storage_snr_db: storage_snr,
            load_ms: t_load.as_secs_f64() * 1e3,
            plan_ms: t_plan.as_secs_f64() * 1e3,
            preprocess_ms: t_prep.as_secs_f64() * 1e3,
            view_ms: t_view.as_secs_f64() * 1e3,
            preview_level: args.preview_level,
            accuracy: crate::plan::json(&args.frame.spectrum),
            adaptive: adaptive_report.as_ref().map(AdaptiveReport::json),
        };
        say!("{}", one_line(&stats));
    }

    /// `--exact`: the SNR against the phantom's exact image, where there is one.
    fn print_exact(&self) -> Result<(), Error> {
        let &Rendered {
            volume_spec,
            ref volume,
            ref view,
            ref scene,
            ref sampling,
            ref image,
            w,
            h,
            ..
        } = self;
        let plain = scene.channels() == 1 && !scene.has_partner_terms();
        match phantom_by_name(volume_spec) {
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
                say!("  SNR vs exact  {:.2} dB", snr_db(&exact, &image.data));
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
                    say!("  SNR vs exact  {:.2} dB", snr_db(&exact.data, &image.data));
                }
                None => {
                    say!("  SNR vs exact  n/a (cued or shaded references exist for gaussians only)")
                }
            },
            _ => say!("  SNR vs exact  n/a (not a built-in phantom)"),
        }
        Ok(())
    }
}
