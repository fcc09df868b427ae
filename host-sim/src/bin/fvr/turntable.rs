//! `fvr turntable`: an APNG of X-ray views on a full turn.

use crate::args::{parse_vec3, prepare_with_progress, volume_help, FrameArgs, InputArgs, PngArgs};
use crate::json::one_line;
use crate::Error;

use crate::scene::SCENE_HELP;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use fvr_core::geometry::{Sampling, View};
use fvr_engine::render::turntable;
use fvr_engine::spectrum::AnySpectrum;
use fvr_engine::{Plan, Settings};
use fvr_host::image::output::{write_apng, ApngStream, Window};
use fvr_host::progress;
use indicatif::ProgressBar;
use std::time::Duration;

#[derive(Args, Clone)]
pub(crate) struct TurntableArgs {
    /// A volume file, a raw file with --raw-dims, a data set, or a built-in phantom.
    #[arg(help = volume_help(), required_unless_present = "scene")]
    pub(crate) volume: Option<String>,
    /// Scene file (TOML): its volume, camera, spectrum, output window and
    /// [turntable] settings; flags given on the command line override them.
    #[arg(long, value_name = "FILE.toml", long_help = SCENE_HELP)]
    pub(crate) scene: Option<PathBuf>,
    /// Number of frames in the turn.
    #[arg(long, default_value_t = 72, value_parser = clap::value_parser!(u32).range(1..=3600))]
    pub(crate) frames: u32,
    /// Frames per second of the animation.
    #[arg(long, default_value_t = 24, value_parser = clap::value_parser!(u16).range(1..=1000))]
    pub(crate) fps: u16,
    /// View direction X,Y,Z of the first frame; later frames turn it about --up.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,-1,0")]
    pub(crate) dir: [f64; 3],
    /// Turntable axis and up hint X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,1")]
    pub(crate) up: [f64; 3],
    #[command(flatten)]
    pub(crate) frame: FrameArgs,
    /// Output file: .apng or .png (an animated PNG either way).
    #[arg(long, default_value = "spin.apng")]
    pub(crate) out: PathBuf,
    /// Print the timings (load, preprocess, views, views per second) as one
    /// JSON object instead of the summary line.
    #[arg(long)]
    pub(crate) stats_json: bool,
    #[command(flatten)]
    pub(crate) png: PngArgs,
    #[command(flatten)]
    pub(crate) input: InputArgs,
}

/// Frames are kept for an exact percentile window up to this many bytes;
/// beyond, the window comes from [`SAMPLE_FRAMES`] evenly spaced frames
/// rendered first, and every frame is encoded as soon as it is rendered.
const HOLD_FRAMES_BYTES: u64 = 256 << 20;

/// Frames rendered first to set the window of a streamed animation.
const SAMPLE_FRAMES: usize = 16;

/// What a turntable of `frames` frames builds from its volume
/// ([`crate::args::plan_job`]).
fn declare_job(args: &TurntableArgs, frames: usize) {
    let size = args.frame.size;
    crate::args::plan_job(
        &args.frame.spectrum,
        None,
        1,
        ("frames and view buffers", move |n, side| {
            // A size beyond the grid is refused later, by name.
            let (w, h) = size.map_or((side, side), |(w, h)| {
                ((w as u64).min(n), (h as u64).min(n))
            });
            let frame = w.saturating_mul(h).saturating_mul(8);
            let all = frame.saturating_mul(frames as u64);
            // Per-view grids at f64 (slice, the column walk's sums (2), a
            // mixed side's transposed grid, output) and the frames kept.
            let grids = n.saturating_mul(n).saturating_mul(40);
            grids.saturating_add(if all <= HOLD_FRAMES_BYTES {
                all
            } else {
                frame.saturating_mul(SAMPLE_FRAMES as u64 + 1)
            })
        }),
        "use fewer --frames, a smaller --size, --precision f16 or --oversample 1",
    );
}

