//! `fvr.Renderer`: one prepared volume, any number of batches of views.

use std::time::Instant;

use fvr_engine::memory::{Budget, Held};
use fvr_engine::volume::Volume;
use fvr_engine::{Plan, Renderer};
use numpy::ndarray::IxDyn;
use numpy::{PyArray3, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::errors::{over_budget, pipeline, type_error, value};
use crate::settings::Options;
use crate::views::shape_text;

/// A volume prepared for rendering: premultiplied, 3D Hartley transformed
/// and stored once; each view is then a 2D slice and an inverse 2D transform.
///
/// `volume` is a 3-D array (z, y, x) of real numbers (converted to aligned
/// C-contiguous float32 when it is not already) or a VOLUME string as
/// `fvr.load` takes it; `spacing` is (dz, dy, dx) in mm, or one number.
/// Settings left None are the accuracy planner's, as `fvr render` leaves
/// them without the flags: the cheapest filter, grid and precision
/// predicted to reach `accuracy_db` (50 dB by default). The scene
/// (`depth_cue`, `lights`, `ambient`) is part of the preparation.
///
/// Raises ValueError for bad settings or data, TypeError for non-numeric
/// input, MemoryError beyond the memory limit, and what `fvr.load` raises
/// for a VOLUME string. See docs/python.md.
#[pyclass(module = "fvr", name = "Renderer", frozen)]
pub(crate) struct PyRenderer {
    inner: Renderer,
    /// The spectra, counted against the memory limit while this renderer
    /// lives (later checks see them, as the CLI's do).
    _held: Held,
    source: String,
    spacing: [f64; 3],
    load_ms: f64,
}

/// The volume `volume` as a float32 `(z, y, x)` array, converted from any
/// real dtype and memory order.
fn as_volume_array<'py>(volume: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let py = volume.py();
    let np = py.import("numpy")?;
    let arr = np.call_method1("asarray", (volume,)).map_err(|e| {
        type_error(format!(
            "volume must be a 3-D array of numbers or a VOLUME name: {}",
            e.value(py)
        ))
    })?;
    let dtype = arr.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if kind.len() != 1 || !"biuf".contains(kind.as_str()) {
        return Err(type_error(format!(
            "volume must hold real numbers, got dtype {}",
            dtype.str()?
        )));
    }
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape.len() != 3 || shape.contains(&0) {
        return Err(value(format!(
            "volume must be a non-empty 3-D array (z, y, x), got shape {}",
            shape_text(&shape)
        )));
    }
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", np.getattr("float32")?)?;
    // C-contiguous and aligned (arrays unpickled from out-of-band buffers,
    // as dask sends them, may be misaligned): no copy when it already is
    // float32, C-contiguous and aligned.
    kwargs.set_item("requirements", "CA")?;
    let arr = np.call_method("require", (arr,), Some(&kwargs))?;
    arr.cast_into::<PyArray3<f32>>()
        .map_err(|_| type_error("volume must be a float32 array"))
}

/// The first non-finite voxel's `(z, y, x)`, if any.
fn first_non_finite(data: &[f32], dims: [usize; 3]) -> Option<(usize, usize, usize)> {
    let i = data.iter().position(|v| !v.is_finite())?;
    let [nx, ny, _] = dims;
    Some((i / (nx * ny), (i / nx) % ny, i % nx))
}

/// Spacing `(dz, dy, dx)` from Python, as the engine's `[dx, dy, dz]`.
fn engine_spacing(spacing: Option<&Bound<'_, PyAny>>) -> PyResult<Option<[f64; 3]>> {
    let Some(s) = spacing.filter(|s| !s.is_none()) else {
        return Ok(None);
    };
    if let Ok(v) = s.extract::<f64>() {
        return Ok(Some([v; 3]));
    }
    let v: Vec<f64> = s
        .extract()
        .map_err(|_| type_error("spacing must be three numbers (dz, dy, dx) in mm, or one"))?;
    match v.as_slice() {
        [dz, dy, dx] => Ok(Some([*dx, *dy, *dz])),
        _ => Err(value(format!(
            "spacing must be three numbers (dz, dy, dx) in mm, got {}",
            v.len()
        ))),
    }
}

/// What preparing `volume` for `plan` holds at its peak: the volume's
/// copy, the spectra and the preparation's half spectrum, as
/// `fvr render` counts them (host-sim's `plan_job`).
fn preparation_budget(volume: &Volume, plan: &Plan, spectra: u64) -> Budget {
    let cells = volume.data.len() as u64;
    let n = plan.grid.side(volume.dims).map_or(u64::MAX, |n| n as u64);
    let bytes = plan.precision.bytes() as u64;
    let complex = if bytes == 8 { 16 } else { 8 };
    let mut budget = Budget::new();
    budget.hold("volume", cells, 4);
    budget.hold(
        "spectrum",
        n.saturating_pow(3).saturating_mul(spectra),
        bytes,
    );
    budget.hold(
        "preparation half spectrum",
        (n / 2 + 1).saturating_mul(n).saturating_mul(n),
        complex,
    );
    if spectra > 1 {
        budget.hold("gradient volume", cells, 4);
    }
    budget
}

