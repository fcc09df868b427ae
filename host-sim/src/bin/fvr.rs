//! `fvr`: frequency-domain volume rendering from the command line.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::parser::ValueSource;
use clap::{ArgMatches, Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use fvr_core::filter::FilterKind;
use fvr_core::geometry::{Sampling, View, DEFAULT_UP};
use fvr_core::scene::{Light, Scene, MAX_LIGHTS};
use fvr_host::image::output::{write_apng, write_png, Bits, Colormap, Style, Window};
use fvr_host::io::nrrd::{read_nrrd, Endian, SampleType};
use fvr_host::io::FORMATS_HELP;
use fvr_host::progress;
use fvr_host::reference::shaded::exact_scene_projection_sampled;
use fvr_host::reference::{exact_projection_sampled, max_abs_error, snr_db};
use fvr_host::render::adaptive::{parse_chain, parse_tolerance, AdaptiveSettings, Bound};
use fvr_host::render::scene_file::{parse_endian, SceneFile};
use fvr_host::render::shaded::{
    light_ring, negative_cue_share, parse_depth_cue, parse_light, parse_light_ring, parse_rgb,
    SceneRenderer, SceneSpectra, DEFAULT_PROFILE_HARMONICS, DEPTH_CUE_HELP,
};
use fvr_host::render::spectrum::{choose_filter, AnySpectrum, KbDesign, Precision};
use fvr_host::render::turntable;
use fvr_host::sources::datasets::DATASETS_HELP;
use fvr_host::sources::{load_volume_with_progress, phantom_by_name, RawLayout, PHANTOM_HELP};

/// Below this estimated storage SNR the renderer warns (see
/// `OwnedSpectrum::storage_snr_estimate_db`).
const STORAGE_SNR_WARNING_DB: f64 = 50.0;

/// Above this share of negatively weighted density (−30 dB) a depth cue
/// warns (see `negative_cue_share`).
const NEGATIVE_CUE_WARNING_SHARE: f64 = 1e-3;

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
  0  success (also for --help and --version)
  2  any error: bad arguments, unreadable or malformed input, a render that
     cannot be done; the reason is printed on stderr as `fvr: error: ...`
     (argument errors are explained by the parser, with a usage line).

Progress bars go to stderr only when it is a terminal; --quiet turns them off.";

const SCENE_HELP: &str = "\
Scene file (TOML) holding any of the render settings, so that a render can be
shared and reproduced. Precedence: a flag given on the command line, then the
scene's value, then the flag's default. Each flag replaces the scene key of the
same name (--light replaces all [[lights]]; a VOLUME replaces the scene's volume
and its raw layout). Relative paths in the scene (volume.path, output.path,
turntable.path, profile:@FILE) are relative to the scene file's directory.

  [volume]     path = \"head.nii.gz\" | builtin = \"teapot@128\", raw_dims = [X, Y, Z],
               raw_type, raw_endian, background, resample
  [camera]     dir = [X, Y, Z], up = [X, Y, Z], size = N | [W, H]
  [spectrum]   filter, oversample, precision, kb_design
  [shading]    ambient = G | [R, G, B], depth_cue = \"linear:1,0.3\", cue_harmonics,
               cue_correction = true
  [light_ring] count, tilt
  [[lights]]   direction = [X, Y, Z], color = G | [R, G, B]      (repeatable)
  [output]     path, bits = 8 | 16, window, level, percentiles = [LO, HI], colormap
  [turntable]  frames, fps, path                                (turntable only)

Unknown keys and wrong types are errors naming the file, the key and the closest
valid key. Examples: the examples/ directory of the repository.";

/// Frequency-domain volume rendering (Totsuka & Levoy 1993): X-ray
/// projections, depth cueing and shading from a 16-bit Hartley spectrum.
/// With no subcommand, renders the built-in default scene to
/// `fvr-default.png`: the Utah teapot lit by three coloured lights, as
/// `fvr render teapot@128 --dir 0.3,1,-0.45 --light-ring 3 --ambient 0.1
/// --out fvr-default.png --stats`.
#[derive(Parser)]
#[command(name = "fvr", version, after_help = GEOMETRY)]
struct Cli {
    /// No progress bars (they are shown only when stderr is a terminal anyway).
    #[arg(long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render the projection of a volume along a view direction.
    #[command(after_help = GEOMETRY)]
    Render(Box<RenderArgs>),
    /// Render a turntable animation (APNG): one preprocessing pass, then
    /// FRAMES X-ray views on a full turn about the up axis.
    #[command(after_help = GEOMETRY)]
    Turntable(TurntableArgs),
    /// Print the SNR in dB of image B against reference image A (NRRD files).
    Compare {
        /// Reference image.
        a: PathBuf,
        /// Image to measure.
        b: PathBuf,
    },
    /// Measure accuracy against exact line integrals of the Gaussian-mixture
    /// phantom and print the Markdown table quoted in the README.
    Accuracy {
        /// Phantom sides to test.
        #[arg(long, value_delimiter = ',', default_values_t = [64usize, 128])]
        sizes: Vec<usize>,
    },
    /// The precision study: SNR of every storage format and arithmetic
    /// against the f64 pipeline and exact line integrals, with bytes per
    /// voxel; writes a Markdown table, a CSV and a PNG plot.
    Precision(fvr_host::studies::precision_cli::PrecisionArgs),
    /// The speed-accuracy map: time per view, SNR against exact line
    /// integrals and memory held over filter, oversampling, storage format,
    /// adaptive tolerance, progressive level and volume size, on the
    /// Gaussian-mixture phantom; writes trade.csv, trade.png (dB against ms,
    /// Pareto fronts) and trade.md (the settings on each front).
    Trade(fvr_host::studies::trade::TradeArgs),
    /// How the time per view grows with the volume's side: the kb3 f16
    /// frequency-domain view against the f32 ray caster (both on all cores),
    /// medians of RUNS views per size; writes growth.csv, growth.md and a
    /// log-log growth.png, and prints the Markdown (with the growth per
    /// doubling against the n² log n ratio).
    Growth {
        /// Volume sides: powers of two from 16 to 256 (512 with --large).
        #[arg(long, value_delimiter = ',', default_values_t = [64usize, 128, 256])]
        sizes: Vec<usize>,
        /// Timed views per size and method (after one warm-up view).
        #[arg(long, default_value_t = 15)]
        runs: usize,
        /// Allow 512 (a 256 MiB spectrum and a 512 MiB volume).
        #[arg(long)]
        large: bool,
        /// Where to write the files.
        #[arg(long, default_value = "growth")]
        out_dir: PathBuf,
    },
    /// The paper's Table 1 measured here: filter taps and time per view with
    /// and without adaptive filtering, and the spatial-domain ray caster, on
    /// the CT head (resampled to 128 along its longest side), a 256³ volume
    /// and a phantom. Prints Markdown.
    AdaptiveTable {
        /// Tolerance in dB.
        #[arg(long, default_value_t = 40.0, value_parser = parse_tolerance)]
        tolerance: f64,
        /// How the tolerance becomes a threshold (see `render --adaptive-bound`).
        #[arg(long, default_value = "exact", value_parser = Bound::from_name)]
        bound: Bound,
        /// Large filter (the spectrum's).
        #[arg(long, value_parser = parse_filter, default_value = "kb3")]
        filter: FilterKind,
        /// Oversampling of the spectrum.
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=2))]
        oversample: u32,
        /// Volumes (ct-head is resampled to 128).
        #[arg(long, value_delimiter = ',', default_values_t = ["ct-head".to_string(), "blobs@256".to_string(), "gaussians@128".to_string(), "shepp-logan@128".to_string()])]
        volumes: Vec<String>,
        /// Timed runs per measurement (the median is reported).
        #[arg(long, default_value_t = 5)]
        runs: usize,
    },
}

