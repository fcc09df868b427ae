//! The precision study (`fvr precision`): storage formats × arithmetic ×
//! volumes × sizes, each measured against the f64 pipeline and, for analytic
//! phantoms, against exact line integrals.
//!
//! Every format goes through the one generic core: [`StoredSpectrum`] holds
//! a spectrum in any [`Sample`] type, prepared in place (rounding per pass
//! or per butterfly stage) or rounded once from a host f32 spectrum, with
//! block exponents for block floating point.

mod extremes;
pub mod plot;
mod stored;
#[cfg(test)]
mod tests;

pub use extremes::{extreme_cases, extremes_markdown, measure_extremes, ExtremeCase, ExtremeRow};
pub use stored::StoredSpectrum;

use std::fmt::Write as _;

use fvr_core::dht::Rounding;
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::num::{
    bf16, Arithmetic, BlockLayout, Blocking, Format, FormatName, Minifloat16, Minifloat8, Q15, Q7,
};
use fvr_core::num::{Real, Sample};
use fvr_core::volume::padded_size;
use half::f16;

use crate::reference::{exact_projection, snr_db};
use crate::sources::{load_volume, phantom_by_name};
use fvr_engine::plan::filter::{choose_filter, choose_oversampling, KbDesign};
use fvr_engine::volume::phantom::Phantom;
use fvr_engine::volume::Volume;

/// Everything a cell of the study needs about one volume at one size.
pub struct Subject {
    /// The volume spec, e.g. `gaussians@64`.
    pub name: String,
    /// The sampled volume.
    pub volume: Volume,
    /// The analytic phantom, if the volume is one.
    pub phantom: Option<Box<dyn Phantom>>,
    /// The filter (and oversampling) every format is prepared for.
    pub filter: Filter,
    /// Views measured.
    pub views: Vec<View>,
    /// Image side (the volume's largest side).
    pub size: usize,
    host_f32: Option<StoredSpectrum<f32>>,
}

/// How the oversampling is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Oversampling {
    /// 2 when premultiplication would amplify storage noise by more than
    /// [`fvr_engine::spectrum::CONDITIONING_LIMIT_DB`], else 1.
    Auto,
    /// Fixed.
    Fixed(u32),
}

/// The four views: along the x axis, along (1, 0.3, 0.2), along (1, 1, 1),
/// and along the y axis. The last one's slice contains the k_x axis, along
/// which per-line block exponents put their largest errors.
pub const VIEWS: [[f64; 3]; 4] = [
    [1.0, 0.0, 0.0],
    [1.0, 0.3, 0.2],
    [1.0, 1.0, 1.0],
    [0.0, 1.0, 0.0],
];

impl Subject {
    /// Load `spec` (a phantom name or a file, through [`load_volume`]) and
    /// choose its filter.
    ///
    /// # Errors
    /// An unknown or unreadable volume, or a bad filter.
    pub fn load(spec: &str, kind: FilterKind, oversampling: Oversampling) -> Result<Self, String> {
        let (volume, phantom) = match phantom_by_name(spec) {
            Some(p) => {
                let p = p?;
                (p.volume, Some(p.phantom))
            }
            None => (load_volume(spec, None)?, None),
        };
        let oversample = match oversampling {
            Oversampling::Fixed(o) => o,
            Oversampling::Auto => {
                choose_oversampling(&volume, kind, KbDesign::Auto).map_err(|e| e.to_string())?
            }
        };
        let filter =
            choose_filter(&volume, kind, oversample, KbDesign::Auto).map_err(|e| e.to_string())?;
        let size = volume.dims.iter().copied().max().unwrap_or(1);
        Ok(Self {
            name: spec.to_string(),
            volume,
            phantom,
            filter,
            views: VIEWS.iter().map(|&d| View::along(d)).collect(),
            size,
            host_f32: None,
        })
    }

    /// A subject from a volume already in memory, rendered at `size × size`
    /// along `views`, with `filter`.
    pub fn new(
        name: &str,
        volume: Volume,
        phantom: Option<Box<dyn Phantom>>,
        filter: Filter,
        views: Vec<View>,
    ) -> Self {
        let size = volume.dims.iter().copied().max().unwrap_or(1);
        Self {
            name: name.to_string(),
            volume,
            phantom,
            filter,
            views,
            size,
            host_f32: None,
        }
    }

    /// Images of every view from `spec`, with arithmetic `T`.
    fn images<S: Sample, T: Real>(
        &self,
        spec: &StoredSpectrum<S>,
    ) -> Result<Vec<Vec<f64>>, String> {
        self.views
            .iter()
            .map(|v| {
                spec.render::<T>(v, self.size, self.size)
                    .map_err(|e| e.to_string())
            })
            .collect()
    }

