//! Python bindings (feature `python`): the only module that knows Python. Maps `Error` to
//! exception classes under `ukflex.UkflexError`, reads strided NumPy inputs, returns fresh
//! arrays, and never lets a panic cross into Python. `system.rs`: the compiled `System`;
//! `scene.rs`: the item-by-item scene checker used by the Python `Scene` builder.

mod callables;
mod scene;
mod sensors;
mod system;

use numpy::ndarray::ArrayView1;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyKeyError, PyOverflowError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;
use pyo3::Borrowed;

use crate::error::Error;
use scene::{beam3_default_elements, beam3_material_point, beam_elastic_dofs, frame_options, item_name, PySceneChecker};
use system::PySystem;

create_exception!(ukflex, UkflexError, PyException, "Base class of every ukflex error.");
create_exception!(ukflex, InvalidSceneError, UkflexError, "Malformed or non-physical scene description.");
create_exception!(ukflex, SingularMassError, UkflexError, "The mass matrix is not positive definite.");
create_exception!(ukflex, NonFiniteError, UkflexError, "An input array holds NaN or infinity.");
create_exception!(ukflex, SolverError, UkflexError, "A solver kernel failed.");
create_exception!(ukflex, ExpressionError, InvalidSceneError, "An expression (a driver's motion, a load) does not parse or names an unknown state quantity; `position` is the 0-based character index.");
create_exception!(ukflex, MemoryLimitError, UkflexError, "An allocation would exceed the System's memory limit (refused before allocating).");
create_exception!(ukflex, BudgetError, SolverError, "A work budget (max_wall_time, ...) ran out before the work was done (e.g. the initial-state correction of a build).");

/// A 1-D float64 input. float64 vectors (what scipy passes) are read in place, strided or
/// not; anything else array-like is converted once with `numpy.asarray(x, dtype=float64)`, and
/// a wrong dimension or a non-numeric input is a `ValueError` naming what was expected.
pub struct Vector<'py>(PyReadonlyArray1<'py, f64>);

impl<'py> std::ops::Deref for Vector<'py> {
    type Target = PyReadonlyArray1<'py, f64>;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl<'a, 'py> FromPyObject<'a, 'py> for Vector<'py> {
    type Error = PyErr;
    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let py = obj.py();
        // fast path: a plain (not subclassed: masked arrays are subclasses) float64 vector
        static NDARRAY: PyOnceLock<Py<PyType>> = PyOnceLock::new();
        let ndarray = NDARRAY.import(py, "numpy", "ndarray")?;
        if obj.get_type().is(ndarray) {
            if let Ok(a) = obj.extract::<PyReadonlyArray1<'py, f64>>() {
                return Ok(Vector(a));
            }
        }
        let np = py.import("numpy")?;
        if obj.is_none() {
            return Err(arg_err("array", "expected a 1-D array of floats, got None"));
        }
        if np.getattr("ma")?.call_method1("isMaskedArray", (obj,))?.is_truthy()? {
            return Err(arg_err("array", "expected a 1-D array of floats, got a masked array (fill or compress it first)"));
        }
        // refuse what float64 conversion would silently change: complex (imaginary part dropped),
        // strings ("1.5" parsed), booleans, objects
        let raw = np.call_method1("asarray", (obj,)).map_err(|e| arg_err("array", format!("expected a 1-D array of floats: {e}")))?;
        let kind: String = raw.getattr("dtype")?.getattr("kind")?.extract()?;
        if !matches!(kind.as_str(), "f" | "i" | "u") {
            let what = match kind.as_str() {
                "c" => "complex values".to_string(),
                "U" | "S" => "strings".to_string(),
                "b" => "booleans".to_string(),
                _ => format!("values of dtype {}", raw.getattr("dtype")?.str()?),
            };
            return Err(arg_err("array", format!("expected a 1-D array of floats, got {what}")));
        }
        let converted = np
            .call_method1("asarray", (raw, "float64"))
            .map_err(|e| arg_err("array", format!("expected a 1-D array of floats: {e}")))?;
        let arr = converted
            .cast_into::<numpy::PyArrayDyn<f64>>()
            .map_err(|_| arg_err("array", "expected a 1-D array of floats"))?;
        if arr.ndim() != 1 {
            return Err(arg_err("array", format!("expected a 1-D array of floats, got an array of shape {:?}", arr.shape())));
        }
        let a = arr.readonly();
        let a1 = a
            .as_array()
            .into_dimensionality::<numpy::ndarray::Ix1>()
            .map_err(|e| arg_err("array", format!("expected a 1-D array of floats: {e}")))?
            .to_owned();
        Ok(Vector(PyArray1::from_owned_array(py, a1).readonly()))
    }
}

