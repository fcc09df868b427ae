//! The sweep's outputs: Pareto fronts, the CSV, the plot and the Markdown
//! summary.

use std::fmt::Write as _;

use fvr_core::filter::FilterKind;
use fvr_core::num::FormatName;

use crate::image::plot::{Canvas, Overlay, Point, Scatter};
use crate::sources::DEFAULT_SEED;

use super::{human_bytes, Memory, Setting, Sweep, TradePhantom};

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
