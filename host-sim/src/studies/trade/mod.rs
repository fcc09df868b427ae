//! `fvr trade`: the speed–accuracy map from one command (issue 7).
//!
//! A sweep over filter × oversampling × storage format × adaptive tolerance ×
//! progressive level × volume size, on the Gaussian-mixture phantom, whose
//! line integrals are known exactly. Each point gets:
//! - the time per view: the median of `views × repeats` wall-clock renders
//!   on one thread, buffers allocated beforehand;
//! - the SNR in dB against the exact line integrals at the image's own
//!   pixel positions (for level `L`, every `2^L` voxels), the worst over the
//!   views;
//! - the memory held while rendering, computed from the sizes: spectrum,
//!   adaptive marks and per-view scratch.
//!
//! The outputs are a CSV ([`CSV_HEADER`]), a Pareto plot (PNG) and a
//! Markdown summary naming the settings on the Pareto front of each volume
//! size ([`pareto_front`]). A sweep whose largest point would not fit in
//! the memory available is refused before any work ([`Sweep::check_memory`]).

mod measure;
mod report;
#[cfg(test)]
mod tests;

pub use measure::{exact_at_pitch, measure, peak_rss, view_directions};
pub use report::{csv, dominates, mark_fronts, pareto_front, plot, summary, Row, CSV_HEADER};

pub use crate::budget::human_bytes;

use std::fmt::Write as _;

use fvr_core::dht::Twiddles;
use fvr_core::filter::{FilterKind, KernelTable};
use fvr_core::image::aux_len;
use fvr_core::num::{BlockLayout, Blocking, Format, FormatName};
use fvr_core::slice::adaptive::marks_words;
use fvr_core::spectrum::prepare_scratch_len;

use crate::options::parse_tolerance;
use crate::sources::{BLOB_COUNT, BLOB_SIGMA_FRACTION, DEFAULT_SEED, GAUSSIAN_COUNT};
use crate::studies::precision::parse_format;
use fvr_engine::slice::adaptive::Cheaper;
use fvr_engine::volume::phantom::GaussianMixture;

/// Largest volume side without `--large`.
pub const MAX_SIZE: usize = 256;
/// Largest volume side with `--large`.
pub const MAX_LARGE_SIZE: usize = 512;
/// Smallest volume side.
pub const MIN_SIZE: usize = 16;
/// Deepest progressive level swept.
pub const MAX_LEVEL: u32 = 3;
/// Smallest preview side a level may produce.
pub const MIN_PREVIEW_SIDE: usize = 8;
/// The cheaper filter of adaptive points: the paper's 1³ filter.
pub const ADAPTIVE_CHAIN: [Cheaper; 1] = [Cheaper::Filter(FilterKind::Nearest)];

/// The axes of a sweep as given (comma-separated lists), before
/// validation by [`Sweep::from_axes`].
#[derive(Debug, Clone)]
pub struct SweepAxes {
    /// Interpolation filters.
    pub filters: String,
    /// Oversampling factors.
    pub oversample: String,
    /// Storage formats of the spectrum.
    pub formats: String,
    /// Adaptive tolerances in dB, or `none`.
    pub adaptive: String,
    /// Progressive levels.
    pub levels: String,
    /// `gaussians` or `blobs`.
    pub phantom: String,
    /// Sides of the phantom.
    pub sizes: String,
    /// Allow sides up to [`MAX_LARGE_SIZE`].
    pub large: bool,
    /// View directions per point.
    pub views: usize,
    /// Timed renders of each view per point.
    pub repeats: usize,
}

/// One point of the sweep: every setting that changes a view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setting {
    /// Side of the cubic phantom.
    pub size: usize,
    /// Interpolation filter.
    pub filter: FilterKind,
    /// Oversampling factor (1 or 2).
    pub oversample: u32,
    /// Storage format of the spectrum.
    pub format: Format,
    /// Adaptive tolerance in dB, if adaptive.
    pub adaptive_db: Option<f64>,
    /// Progressive level.
    pub level: u32,
}