#[derive(Args)]
struct RenderArgs {
    /// A volume file, a raw file with --raw-dims, a data set, or a built-in phantom.
    #[arg(help = volume_help(), required_unless_present = "scene")]
    volume: Option<String>,
    /// Scene file (TOML) with any of the settings below; flags given on the
    /// command line override the scene's values.
    #[arg(long, value_name = "FILE.toml", long_help = SCENE_HELP)]
    scene: Option<PathBuf>,
    /// View direction X,Y,Z, from the eye into the scene.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, required_unless_present = "scene")]
    dir: Option<[f64; 3]>,
    /// Up hint X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,1")]
    up: [f64; 3],
    /// Image size W or WxH in pixels (of --pixel-size mm, or of one voxel
    /// with --ignore-spacing); at most the padded grid.
    /// Default: the padded grid divided by the oversampling.
    #[arg(long, value_parser = parse_size)]
    size: Option<(usize, usize)>,
    #[command(flatten)]
    units: UnitArgs,
    #[command(flatten)]
    spectrum: SpectrumArgs,
    /// Depth cue: none, linear:FRONT,BACK, sine:FRONT,BACK, profile:W0,W1,...,
    /// profile:@FILE or profile:gauss:C,S (details with --help).
    #[arg(long, default_value = "none", long_help = DEPTH_CUE_HELP)]
    depth_cue: String,
    /// Cosine harmonics fitted to a profile depth cue (1 to 16).
    #[arg(long, default_value_t = DEFAULT_PROFILE_HARMONICS)]
    cue_harmonics: usize,
    /// Ambient colour R,G,B or one grey value (paper eq. 7). Default: 1 without
    /// lights, 0.2 with.
    #[arg(long, value_parser = parse_rgb)]
    ambient: Option<[f64; 3]>,
    /// A directional light X,Y,Z:R,G,B: the direction towards the light and
    /// its colour (or one grey value). Repeatable, up to 8. Surfaces of denser
    /// structures that face a light are lit (hemispherical model, eq. 8-11).
    #[arg(long = "light", value_parser = parse_light, allow_hyphen_values = true)]
    lights: Vec<Light>,
    /// N lights evenly spaced around the view axis (as in the paper's figure
    /// 8), saturated colours evenly spaced in hue (3: red at the top, green,
    /// blue), tilted TILT degrees towards the eye (default 30). Added to any
    /// --light.
    #[arg(long, value_name = "N[:TILT]", value_parser = parse_light_ring)]
    light_ring: Option<(usize, f64)>,
    /// Leave out the eq. 14 correction when depth cueing and shading are
    /// combined (only to see what it fixes).
    #[arg(long)]
    no_cue_correction: bool,
    /// Output file: .nrrd (float32; sizes W H, or 3 W H for RGB) or .png
    /// (grey: windowed, see --bits, --window/--level, --percentiles and
    /// --colormap; RGB: 8-bit, one percentile window over all channels).
    #[arg(long, required_unless_present = "scene")]
    out: Option<PathBuf>,
    #[command(flatten)]
    png: PngArgs,
    /// Print timing, memory and filter details.
    #[arg(long)]
    stats: bool,
    /// Resample to cubic voxels with N samples along the longest physical
    /// side (trilinear) before rendering. X-ray views of anisotropic data
    /// such as CT (0.957 x 0.957 x 1.5 mm) are exact without it; depth cues
    /// and lights need it.
    #[arg(long, value_name = "N")]
    resample: Option<usize>,
    /// Print the statistics as one JSON object instead (implies --stats).
    #[arg(long)]
    stats_json: bool,
    /// Adaptive filtering (paper §4): use a cheaper filter wherever the
    /// spectrum is weak, keeping the image within DB decibels of the
    /// full-filter image (eq. 16). Plain X-ray views only.
    #[arg(long, value_name = "DB", value_parser = parse_tolerance, allow_hyphen_values = true)]
    adaptive: Option<f64>,
    /// The cheaper filters of --adaptive, cheapest first (1 or 2 of nearest,
    /// linear, cubic, kb3, ...; each narrower than --filter).
    #[arg(long, default_value = "nearest")]
    adaptive_chain: String,
    /// Use this response difference h_d in eq. 16 instead of the one computed
    /// for the filter pair (the paper used 0.3); implies --adaptive-bound
    /// paper. A smaller value than the filters' own voids the guarantee;
    /// --stats then shows the SNR reached.
    #[arg(long, value_name = "H")]
    adaptive_hd: Option<f64>,
    /// How --adaptive turns decibels into a magnitude threshold: `exact`
    /// measures the error field of eq. 15 (one 3D inverse transform per
    /// candidate threshold, about 8, once per volume); `paper` uses eq. 16
    /// with the worst-case response difference h_d (instant, but loose).
    /// Default: `exact`, or `paper` when --adaptive-hd is given.
    #[arg(long, value_name = "BOUND", value_parser = Bound::from_name)]
    adaptive_bound: Option<Bound>,
    /// Progressive preview level: 0 full resolution; L renders the image at
    /// 1/2^L of the size from the central 1/4^L of the slice (4^L times fewer
    /// interpolations). Plain X-ray views only. (`--level` is the PNG
    /// window level, as in radiology viewers.)
    #[arg(long, value_name = "L", default_value_t = 0)]
    preview_level: u32,
    /// For a built-in phantom, also print the SNR against its exact line integrals.
    #[arg(long)]
    exact: bool,
    #[command(flatten)]
    input: InputArgs,
}

/// How a PNG is made from the rendered values (render and turntable).
#[derive(Args, Clone)]
struct PngArgs {
    /// PNG bits per channel: 8 or 16.
    #[arg(long, default_value = "8")]
    bits: Bits,
    /// Window width W: values in [L - W/2, L + W/2] span black to white
    /// (needs --level). Default: automatic, from --percentiles.
    #[arg(long, requires = "level", allow_hyphen_values = true)]
    window: Option<f64>,
    /// Window level (centre) L; needs --window.
    #[arg(long, requires = "window", allow_hyphen_values = true)]
    level: Option<f64>,
    /// Automatic window: the LOW,HIGH percentiles of the pixel values.
    #[arg(long, value_parser = parse_percentiles, default_value = "0.5,99.5", conflicts_with = "window")]
    percentiles: (f64, f64),
    /// Colormap for the X-ray image: gray, bone or hot (MATLAB's maps, as
    /// tabulated in matplotlib).
    #[arg(long, default_value = "gray")]
    colormap: Colormap,
}

impl PngArgs {
    fn style(&self) -> Result<Style, String> {
        let window = match (self.window, self.level) {
            (Some(w), Some(l)) => Window::from_width_level(w, l)?,
            _ => Window::from_percentiles(self.percentiles.0, self.percentiles.1)?,
        };
        Ok(Style {
            bits: self.bits,
            window,
            colormap: self.colormap,
        })
    }
}

#[derive(Args)]
struct TurntableArgs {
    /// A volume file, a raw file with --raw-dims, a data set, or a built-in phantom.
    #[arg(help = volume_help(), required_unless_present = "scene")]
    volume: Option<String>,
    /// Scene file (TOML): its volume, camera, spectrum, output window and
    /// [turntable] settings; flags given on the command line override them.
    #[arg(long, value_name = "FILE.toml", long_help = SCENE_HELP)]
    scene: Option<PathBuf>,
    /// Number of frames in the turn.
    #[arg(long, default_value_t = 72, value_parser = clap::value_parser!(u32).range(1..=3600))]
    frames: u32,
    /// Frames per second of the animation.
    #[arg(long, default_value_t = 24, value_parser = clap::value_parser!(u16).range(1..=1000))]
    fps: u16,
    /// View direction X,Y,Z of the first frame; later frames turn it about --up.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,-1,0")]
    dir: [f64; 3],
    /// Turntable axis and up hint X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,1")]
    up: [f64; 3],
    /// Image size W or WxH in pixels (of --pixel-size mm, or of one voxel
    /// with --ignore-spacing); at most the padded grid.
    /// Default: the padded grid divided by the oversampling.
    #[arg(long, value_parser = parse_size)]
    size: Option<(usize, usize)>,
    #[command(flatten)]
    units: UnitArgs,
    #[command(flatten)]
    spectrum: SpectrumArgs,
    /// Output file: .apng or .png (an animated PNG either way).
    #[arg(long, default_value = "spin.apng")]
    out: PathBuf,
    /// Print the timings (load, preprocess, views, views per second) as one
    /// JSON object instead of the summary line.
    #[arg(long)]
    stats_json: bool,
    #[command(flatten)]
    png: PngArgs,
    #[command(flatten)]
    input: InputArgs,
}

