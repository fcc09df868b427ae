//! `fvr`: frequency-domain volume rendering from the command line.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::{Args, Parser, Subcommand};
use fvr_core::filter::FilterKind;
use fvr_core::geometry::{View, DEFAULT_UP};
use fvr_core::scene::{Light, Scene, MAX_LIGHTS};
use fvr_host::adaptive::{parse_chain, parse_tolerance};
use fvr_host::datasets::DATASETS_HELP;
use fvr_host::formats::FORMATS_HELP;
use fvr_host::nrrd::{read_nrrd, Endian, SampleType};
use fvr_host::output::{write_apng, write_png, Bits, Colormap, Style, Window};
use fvr_host::pipeline::{choose_filter, AnySpectrum, KbDesign, Precision};
use fvr_host::reference::{exact_projection, max_abs_error, snr_db};
use fvr_host::scene::{load_volume_with_progress, phantom_by_name, RawLayout, PHANTOM_HELP};
use fvr_host::scene_reference::exact_scene_projection;
use fvr_host::shaded::{
    light_ring, negative_cue_share, parse_depth_cue, parse_light, parse_light_ring, parse_rgb,
    SceneRenderer, SceneSpectra, DEFAULT_PROFILE_HARMONICS, DEPTH_CUE_HELP,
};
use fvr_host::{progress, turntable};

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

EXIT STATUS
  0  success (also for --help and --version)
  2  any error: bad arguments, unreadable or malformed input, a render that
     cannot be done; the reason is printed on stderr as `fvr: error: ...`
     (argument errors are explained by the parser, with a usage line).

Progress bars go to stderr only when it is a terminal; --quiet turns them off.";

