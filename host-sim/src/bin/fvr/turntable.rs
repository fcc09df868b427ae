//! `fvr turntable`: an APNG of X-ray views on a full turn.

use crate::args::{parse_vec3, prepare_with_progress, volume_help, FrameArgs, InputArgs, PngArgs};
use crate::json::one_line;
use crate::Error;

use crate::scene::SCENE_HELP;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use fvr_host::image::output::write_apng;
use fvr_host::progress;
use fvr_host::render::turntable;

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

pub(crate) fn turntable(args: &TurntableArgs) -> Result<(), Error> {
    let views = turntable::orbit(args.dir, args.up, args.frames as usize)?;
    let style = args.png.style()?;
    let t0 = Instant::now();
    let volume_spec = args.volume.as_deref().ok_or_else(|| {
        "no volume: give VOLUME, or `volume.path` or `volume.builtin` in the scene".to_string()
    })?;
    crate::render::check_output(&args.out, &["apng", "png"], volume_spec)?;
    let volume = args.input.load(volume_spec)?;
    let t_load = t0.elapsed();
    let args = &crate::plan::planned(args, &volume)?;
    let t1 = Instant::now();
    let spec = prepare_with_progress(
        &volume,
        args.frame.spectrum.filter,
        args.frame.spectrum.oversample,
        args.frame.spectrum.kb_design,
        args.frame.spectrum.precision,
    )?;
    let t_prep = t1.elapsed();
    let n = spec.n();
    let side = n / args.frame.spectrum.oversample as usize;
    let (w, h) = args.frame.size.unwrap_or((side, side));
    fvr_core::image::check_image(w, h, n)?;
    let mut budget = fvr_host::budget::Budget::new();
    budget.hold("frames", views.len() as u64, (w * h * 8) as u64);
    budget.check(
        fvr_host::budget::limit(),
        "use fewer --frames or a smaller --size",
    )?;
    let sampling = args.frame.units.sampling(&volume, n, side)?;
    let bar = progress::count(views.len() as u64, "frames");
    let t2 = Instant::now();
    let frames = turntable::render_views(&spec, &views, &sampling, w, h, &bar);
    let t_views = t2.elapsed();
    bar.finish_and_clear();
    let frames = frames?;
    for frame in &frames {
        crate::render::check_finite(frame)?;
    }
    write_apng(&args.out, w, h, &frames, args.fps, &style)?;
    let secs = t_views.as_secs_f64();
    println!(
        "wrote {} ({} frames, {w}x{h}, {} fps)",
        args.out.display(),
        frames.len(),
        args.fps
    );
    let views_per_second = frames.len() as f64 / secs.max(1e-9);
    if args.stats_json {
        let stats = TurntableStats {
            volume: volume_spec,
            dims: volume.dims,
            image: [w, h],
            frames: frames.len(),
            fps: args.fps,
            spectrum_side: n,
            precision: args.frame.spectrum.precision.name(),
            spectrum_bytes: spec.bytes(),
            filter: args.frame.spectrum.filter.name(),
            oversample: args.frame.spectrum.oversample,
            load_ms: t_load.as_secs_f64() * 1e3,
            preprocess_ms: t_prep.as_secs_f64() * 1e3,
            views_ms: secs * 1e3,
            ms_per_view: secs * 1e3 / frames.len().max(1) as f64,
            views_per_second,
            accuracy: crate::plan::json(&args.frame.spectrum),
        };
        println!("{}", one_line(&stats));
    } else {
        println!(
            "  load {:.1} ms, preprocess {:.1} ms ({n}^3 {}), {} views in {:.1} ms = {:.1} views/s",
            t_load.as_secs_f64() * 1e3,
            t_prep.as_secs_f64() * 1e3,
            args.frame.spectrum.precision,
            frames.len(),
            secs * 1e3,
            views_per_second
        );
        crate::plan::print_human(&args.frame.spectrum);
    }
    Ok(())
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
    filter: &'a str,
    oversample: u32,
    load_ms: f64,
    preprocess_ms: f64,
    views_ms: f64,
    ms_per_view: f64,
    views_per_second: f64,
    accuracy: Option<crate::plan::AccuracyJson>,
}
