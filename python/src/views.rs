//! Views from Python: directions `(B, 3)` (or one `(3,)`) with an up hint,
//! or rotations `(B, 3, 3)`.
//!
//! The rotation convention (docs/python.md): `R` maps camera coordinates
//! to the volume's `(x, y, z)`, and its columns are the camera's axes,
//! `R[:, 0]` = image right (columns grow along it), `R[:, 1]` = image up
//! (rows grow against it) and `R[:, 2]` = towards the eye, so the view
//! direction (from the eye into the scene, the CLI's `--dir`) is
//! `-R[:, 2]`: the camera looks down its own −z axis, as in OpenGL. `R` is
//! rendered exactly as `fvr render --dir -R[:,2] --up R[:,1]`, which the
//! engine turns back into the same frame to within rounding.

use fvr_core::geometry::{View, DEFAULT_UP};
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{type_error, value};

/// Largest deviation of `RᵀR` from the identity a rotation may show: a
/// float32 rotation matrix passes, a scaled or sheared one does not.
const ORTHONORMAL_TOLERANCE: f64 = 1e-5;

/// The views asked for, and whether one view was given as a `(3,)` vector
/// (the result is then one image rather than a batch of one).
pub(crate) struct Views {
    pub(crate) views: Vec<View>,
    pub(crate) single: bool,
}

/// `x` as a C-contiguous float64 array; real numbers only.
fn float64_array<'py>(x: &Bound<'py, PyAny>, what: &str) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let py = x.py();
    let np = py.import("numpy")?;
    let arr = np.call_method1("asarray", (x,)).map_err(|e| {
        type_error(format!(
            "{what} must be an array of numbers: {}",
            e.value(py)
        ))
    })?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    if !"biuf".contains(kind.as_str()) || kind.is_empty() {
        let dtype = arr.getattr("dtype")?.str()?.to_string();
        return Err(type_error(format!(
            "{what} must hold real numbers, got dtype {dtype}"
        )));
    }
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", np.getattr("float64")?)?;
    // C-contiguous and aligned (arrays unpickled from out-of-band buffers,
    // as dask sends them, may be misaligned): a copy only when needed.
    kwargs.set_item("requirements", "CA")?;
    let arr = np.call_method("require", (arr,), Some(&kwargs))?;
    let arr = arr
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|_| type_error(format!("{what} must be a numeric array")))?;
    let shape = arr.shape().to_vec();
    let data = arr.readonly().as_slice()?.to_vec();
    Ok((shape, data))
}

fn triple(v: &[f64]) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

/// Parse `views` (and `up`) as documented on `Renderer.project`.
pub(crate) fn parse(views: &Bound<'_, PyAny>, up: Option<&Bound<'_, PyAny>>) -> PyResult<Views> {
    let (shape, data) = float64_array(views, "views")?;
    match shape.as_slice() {
        [3] => {
            let ups = parse_up(up, 1)?;
            Ok(Views {
                views: vec![View {
                    dir: triple(&data),
                    up: ups[0],
                }],
                single: true,
            })
        }
        [b, 3] => {
            let ups = parse_up(up, *b)?;
            let views = data
                .chunks_exact(3)
                .zip(ups)
                .map(|(d, up)| View { dir: triple(d), up })
                .collect();
            Ok(Views {
                views,
                single: false,
            })
        }
        [_, 3, 3] => {
            if up.is_some_and(|u| !u.is_none()) {
                return Err(value(
                    "up must be None with rotations (B, 3, 3): a rotation's second column is its up",
                ));
            }
            let views = data
                .chunks_exact(9)
                .enumerate()
                .map(|(i, r)| rotation_view(i, r))
                .collect::<PyResult<_>>()?;
            Ok(Views {
                views,
                single: false,
            })
        }
        other => Err(value(format!(
            "views must be directions (B, 3), one direction (3,) or rotations (B, 3, 3), got shape {}",
            shape_text(other)
        ))),
    }
}

/// `(3, 4)` as Python prints a shape.
pub(crate) fn shape_text(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The up hints for `count` views: the CLI's default `(0, 0, 1)`, one
/// `(3,)` for all, or `(count, 3)`.
fn parse_up(up: Option<&Bound<'_, PyAny>>, count: usize) -> PyResult<Vec<[f64; 3]>> {
    let up = match up {
        Some(u) if !u.is_none() => u,
        _ => return Ok(vec![DEFAULT_UP; count]),
    };
    let (shape, data) = float64_array(up, "up")?;
    match shape.as_slice() {
        [3] => Ok(vec![triple(&data); count]),
        [b, 3] if *b == count => Ok(data.chunks_exact(3).map(triple).collect()),
        other => Err(value(format!(
            "up must be one vector (3,) or one per view ({count}, 3), got shape {}",
            shape_text(other)
        ))),
    }
}

/// The view of rotation `r` (row-major 3×3), number `i` in the batch.
fn rotation_view(i: usize, r: &[f64]) -> PyResult<View> {
    let at = |row: usize, col: usize| r[3 * row + col];
    if r.iter().any(|v| !v.is_finite()) {
        return Err(value(format!("rotation {i} holds a non-finite value")));
    }
    // RᵀR against the identity, and the determinant's sign (a reflection
    // would mirror the image).
    let mut worst = 0.0f64;
    for a in 0..3 {
        for b in 0..3 {
            let dot: f64 = (0..3).map(|k| at(k, a) * at(k, b)).sum();
            let want = if a == b { 1.0 } else { 0.0 };
            worst = worst.max((dot - want).abs());
        }
    }
    let det = at(0, 0) * (at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1))
        - at(0, 1) * (at(1, 0) * at(2, 2) - at(1, 2) * at(2, 0))
        + at(0, 2) * (at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0));
    if worst > ORTHONORMAL_TOLERANCE || det <= 0.0 {
        return Err(value(format!(
            "rotation {i} is not a rotation (|R^T R - I| = {worst:.1e}, det = {det:.3}): \
             give orthonormal matrices with det +1"
        )));
    }
    Ok(View {
        dir: [-at(0, 2), -at(1, 2), -at(2, 2)],
        up: [at(0, 1), at(1, 1), at(2, 1)],
    })
}