/// Frequency-domain volume rendering (Totsuka & Levoy 1993): X-ray
/// projections, depth cueing and shading from a 16-bit Hartley spectrum.
/// With no subcommand, renders the built-in default scene to
/// `fvr-default.png`: `fvr render blobs@128:4 --dir 1,0.45,-0.3 --light-ring 3
/// --ambient 0.05 --stats`.
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
    Precision(fvr_host::precision_cli::PrecisionArgs),
    /// The speed-accuracy map: time per view, SNR against exact line
    /// integrals and memory held over filter, oversampling, storage format,
    /// adaptive tolerance, progressive level and volume size, on the
    /// Gaussian-mixture phantom; writes trade.csv, trade.png (dB against ms,
    /// Pareto fronts) and trade.md (the settings on each front).
    Trade(fvr_host::trade::TradeArgs),
    /// The paper's Table 1 measured here: filter taps and time per view with
    /// and without adaptive filtering, and the spatial-domain ray caster, on
    /// the CT head (resampled to 128 along its longest side), a 256³ volume
    /// and a phantom. Prints Markdown.
    AdaptiveTable {
        /// Tolerance in dB.
        #[arg(long, default_value_t = 40.0, value_parser = parse_tolerance)]
        tolerance: f64,
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
    #[arg(help = volume_help())]
    volume: String,
    /// View direction X,Y,Z, from the eye into the scene.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    dir: [f64; 3],
    /// Up hint X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,1")]
    up: [f64; 3],
    /// Image size W or WxH in pixels of one voxel; at most the padded grid.
    /// Default: the padded grid divided by the oversampling.
    #[arg(long, value_parser = parse_size)]
    size: Option<(usize, usize)>,
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
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    png: PngArgs,
    /// Print timing, memory and filter details.
    #[arg(long)]
    stats: bool,
    /// Resample to cubic voxels with N samples along the longest physical
    /// side (trilinear) before rendering: for anisotropic data such as CT
    /// (0.957 x 0.957 x 1.5 mm), which is otherwise rendered in voxel units.
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
    /// for the filter pair (the paper used 0.3). A smaller value than the
    /// filters' own voids the guarantee; --stats then shows the SNR reached.
    #[arg(long, value_name = "H")]
    adaptive_hd: Option<f64>,
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
    #[arg(help = volume_help())]
    volume: String,
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
    /// Image size W or WxH in pixels of one voxel; at most the padded grid.
    /// Default: the padded grid divided by the oversampling.
    #[arg(long, value_parser = parse_size)]
    size: Option<(usize, usize)>,
    #[command(flatten)]
    spectrum: SpectrumArgs,
    /// Output file: .apng or .png (an animated PNG either way).
    #[arg(long, default_value = "spin.apng")]
    out: PathBuf,
    #[command(flatten)]
    png: PngArgs,
    #[command(flatten)]
    input: InputArgs,
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

fn parse_endian(s: &str) -> Result<Endian, String> {
    match s {
        "little" => Ok(Endian::Little),
        "big" => Ok(Endian::Big),
        _ => Err(format!("unknown byte order `{s}`: expected little or big")),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    progress::set_quiet(cli.quiet);
    let result = match cli.command {
        None => default_scene(),
        Some(Command::Render(args)) => render(&args),
        Some(Command::Turntable(args)) => turntable(&args),
        Some(Command::Compare { a, b }) => compare(&a, &b),
        Some(Command::Accuracy { sizes }) => accuracy(&sizes),
        Some(Command::AdaptiveTable {
            tolerance,
            filter,
            oversample,
            volumes,
            runs,
        }) => adaptive_table(tolerance, filter, oversample, &volumes, runs),
        Some(Command::Precision(args)) => fvr_host::precision_cli::run(&args),
        Some(Command::Trade(args)) => fvr_host::trade::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fvr: error: {e}");
            ExitCode::from(2)
        }
    }
}

fn default_scene() -> Result<(), String> {
    let args = RenderArgs {
        volume: "blobs@128:4".into(),
        dir: [1.0, 0.45, -0.3],
        up: DEFAULT_UP,
        size: None,
        spectrum: SpectrumArgs::default(),
        depth_cue: "none".into(),
        cue_harmonics: DEFAULT_PROFILE_HARMONICS,
        ambient: Some([0.05; 3]),
        lights: Vec::new(),
        light_ring: Some((3, 30.0)),
        no_cue_correction: false,
        out: PathBuf::from("fvr-default.png"),
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
        preview_level: 0,
        exact: false,
        input: InputArgs::default(),
    };
    println!(
        "fvr: rendering the default scene: 24 Gaussian blobs lit by red, green and blue lights \
         120 degrees apart, as in the paper's figure 8 (run `fvr --help` for options)"
    );
    render(&args)
}

fn render(args: &RenderArgs) -> Result<(), String> {
    let ext = args.out.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext != "png" && ext != "nrrd" {
        return Err(format!(
            "output `{}` must end in .png or .nrrd",
            args.out.display()
        ));
    }
    let view = View {
        dir: args.dir,
        up: args.up,
    };
    view.frame().map_err(|e| e.to_string())?;
    let style = args.png.style()?;
    let t0 = Instant::now();
    let mut volume = args.input.load(&args.volume)?;
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
    let (w, h) = args.size.unwrap_or((
        n / args.spectrum.oversample as usize,
        n / args.spectrum.oversample as usize,
    ));
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
    let mut adaptive_report = None;
    let t2 = Instant::now();
    let (image, w, h) = if args.preview_level > 0 {
        let (pw, ph) = fvr_core::progressive::preview_size(w, h, args.preview_level);
        let data = spectra
            .density
            .render_level(&view, pw, ph, args.preview_level)
            .map_err(|e| e.to_string())?;
        (
            fvr_host::shaded::Image {
                channels: 1,
                width: pw,
                height: ph,
                data: data.into_iter().map(|v| v * scene.ambient[0]).collect(),
            },
            pw,
            ph,
        )
    } else if let Some(tolerance) = args.adaptive {
        let report = adaptive_render(
            &spectra.density,
            &view,
            w,
            h,
            tolerance,
            &parse_chain(&args.adaptive_chain)?,
            args.adaptive_hd,
        )?;
        let data = report.image.iter().map(|v| v * scene.ambient[0]).collect();
        adaptive_report = Some(report);
        (
            fvr_host::shaded::Image {
                channels: 1,
                width: w,
                height: h,
                data,
            },
            w,
            h,
        )
    } else {
        let image = spectra
            .render(&scene, &view, w, h)
            .map_err(|e| e.to_string())?;
        (image, w, h)
    };
    let t_view = adaptive_report
        .as_ref()
        .map_or(t2.elapsed(), |r| r.view_time);
    if ext == "png" {
        if image.channels == 1 {
            write_png(&args.out, w, h, &image.data, &style)?;
        } else {
            image.write_png(&args.out)?;
        }
    } else {
        image.write_nrrd(&args.out)?;
    }
    let kind = if image.channels == 1 { "grey" } else { "RGB" };
    println!("wrote {} ({w}x{h} {kind})", args.out.display());
    if args.stats && !args.stats_json {
        let d = volume.dims;
        println!(
            "  volume        {}x{}x{} ({})",
            d[0], d[1], d[2], args.volume
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
                "  level         {} ({w}x{h} at pitch {} voxels, central 1/{} of the slice)",
                args.preview_level,
                1u64 << args.preview_level,
                1u64 << (2 * args.preview_level)
            );
        }
        if let Some(r) = &adaptive_report {
            r.print_human();
        }
    }
    if args.stats_json {
        let mut fields = vec![
            ("volume", json_str(&args.volume)),
            ("dims", format!("{:?}", volume.dims)),
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
        match phantom_by_name(&args.volume) {
            Some(Ok(p)) if plain => {
                let exact = exact_projection(p.phantom.as_ref(), volume.dims, &view, w, h)
                    .map_err(|e| e.to_string())?;
                let ambient = scene.ambient[0];
                let exact: Vec<f64> = exact.iter().map(|v| v * ambient).collect();
                println!("  SNR vs exact  {:.2} dB", snr_db(&exact, &image.data));
            }
            Some(Ok(p)) => match p.phantom.as_gaussian_mixture() {
                Some(mixture) => {
                    let exact =
                        exact_scene_projection(mixture, volume.dims, &scene, &view, w, h, 0.05)
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

/// The scene from the command line: cue, ambient, lights.
fn build_scene(args: &RenderArgs) -> Result<Scene, String> {
    let cue = parse_depth_cue(&args.depth_cue, args.cue_harmonics)?;
    let mut lights = args.lights.clone();
    if let Some((count, tilt)) = args.light_ring {
        let view = View {
            dir: args.dir,
            up: args.up,
        };
        lights.extend(light_ring(&view, count, tilt).map_err(|e| e.to_string())?);
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
    let volume = args.input.load(&args.volume)?;
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
    let bar = progress::count(views.len() as u64, "frames");
    let t2 = Instant::now();
    let frames = turntable::render_views(&spec, &views, w, h, &bar);
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
    println!(
        "  load {:.1} ms, preprocess {:.1} ms ({n}^3 {}), {} views in {:.1} ms = {:.1} views/s",
        t_load.as_secs_f64() * 1e3,
        t_prep.as_secs_f64() * 1e3,
        args.spectrum.precision,
        frames.len(),
        secs * 1e3,
        frames.len() as f64 / secs.max(1e-9)
    );
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
    let rows = fvr_host::accuracy::accuracy_table(sizes).map_err(|e| e.to_string())?;
    print!("{}", fvr_host::accuracy::markdown(&rows));
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
    marks: fvr_host::adaptive::AdaptiveMarks,
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
                    "{{\"filter\": {}, \"h_d\": {}, \"threshold\": {}, \"marked\": {}, \"samples\": {}}}",
                    json_str(l.filter.kind().name()),
                    json_num(l.h_d),
                    json_num(l.threshold),
                    l.marked,
                    s.per_filter[i + 1]
                )
            })
            .collect();
        format!(
            "{{\"tolerance_db\": {}, \"taps\": {}, \"full_taps\": {}, \"taps_ratio\": {}, \
             \"samples\": {}, \"full_filter_samples\": {}, \"levels\": [{}], \"marks_bytes\": {}, \
             \"mark_ms\": {}, \"view_ms\": {}, \"full_view_ms\": {}, \"snr_vs_full_db\": {}, \
             \"note\": {}}}",
            json_num(self.marks.tolerance_db),
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
    tolerance: f64,
    chain: &[FilterKind],
    h_d: Option<f64>,
) -> Result<AdaptiveReport, String> {
    fn go<S: fvr_core::real::Sample, T: fvr_core::real::Real>(
        any: &AnySpectrum,
        spec: &fvr_host::pipeline::OwnedSpectrum<S>,
        view: &View,
        w: usize,
        h: usize,
        tolerance: f64,
        chain: &[FilterKind],
        h_d: Option<f64>,
    ) -> Result<AdaptiveReport, String> {
        let t0 = Instant::now();
        let marks = fvr_host::adaptive::AdaptiveMarks::build(spec, tolerance, chain, h_d)?;
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
        AnySpectrum::F16(s) => go::<_, f32>(spec, s, view, w, h, tolerance, chain, h_d),
        AnySpectrum::F32(s) => go::<_, f32>(spec, s, view, w, h, tolerance, chain, h_d),
        AnySpectrum::F64(s) => go::<_, f64>(spec, s, view, w, h, tolerance, chain, h_d),
    }
}

fn adaptive_table(
    tolerance: f64,
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
        rows.push(fvr_host::adaptive::table1_row(
            name,
            &volume,
            filter,
            &[FilterKind::Nearest],
            tolerance,
            &view,
            runs.max(1),
        )?);
        eprintln!("fvr: measured {name}");
    }
    print!("{}", fvr_host::adaptive::table1_markdown(&rows, tolerance));
    Ok(())
}
