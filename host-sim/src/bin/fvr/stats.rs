//! `--stats` and `--stats-json` of every subcommand that renders (`render`,
//! `turntable`, `project`): one schema, the same keys and units everywhere,
//! and per-subcommand members after them.
//!
//! `--stats` prints the lines on stdout after the `wrote …` line;
//! `--stats-json` prints one JSON object on stdout and nothing else there
//! (the `wrote …` line is left out).

use std::path::Path;
use std::time::Duration;

use fvr_engine::volume::Volume;
use fvr_engine::Renderer;
use serde::Serialize;
use serde_json::value::RawValue;

use crate::args::FrameArgs;
use crate::json::{debug_triple, one_line};
use crate::taper::TaperJson;

/// `--stats` and `--stats-json`, worded and parsed once for every
/// subcommand that renders.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub(crate) struct StatsArgs {
    /// Print the sizes, choices and timings after the run (load, plan,
    /// prepare, views).
    #[arg(long)]
    pub(crate) stats: bool,
    /// Print them as one JSON object on stdout instead, and nothing else
    /// there.
    #[arg(long)]
    pub(crate) stats_json: bool,
}

/// `grey` for one channel, `RGB` for three.
pub(crate) fn kind(channels: usize) -> &'static str {
    if channels == 1 {
        "grey"
    } else {
        "RGB"
    }
}

/// The members every renderer's `--stats-json` holds, in the order printed.
#[derive(Serialize)]
pub(crate) struct Stats {
    /// The subcommand: `render`, `turntable` or `project`.
    pub(crate) command: &'static str,
    /// The volume as given (file, data set or phantom).
    pub(crate) volume: String,
    /// Its samples along x, y, z (after --resample).
    pub(crate) dims: [usize; 3],
    /// Its voxel spacing in mm.
    pub(crate) spacing_mm: Box<RawValue>,
    /// Pixel size in mm (voxels with --ignore-spacing).
    pub(crate) pixel_size: f64,
    pub(crate) ignore_spacing: bool,
    /// `[W, H, channels]` of one view.
    pub(crate) image: [usize; 3],
    /// `grey` or `RGB`.
    pub(crate) kind: &'static str,
    pub(crate) spectrum_side: usize,
    pub(crate) precision: &'static str,
    pub(crate) spectrum_bytes: usize,
    /// The `|∇f|` spectrum of the lights (null without lights).
    pub(crate) gradient_spectrum_bytes: Option<usize>,
    pub(crate) filter: &'static str,
    pub(crate) oversample: serde_json::Value,
    /// Estimated SNR of the stored spectrum against the f64 pipeline.
    pub(crate) storage_snr_db: f64,
    /// The planner's predicted SNR of a view (null when none was made).
    pub(crate) predicted_db: Option<f64>,
    pub(crate) load_ms: f64,
    pub(crate) plan_ms: f64,
    /// Filter fit and 3D transforms.
    pub(crate) prepare_ms: f64,
    /// Views rendered.
    pub(crate) views: usize,
    /// All views, without loading, preparing or writing.
    pub(crate) views_ms: f64,
    pub(crate) ms_per_view: f64,
    /// The file written.
    pub(crate) output: String,
    pub(crate) accuracy: Option<crate::plan::AccuracyJson>,
    /// `--taper`: the voxels and the faces tapered (null without it).
    pub(crate) taper: Option<TaperJson>,
}

/// What a finished job reports, from its prepared renderer.
pub(crate) struct Job<'a> {
    pub(crate) command: &'static str,
    pub(crate) volume_spec: &'a str,
    pub(crate) volume: &'a Volume,
    pub(crate) renderer: &'a Renderer,
    /// The flags after the planner's choice.
    pub(crate) frame: &'a FrameArgs,
    pub(crate) image: [usize; 3],
    pub(crate) load: Duration,
    pub(crate) views: usize,
    pub(crate) views_time: Duration,
    pub(crate) output: &'a Path,
    /// `fvr render --zoom`: the pixels are the renderer's divided by it.
    pub(crate) zoom: usize,
    /// What `--taper` did.
    pub(crate) taper: Option<TaperJson>,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