const PREPARE_HINT: &str =
    "use a smaller volume, precision=\"f16\" or oversample=1, or raise fvr.set_max_memory";
const BATCH_HINT: &str =
    "render fewer views at once or a smaller size, or raise fvr.set_max_memory";

#[pymethods]
impl PyRenderer {
    #[new]
    #[pyo3(signature = (
        volume, spacing=None, *, accuracy_db=None, filter=None, oversample=None,
        precision=None, depth_cue=None, ambient=None, lights=None,
        ignore_spacing=false, pixel_size=None, preview_level=0, adaptive=None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new<'py>(
        py: Python<'py>,
        volume: &Bound<'py, PyAny>,
        spacing: Option<&Bound<'py, PyAny>>,
        accuracy_db: Option<f64>,
        filter: Option<String>,
        oversample: Option<f64>,
        precision: Option<String>,
        depth_cue: Option<String>,
        ambient: Option<Bound<'py, PyAny>>,
        lights: Option<Bound<'py, PyAny>>,
        ignore_spacing: bool,
        pixel_size: Option<f64>,
        preview_level: u32,
        adaptive: Option<f64>,
    ) -> PyResult<Self> {
        let options = Options {
            accuracy_db,
            filter,
            oversample,
            precision,
            depth_cue,
            ambient,
            lights,
            ignore_spacing,
            pixel_size,
            preview_level,
            adaptive_db: adaptive,
        };
        let settings = options.settings()?;
        let given_spacing = engine_spacing(spacing)?;
        let t0 = Instant::now();
        // A VOLUME name or file, as the CLI takes it; else an array.
        let (volume, source) = if let Ok(spec) = volume.extract::<String>() {
            let loaded = crate::load_volume(py, &spec)?;
            (loaded, spec)
        } else {
            let arr = as_volume_array(volume)?;
            let shape = arr.shape().to_vec();
            let dims = [shape[2], shape[1], shape[0]];
            let readonly = arr
                .try_readonly()
                .map_err(|_| value("volume is being written by another call"))?;
            let data = readonly.as_slice()?;
            if let Some((z, y, x)) = first_non_finite(data, dims) {
                return Err(value(format!(
                    "volume holds a non-finite value (NaN or infinity) at (z, y, x) = ({z}, {y}, {x})"
                )));
            }
            // The engine's volume owns its samples: one copy, dropped once
            // the spectrum is built (counted in the budget below).
            let copy = fvr_engine::memory::Budget::new()
                .hold("volume", data.len() as u64, 4)
                .check(fvr_engine::memory::limit(), PREPARE_HINT);
            copy.map_err(|e| over_budget(&e))?;
            let volume = Volume {
                dims,
                // With the GIL held: no Python thread writes the array meanwhile.
                data: data.to_vec(),
                spacing: fvr_engine::volume::DEFAULT_SPACING,
                orientation: None,
            };
            (volume, "array".to_string())
        };
        let volume = match given_spacing {
            Some(s) => volume
                .with_spacing(s)
                .map_err(|e| value(format!("spacing: {e}")))?,
            None => volume,
        };
        let load_ms = t0.elapsed().as_secs_f64() * 1e3;
        let spectra = if settings.scene.needs_gradient_spectrum() {
            2
        } else {
            1
        };
        let inner = py.detach(|| -> PyResult<Renderer> {
            let plan = Plan::choose(&volume, &settings).map_err(pipeline)?;
            preparation_budget(&volume, &plan, spectra)
                .check(fvr_engine::memory::limit(), PREPARE_HINT)
                .map_err(|e| over_budget(&e))?;
            Renderer::prepare(&volume, settings, plan, &|_| {}).map_err(pipeline)
        })?;
        let held = fvr_engine::memory::hold(inner.spectra().bytes() as u64);
        let spacing = volume.spacing;
        Ok(Self {
            inner,
            _held: held,
            source,
            spacing,
            load_ms,
        })
    }

    /// Render views on all cores with the GIL released.
    ///
    /// `views`: directions (B, 3) from the eye into the volume, in (x, y, z)
    /// with x the array's last axis (the CLI's --dir); one direction (3,)
    /// for one (H, W) image; or rotations (B, 3, 3) whose columns are the
    /// camera's right, up and backward axes (the view direction is
    /// -R[:, 2]). `up`: the up hint for directions, (3,) or (B, 3), default
    /// (0, 0, 1). `size`: (height, width) or one side, default
    /// `default_size`. `out`: a C-contiguous float32 array of the result's
    /// shape to write into.
    ///
    /// Returns float32 (B, H, W), or (B, H, W, 3) for coloured scenes, each
    /// image bit for bit `fvr render`'s NRRD of the same view.
    #[pyo3(signature = (views, up=None, size=None, out=None))]
    fn project<'py>(
        &self,
        py: Python<'py>,
        views: &Bound<'py, PyAny>,
        up: Option<&Bound<'py, PyAny>>,
        size: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let parsed = crate::views::parse(views, up)?;
        let size = parse_size(size)?;
        let shape = self
            .inner
            .batch_shape(parsed.views.len(), size)
            .map_err(pipeline)?;
        let mut dims = vec![shape.views, shape.height, shape.width];
        if shape.channels > 1 {
            dims.push(shape.channels);
        }
        let out = match out.filter(|o| !o.is_none()) {
            Some(o) => checked_out(o, &dims)?,
            None => {
                // The images and each thread's slice grid (as `fvr render`
                // counts a view's buffers: 40 bytes a cell).
                let n = self.inner.n() as u64;
                let threads = std::thread::available_parallelism().map_or(1, |t| t.get());
                Budget::new()
                    .hold("images", shape.len() as u64, 4)
                    .hold("view buffers", (threads as u64) * n * n, 40)
                    .check(fvr_engine::memory::limit(), BATCH_HINT)
                    .map_err(|e| over_budget(&e))?;
                PyArrayDyn::<f32>::zeros(py, IxDyn(&dims), false)
            }
        };
        {
            let mut writable = out
                .try_readwrite()
                .map_err(|_| value("out must be writeable and not in use"))?;
            let slice = writable.as_slice_mut()?;
            let (inner, views) = (&self.inner, &parsed.views);
            py.detach(|| inner.render_batch_into(views, size, slice))
                .map_err(pipeline)?;
        }
        if parsed.single {
            return out.get_item(0);
        }
        Ok(out.into_any())
    }

    /// The choices, predicted dB, bytes and times, as `fvr render
    /// --stats-json` reports them, plus `warnings`.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::report::report(py, &self.inner, &self.source, self.spacing, self.load_ms)
    }

    /// A read-only copy of the stored density spectrum, (n, n, n) in its
    /// storage dtype (float16, float32 or float64), kx fastest in natural
    /// Hartley order, and the scale images are divided by.
    fn spectrum<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        crate::report::spectrum(py, &self.inner)
    }

    /// The default image shape `(height, width)`.
    #[getter]
    fn default_size(&self) -> (usize, usize) {
        let side = self.inner.default_side();
        (side, side)
    }

    fn __repr__(&self) -> String {
        let plan = self.inner.plan();
        let [x, y, z] = self.inner.dims();
        format!(
            "fvr.Renderer({} of {z}x{y}x{x} (z, y, x): --filter {} --oversample {} --precision {}, {}^3 spectrum)",
            self.source,
            plan.filter.name(),
            plan.grid.name(),
            plan.precision,
            self.inner.n()
        )
    }
}

