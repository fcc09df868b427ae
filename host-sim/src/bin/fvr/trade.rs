//! `fvr trade`: the speed–accuracy map, written to trade.csv, trade.md and
//! trade.png.

use crate::Error;
use std::path::PathBuf;

use clap::Args;
use fvr_host::studies::trade::{csv, human_bytes, measure, plot, summary, Sweep, SweepAxes};

/// Arguments of `fvr trade`.
#[derive(Args, Debug, Clone)]
pub(crate) struct TradeArgs {
    /// Interpolation filters, comma-separated: nearest, linear, cubic, kb3,
    /// kb4, kb5, kb6.
    #[arg(long, default_value = "nearest,linear,cubic,kb3,kb4,kb5,kb6")]
    filters: String,
    /// Oversampling factors: 1, 2 or both.
    #[arg(long, default_value = "1,2")]
    oversample: String,
    /// Storage formats of the spectrum: f16, f32, bf16, a 16-bit minifloat
    /// eEmM (e.g. e4m11), q15, q15-line.
    #[arg(long, default_value = "f16,f32")]
    formats: String,
    /// Adaptive tolerances in dB, or `none` for the full filter everywhere.
    /// Adaptive points need oversampling 2 and level 0, and a filter wider
    /// than nearest (the cheaper filter).
    #[arg(long, default_value = "none,40,60")]
    adaptive: String,
    /// Progressive levels: 0 is the full image (the volume's side); L is a
    /// preview 2^L times smaller from the central 1/4^L of the slice.
    #[arg(long, default_value = "0,1,2")]
    levels: String,
    /// The Gaussian-mixture phantom: `gaussians` (8 Gaussians, sigma 1.5 to
    /// 0.12 N voxels) or `blobs` (24 smaller ones, sigma 1.5 to 0.05 N:
    /// more detail, so filters and previews differ more).
    #[arg(long, default_value = "gaussians")]
    phantom: String,
    /// Sides of the phantom (16 to 256; 512 with --large).
    #[arg(long, default_value = "64,128")]
    sizes: String,
    /// Allow sides up to 512 (a 512³ f16 spectrum at oversampling 2 holds 2 GiB).
    #[arg(long)]
    large: bool,
    /// View directions per point.
    #[arg(long, default_value_t = 3)]
    views: usize,
    /// Timed renders of each view per point (the median of views × repeats
    /// is reported).
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Memory the sweep may use, in bytes with an optional K, M or G suffix
    /// (powers of 1024). Default: MemAvailable from /proc/meminfo.
    #[arg(long, value_name = "BYTES")]
    memory_limit: Option<String>,
    /// Directory for trade.csv, trade.png and trade.md.
    #[arg(long, default_value = "fvr-trade")]
    out_dir: PathBuf,
}

impl TradeArgs {
    fn axes(&self) -> SweepAxes {
        SweepAxes {
            filters: self.filters.clone(),
            oversample: self.oversample.clone(),
            formats: self.formats.clone(),
            adaptive: self.adaptive.clone(),
            levels: self.levels.clone(),
            phantom: self.phantom.clone(),
            sizes: self.sizes.clone(),
            large: self.large,
            views: self.views,
            repeats: self.repeats,
        }
    }
}

/// The command line as typed, with the program named `fvr`.
fn command_line() -> String {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    args.insert(0, "fvr".into());
    args.join(" ")
}

/// Run `fvr trade`.
///
/// # Errors
/// Bad or conflicting arguments and a sweep beyond memory (both before any
/// work), a pipeline failure, or output that cannot be written.
pub(crate) fn run(args: &TradeArgs) -> Result<(), Error> {
    let sweep = Sweep::from_axes(&args.axes())?;
    let (available, source) = match &args.memory_limit {
        Some(text) => (
            fvr_host::budget::parse_bytes("--memory-limit", text)?,
            "--memory-limit".to_string(),
        ),
        None => {
            let limit = fvr_host::budget::limit();
            (limit.bytes, limit.source.to_string())
        }
    };
    sweep.check_memory(available, &source)?;
    let dir = &args.out_dir;
    fvr_host::studies::prepare_out_dir(dir)?;
    let total = sweep.settings().len();
    eprintln!("fvr trade: {total} points");
    let mut done = 0;
    let rows = measure(&sweep, |r| {
        done += 1;
        eprintln!(
            "  [{done}/{total}] {}³ {:<40} {:9.3} ms {:7.1} dB  {}",
            r.setting.size,
            r.setting.describe(),
            r.ms_per_view,
            r.snr_db,
            human_bytes(r.memory.held())
        );
    })?;
    let write = |name: &str, text: &str| fvr_host::io::atomic::write_text(&dir.join(name), text);
    write("trade.csv", &csv(&rows, sweep.views, sweep.repeats))?;
    write("trade.md", &summary(&rows, &sweep, &command_line()))?;
    plot(&rows).write_png(&dir.join("trade.png"))?;
    eprintln!(
        "wrote trade.csv, trade.md and trade.png in {}",
        dir.display()
    );
    Ok(())
}