/// Physical units (render and turntable).
#[derive(Args, Clone, Copy, Default)]
struct UnitArgs {
    /// Pixel size in mm. Default: the smallest voxel spacing, or, if the
    /// volume's longest physical side would not fit the default image at
    /// that size, the size that fits it (longest side / default width).
    #[arg(
        long,
        value_name = "MM",
        conflicts_with = "ignore_spacing",
        allow_hyphen_values = true
    )]
    pixel_size: Option<f64>,
    /// Render in voxel units, as if the voxels were 1 mm cubes, ignoring the
    /// volume's spacing (the behaviour before spacing was used).
    #[arg(long)]
    ignore_spacing: bool,
}

impl UnitArgs {
    /// The voxel spacing and pixel size: the volume's spacing, or 1 mm
    /// with `--ignore-spacing`; `--pixel-size`, or by default the smallest
    /// spacing, raised if need be so that the longest physical side fits
    /// `default_side` pixels (the default image). Warns when the longest
    /// side exceeds the image grid's period `n·p`.
    fn sampling(
        &self,
        volume: &fvr_host::volume::Volume,
        n: usize,
        default_side: usize,
    ) -> Result<Sampling, String> {
        if self.ignore_spacing {
            return Ok(Sampling::UNIT);
        }
        let spacing = volume.spacing;
        let longest = (0..3)
            .map(|a| volume.dims[a] as f64 * spacing[a])
            .fold(0.0, f64::max);
        let pixel_size = match self.pixel_size {
            Some(p) => p,
            None => {
                let finest = spacing.iter().copied().fold(f64::INFINITY, f64::min);
                finest.max(longest / default_side.max(1) as f64)
            }
        };
        let sampling =
            Sampling::new(spacing, pixel_size).map_err(|e| format!("--pixel-size: {e}"))?;
        let period = n as f64 * pixel_size;
        if longest > period {
            eprintln!(
                "fvr: warning: the volume's longest side ({longest:.1} mm) exceeds the image \
                 grid's period ({n} pixels of {pixel_size} mm = {period:.1} mm): views across \
                 it wrap around. Use a larger --pixel-size or --oversample 2."
            );
        }
        Ok(sampling)
    }
}

/// How the spectrum is made (render and turntable).
#[derive(Args, Clone, Copy)]
struct SpectrumArgs {
    /// Interpolation filter: nearest, linear, cubic, kb3, kb4, kb5, kb6.
    #[arg(long, value_parser = parse_filter, default_value = "kb4")]
    filter: FilterKind,
    /// Oversampling of the spectrum grid: 1 or 2.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=2))]
    oversample: u32,
    /// Spectrum storage and arithmetic: f16 (f32 arithmetic), f32 or f64.
    #[arg(long, default_value = "f16")]
    precision: Precision,
    /// Kaiser-Bessel shape: `auto` fits beta to the volume's energy
    /// distribution; a number is the design oversampling of Beatty's formula.
    #[arg(long, default_value = "auto")]
    kb_design: KbDesign,
}

impl Default for SpectrumArgs {
    fn default() -> Self {
        Self {
            filter: FilterKind::Kb4,
            oversample: 1,
            precision: Precision::F16,
            kb_design: KbDesign::Auto,
        }
    }
}

/// How the volume is read (render and turntable).
#[derive(Args, Clone, Copy)]
struct InputArgs {
    /// Read VOLUME as a headerless raw file of these sizes X,Y,Z.
    #[arg(long, value_parser = parse_dims)]
    raw_dims: Option<[usize; 3]>,
    /// Sample type of a raw file: u8, i8, u16, i16, u32, i32, f32, f64.
    #[arg(long, default_value = "u8")]
    raw_type: SampleType,
    /// Byte order of a raw file: little or big.
    #[arg(long, default_value = "little", value_parser = parse_endian)]
    raw_endian: Endian,
    /// Value of empty space: voxels become max(value - B, 0) before
    /// rendering. Use -1024 for CT in Hounsfield units (air).
    #[arg(long, allow_hyphen_values = true)]
    background: Option<f64>,
}

impl Default for InputArgs {
    fn default() -> Self {
        Self {
            raw_dims: None,
            raw_type: SampleType::U8,
            raw_endian: Endian::Little,
            background: None,
        }
    }
}

impl InputArgs {
    /// Load `spec` with a progress bar, then subtract the background.
    fn load(&self, spec: &str) -> Result<fvr_host::volume::Volume, String> {
        let raw = self.raw_dims.map(|dims| RawLayout {
            dims,
            ty: self.raw_type,
            endian: self.raw_endian,
        });
        let mut volume = load_with_progress(spec, raw)?;
        if let Some(b) = self.background {
            volume.subtract_background(b)?;
        }
        Ok(volume)
    }
}

fn volume_help() -> String {
    format!(
        "Volume: a file ({FORMATS_HELP}), a raw file (with --raw-dims), one of the {DATASETS_HELP}, or one of the {PHANTOM_HELP}"
    )
}

fn parse_percentiles(s: &str) -> Result<(f64, f64), String> {
    let bad = || format!("expected percentiles LOW,HIGH with 0 <= LOW < HIGH <= 100, got `{s}`");
    let (lo, hi) = s.split_once(',').ok_or_else(bad)?;
    let lo = lo.trim().parse::<f64>().map_err(|_| bad())?;
    let hi = hi.trim().parse::<f64>().map_err(|_| bad())?;
    Window::from_percentiles(lo, hi).map_err(|_| bad())?;
    Ok((lo, hi))
}

fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').collect();
    let bad = || format!("expected three comma-separated numbers X,Y,Z, got `{s}`");
    if parts.len() != 3 {
        return Err(bad());
    }
    let mut v = [0.0; 3];
    for (slot, p) in v.iter_mut().zip(parts) {
        *slot = p.trim().parse::<f64>().map_err(|_| bad())?;
        if !slot.is_finite() {
            return Err(format!("vector components must be finite, got `{s}`"));
        }
    }
    Ok(v)
}

fn parse_dims(s: &str) -> Result<[usize; 3], String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|p| p.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected sizes X,Y,Z, got `{s}`"))?;
    match v.as_slice() {
        [x, y, z] if *x > 0 && *y > 0 && *z > 0 => Ok([*x, *y, *z]),
        _ => Err(format!("expected three positive sizes X,Y,Z, got `{s}`")),
    }
}

fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let bad = || format!("expected W or WxH with positive integers, got `{s}`");
    let (w, h) = match s.split_once(['x', 'X']) {
        Some((w, h)) => (w, h),
        None => (s, s),
    };
    let w = w.trim().parse::<usize>().map_err(|_| bad())?;
    let h = h.trim().parse::<usize>().map_err(|_| bad())?;
    if w == 0 || h == 0 {
        return Err(bad());
    }
    Ok((w, h))
}

fn parse_filter(s: &str) -> Result<FilterKind, String> {
    FilterKind::from_name(s).ok_or_else(|| {
        format!("unknown filter `{s}`: expected nearest, linear, cubic, kb3, kb4, kb5 or kb6")
    })
}

fn main() -> ExitCode {
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    progress::set_quiet(cli.quiet);
    let given = |sub: &str, id: &str| {
        matches
            .subcommand_matches(sub)
            .is_some_and(|m| given_on_command_line(m, id))
    };
    let result = match cli.command {
        None => default_scene(),
        Some(Command::Render(mut args)) => args
            .scene
            .clone()
            .map_or(Ok(()), |path| {
                SceneFile::load(&path).map(|scene| {
                    apply_scene_to_render(&mut args, &scene, &|id| given("render", id))
                })
            })
            .and_then(|()| render(&args)),
        Some(Command::Turntable(mut args)) => args
            .scene
            .clone()
            .map_or(Ok(()), |path| {
                SceneFile::load(&path).map(|scene| {
                    apply_scene_to_turntable(&mut args, &scene, &|id| given("turntable", id))
                })
            })
            .and_then(|()| turntable(&args)),
        Some(Command::Compare { a, b }) => compare(&a, &b),
        Some(Command::Accuracy { sizes }) => accuracy(&sizes),
        Some(Command::AdaptiveTable {
            tolerance,
            bound,
            filter,
            oversample,
            volumes,
            runs,
        }) => adaptive_table(tolerance, bound, filter, oversample, &volumes, runs),
        Some(Command::Precision(args)) => fvr_host::studies::precision_cli::run(&args),
        Some(Command::Trade(args)) => fvr_host::studies::trade::run(&args),
        Some(Command::Growth {
            sizes,
            runs,
            large,
            out_dir,
        }) => fvr_host::studies::growth::run(&sizes, runs, large, &out_dir, |r| {
            eprintln!(
                "fvr: {}³: {:.3} ms against {:.2} ms",
                r.n, r.frequency_ms, r.raycast_ms
            )
        })
        .map(|md| print!("{md}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fvr: error: {e}");
            ExitCode::from(2)
        }
    }
}

