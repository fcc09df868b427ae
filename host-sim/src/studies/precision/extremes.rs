//! The stability cases of the precision study: volumes at the extremes of
//! range and frequency, in every format.

use std::fmt::Write as _;

use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;
use fvr_core::num::{Arithmetic, Format, FormatName};

use crate::reference::snr_db;
use fvr_engine::plan::filter::{choose_filter, choose_oversampling, KbDesign};
use fvr_engine::volume::Volume;

use super::{db, modes_for, Subject, VIEWS};

/// A stability case: a volume at an extreme, with the views it is rendered
/// along.
pub struct ExtremeCase {
    /// Short name (used in the docs table).
    pub name: &'static str,
    /// The volume.
    pub volume: Volume,
    /// Views.
    pub views: Vec<View>,
}

/// The stability cases of the docs, at side `n` (even): a constant volume,
/// a single-voxel impulse at the centre, a Nyquist checkerboard, a constant
/// full-range u16 volume, the Gaussian phantom scaled by 1e-6, and a
/// Shepp–Logan head in Hounsfield units (air −1000).
pub fn extreme_cases(n: usize) -> Vec<ExtremeCase> {
    use fvr_engine::volume::phantom::{sample, GaussianMixture, SheppLogan};
    let dims = [n, n, n];
    let views = || VIEWS.iter().map(|&d| View::along(d)).collect::<Vec<_>>();
    let filled = |f: &dyn Fn(usize, usize, usize) -> f32| {
        let mut v = Volume::zeros(dims);
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let idx = v.index(i, j, k);
                    v.data[idx] = f(i, j, k);
                }
            }
        }
        v
    };
    let gauss = sample(&GaussianMixture::random(1, n, 8), dims);
    let sl = sample(&SheppLogan::new(dims), dims);
    vec![
        ExtremeCase {
            name: "constant 1",
            volume: filled(&|_, _, _| 1.0),
            views: views(),
        },
        ExtremeCase {
            name: "impulse",
            volume: filled(&|i, j, k| if [i, j, k] == [n / 2; 3] { 1.0 } else { 0.0 }),
            views: views(),
        },
        ExtremeCase {
            name: "nyquist checkerboard",
            volume: filled(&|i, j, k| if (i + j + k) % 2 == 0 { 1.0 } else { -1.0 }),
            views: views(),
        },
        ExtremeCase {
            name: "u16 65535",
            volume: filled(&|_, _, _| 65535.0),
            views: views(),
        },
        ExtremeCase {
            name: "gaussians x 1e-6",
            volume: Volume::new(dims, gauss.data.iter().map(|v| v * 1e-6).collect()),
            views: views(),
        },
        ExtremeCase {
            name: "shepp-logan in HU",
            volume: Volume::new(dims, sl.data.iter().map(|v| 1000.0 * v - 1000.0).collect()),
            views: views(),
        },
    ]
}

/// One stability measurement.
#[derive(Clone, Debug)]
pub struct ExtremeRow {
    /// The case.
    pub case: &'static str,
    /// Premultiplication gain at oversampling 1, dB.
    pub gain_db: f64,
    /// Oversampling chosen.
    pub oversample: u32,
    /// The format.
    pub format: Format,
    /// Its arithmetic.
    pub arithmetic: Arithmetic,
    /// Worst SNR over the views against the f64 pipeline (dB), or the error.
    pub snr_f64: Result<f64, String>,
    /// `n·max|voxel|`, the largest line integral the volume could give.
    pub line_scale: f64,
    /// Largest `|pixel − f64 pixel|` over all views.
    pub max_error: f64,
    /// NaN or infinite pixels.
    pub non_finite: usize,
}

/// Measure every case of [`extreme_cases`] with `formats` (each with
/// [`modes_for`]), at the oversampling [`choose_oversampling`] picks for kb4
/// unless `oversample` fixes it.
///
/// # Errors
/// The f64 reference fails.
pub fn measure_extremes(
    n: usize,
    formats: &[Format],
    oversample: Option<u32>,
) -> Result<Vec<ExtremeRow>, String> {
    use fvr_engine::plan::filter::premultiplication_gain_db;
    let mut rows = Vec::new();
    for case in extreme_cases(n) {
        let kind = FilterKind::Kb4;
        let f1 = choose_filter(&case.volume, kind, 1, KbDesign::Auto).map_err(|e| e.to_string())?;
        let gain_db = premultiplication_gain_db(&case.volume, f1).map_err(|e| e.to_string())?;
        let o = match oversample {
            Some(o) => o,
            None => choose_oversampling(&case.volume, kind, KbDesign::Auto)
                .map_err(|e| e.to_string())?,
        };
        let filter =
            choose_filter(&case.volume, kind, o, KbDesign::Auto).map_err(|e| e.to_string())?;
        let mut subject = Subject::new(case.name, case.volume, None, filter, case.views);
        let (reference, _) = subject.render_format(Format::F64, Arithmetic::PerPass)?;
        let vmax = subject
            .volume
            .data
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs() as f64));
        let line_scale = subject.size as f64 * vmax;
        for &format in formats {
            for arithmetic in modes_for(format) {
                let got = subject.render_format(format, arithmetic);
                let (snr_f64, max_error, non_finite) = match got {
                    Ok((images, _)) => (
                        Ok(images
                            .iter()
                            .zip(&reference)
                            .map(|(i, r)| snr_db(r, i))
                            .fold(f64::INFINITY, f64::min)),
                        images
                            .iter()
                            .flatten()
                            .zip(reference.iter().flatten())
                            .fold(0.0f64, |m, (i, r)| m.max((i - r).abs())),
                        images.iter().flatten().filter(|v| !v.is_finite()).count(),
                    ),
                    Err(e) => (Err(e), f64::NAN, 0),
                };
                rows.push(ExtremeRow {
                    case: case.name,
                    gain_db,
                    oversample: o,
                    format,
                    arithmetic,
                    snr_f64,
                    line_scale,
                    max_error,
                    non_finite,
                });
            }
        }
    }
    Ok(rows)
}

/// The stability rows as a Markdown table.
pub fn extremes_markdown(rows: &[ExtremeRow]) -> String {
    let mut s = String::from(
        "| case | gain at σ=1 | oversample | format | arithmetic | SNR vs f64 | max error / (n·max\\|v\\|) | NaN/Inf |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let snr = match &r.snr_f64 {
            Ok(v) => db(*v),
            Err(e) => format!("error: {e}"),
        };
        let _ = writeln!(
            s,
            "| {} | {:.1} dB | {} | {} | {} | {} | {:.1e} | {} |",
            r.case,
            r.gain_db,
            r.oversample,
            FormatName(r.format),
            r.arithmetic.name(),
            snr,
            r.max_error / r.line_scale,
            r.non_finite
        );
    }
    s
}
