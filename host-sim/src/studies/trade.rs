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

use std::fmt::Write as _;
use std::time::Instant;

use fvr_core::adaptive::{extract_slice_adaptive, marks_words, AdaptiveLevel, Marks};
use fvr_core::dht::{Rounding, Twiddles};
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::format::{bf16, BlockLayout, Blocking, Format, FormatName, Minifloat16, Q15};
use fvr_core::geometry::View;
use fvr_core::progressive::render_level;
use fvr_core::real::Sample;
use fvr_core::render::{aux_len, finish_projection, placement, render};
use fvr_core::spectrum::{prepare_scratch_len, Spectrum};
use half::f16;

use crate::image::plot::{Canvas, Overlay, Point, Scatter};
use crate::reference::snr_db;
use crate::render::adaptive::{parse_tolerance, AdaptiveMarks, AdaptiveSettings, Bound};
use crate::render::spectrum::{choose_filter, KbDesign};
use crate::sources::phantom::{sample, GaussianMixture, Phantom};
use crate::sources::{BLOB_COUNT, BLOB_SIGMA_FRACTION, DEFAULT_SEED, GAUSSIAN_COUNT};
use crate::studies::precision::{parse_format, StoredSpectrum};
use crate::volume::Volume;

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
/// The cheaper filter of adaptive points (the project's default chain).
pub const ADAPTIVE_CHAIN: [FilterKind; 1] = [FilterKind::Nearest];

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
fn axis<T: PartialEq>(
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
const FORMATS_HELP: &str = "f16, bf16, f32, a 16-bit minifloat eEmM (e.g. e4m11), q15, q15-line";

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

/// Parse a byte count with an optional `K`, `M` or `G` suffix (powers of 1024).
///
/// # Errors
/// Anything else, or an overflow.
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (digits, shift) = match t.char_indices().last() {
        Some((i, 'K' | 'k')) => (&t[..i], 10),
        Some((i, 'M' | 'm')) => (&t[..i], 20),
        Some((i, 'G' | 'g')) => (&t[..i], 30),
        _ => (t, 0),
    };
    digits
        .parse::<u64>()
        .ok()
        .and_then(|v| v.checked_mul(1u64 << shift))
        .ok_or_else(|| {
            format!("--memory-limit `{s}`: expected a number of bytes, optionally with K, M or G")
        })
}

/// Bytes in binary units, e.g. `1.5 GiB`.
pub fn human_bytes(b: u64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < units.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", units[u])
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

/// The view directions: azimuth `20° + i·137.5°` (the golden angle), and
/// elevation cycling through 25°, −15°, 40°, 5°, −30°. None is along an
/// axis (axis-aligned slices fall on grid planes and flatter the cheap
/// filters) nor parallel to the default up hint.
pub fn view_directions(count: usize) -> Vec<[f64; 3]> {
    const ELEVATIONS: [f64; 5] = [25.0, -15.0, 40.0, 5.0, -30.0];
    (0..count)
        .map(|i| {
            let az = (20.0 + 137.507_764 * i as f64).to_radians();
            let el = ELEVATIONS[i % ELEVATIONS.len()].to_radians();
            [az.cos() * el.cos(), az.sin() * el.cos(), el.sin()]
        })
        .collect()
}

/// Exact line integrals of `phantom` at the pixels of a `width × height`
/// image `pitch` voxels apart: pixel `(col, row)` at
/// `c + (col − W/2)·pitch·r + (H/2 − row)·pitch·u` (the placement of
/// [`fvr_core::progressive`]).
///
/// # Errors
/// Bad view vectors.
pub fn exact_at_pitch(
    phantom: &dyn Phantom,
    dims: [usize; 3],
    view: &View,
    width: usize,
    height: usize,
    pitch: f64,
) -> Result<Vec<f64>, fvr_core::Error> {
    let frame = view.frame()?;
    let c = dims.map(|d| d as f64 / 2.0);
    let mut out = Vec::with_capacity(width * height);
    for row in 0..height {
        for col in 0..width {
            let p = frame.pixel_position(c, width, height, col as f64, row as f64);
            let p = core::array::from_fn(|i| c[i] + pitch * (p[i] - c[i]));
            out.push(phantom.line_integral(p, frame.dir));
        }
    }
    Ok(out)
}

/// `flags[i]` is true when point `i` is on the Pareto front of
/// `(ms, dB)`: no other point is at least as fast and at least as accurate
/// and strictly better in one. Points with a non-finite coordinate are
/// never on the front and dominate nothing.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let ok = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    points
        .iter()
        .map(|p| ok(p) && !points.iter().any(|q| ok(q) && dominates(*q, *p)))
        .collect()
}

