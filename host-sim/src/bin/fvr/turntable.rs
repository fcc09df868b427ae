//! `fvr turntable`: an APNG of views on a full turn, X-ray, depth-cued or
//! shaded, each frame the view `fvr render` makes with the same options.

use crate::args::{parse_vec3, prepare_with_progress, volume_help, FrameArgs, InputArgs, PngArgs};
use crate::look::LookArgs;
use crate::stats::Job;
use crate::Error;

use crate::scene::SCENE_HELP;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use fvr_core::geometry::View;
use fvr_core::shading::Scene;
use fvr_engine::render::turntable;
use fvr_engine::{Plan, Renderer, Settings};
use fvr_host::image::output::{ApngStream, Bits, Colormap, Window};
use fvr_host::progress;
use indicatif::ProgressBar;
use std::time::Duration;

#[derive(Args, Clone)]
pub(crate) struct TurntableArgs {
    /// A volume file, a raw file with --raw-dims, a data set, or a built-in phantom.
    #[arg(help = volume_help(), required_unless_present = "scene")]
    pub(crate) volume: Option<String>,
    /// Scene file (TOML): its volume, camera, spectrum, shading, lights,
    /// output window and [turntable] settings; flags given on the command
    /// line override them.
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
    #[command(flatten)]
    pub(crate) look: LookArgs,
    #[command(flatten)]
    pub(crate) zoom: crate::zoom::ZoomArgs,
    /// Output file: .apng or .png (an animated PNG either way; RGB, 8-bit,
    /// for coloured lights).
    #[arg(long, default_value = "spin.apng")]
    pub(crate) out: PathBuf,
    #[command(flatten)]
    pub(crate) report: crate::stats::StatsArgs,
    #[command(flatten)]
    pub(crate) png: PngArgs,
    #[command(flatten)]
    pub(crate) input: InputArgs,
}

/// Frames are kept for an exact percentile window up to this many bytes;
/// beyond, the window comes from [`SAMPLE_FRAMES`] evenly spaced frames
/// rendered first, and every frame is encoded as soon as it is rendered.
const HOLD_FRAMES_BYTES: u64 = 256 << 20;

/// Frames rendered first to set the window of a streamed animation (and
/// of a depth-cued one, from the uncued views).
const SAMPLE_FRAMES: usize = 16;

/// What a turntable of `frames` frames builds from its volume
/// ([`crate::args::plan_job`]).
fn declare_job(args: &TurntableArgs, scene: &Scene, frames: usize) {
    let size = args.frame.size;
    let channels = scene.channels() as u64;
    let zoom = args.zoom.zoom as u64;
    crate::args::plan_job(
        &args.frame.spectrum,
        args.look.resample,
        crate::args::spectra(scene),
        ("frames and view buffers", move |n, side| {
            let (w, h) = crate::args::planned_image(size, n, side);
            let frame = w
                .saturating_mul(h)
                .saturating_mul(8 * channels)
                .saturating_mul(zoom * zoom);
            let all = frame.saturating_mul(frames as u64);
            // With --zoom, the padded grid and its transposed copy at f64.
            let m = n.saturating_mul(zoom);
            let zoomed = if zoom > 1 {
                m.saturating_mul(m).saturating_mul(16)
            } else {
                0
            };
            // One view's grids and the frames kept.
            let grids = crate::args::view_grid_bytes(n).saturating_add(zoomed);
            grids.saturating_add(if all <= HOLD_FRAMES_BYTES {
                all
            } else {
                frame.saturating_mul(SAMPLE_FRAMES as u64 + 1)
            })
        }),
        "use fewer --frames, a smaller --size, --zoom or --resample, --precision f16 or --oversample 1",
    );
}

/// `fvr turntable --stats-json`: its members after the common ones.
#[derive(Serialize)]
struct TurntableExtra {
    frames: usize,
    fps: u16,
    /// The spectrum's copy with x and y exchanged, for strip rows along y
    /// (0 when no frame took it).
    exchanged_bytes: usize,
    views_per_second: f64,
    /// The PNG window `[low, high]` all frames share.
    window: [f64; 2],
}

