//! `fvr`: frequency-domain volume rendering from the command line.
//!
//! Built with `--cfg fuzzing` (by `cargo fuzz`, from `fuzz/`), the same
//! program is a libFuzzer target over arguments and scene files ([`fuzz`]).
#![cfg_attr(fuzzing, no_main)]

#[macro_use]
mod stdout;

mod accuracy;
mod adaptive_report;
mod adaptive_table;
mod anatomy;
mod args;
mod checks;
mod clap_error;
mod compare;
mod convert;
mod film;
#[cfg(fuzzing)]
mod fuzz;
mod growth;
mod http;
mod json;
mod look;
mod plan;
mod precision;
mod prepare;
mod prepared;
mod project;
mod render;
mod scene;
#[cfg(not(fuzzing))]
mod signals;
mod stats;
mod taper;
#[cfg(test)]
mod tests;
mod trade;
mod turntable;
mod view;
mod views;
mod zoom;

use crate::accuracy::accuracy;
use crate::adaptive_table::adaptive_table;
use crate::args::{FrameArgs, InputArgs, PngArgs};
use crate::compare::compare;
use crate::render::{render, RenderArgs};
use crate::scene::{apply_scene_to_render, given_on_command_line, merge_scene};
use crate::turntable::{turntable, TurntableArgs};

use std::path::Path;
use std::process::ExitCode;

/// Any error of a subcommand; `main` prints it as one line and exits 2.
pub(crate) type Error = Box<dyn std::error::Error>;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use fvr_core::geometry::DEFAULT_UP;
use fvr_host::image::output::{Bits, Colormap};
use fvr_host::progress;
use fvr_host::scene_file::SceneFile;

const GEOMETRY: &str = "\
GEOMETRY CONTRACT
  Voxel (i,j,k) sits at (i,j,k); i is the fastest axis in files.
  The rotation centre is c = (nx/2, ny/2, nz/2).
  --dir d points from the eye into the scene; --up u0 defaults to 0,0,1.
  right r = normalize(d x u0), up u = r x d.
  Pixel (col,row), row 0 at the top, of a W x H image sits at
  p = c + (col - W/2) r + (H/2 - row) u, and its value is the line integral
  of the band-limited interpolant of the voxels along p + t d, in voxel units.
  A zero d or u0, or u0 parallel to d, is an error.

PHYSICAL UNITS (fvr render, fvr turntable)
  By default fvr uses the volume's voxel spacing D (mm, from the
  file; 1,1,1 when it gives none) and a pixel size P (--pixel-size, mm):
  voxel (i,j,k) sits at (i Dx, j Dy, k Dz), the centre is C = (n/2) D, pixel
  (col,row) sits at C + (col - W/2) P r + (H/2 - row) P u with r, u, d unit
  vectors in mm, and its value is the line integral in mm (mm x volume
  units). This is exact in the frequency domain: the slice is taken at index
  frequencies k r_a D_a/P and scaled by Dx Dy Dz/P^2. --ignore-spacing gives
  the voxel-unit contract above. Depth cues and lights need cubic voxels
  imaged at their own size (--resample N makes them so).