/// The scene `fvr` renders with no subcommand (output relative to the
/// working directory).
const DEFAULT_SCENE: &str = include_str!("../default-scene.toml");

fn default_scene() -> Result<(), String> {
    let mut args = RenderArgs {
        volume: None,
        scene: None,
        dir: None,
        up: DEFAULT_UP,
        size: None,
        units: UnitArgs::default(),
        spectrum: SpectrumArgs::default(),
        depth_cue: "none".into(),
        cue_harmonics: DEFAULT_PROFILE_HARMONICS,
        ambient: None,
        lights: Vec::new(),
        light_ring: None,
        no_cue_correction: false,
        out: None,
        png: PngArgs {
            bits: Bits::Eight,
            window: None,
            level: None,
            percentiles: fvr_host::image::AUTO_WINDOW_PERCENTILES,
            colormap: Colormap::Gray,
        },
        stats: true,
        resample: None,
        stats_json: false,
        adaptive: None,
        adaptive_chain: "nearest".into(),
        adaptive_hd: None,
        adaptive_bound: None,
        preview_level: 0,
        exact: false,
        input: InputArgs::default(),
    };
    let scene = SceneFile::parse(DEFAULT_SCENE, "the default scene", Path::new(""))?;
    apply_scene_to_render(&mut args, &scene, &|_| false);
    println!(
        "fvr: rendering the default scene: the Utah teapot lit by red, green and blue lights \
         120 degrees apart, as in the paper's figure 8 (run `fvr --help` for options)"
    );
    render(&args)
}

/// Whether the argument `id` was given on the command line (not defaulted).
fn given_on_command_line(matches: &ArgMatches, id: &str) -> bool {
    matches.try_get_raw(id).is_ok() && matches.value_source(id) == Some(ValueSource::CommandLine)
}

/// Set `slot` to the scene's `value` unless the flag `id` was given.
fn fill<T>(given: &dyn Fn(&str) -> bool, id: &str, slot: &mut T, value: Option<T>) {
    if let (false, Some(v)) = (given(id), value) {
        *slot = v;
    }
}

/// Fill the volume settings from the scene. A VOLUME given on the command
/// line drops the scene's raw layout, which describes the scene's file.
fn apply_scene_to_input(
    volume: &mut Option<String>,
    input: &mut InputArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    let v = &scene.volume;
    if !given("volume") {
        fill(given, "volume", volume, v.spec.clone().map(Some));
        fill(given, "raw_dims", &mut input.raw_dims, v.raw_dims.map(Some));
        fill(given, "raw_type", &mut input.raw_type, v.raw_type);
        fill(given, "raw_endian", &mut input.raw_endian, v.raw_endian);
    }
    fill(
        given,
        "background",
        &mut input.background,
        v.background.map(Some),
    );
}

/// Fill the physical-unit settings from the scene. A command-line choice of
/// either wins over the scene's other one, since the two conflict.
fn apply_scene_to_units(units: &mut UnitArgs, scene: &SceneFile, given: &dyn Fn(&str) -> bool) {
    if !given("ignore_spacing") {
        fill(
            given,
            "pixel_size",
            &mut units.pixel_size,
            scene.camera.pixel_size.map(Some),
        );
    }
    if !given("pixel_size") {
        fill(
            given,
            "ignore_spacing",
            &mut units.ignore_spacing,
            scene.volume.ignore_spacing,
        );
    }
}

fn apply_scene_to_spectrum(
    spectrum: &mut SpectrumArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    let s = &scene.spectrum;
    fill(given, "filter", &mut spectrum.filter, s.filter);
    fill(given, "oversample", &mut spectrum.oversample, s.oversample);
    fill(given, "precision", &mut spectrum.precision, s.precision);
    fill(given, "kb_design", &mut spectrum.kb_design, s.kb_design);
}

/// Fill the PNG settings. `--percentiles` on the command line also drops
/// the scene's window and level, which would otherwise take precedence.
fn apply_scene_to_png(png: &mut PngArgs, scene: &SceneFile, given: &dyn Fn(&str) -> bool) {
    let o = &scene.output;
    fill(given, "bits", &mut png.bits, o.bits);
    if !given("percentiles") && !given("window") && !given("level") {
        fill(given, "window", &mut png.window, o.window.map(Some));
        fill(given, "level", &mut png.level, o.level.map(Some));
    }
    fill(given, "percentiles", &mut png.percentiles, o.percentiles);
    fill(given, "colormap", &mut png.colormap, o.colormap);
}

/// Fill every render setting the command line did not give from the scene
/// (precedence: flags, then the scene, then the flags' defaults). Each flag
/// replaces the scene key of the same name: `--light` replaces all of the
/// scene's `[[lights]]`, `--light-ring` its `[light_ring]`.
fn apply_scene_to_render(args: &mut RenderArgs, scene: &SceneFile, given: &dyn Fn(&str) -> bool) {
    apply_scene_to_input(&mut args.volume, &mut args.input, scene, given);
    fill(
        given,
        "resample",
        &mut args.resample,
        scene.volume.resample.map(Some),
    );
    let c = &scene.camera;
    fill(given, "dir", &mut args.dir, c.dir.map(Some));
    fill(given, "up", &mut args.up, c.up);
    fill(given, "size", &mut args.size, c.size.map(Some));
    apply_scene_to_units(&mut args.units, scene, given);
    apply_scene_to_spectrum(&mut args.spectrum, scene, given);
    let sh = &scene.shading;
    fill(
        given,
        "depth_cue",
        &mut args.depth_cue,
        sh.depth_cue.clone(),
    );
    fill(
        given,
        "cue_harmonics",
        &mut args.cue_harmonics,
        sh.cue_harmonics,
    );
    fill(given, "ambient", &mut args.ambient, sh.ambient.map(Some));
    fill(
        given,
        "no_cue_correction",
        &mut args.no_cue_correction,
        sh.cue_correction.map(|on| !on),
    );
    fill(given, "lights", &mut args.lights, scene.lights.clone());
    fill(
        given,
        "light_ring",
        &mut args.light_ring,
        scene.light_ring.map(Some),
    );
    fill(
        given,
        "out",
        &mut args.out,
        scene.output.path.clone().map(Some),
    );
    apply_scene_to_png(&mut args.png, scene, given);
}

/// Fill the turntable settings the command line did not give from the
/// scene: volume, camera, spectrum, output window and `[turntable]`. Scene
/// keys a turntable does not use are named on stderr.
fn apply_scene_to_turntable(
    args: &mut TurntableArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    apply_scene_to_input(&mut args.volume, &mut args.input, scene, given);
    let c = &scene.camera;
    fill(given, "dir", &mut args.dir, c.dir);
    fill(given, "up", &mut args.up, c.up);
    fill(given, "size", &mut args.size, c.size.map(Some));
    apply_scene_to_units(&mut args.units, scene, given);
    apply_scene_to_spectrum(&mut args.spectrum, scene, given);
    apply_scene_to_png(&mut args.png, scene, given);
    let t = &scene.turntable;
    fill(given, "frames", &mut args.frames, t.frames);
    fill(given, "fps", &mut args.fps, t.fps);
    fill(given, "out", &mut args.out, t.path.clone());
    let unused: Vec<&str> = [
        ("volume.resample", scene.volume.resample.is_some()),
        (
            "[shading]",
            scene.shading != fvr_host::render::scene_file::ShadingSection::default(),
        ),
        (
            "[[lights]]",
            scene.lights.as_ref().is_some_and(|l| !l.is_empty()),
        ),
        ("[light_ring]", scene.light_ring.is_some()),
        ("output.path", scene.output.path.is_some()),
    ]
    .into_iter()
    .filter_map(|(name, set)| set.then_some(name))
    .collect();
    if !unused.is_empty() {
        eprintln!(
            "fvr: note: the turntable renders X-ray views and does not use the scene's {}",
            unused.join(", ")
        );
    }
}

impl RenderArgs {
    fn volume_spec(&self) -> Result<&str, String> {
        self.volume.as_deref().ok_or_else(|| {
            "no volume: give VOLUME, or `volume.path` or `volume.builtin` in the scene".into()
        })
    }