/// A real scalar argument (a time, an axis coordinate, a tolerance): what `float()` takes, with a
/// number beyond the double range (a 400-digit integer) a `ValueError` saying so instead of
/// Python's bare `OverflowError` (PyO3 names the argument in the exception note).
pub struct Real(pub f64);

impl<'a, 'py> FromPyObject<'a, 'py> for Real {
    type Error = PyErr;
    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        match obj.extract::<f64>() {
            Ok(v) => Ok(Real(v)),
            Err(e) if e.is_instance_of::<PyOverflowError>(obj.py()) => {
                let text = obj.repr().map(|r| r.to_string()).unwrap_or_default();
                let shown: String = text.chars().take(40).collect();
                Err(arg_err("number", format!("expected a real number within the double-precision range, got {shown}{}", if text.chars().count() > 40 { "..." } else { "" })))
            }
            Err(e) => Err(e),
        }
    }
}

pub(crate) fn to_py(e: Error) -> PyErr {
    // a load's Python callable failed (its NaN stopped the computation): raise what it raised
    if let Some(pending) = callables::take_pending() {
        return pending;
    }
    let msg = e.to_string();
    match e {
        Error::Description(_) | Error::InvalidProperty { .. } | Error::UnknownBody { .. } => InvalidSceneError::new_err(msg),
        Error::Argument { what, message } => invalid_argument(&what, &message).unwrap_or_else(|_| PyValueError::new_err(msg)),
        Error::Shape { ref what, .. } => invalid_argument(what, &msg[what.len() + 2..]).unwrap_or_else(|_| PyValueError::new_err(msg)),
        Error::NonFinite { .. } => NonFiniteError::new_err(msg),
        Error::SingularMass { .. } => SingularMassError::new_err(msg),
        Error::Solver(_) | Error::Drift { .. } => SolverError::new_err(msg),
        Error::Budget { .. } => BudgetError::new_err(msg),
        Error::Expression { text, position, .. } => Python::attach(|py| {
            let err = ExpressionError::new_err(msg);
            let v = err.value(py);
            // best effort: the message already carries both
            let _ = v.setattr("position", position);
            let _ = v.setattr("expression", text);
            err
        }),
        Error::Memory { .. } => MemoryLimitError::new_err(msg),
        Error::UnknownName { what, name, valid } => unknown_name(&what, &name, &valid).unwrap_or_else(|_| PyKeyError::new_err(msg)),
    }
}

/// `ukflex.UnknownNameError` (a `UkflexError` and a `KeyError`, defined in `ukflex.errors`,
/// which writes its message) for an unknown `name` of kind `what`, listing the valid ones.
fn unknown_name(what: &str, name: &str, valid: &[String]) -> PyResult<PyErr> {
    Python::attach(|py| {
        let cls = py.import("ukflex.errors")?.getattr("UnknownNameError")?;
        let exc = cls.call_method1("of", (what, name, valid.to_vec()))?;
        Ok(PyErr::from_value(exc))
    })
}

/// `ukflex.InvalidArgumentError(what, message)` (a `UkflexError`, `ValueError` and `TypeError`,
/// defined in `ukflex.errors`): the Python class of `Error::Argument` and `Error::Shape`.
fn invalid_argument(what: &str, message: &str) -> PyResult<PyErr> {
    Python::attach(|py| {
        let cls = py.import("ukflex.errors")?.getattr("InvalidArgumentError")?;
        Ok(PyErr::from_value(cls.call1((what, message))?))
    })
}

/// An argument error raised from the bindings themselves (conversions of Python objects).
pub(crate) fn arg_err(what: &str, message: impl Into<String>) -> PyErr {
    to_py(Error::argument(what, message))
}

/// Copy a (possibly strided) NumPy vector into `dst`, checking length and finiteness.
pub(crate) fn read_into(what: &str, src: &ArrayView1<f64>, dst: &mut [f64]) -> Result<(), Error> {
    if src.len() != dst.len() {
        return Err(Error::Shape { what: what.to_string(), expected: dst.len(), got: src.len() });
    }
    // contiguous fast path (the common case): plain copy, one finiteness pass
    if let Some(sl) = src.as_slice() {
        dst.copy_from_slice(sl);
        if dst.iter().all(|x| x.is_finite()) {
            return Ok(());
        }
    }
    for (i, (d, s)) in dst.iter_mut().zip(src.iter()).enumerate() {
        if !s.is_finite() {
            return Err(Error::NonFinite { what: what.to_string(), index: i });
        }
        *d = *s;
    }
    Ok(())
}