pub(crate) fn turntable(args: &TurntableArgs) -> Result<(), Error> {
    crate::checks::check_direction("--dir (camera.dir in a scene)", args.dir)?;
    crate::checks::check_direction("--up (camera.up in a scene)", args.up)?;
    let views = turntable::orbit(args.dir, args.up, args.frames as usize)?;
    let style = args.png.style()?;
    let t0 = Instant::now();
    let volume_spec = args.volume.as_deref().ok_or_else(|| {
        "no volume: give VOLUME, or `volume.path` or `volume.builtin` in the scene".to_string()
    })?;
    let scene: Vec<&std::path::Path> = args.scene.iter().map(|p| p.as_path()).collect();
    crate::checks::check_output(&args.out, &["apng", "png"], volume_spec, &scene)?;
    declare_job(args, views.len());
    let volume = args.input.load(volume_spec)?;
    crate::checks::check_not_input(&args.out)?;
    let _volume = fvr_host::budget::hold(volume.data.len() as u64 * 4);
    fvr_host::budget::check_plan(volume.dims)?;
    let t_load = t0.elapsed();
    let settings = Settings {
        units: args.frame.units.units(),
        ..crate::plan::settings(&args.frame.spectrum)
    };
    let plan = Plan::choose(&volume, &settings)?;
    let t_plan = plan.time;
    let mut planned = args.clone();
    crate::plan::apply(&mut planned.frame.spectrum, &plan);
    let args = &planned;
    // The planner may have changed the spectrum's settings.
    declare_job(args, views.len());
    fvr_host::budget::check_plan(volume.dims)?;
    let renderer = prepare_with_progress(&volume, settings, plan)?;
    for w in renderer.warnings() {
        eprintln!("fvr: warning: {w}");
    }
    let t_prep = renderer.prepare_time();
    let spec = &renderer.spectra().density;
    let n = renderer.n();
    let (w, h) = renderer.image_size(args.frame.size)?;
    let sampling = *renderer.sampling();
    let all_bytes = (views.len() as u64).saturating_mul((w * h * 8) as u64);
    let sampled = !matches!(style.window, Window::Range(..)) && all_bytes > HOLD_FRAMES_BYTES;
    let extra = if sampled {
        SAMPLE_FRAMES.min(views.len())
    } else {
        0
    };
    let bar = progress::count((views.len() + extra) as u64, "frames");
    let t2 = Instant::now();
    let result = write_frames(spec, &views, &sampling, (w, h), &bar, args, sampled);
    bar.finish_and_clear();
    let encode = result?;
    let t_views = t2.elapsed().saturating_sub(encode);
    let frames = views.len();
    let secs = t_views.as_secs_f64();
    say!(
        "wrote {} ({} frames, {w}x{h}, {} fps)",
        args.out.display(),
        frames,
        args.fps
    );
    let views_per_second = frames as f64 / secs.max(1e-9);
    if args.stats_json {
        let stats = TurntableStats {
            volume: volume_spec,
            dims: volume.dims,
            image: [w, h],
            frames,
            fps: args.fps,
            spectrum_side: n,
            precision: args.frame.spectrum.precision.name(),
            spectrum_bytes: spec.bytes(),
            exchanged_bytes: spec.exchanged_bytes(),
            filter: args.frame.spectrum.filter.name(),
            oversample: crate::plan::oversample_json(args.frame.spectrum.oversample),
            load_ms: t_load.as_secs_f64() * 1e3,
            plan_ms: t_plan.as_secs_f64() * 1e3,
            preprocess_ms: t_prep.as_secs_f64() * 1e3,
            views_ms: secs * 1e3,
            ms_per_view: secs * 1e3 / frames.max(1) as f64,
            views_per_second,
            accuracy: crate::plan::json(&args.frame.spectrum),
        };
        say!("{}", one_line(&stats));
    } else {
        say!(
            "  load {:.1} ms, plan {:.1} ms, preprocess {:.1} ms ({n}^3 {}), {} views in {:.1} ms = {:.1} views/s",
            t_load.as_secs_f64() * 1e3,
            t_plan.as_secs_f64() * 1e3,
            t_prep.as_secs_f64() * 1e3,
            args.frame.spectrum.precision,
            frames,
            secs * 1e3,
            views_per_second
        );
        crate::plan::print_human(&args.frame.spectrum);
    }
    Ok(())
}

/// Render the views and write the animation. With a fixed window, or with
/// `sampled` (the window from evenly spaced frames rendered first), each
/// frame is encoded as it comes; otherwise all frames are kept for an exact
/// percentile window. Returns the time spent encoding.
fn write_frames(
    spec: &AnySpectrum,
    views: &[View],
    sampling: &Sampling,
    (w, h): (usize, usize),
    bar: &ProgressBar,
    args: &TurntableArgs,
    sampled: bool,
) -> Result<Duration, Error> {
    let style = &args.png.style()?;
    let range = match style.window {
        Window::Range(lo, hi) => Some((lo, hi)),
        Window::Percentiles(..) if sampled => {
            let k = SAMPLE_FRAMES.min(views.len());
            let picks: Vec<View> = (0..k).map(|i| views[i * views.len() / k]).collect();
            let frames = turntable::render_views(spec, &picks, sampling, w, h, &|| bar.inc(1))?;
            Some(style.window.resolve(&frames.concat()))
        }
        Window::Percentiles(..) => None,
    };
    let Some(range) = range else {
        let frames = turntable::render_views(spec, views, sampling, w, h, &|| bar.inc(1))?;
        for frame in &frames {
            crate::checks::check_finite(
                frame,
                &crate::checks::overflow_cause(false, false, false),
            )?;
        }
        let t = Instant::now();
        write_apng(&args.out, w, h, &frames, args.fps, style)?;
        return Ok(t.elapsed());
    };
    let mut stream = ApngStream::create(&args.out, (w, h), views.len(), args.fps, style, range)?;
    let mut encode = Duration::ZERO;
    turntable::render_each(spec, views, sampling, (w, h), &|| bar.inc(1), |_, frame| {
        crate::checks::check_finite(frame, &crate::checks::overflow_cause(false, false, false))?;
        let t = Instant::now();
        stream.push(frame)?;
        encode += t.elapsed();
        Ok::<(), Error>(())
    })?;
    let t = Instant::now();
    stream.finish()?;
    Ok(encode + t.elapsed())
}

/// `fvr turntable --stats-json`, in the order printed.
#[derive(Serialize)]
struct TurntableStats<'a> {
    volume: &'a str,
    dims: [usize; 3],
    image: [usize; 2],
    frames: usize,
    fps: u16,
    spectrum_side: usize,
    precision: &'a str,
    spectrum_bytes: usize,
    /// The spectrum's copy with x and y exchanged, for strip rows along y
    /// (0 when no frame took it).
    exchanged_bytes: usize,
    filter: &'a str,
    oversample: serde_json::Value,
    load_ms: f64,
    plan_ms: f64,
    preprocess_ms: f64,
    views_ms: f64,
    ms_per_view: f64,
    views_per_second: f64,
    accuracy: Option<crate::plan::AccuracyJson>,
}
