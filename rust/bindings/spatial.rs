//! `ukflex._core.spatial_outputs`: the spatial sensors (`spatial::outputs`) over stored states,
//! for `ukflex.spatial` (no Python per state).

use numpy::PyArray1;
use numpy::PyArrayMethods;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::sensors::read_states;
use super::{arg_err, finite_out, to_py, Vector};
use crate::data::{Data, RankTolerance};
use crate::dynamics;
use crate::model::Model;
use crate::spatial::outputs;

/// Spatial outputs of the description `description_json` at the states `(t, q, qd)` (q, qd:
/// (nt, n)): `bodies` (nt, n_bodies, 25: centre of mass, its velocity, unit quaternion, angular
/// velocity world and body, rotation matrix rows), `body_columns`, `reactions`
/// (nt, n_constraints, 12: force and torque on the first marker's body about its point, world
/// then joint axes; minimum-norm multipliers at the rank tolerance `rcond`/`atol`),
/// `reaction_names`, `momentum` (nt, 6: linear, angular about the origin), `kinetic_energy`,
/// `potential_energy` (nt,), `driver_values` (nt, n_constraints; NaN for non-drivers).
#[pyfunction]
#[pyo3(signature = (description_json, t, q, qd, reactions=true, rcond=None, atol=0.0))]
pub fn spatial_outputs<'py>(py: Python<'py>, description_json: &str, t: Vector<'py>, q: &Bound<'py, PyAny>, qd: &Bound<'py, PyAny>, reactions: bool, rcond: Option<f64>, atol: f64) -> PyResult<Bound<'py, PyDict>> {
    let model = Model::from_json(description_json).map_err(to_py)?;
    let n = model.n;
    let (qs, nt) = read_states(q, n, "q")?;
    let (qds, nt2) = read_states(qd, n, "qd")?;
    let ts: Vec<f64> = t.as_array().iter().copied().collect();
    if nt2 != nt || ts.len() != nt {
        return Err(arg_err("t", format!("t, q and qd must hold the same number of states, got {}, {nt} and {nt2}", ts.len())));
    }
    let mut data = Data::new(&model);
    data.tolerance = RankTolerance { rcond, atol };
    let (nb, nc) = (model.bodies.len(), model.constraints.len());
    let mut bo = vec![0.0; nt * nb * outputs::BODY_WIDTH];
    let mut rx = vec![0.0; if reactions { nt * nc * 12 } else { 0 }];
    let mut mo = vec![0.0; nt * 6];
    let (mut ke, mut pe) = (vec![0.0; nt], vec![0.0; nt]);
    let mut dv = vec![0.0; nt * nc];
    let mut scratch = vec![0.0; model.constraints.iter().map(|c| c.scratch_len()).max().unwrap_or(0)];
    py.detach(|| -> Result<(), crate::error::Error> {
        for k in 0..nt {
            let (qk, qdk) = (&qs[k * n..(k + 1) * n], &qds[k * n..(k + 1) * n]);
            outputs::body_outputs(&model, qk, qdk, &mut bo[k * nb * outputs::BODY_WIDTH..(k + 1) * nb * outputs::BODY_WIDTH]);
            if reactions {
                outputs::reactions(&model, &mut data, ts[k], qk, qdk, &mut rx[k * nc * 12..(k + 1) * nc * 12])?;
            }
            mo[6 * k..6 * k + 6].copy_from_slice(&outputs::momentum(&model, qk, qdk));
            ke[k] = dynamics::kinetic_energy(&model, &mut data, qk, qdk);
            pe[k] = dynamics::potential_energy(&model, qk);
            dv[k * nc..(k + 1) * nc].copy_from_slice(&outputs::driver_values(&model, ts[k], qk, &mut scratch));
        }
        finite_out("spatial body outputs", &bo)?;
        finite_out("spatial reactions", &rx)?;
        Ok(())
    })
    .map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("bodies", PyArray1::from_vec(py, bo).reshape([nt, nb, outputs::BODY_WIDTH])?)?;
    let mut cols: Vec<&str> = outputs::BODY_COLUMNS.to_vec();
    cols.extend(["R20", "R21", "R22"]);
    d.set_item("body_columns", cols)?;
    d.set_item("body_names", model.bodies.iter().map(|b| b.name.clone()).collect::<Vec<_>>())?;
    if reactions {
        d.set_item("reactions", PyArray1::from_vec(py, rx).reshape([nt, nc, 12])?)?;
    }
    d.set_item("reaction_columns", outputs::REACTION_COLUMNS.to_vec())?;
    d.set_item("reaction_names", model.constraints.iter().map(|c| c.name.clone()).collect::<Vec<_>>())?;
    d.set_item("momentum", PyArray1::from_vec(py, mo).reshape([nt, 6])?)?;
    d.set_item("kinetic_energy", PyArray1::from_vec(py, ke))?;
    d.set_item("potential_energy", PyArray1::from_vec(py, pe))?;
    d.set_item("driver_values", PyArray1::from_vec(py, dv).reshape([nt, nc])?)?;
    Ok(d)
}
