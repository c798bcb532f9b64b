//! Helpers of the sensor methods of `System` (`system.rs`): reading a batch of states, and
//! `motion_values`, which evaluates a driver motion description (inspection and tests).

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;

use super::{arg_err, to_py, Vector};
use crate::constraint::Motion;
use crate::description::{self, MotionDesc};
use crate::error::Error;

/// A float64 array of shape `(nt, n)` (or `(n,)`, one state) as a row-major `Vec` and `nt`.
pub(super) fn read_states(obj: &Bound<'_, PyAny>, n: usize, what: &str) -> PyResult<(Vec<f64>, usize)> {
    let py = obj.py();
    let arr = py
        .import("numpy")?
        .call_method1("asarray", (obj, "float64"))
        .map_err(|e| arg_err(what, format!("expected an array of floats: {e}")))?
        .cast_into::<numpy::PyArrayDyn<f64>>()
        .map_err(|_| arg_err(what, format!("expected an array of floats")))?;
    let view = arr.readonly();
    let a = view.as_array();
    let rows = match a.shape() {
        [m] if *m == n => 1,
        [nt, m] if *m == n => *nt,
        other => return Err(arg_err(what, format!("must have shape (n,) or (nt, n) with n = {n}, got {other:?}"))),
    };
    let flat: Vec<f64> = a.iter().copied().collect();
    crate::error::check_finite(what, &flat).map_err(to_py)?;
    Ok((flat, rows))
}

/// A history of states `(t, q, qd)` (`t` (nt,), `q`, `qd` (nt, n) or (n,)) as row-major `Vec`s
/// and `nt`, checked for matching lengths and finite values.
#[allow(clippy::type_complexity)]
pub(super) fn read_history(t: &Vector<'_>, q: &Bound<'_, PyAny>, qd: &Bound<'_, PyAny>, n: usize) -> PyResult<(Vec<f64>, Vec<f64>, Vec<f64>, usize)> {
    let (qs, nt) = read_states(q, n, "q")?;
    let (qds, nt2) = read_states(qd, n, "qd")?;
    let ts: Vec<f64> = t.as_array().iter().copied().collect();
    if nt2 != nt || ts.len() != nt {
        return Err(arg_err("t", format!("t, q and qd must hold the same number of states, got {}, {nt} and {nt2}", ts.len())));
    }
    crate::error::check_finite("t", &ts).map_err(to_py)?;
    Ok((ts, qs, qds, nt))
}

/// `(f, f', f'')` of a driver motion (a description dict as JSON) at the times `t`, shape
/// (3, nt). The same code as a driver's row: parse errors are `ExpressionError`.
#[pyfunction]
pub fn motion_values<'py>(py: Python<'py>, motion_json: &str, t: Vector<'py>) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let v: serde_json::Value = serde_json::from_str(motion_json).map_err(|e| to_py(Error::Description(e.to_string())))?;
    let d: MotionDesc = serde_json::from_value(description::to_external(v)).map_err(|e| to_py(Error::Description(e.to_string())))?;
    let m = Motion::from_desc("motion", &d).map_err(to_py)?;
    let t = t.as_array();
    let nt = t.len();
    let mut out = vec![0.0; 3 * nt];
    let mut scratch = vec![0.0; m.scratch_len()];
    for (k, &tk) in t.iter().enumerate() {
        let (f, d1, d2) = m.eval(tk, &mut scratch);
        out[k] = f;
        out[nt + k] = d1;
        out[2 * nt + k] = d2;
    }
    PyArray1::from_vec(py, out).reshape([3, nt])
}
