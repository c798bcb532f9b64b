//! Python callables as load values (`force::value::LoadCallback`): `f(t, state)` with `state`
//! a dict of the callable's inputs. The runs release the interpreter; a call attaches to it
//! for the duration of the callable only. A failure (an exception, a non-finite or non-number
//! result) is recorded here and the call returns NaN; the NaN stops the computation with an
//! error, and `to_py` raises the recorded one in its place (same thread: the runs do not
//! spawn threads).

use std::cell::RefCell;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::NonFiniteError;
use crate::force::value::LoadCallback;

thread_local! {
    static PENDING: RefCell<Option<PyErr>> = const { RefCell::new(None) };
}

/// The error a callable recorded since the last call (taken).
pub(crate) fn take_pending() -> Option<PyErr> {
    PENDING.with(|p| p.borrow_mut().take())
}

fn record(e: PyErr) {
    PENDING.with(|p| {
        let mut p = p.borrow_mut();
        if p.is_none() {
            *p = Some(e);
        }
    });
}

#[derive(Debug)]
pub struct PyCallback {
    name: String,
    f: Py<PyAny>,
    inputs: Vec<String>,
}

impl LoadCallback for PyCallback {
    fn call(&self, t: f64, x: &[f64]) -> f64 {
        Python::attach(|py| {
            let run = || -> PyResult<f64> {
                let state = PyDict::new(py);
                for (k, v) in self.inputs.iter().zip(x) {
                    state.set_item(k, *v)?;
                }
                self.f.bind(py).call1((t, state))?.extract::<f64>()
            };
            match run() {
                Ok(v) if v.is_finite() => v,
                Ok(v) => {
                    record(NonFiniteError::new_err(format!("the load callable '{}' returned {v} at t = {t}", self.name)));
                    f64::NAN
                }
                Err(e) => {
                    record(e);
                    f64::NAN
                }
            }
        })
    }
}

/// The resolver of `Model::attach_callables` over a dict `{name: callable}`.
pub(crate) fn attach(model: &mut crate::model::Model, callables: Option<&Bound<'_, PyDict>>) -> crate::error::Result<()> {
    let mut resolve = |name: &str, inputs: &[String]| -> Option<Arc<dyn LoadCallback>> {
        let f = callables?.get_item(name).ok()??;
        if !f.is_callable() {
            return None;
        }
        Some(Arc::new(PyCallback { name: name.to_string(), f: f.unbind(), inputs: inputs.to_vec() }))
    };
    model.attach_callables(&mut resolve)
}