/// `a` dominates `b`: no slower, no less accurate, and better in one.
pub fn dominates(a: (f64, f64), b: (f64, f64)) -> bool {
    a.0 <= b.0 && a.1 >= b.1 && (a.0 < b.0 || a.1 > b.1)
}

/// One measured point.
#[derive(Clone, Debug)]
pub struct Row {
    /// What was measured.
    pub setting: Setting,
    /// Median time per view, ms.
    pub ms_per_view: f64,
    /// Fastest view, ms.
    pub ms_min: f64,
    /// Worst SNR over the views against the exact line integrals, dB.
    pub snr_db: f64,
    /// Mean SNR over the views, dB.
    pub snr_mean_db: f64,
    /// Memory, from the sizes.
    pub memory: Memory,
    /// Time to prepare the spectrum (filter fit, premultiply, 3D transform), ms.
    pub prepare_ms: f64,
    /// Filter taps read relative to the full filter, adaptive points only.
    pub taps_fraction: Option<f64>,
    /// The process's peak resident set so far (VmHWM), bytes, if readable.
    pub peak_rss: Option<u64>,
    /// On the Pareto front of its volume size.
    pub pareto: bool,
}

/// The CSV header; the columns are documented in `docs/trade/README.md`.
pub const CSV_HEADER: &str = "size,grid,filter,oversample,format,adaptive_db,level,image_side,\
views,repeats,ms_per_view,ms_min,snr_db,snr_mean_db,spectrum_bytes,marks_bytes,scratch_bytes,\
held_bytes,prepare_ms,adaptive_taps_fraction,peak_rss_bytes,pareto";

/// The rows as CSV, with [`CSV_HEADER`].
pub fn csv(rows: &[Row], views: usize, repeats: usize) -> String {
    let mut s = format!("{CSV_HEADER}\n");
    for r in rows {
        let st = &r.setting;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{:.6},{:.6},{:.2},{:.2},{},{},{},{},{:.1},{},{},{}",
            st.size,
            st.grid(),
            st.filter.name(),
            st.oversample,
            FormatName(st.format),
            st.adaptive_db.map_or("none".to_string(), |d| d.to_string()),
            st.level,
            st.image_side(),
            views,
            repeats,
            r.ms_per_view,
            r.ms_min,
            r.snr_db,
            r.snr_mean_db,
            r.memory.spectrum,
            r.memory.marks,
            r.memory.scratch,
            r.memory.held(),
            r.prepare_ms,
            r.taps_fraction.map_or(String::new(), |t| format!("{t:.4}")),
            r.peak_rss.map_or(String::new(), |b| b.to_string()),
            u8::from(r.pareto)
        );
    }
    s
}

/// `v` as the CSV prints it: ms to the nanosecond, dB to 0.01, so that
/// the CSV's `pareto` flags are the front of the CSV's own figures.
fn as_printed(v: f64, decimals: usize) -> f64 {
    format!("{v:.decimals$}").parse().unwrap_or(v)
}

/// Mark the Pareto front of each volume size in `rows`, on the figures as
/// the CSV prints them.
pub fn mark_fronts(rows: &mut [Row]) {
    let mut sizes: Vec<usize> = rows.iter().map(|r| r.setting.size).collect();
    sizes.sort_unstable();
    sizes.dedup();
    for size in sizes {
        let idx: Vec<usize> = (0..rows.len())
            .filter(|&i| rows[i].setting.size == size)
            .collect();
        let pts: Vec<(f64, f64)> = idx
            .iter()
            .map(|&i| {
                (
                    as_printed(rows[i].ms_per_view, 6),
                    as_printed(rows[i].snr_db, 2),
                )
            })
            .collect();
        for (&i, on) in idx.iter().zip(pareto_front(&pts)) {
            rows[i].pareto = on;
        }
    }
}