/// A per-call result must be finite: inputs beyond what double precision can evaluate (positions
/// of 1e160, velocities whose squares overflow) end here as a `NonFiniteError` naming the stage,
/// never as NaN handed back to the caller.
pub(crate) fn finite_out(stage: &str, v: &[f64]) -> Result<(), Error> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(Error::NonFinite { what: format!("{stage} result (inputs out of double-precision range, or a degenerate state?)"), index }),
        None => Ok(()),
    }
}

pub(crate) fn check_time(t: f64) -> Result<(), Error> {
    if t.is_finite() { Ok(()) } else { Err(Error::NonFinite { what: "t".into(), index: 0 }) }
}

/// A core `Array` as a NumPy array (1-D or 2-D).
pub(crate) fn array<'py>(py: Python<'py>, a: crate::body::Array) -> PyResult<Bound<'py, PyAny>> {
    finite_out("result", a.values()).map_err(to_py)?;
    match a {
        crate::body::Array::Vector(v) => Ok(PyArray1::from_vec(py, v).into_any()),
        crate::body::Array::Matrix { rows, cols, data } => Ok(mat(py, data, rows, cols)?.into_any()),
    }
}

/// A JSON value of the core (an inspection answer) as Python objects (dicts, lists, floats).
pub(crate) fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (v.to_string(),))
}

pub(crate) fn mat<'py>(py: Python<'py>, v: Vec<f64>, rows: usize, cols: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    PyArray1::from_vec(py, v).reshape([rows, cols])
}

/// Evaluate the dense output recorded by `System.integrate(..., dense=True)` of a run of
/// `method` at the times `t` (k,): returns (dim, k). Each time uses the step whose interval
/// holds it (outside the run: the first or last step's polynomial, extrapolated). The record is
/// checked against the method's layout first (`DenseView::check`: a `ValueError` naming what
/// is inconsistent); a value that does not fit a double (extrapolated far out) is a
/// `NonFiniteError`.
#[pyfunction]
fn dense_eval<'py>(py: Python<'py>, method: &str, meta: numpy::PyReadonlyArray2<'py, f64>, data: numpy::PyReadonlyArray2<'py, f64>, part_len: &Bound<'py, PyAny>, t: Vector<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    use crate::integrate::{DenseView, Method};
    // whole numbers >= 0 (a negative or huge one is a ValueError naming it, not an OverflowError)
    let bad = || arg_err("dense_eval", "part_len must be a list of whole numbers >= 0 (the lengths of the record's parts)");
    let mut lens = Vec::new();
    for x in part_len.try_iter().map_err(|_| bad())? {
        lens.push(x.map_err(|_| bad())?.extract::<u64>().map_err(|_| bad())?.try_into().map_err(|_| bad())?);
    }
    let part_len: Vec<usize> = lens;
    let method = Method::from_name(method).ok_or_else(|| arg_err("method", format!("unknown native method '{method}' (use 'DOPRI5', 'RADAU5', 'GENALPHA' or 'RADAU5M')")))?;
    let (meta, data) = (meta.as_array(), data.as_array());
    if meta.ncols() != 3 || meta.nrows() != data.nrows() {
        return Err(arg_err("record", format!(
            "dense_eval: inconsistent dense record: meta must be (nseg, 3) and data (nseg, width), got {:?} and {:?}", meta.shape(), data.shape())));
    }
    // row-major views of the arrays (copied only when they are not C-contiguous)
    let meta_v: std::borrow::Cow<[f64]> = match meta.as_slice() { Some(s) => s.into(), None => meta.iter().copied().collect::<Vec<_>>().into() };
    let data_v: std::borrow::Cow<[f64]> = match data.as_slice() { Some(s) => s.into(), None => data.iter().copied().collect::<Vec<_>>().into() };
    let rec = DenseView { meta: &meta_v, data: &data_v, part_len: &part_len };
    let dim = rec.check(&method).map_err(to_py)?;
    let ts: Vec<f64> = t.as_array().iter().copied().collect();
    crate::error::check_finite("t", &ts).map_err(to_py)?;
    let k = ts.len();
    let mut out = vec![0.0; dim.checked_mul(k).ok_or_else(|| arg_err("dense_eval", "too many values"))?];
    let mut buf = vec![0.0; dim];
    for (j, tj) in ts.iter().enumerate() {
        rec.eval(&method, *tj, &mut buf);
        finite_out("dense_eval", &buf).map_err(to_py)?;
        for i in 0..dim {
            out[i * k + j] = buf[i];
        }
    }
    mat(py, out, dim, k)
}

