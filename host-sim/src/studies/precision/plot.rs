//! The precision study's plot: SNR against f64 over bytes per voxel.

use fvr_core::num::{Arithmetic, Format, FormatName};

use super::Cell;
use crate::image::plot::{Canvas, Point, Scatter};

/// SNR against f64 over bytes per voxel; formats that share a size are
/// spread sideways and named under the axis.
pub fn plot(cells: &[Cell]) -> Canvas {
    let mut formats: Vec<(Format, f64)> = Vec::new();
    for c in cells
        .iter()
        .filter(|c| c.error.is_none() && c.format != Format::F64)
    {
        if !formats.iter().any(|(f, _)| *f == c.format) {
            formats.push((c.format, c.bytes_per_voxel));
        }
    }
    // Spread formats of the same (rounded) size over ±0.35 octave.
    let class = |b: f64| b.log2().round() as i64;
    let mut xs: Vec<(Format, f64)> = Vec::new();
    for (f, b) in &formats {
        let peers: Vec<&(Format, f64)> = formats
            .iter()
            .filter(|(_, c)| class(*c) == class(*b))
            .collect();
        let i = peers.iter().position(|(g, _)| g == f).unwrap_or(0) as f64;
        let m = peers.len() as f64;
        let spread = (0.7 / m).min(0.12);
        let x = 2f64.powf(class(*b) as f64 + (i - (m - 1.0) / 2.0) * spread);
        xs.push((*f, x));
    }
    let series = [
        ("per-pass", [31, 119, 180]),
        ("per-stage", [214, 39, 40]),
        ("host-once", [44, 160, 44]),
    ];
    let points: Vec<Point> = cells
        .iter()
        .filter(|c| c.error.is_none() && c.snr_f64.is_finite())
        .filter_map(|c| {
            let x = xs.iter().find(|(f, _)| *f == c.format)?.1;
            let series = match c.arithmetic {
                Arithmetic::PerPass => 0,
                Arithmetic::PerStage => 1,
                Arithmetic::HostOnce => 2,
            };
            // Modes side by side: per-pass left, per-stage centre, host-once right.
            Some(Point {
                x: x * 2f64.powf(0.012 * (series as f64 - 1.0)),
                y: c.snr_f64,
                series,
            })
        })
        .collect();
    let labels: Vec<(f64, String)> = xs
        .iter()
        .map(|(f, x)| (*x, FormatName(*f).to_string()))
        .collect();
    let top = points.iter().map(|p| p.y).fold(60.0f64, f64::max);
    let scatter = Scatter {
        title: "SNR VS THE F64 PIPELINE, EVERY VOLUME AND SIZE",
        x_label: "SPECTRUM BYTES PER VOXEL (LOG SCALE)",
        y_label: "SNR DB",
        x_range: (0.6, 6.0),
        y_range: (0.0, (top / 20.0).ceil() * 20.0),
        x_ticks: &[1.0, 2.0, 4.0],
        y_step: 20.0,
        y_lines: &[(40.0, "40 DB"), (50.0, "50 DB (PAPER)"), (75.0, "75 DB")],
        series: &series,
        x_labels: &labels,
        points: &points,
    };
    scatter.draw(1000, 700)
}