/// Peak resident set size of this process (VmHWM), bytes.
pub fn peak_rss() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: u64 = s
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    kb.checked_mul(1024)
}

/// The phantom of one size with its exact images, per view and level.
struct Subject {
    volume: Volume,
    views: Vec<View>,
    /// `exact[level][view]`.
    exact: Vec<Vec<Vec<f64>>>,
}

impl Subject {
    fn new(
        phantom: TradePhantom,
        size: usize,
        views: usize,
        levels: &[u32],
    ) -> Result<Self, String> {
        let dims = [size; 3];
        let phantom = phantom.mixture(size);
        let volume = sample(&phantom, dims);
        let views: Vec<View> = view_directions(views)
            .into_iter()
            .map(View::along)
            .collect();
        let deepest = levels.iter().copied().max().unwrap_or(0);
        let exact = (0..=deepest)
            .map(|l| {
                let side = (size >> l).max(1);
                views
                    .iter()
                    .map(|v| {
                        exact_at_pitch(&phantom, dims, v, side, side, (1u64 << l) as f64)
                            .map_err(|e| e.to_string())
                    })
                    .collect::<Result<Vec<_>, _>>()
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            volume,
            views,
            exact,
        })
    }
}

/// Reusable buffers for one point's renders.
struct Renderer<'s, 'm, S> {
    spec: &'s Spectrum<'s, S>,
    kernel: KernelTable<f32>,
    small: Vec<KernelTable<f32>>,
    marks: Option<&'m AdaptiveMarks>,
    tw: Vec<f32>,
    grid: Vec<f32>,
    aux: Vec<f32>,
    out: Vec<f32>,
    level: u32,
    side: usize,
    taps: u64,
    full_taps: u64,
}

impl<'s, 'm, S: Sample> Renderer<'s, 'm, S> {
    fn new(
        spec: &'s Spectrum<'s, S>,
        marks: Option<&'m AdaptiveMarks>,
        level: u32,
        side: usize,
    ) -> Self {
        let n = spec.n();
        let m = if marks.is_some() { n } else { n >> level };
        let mut tw = vec![0.0f32; Twiddles::<f32>::buffer_len(n)];
        Twiddles::new(&mut tw, n).expect("the spectrum's side is a power of two");
        Self {
            spec,
            kernel: KernelTable::new(*spec.filter()),
            small: marks.map_or(Vec::new(), |mk| {
                mk.levels
                    .iter()
                    .map(|l| KernelTable::new(l.filter))
                    .collect()
            }),
            marks,
            tw,
            grid: vec![0.0; m * m],
            aux: vec![0.0; aux_len(m)],
            out: vec![0.0; side * side],
            level,
            side,
            taps: 0,
            full_taps: 0,
        }
    }

