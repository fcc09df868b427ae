//! `fvr prepare`: a volume's spectrum, kernel table and twiddles as one
//! `.fvrs` image (`docs/fvrs.md`) for a part, checked against the part's
//! flash and RAM before anything is prepared or written; as the file, a
//! raw image for loading at run time, or a C `.c`/`.h` pair for flash.

use crate::taper::TaperArgs;
use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::fvrs::{Header, Part};
use fvr_core::volume::{padded_size, GridOversampling};
use fvr_engine::spectrum::Precision as EnginePrecision;
use fvr_engine::volume::Volume;
use fvr_engine::{Plan, Renderer, Settings};
use fvr_host::parts::{self, Need, Placement};

use crate::args::{parse_accuracy, parse_filter, volume_help, InputArgs};
use crate::Error;

/// How the image is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum Emit {
    /// The `.fvrs` file, read in place (flash, or a memory-mapped file).
    Fvrs,
    /// The same bytes as `.bin`, to be loaded into RAM at run time.
    Bin,
    /// A `.c`/`.h` pair defining a 64-byte-aligned `const` array (flash).
    C,
}

/// Storage of the spectrum's coefficients.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum StoredPrecision {
    /// IEEE binary16 (f32 arithmetic on the device).
    F16,
    /// IEEE binary32.
    F32,
    /// Q15 block floating point: not in .fvrs 1.0 (refused with a line).
    Q15,
}

#[derive(Args)]
pub(crate) struct PrepareArgs {
    /// A volume file, a raw file with --raw-dims, a data set, or a built-in phantom.
    #[arg(help = volume_help())]
    pub(crate) volume: String,
    /// The part to budget for: m4f (2 MiB flash, 512 KiB RAM), m3 (4 MiB,
    /// 4 MiB), m7 (2 MiB, 1 MiB) or host (no budget).
    #[arg(long = "for", value_name = "PART", value_parser = parse_part)]
    pub(crate) part: Part,
    /// Output: FILE.fvrs (--emit fvrs), FILE.bin (--emit bin), or a name
    /// NAME (or NAME.c) for NAME.c and NAME.h (--emit c; the array is
    /// called NAME, so NAME must be a C identifier).
    #[arg(long, value_name = "PATH")]
    pub(crate) out: PathBuf,
    /// fvrs: the .fvrs file; bin: the same bytes, to load into RAM at run
    /// time (budgeted against RAM); c: a .c/.h pair for flash.
    #[arg(long, value_enum, default_value = "fvrs")]
    pub(crate) emit: Emit,
    /// Spectrum storage: f16 or f32 (q15 is not in .fvrs 1.0).
    #[arg(long, value_enum, default_value = "f16")]
    pub(crate) precision: StoredPrecision,
    /// Interpolation filter. Default: the cheapest predicted to reach
    /// --accuracy.
    #[arg(long, value_parser = parse_filter)]
    pub(crate) filter: Option<FilterKind>,
    /// Grid oversampling, 1 or 2.
    #[arg(long, default_value = "1", value_parser = clap::value_parser!(u32).range(1..=2))]
    pub(crate) oversample: u32,
    /// Target SNR in dB that chooses the filter (default 50).
    #[arg(long, value_name = "DB", value_parser = parse_accuracy)]
    pub(crate) accuracy: Option<f64>,
    /// Resample to N samples along the longest side first. Without it, a
    /// volume too large for the part is halved until it fits (said on
    /// stderr); with it, a size that does not fit is refused.
    #[arg(long, value_name = "N")]
    pub(crate) resample: Option<usize>,
    #[command(flatten)]
    pub(crate) taper: TaperArgs,
    #[command(flatten)]
    pub(crate) input: InputArgs,
}

fn parse_part(s: &str) -> Result<Part, String> {
    Part::from_name(&s.to_ascii_lowercase())
        .ok_or_else(|| format!("unknown part `{s}`: expected m4f, m3, m7 or host"))
}