pub(crate) fn turntable(args: &TurntableArgs) -> Result<(), Error> {
    crate::checks::check_direction("--dir (camera.dir in a scene)", args.dir)?;
    crate::checks::check_direction("--up (camera.up in a scene)", args.up)?;
    args.look.check()?;
    let views = turntable::orbit(args.dir, args.up, args.frames as usize)?;
    if args.png.display != fvr_host::image::film::Display::Linear {
        return Err(
            "--display film is for fvr render: a turntable shows the line integrals linearly"
                .into(),
        );
    }
    let style = args.png.style()?;
    let volume_spec = args.volume.as_deref().ok_or_else(|| {
        "no volume: give VOLUME, or `volume.path` or `volume.builtin` in the scene".to_string()
    })?;
    let mut others: Vec<&Path> = args.scene.iter().map(|p| p.as_path()).collect();
    if let Some(profile) = args.look.depth_cue.strip_prefix("profile:@") {
        others.push(Path::new(profile));
    }
    crate::checks::check_output(&args.out, &["apng", "png"], volume_spec, &others)?;
    let scene = args.look.scene(&views[0])?;
    if args.zoom.zoom > 1 && (scene != Scene::xray() || args.look.preview_level > 0) {
        return Err(format!(
            "--zoom {} magnifies plain X-ray turntables: leave out --zoom, or the lights, \
             depth cue, --ambient and --preview-level",
            args.zoom.zoom
        )
        .into());
    }
    if scene.channels() > 1 && (args.png.colormap != Colormap::Gray || args.png.bits != Bits::Eight)
    {
        return Err(
            "--colormap and --bits 16 apply to grey frames; coloured lights make RGB frames \
             (8-bit): leave them out, or give grey light colours"
                .into(),
        );
    }
    declare_job(args, &scene, views.len());
    let t0 = Instant::now();
    let mut volume = args.input.load(volume_spec)?;
    crate::checks::check_not_input(&args.out)?;
    let mut _volume = fvr_host::budget::hold(volume.data.len() as u64 * 4);
    let taper = args.look.taper.apply(&mut volume)?;
    if let Some(largest) = args.look.resample {
        crate::checks::check_resample(&volume, largest)?;
        volume = volume.resample_isotropic(largest)?;
        _volume = fvr_host::budget::hold(volume.data.len() as u64 * 4);
    }
    fvr_host::budget::check_plan(volume.dims)?;
    let t_load = t0.elapsed();
    let settings = Settings {
        scene: scene.clone(),
        preview_level: args.look.preview_level,
        units: args.frame.units.units(),
        ..crate::plan::settings(&args.frame.spectrum)
    };
    settings.check()?;
    let plan = Plan::choose(&volume, &settings)?;
    let mut planned = args.clone();
    crate::plan::apply(&mut planned.frame.spectrum, &plan);
    let args = &planned;
    // The planner may have changed the spectrum's settings.
    declare_job(args, &scene, views.len());
    fvr_host::budget::check_plan(volume.dims)?;
    let renderer = prepare_with_progress(&volume, settings, plan)?;
    for w in renderer.warnings() {
        eprintln!("fvr: warning: {w}");
    }
    crate::look::warn_negative_cue(&volume, &scene, &views[0])?;
    let size = renderer.image_size(args.frame.size)?;
    let zoom = args.zoom.zoom;
    let (w, h) = match args.look.preview_level {
        0 => (size.0 * zoom, size.1 * zoom),
        level => fvr_core::render::preview_size(size.0, size.1, level),
    };
    let source = Source {
        renderer: &renderer,
        scene: &scene,
        size,
        zoom,
        image: (w, h),
        cause: args.look.overflow_cause(),
    };
    let channels = scene.channels();
    let frame_bytes = (w * h * channels * 8) as u64;
    let all_bytes = (views.len() as u64).saturating_mul(frame_bytes);
    let cue_gain = crate::look::cue_gain(&scene.cue)?;
    let picks = match style.window {
        Window::Range(..) => 0,
        _ if cue_gain.is_some() || all_bytes > HOLD_FRAMES_BYTES => SAMPLE_FRAMES.min(views.len()),
        _ => 0,
    };
    let bar = progress::count((views.len() + picks) as u64, "frames");
    let t2 = Instant::now();
    let result = write_frames(&source, &views, &bar, args, picks, cue_gain, channels);
    bar.finish_and_clear();
    let (encode, range) = result?;
    let t_views = t2.elapsed().saturating_sub(encode);
    let frames = views.len();
    let kind = crate::stats::kind(channels);
    if !args.report.stats_json {
        say!(
            "wrote {} ({frames} frame{}, {w}x{h} {kind}, {} fps)",
            args.out.display(),
            if frames == 1 { "" } else { "s" },
            args.fps
        );
    }
    let job = Job {
        command: "turntable",
        volume_spec,
        volume: &volume,
        renderer: &renderer,
        frame: &args.frame,
        image: [w, h, channels],
        load: t_load,
        views: frames,
        views_time: t_views,
        output: &args.out,
        zoom,
        taper,
    };
    let views_per_second = frames as f64 / t_views.as_secs_f64().max(1e-9);
    if args.report.stats_json {
        job.print_json(&TurntableExtra {
            frames,
            fps: args.fps,
            exchanged_bytes: renderer.spectra().density.exchanged_bytes(),
            views_per_second,
            window: [range.0, range.1],
        });
    } else if args.report.stats {
        job.print_human();
        say!("  rate          {views_per_second:.1} views/s");
        say!(
            "  window        {} to {}{}",
            range.0,
            range.1,
            match cue_gain {
                Some(g) if !matches!(style.window, Window::Range(..)) =>
                    format!(" (the uncued views' window times {g}, the cue's largest weight)"),
                _ => String::new(),
            }
        );
    }
    Ok(())
}