/// Bytes a point needs, computed from the sizes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Memory {
    /// The stored spectrum (block exponents included).
    pub spectrum: u64,
    /// Adaptive marks: one bit per spectrum sample per cheaper filter.
    pub marks: u64,
    /// Per-view scratch: kernel tables, twiddles, slice grid, auxiliary
    /// rows and the output image, all f32.
    pub scratch: u64,
    /// Transient, while preparing: the f32 volume and the transform scratch.
    pub prepare: u64,
}

impl Memory {
    /// Held while rendering: spectrum, marks and scratch.
    pub fn held(&self) -> u64 {
        self.spectrum + self.marks + self.scratch
    }

    /// The most the point needs at once: what is held, plus the volume and
    /// transform scratch of the preparation (counted in full, although the
    /// transform scratch is freed before rendering).
    pub fn peak(&self) -> u64 {
        self.held() + self.prepare
    }
}

impl Setting {
    /// Side of the padded spectrum.
    pub fn grid(&self) -> usize {
        (self.size * self.oversample as usize).next_power_of_two()
    }

    /// Side of the image: the volume's side divided by `2^level`.
    pub fn image_side(&self) -> usize {
        (self.size >> self.level).max(1)
    }

    /// The memory this point needs, from the sizes alone.
    pub fn memory(&self) -> Memory {
        let n = self.grid() as u64;
        let f32_bytes = 4u64;
        let spectrum =
            (self.format.bytes_per_voxel(self.grid()) * (n * n * n) as f64).ceil() as u64;
        let chain = if self.adaptive_db.is_some() {
            ADAPTIVE_CHAIN.len() as u64
        } else {
            0
        };
        let marks = chain * marks_words(self.grid()) as u64 * 4;
        let m = n >> self.level;
        let grid = if self.adaptive_db.is_some() {
            n * n
        } else {
            m * m
        };
        let image = (self.image_side() * self.image_side()) as u64;
        let tables = (1 + chain) * std::mem::size_of::<KernelTable<f32>>() as u64;
        let twiddles = Twiddles::<f32>::buffer_len(self.grid()) as u64;
        let scratch = tables + f32_bytes * (twiddles + grid + aux_len(m as usize) as u64 + image);
        let volume = (self.size as u64).pow(3) * f32_bytes;
        let line_exponents = match self.format {
            Format::Q15(Blocking::Blocks(BlockLayout::Line)) => 2 * n * n,
            _ => 0,
        };
        let prepare = volume
            + line_exponents
            + f32_bytes * (prepare_scratch_len(self.grid()) as u64 + twiddles);
        Memory {
            spectrum,
            marks,
            scratch,
            prepare,
        }
    }

    /// The settings in words, e.g. `kb3 σ=2 f16 adaptive 40 dB level 1`.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "{} σ={} {}",
            self.filter.name(),
            self.oversample,
            FormatName(self.format)
        );
        if let Some(db) = self.adaptive_db {
            let _ = write!(s, " adaptive {db} dB");
        }
        if self.level > 0 {
            let _ = write!(s, " level {}", self.level);
        }
        s
    }
}

/// The phantoms `fvr trade` measures on: Gaussian mixtures, whose line
/// integrals are exact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TradePhantom {
    /// `gaussians@N`: 8 Gaussians, σ from 1.5 to 0.12·N voxels.
    Gaussians,
    /// `blobs@N`: 24 Gaussians, σ from 1.5 to 0.05·N voxels.
    Blobs,
}

impl TradePhantom {
    /// The phantom's name, as in `fvr render`.
    pub fn name(self) -> &'static str {
        match self {
            TradePhantom::Gaussians => "gaussians",
            TradePhantom::Blobs => "blobs",
        }
    }

    /// The mixture at side `n`, with the default seed.
    pub fn mixture(self, n: usize) -> GaussianMixture {
        match self {
            TradePhantom::Gaussians => GaussianMixture::random(DEFAULT_SEED, n, GAUSSIAN_COUNT),
            TradePhantom::Blobs => {
                GaussianMixture::random_with(DEFAULT_SEED, n, BLOB_COUNT, BLOB_SIGMA_FRACTION)
            }
        }
    }
}

