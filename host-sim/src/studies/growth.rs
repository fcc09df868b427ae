//! How the time per view grows with the volume's side `n`: the
//! frequency-domain view (O(n² log n)) against the spatial-domain ray caster
//! (O(n³)), measured in one run and plotted on log–log axes.
//!
//! Each size is a Gaussian mixture phantom (seed 1, 8 components) of `n³`
//! voxels, rendered to an `n × n` image along (1, 0.3, 0.2): kb3 at
//! oversampling 1 from an f16 spectrum, extraction on all cores, against the
//! f32 trilinear ray caster on all cores. Times are medians of `runs` views
//! after one warm-up view, the sizes timed in turn in each round, each
//! timed view right after an untimed one of its size; preprocessing is
//! not timed.

use std::path::Path;
use std::time::Instant;

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use half::f16;

use crate::image::plot::{Canvas, Rgb};
use crate::reference::raycast::RayCaster;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};

/// Time per view at one size.
#[derive(Clone, Debug, PartialEq)]
pub struct GrowthRow {
    /// Volume side.
    pub n: usize,
    /// Median ms per frequency-domain view.
    pub frequency_ms: f64,
    /// Median ms per ray-cast view.
    pub raycast_ms: f64,
}

/// Check the sizes: powers of two from 16 to 512 (512 only with `large`),
/// increasing, at least two.
///
/// # Errors
/// A size out of range or not a power of two, fewer than two sizes, or a
/// size given twice or out of order.
pub fn check_sizes(sizes: &[usize], large: bool) -> Result<(), String> {
    let top = if large { 512 } else { 256 };
    for &n in sizes {
        if !n.is_power_of_two() || !(16..=top).contains(&n) {
            return Err(format!(
                "size {n} is not a power of two from 16 to {top}{}",
                if large { "" } else { " (512 needs --large)" }
            ));
        }
    }
    if sizes.len() < 2 || sizes.windows(2).any(|w| w[1] <= w[0]) {
        return Err(format!(
            "give at least two increasing sizes, e.g. 64,128,256; got {sizes:?}"
        ));
    }
    Ok(())
}