    fn view(&self) -> Result<View, String> {
        let dir = self.dir.ok_or_else(|| {
            "no view direction: give --dir, or `camera.dir` in the scene".to_string()
        })?;
        Ok(View { dir, up: self.up })
    }

    fn out_path(&self) -> Result<&Path, String> {
        self.out
            .as_deref()
            .ok_or_else(|| "no output file: give --out, or `output.path` in the scene".into())
    }
}

fn render(args: &RenderArgs) -> Result<(), String> {
    let out = args.out_path()?;
    let volume_spec = args.volume_spec()?;
    let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext != "png" && ext != "nrrd" {
        return Err(format!(
            "output `{}` must end in .png or .nrrd",
            out.display()
        ));
    }
    let view = args.view()?;
    view.frame().map_err(|e| e.to_string())?;
    let style = args.png.style()?;
    let t0 = Instant::now();
    let mut volume = args.input.load(volume_spec)?;
    if let Some(largest) = args.resample {
        volume = volume.resample_isotropic(largest)?;
    }
    let t_load = t0.elapsed();
    let scene = build_scene(args)?;
    let t1 = Instant::now();
    let (spectra, filter) = prepare_scene_with_progress(
        &volume,
        args.spectrum.filter,
        args.spectrum.oversample,
        args.spectrum.kb_design,
        args.spectrum.precision,
        &scene,
    )?;
    let t_prep = t1.elapsed();
    let volume_sum: f64 = volume.data.iter().map(|&v| v as f64).sum();
    let storage_snr = spectra.density.storage_snr_estimate_db(volume_sum);
    if storage_snr < STORAGE_SNR_WARNING_DB {
        eprintln!(
            "fvr: warning: premultiplying for {} at oversample {} amplifies this volume's edges; \
             the {} spectrum is estimated to hold only {storage_snr:.1} dB. \
             Use --oversample 2, --filter cubic, or --precision f32.",
            args.spectrum.filter.name(),
            args.spectrum.oversample,
            args.spectrum.precision
        );
    }
    let (lowest, share) = negative_cue_share(&volume, &scene, &view).map_err(|e| e.to_string())?;
    if share > NEGATIVE_CUE_WARNING_SHARE {
        eprintln!(
            "fvr: warning: the depth cue is given between t = -R and +R; extrapolated beyond, \
             into the volume's corners on this view, it falls to {lowest:.3}, and {:.2}% of the \
             weighted density counts negatively. Raise the smaller of FRONT and BACK to avoid it.",
            100.0 * share
        );
    }
    let n = spectra.density.n();
    let default_side = n / args.spectrum.oversample as usize;
    let (w, h) = args.size.unwrap_or((default_side, default_side));
    let sampling = args.units.sampling(&volume, n, default_side)?;
    let plain_view = scene.channels() == 1 && !scene.has_partner_terms();
    if (args.preview_level > 0 || args.adaptive.is_some()) && !plain_view {
        return Err(
            "--preview-level and --adaptive work on plain X-ray views: leave out --depth-cue, \
                    --light, --light-ring and a coloured --ambient"
                .into(),
        );
    }
    if args.preview_level > 0 && args.adaptive.is_some() {
        return Err("--preview-level and --adaptive cannot be combined: choose one".into());
    }
    // Cubic voxels imaged at their own size read the slice along the frame's
    // own axes: only the gain ΔV/p² = Δ differs from voxel units.
    if args.adaptive.is_some() && sampling.uniform_pitch().is_none() {
        return Err(format!(
            "--adaptive needs cubic voxels imaged at their own size (or voxel units), and this \
             render uses {} mm voxels and {} mm pixels: add --resample N, drop --pixel-size, \
             or add --ignore-spacing",
            fmt_spacing(sampling.spacing()),
            sampling.pixel_size()
        ));
    }
    let mut adaptive_report = None;
    let t2 = Instant::now();
    let (image, w, h) = if args.preview_level > 0 {
        let (pw, ph) = fvr_core::progressive::preview_size(w, h, args.preview_level);
        let data = spectra
            .density
            .render_level_sampled(&view, &sampling, pw, ph, args.preview_level)
            .map_err(|e| e.to_string())?;
        (
            fvr_host::render::shaded::Image {
                channels: 1,
                width: pw,
                height: ph,
                data: data.into_iter().map(|v| v * scene.ambient[0]).collect(),
            },
            pw,
            ph,
        )
    } else if let Some(tolerance) = args.adaptive {
        let settings = AdaptiveSettings {
            tolerance_db: tolerance,
            chain: parse_chain(&args.adaptive_chain)?,
            h_d: args.adaptive_hd,
            bound: args.adaptive_bound.unwrap_or(match args.adaptive_hd {
                Some(_) => Bound::Paper,
                None => Bound::Exact,
            }),
        };
        let report = adaptive_render(&spectra.density, &view, w, h, &settings)?;
        let gain = sampling.gain() * scene.ambient[0];
        let data = report.image.iter().map(|v| v * gain).collect();
        adaptive_report = Some(report);
        (
            fvr_host::render::shaded::Image {
                channels: 1,
                width: w,
                height: h,
                data,
            },
            w,
            h,
        )
    } else {
        let image = spectra.render_sampled(&scene, &view, &sampling, w, h)?;
        (image, w, h)
    };
    let t_view = adaptive_report
        .as_ref()
        .map_or(t2.elapsed(), |r| r.view_time);
    if ext == "png" {
        if image.channels == 1 {
            write_png(out, w, h, &image.data, &style)?;
        } else {
            image.write_png(out)?;
        }
    } else {
        image.write_nrrd(out)?;
    }
    let kind = if image.channels == 1 { "grey" } else { "RGB" };
    println!("wrote {} ({w}x{h} {kind})", out.display());
    if args.stats && !args.stats_json {
        let d = volume.dims;
        println!(
            "  volume        {}x{}x{} ({})",
            d[0], d[1], d[2], volume_spec
        );
        let [dx, dy, dz] = volume.spacing;
        println!(
            "  spacing       {dx} x {dy} x {dz} mm{}",
            if args.units.ignore_spacing {
                " (ignored: --ignore-spacing, voxel units)"
            } else {
                ""
            }
        );
        println!(
            "  pixel size    {} {}",
            sampling.pixel_size(),
            if args.units.ignore_spacing {
                "voxel"
            } else {
                "mm (values in mm x volume units)"
            }
        );
        println!(
            "  spectrum      {n}^3 {} = {} bytes ({} bytes/voxel)",
            args.spectrum.precision,
            spectra.density.bytes(),
            args.spectrum.precision.bytes()
        );
        match &spectra.gradient {
            Some(g) => println!(
                "  |grad f|      {} bytes (second spectrum, for the lights)",
                g.bytes()
            ),
            None => println!("  |grad f|      not built (no light needs it)"),
        }
        let working = match args.spectrum.precision {
            Precision::F64 => SceneRenderer::<f64>::new(n, filter, &scene).map(|r| r.bytes()),
            _ => SceneRenderer::<f32>::new(n, filter, &scene).map(|r| r.bytes()),
        }
        .map_err(|e| e.to_string())?;
        println!(
            "  per view      {working} bytes ({} slice fields, tables, twiddles)",
            scene.field_count()
        );
        println!("  held          {} bytes in all", spectra.bytes() + working);
        let f = spectra.density.filter();
        if f.kind().is_kaiser_bessel() {
            println!(
                "  filter        {} (oversample {}, beta {:.3})",
                f.kind().name(),
                f.oversample(),
                f.beta()
            );
        } else {
            println!(
                "  filter        {} (oversample {})",
                f.kind().name(),
                f.oversample()
            );
        }
        println!("  storage SNR   {storage_snr:.1} dB (estimate, against the f64 pipeline)");
        println!("  load          {:.1} ms", t_load.as_secs_f64() * 1e3);
        println!("  preprocess    {:.1} ms", t_prep.as_secs_f64() * 1e3);
        println!("  view          {:.2} ms", t_view.as_secs_f64() * 1e3);
        if args.preview_level > 0 {
            println!(
                "  level         {} ({w}x{h} at pitch {} {}, central 1/{} of the slice)",
                args.preview_level,
                (1u64 << args.preview_level) as f64 * sampling.pixel_size(),
                if sampling == Sampling::UNIT {
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
    }
    if args.stats_json {
        let mut fields = vec![
            ("volume", json_str(volume_spec)),
            ("dims", format!("{:?}", volume.dims)),
            ("spacing_mm", format!("{:?}", volume.spacing)),
            ("pixel_size", json_num(sampling.pixel_size())),
            ("ignore_spacing", args.units.ignore_spacing.to_string()),
            ("image", format!("[{w}, {h}, {}]", image.channels)),
            ("spectrum_side", n.to_string()),
            ("precision", json_str(args.spectrum.precision.name())),
            ("spectrum_bytes", spectra.density.bytes().to_string()),
            (
                "gradient_spectrum_bytes",
                spectra
                    .gradient
                    .as_ref()
                    .map_or("null".into(), |g| g.bytes().to_string()),
            ),
            ("filter", json_str(filter.kind().name())),
            ("oversample", filter.oversample().to_string()),
            ("storage_snr_db", json_num(storage_snr)),
            ("load_ms", json_num(t_load.as_secs_f64() * 1e3)),
            ("preprocess_ms", json_num(t_prep.as_secs_f64() * 1e3)),
            ("view_ms", json_num(t_view.as_secs_f64() * 1e3)),
            ("preview_level", args.preview_level.to_string()),
        ];
        if let Some(r) = &adaptive_report {
            fields.push(("adaptive", r.json()));
        }
        let body: Vec<String> = fields
            .iter()
            .map(|(k, v)| format!("{}: {v}", json_str(k)))
            .collect();
        println!("{{{}}}", body.join(", "));
    }
    if args.exact {
        let plain = scene.channels() == 1 && !scene.has_partner_terms();
        match phantom_by_name(volume_spec) {
            Some(Ok(p)) if plain => {
                let exact = exact_projection_sampled(
                    p.phantom.as_ref(),
                    volume.dims,
                    &view,
                    &sampling,
                    w,
                    h,
                )
                .map_err(|e| e.to_string())?;
                let ambient = scene.ambient[0];
                let exact: Vec<f64> = exact.iter().map(|v| v * ambient).collect();
                println!("  SNR vs exact  {:.2} dB", snr_db(&exact, &image.data));
            }
            Some(Ok(p)) => match p.phantom.as_gaussian_mixture() {
                Some(mixture) => {
                    let exact = exact_scene_projection_sampled(
                        mixture,
                        volume.dims,
                        &sampling,
                        &scene,
                        &view,
                        w,
                        h,
                        0.05,
                    )
                    .map_err(|e| e.to_string())?;
                    println!("  SNR vs exact  {:.2} dB", snr_db(&exact.data, &image.data));
                }
                None => println!(
                    "  SNR vs exact  n/a (cued or shaded references exist for gaussians only)"
                ),
            },
            _ => println!("  SNR vs exact  n/a (not a built-in phantom)"),
        }
    }
    Ok(())
}

fn fmt_spacing(s: [f64; 3]) -> String {
    format!("{} x {} x {}", s[0], s[1], s[2])
}

/// The scene from the command line: cue, ambient, lights.
fn build_scene(args: &RenderArgs) -> Result<Scene, String> {
    let cue = parse_depth_cue(&args.depth_cue, args.cue_harmonics)?;
    let mut lights = args.lights.clone();
    if let Some((count, tilt)) = args.light_ring {
        lights.extend(light_ring(&args.view()?, count, tilt).map_err(|e| e.to_string())?);
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
        ));
    }
    for light in &lights {
        scene.add_light(*light).map_err(|e| e.to_string())?;
    }
    scene.validate().map_err(|e| e.to_string())?;
    Ok(scene)
}

/// Load a volume with a progress bar on the bytes read.
fn load_with_progress(
    spec: &str,
    raw: Option<RawLayout>,
) -> Result<fvr_host::volume::Volume, String> {
    let bar = progress::bytes("loading");
    let volume = load_volume_with_progress(spec, raw, &bar);
    bar.finish_and_clear();
    volume
}

/// Fit the filter and prepare the scene's spectra, with a spinner.
fn prepare_scene_with_progress(
    volume: &fvr_host::volume::Volume,
    kind: FilterKind,
    oversample: u32,
    design: KbDesign,
    precision: Precision,
    scene: &Scene,
) -> Result<(SceneSpectra, fvr_core::filter::Filter), String> {
    let bar = progress::spinner("fitting filter");
    let result = choose_filter(volume, kind, oversample, design)
        .map_err(|e| e.to_string())
        .and_then(|filter| {
            bar.set_message(if scene.needs_gradient_spectrum() {
                "preprocess (density and |grad f| spectra)"
            } else {
                "preprocess"
            });
            SceneSpectra::prepare(volume, filter, precision, scene)
                .map(|s| (s, filter))
                .map_err(|e| e.to_string())
        });
    bar.finish_and_clear();
    result
}

/// Fit the filter and prepare the spectrum, with a spinner (the core's
/// preparation is one call with no progress of its own).
fn prepare_with_progress(
    volume: &fvr_host::volume::Volume,
    kind: FilterKind,
    oversample: u32,
    design: KbDesign,
    precision: Precision,
) -> Result<AnySpectrum, String> {
    let bar = progress::spinner("fitting filter");
    let result = choose_filter(volume, kind, oversample, design)
        .map_err(|e| e.to_string())
        .and_then(|filter| {
            bar.set_message("preprocess");
            AnySpectrum::prepare(volume, filter, precision).map_err(|e| e.to_string())
        });
    bar.finish_and_clear();
    result
}

fn turntable(args: &TurntableArgs) -> Result<(), String> {
    let views = turntable::orbit(args.dir, args.up, args.frames as usize)?;
    let style = args.png.style()?;
    let t0 = Instant::now();
    let volume_spec = args.volume.as_deref().ok_or_else(|| {
        "no volume: give VOLUME, or `volume.path` or `volume.builtin` in the scene".to_string()
    })?;
    let volume = args.input.load(volume_spec)?;
    let t_load = t0.elapsed();
    let t1 = Instant::now();
    let spec = prepare_with_progress(
        &volume,
        args.spectrum.filter,
        args.spectrum.oversample,
        args.spectrum.kb_design,
        args.spectrum.precision,
    )?;
    let t_prep = t1.elapsed();
    let n = spec.n();
    let side = n / args.spectrum.oversample as usize;
    let (w, h) = args.size.unwrap_or((side, side));
    let sampling = args.units.sampling(&volume, n, side)?;
    let bar = progress::count(views.len() as u64, "frames");
    let t2 = Instant::now();
    let frames = turntable::render_views(&spec, &views, &sampling, w, h, &bar);
    let t_views = t2.elapsed();
    bar.finish_and_clear();
    let frames = frames.map_err(|e| e.to_string())?;
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
        let fields = [
            ("volume", json_str(volume_spec)),
            ("dims", format!("{:?}", volume.dims)),
            ("image", format!("[{w}, {h}]")),
            ("frames", frames.len().to_string()),
            ("fps", args.fps.to_string()),
            ("spectrum_side", n.to_string()),
            ("precision", json_str(args.spectrum.precision.name())),
            ("spectrum_bytes", spec.bytes().to_string()),
            ("filter", json_str(args.spectrum.filter.name())),
            ("oversample", args.spectrum.oversample.to_string()),
            ("load_ms", json_num(t_load.as_secs_f64() * 1e3)),
            ("preprocess_ms", json_num(t_prep.as_secs_f64() * 1e3)),
            ("views_ms", json_num(secs * 1e3)),
            (
                "ms_per_view",
                json_num(secs * 1e3 / frames.len().max(1) as f64),
            ),
            ("views_per_second", json_num(views_per_second)),
        ];
        let body: Vec<String> = fields
            .iter()
            .map(|(k, v)| format!("{}: {v}", json_str(k)))
            .collect();
        println!("{{{}}}", body.join(", "));
    } else {
        println!(
            "  load {:.1} ms, preprocess {:.1} ms ({n}^3 {}), {} views in {:.1} ms = {:.1} views/s",
            t_load.as_secs_f64() * 1e3,
            t_prep.as_secs_f64() * 1e3,
            args.spectrum.precision,
            frames.len(),
            secs * 1e3,
            views_per_second
        );
    }
    Ok(())
}

