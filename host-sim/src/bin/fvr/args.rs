//! Argument groups render and turntable share, and their value parsers.

use crate::Error;
use clap::Args;
use fvr_core::filter::FilterKind;
use fvr_core::volume::GridOversampling;
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::spectrum::Precision;
use fvr_engine::{Plan, Renderer, Settings, Units};
use fvr_host::image::output::{Bits, Colormap, Style, Window};
use fvr_host::io::nrrd::{Endian, SampleType};
use fvr_host::io::FORMATS_HELP;
use fvr_host::progress;
use fvr_host::scene_file::parse_endian;
use fvr_host::sources::datasets::DATASETS_HELP;
use fvr_host::sources::{load_volume_with_progress, RawLayout, PHANTOM_HELP};

/// How a PNG is made from the rendered values (render and turntable).
#[derive(Args, Clone)]
pub(crate) struct PngArgs {
    /// PNG bits per channel: 8 or 16.
    #[arg(long, default_value = "8")]
    pub(crate) bits: Bits,
    /// Window width W: values in [L - W/2, L + W/2] span black to white
    /// (needs --level). Default: automatic, from --percentiles.
    #[arg(long, requires = "level", allow_hyphen_values = true)]
    pub(crate) window: Option<f64>,
    /// Window level (centre) L; needs --window.
    #[arg(long, requires = "window", allow_hyphen_values = true)]
    pub(crate) level: Option<f64>,
    /// Automatic window: the LOW,HIGH percentiles of the pixel values.
    #[arg(long, value_parser = parse_percentiles, default_value = "0.5,99.5", conflicts_with = "window")]
    pub(crate) percentiles: (f64, f64),
    /// Colormap for the X-ray image: gray, bone or hot (MATLAB's maps, as
    /// tabulated in matplotlib).
    #[arg(long, default_value = "gray")]
    pub(crate) colormap: Colormap,
    /// How an X-ray PNG shows the line integrals p: `linear` (windowed as
    /// they are) or `film[:K]`, a radiograph's attenuation look, 1 − exp(−K·p),
    /// bright where matter attenuates; K (per mm × volume unit) defaults to
    /// 3 / (the 99th percentile of p), which shows the longest paths near
    /// white. Shown on [0, 1] unless --window or --percentiles is given.
    /// NRRD outputs keep the line integrals. Grey X-ray renders only.
    #[arg(long, default_value = "linear")]
    pub(crate) display: fvr_host::image::film::Display,
}

impl PngArgs {
    pub(crate) fn style(&self) -> Result<Style, Error> {
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

/// The image and the spectrum it is read from (render and turntable).
#[derive(Args, Clone, Copy, Default)]
pub(crate) struct FrameArgs {
    /// Image size W or WxH in pixels (of --pixel-size mm, or of one voxel
    /// with --ignore-spacing); at most the padded grid.
    /// Default: the padded grid divided by the oversampling.
    #[arg(long, value_parser = parse_size)]
    pub(crate) size: Option<(usize, usize)>,
    #[command(flatten)]
    pub(crate) units: UnitArgs,
    #[command(flatten)]
    pub(crate) spectrum: SpectrumArgs,
}

/// Physical units (render and turntable).
#[derive(Args, Clone, Copy, Default)]
pub(crate) struct UnitArgs {
    /// Pixel size in mm. Default: the smallest voxel spacing, or, if the
    /// volume's longest physical side would not fit the default image at
    /// that size, the size that fits it (longest side / default width).
    #[arg(
        long,
        value_name = "MM",
        conflicts_with = "ignore_spacing",
        allow_hyphen_values = true
    )]
    pub(crate) pixel_size: Option<f64>,
    /// Render in voxel units, as if the voxels were 1 mm cubes, ignoring the
    /// volume's spacing (the behaviour before spacing was used).
    #[arg(long)]
    pub(crate) ignore_spacing: bool,
}

impl UnitArgs {
    /// The engine's units for these flags.
    pub(crate) fn units(&self) -> Units {
        Units {
            ignore_spacing: self.ignore_spacing,
            pixel_size: self.pixel_size,
        }
    }
}