EXIT STATUS
  0  success (also for --help and --version, and when standard output is a
     pipe closed early: the rest of the printed text is dropped)
  1  fvr compare --min-db DB: the SNR is below DB (one line on stderr)
  2  any error: bad arguments, unreadable or malformed input, a render that
     cannot be done; the reason is printed on stderr as `fvr: error: ...`
     (for argument errors too: the parser's message, tip and usage line).
  130  stopped by SIGINT, SIGTERM or SIGHUP: the output being written is
     removed and the previous file left as it was.

Progress bars go to stderr only when it is a terminal; --quiet turns them off.";

/// Frequency-domain volume rendering (Totsuka & Levoy 1993): X-ray
/// projections, depth cueing and shading from a 16-bit Hartley spectrum.
/// With no subcommand, renders the built-in default scene to
/// `fvr-default.png`: the Utah teapot lit by three coloured lights, as
/// `fvr render teapot@128 --dir 0.3,1,-0.45 --light-ring 3 --ambient 0.1
/// --out fvr-default.png --stats`.
#[derive(Parser)]
#[command(name = "fvr", version, after_help = GEOMETRY)]
pub(crate) struct Cli {
    /// No progress bars (they are shown only when stderr is a terminal
    /// anyway) and no notes on stderr.
    #[arg(long, global = true)]
    quiet: bool,
    /// The most memory a job may plan to hold (bytes, or with K, M or G).
    /// Default: the smallest of the address-space limit (ulimit -v), the
    /// cgroup's memory limit and MemAvailable.
    #[arg(long, global = true, value_name = "BYTES")]
    max_memory: Option<String>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Render the projection of a volume along a view direction.
    #[command(after_help = GEOMETRY)]
    Render(Box<RenderArgs>),
    /// Render a turntable animation (APNG): one preprocessing pass, then
    /// FRAMES views on a full turn about the up axis, X-ray, depth-cued or
    /// lit, with the view options of `render`.
    #[command(after_help = GEOMETRY)]
    Turntable(Box<TurntableArgs>),
    /// Render many X-ray views from one preprocessing pass into one float32
    /// stack (NRRD or .npy): views from a CSV or JSON file, or --random N
    /// rotations.
    Project(Box<crate::project::ProjectArgs>),
    /// Print the SNR in dB of image B against reference image A (NRRD files),
    /// or JSON with --json; --min-db DB exits 1 below DB (for CI).
    Compare(crate::compare::CompareArgs),
    /// Write a volume (after --background) as a float NRRD file with its
    /// voxel spacing, for tools that cannot read the original format.
    Convert(crate::convert::ConvertArgs),
    /// Measure accuracy against exact line integrals of the Gaussian-mixture
    /// phantom and print the Markdown table quoted in the README.
    Accuracy(crate::accuracy::AccuracyArgs),
    /// The precision study: SNR of every storage format and arithmetic
    /// against the f64 pipeline and exact line integrals, with bytes per
    /// voxel; writes a Markdown table, a CSV and a PNG plot.
    Precision(crate::precision::PrecisionArgs),
    /// The speed-accuracy map: time per view, SNR against exact line
    /// integrals and memory held over filter, oversampling, storage format,
    /// adaptive tolerance, progressive level and volume size, on the
    /// Gaussian-mixture phantom; writes trade.csv, trade.png (dB against ms,
    /// Pareto fronts) and trade.md (the settings on each front).
    Trade(crate::trade::TradeArgs),
    /// How the time per view grows with the volume's side: the kb3 f16
    /// frequency-domain view against the f32 ray caster (both on all cores),
    /// medians of RUNS views per size, the sizes timed in turn so that a
    /// change of load reaches them alike; writes growth.csv, growth.md and a
    /// log-log growth.png, and prints the Markdown (with the growth per
    /// doubling against the n² log n ratio).
    Growth(crate::growth::GrowthArgs),
    /// The paper's Table 1 measured here: filter taps and time per view with
    /// and without adaptive filtering, and the spatial-domain ray caster, on
    /// the CT head (resampled to 128 along its longest side), a 256³ volume
    /// and a phantom. Prints Markdown.
    AdaptiveTable(crate::adaptive_table::AdaptiveTableArgs),
    /// Serve the browser viewer (built by `bash scripts/web.sh`) and VOLUME
    /// on 127.0.0.1 at a free port; prints the address; Ctrl-C stops.
    View(crate::view::ViewArgs),
    /// Prepare a volume's spectrum once for a part (m4f, m3, m7 or host):
    /// a .fvrs image (docs/fvrs.md) checked against the part's flash and
    /// RAM before anything is written, as the file, a raw image for loading
    /// at run time, or a C .c/.h pair to link into flash.
    Prepare(crate::prepare::PrepareArgs),
}

#[cfg(not(fuzzing))]
fn main() -> ExitCode {
    signals::install();
    run(std::env::args_os())
}

/// Parse `args` (the program's name first) and run the command.
pub(crate) fn run<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let parsed = Cli::command()
        .try_get_matches_from(args)
        .and_then(|m| Cli::from_arg_matches(&m).map(|cli| (m, cli)));
    let (matches, cli) = match parsed {
        Ok(ok) => ok,
        Err(e) => return clap_error::exit(&e),
    };
    progress::set_quiet(cli.quiet);
    fvr_host::budget::install();
    if let Some(text) = &cli.max_memory {
        match fvr_host::budget::parse_bytes("--max-memory", text) {
            Ok(bytes) => fvr_host::budget::set_max_memory(bytes),
            Err(e) => {
                eprintln!("fvr: error: {e}");
                return ExitCode::from(2);
            }
        }
    }
    let given = |sub: &str, id: &str| {
        matches
            .subcommand_matches(sub)
            .is_some_and(|m| given_on_command_line(m, id))
    };
    let result = match cli.command {
        None => default_scene(),
        Some(Command::Render(mut args)) => {
            args.frame.spectrum.given = plan::Given::from_flags(&|id| given("render", id));
            merge_scene(&mut *args, &|id| given("render", id)).and_then(|()| render(&args))
        }
        Some(Command::Turntable(mut args)) => {
            args.frame.spectrum.given = plan::Given::from_flags(&|id| given("turntable", id));
            merge_scene(&mut *args, &|id| given("turntable", id)).and_then(|()| turntable(&args))
        }
        Some(Command::Project(mut args)) => {
            args.frame.spectrum.given = plan::Given::from_flags(&|id| given("project", id));
            crate::project::project(&args)
        }
        Some(Command::Compare(args)) => compare(&args),
        Some(Command::Convert(args)) => crate::convert::convert(&args),
        Some(Command::Accuracy(args)) => accuracy(&args),
        Some(Command::AdaptiveTable(args)) => adaptive_table(&args),
        Some(Command::Precision(args)) => crate::precision::run(&args),
        Some(Command::Prepare(args)) => crate::prepare::prepare(&args),
        Some(Command::Trade(args)) => crate::trade::run(&args),
        Some(Command::Growth(args)) => crate::growth::run(&args),
        Some(Command::View(args)) => crate::view::view(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.downcast_ref::<crate::compare::BelowMinDb>().is_some() => {
            eprintln!("fvr: {e}");
            ExitCode::from(1)
        }
        Err(e) => {
            eprintln!("fvr: error: {}", fvr_host::text::bounded(&e.to_string()));
            ExitCode::from(2)
        }
    }
}

/// The scene `fvr` renders with no subcommand (output relative to the
/// working directory).
pub(crate) const DEFAULT_SCENE: &str = include_str!("../../default-scene.toml");

fn default_scene() -> Result<(), Error> {
    let mut args = RenderArgs {
        volume: None,
        scene: None,
        dir: None,
        up: DEFAULT_UP,
        frame: FrameArgs::default(),
        look: crate::look::LookArgs::default(),
        out: None,
        png: PngArgs {
            bits: Bits::Eight,
            window: None,
            level: None,
            percentiles: fvr_host::image::AUTO_WINDOW_PERCENTILES,
            colormap: Colormap::Gray,
            display: fvr_host::image::film::Display::Linear,
        },
        report: crate::stats::StatsArgs {
            stats: true,
            stats_json: false,
        },
        adaptive: None,
        adaptive_chain: render::DEFAULT_CHAIN.into(),
        adaptive_hd: None,
        adaptive_bound: None,
        adaptive_plain_below: fvr_engine::slice::adaptive::DEFAULT_PLAIN_BELOW,
        adaptive_probes: fvr_engine::slice::adaptive::DEFAULT_PROBES,
        exact: false,
        input: InputArgs::default(),
        zoom: Default::default(),
        anatomy: Default::default(),
    };
    let scene = SceneFile::parse(DEFAULT_SCENE, "the default scene", Path::new(""))?;
    apply_scene_to_render(&mut args, &scene, &|_| false);
    say!(
        "fvr: rendering the default scene: the Utah teapot lit by red, green and blue lights \
         120 degrees apart, as in the paper's figure 8 (run `fvr --help` for options)"
    );
    render(&args)
}
