//! `fvr._fvr`, the extension module behind the Python package `fvr`
//! (python/fvr): `load` reads whatever the CLI's VOLUME takes,
//! `Renderer` prepares a volume once and renders batches of views into
//! numpy arrays on all cores with the GIL released.
//!
//! Everything here is safe Rust: PyO3's macros and the numpy crate's
//! checked borrows need no `unsafe` of ours (the workspace forbids it).

mod errors;
mod renderer;
mod report;
mod settings;
mod views;

use fvr_engine::volume::Volume;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// Load `spec` through the CLI's reader, with the GIL released, checked
/// against the memory limit as the CLI checks it.
pub(crate) fn load_volume(py: Python<'_>, spec: &str) -> PyResult<Volume> {
    let spec_owned = spec.to_string();
    py.detach(move || fvr_host::sources::load_volume(&spec_owned, None))
        .map_err(|e| errors::load(spec, e))
}

/// Load whatever the CLI's VOLUME takes: a file (NRRD, NIfTI, DICOM, .den,
/// .inv3), a data set (brainsmall, ct-head, mri-head) or a phantom
/// (gaussians@64, sphere@64, teapot@64).
///
/// Returns (volume, spacing): a float32 (z, y, x) array that owns the
/// loaded samples (no copy) and the spacing (dz, dy, dx) in mm. Raises
/// FileNotFoundError, OSError, MemoryError or ValueError.
#[pyfunction]
fn load<'py>(py: Python<'py>, spec: &str) -> PyResult<Bound<'py, PyTuple>> {
    let volume = load_volume(py, spec)?;
    let [nx, ny, nz] = volume.dims;
    let [dx, dy, dz] = volume.spacing;
    // The Vec moves into the array: x fastest is C order for (z, y, x).
    let arr = PyArray1::from_vec(py, volume.data)
        .reshape([nz, ny, nx])?
        .into_any();
    let spacing = PyTuple::new(py, [dz, dy, dx])?.into_any();
    PyTuple::new(py, [arr, spacing])
}

/// The limit `set_max_memory` set, if any.
static MAX_MEMORY: std::sync::OnceLock<u64> = std::sync::OnceLock::new();

/// The CLI's --max-memory: an integer of bytes, or text such as "4G". Set
/// once per process, as the flag; a second, different value raises
/// ValueError.
#[pyfunction]
fn set_max_memory(limit: &Bound<'_, PyAny>) -> PyResult<()> {
    let bytes = match limit.extract::<u64>() {
        Ok(b) => b,
        Err(_) => {
            let text: String = limit.extract().map_err(|_| {
                errors::type_error("max memory must be a number of bytes or text such as \"4G\"")
            })?;
            fvr_host::budget::parse_bytes("max memory", &text).map_err(errors::value)?
        }
    };
    // The engine takes the first limit set, as the CLI's flag: say so
    // rather than ignore a second one.
    let first = *MAX_MEMORY.get_or_init(|| bytes);
    if first != bytes {
        return Err(errors::value(format!(
            "the memory limit is set once per process (as --max-memory), and it is already {first} bytes"
        )));
    }
    fvr_host::budget::set_max_memory(bytes);
    Ok(())
}

/// The memory limit in force: (bytes, where it comes from).
#[pyfunction]
fn memory_limit() -> (u64, String) {
    let limit = fvr_host::budget::limit();
    (limit.bytes, limit.source.to_string())
}

#[pymodule]
fn _fvr(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // The machine's limits (ulimit -v, cgroup, MemAvailable), as `fvr` reads them.
    fvr_host::budget::install();
    m.add_class::<renderer::PyRenderer>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(set_max_memory, m)?)?;
    m.add_function(wrap_pyfunction!(memory_limit, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