/// Where the frames come from: the prepared renderer and its scene.
struct Source<'a> {
    renderer: &'a Renderer,
    scene: &'a Scene,
    /// The image size asked for (before a preview level shrinks it or a
    /// zoom magnifies it).
    size: (usize, usize),
    /// `--zoom`: each side magnified this many times (plain X-ray views).
    zoom: usize,
    /// The frames' size.
    image: (usize, usize),
    /// What to blame for non-finite pixels.
    cause: String,
}

impl Source<'_> {
    /// Render `views` in `scene`, handing each frame to `each`. A plain
    /// X-ray turntable reuses one set of view buffers for every frame.
    fn each(
        &self,
        views: &[View],
        scene: &Scene,
        bar: &ProgressBar,
        mut each: impl FnMut(&[f64]) -> Result<(), Error>,
    ) -> Result<(), Error> {
        let r = self.renderer;
        let check = |frame: &[f64]| crate::checks::check_finite(frame, &self.cause);
        if *scene == Scene::xray() && r.settings().preview_level == 0 {
            let spec = &r.spectra().density;
            return turntable::render_each(
                spec,
                views,
                r.sampling(),
                self.size,
                self.zoom,
                &|| bar.inc(1),
                |_, frame| {
                    check(frame)?;
                    each(frame)
                },
            );
        }
        for view in views {
            let data = if scene == self.scene {
                r.render(view, Some(self.size))?.0.data
            } else {
                let (w, h) = self.size;
                r.spectra()
                    .render_sampled(scene, view, r.sampling(), w, h)?
                    .data
            };
            check(&data)?;
            each(&data)?;
            bar.inc(1);
        }
        Ok(())
    }
}

/// Render the views and write the animation, every frame through one
/// window: the one given; for a depth cue, the percentile window of
/// `picks` evenly spaced uncued views times the cue's largest weight
/// (`cue_gain`), so that near content stays brighter than far content;
/// else the percentile window of `picks` evenly spaced frames rendered
/// first, or with no picks, of all frames (kept until the window is
/// known). Returns the time spent encoding and the window.
fn write_frames(
    source: &Source<'_>,
    views: &[View],
    bar: &ProgressBar,
    args: &TurntableArgs,
    picks: usize,
    cue_gain: Option<f64>,
    channels: usize,
) -> Result<(Duration, (f64, f64)), Error> {
    let style = args.png.style()?;
    let mut kept: Vec<f64> = Vec::new();
    let range = match style.window {
        Window::Range(lo, hi) => Some((lo, hi)),
        Window::Percentiles(..) if picks > 0 => {
            let chosen: Vec<View> = (0..picks).map(|i| views[i * views.len() / picks]).collect();
            let sample_scene = match cue_gain {
                Some(_) => crate::look::uncued(source.scene),
                None => source.scene.clone(),
            };
            let mut pixels = Vec::new();
            source.each(&chosen, &sample_scene, bar, |f| {
                pixels.extend_from_slice(f);
                Ok(())
            })?;
            let (lo, hi) = style.window.resolve(&pixels);
            let g = cue_gain.unwrap_or(1.0);
            Some((lo * g, hi * g))
        }
        Window::Percentiles(..) => {
            source.each(views, source.scene, bar, |f| {
                kept.extend_from_slice(f);
                Ok(())
            })?;
            None
        }
    };
    // The window over every kept frame is output work, timed with the
    // encoding (not as views' time, which `ms_per_view` reports).
    let t = Instant::now();
    let range = range.unwrap_or_else(|| style.window.resolve(&kept));
    let window_time = t.elapsed();
    let (w, h) = source.image;
    let create = || -> Result<ApngStream, String> {
        let rgb = channels != 1;
        ApngStream::create(&args.out, (w, h), views.len(), args.fps, &style, range, rgb)
    };
    let mut encode = window_time;
    if !kept.is_empty() {
        let t = Instant::now();
        let mut stream = create()?;
        for frame in kept.chunks(w * h * channels) {
            stream.push(frame)?;
        }
        stream.finish()?;
        return Ok((window_time + t.elapsed(), range));
    }
    let mut stream = create()?;
    source.each(views, source.scene, bar, |frame| {
        let t = Instant::now();
        stream.push(frame)?;
        encode += t.elapsed();
        Ok(())
    })?;
    let t = Instant::now();
    stream.finish()?;
    Ok((encode + t.elapsed(), range))
}