/// `size`: None (the default image), one side, or `(height, width)`; the
/// engine's `(width, height)`.
fn parse_size(size: Option<&Bound<'_, PyAny>>) -> PyResult<Option<(usize, usize)>> {
    let Some(s) = size.filter(|s| !s.is_none()) else {
        return Ok(None);
    };
    let positive = |v: i64, what: &str| -> PyResult<usize> {
        usize::try_from(v)
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| value(format!("size: {what} must be a positive integer, got {v}")))
    };
    if let Ok(side) = s.extract::<i64>() {
        let side = positive(side, "the side")?;
        return Ok(Some((side, side)));
    }
    let (h, w): (i64, i64) = s
        .extract()
        .map_err(|_| type_error("size must be None, an integer or (height, width)"))?;
    Ok(Some((
        positive(w, "the width")?,
        positive(h, "the height")?,
    )))
}

/// A caller's `out`: a writeable C-contiguous float32 array of `dims`.
fn checked_out<'py>(
    out: &Bound<'py, PyAny>,
    dims: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let arr = out
        .cast::<PyArrayDyn<f32>>()
        .map_err(|_| type_error("out must be a numpy float32 array"))?;
    if arr.shape() != dims {
        return Err(value(format!(
            "out has shape {}, but these views need {}",
            shape_text(arr.shape()),
            shape_text(dims)
        )));
    }
    if !arr.is_c_contiguous() {
        return Err(value("out must be C-contiguous"));
    }
    Ok(arr.clone())
}