    /// The images of `format` prepared with `arithmetic`, and the spectrum's
    /// bytes per input voxel.
    ///
    /// # Errors
    /// A format this arithmetic cannot prepare ([`Format::check`]), or a
    /// failure of the pipeline (named).
    pub fn render_format(
        &mut self,
        format: Format,
        arithmetic: Arithmetic,
    ) -> Result<(Vec<Vec<f64>>, f64), String> {
        let n =
            padded_size(self.volume.dims, self.filter.oversample()).map_err(|e| e.to_string())?;
        format.check(arithmetic, n).map_err(|e| e.to_string())?;
        if arithmetic == Arithmetic::HostOnce && self.host_f32.is_none() {
            self.host_f32 = Some(
                StoredSpectrum::<f32>::prepare::<f32>(&self.volume, self.filter, Rounding::PerPass)
                    .map_err(|e| e.to_string())?,
            );
        }
        let voxels = self.volume.data.len() as f64;
        macro_rules! go {
            ($s:ty, $blocking:expr) => {
                self.run::<$s>(arithmetic, $blocking, voxels)
            };
        }
        match format {
            Format::F16 => go!(f16, Blocking::Volume),
            Format::Bf16 => go!(bf16, Blocking::Volume),
            Format::Minifloat16(2) => go!(Minifloat16<2>, Blocking::Volume),
            Format::Minifloat16(3) => go!(Minifloat16<3>, Blocking::Volume),
            Format::Minifloat16(4) => go!(Minifloat16<4>, Blocking::Volume),
            Format::Minifloat16(6) => go!(Minifloat16<6>, Blocking::Volume),
            Format::Minifloat16(7) => go!(Minifloat16<7>, Blocking::Volume),
            Format::Minifloat8(2) => go!(Minifloat8<2>, Blocking::Volume),
            Format::Minifloat8(3) => go!(Minifloat8<3>, Blocking::Volume),
            Format::Minifloat8(4) => go!(Minifloat8<4>, Blocking::Volume),
            Format::Minifloat8(5) => go!(Minifloat8<5>, Blocking::Volume),
            Format::Q15(b) => go!(Q15, b),
            Format::Q7(b) => go!(Q7, b),
            Format::F32 => go!(f32, Blocking::Volume),
            Format::F64 => {
                let s = StoredSpectrum::<f64>::prepare::<f64>(
                    &self.volume,
                    self.filter,
                    Rounding::PerPass,
                )
                .map_err(|e| e.to_string())?;
                Ok((self.images::<f64, f64>(&s)?, s.bytes() as f64 / voxels))
            }
            other => Err(format!(
                "format {} has no storage type here",
                FormatName(other)
            )),
        }
    }

    fn run<S: Sample>(
        &self,
        arithmetic: Arithmetic,
        blocking: Blocking,
        voxels: f64,
    ) -> Result<(Vec<Vec<f64>>, f64), String> {
        let spec = match arithmetic {
            Arithmetic::PerPass | Arithmetic::PerStage => {
                let rounding = if arithmetic == Arithmetic::PerPass {
                    Rounding::PerPass
                } else {
                    Rounding::PerStage
                };
                let line_blocks = matches!(blocking, Blocking::Blocks(BlockLayout::Line));
                StoredSpectrum::<S>::prepare_in_place::<f32>(
                    &self.volume,
                    self.filter,
                    rounding,
                    line_blocks,
                )
                .map_err(|e| e.to_string())?
            }
            Arithmetic::HostOnce => {
                let src = self.host_f32.as_ref().expect("prepared above");
                StoredSpectrum::<S>::encode(src, blocking).map_err(|e| e.to_string())?
            }
        };
        Ok((self.images::<S, f32>(&spec)?, spec.bytes() as f64 / voxels))
    }
}

/// One measured cell.
#[derive(Clone, Debug)]
pub struct Cell {
    /// Volume spec.
    pub volume: String,
    /// Largest side of the volume.
    pub size: usize,
    /// Side of the padded spectrum.
    pub grid: usize,
    /// Storage format.
    pub format: Format,
    /// Arithmetic of the preparation.
    pub arithmetic: Arithmetic,
    /// Spectrum bytes per voxel of the input volume (exponents included).
    pub bytes_per_voxel: f64,
    /// Worst SNR over the views against the f64 pipeline, dB.
    pub snr_f64: f64,
    /// Worst SNR over the views against exact line integrals, dB.
    pub snr_exact: Option<f64>,
    /// Largest pixel error against the f64 pipeline, relative to the largest
    /// pixel of the f64 image.
    pub max_error: f64,
    /// Pixels that were NaN or infinite.
    pub non_finite: usize,
    /// Why the cell could not be measured, if it could not.
    pub error: Option<String>,
}