/// A validated sweep: every axis non-empty and every value usable.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// The phantom.
    pub phantom: TradePhantom,
    /// Phantom sides.
    pub sizes: Vec<usize>,
    /// Filters.
    pub filters: Vec<FilterKind>,
    /// Oversampling factors.
    pub oversamples: Vec<u32>,
    /// Storage formats.
    pub formats: Vec<Format>,
    /// Adaptive tolerances (`None`: full filter).
    pub adaptive: Vec<Option<f64>>,
    /// Progressive levels.
    pub levels: Vec<u32>,
    /// View directions per point.
    pub views: usize,
    /// Timed renders of each view.
    pub repeats: usize,
}

/// Split a comma-separated axis, refusing an empty list or entry, and
/// parse each entry; duplicates are dropped, the order kept.
pub(crate) fn axis<T: PartialEq>(
    option: &str,
    text: &str,
    parse: impl Fn(&str) -> Result<T, String>,
) -> Result<Vec<T>, String> {
    if text.trim().is_empty() {
        return Err(format!("--{option} is empty: give at least one value"));
    }
    let mut out = Vec::new();
    for item in text.split(',') {
        let item = item.trim();
        if item.is_empty() {
            return Err(format!("--{option} `{text}` has an empty entry"));
        }
        let v = parse(item).map_err(|e| format!("--{option}: {e}"))?;
        if !out.contains(&v) {
            out.push(v);
        }
    }
    Ok(out)
}

fn filter_names() -> String {
    FilterKind::ALL.map(FilterKind::name).join(", ")
}

/// The formats `fvr trade` prepares in place (16- and 32-bit, per pass).
pub(crate) const FORMATS_HELP: &str =
    "f16, bf16, f32, a 16-bit minifloat eEmM (e.g. e4m11), q15, q15-line";

fn parse_trade_format(s: &str) -> Result<Format, String> {
    let f = parse_format(s)?;
    match f {
        Format::F16
        | Format::Bf16
        | Format::F32
        | Format::Q15(Blocking::Volume)
        | Format::Q15(Blocking::Blocks(BlockLayout::Line)) => Ok(f),
        Format::Minifloat16(e) if [2, 3, 4, 6, 7].contains(&e) => Ok(f),
        _ => Err(format!(
            "format `{s}` is not swept (f64 is the reference; 8-bit and per-brick formats are \
             in `fvr precision`): use {FORMATS_HELP}"
        )),
    }
}

