//! `Renderer.report` (the keys of `fvr render --stats-json` that describe
//! the volume and its preparation) and `Renderer.spectrum()`.

use fvr_engine::spectrum::AnySpectrum;
use fvr_engine::Renderer;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// σ as `--stats-json` prints it: an integer for 1 and 2, else a float.
fn oversample<'py>(
    py: Python<'py>,
    grid: fvr_core::volume::GridOversampling,
) -> PyResult<Bound<'py, PyAny>> {
    Ok(if grid.is_pow2() {
        grid.integer().into_pyobject(py)?.into_any()
    } else {
        grid.factor().into_pyobject(py)?.into_any()
    })
}

/// `None` for a term with no error at all (infinite dB), as in the JSON.
fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// The report of `r`, whose volume came from `source` with `spacing`
/// (`[dx, dy, dz]`, listed so) after `load_ms`.
pub(crate) fn report<'py>(
    py: Python<'py>,
    r: &Renderer,
    source: &str,
    spacing: [f64; 3],
    load_ms: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let plan = r.plan();
    let spectra = r.spectra();
    let side = r.default_side();
    let channels = r.settings().scene.channels();
    d.set_item("volume", source)?;
    d.set_item("dims", r.dims().to_vec())?;
    d.set_item("spacing_mm", spacing.to_vec())?;
    d.set_item("pixel_size", r.sampling().pixel_size())?;
    d.set_item("ignore_spacing", r.settings().units.ignore_spacing)?;
    d.set_item("image", vec![side, side, channels])?;
    d.set_item("spectrum_side", r.n())?;
    d.set_item("precision", plan.precision.name())?;
    d.set_item("spectrum_bytes", spectra.density.bytes())?;
    d.set_item(
        "gradient_spectrum_bytes",
        spectra.gradient.as_ref().map(AnySpectrum::bytes),
    )?;
    d.set_item("filter", r.filter().kind().name())?;
    d.set_item("oversample", oversample(py, plan.grid)?)?;
    d.set_item("storage_snr_db", r.storage_snr_db())?;
    d.set_item("load_ms", load_ms)?;
    d.set_item("plan_ms", plan.time.as_secs_f64() * 1e3)?;
    d.set_item("prepare_ms", r.prepare_time().as_secs_f64() * 1e3)?;
    d.set_item("preview_level", r.settings().preview_level)?;
    let p = plan.prediction;
    let accuracy = PyDict::new(py);
    accuracy.set_item("target_db", plan.target_db)?;
    accuracy.set_item(
        "target_is_default",
        plan.target_db.is_some() && !plan.explicit,
    )?;
    accuracy.set_item("predicted_db", finite(p.db))?;
    accuracy.set_item("predicted_views_db", p.views_db.map(finite).to_vec())?;
    accuracy.set_item("filter", p.candidate.filter.name())?;
    accuracy.set_item("oversample", oversample(py, p.grid)?)?;
    accuracy.set_item("precision", p.candidate.precision.name())?;
    accuracy.set_item("limited_by", p.dominant().name())?;
    accuracy.set_item("edge_db", finite(p.parts_db[0]))?;
    accuracy.set_item("kernel_db", finite(p.parts_db[1]))?;
    accuracy.set_item("storage_db", finite(p.parts_db[2]))?;
    d.set_item("accuracy", accuracy)?;
    let warnings: Vec<&String> = plan.warnings.iter().chain(r.warnings()).collect();
    d.set_item("warnings", warnings)?;
    Ok(d)
}

/// The density spectrum as a read-only `(n, n, n)` array in its storage
/// type (float16, float32 or float64; `kx` fastest, natural Hartley
/// order), and the scale the engine divides images by.
pub(crate) fn spectrum<'py>(py: Python<'py>, r: &Renderer) -> PyResult<Bound<'py, PyTuple>> {
    let n = r.n();
    let density = &r.spectra().density;
    let (arr, scale) = match density {
        AnySpectrum::F16(s) => (PyArray1::from_slice(py, s.data()).into_any(), s.scale()),
        AnySpectrum::F32(s) => (PyArray1::from_slice(py, s.data()).into_any(), s.scale()),
        AnySpectrum::F64(s) => (PyArray1::from_slice(py, s.data()).into_any(), s.scale()),
    };
    let arr = arr.call_method1("reshape", ((n, n, n),))?;
    let kwargs = PyDict::new(py);
    kwargs.set_item("write", false)?;
    arr.call_method("setflags", (), Some(&kwargs))?;
    PyTuple::new(py, [arr, scale.into_pyobject(py)?.into_any()])
}