/// Measure every size in `sizes` (checked by [`check_sizes`]) with `runs`
/// timed views each, calling `progress` with each size's row at the end.
///
/// Every size is set up first (phantom, spectrum, renderer, ray caster,
/// one warm-up view each) and held; then each of the `runs` rounds times
/// one view of each size in turn, right after an untimed one of the same
/// size. A change of load on the machine then reaches every size alike,
/// and the ratios between sizes, which are what this study is about, hold
/// under it.
///
/// # Errors
/// Bad sizes or runs, or a render that fails.
pub fn measure(
    sizes: &[usize],
    runs: usize,
    large: bool,
    mut progress: impl FnMut(&GrowthRow),
) -> Result<Vec<GrowthRow>, String> {
    check_sizes(sizes, large)?;
    super::check_repeats("--runs", runs)?;
    let view = View::along([1.0, 0.3, 0.2]);
    let filter = Filter::new(FilterKind::Kb3, 1).map_err(|e| e.to_string())?;
    struct Setup {
        n: usize,
        spec: OwnedSpectrum<f16>,
        renderer: ViewRenderer<f32>,
        caster: RayCaster,
        out: Vec<f32>,
    }
    impl Setup {
        fn frequency(&mut self, view: &View) -> Result<(), String> {
            let n = self.n;
            self.renderer
                .render_into(&self.spec, view, n, n, &mut self.out)
                .map_err(|e| e.to_string())
        }
        fn raycast(&self, view: &View) -> Result<(), String> {
            self.caster.project(view, self.n, self.n, 1.0, 0).map(drop)
        }
    }
    let mut setups = Vec::with_capacity(sizes.len());
    for &n in sizes {
        let volume = sample(&GaussianMixture::random(1, n, 8), [n; 3]);
        let spec =
            OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).map_err(|e| e.to_string())?;
        let mut setup = Setup {
            n,
            renderer: ViewRenderer::<f32>::new(spec.n(), filter),
            spec,
            caster: RayCaster::new(&volume),
            out: vec![0.0f32; n * n],
        };
        setup.frequency(&view)?;
        setup.raycast(&view)?;
        setups.push(setup);
    }
    let mut times = vec![(Vec::with_capacity(runs), Vec::with_capacity(runs)); setups.len()];
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    for _ in 0..runs {
        for (setup, (frequency, raycast)) in setups.iter_mut().zip(&mut times) {
            // Untimed, so that the timed view finds the caches holding this
            // size's data, as the next view of one volume would, rather
            // than the previous size's.
            setup.frequency(&view)?;
            let t = Instant::now();
            setup.frequency(&view)?;
            frequency.push(ms(t));
            let t = Instant::now();
            setup.raycast(&view)?;
            raycast.push(ms(t));
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut rows = Vec::with_capacity(setups.len());
    for (setup, (frequency, raycast)) in setups.iter().zip(&mut times) {
        let row = GrowthRow {
            n: setup.n,
            frequency_ms: median(frequency),
            raycast_ms: median(raycast),
        };
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// The CSV: `n,frequency_ms,raycast_ms,ratio`.
pub fn csv(rows: &[GrowthRow]) -> String {
    let mut s = String::from("n,frequency_ms,raycast_ms,ratio\n");
    for r in rows {
        s += &format!(
            "{},{:.4},{:.4},{:.2}\n",
            r.n,
            r.frequency_ms,
            r.raycast_ms,
            r.raycast_ms / r.frequency_ms
        );
    }
    s
}

/// Growth per doubling between consecutive rows, `(n, frequency, raycast)`,
/// normalized to one doubling when sizes skip (`ratio^(1/doublings)`).
pub fn growth_per_doubling(rows: &[GrowthRow]) -> Vec<(usize, f64, f64)> {
    rows.windows(2)
        .map(|w| {
            let doublings = (w[1].n as f64 / w[0].n as f64).log2();
            let per = |a: f64, b: f64| (b / a).powf(1.0 / doublings);
            (
                w[1].n,
                per(w[0].frequency_ms, w[1].frequency_ms),
                per(w[0].raycast_ms, w[1].raycast_ms),
            )
        })
        .collect()
}

/// The n² log n growth per doubling from `n/2` to `n`: `4·log₂n/log₂(n/2)`.
pub fn ideal_per_doubling(n: usize) -> f64 {
    let l = (n as f64).log2();
    4.0 * l / (l - 1.0)
}

/// A Markdown table of the run, with the growth per doubling.
pub fn markdown(rows: &[GrowthRow]) -> String {
    let mut s = String::from(
        "| n | frequency kb3 f16 | ray caster | ratio | growth, frequency | growth, ray caster | n² log n |\n\
         |---|---|---|---|---|---|---|\n",
    );
    let growth = growth_per_doubling(rows);
    for (i, r) in rows.iter().enumerate() {
        let (gf, gr, ideal) = match i.checked_sub(1).map(|j| growth[j]) {
            Some((n, f, c)) => (
                format!("{f:.2}×"),
                format!("{c:.2}×"),
                format!("{:.2}×", ideal_per_doubling(n)),
            ),
            None => ("".into(), "".into(), "".into()),
        };
        s += &format!(
            "| {}³ | {:.3} ms | {:.2} ms | {:.0}× | {gf} | {gr} | {ideal} |\n",
            r.n,
            r.frequency_ms,
            r.raycast_ms,
            r.raycast_ms / r.frequency_ms
        );
    }
    s
}

const FREQUENCY: Rgb = [200, 40, 40];
const RAYCAST: Rgb = [40, 80, 200];
const REFERENCE: Rgb = [120, 120, 120];

/// Both curves on log–log axes (log₂ n across, log₁₀ ms up), with the
/// n² log n and n³ slopes drawn dashed from each curve's first point.
pub fn plot(rows: &[GrowthRow]) -> Canvas {
    let (width, height) = (900i64, 600i64);
    let mut c = Canvas::new(width as usize, height as usize);
    let (left, right, top, bottom) = (90i64, width - 30, 50i64, height - 70);
    let black = [0, 0, 0];
    let grey = [210, 210, 210];
    let (n0, n1) = (rows[0].n as f64, rows[rows.len() - 1].n as f64);
    let all = rows.iter().flat_map(|r| [r.frequency_ms, r.raycast_ms]);
    let lo = all.clone().fold(f64::INFINITY, f64::min).log10().floor();
    let hi = all.fold(0.0f64, f64::max).log10().ceil().max(lo + 1.0);
    let px = |n: f64| {
        left + ((n.log2() - n0.log2()) / (n1.log2() - n0.log2()) * (right - left) as f64) as i64
    };
    let py = |ms: f64| bottom - ((ms.log10() - lo) / (hi - lo) * (bottom - top) as f64) as i64;
    c.text(
        left,
        12,
        "TIME PER VIEW AGAINST VOLUME SIDE (LOG-LOG)",
        2,
        black,
    );
    let mut decade = lo;
    while decade <= hi + 1e-9 {
        let ms = 10f64.powf(decade);
        c.line((left, py(ms)), (right, py(ms)), grey, 0);
        let label = if ms >= 1.0 {
            format!("{ms:.0} MS")
        } else {
            format!("{ms} MS")
        };
        c.text(
            left - 8 - Canvas::text_width(&label, 2),
            py(ms) - 5,
            &label,
            2,
            black,
        );
        decade += 1.0;
    }
    for r in rows {
        let x = px(r.n as f64);
        c.line((x, top), (x, bottom), grey, 0);
        let label = format!("{}", r.n);
        c.text(
            x - Canvas::text_width(&label, 2) / 2,
            bottom + 10,
            &label,
            2,
            black,
        );
    }
    c.text(
        left,
        bottom + 40,
        "N (VOXELS A SIDE, N3 VOLUME, N2 IMAGE)",
        2,
        black,
    );
    let first = &rows[0];
    let n2logn = |n: f64| n * n * n.log2() / (n0 * n0 * n0.log2());
    let n3 = |n: f64| (n / n0).powi(3);
    for (start, model) in [
        (first.frequency_ms, &n2logn as &dyn Fn(f64) -> f64),
        (first.raycast_ms, &n3),
    ] {
        let pts: Vec<(i64, i64)> = rows
            .iter()
            .map(|r| (px(r.n as f64), py(start * model(r.n as f64))))
            .collect();
        for w in pts.windows(2) {
            c.line(w[0], w[1], REFERENCE, 6);
        }
    }
    for (colour, pick) in [
        (
            FREQUENCY,
            &(|r: &GrowthRow| r.frequency_ms) as &dyn Fn(&GrowthRow) -> f64,
        ),
        (RAYCAST, &|r: &GrowthRow| r.raycast_ms),
    ] {
        let pts: Vec<(i64, i64)> = rows.iter().map(|r| (px(r.n as f64), py(pick(r)))).collect();
        for w in pts.windows(2) {
            c.line(w[0], w[1], colour, 0);
        }
        for &(x, y) in &pts {
            c.rect(x - 4, y - 4, 9, 9, colour);
        }
    }
    let legend = [
        (FREQUENCY, "FREQUENCY DOMAIN KB3 F16"),
        (RAYCAST, "RAY CASTER F32 TRILINEAR"),
        (REFERENCE, "DASHED: N2 LOG N AND N3 FROM THE FIRST POINT"),
    ];
    for (i, (colour, text)) in legend.iter().enumerate() {
        let y = top + 10 + 22 * i as i64;
        c.rect(left + 10, y, 12, 12, *colour);
        c.text(left + 30, y + 1, text, 2, black);
    }
    c
}

/// Measure and write `growth.csv`, `growth.md` and `growth.png` into
/// `out_dir`; returns the Markdown.
///
/// # Errors
/// As [`measure`], or a file that cannot be written.
pub fn run(
    sizes: &[usize],
    runs: usize,
    large: bool,
    out_dir: &Path,
    progress: impl FnMut(&GrowthRow),
) -> Result<String, String> {
    check_sizes(sizes, large)?;
    super::check_repeats("--runs", runs)?;
    super::prepare_out_dir(out_dir)?;
    let rows = measure(sizes, runs, large, progress)?;
    let write = |name: &str, text: &str| crate::io::atomic::write_text(&out_dir.join(name), text);
    write("growth.csv", &csv(&rows))?;
    let md = markdown(&rows);
    write("growth.md", &md)?;
    plot(&rows).write_png(&out_dir.join("growth.png"))?;
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked() {
        assert!(check_sizes(&[64, 128, 256], false).is_ok());
        assert!(check_sizes(&[256, 512], false)
            .unwrap_err()
            .contains("512 needs --large"));
        assert!(check_sizes(&[256, 512], true).is_ok());
        assert!(check_sizes(&[100, 128], false)
            .unwrap_err()
            .contains("power of two"));
        assert!(check_sizes(&[128], false).unwrap_err().contains("two"));
        assert!(check_sizes(&[128, 64], false)
            .unwrap_err()
            .contains("increasing"));
    }

    #[test]
    fn growth_is_normalized_per_doubling() {
        let rows = [
            GrowthRow {
                n: 32,
                frequency_ms: 1.0,
                raycast_ms: 2.0,
            },
            GrowthRow {
                n: 128,
                frequency_ms: 16.0,
                raycast_ms: 128.0,
            },
        ];
        let g = growth_per_doubling(&rows);
        assert_eq!(g.len(), 1);
        assert_eq!(g[0].0, 128);
        assert!((g[0].1 - 4.0).abs() < 1e-12 && (g[0].2 - 8.0).abs() < 1e-12);
        // n² log n from 128 to 256: 4 · 8/7.
        assert!((ideal_per_doubling(256) - 32.0 / 7.0).abs() < 1e-12);
        let text = csv(&rows);
        assert_eq!(text.lines().next(), Some("n,frequency_ms,raycast_ms,ratio"));
        assert_eq!(text.lines().nth(2), Some("128,16.0000,128.0000,8.00"));
        assert!(markdown(&rows).contains("| 128³ | 16.000 ms | 128.00 ms | 8× | 4.00× | 8.00× |"));
    }
}