impl Sweep {
    /// Validate the arguments. Every error comes before any work and names
    /// the option.
    ///
    /// # Errors
    /// An empty axis or entry, an unknown filter (naming the valid ones), an
    /// unsupported format, a size out of range (512 needs `--large`), a level
    /// too deep for a size, zero views or repeats, and conflicting options:
    /// adaptive tolerances with oversampling 1 only, with levels above 0
    /// only, or with the nearest filter only.
    pub fn from_axes(args: &SweepAxes) -> Result<Self, String> {
        let filters = axis("filters", &args.filters, |s| {
            FilterKind::from_name(s)
                .ok_or_else(|| format!("unknown filter `{s}`: valid are {}", filter_names()))
        })?;
        let oversamples = axis("oversample", &args.oversample, |s| match s {
            "1" => Ok(1u32),
            "2" => Ok(2),
            _ => Err(format!("oversampling `{s}` must be 1 or 2")),
        })?;
        let formats = axis("formats", &args.formats, parse_trade_format)?;
        let adaptive = axis("adaptive", &args.adaptive, |s| {
            if s == "none" {
                Ok(None)
            } else {
                parse_tolerance(s)
                    .map(Some)
                    .map_err(|e| format!("{e} or `none`"))
            }
        })?;
        let max_size = if args.large { MAX_LARGE_SIZE } else { MAX_SIZE };
        let sizes = axis("sizes", &args.sizes, |s| {
            let n: usize = s
                .parse()
                .map_err(|_| format!("size `{s}` is not a whole number"))?;
            if n > MAX_SIZE && n <= MAX_LARGE_SIZE && !args.large {
                return Err(format!(
                    "size {n} is above {MAX_SIZE}: add --large to sweep up to {MAX_LARGE_SIZE}"
                ));
            }
            if !(MIN_SIZE..=max_size).contains(&n) {
                return Err(format!("size {n} is outside {MIN_SIZE} to {max_size}"));
            }
            Ok(n)
        })?;
        let levels = axis("levels", &args.levels, |s| match s.parse::<u32>() {
            Ok(l) if l <= MAX_LEVEL => Ok(l),
            _ => Err(format!("level `{s}` must be 0 to {MAX_LEVEL}")),
        })?;
        let smallest = *sizes.iter().min().expect("axis is non-empty");
        if let Some(&l) = levels.iter().find(|&&l| smallest >> l < MIN_PREVIEW_SIDE) {
            return Err(format!(
                "--levels {l} with --sizes {smallest}: the preview would be {} pixels wide, \
                 below {MIN_PREVIEW_SIDE}",
                smallest >> l
            ));
        }
        if args.views == 0 || args.repeats == 0 {
            return Err(format!(
                "--views {} --repeats {}: both must be at least 1",
                args.views, args.repeats
            ));
        }
        super::check_repeats("--repeats", args.repeats)?;
        if args.views > 64 {
            return Err(format!("--views {}: at most 64", args.views));
        }
        if let Some(db) = adaptive.iter().flatten().next() {
            let conflict = if !oversamples.contains(&2) {
                Some("needs --oversample 2 (marks at oversampling 1 would leave no sample weak enough: the filters' response ratio is too large at the grid's edge)")
            } else if !levels.contains(&0) {
                Some("needs level 0 in --levels (progressive previews are not adaptive)")
            } else if filters.iter().all(|&f| f == FilterKind::Nearest) {
                Some("needs a filter wider than nearest in --filters (nearest is the cheaper filter)")
            } else {
                None
            };
            if let Some(why) = conflict {
                return Err(format!("--adaptive {db} {why}"));
            }
        }
        let phantom = match args.phantom.as_str() {
            "gaussians" => TradePhantom::Gaussians,
            "blobs" => TradePhantom::Blobs,
            other => {
                return Err(format!(
                    "--phantom `{other}`: expected gaussians or blobs (Gaussian mixtures, whose \
                     line integrals are exact)"
                ))
            }
        };
        Ok(Self {
            phantom,
            sizes,
            filters,
            oversamples,
            formats,
            adaptive,
            levels,
            views: args.views,
            repeats: args.repeats,
        })
    }

    /// Every point, in the order measured: by size, filter, oversampling,
    /// format, adaptive tolerance, level. Adaptive points exist only at
    /// oversampling 2, level 0 and for filters wider than nearest.
    pub fn settings(&self) -> Vec<Setting> {
        let mut out = Vec::new();
        for &size in &self.sizes {
            for &filter in &self.filters {
                for &oversample in &self.oversamples {
                    for &format in &self.formats {
                        for &adaptive_db in &self.adaptive {
                            for &level in &self.levels {
                                let s = Setting {
                                    size,
                                    filter,
                                    oversample,
                                    format,
                                    adaptive_db,
                                    level,
                                };
                                if adaptive_db.is_none() || adaptive_allowed(&s) {
                                    out.push(s);
                                }
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// Refuse the sweep if its largest point needs more than `available`
    /// bytes.
    ///
    /// # Errors
    /// The message names the point, what it needs and what is available.
    pub fn check_memory(&self, available: u64, source: &str) -> Result<(), String> {
        let settings = self.settings();
        let Some(worst) = settings.iter().max_by_key(|s| s.memory().peak()) else {
            return Ok(());
        };
        let m = worst.memory();
        let refs = (self.views * worst.size * worst.size * 8) as u64;
        let need = m.peak() + refs;
        if need > available {
            return Err(format!(
                "the sweep's largest point ({}³, {}) needs {} (spectrum {}, marks {}, view \
                 scratch {}, volume and transform scratch {}), but only {} is available \
                 ({source}): leave out the largest sizes, oversampling 2 or f32",
                worst.size,
                worst.describe(),
                human_bytes(need),
                human_bytes(m.spectrum),
                human_bytes(m.marks),
                human_bytes(m.scratch),
                human_bytes(m.prepare),
                human_bytes(available)
            ));
        }
        Ok(())
    }
}

fn adaptive_allowed(s: &Setting) -> bool {
    s.oversample == 2 && s.level == 0 && s.filter.width() > ADAPTIVE_CHAIN[0].width()
}