/// The weight of the part of an error estimate across the constraints at conditioning `kappa`
/// against the run's best `kappa_ref` (`integrate::normal_weight`, docs/integrators.md).
#[pyfunction]
fn normal_weight(kappa: f64, kappa_ref: f64) -> f64 {
    crate::integrate::normal_weight(kappa.max(0.0), kappa_ref)
}

/// The native methods' run options as the core defines them (`rust/integrate/options.rs`): a
/// dict with `native_methods`, `common` (options every method takes), `options` ({method: the
/// options it takes}), and `defaults` (`rtol`, `atol_per_rtol`, `rtol_min`,
/// `projection_per_atol`). The CLI, scene files and `simulate` read these; none restates them.
#[pyfunction]
fn run_options(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    use crate::integrate::{options_of, ATOL_PER_RTOL, COMMON_OPTIONS, DEFAULT_RTOL, NATIVE_METHODS, PROJECTION_PER_ATOL, RTOL_MIN};
    let options: serde_json::Map<String, serde_json::Value> = NATIVE_METHODS.iter().map(|m| (m.to_string(), serde_json::json!(options_of(m)))).collect();
    let v = serde_json::json!({
        "native_methods": NATIVE_METHODS,
        "common": COMMON_OPTIONS,
        "options": options,
        "defaults": {"rtol": DEFAULT_RTOL, "atol_per_rtol": ATOL_PER_RTOL, "rtol_min": RTOL_MIN, "projection_per_atol": PROJECTION_PER_ATOL},
    });
    json_to_py(py, &v)
}

/// The tolerance rule of every run (`integrate::check_tolerances`): `rtol > 0` and finite,
/// `atol >= 0` and finite (one value or `dim`); returns atol as a (dim,) array.
#[pyfunction]
fn check_tolerances<'py>(py: Python<'py>, rtol: Real, atol: Vector<'py>, dim: usize) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let a: Vec<f64> = atol.as_array().iter().copied().collect();
    let v = crate::integrate::check_tolerances(rtol.0, &a, dim).map_err(to_py)?;
    Ok(PyArray1::from_vec(py, v))
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<PySystem>()?;
    m.add_class::<PySceneChecker>()?;
    m.add_function(wrap_pyfunction!(item_name, m)?)?;
    m.add_function(wrap_pyfunction!(beam_elastic_dofs, m)?)?;
    m.add_function(wrap_pyfunction!(beam3_default_elements, m)?)?;
    m.add_function(wrap_pyfunction!(beam3_material_point, m)?)?;
    m.add_function(wrap_pyfunction!(frame_options, m)?)?;
    m.add_function(wrap_pyfunction!(sensors::motion_values, m)?)?;
    m.add_function(wrap_pyfunction!(dense_eval, m)?)?;
    m.add_function(wrap_pyfunction!(run_options, m)?)?;
    m.add_function(wrap_pyfunction!(check_tolerances, m)?)?;
    m.add("UkflexError", py.get_type::<UkflexError>())?;
    m.add("InvalidSceneError", py.get_type::<InvalidSceneError>())?;
    m.add("SingularMassError", py.get_type::<SingularMassError>())?;
    m.add("NonFiniteError", py.get_type::<NonFiniteError>())?;
    m.add("SolverError", py.get_type::<SolverError>())?;
    m.add("ExpressionError", py.get_type::<ExpressionError>())?;
    m.add("MemoryLimitError", py.get_type::<MemoryLimitError>())?;
    m.add("PROJECTION_PER_ATOL", crate::integrate::PROJECTION_PER_ATOL)?;
    m.add("PROJECTION_MOVE_LIMIT", crate::integrate::PROJECTION_MOVE_LIMIT)?;
    m.add("RESOLUTION", crate::model::scale::RESOLUTION)?;
    let auto = pyo3::types::PyDict::new(py);
    for (name, value) in crate::integrate::choice::constants() {
        auto.set_item(name, value)?;
    }
    auto.set_item("FLOOR_POINTS", crate::integrate::choice::FLOOR_POINTS.to_vec())?;
    m.add("AUTO", auto)?;
    m.add_function(wrap_pyfunction!(normal_weight, m)?)?;
    m.add("BudgetError", py.get_type::<BudgetError>())?;
    Ok(())
}

