//! `fvr project`: many views of one volume from one preparation, written as
//! one float32 stack (NRRD or `.npy`), for projection sets (digitally
//! reconstructed radiographs, training data, registration).

use crate::taper::TaperArgs;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use fvr_engine::render::view::WalkCounts;
use fvr_engine::{PipelineError, Plan, Settings};
use fvr_host::io::stack::{write_stack, StackFormat, StackShape};
use fvr_host::progress;
use serde::Serialize;

use crate::args::{parse_vec3, prepare_with_progress, volume_help, FrameArgs, InputArgs};
use crate::views::{random_views, read_views, views_csv, MAX_VIEWS};
use crate::Error;

#[derive(Args, Clone)]
pub(crate) struct ProjectArgs {
    /// A volume file, a raw file with --raw-dims, a data set, or a built-in phantom.
    #[arg(help = volume_help())]
    pub(crate) volume: String,
    /// The views, from a file: CSV, one view a line, `dx,dy,dz` or
    /// `dx,dy,dz,ux,uy,uz` (`#` comments and a header line allowed), or JSON,
    /// a list of `[dx,dy,dz]` or `{"dir": [..], "up": [..]}`. Each view is
    /// what `fvr render --dir D --up U` renders.
    #[arg(
        long,
        value_name = "FILE",
        required_unless_present = "random",
        conflicts_with = "random"
    )]
    pub(crate) views: Option<PathBuf>,
    /// N views at uniformly random rotations (direction uniform on the
    /// sphere, roll uniform about it), drawn from --seed.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=MAX_VIEWS as i64))]
    pub(crate) random: Option<u32>,
    /// Seed of --random: the same seed gives the same views on every machine.
    #[arg(long, default_value_t = 1, requires = "random")]
    pub(crate) seed: u64,
    /// Up hint X,Y,Z of the views a --views file gives without one.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,1")]
    pub(crate) up: [f64; 3],
    #[command(flatten)]
    pub(crate) frame: FrameArgs,
    /// Output: .nrrd (float32, sizes W H B, kinds `space space list`, the
    /// pixel size as spacing) or .npy (float32, shape (B, H, W)).
    #[arg(long)]
    pub(crate) out: PathBuf,
    /// Also write the views used, one `dx,dy,dz,ux,uy,uz` line each (the CSV
    /// that --views reads back): the geometry of a --random set.
    #[arg(long, value_name = "FILE.csv")]
    pub(crate) save_views: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) report: crate::stats::StatsArgs,
    #[command(flatten)]
    pub(crate) taper: TaperArgs,
    #[command(flatten)]
    pub(crate) zoom: crate::zoom::ZoomArgs,
    #[command(flatten)]
    pub(crate) input: InputArgs,
}

/// Views rendered per call of the engine's batch: each call spreads its
/// views over every core, and the progress bar moves between calls.
const VIEWS_PER_CALL: usize = 32;

/// `fvr project --stats-json`: its members after the common ones.
#[derive(Serialize)]
struct ProjectExtra {
    /// Writing the stack (and the --save-views file).
    write_ms: f64,
    /// How many views each slice walk took (`column`, `exchanged`,
    /// `strip`, `reordered`, `exact`, `core`; walks that took none are
    /// left out, and scenes, previews and adaptive views count none).
    walks: BTreeMap<&'static str, usize>,
}

/// What the job holds beside the spectrum: the stack, and per-thread view
/// buffers ([`crate::args::plan_job`]); with --zoom, the stack magnified
/// and one view's zero-padded grid and its transposed copy at f64.
fn declare_job(args: &ProjectArgs, count: usize) {
    let size = args.frame.size;
    let threads = rayon::current_num_threads() as u64;
    let zoom = args.zoom.zoom as u64;
    crate::args::plan_job(
        &args.frame.spectrum,
        None,
        1,
        ("stack and view buffers", move |n, side| {
            let (w, h) = crate::args::planned_image(size, n, side);
            let stack = w
                .saturating_mul(h)
                .saturating_mul(4)
                .saturating_mul(count as u64)
                .saturating_mul(zoom * zoom);
            // Each thread's view grids, as a turntable's.
            let grids = crate::args::view_grid_bytes(n).saturating_mul(threads);
            let m = n.saturating_mul(zoom);
            let zoomed = match zoom {
                1 => 0,
                _ => m.saturating_mul(m).saturating_mul(16),
            };
            stack.saturating_add(grids).saturating_add(zoomed)
        }),
        "use fewer views, a smaller --size or --zoom, --precision f16 or --oversample 1",
    );
}