/// How the spectrum is made (render and turntable).
#[derive(Args, Clone, Copy)]
pub(crate) struct SpectrumArgs {
    /// Interpolation filter: nearest, linear, cubic, kb3, kb4, kb5, kb6.
    /// Default: chosen for --accuracy.
    #[arg(long, value_parser = parse_filter, default_value = "kb4", hide_default_value = true)]
    pub(crate) filter: FilterKind,
    /// Oversampling of the spectrum grid: 1, 1.25, 1.5 or 2 (1.25 and 1.5
    /// are mixed-radix grids, for plain X-ray views). Default: chosen for
    /// --accuracy.
    #[arg(
        long,
        default_value = "1",
        hide_default_value = true,
        value_parser = parse_oversample
    )]
    pub(crate) oversample: GridOversampling,
    /// Spectrum storage and arithmetic: f16 (f32 arithmetic), f32 or f64.
    /// Default: chosen for --accuracy.
    #[arg(long, default_value = "f16", hide_default_value = true)]
    pub(crate) precision: Precision,
    /// Kaiser-Bessel shape: `auto` fits beta to the volume's energy
    /// distribution; a number is the design oversampling of Beatty's formula.
    #[arg(long, default_value = "auto")]
    pub(crate) kb_design: KbDesign,
    /// Target SNR in dB against the exact projection: choose the cheapest
    /// filter, oversampling and precision predicted to reach it on this
    /// volume (--filter, --oversample and --precision given are kept).
    /// Default 50; with all three of those given and no --accuracy, they
    /// apply as given, with a warning below 40 dB predicted.
    #[arg(long, value_name = "DB", value_parser = parse_accuracy)]
    pub(crate) accuracy: Option<f64>,
    /// Which of the settings above were given on the command line.
    #[arg(skip)]
    pub(crate) given: crate::plan::Given,
    /// The prediction made for the settings used.
    #[arg(skip)]
    pub(crate) outcome: Option<crate::plan::Outcome>,
}

impl Default for SpectrumArgs {
    fn default() -> Self {
        Self {
            filter: FilterKind::Kb4,
            oversample: GridOversampling::X1,
            precision: Precision::F16,
            kb_design: KbDesign::Auto,
            accuracy: None,
            given: crate::plan::Given::default(),
            outcome: None,
        }
    }
}

pub(crate) fn parse_oversample(s: &str) -> Result<GridOversampling, String> {
    let x = s.trim().parse::<f64>().ok();
    GridOversampling::ALL
        .into_iter()
        .find(|g| Some(g.factor()) == x)
        .ok_or_else(|| format!("expected 1, 1.25, 1.5 or 2, got `{s}`"))
}

pub(crate) fn parse_accuracy(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("expected a positive number of decibels, got `{s}`")),
    }
}