fn compare(a: &Path, b: &Path) -> Result<(), String> {
    let ia = read_nrrd(a).map_err(|e| e.to_string())?;
    let ib = read_nrrd(b).map_err(|e| e.to_string())?;
    if ia.dims != ib.dims {
        return Err(format!(
            "images differ in size: {:?} against {:?}",
            ia.dims, ib.dims
        ));
    }
    let ra: Vec<f64> = ia.data.iter().map(|&v| v as f64).collect();
    let rb: Vec<f64> = ib.data.iter().map(|&v| v as f64).collect();
    println!(
        "SNR of {} against {}: {:.2} dB (max abs error {:.3e})",
        b.display(),
        a.display(),
        snr_db(&ra, &rb),
        max_abs_error(&ra, &rb)
    );
    Ok(())
}

fn accuracy(sizes: &[usize]) -> Result<(), String> {
    let rows = fvr_host::studies::accuracy::accuracy_table(sizes).map_err(|e| e.to_string())?;
    print!("{}", fvr_host::studies::accuracy::markdown(&rows));
    Ok(())
}

fn json_str(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn json_num(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        "null".into()
    }
}

/// An adaptive render with what it did.
struct AdaptiveReport {
    image: Vec<f64>,
    marks: fvr_host::render::adaptive::AdaptiveMarks,
    stats: fvr_core::adaptive::AdaptiveStats,
    mark_time: std::time::Duration,
    view_time: std::time::Duration,
    full_view_time: std::time::Duration,
    snr_vs_full: f64,
}