    fn render(&mut self, view: &View) -> Result<(), fvr_core::Error> {
        let n = self.spec.n();
        let tw = Twiddles::from_table(&self.tw, n)?;
        let side = self.side;
        if let Some(mk) = self.marks {
            let levels: Vec<AdaptiveLevel<'_, '_, f32>> = mk
                .levels
                .iter()
                .zip(&self.small)
                .map(|(l, t)| {
                    Ok(AdaptiveLevel {
                        kernel: t,
                        marks: Marks::new(&l.words, n)?,
                        gain: l.gain as f32,
                    })
                })
                .collect::<Result<_, fvr_core::Error>>()?;
            let frame = view.frame()?;
            let stats =
                extract_slice_adaptive(self.spec, &self.kernel, &levels, &frame, &mut self.grid)?;
            self.taps += stats.taps;
            self.full_taps += stats.full_taps;
            let place = placement(self.spec.dims(), &frame, side, side);
            finish_projection(
                &mut self.grid,
                n,
                &place,
                1.0 / self.spec.scale(),
                side,
                side,
                &tw,
                &mut self.aux,
                &mut self.out,
            )
        } else if self.level == 0 {
            render(
                self.spec,
                &self.kernel,
                view,
                side,
                side,
                &tw,
                &mut self.grid,
                &mut self.aux,
                &mut self.out,
            )
        } else {
            render_level(
                self.spec,
                &self.kernel,
                view,
                side,
                side,
                self.level,
                &tw,
                &mut self.grid,
                &mut self.aux,
                &mut self.out,
            )
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let k = v.len();
    if k % 2 == 1 {
        v[k / 2]
    } else {
        0.5 * (v[k / 2 - 1] + v[k / 2])
    }
}

/// Measure every setting of `group` (one size, filter, oversampling and
/// format) on the prepared `spec`.
fn measure_group<S: Sample>(
    spec: &Spectrum<'_, S>,
    subject: &Subject,
    group: &[Setting],
    repeats: usize,
    prepare_ms: f64,
    mut progress: impl FnMut(&Row),
) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    let mut marks_cache: Vec<(f64, AdaptiveMarks)> = Vec::new();
    for st in group {
        if let Some(db) = st.adaptive_db {
            if !marks_cache.iter().any(|(d, _)| *d == db) {
                // The paper's bound: marks in about a second where the exact
                // bound's 3D transforms take seconds to minutes per spectrum.
                let settings = AdaptiveSettings {
                    chain: ADAPTIVE_CHAIN.to_vec(),
                    bound: Bound::Paper,
                    ..AdaptiveSettings::new(db)
                };
                let mk = AdaptiveMarks::build_for(spec, &settings)?;
                marks_cache.push((db, mk));
            }
        }
        let marks = st
            .adaptive_db
            .and_then(|db| marks_cache.iter().find(|(d, _)| *d == db).map(|(_, m)| m));
        let side = st.image_side();
        let mut r = Renderer::new(spec, marks, st.level, side);
        let exact = &subject.exact[st.level as usize];
        let mut snrs = Vec::with_capacity(subject.views.len());
        for (view, reference) in subject.views.iter().zip(exact) {
            r.render(view).map_err(|e| e.to_string())?;
            let image: Vec<f64> = r.out.iter().map(|&v| v as f64).collect();
            snrs.push(snr_db(reference, &image));
        }
        let taps_fraction = marks.map(|_| r.taps as f64 / r.full_taps.max(1) as f64);
        let mut times = Vec::with_capacity(repeats * subject.views.len());
        for _ in 0..repeats {
            for view in &subject.views {
                let t = Instant::now();
                r.render(view).map_err(|e| e.to_string())?;
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        let ms_min = times.iter().copied().fold(f64::INFINITY, f64::min);
        // Computed before any work (the refusal); the allocation agrees
        // (`memory_model_matches_the_allocated_spectrum`), and the row
        // reports what was allocated.
        let mut memory = st.memory();
        memory.spectrum = spec.bytes() as u64;
        if let Some(mk) = marks {
            memory.marks = mk.bytes() as u64;
        }
        let row = Row {
            setting: *st,
            ms_per_view: median(times),
            ms_min,
            snr_db: snrs.iter().copied().fold(f64::INFINITY, f64::min),
            snr_mean_db: snrs.iter().sum::<f64>() / snrs.len() as f64,
            memory,
            prepare_ms,
            taps_fraction,
            peak_rss: peak_rss(),
            pareto: false,
        };
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// Prepare the spectrum of `subject` for the group's filter and format,
/// then measure the group.
fn prepare_and_measure(
    subject: &Subject,
    group: &[Setting],
    repeats: usize,
    progress: impl FnMut(&Row),
) -> Result<Vec<Row>, String> {
    let first = group[0];
    let t0 = Instant::now();
    let filter: Filter = choose_filter(
        &subject.volume,
        first.filter,
        first.oversample,
        KbDesign::Auto,
    )
    .map_err(|e| e.to_string())?;
    macro_rules! go {
        ($s:ty, $line:expr) => {{
            let spec = if $line {
                StoredSpectrum::<$s>::prepare_line_blocks::<f32>(
                    &subject.volume,
                    filter,
                    Rounding::PerPass,
                )
            } else {
                StoredSpectrum::<$s>::prepare::<f32>(&subject.volume, filter, Rounding::PerPass)
            }
            .map_err(|e| e.to_string())?;
            let prepare_ms = t0.elapsed().as_secs_f64() * 1e3;
            let view = spec.view();
            measure_group(&view, subject, group, repeats, prepare_ms, progress)
        }};
    }
    match first.format {
        Format::F16 => go!(f16, false),
        Format::Bf16 => go!(bf16, false),
        Format::F32 => go!(f32, false),
        Format::Minifloat16(2) => go!(Minifloat16<2>, false),
        Format::Minifloat16(3) => go!(Minifloat16<3>, false),
        Format::Minifloat16(4) => go!(Minifloat16<4>, false),
        Format::Minifloat16(6) => go!(Minifloat16<6>, false),
        Format::Minifloat16(7) => go!(Minifloat16<7>, false),
        Format::Q15(Blocking::Volume) => go!(Q15, false),
        Format::Q15(Blocking::Blocks(BlockLayout::Line)) => go!(Q15, true),
        other => Err(format!(
            "format {} is not swept: use {FORMATS_HELP}",
            FormatName(other)
        )),
    }
}

/// Run the sweep (after [`Sweep::check_memory`]); `progress` is called
/// after each point. Rows come back with their Pareto flags set.
///
/// # Errors
/// A failure of the pipeline, named.
pub fn measure(sweep: &Sweep, mut progress: impl FnMut(&Row)) -> Result<Vec<Row>, String> {
    let settings = sweep.settings();
    let mut rows = Vec::with_capacity(settings.len());
    for &size in &sweep.sizes {
        let subject = Subject::new(sweep.phantom, size, sweep.views, &sweep.levels)?;
        let mine: Vec<Setting> = settings
            .iter()
            .copied()
            .filter(|s| s.size == size)
            .collect();
        // Points sharing a spectrum are consecutive.
        let mut start = 0;
        while start < mine.len() {
            let key = |s: &Setting| (s.filter, s.oversample, s.format);
            let end = start
                + mine[start..]
                    .iter()
                    .take_while(|s| key(s) == key(&mine[start]))
                    .count();
            rows.extend(prepare_and_measure(
                &subject,
                &mine[start..end],
                sweep.repeats,
                &mut progress,
            )?);
            start = end;
        }
    }
    mark_fronts(&mut rows);
    Ok(rows)
}

const FILTER_COLOURS: [[u8; 3]; 7] = [
    [127, 127, 127],
    [140, 86, 75],
    [148, 103, 189],
    [31, 119, 180],
    [44, 160, 44],
    [255, 127, 14],
    [214, 39, 40],
];

fn filter_index(f: FilterKind) -> usize {
    FilterKind::ALL.iter().position(|&k| k == f).unwrap_or(0)
}

/// 1-2-5 ticks covering `[lo, hi]`.
fn ticks_125(lo: f64, hi: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut decade = 10f64.powf(lo.log10().floor());
    while decade <= hi {
        for m in [1.0, 2.0, 5.0] {
            let t = m * decade;
            if t >= lo && t <= hi {
                // Round away binary noise so the labels read 0.2, not 0.20000000000000001.
                out.push(format!("{t:.6}").parse().unwrap_or(t));
            }
        }
        decade *= 10.0;
    }
    out
}

/// dB against ms per view (log axis), colour by filter, marker size by
/// level (largest for level 0), with each volume size's Pareto front drawn
/// as a staircase and its points ringed.
pub fn plot(rows: &[Row]) -> Canvas {
    let finite: Vec<&Row> = rows
        .iter()
        .filter(|r| r.ms_per_view.is_finite() && r.ms_per_view > 0.0 && r.snr_db.is_finite())
        .collect();
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    let mut top = 40.0f64;
    for r in &finite {
        lo = lo.min(r.ms_per_view);
        hi = hi.max(r.ms_per_view);
        top = top.max(r.snr_db);
    }
    if !lo.is_finite() {
        (lo, hi) = (0.1, 10.0);
    }
    let (lo, hi) = (lo / 1.3, hi * 1.3);
    let points: Vec<Point> = finite
        .iter()
        .map(|r| Point {
            x: r.ms_per_view,
            y: r.snr_db.max(0.0),
            series: filter_index(r.setting.filter),
        })
        .collect();
    let marker_sizes: Vec<i64> = finite
        .iter()
        .map(|r| 7 - 2 * r.setting.level.min(2) as i64)
        .collect();
    let mut sizes: Vec<usize> = finite.iter().map(|r| r.setting.size).collect();
    sizes.sort_unstable();
    sizes.dedup();
    let fronts: Vec<(String, Vec<(f64, f64)>)> = sizes
        .iter()
        .map(|&n| {
            let mut f: Vec<(f64, f64)> = finite
                .iter()
                .filter(|r| r.setting.size == n && r.pareto)
                .map(|r| (r.ms_per_view, r.snr_db.max(0.0)))
                .collect();
            f.sort_by(|a, b| a.0.total_cmp(&b.0));
            (format!("{n}"), f)
        })
        .collect();
    let series: Vec<(&str, [u8; 3])> = FilterKind::ALL
        .iter()
        .zip(FILTER_COLOURS)
        .map(|(k, c)| (k.name(), c))
        .collect();
    let ticks = ticks_125(lo, hi);
    let scatter = Scatter {
        title: "SNR VS EXACT AGAINST TIME PER VIEW. STAIRS = PARETO FRONT OF EACH SIZE",
        x_label: "MS PER VIEW (LOG SCALE). MARKERS = LEVEL 0, 1, 2 (LARGE TO SMALL)",
        y_label: "SNR DB",
        x_range: (lo, hi),
        // A spare 20 dB on top keeps the legend clear of the points.
        y_range: (0.0, (top / 20.0).ceil() * 20.0 + 20.0),
        x_ticks: &ticks,
        y_step: 20.0,
        y_lines: &[(50.0, "50 DB (PAPER)")],
        series: &series,
        x_labels: &[],
        points: &points,
    };
    scatter.draw_with(
        1000,
        700,
        &Overlay {
            fronts: &fronts,
            marker_sizes: &marker_sizes,
        },
    )
}

/// The CPU model from /proc/cpuinfo, if readable.
fn cpu_model() -> Option<String> {
    let s = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    s.lines()
        .find_map(|l| l.strip_prefix("model name"))
        .and_then(|r| r.split_once(':'))
        .map(|(_, m)| m.trim().to_string())
}

fn setting_cells(st: &Setting) -> String {
    format!(
        "{} | {} | {} | {} | {} | {}²",
        st.filter.name(),
        st.oversample,
        FormatName(st.format),
        st.adaptive_db.map_or("—".into(), |d| format!("{d} dB")),
        st.level,
        st.image_side()
    )
}

/// The Markdown summary: how the run was made, the Pareto front of each
/// size, and the fastest point at or above 50 dB per size.
pub fn summary(rows: &[Row], sweep: &Sweep, command: &str) -> String {
    let mut s = String::from("# Speed–accuracy trade: measured\n\n");
    let threads = std::thread::available_parallelism().map_or(0, |n| n.get());
    let _ = write!(
        s,
        "Made by `{command}` on {} ({threads} hardware threads), {} points.\n\n\
         - Phantom: `{}@N` ({}, seed {DEFAULT_SEED}), {} view \
         directions (golden-angle azimuths, elevations from 40° to −30°).\n\
         - Time per view: the median of {} views × {} repeats, wall clock, one thread, \
         buffers allocated beforehand. It is noisy (other processes share the machine): \
         compare ratios within one run, not absolute times across runs.\n\
         - SNR: the worst view, 10·log10(Σref²/Σ(img−ref)²), against the exact line \
         integrals at the image's pixels; a level-L preview is compared with the exact \
         integrals every 2^L voxels, so its dB includes the detail the preview leaves out.\n\
         - Memory held: spectrum + adaptive marks + per-view scratch, from the sizes.\n\
         - Adaptive points use nearest as the cheaper filter, at oversampling 2 and level 0 only.\n\n",
        cpu_model().unwrap_or_else(|| "an unknown CPU".into()),
        rows.len(),
        sweep.phantom.name(),
        match sweep.phantom {
            TradePhantom::Gaussians => "8 random Gaussians, σ from 1.5 to 0.12·N voxels",
            TradePhantom::Blobs => "24 random Gaussians, σ from 1.5 to 0.05·N voxels",
        },
        sweep.views,
        sweep.views,
        sweep.repeats,
    );
    s.push_str(&levels_table(rows, sweep));
    for &size in &sweep.sizes {
        let mut front: Vec<&Row> = rows
            .iter()
            .filter(|r| r.setting.size == size && r.pareto)
            .collect();
        front.sort_by(|a, b| a.ms_per_view.total_cmp(&b.ms_per_view));
        let _ = write!(
            s,
            "## {size}³: the Pareto front\n\n\
             | filter | oversampling | format | adaptive | level | image | ms/view | dB | held |\n\
             |---|---|---|---|---|---|---|---|---|\n"
        );
        for r in &front {
            let _ = writeln!(
                s,
                "| {} | {:.3} | {:.1} | {} |",
                setting_cells(&r.setting),
                r.ms_per_view,
                r.snr_db,
                human_bytes(r.memory.held())
            );
        }
        let best50 = rows
            .iter()
            .filter(|r| r.setting.size == size && r.setting.level == 0 && r.snr_db >= 50.0)
            .min_by(|a, b| a.ms_per_view.total_cmp(&b.ms_per_view));
        match best50 {
            Some(r) => {
                let _ = writeln!(
                    s,
                    "\nFastest full-resolution point at ≥ 50 dB: {} ({:.3} ms, {:.1} dB).\n",
                    r.setting.describe(),
                    r.ms_per_view,
                    r.snr_db
                );
            }
            None => s.push_str("\nNo full-resolution point reached 50 dB.\n\n"),
        }
    }
    s
}

/// Each size and level: its fastest point at ≥ 50 dB, and its most
/// accurate point, so every level's time and dB can be read off.
fn levels_table(rows: &[Row], sweep: &Sweep) -> String {
    let mut s = String::from(
        "## Each level: fastest at ≥ 50 dB, and most accurate\n\n\
         | size | level | image | fastest at ≥ 50 dB | ms/view | dB | most accurate | ms/view | dB |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for &size in &sweep.sizes {
        for &level in &sweep.levels {
            let mine: Vec<&Row> = rows
                .iter()
                .filter(|r| r.setting.size == size && r.setting.level == level)
                .collect();
            let Some(first) = mine.first() else { continue };
            let fast = mine
                .iter()
                .filter(|r| r.snr_db >= 50.0)
                .min_by(|a, b| a.ms_per_view.total_cmp(&b.ms_per_view));
            let best = mine.iter().max_by(|a, b| a.snr_db.total_cmp(&b.snr_db));
            let cells = |r: Option<&&Row>| match r {
                Some(r) => format!(
                    "{} | {:.3} | {:.1}",
                    r.setting.describe(),
                    r.ms_per_view,
                    r.snr_db
                ),
                None => "none | — | —".into(),
            };
            let _ = writeln!(
                s,
                "| {size}³ | {level} | {}² | {} | {} |",
                first.setting.image_side(),
                cells(fast),
                cells(best)
            );
        }
    }
    s.push('\n');
    s
}

/// The command line as typed, with the program named `fvr`.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::sources::phantom::SplitMix64;
    use fvr_core::spectrum::padded_size;

    /// On a random cloud with ties, no front point is dominated by any
    /// point, and every point off the front is dominated by one on it.
    #[test]
    fn pareto_front_is_undominated_and_dominates_the_rest() {
        let mut rng = SplitMix64::new(7);
        for trial in 0..20 {
            let count = 1 + trial * 7;
            let mut pts: Vec<(f64, f64)> = (0..count)
                .map(|_| {
                    // Coarse values so that ties in ms and in dB occur.
                    let ms = (rng.next_f64() * 20.0).round() / 2.0 + 0.1;
                    let db = (rng.next_f64() * 12.0).round() * 10.0;
                    (ms, db)
                })
                .collect();
            pts.push((f64::NAN, 500.0));
            pts.push((0.01, f64::NAN));
            let front = pareto_front(&pts);
            assert!(
                !front[count] && !front[count + 1],
                "non-finite points are off"
            );
            assert!(front.iter().any(|&f| f), "a finite cloud has a front");
            for (i, &p) in pts.iter().enumerate() {
                if front[i] {
                    assert!(
                        pts.iter()
                            .filter(|q| q.0.is_finite() && q.1.is_finite())
                            .all(|&q| !dominates(q, p)),
                        "front point {p:?} is dominated"
                    );
                } else if p.0.is_finite() && p.1.is_finite() {
                    assert!(
                        pts.iter()
                            .zip(&front)
                            .any(|(&q, &on)| on && dominates(q, p)),
                        "{p:?} is off the front but no front point dominates it"
                    );
                }
            }
        }
    }

    /// A hand-made set: the staircase (1, 10), (2, 30), (4, 50) is the
    /// front; (2, 10), (3, 30), (5, 50) and a duplicate-ms slower point are
    /// dominated; an exact duplicate of a front point stays on it.
    #[test]
    fn pareto_front_of_a_known_staircase() {
        let pts = [
            (1.0, 10.0),
            (2.0, 30.0),
            (4.0, 50.0),
            (2.0, 10.0),
            (3.0, 30.0),
            (5.0, 50.0),
            (4.0, 49.0),
            (4.0, 50.0),
        ];
        assert_eq!(
            pareto_front(&pts),
            [true, true, true, false, false, false, false, true]
        );
    }

    /// The computed spectrum bytes equal what the pipeline allocates, for
    /// an element format and a block format.
    #[test]
    fn memory_model_matches_the_allocated_spectrum() {
        let size = 24;
        let volume = sample(&GaussianMixture::random(1, size, 4), [size; 3]);
        for (format, os) in [
            (Format::F16, 1),
            (Format::Q15(Blocking::Blocks(BlockLayout::Line)), 2),
        ] {
            let st = Setting {
                size,
                filter: FilterKind::Kb3,
                oversample: os,
                format,
                adaptive_db: None,
                level: 0,
            };
            let filter = Filter::new(FilterKind::Kb3, os).unwrap();
            let bytes = match format {
                Format::F16 => {
                    StoredSpectrum::<f16>::prepare::<f32>(&volume, filter, Rounding::PerPass)
                        .unwrap()
                        .bytes()
                }
                _ => StoredSpectrum::<Q15>::prepare_line_blocks::<f32>(
                    &volume,
                    filter,
                    Rounding::PerPass,
                )
                .unwrap()
                .bytes(),
            };
            assert_eq!(st.memory().spectrum, bytes as u64, "{format:?}");
            assert_eq!(st.grid(), padded_size([size; 3], os).unwrap());
        }
    }

    /// At pitch 1 the exact reference is [`crate::reference::exact_projection`];
    /// at pitch 2 it is every other pixel of the full image.
    #[test]
    fn exact_at_pitch_subsamples_the_full_image() {
        let n = 32;
        let p = GaussianMixture::random(3, n, 4);
        let v = View::along(view_directions(2)[1]);
        let full = crate::reference::exact_projection(&p, [n; 3], &v, n, n).unwrap();
        // Same positions up to the rounding of c + 1·(p − c).
        let peak = full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let same = exact_at_pitch(&p, [n; 3], &v, n, n, 1.0).unwrap();
        let worst = same
            .iter()
            .zip(&full)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(worst <= 1e-12 * peak, "pitch 1 differs by {worst}");
        let half = exact_at_pitch(&p, [n; 3], &v, n / 2, n / 2, 2.0).unwrap();
        for row in 0..n / 2 {
            for col in 0..n / 2 {
                let (a, b) = (half[row * n / 2 + col], full[2 * row * n + 2 * col]);
                assert!(
                    (a - b).abs() <= 1e-12 * peak,
                    "{row},{col}: {a} against {b}"
                );
            }
        }
    }

    #[test]
    fn byte_counts_parse_with_suffixes() {
        assert_eq!(parse_bytes("1024").unwrap(), 1024);
        assert_eq!(parse_bytes("3K").unwrap(), 3072);
        assert_eq!(parse_bytes("2M").unwrap(), 2 << 20);
        assert_eq!(parse_bytes("1G").unwrap(), 1 << 30);
        assert!(parse_bytes("x").is_err());
        assert!(parse_bytes("99999999999G").is_err());
    }

    #[test]
    fn views_are_never_parallel_to_the_up_hint() {
        for d in view_directions(64) {
            assert!(d[2].abs() < 0.7, "{d:?}");
            assert!(View::along(d).frame().is_ok());
        }
    }
}