/// The formats of the study with the arithmetic modes each supports.
pub fn default_formats() -> Vec<Format> {
    let line = Blocking::Blocks(BlockLayout::Line);
    let brick = |b| Blocking::Blocks(BlockLayout::Brick(b));
    vec![
        Format::F64,
        Format::F32,
        Format::F16,
        Format::Bf16,
        Format::Minifloat16(3),
        Format::Minifloat16(4),
        Format::Minifloat16(6),
        Format::Minifloat16(7),
        Format::Q15(Blocking::Volume),
        Format::Q15(line),
        Format::Q15(brick(4)),
        Format::Q15(brick(8)),
        Format::Minifloat8(3),
        Format::Minifloat8(4),
        Format::Minifloat8(5),
        Format::Q7(Blocking::Volume),
        Format::Q7(line),
        Format::Q7(brick(2)),
        Format::Q7(brick(4)),
    ]
}

/// Parse a format name: `f64`, `f32`, `f16`, `bf16`, `eEmM` (a minifloat
/// split, 16 or 8 bits), `q15`, `q7`, with `-line` or `-brickB` for block
/// floating point.
///
/// # Errors
/// An unknown name, a split that does not add up, a bad brick.
pub fn parse_format(s: &str) -> Result<Format, String> {
    match s {
        "f64" => return Ok(Format::F64),
        "f32" => return Ok(Format::F32),
        "f16" => return Ok(Format::F16),
        "bf16" => return Ok(Format::Bf16),
        _ => {}
    }
    let (head, blocking) = match s.split_once('-') {
        None => (s, Blocking::Volume),
        Some((h, "line")) => (h, Blocking::Blocks(BlockLayout::Line)),
        Some((h, b)) => match b.strip_prefix("brick").map(str::parse::<usize>) {
            Some(Ok(side)) if side > 0 => (h, Blocking::Blocks(BlockLayout::Brick(side))),
            _ => {
                return Err(format!(
                    "format `{s}`: expected `-line` or `-brickB` (B a positive integer) after the mantissa"
                ))
            }
        },
    };
    match head {
        "q15" => return Ok(Format::Q15(blocking)),
        "q7" => return Ok(Format::Q7(blocking)),
        _ => {}
    }
    if blocking != Blocking::Volume {
        return Err(format!(
            "format `{s}`: only q15 and q7 take block exponents"
        ));
    }
    let split = head
        .strip_prefix('e')
        .and_then(|r| r.split_once('m'))
        .and_then(|(e, m)| Some((e.parse::<u32>().ok()?, m.parse::<u32>().ok()?)));
    match split {
        Some((e, m)) => Format::minifloat(e, m).map_err(|e| format!("format `{s}`: {e}")),
        None => Err(format!(
            "unknown format `{s}`: expected f64, f32, f16, bf16, eEmM (e.g. e4m11, e4m3), q15, q7, q15-line, q15-brick8"
        )),
    }
}

/// The arithmetic modes a format is measured with.
pub fn modes_for(format: Format) -> Vec<Arithmetic> {
    match format {
        Format::F64 => vec![Arithmetic::PerPass],
        Format::F32 => vec![Arithmetic::PerPass, Arithmetic::PerStage],
        Format::Q15(Blocking::Blocks(BlockLayout::Brick(_)))
        | Format::Q7(Blocking::Blocks(BlockLayout::Brick(_))) => vec![Arithmetic::HostOnce],
        _ => Arithmetic::ALL.to_vec(),
    }
}

/// Largest `|a − b|` relative to the largest `|a|`.
pub(crate) fn relative_max_error(reference: &[f64], test: &[f64]) -> f64 {
    let peak = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let err = reference
        .iter()
        .zip(test)
        .fold(0.0f64, |m, (r, t)| m.max((t - r).abs()));
    err / peak
}