/// How the volume is read (render and turntable).
#[derive(Args, Clone, Copy)]
pub(crate) struct InputArgs {
    /// Read VOLUME as a headerless raw file of these sizes X,Y,Z.
    #[arg(long, value_parser = parse_dims)]
    pub(crate) raw_dims: Option<[usize; 3]>,
    /// Sample type of a raw file: u8, i8, u16, i16, u32, i32, f32, f64.
    #[arg(long, default_value = "u8")]
    pub(crate) raw_type: SampleType,
    /// Byte order of a raw file: little or big.
    #[arg(long, default_value = "little", value_parser = parse_endian)]
    pub(crate) raw_endian: Endian,
    /// Value of empty space: voxels become max(value - B, 0) before
    /// rendering. Use -1024 for CT in Hounsfield units (air).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) background: Option<f64>,
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
    pub(crate) fn load(&self, spec: &str) -> Result<fvr_engine::volume::Volume, Error> {
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

pub(crate) fn parse_percentiles(s: &str) -> Result<(f64, f64), String> {
    let bad = || format!("expected percentiles LOW,HIGH with 0 <= LOW < HIGH <= 100, got `{s}`");
    let (lo, hi) = s.split_once(',').ok_or_else(bad)?;
    let lo = lo.trim().parse::<f64>().map_err(|_| bad())?;
    let hi = hi.trim().parse::<f64>().map_err(|_| bad())?;
    Window::from_percentiles(lo, hi).map_err(|_| bad())?;
    Ok((lo, hi))
}

pub(crate) fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
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

pub(crate) fn parse_dims(s: &str) -> Result<[usize; 3], String> {
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

pub(crate) fn parse_size(s: &str) -> Result<(usize, usize), String> {
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

pub(crate) fn parse_filter(s: &str) -> Result<FilterKind, String> {
    FilterKind::from_name(s).ok_or_else(|| {
        format!("unknown filter `{s}`: expected nearest, linear, cubic, kb3, kb4, kb5 or kb6")
    })
}

/// Load a volume with a progress bar on the bytes read.
pub(crate) fn load_with_progress(
    spec: &str,
    raw: Option<RawLayout>,
) -> Result<fvr_engine::volume::Volume, Error> {
    let bar = progress::bytes("loading");
    let volume = load_volume_with_progress(spec, raw, &bar);
    bar.finish_and_clear();
    Ok(volume?)
}

/// Prepare `volume` for `plan` ([`Renderer::prepare`]), with a spinner
/// naming the stage (the core's preparation is one call with no progress
/// of its own).
pub(crate) fn prepare_with_progress(
    volume: &fvr_engine::volume::Volume,
    settings: Settings,
    plan: Plan,
) -> Result<Renderer, Error> {
    let bar = progress::spinner("fitting filter");
    let renderer = Renderer::prepare(volume, settings, plan, &|stage: &str| {
        bar.set_message(stage.to_string())
    });
    bar.finish_and_clear();
    Ok(renderer?)
}

/// The spectra `scene` prepares, for [`plan_job`]: the volume's, and the
/// `|∇f|` spectrum when it is lit.
pub(crate) fn spectra(scene: &fvr_core::shading::Scene) -> u64 {
    if scene.needs_gradient_spectrum() {
        2
    } else {
        1
    }
}

/// Declare, before loading, what the job builds from its volume: `spectra`
/// spectra (2 with a `|∇f|` spectrum, which also needs a gradient volume),
/// on the grid of `resample` (or of the volume's longest side) at the
/// flags' oversampling and precision, and `per_grid(n, side)` bytes of
/// images or frames (named `label`) for a grid of side `n` and the default
/// image side `side`. Readers check it before decoding
/// ([`fvr_host::budget::check_load`]).
pub(crate) fn plan_job(
    spectrum: &SpectrumArgs,
    resample: Option<usize>,
    spectra: u64,
    (label, per_grid): (
        &'static str,
        impl Fn(u64, u64) -> u64 + Send + Sync + 'static,
    ),
    hint: &'static str,
) {
    let (grid, bytes) = (spectrum.oversample, spectrum.precision.bytes() as u64);
    fvr_host::budget::set_plan(hint, move |dims| {
        let largest = resample.unwrap_or_else(|| dims.iter().copied().max().unwrap_or(1));
        let n = grid.side([largest, 1, 1]).map_or(u64::MAX, |n| n as u64);
        // A grid too large for the volume's shape is refused later, by name.
        let thin =
            resample.is_none() && fvr_engine::volume::check_padding(dims, n as usize).is_err();
        let cells = if thin { 0 } else { n.saturating_pow(3) };
        let mut budget = fvr_host::budget::Budget::new();
        budget.hold("spectrum", cells.saturating_mul(spectra), bytes);
        // The fast preparation's complex half spectrum, one spectrum at a
        // time (fvr_engine::spectrum::prepare::fast_budget).
        let complex = if bytes == 8 { 16 } else { 8 };
        budget.hold(
            "preparation half spectrum",
            if thin {
                0
            } else {
                (n / 2 + 1).saturating_mul(n).saturating_mul(n)
            },
            complex,
        );
        if spectra > 1 {
            let count = dims.iter().fold(1u64, |a, &d| a.saturating_mul(d as u64));
            budget.hold("gradient volume", count, 4);
        }
        if let Some(r) = resample {
            budget.hold("resampled volume", (r as u64).saturating_pow(3), 4);
        }
        // fvr_engine::plan::image_side, from the largest side.
        let side = (largest as u64)
            .checked_next_power_of_two()
            .unwrap_or(u64::MAX)
            .min(n);
        budget.hold(label, per_grid(n, side), 1);
        budget
    });
}

pub(crate) fn volume_help() -> String {
    format!(
        "Volume: a file ({FORMATS_HELP}), a raw file (with --raw-dims), one of the {DATASETS_HELP}, or one of the {PHANTOM_HELP}"
    )
}

/// The image a job declares ([`plan_job`]'s `per_grid`): `size`, or the
/// default `side` square, each side at most the grid's `n` (a size beyond
/// the grid is refused later, by name).
pub(crate) fn planned_image(size: Option<(usize, usize)>, n: u64, side: u64) -> (u64, u64) {
    size.map_or((side, side), |(w, h)| {
        ((w as u64).min(n), (h as u64).min(n))
    })
}

/// One view's grids at f64 on a grid of side `n`: the slice, the column
/// walk's sums (2), a mixed side's transposed grid and the output.
pub(crate) fn view_grid_bytes(n: u64) -> u64 {
    n.saturating_mul(n).saturating_mul(40)
}
