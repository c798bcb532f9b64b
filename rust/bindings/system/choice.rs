//! `System.auto_choice`: `method="auto"`'s analysis and decision in one call
//! (`rust/integrate/choice/`; a fourth `#[pymethods]` block of `PySystem`).

use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::super::{arg_err, read_into, to_py, Real, Vector};
use super::PySystem;
use crate::error::Error;
use crate::integrate::choice::{self, AutoChoice, Spectrum};

/// The decision as a dict: verdict, method (None when more modes are needed), omega_elastic,
/// omega_max, step, newton_rtol, rtol (the integrator's, `choice::integrator_rtol`), phase, floor, floor_modes, overdamped (None or a dict omega,
/// zeta, fast, h_explicit).
fn choice_dict<'py>(py: Python<'py>, c: &AutoChoice, rtol: f64) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("verdict", c.verdict.name())?;
    d.set_item("method", if c.method.is_empty() { None } else { Some(c.method) })?;
    d.set_item("omega_elastic", c.omega_elastic)?;
    d.set_item("omega_max", c.omega_max)?;
    d.set_item("step", c.step)?;
    d.set_item("newton_rtol", c.newton_rtol)?;
    d.set_item("rtol", choice::integrator_rtol(c, rtol))?;
    d.set_item("phase", c.phase)?;
    d.set_item("floor", c.floor)?;
    let modes: Vec<(f64, f64, f64)> = c.floor_modes.iter().map(|m| (m[0], m[1], m[2])).collect();
    d.set_item("floor_modes", modes)?;
    match c.overdamped {
        Some(o) => {
            let od = PyDict::new(py);
            od.set_item("omega", o.omega)?;
            od.set_item("zeta", o.zeta)?;
            od.set_item("fast", o.fast)?;
            od.set_item("h_explicit", o.h_explicit)?;
            d.set_item("overdamped", od)?;
        }
        None => d.set_item("overdamped", py.None())?,
    }
    Ok(d)
}

#[pymethods]
impl PySystem {
    /// `method="auto"`'s decision for a run from `(t0, q, qd)` to `t_end` at `rtol`
    /// (`rust/integrate/choice/`), GIL released. Without `n_dof` (a small system): the whole
    /// analysis here (the constraint rank, the dense modal analysis, the elastic shares, the
    /// floor, the overdamped modes). A large system gives its `n_dof` and, once the sparse
    /// analysis has them, its lowest modes `omega` (k,), `shapes` (n, k) and `omega_max`; with
    /// `n_dof` alone the answer needs no spectrum (no degree of freedom, no elastic potential)
    /// or has `method` None (ask with a spectrum), and with a spectrum `verdict`
    /// "need_more_modes" asks for more modes. Returns a dict (verdict, method, omega_elastic,
    /// omega_max, step, newton_rtol, rtol (the integrator's, `choice::integrator_rtol`), phase, floor, floor_modes, overdamped).
    /// `floor=False` leaves out the floor of a fixed-step RADAU5M choice (floor None, no
    /// modes): it decides nothing, and `simulate` computes it when `res.extra["auto"]` is read.
    #[pyo3(signature = (t0, q, qd, t_end, rtol, n_dof=None, omega=None, shapes=None, omega_max=None, floor=true))]
    #[allow(clippy::too_many_arguments)]
    fn auto_choice<'py>(&self, py: Python<'py>, t0: Real, q: Vector<'py>, qd: Vector<'py>, t_end: Real, rtol: f64, n_dof: Option<usize>, omega: Option<Vector<'py>>, shapes: Option<PyReadonlyArray2<'py, f64>>, omega_max: Option<f64>, floor: bool) -> PyResult<Bound<'py, PyDict>> {
        let (t0, span) = (t0.0, t_end.0 - t0.0);
        if !(span.is_finite() && span > 0.0) {
            return Err(arg_err("t_end", format!("t_end must be finite and greater than t0 = {t0}, got {}", t_end.0)));
        }
        crate::integrate::check_tolerances(rtol, &[0.0], 1).map_err(to_py)?;
        let n = self.model.n;
        let (mut qv, mut vv) = (vec![0.0; n], vec![0.0; n]);
        read_into("q", &q.as_array(), &mut qv).map_err(to_py)?;
        read_into("qd", &qd.as_array(), &mut vv).map_err(to_py)?;
        let given = match (omega, shapes, omega_max) {
            (Some(w), Some(s), Some(wmax)) => {
                let w: Vec<f64> = w.as_array().to_vec();
                let sa = s.as_array();
                if sa.shape() != [n, w.len()] {
                    return Err(arg_err("shapes", format!("expected shape ({n}, {}), got {:?}", w.len(), sa.shape())));
                }
                let mut flat = vec![0.0; n * w.len()];
                for k in 0..w.len() {
                    for i in 0..n {
                        flat[k * n + i] = sa[[i, k]];
                    }
                }
                crate::error::check_finite("omega", &w).map_err(to_py)?;
                crate::error::check_finite("shapes", &flat).map_err(to_py)?;
                Some((w, flat, wmax))
            }
            (None, None, None) => None,
            _ => return Err(arg_err("auto_choice", "give omega, shapes and omega_max together, or none of them")),
        };
        let traits = self.traits;
        let out = py.detach(|| {
            self.with_ws(|model, ws| {
                let data = &mut ws.data;
                match (n_dof, given) {
                    (None, None) => choice::choose_dense(model, data, traits, t0, &qv, &vv, span, rtol, floor),
                    (Some(k), None) => Ok(choice::prelude(traits, k).unwrap_or_else(|| AutoChoice::needs_spectrum())),
                    (Some(k), Some((omega, shapes, omega_max))) => {
                        let sp = Spectrum { omega, shapes, n, omega_max, n_dof: k };
                        choice::choose(model, data, traits, t0, &qv, &vv, span, rtol, &sp, floor)
                    }
                    (None, Some(_)) => Err(Error::argument("auto_choice", "a spectrum needs its n_dof")),
                }
            })
        })?;
        choice_dict(py, &out, rtol)
    }
}