/// Measure every format (with its modes) on one subject. `progress` is
/// called after each cell.
///
/// # Errors
/// The f64 reference could not be made.
pub fn study_subject(
    subject: &mut Subject,
    formats: &[Format],
    mut progress: impl FnMut(&Cell),
) -> Result<Vec<Cell>, String> {
    let (reference, _) = subject.render_format(Format::F64, Arithmetic::PerPass)?;
    let exact: Option<Vec<Vec<f64>>> = match &subject.phantom {
        Some(p) => Some(
            subject
                .views
                .iter()
                .map(|v| {
                    exact_projection(
                        p.as_ref(),
                        subject.volume.dims,
                        v,
                        subject.size,
                        subject.size,
                    )
                    .map_err(|e| e.to_string())
                })
                .collect::<Result<_, _>>()?,
        ),
        None => None,
    };
    let grid =
        padded_size(subject.volume.dims, subject.filter.oversample()).map_err(|e| e.to_string())?;
    let mut cells = Vec::new();
    for &format in formats {
        for arithmetic in modes_for(format) {
            let mut cell = Cell {
                volume: subject.name.clone(),
                size: subject.size,
                grid,
                format,
                arithmetic,
                bytes_per_voxel: f64::NAN,
                snr_f64: f64::NAN,
                snr_exact: None,
                max_error: f64::NAN,
                non_finite: 0,
                error: None,
            };
            match subject.render_format(format, arithmetic) {
                Ok((images, bytes)) => {
                    cell.bytes_per_voxel = bytes;
                    cell.non_finite = images.iter().flatten().filter(|v| !v.is_finite()).count();
                    cell.snr_f64 = images
                        .iter()
                        .zip(&reference)
                        .map(|(i, r)| snr_db(r, i))
                        .fold(f64::INFINITY, f64::min);
                    cell.max_error = images
                        .iter()
                        .zip(&reference)
                        .map(|(i, r)| relative_max_error(r, i))
                        .fold(0.0, f64::max);
                    cell.snr_exact = exact.as_ref().map(|ex| {
                        images
                            .iter()
                            .zip(ex)
                            .map(|(i, r)| snr_db(r, i))
                            .fold(f64::INFINITY, f64::min)
                    });
                }
                Err(e) => cell.error = Some(e),
            }
            progress(&cell);
            cells.push(cell);
        }
    }
    Ok(cells)
}

pub(crate) fn db(v: f64) -> String {
    if v.is_nan() {
        "—".into()
    } else if v == f64::INFINITY {
        "∞".into()
    } else {
        format!("{v:.1}")
    }
}

/// The cells as CSV, one line per cell, with a header.
pub fn csv(cells: &[Cell]) -> String {
    let mut s = String::from(
        "volume,size,grid,format,arithmetic,bytes_per_voxel,snr_vs_f64_db,snr_vs_exact_db,max_pixel_error_rel,non_finite_pixels,error\n",
    );
    for c in cells {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{:.4},{:.2},{},{:.3e},{},{}",
            c.volume,
            c.size,
            c.grid,
            FormatName(c.format),
            c.arithmetic.name(),
            c.bytes_per_voxel,
            c.snr_f64,
            c.snr_exact.map_or(String::new(), |v| format!("{v:.2}")),
            c.max_error,
            c.non_finite,
            c.error.as_deref().unwrap_or("").replace(',', ";")
        );
    }
    s
}

/// The cells as a Markdown table.
pub fn markdown(cells: &[Cell]) -> String {
    let mut s = String::from(
        "| volume | grid | format | arithmetic | bytes/voxel | SNR vs f64 | SNR vs exact | max pixel error |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for c in cells {
        if let Some(e) = &c.error {
            let _ = writeln!(
                s,
                "| {} | {}³ | {} | {} | — | refused: {e} | | |",
                c.volume,
                c.grid,
                FormatName(c.format),
                c.arithmetic.name()
            );
            continue;
        }
        let _ = writeln!(
            s,
            "| {} | {}³ | {} | {} | {:.3} | {} | {} | {:.1e} |",
            c.volume,
            c.grid,
            FormatName(c.format),
            c.arithmetic.name(),
            c.bytes_per_voxel,
            db(c.snr_f64),
            c.snr_exact.map_or("—".into(), db),
            c.max_error
        );
    }
    s
}

/// A pivot of the SNR against f64: one row per format and arithmetic, one
/// column per volume.
pub fn summary(cells: &[Cell]) -> String {
    let mut volumes: Vec<String> = Vec::new();
    for c in cells {
        if !volumes.contains(&c.volume) {
            volumes.push(c.volume.clone());
        }
    }
    let mut s = String::from("| format | arithmetic | bytes/voxel |");
    for v in &volumes {
        let _ = write!(s, " {v} |");
    }
    s.push('\n');
    s.push_str(&"|---".repeat(3 + volumes.len()));
    s.push_str("|\n");
    let mut keys: Vec<(Format, Arithmetic)> = Vec::new();
    for c in cells {
        if !keys.contains(&(c.format, c.arithmetic)) {
            keys.push((c.format, c.arithmetic));
        }
    }
    for (f, a) in keys {
        let row: Vec<&Cell> = cells
            .iter()
            .filter(|c| c.format == f && c.arithmetic == a)
            .collect();
        let bytes = row
            .iter()
            .find(|c| c.error.is_none())
            .map_or("—".into(), |c| format!("{:.3}", c.bytes_per_voxel));
        let _ = write!(s, "| {} | {} | {bytes} |", FormatName(f), a.name());
        for v in &volumes {
            let cell = row.iter().find(|c| &c.volume == v);
            let text = match cell {
                Some(c) if c.error.is_none() => db(c.snr_f64),
                Some(_) => "refused".into(),
                None => String::new(),
            };
            let _ = write!(s, " {text} |");
        }
        s.push('\n');
    }
    s
}