impl Job<'_> {
    /// The common members.
    pub(crate) fn stats(&self) -> Stats {
        let r = self.renderer;
        let spectrum = &self.frame.spectrum;
        Stats {
            command: self.command,
            volume: self.volume_spec.to_string(),
            dims: self.volume.dims,
            spacing_mm: debug_triple(self.volume.spacing),
            pixel_size: r.sampling().pixel_size() / self.zoom as f64,
            ignore_spacing: self.frame.units.ignore_spacing,
            image: self.image,
            kind: kind(self.image[2]),
            spectrum_side: r.n(),
            precision: spectrum.precision.name(),
            spectrum_bytes: r.spectra().density.bytes(),
            gradient_spectrum_bytes: r.spectra().gradient.as_ref().map(|g| g.bytes()),
            filter: r.filter().kind().name(),
            oversample: crate::plan::oversample_json(spectrum.oversample),
            storage_snr_db: r.storage_snr_db(),
            predicted_db: spectrum
                .outcome
                .map(|o| o.prediction.db)
                .filter(|db| db.is_finite()),
            load_ms: ms(self.load),
            plan_ms: ms(r.plan().time),
            prepare_ms: ms(r.prepare_time()),
            views: self.views,
            views_ms: ms(self.views_time),
            ms_per_view: ms(self.views_time) / self.views.max(1) as f64,
            output: self.output.display().to_string(),
            accuracy: crate::plan::json(spectrum),
            taper: self.taper.clone(),
        }
    }

    /// `--stats-json`: the common members, then `extra`'s, on one line.
    pub(crate) fn print_json(&self, extra: &impl Serialize) {
        #[derive(Serialize)]
        struct Both<'a, X: Serialize> {
            #[serde(flatten)]
            common: Stats,
            #[serde(flatten)]
            extra: &'a X,
        }
        say!(
            "{}",
            one_line(&Both {
                common: self.stats(),
                extra
            })
        );
    }

    /// `--stats`: the common lines, aligned as `render` prints them; the
    /// caller prints its own after.
    pub(crate) fn print_human(&self) {
        let r = self.renderer;
        let d = self.volume.dims;
        let ignore = self.frame.units.ignore_spacing;
        say!(
            "  volume        {}x{}x{} ({})",
            d[0],
            d[1],
            d[2],
            self.volume_spec
        );
        let [dx, dy, dz] = self.volume.spacing;
        say!(
            "  spacing       {dx} x {dy} x {dz} mm{}",
            if ignore {
                " (ignored: --ignore-spacing, voxel units)"
            } else {
                ""
            }
        );
        say!(
            "  pixel size    {} {}",
            r.sampling().pixel_size() / self.zoom as f64,
            if ignore {
                "voxel"
            } else {
                "mm (values in mm x volume units)"
            }
        );
        let [w, h, c] = self.image;
        say!("  image         {w}x{h} {}", kind(c));
        let spectrum = &self.frame.spectrum;
        say!(
            "  spectrum      {}^3 {} = {} bytes ({} bytes/voxel)",
            r.n(),
            spectrum.precision,
            r.spectra().density.bytes(),
            spectrum.precision.bytes()
        );
        match &r.spectra().gradient {
            Some(g) => say!(
                "  |grad f|      {} bytes (second spectrum, for the lights)",
                g.bytes()
            ),
            None => say!("  |grad f|      not built (no light needs it)"),
        }
        let f = r.spectra().density.filter();
        if f.kind().is_kaiser_bessel() {
            say!(
                "  filter        {} (oversample {}, beta {:.3})",
                f.kind().name(),
                spectrum.oversample.name(),
                f.beta()
            );
        } else {
            say!(
                "  filter        {} (oversample {})",
                f.kind().name(),
                spectrum.oversample.name()
            );
        }
        say!(
            "  storage SNR   {:.1} dB (estimate, against the f64 pipeline)",
            r.storage_snr_db()
        );
        crate::plan::print_human(spectrum);
        say!("  load          {:.1} ms", ms(self.load));
        say!("  plan          {:.1} ms", ms(r.plan().time));
        say!("  prepare       {:.1} ms", ms(r.prepare_time()));
        say!(
            "  views         {} in {:.2} ms = {:.2} ms a view",
            self.views,
            ms(self.views_time),
            ms(self.views_time) / self.views.max(1) as f64
        );
    }
}