/// The files written for `emit` at `out`, checked.
fn outputs(args: &PrepareArgs) -> Result<Vec<PathBuf>, Error> {
    let out = &args.out;
    let files = match args.emit {
        Emit::Fvrs | Emit::Bin => {
            let ext: &'static [&'static str] = if args.emit == Emit::Fvrs {
                &["fvrs"]
            } else {
                &["bin"]
            };
            crate::checks::check_output(out, ext, &args.volume, &[])?;
            vec![out.clone()]
        }
        Emit::C => {
            let base = match out.extension().and_then(|e| e.to_str()) {
                Some(e) if e.eq_ignore_ascii_case("c") => out.with_extension(""),
                Some(e) => {
                    return Err(format!(
                        "--emit c writes NAME.c and NAME.h: give --out NAME or NAME.c, not `.{e}`"
                    )
                    .into())
                }
                None => out.clone(),
            };
            let files = vec![base.with_extension("c"), base.with_extension("h")];
            for f in &files {
                crate::checks::check_output(f, &["c", "h"], &args.volume, &[])?;
            }
            files
        }
    };
    Ok(files)
}

fn placement(emit: Emit) -> Placement {
    match emit {
        Emit::Bin => Placement::Ram,
        Emit::Fvrs | Emit::C => Placement::Flash,
    }
}

/// The need of a volume of `dims` prepared as asked (with the widest
/// filter allowed when the planner is still to choose).
fn need_for(
    dims: [usize; 3],
    args: &PrepareArgs,
    precision: fvr_core::fvrs::Precision,
) -> Result<(Need, u64, usize), Error> {
    let kind = args.filter.unwrap_or(FilterKind::Kb6);
    let filter = Filter::new(kind, args.oversample)?;
    let n = padded_size(dims, args.oversample)?;
    let header = Header {
        precision,
        filter,
        part: args.part,
        n,
        dims,
        scale: 1.0,
    };
    let len = header.layout()?.file_len;
    Ok((parts::need(len, n, placement(args.emit)), len, n))
}

/// The volume to prepare: as given, resampled to `--resample`, or halved
/// until it fits the part. Refuses, with the numbers, a size that does not
/// fit.
fn fit(
    volume: Volume,
    args: &PrepareArgs,
    precision: fvr_core::fvrs::Precision,
) -> Result<Volume, Error> {
    let largest = volume.dims.iter().copied().max().unwrap_or(1);
    let refuse = |dims: [usize; 3], e: String| -> Error {
        format!(
            "{} at {} x {} x {} {e}{}",
            args.volume,
            dims[0],
            dims[1],
            dims[2],
            if args.resample.is_some() {
                "; choose a smaller --resample"
            } else {
                ""
            }
        )
        .into()
    };
    if let Some(r) = args.resample {
        let dims = volume.resampled_dims(r)?;
        let (need, _, _) = need_for(dims, args, precision)?;
        parts::check(args.part, need).map_err(|e| refuse(dims, e))?;
        return Ok(volume.resample_isotropic(r)?);
    }
    let (need, _, _) = need_for(volume.dims, args, precision)?;
    let Err(first) = parts::check(args.part, need) else {
        return Ok(volume);
    };
    let mut side = largest / 2;
    while side >= 8 {
        let dims = volume.resampled_dims(side)?;
        let (need, len, n) = need_for(dims, args, precision)?;
        if parts::check(args.part, need).is_ok() {
            if !fvr_host::progress::quiet() {
                eprintln!(
                    "fvr: note: {} at {} x {} x {} {first}; resampled to {} x {} x {} \
                     (n = {n}, {} image) to fit (--resample N chooses the size)",
                    args.volume,
                    volume.dims[0],
                    volume.dims[1],
                    volume.dims[2],
                    dims[0],
                    dims[1],
                    dims[2],
                    parts::bytes(len)
                );
            }
            return Ok(volume.resample_isotropic(side)?);
        }
        side /= 2;
    }
    Err(refuse(volume.dims, first))
}

