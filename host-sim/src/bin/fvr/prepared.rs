//! `fvr render PREPARED.fvrs`: a view of a spectrum `fvr prepare` stored,
//! without loading, planning or preparing the volume again (docs/fvrs.md).
//!
//! The file fixes the filter, the grid and the precision, and holds no
//! voxel spacing, so the view is rendered in voxel units: the image is the
//! one `fvr render VOLUME --ignore-spacing` makes with the same filter,
//! oversampling and precision, bit for bit. Options that need the volume
//! (lights, depth cues, adaptive filtering, `--exact`, the planner's) are
//! refused in one line rather than ignored.

use std::path::Path;
use std::time::Instant;

use fvr_core::fvrs::Precision as Stored;
use fvr_core::geometry::{Sampling, View};
use fvr_engine::spectrum::{AnySpectrum, OwnedSpectrum};
use fvr_host::image::output::{write_png, Style, Window};
use fvr_host::image::Image;
use serde::Serialize;

use crate::render::RenderArgs;
use crate::Error;

/// Whether `spec` names a prepared spectrum (`.fvrs`, any case).
pub(crate) fn is_prepared(spec: &str) -> bool {
    Path::new(spec)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("fvrs"))
}

/// The first option given that a prepared spectrum cannot honour.
fn refused_option(args: &RenderArgs) -> Option<&'static str> {
    let given = &args.frame.spectrum.given;
    let look = &args.look;
    [
        (given.filter, "--filter"),
        (given.oversample, "--oversample"),
        (given.precision, "--precision"),
        (args.frame.spectrum.accuracy.is_some(), "--accuracy"),
        (look.depth_cue != "none", "--depth-cue"),
        (look.ambient.is_some(), "--ambient"),
        (!look.lights.is_empty(), "--light"),
        (look.light_ring.is_some(), "--light-ring"),
        (look.resample.is_some(), "--resample"),
        (look.taper.taper.is_some(), "--taper"),
        (look.preview_level > 0, "--preview-level"),
        (args.adaptive.is_some(), "--adaptive"),
        (args.exact, "--exact"),
        (args.frame.units.pixel_size.is_some(), "--pixel-size"),
        (args.input.raw_dims.is_some(), "--raw-dims"),
        (args.input.background.is_some(), "--background"),
    ]
    .into_iter()
    .find_map(|(given, name)| given.then_some(name))
}

