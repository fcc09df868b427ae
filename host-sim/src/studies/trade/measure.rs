//! Measuring a sweep: one phantom and its exact images per size, then
//! timed renders of every setting.

use std::time::Instant;

use fvr_core::dht::{Rounding, Twiddles};
use fvr_core::filter::{Filter, KernelTable};
use fvr_core::geometry::View;
use fvr_core::image::{aux_len, finish, placement, Crop};
use fvr_core::num::Sample;
use fvr_core::num::{bf16, BlockLayout, Blocking, Format, FormatName, Minifloat16, Q15};
use fvr_core::render::{render, Buffers, Request, Source};
use fvr_core::slice::adaptive::extract_slice_adaptive;
use fvr_core::spectrum::Spectrum;
use half::f16;

use crate::reference::snr_db;
use crate::studies::precision::StoredSpectrum;
use fvr_engine::plan::filter::{choose_filter, KbDesign};
use fvr_engine::slice::adaptive::walk::{self, AdaptiveJob};
use fvr_engine::slice::adaptive::{AdaptiveMarks, AdaptiveSettings, Bound};
use fvr_engine::slice::exact::Tiling;
use fvr_engine::volume::phantom::{sample, Phantom};
use fvr_engine::volume::Volume;

use super::{mark_fronts, Row, Setting, Sweep, TradePhantom, ADAPTIVE_CHAIN, FORMATS_HELP};

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
pub(crate) struct Subject {
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
            small: marks.map_or(Vec::new(), |mk| mk.tables()),
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
            let levels = mk.core_levels(&self.small)?;
            let frame = view.frame()?;
            // On this thread, as the plain points' core render: the host's
            // walk where it serves the spectrum, else the core's.
            let (kernel, grid) = (&self.kernel, &mut self.grid);
            let tiling = Tiling::default();
            let job = AdaptiveJob::new(
                self.spec,
                kernel,
                &levels,
                mk.summary(),
                &frame,
                tiling,
                false,
            );
            let stats = match walk::extract(&job, grid) {
                Some(stats) => stats,
                None => extract_slice_adaptive(self.spec, kernel, &levels, &frame, grid)?,
            };
            self.taps += stats.taps;
            self.full_taps += stats.full_taps;
            let place = placement(self.spec.dims(), &frame, side, side);
            finish(
                &mut self.grid,
                n,
                &Crop::new(place, 1.0 / self.spec.scale(), side, side),
                &tw,
                &mut self.aux,
                &mut self.out,
            )
        } else if self.level == 0 {
            render(
                &Source::new(self.spec, &self.kernel, &tw),
                &Request::new(*view, side, side),
                Buffers {
                    grid: &mut self.grid,
                    aux: &mut self.aux,
                    out: &mut self.out,
                },
            )
            .map(|_| ())
        } else {
            render(
                &Source::new(self.spec, &self.kernel, &tw),
                &Request {
                    level: self.level,
                    ..Request::new(*view, side, side)
                },
                Buffers {
                    grid: &mut self.grid,
                    aux: &mut self.aux,
                    out: &mut self.out,
                },
            )
            .map(|_| ())
        }
    }
}

pub(crate) fn median(mut v: Vec<f64>) -> f64 {
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
            let volume = &subject.volume;
            let spec = StoredSpectrum::<$s>::prepare_in_place::<f32>(
                volume,
                filter,
                Rounding::PerPass,
                $line,
            )
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