pub(crate) fn project(args: &ProjectArgs) -> Result<(), Error> {
    let format = StackFormat::of(&args.out)
        .ok_or_else(|| format!("output `{}` must end in .nrrd or .npy", args.out.display()))?;
    let others: Vec<&Path> = args.views.iter().map(PathBuf::as_path).collect();
    crate::checks::check_output(&args.out, &["nrrd", "npy"], &args.volume, &others)?;
    if let Some(csv) = &args.save_views {
        crate::checks::check_output(csv, &["csv"], &args.volume, &others)?;
        if csv == &args.out {
            return Err("--save-views and --out name the same file".into());
        }
    }
    crate::checks::check_direction("--up", args.up)?;
    args.taper.check()?;
    let views = match (&args.views, args.random) {
        (Some(file), _) => read_views(file, args.up)?,
        (None, Some(n)) => random_views(n as usize, args.seed),
        (None, None) => return Err("give --views FILE or --random N".into()),
    };
    for (i, v) in views.iter().enumerate() {
        crate::checks::check_direction(&format!("view {i}: the direction"), v.dir)?;
        crate::checks::check_direction(&format!("view {i}: the up vector"), v.up)?;
        v.frame()
            .map_err(|e| format!("view {i} ({:?} up {:?}): {e}", v.dir, v.up))?;
    }
    declare_job(args, views.len());
    let t0 = Instant::now();
    let mut volume = args.input.load(&args.volume)?;
    crate::checks::check_not_input(&args.out)?;
    if let Some(csv) = &args.save_views {
        crate::checks::check_not_input(csv)?;
    }
    let _volume = fvr_host::budget::hold(volume.data.len() as u64 * 4);
    let taper = args.taper.apply(&mut volume)?;
    fvr_host::budget::check_plan(volume.dims)?;
    let t_load = t0.elapsed();
    let settings = Settings {
        units: args.frame.units.units(),
        ..crate::plan::settings(&args.frame.spectrum)
    };
    settings.check()?;
    let plan = Plan::choose(&volume, &settings)?;
    let mut planned = args.clone();
    crate::plan::apply(&mut planned.frame.spectrum, &plan);
    let args = &planned;
    declare_job(args, views.len());
    fvr_host::budget::check_plan(volume.dims)?;
    let renderer = prepare_with_progress(&volume, settings, plan)?;
    for w in renderer.warnings() {
        eprintln!("fvr: warning: {w}");
    }
    let size = args.frame.size;
    let zoom = args.zoom.zoom;
    let mut shape = renderer.batch_shape(views.len(), size)?;
    (shape.width, shape.height) = (shape.width * zoom, shape.height * zoom);
    let mut stack = vec![0.0f32; shape.len()];
    let bar = progress::count(views.len() as u64, "views");
    let t_views = Instant::now();
    let frame = shape.frame_len();
    let mut walks = WalkCounts::default();
    // The engine refuses a frame that overflows f32; the message here
    // numbers the view in the whole job and names the options.
    let overflow = |view: usize, value: f32| {
        Error::from(format!(
            "view {view} has non-finite pixels once stored as f32 (the first is {value}): {}",
            crate::checks::overflow_cause(false, false, false)
        ))
    };
    if zoom > 1 {
        // One magnified view at a time, each on every core: the engine's
        // zoomed render, frame by frame.
        let plain = Some(renderer.image_size(size)?);
        for (k, (view, out)) in views.iter().zip(stack.chunks_mut(frame)).enumerate() {
            let (image, _) = renderer
                .render_zoomed(view, plain, zoom)
                .map_err(|e| match e {
                    PipelineError::Overflow { value, .. } => overflow(k, value),
                    other => other.into(),
                })?;
            for (o, v) in out.iter_mut().zip(&image.data) {
                *o = *v as f32;
            }
            bar.inc(1);
        }
    } else {
        for (k, (chunk, out)) in views
            .chunks(VIEWS_PER_CALL)
            .zip(stack.chunks_mut(VIEWS_PER_CALL * frame))
            .enumerate()
        {
            let report = renderer
                .render_batch_into(chunk, size, out)
                .map_err(|e| match e {
                    PipelineError::Overflow { view, value, .. } => {
                        overflow(k * VIEWS_PER_CALL + view, value)
                    }
                    other => other.into(),
                })?;
            walks = walks.merged(report.walks);
            bar.inc(chunk.len() as u64);
        }
    }
    bar.finish_and_clear();
    let t_views = t_views.elapsed();
    let t_write = Instant::now();
    let pixel_size = renderer.zoomed_sampling(zoom)?.pixel_size();
    let stack_shape = StackShape {
        views: shape.views,
        channels: shape.channels,
        width: shape.width,
        height: shape.height,
    };
    write_stack(&args.out, format, stack_shape, pixel_size, &stack)?;
    if let Some(csv) = &args.save_views {
        fvr_host::io::atomic::write_text(csv, &views_csv(&views))?;
    }
    let t_write = t_write.elapsed();
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let (w, h, c) = (shape.width, shape.height, shape.channels);
    if !args.report.stats_json {
        say!(
            "wrote {} ({} views of {w}x{h} {})",
            args.out.display(),
            views.len(),
            crate::stats::kind(c)
        );
    }
    let job = crate::stats::Job {
        command: "project",
        volume_spec: &args.volume,
        volume: &volume,
        renderer: &renderer,
        frame: &args.frame,
        image: [w, h, c],
        load: t_load,
        views: views.len(),
        views_time: t_views,
        output: &args.out,
        zoom,
        taper,
    };
    if args.report.stats_json {
        job.print_json(&ProjectExtra {
            write_ms: ms(t_write),
            walks: walks.taken().map(|(w, c)| (w.name(), c)).collect(),
        });
    } else if args.report.stats {
        job.print_human();
        let taken: Vec<String> = walks
            .taken()
            .map(|(w, c)| format!("{} {c}", w.name()))
            .collect();
        if !taken.is_empty() {
            say!("  walks         {}", taken.join(", "));
        }
        say!("  write         {:.1} ms", ms(t_write));
    }
    Ok(())
}
