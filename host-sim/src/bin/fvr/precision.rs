//! `fvr precision`: arguments, the run, and its outputs (Markdown, CSV,
//! PNG plot).

use crate::Error;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use fvr_core::filter::FilterKind;
use fvr_core::num::{Format, FormatName};

use fvr_host::sources::phantom_by_name;
use fvr_host::studies::precision::plot::plot;
use fvr_host::studies::precision::{
    csv, default_formats, markdown, parse_format, study_subject, summary, Cell, Oversampling,
    Subject,
};

/// Arguments of `fvr precision`.
#[derive(Args, Debug)]
pub(crate) struct PrecisionArgs {
    /// Volumes: built-in phantoms (`gaussians`, `shepp-logan`, `sphere`),
    /// which are measured at every `--sizes` unless given as `name@N`, or
    /// NRRD files.
    #[arg(long, value_delimiter = ',', default_values_t = ["gaussians".to_string(), "shepp-logan".to_string()])]
    volumes: Vec<String>,
    /// Sides for phantoms named without `@N`.
    #[arg(long, value_delimiter = ',', default_values_t = [64usize, 128, 256])]
    sizes: Vec<usize>,
    /// Formats: f64, f32, f16, bf16, eEmM (16- or 8-bit minifloat, e.g.
    /// e4m11, e4m3), q15 and q7 (fixed point), q15-line, q15-brickB, q7-line,
    /// q7-brickB (block floating point). Default: the full study.
    #[arg(long, value_delimiter = ',')]
    formats: Vec<String>,
    /// Interpolation filter.
    #[arg(long, default_value = "kb4")]
    filter: String,
    /// Oversampling: `auto` (2 where premultiplication is ill-conditioned),
    /// 1 or 2.
    #[arg(long, default_value = "auto")]
    oversample: String,
    /// Directory for precision.md, precision.csv and precision.png (and
    /// extremes.md); without it the Markdown goes to standard output.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Measure the stability cases instead (constant, impulse, Nyquist
    /// checkerboard, u16 65535, 1e-6 scaling, Hounsfield units) at this side,
    /// at oversampling 1 and at the automatic choice.
    #[arg(long)]
    extremes: Option<usize>,
}

/// Run the study.
///
/// # Errors
/// Bad arguments (named, before any work), unreadable volumes, or output
/// that cannot be written.
pub(crate) fn run(args: &PrecisionArgs) -> Result<(), Error> {
    // Configuration first: every error here comes before any transform.
    let formats: Vec<Format> = if args.formats.is_empty() {
        default_formats()
    } else {
        args.formats
            .iter()
            .map(|s| parse_format(s))
            .collect::<Result<_, _>>()?
    };
    let kind = FilterKind::from_name(&args.filter)
        .ok_or_else(|| format!("unknown filter `{}`", args.filter))?;
    let oversampling = match args.oversample.as_str() {
        "auto" => Oversampling::Auto,
        "1" => Oversampling::Fixed(1),
        "2" => Oversampling::Fixed(2),
        o => return Err(format!("oversampling `{o}` must be auto, 1 or 2").into()),
    };
    if let Some(dir) = &args.out_dir {
        fvr_host::studies::prepare_out_dir(dir)?;
    }
    if let Some(n) = args.extremes {
        if n < 2 || n % 2 != 0 || n > 128 {
            return Err(format!("--extremes {n}: the side must be even, from 2 to 128").into());
        }
        let mut md = format!(
            "# Stability at the extremes: measured\n\n\
             Made by `fvr precision --extremes {n}`: kb4, side {n}, every format; \
             first at oversampling 1, then at the oversampling chosen automatically.\n\n"
        );
        for (title, o) in [
            ("Oversampling 1", Some(1)),
            ("Automatic oversampling", None),
        ] {
            let rows = fvr_host::studies::precision::measure_extremes(n, &formats, o)?;
            md += &format!(
                "## {title}\n\n{}\n",
                fvr_host::studies::precision::extremes_markdown(&rows)
            );
        }
        return match &args.out_dir {
            None => {
                say_part!("{md}");
                Ok(())
            }
            Some(dir) => {
                fvr_host::io::atomic::write_text(&dir.join("extremes.md"), &md)?;
                Ok(())
            }
        };
    }
    let mut specs = Vec::new();
    for v in &args.volumes {
        let is_bare_phantom = !v.contains('@') && phantom_by_name(v).is_some();
        if is_bare_phantom {
            for n in &args.sizes {
                specs.push(format!("{v}@{n}"));
            }
        } else {
            specs.push(v.clone());
        }
    }
    let mut cells: Vec<Cell> = Vec::new();
    for spec in &specs {
        let t0 = Instant::now();
        let mut subject = Subject::load(spec, kind, oversampling)?;
        // Formats this grid cannot hold (a brick that does not divide it) are
        // configuration errors, reported before any transform.
        let grid = fvr_core::volume::padded_size(subject.volume.dims, subject.filter.oversample())?;
        for &f in &formats {
            for a in fvr_host::studies::precision::modes_for(f) {
                f.check(a, grid)
                    .map_err(|e| format!("format {} on {spec}: {e}", FormatName(f)))?;
            }
        }
        eprintln!(
            "fvr precision: {spec} (filter {} at oversampling {})",
            kind.name(),
            subject.filter.oversample()
        );
        let got = study_subject(&mut subject, &formats, |c| match &c.error {
            None => eprintln!(
                "  {:>10} {:>9}  {:.3} B/voxel  {:7.1} dB vs f64  {}",
                FormatName(c.format).to_string(),
                c.arithmetic.name(),
                c.bytes_per_voxel,
                c.snr_f64,
                c.snr_exact
                    .map_or(String::new(), |e| format!("{e:6.1} dB vs exact"))
            ),
            Some(e) => eprintln!(
                "  {:>10} {:>9}  refused: {e}",
                FormatName(c.format).to_string(),
                c.arithmetic.name()
            ),
        })?;
        eprintln!("  ({:.1} s)", t0.elapsed().as_secs_f64());
        cells.extend(got);
    }
    let md = report(&cells, args);
    match &args.out_dir {
        None => say_part!("{md}"),
        Some(dir) => {
            let write =
                |name: &str, text: &str| fvr_host::io::atomic::write_text(&dir.join(name), text);
            write("precision.md", &md)?;
            write("precision.csv", &csv(&cells))?;
            plot(&cells).write_png(&dir.join("precision.png"))?;
            eprintln!(
                "wrote precision.md, precision.csv and precision.png in {}",
                dir.display()
            );
        }
    }
    Ok(())
}

fn report(cells: &[Cell], args: &PrecisionArgs) -> String {
    let mut s = String::from("# Precision study: measured tables\n\n");
    s += &format!(
        "Made by `fvr precision --filter {} --oversample {}{}` (volumes {}; sizes {}). \
         SNR is the worst of four views (the x axis, (1,0.3,0.2), (1,1,1), the y axis), \
         10·log10(Σref²/Σ(img−ref)²). Bytes per voxel count the spectrum (block \
         exponents included) per voxel of the input volume. The max pixel error \
         is relative to the largest pixel of the f64 image.\n\n",
        args.filter,
        args.oversample,
        if args.formats.is_empty() {
            String::new()
        } else {
            format!(" --formats {}", args.formats.join(","))
        },
        args.volumes.join(", "),
        args.sizes
            .iter()
            .map(|n| n.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    s += "## SNR against the f64 pipeline (dB), by volume\n\n";
    s += &summary(cells);
    s += "\n## Every cell\n\n";
    s += &markdown(cells);
    s
}