impl AdaptiveReport {
    fn print_human(&self) {
        let s = &self.stats;
        let pct = |v: u64, of: u64| 100.0 * v as f64 / of.max(1) as f64;
        println!(
            "  adaptive      {} dB: {} of {} taps ({:.1}%), {:.2} ms per view against {:.2} ms \
             with the full filter; image {:.1} dB from the full-filter image",
            self.marks.tolerance_db,
            s.taps,
            s.full_taps,
            pct(s.taps, s.full_taps),
            self.view_time.as_secs_f64() * 1e3,
            self.full_view_time.as_secs_f64() * 1e3,
            self.snr_vs_full
        );
        println!(
            "  samples       {:.1}% on the full filter",
            pct(s.per_filter[0], s.samples)
        );
        for (i, l) in self.marks.levels.iter().enumerate() {
            println!(
                "  samples       {:.1}% on {} (h_d {:.3}, threshold {:.3e}, {} of {} spectrum samples marked)",
                pct(s.per_filter[i + 1], s.samples),
                l.filter.kind().name(),
                l.h_d,
                l.threshold,
                l.marked,
                l.words.len() * 32
            );
            if let Some(r) = l.error_ratio {
                println!(
                    "  error field   {:.1} dB below the volume (exact bound, eq. 15)",
                    -10.0 * r.log10()
                );
            }
        }
        println!(
            "  marks         {} bytes (1 bit per voxel per level), built in {:.1} ms",
            self.marks.bytes(),
            self.mark_time.as_secs_f64() * 1e3
        );
        if let Some(note) = self.marks.effect(s) {
            println!("  note          {note}");
        }
    }

    fn json(&self) -> String {
        let s = &self.stats;
        let levels: Vec<String> = self
            .marks
            .levels
            .iter()
            .enumerate()
            .map(|(i, l)| {
                format!(
                    "{{\"filter\": {}, \"h_d\": {}, \"threshold\": {}, \"marked\": {}, \"samples\": {}, \"error_field_db\": {}}}",
                    json_str(l.filter.kind().name()),
                    json_num(l.h_d),
                    json_num(l.threshold),
                    l.marked,
                    s.per_filter[i + 1],
                    l.error_ratio.map_or("null".into(), |r| json_num(-10.0 * r.log10()))
                )
            })
            .collect();
        format!(
            "{{\"tolerance_db\": {}, \"bound\": {}, \"taps\": {}, \"full_taps\": {}, \"taps_ratio\": {}, \
             \"samples\": {}, \"full_filter_samples\": {}, \"levels\": [{}], \"marks_bytes\": {}, \
             \"mark_ms\": {}, \"view_ms\": {}, \"full_view_ms\": {}, \"snr_vs_full_db\": {}, \
             \"note\": {}}}",
            json_num(self.marks.tolerance_db),
            json_str(self.marks.bound.name()),
            s.taps,
            s.full_taps,
            json_num(s.taps as f64 / s.full_taps.max(1) as f64),
            s.samples,
            s.per_filter[0],
            levels.join(", "),
            self.marks.bytes(),
            json_num(self.mark_time.as_secs_f64() * 1e3),
            json_num(self.view_time.as_secs_f64() * 1e3),
            json_num(self.full_view_time.as_secs_f64() * 1e3),
            json_num(self.snr_vs_full),
            self.marks.effect(s).map_or("null".into(), |n| json_str(&n))
        )
    }
}

/// Mark the spectrum, render adaptively, and render with the full filter
/// for comparison.
fn adaptive_render(
    spec: &AnySpectrum,
    view: &View,
    w: usize,
    h: usize,
    settings: &AdaptiveSettings,
) -> Result<AdaptiveReport, String> {
    fn go<S: fvr_core::real::Sample, T: fvr_core::real::Real>(
        any: &AnySpectrum,
        spec: &fvr_host::render::spectrum::OwnedSpectrum<S>,
        view: &View,
        w: usize,
        h: usize,
        settings: &AdaptiveSettings,
    ) -> Result<AdaptiveReport, String> {
        let t0 = Instant::now();
        let marks = fvr_host::render::adaptive::AdaptiveMarks::build(spec, settings)?;
        let mark_time = t0.elapsed();
        let t1 = Instant::now();
        let (image, stats) = marks
            .render::<S, T>(spec, view, w, h)
            .map_err(|e| e.to_string())?;
        let view_time = t1.elapsed();
        let t2 = Instant::now();
        let full = any.render(view, w, h).map_err(|e| e.to_string())?;
        let full_view_time = t2.elapsed();
        Ok(AdaptiveReport {
            snr_vs_full: snr_db(&full, &image),
            image,
            marks,
            stats,
            mark_time,
            view_time,
            full_view_time,
        })
    }
    match spec {
        AnySpectrum::F16(s) => go::<_, f32>(spec, s, view, w, h, settings),
        AnySpectrum::F32(s) => go::<_, f32>(spec, s, view, w, h, settings),
        AnySpectrum::F64(s) => go::<_, f64>(spec, s, view, w, h, settings),
    }
}