pub(crate) fn prepare(args: &PrepareArgs) -> Result<(), Error> {
    let precision = match args.precision {
        StoredPrecision::F16 => fvr_core::fvrs::Precision::F16,
        StoredPrecision::F32 => fvr_core::fvrs::Precision::F32,
        StoredPrecision::Q15 => {
            return Err(
                "--precision q15: Q15 block-floating-point spectra are not in the .fvrs \
                        1.0 format yet (f16 or f32); the Rust firmware's Q15 path prepares on \
                        the device"
                    .into(),
            )
        }
    };
    args.taper.check()?;
    let files = outputs(args)?;
    let mut volume = args.input.load(&args.volume)?;
    for f in &files {
        crate::checks::check_not_input(f)?;
    }
    args.taper.apply(&mut volume)?;
    let volume = fit(volume, args, precision)?;
    let settings = Settings {
        accuracy_db: args.accuracy,
        filter: args.filter,
        oversample: Some(if args.oversample == 2 {
            GridOversampling::X2
        } else {
            GridOversampling::X1
        }),
        precision: Some(match precision {
            fvr_core::fvrs::Precision::F16 => EnginePrecision::F16,
            fvr_core::fvrs::Precision::F32 => EnginePrecision::F32,
        }),
        ..Settings::default()
    };
    settings.check()?;
    let plan = Plan::choose(&volume, &settings)?;
    for w in &plan.warnings {
        eprintln!("fvr: warning: {w}");
    }
    let renderer = Renderer::prepare(&volume, settings, plan, &|_| {})?;
    let image = fvr_host::io::fvrs::image(&renderer.spectra().density, args.part)?;
    // The same check with the filter chosen: the image is never larger than
    // the estimate (the widest filter), but say so if it were.
    let n = renderer.n();
    let need = parts::need(image.len() as u64, n, placement(args.emit));
    parts::check(args.part, need)?;
    write_outputs(args, &files, &image)?;
    if !fvr_host::progress::quiet() {
        let d = renderer.dims();
        eprintln!(
            "fvr: note: wrote {} ({} image: {} {} spectrum n = {n} of {} x {} x {}, filter {}) for {}{}",
            files
                .iter()
                .map(|f| f.display().to_string())
                .collect::<Vec<_>>()
                .join(" and "),
            parts::bytes(image.len() as u64),
            precision.name(),
            if n.is_power_of_two() { "cube" } else { "grid" },
            d[0],
            d[1],
            d[2],
            renderer.filter().kind().name(),
            args.part.name(),
            parts::memory(args.part).map_or(String::new(), |m| format!(
                "; needs {} bytes of flash of {} and {} of RAM of {}",
                need.flash, m.flash, need.ram, m.ram
            ))
        );
    }
    Ok(())
}

/// Write the image as asked; for C, both texts are made before either
/// file is written.
fn write_outputs(args: &PrepareArgs, files: &[PathBuf], image: &[u8]) -> Result<(), Error> {
    use fvr_host::io::atomic::write_bytes;
    let fail = |f: &Path, e: std::io::Error| format!("cannot write `{}`: {e}", f.display());
    match args.emit {
        Emit::Fvrs | Emit::Bin => write_bytes(&files[0], image).map_err(|e| fail(&files[0], e))?,
        Emit::C => {
            let name = files[0]
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or_default();
            let header_file = files[1]
                .file_name()
                .and_then(|s| s.to_str())
                .unwrap_or_default();
            let command = format!(
                "fvr prepare {} --for {} --precision {} --emit c",
                args.volume,
                args.part.name(),
                match args.precision {
                    StoredPrecision::F32 => "f32",
                    _ => "f16",
                }
            );
            let (h, c) = fvr_host::io::c_array::c_pair(image, name, header_file, &command)?;
            write_bytes(&files[1], h.as_bytes()).map_err(|e| fail(&files[1], e))?;
            write_bytes(&files[0], c.as_bytes()).map_err(|e| fail(&files[0], e))?;
        }
    }
    Ok(())
}