/// Render `view` of the prepared spectrum `path` into `out` (`ext`: png or
/// nrrd), with `style` for a PNG.
pub(crate) fn render(
    args: &RenderArgs,
    path: &str,
    out: &Path,
    ext: &str,
    view: &View,
    style: Style,
) -> Result<(), Error> {
    if let Some(option) = refused_option(args) {
        return Err(format!(
            "{option} does not apply to a prepared spectrum (`{path}`): it fixes the filter, \
             grid and precision and renders plain X-ray views in voxel units; give the volume \
             itself to use {option}"
        )
        .into());
    }
    let t0 = Instant::now();
    let file = fvr_host::io::fvrs::FvrsFile::read(Path::new(path))?;
    // `read` checked every section and value; this takes the header again.
    let parsed = file.parse_read().map_err(|e| format!("`{path}`: {e}"))?;
    let copy = |what: &str| format!("`{path}`: the {what} spectrum has block exponents");
    let spectrum = match parsed.header().precision {
        Stored::F16 => AnySpectrum::F16(
            OwnedSpectrum::from_view(&parsed.spectrum_f16().map_err(|e| e.to_string())?)
                .ok_or_else(|| copy("f16"))?,
        ),
        Stored::F32 => AnySpectrum::F32(
            OwnedSpectrum::from_view(&parsed.spectrum_f32().map_err(|e| e.to_string())?)
                .ok_or_else(|| copy("f32"))?,
        ),
    };
    drop(file);
    let t_load = t0.elapsed();
    let dims = parsed_dims(&spectrum);
    let n = spectrum.n();
    let side = fvr_engine::plan::image_side(dims, n)?;
    let (w, h) = args.frame.size.unwrap_or((side, side));
    fvr_core::image::check_image(w, h, n)?;
    let t1 = Instant::now();
    let data = spectrum.render_sampled(view, &Sampling::UNIT, w, h)?;
    let t_view = t1.elapsed();
    crate::checks::check_finite(&data, "the prepared spectrum")?;
    let mut window = None;
    if ext == "png" {
        let range = style.window.resolve(&data);
        window = Some([range.0, range.1]);
        let style = Style {
            window: Window::Range(range.0, range.1),
            ..style
        };
        write_png(out, w, h, &data, &style)?;
    } else {
        let image = Image {
            width: w,
            height: h,
            channels: 1,
            data,
        };
        // One voxel a pixel: the spacing the render in voxel units writes.
        fvr_host::image::nrrd_image::write_image_nrrd(out, &image, Some(1.0))?;
    }
    let filter = spectrum.filter();
    let stats = PreparedStats {
        command: "render",
        volume: path.to_string(),
        dims,
        spacing_mm: None,
        pixel_size: 1.0,
        ignore_spacing: true,
        image: [w, h, 1],
        kind: "grey",
        spectrum_side: n,
        precision: match parsed_precision(&spectrum) {
            Stored::F16 => "f16",
            Stored::F32 => "f32",
        },
        spectrum_bytes: spectrum.bytes(),
        filter: filter.kind().name(),
        oversample: filter.oversample(),
        load_ms: t_load.as_secs_f64() * 1e3,
        plan_ms: 0.0,
        prepare_ms: 0.0,
        views: 1,
        views_ms: t_view.as_secs_f64() * 1e3,
        ms_per_view: t_view.as_secs_f64() * 1e3,
        output: out.display().to_string(),
        accuracy: None,
        taper: None,
        window,
    };
    if args.report.stats_json {
        say!("{}", crate::json::one_line(&stats));
        return Ok(());
    }
    say!("wrote {} ({w}x{h} grey)", out.display());
    if args.report.stats {
        say!(
            "  volume        {}x{}x{} ({path}, prepared)",
            dims[0],
            dims[1],
            dims[2]
        );
        say!("  pixel size    1 voxel (a prepared spectrum holds no spacing)");
        say!(
            "  spectrum      {n}^3 {} = {} bytes, filter {} (oversample {})",
            stats.precision,
            stats.spectrum_bytes,
            stats.filter,
            stats.oversample
        );
        say!("  load          {:.1} ms", stats.load_ms);
        say!("  view          {:.2} ms", stats.views_ms);
    }
    Ok(())
}

fn parsed_dims(spectrum: &AnySpectrum) -> [usize; 3] {
    match spectrum {
        AnySpectrum::F16(s) => s.view().dims(),
        AnySpectrum::F32(s) => s.view().dims(),
        AnySpectrum::F64(s) => s.view().dims(),
    }
}

fn parsed_precision(spectrum: &AnySpectrum) -> Stored {
    match spectrum {
        AnySpectrum::F16(_) => Stored::F16,
        _ => Stored::F32,
    }
}

/// `--stats-json` of a prepared render: the members of every renderer's
/// schema (`stats::Stats`), with `spacing_mm`, the storage SNR, the
/// prediction and `accuracy` unknown (null) and no planning or preparation.
#[derive(Serialize)]
struct PreparedStats {
    command: &'static str,
    volume: String,
    dims: [usize; 3],
    spacing_mm: Option<[f64; 3]>,
    pixel_size: f64,
    ignore_spacing: bool,
    image: [usize; 3],
    kind: &'static str,
    spectrum_side: usize,
    precision: &'static str,
    spectrum_bytes: usize,
    filter: &'static str,
    oversample: u32,
    load_ms: f64,
    plan_ms: f64,
    prepare_ms: f64,
    views: usize,
    views_ms: f64,
    ms_per_view: f64,
    output: String,
    accuracy: Option<()>,
    taper: Option<()>,
    window: Option<[f64; 2]>,
}