fn adaptive_table(
    tolerance: f64,
    bound: Bound,
    kind: FilterKind,
    oversample: u32,
    volumes: &[String],
    runs: usize,
) -> Result<(), String> {
    let filter = fvr_core::filter::Filter::new(kind, oversample).map_err(|e| e.to_string())?;
    let view = View::along([1.0, 0.3, 0.2]);
    let mut rows = Vec::new();
    for name in volumes {
        let mut volume = load_with_progress(name, None)?;
        if name == "ct-head" {
            volume.subtract_background(-1024.0)?;
            volume = volume.resample_isotropic(128)?;
        }
        let settings = AdaptiveSettings {
            bound,
            ..AdaptiveSettings::new(tolerance)
        };
        rows.push(fvr_host::render::adaptive::table1_row(
            name,
            &volume,
            filter,
            &settings,
            &view,
            runs.max(1),
        )?);
        eprintln!("fvr: measured {name}");
    }
    print!(
        "{}",
        fvr_host::render::adaptive::table1_markdown(&rows, tolerance)
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene that sets every key `fvr render` reads.
    const FULL_SCENE: &str = r#"
        [volume]
        path = "v.raw"
        raw_dims = [4, 5, 6]
        raw_type = "u16"
        raw_endian = "big"
        background = -1024
        resample = 96
        [camera]
        dir = [1, 0.5, -0.25]
        up = [0, 1, 0]
        size = [64, 32]
        pixel_size = 0.5
        [spectrum]
        filter = "cubic"
        oversample = 2
        precision = "f32"
        kb_design = 1.5
        [shading]
        ambient = 0.1
        depth_cue = "linear:1,0.3"
        cue_harmonics = 6
        cue_correction = false
        [light_ring]
        count = 2
        tilt = 10
        [[lights]]
        direction = [0, 1, 0]
        color = [1, 0, 0]
        [output]
        path = "a.png"
        bits = 16
        window = 2.0
        level = 1
        colormap = "bone"
        [turntable]
        frames = 12
        fps = 6
        path = "spin.apng"
    "#;

    fn parse_cli(argv: &[&str]) -> (Cli, ArgMatches) {
        let m = Cli::command()
            .try_get_matches_from(argv)
            .expect("arguments parse");
        (Cli::from_arg_matches(&m).expect("arguments convert"), m)
    }

    fn merged_render(scene: &str, flags: &[&str]) -> RenderArgs {
        let mut argv = vec!["fvr", "render", "--scene", "s.toml"];
        argv.extend(flags);
        let (cli, m) = parse_cli(&argv);
        let Some(Command::Render(mut args)) = cli.command else {
            panic!("not a render")
        };
        let sub = m.subcommand_matches("render").expect("render matches");
        let scene = SceneFile::parse(scene, "s.toml", Path::new("/s")).expect("scene parses");
        apply_scene_to_render(&mut args, &scene, &|id| given_on_command_line(sub, id));
        *args
    }

    #[test]
    fn scene_fills_every_render_setting() {
        let a = merged_render(FULL_SCENE, &[]);
        assert_eq!(a.volume.as_deref(), Some("/s/v.raw"));
        assert_eq!(a.input.raw_dims, Some([4, 5, 6]));
        assert_eq!(a.input.raw_type, SampleType::U16);
        assert_eq!(a.input.raw_endian, Endian::Big);
        assert_eq!(a.input.background, Some(-1024.0));
        assert_eq!(a.resample, Some(96));
        assert_eq!(a.dir, Some([1.0, 0.5, -0.25]));
        assert_eq!(a.up, [0.0, 1.0, 0.0]);
        assert_eq!(a.size, Some((64, 32)));
        assert_eq!(a.units.pixel_size, Some(0.5));
        assert!(!a.units.ignore_spacing);
        assert_eq!(a.spectrum.filter, FilterKind::Cubic);
        assert_eq!(a.spectrum.oversample, 2);
        assert_eq!(a.spectrum.precision, Precision::F32);
        assert_eq!(a.spectrum.kb_design, KbDesign::Sigma(1.5));
        assert_eq!(a.ambient, Some([0.1; 3]));
        assert_eq!(a.depth_cue, "linear:1,0.3");
        assert_eq!(a.cue_harmonics, 6);
        assert!(a.no_cue_correction);
        assert_eq!(a.light_ring, Some((2, 10.0)));
        assert_eq!(
            a.lights,
            vec![Light {
                towards: [0.0, 1.0, 0.0],
                color: [1.0, 0.0, 0.0]
            }]
        );
        assert_eq!(a.out.as_deref(), Some(Path::new("/s/a.png")));
        assert_eq!(a.png.bits, Bits::Sixteen);
        assert_eq!((a.png.window, a.png.level), (Some(2.0), Some(1.0)));
        assert_eq!(a.png.colormap, Colormap::Bone);
        // An empty scene leaves the flags' defaults.
        let d = merged_render("", &["v.nrrd", "--dir", "0,1,0", "--out", "o.png"]);
        assert_eq!(d.spectrum.filter, FilterKind::Kb4);
        assert_eq!(d.up, DEFAULT_UP);
        assert_eq!(d.depth_cue, "none");
        assert!(!d.no_cue_correction && d.lights.is_empty() && d.light_ring.is_none());
    }

    #[test]
    fn each_flag_overrides_its_scene_key() {
        type Check = fn(&RenderArgs) -> bool;
        let cases: &[(&[&str], Check)] = &[
            (&["other.nrrd"], |a| {
                a.volume.as_deref() == Some("other.nrrd") && a.input.raw_dims.is_none()
            }),
            (&["--raw-dims", "7,8,9"], |a| {
                a.input.raw_dims == Some([7, 8, 9])
            }),
            (&["--raw-type", "f32"], |a| {
                a.input.raw_type == SampleType::F32
            }),
            (&["--raw-endian", "little"], |a| {
                a.input.raw_endian == Endian::Little
            }),
            (&["--background", "0"], |a| a.input.background == Some(0.0)),
            (&["--resample", "64"], |a| a.resample == Some(64)),
            (&["--dir", "0,0,1"], |a| a.dir == Some([0.0, 0.0, 1.0])),
            (&["--up", "1,0,0"], |a| a.up == [1.0, 0.0, 0.0]),
            (&["--size", "8"], |a| a.size == Some((8, 8))),
            (&["--pixel-size", "2"], |a| a.units.pixel_size == Some(2.0)),
            (&["--ignore-spacing"], |a| {
                a.units.ignore_spacing && a.units.pixel_size.is_none()
            }),
            (&["--filter", "kb3"], |a| {
                a.spectrum.filter == FilterKind::Kb3
            }),
            (&["--oversample", "1"], |a| a.spectrum.oversample == 1),
            (&["--precision", "f16"], |a| {
                a.spectrum.precision == Precision::F16
            }),
            (&["--kb-design", "auto"], |a| {
                a.spectrum.kb_design == KbDesign::Auto
            }),
            (&["--ambient", "0.5"], |a| a.ambient == Some([0.5; 3])),
            (&["--depth-cue", "none"], |a| a.depth_cue == "none"),
            (&["--cue-harmonics", "3"], |a| a.cue_harmonics == 3),
            (&["--light", "1,0,0:0,0,1"], |a| {
                a.lights
                    == [Light {
                        towards: [1.0, 0.0, 0.0],
                        color: [0.0, 0.0, 1.0],
                    }]
            }),
            (&["--light-ring", "3"], |a| a.light_ring == Some((3, 30.0))),
            (&["--out", "x.nrrd"], |a| {
                a.out.as_deref() == Some(Path::new("x.nrrd"))
            }),
            (&["--bits", "8"], |a| a.png.bits == Bits::Eight),
            (&["--window", "4", "--level", "3"], |a| {
                (a.png.window, a.png.level) == (Some(4.0), Some(3.0))
            }),
            (&["--percentiles", "1,99"], |a| {
                a.png.percentiles == (1.0, 99.0) && a.png.window.is_none()
            }),
            (&["--colormap", "hot"], |a| a.png.colormap == Colormap::Hot),
        ];
        let scene_only = merged_render(FULL_SCENE, &[]);
        for (flags, check) in cases {
            assert!(!check(&scene_only), "{flags:?} matches the scene already");
            assert!(check(&merged_render(FULL_SCENE, flags)), "{flags:?}");
        }
        // --no-cue-correction is a switch: the scene turns it on, the flag
        // cannot turn it off, and an unset scene key leaves it to the flag.
        let on = "[shading]\ncue_correction = true\n";
        assert!(merged_render(on, &["--no-cue-correction"]).no_cue_correction);
        assert!(!merged_render(on, &[]).no_cue_correction);
    }

    #[test]
    fn turntable_takes_scene_values_and_flags_win() {
        let run = |flags: &[&str]| {
            let mut argv = vec!["fvr", "turntable", "--scene", "s.toml"];
            argv.extend(flags);
            let (cli, m) = parse_cli(&argv);
            let Some(Command::Turntable(mut args)) = cli.command else {
                panic!("not a turntable")
            };
            let sub = m.subcommand_matches("turntable").expect("matches");
            let scene = SceneFile::parse(FULL_SCENE, "s.toml", Path::new("/s")).expect("parses");
            apply_scene_to_turntable(&mut args, &scene, &|id| given_on_command_line(sub, id));
            args
        };
        let a = run(&[]);
        assert_eq!((a.frames, a.fps), (12, 6));
        assert_eq!(a.out, PathBuf::from("/s/spin.apng"));
        assert_eq!(a.dir, [1.0, 0.5, -0.25]);
        assert_eq!(a.spectrum.filter, FilterKind::Cubic);
        let b = run(&[
            "--frames", "3", "--fps", "30", "--out", "t.apng", "--dir", "0,1,0",
        ]);
        assert_eq!((b.frames, b.fps), (3, 30));
        assert_eq!(b.out, PathBuf::from("t.apng"));
        assert_eq!(b.dir, [0.0, 1.0, 0.0]);
    }

    #[test]
    fn default_scene_is_a_valid_scene() {
        let scene = SceneFile::parse(DEFAULT_SCENE, "default", Path::new("")).expect("parses");
        assert!(scene.volume.spec.is_some() && scene.camera.dir.is_some());
        assert_eq!(scene.output.path, Some(PathBuf::from("fvr-default.png")));
    }
}
