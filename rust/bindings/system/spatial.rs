//! `System.spatial_outputs`: the spatial sensors (`sensors::spatial`, `sensors`) over stored
//! states, on the System's own model and workspace (no rebuild, no Python per state), for
//! `ukflex.spatial_outputs` and the sensors of a spatial result (`ukflex.results.spatial`).

use numpy::PyArray1;
use numpy::PyArrayMethods;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::super::sensors::read_history;
use super::super::{arg_err, finite_out, mat, Vector};
use super::PySystem;
use crate::dynamics;
use crate::error::Error;
use crate::force::ForceKind;
use crate::sensors;
use crate::sensors::spatial as outputs;

#[pymethods]
impl PySystem {
    /// Start the turn counts of the spatial rotational spring-dampers and motors afresh
    /// (`Data::turns`: the next evaluation reads each angle within half a turn of its rest
    /// angle): a run through `rhs` (scipy's methods) calls it at its start, as a native run
    /// starts from a fresh workspace.
    fn restart_turns(&self) -> PyResult<()> {
        self.with_ws(|_, ws| {
            ws.data.turns.fill(f64::NAN);
            Ok::<(), Error>(())
        })
    }

    /// Spatial outputs at the states `(t, q, qd)` (`t` (nt,), q, qd (nt, n)) of a `"dim": 3`
    /// model: `bodies` (nt, n_bodies, 25: centre of mass, its velocity, unit quaternion, angular
    /// velocity world and body, rotation matrix rows), `body_columns`, `body_names`;
    /// `reactions` (nt, n_constraints, 13: force and torque on the first marker's body about its
    /// point, world then joint axes, from the minimum-norm multipliers at the System's rank
    /// tolerance, and the power `-lambda^T A qd`), `reaction_columns`, `reaction_names`,
    /// `reaction_bodies`; `momentum` (nt, 6: linear, angular about the origin);
    /// `kinetic_energy`, `potential_energy` (nt,); `body_energies` (nt, n_bodies, 3: kinetic,
    /// strain (flexible3 bodies; 0 for rigid kinds), gravity); `force_names`, `force_kinds`, `force_potentials`, `force_powers` (nt, n_forces);
    /// `dissipation_power` (nt,); `driver_values` (nt, n_constraints; NaN for non-drivers).
    #[pyo3(signature = (t, q, qd, reactions=true))]
    fn spatial_outputs<'py>(&self, py: Python<'py>, t: Vector<'py>, q: &Bound<'py, PyAny>, qd: &Bound<'py, PyAny>, reactions: bool) -> PyResult<Bound<'py, PyDict>> {
        if !self.model.is_spatial() {
            return Err(arg_err("System.spatial_outputs", "a planar model has no spatial outputs (use System.sensors); build a scene with \"dim\": 3"));
        }
        let n = self.model.n;
        let (ts, qs, qds, nt) = read_history(&t, q, qd, n)?;
        let (nb, nc, nf) = (self.model.bodies.len(), self.model.constraints.len(), self.model.forces.len());
        let (bw, rw) = (outputs::BODY_WIDTH, outputs::REACTION_WIDTH);
        let mut bo = vec![0.0; nt * nb * bw];
        let mut rx = vec![0.0; if reactions { nt * nc * rw } else { 0 }];
        let mut mo = vec![0.0; nt * 6];
        let (mut ke, mut pe, mut dp) = (vec![0.0; nt], vec![0.0; nt], vec![0.0; nt]);
        let mut be = vec![0.0; nt * nb * 3];
        let (mut fp, mut fw) = (vec![0.0; nt * nf], vec![0.0; nt * nf]);
        let mut dv = vec![0.0; nt * nc];
        let mut gravity = vec![0.0; nb];
        // the beam elements' section forces [N, Q_y, Q_z, M_t, M_y, M_z] (body/beam3.rs)
        let beams: Vec<usize> = (0..nf).filter(|&i| matches!(&self.model.forces[i].kind, ForceKind::Spatial(sf) if sf.kind() == "beam3_element")).collect();
        let mut sf6 = vec![0.0; nt * beams.len() * 6];
        let scratch_len = self.model.constraints.iter().map(|c| c.scratch_len()).max().unwrap_or(0);
        self.with_ws(|model, ws| {
            let (mut scratch, mut v, mut f, mut g) = (vec![0.0; scratch_len], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            // the history's own turn count: from its first state (within half a turn of each
            // rotational spring's angle0), then state to state; the workspace's is kept for later calls
            let saved = std::mem::replace(&mut ws.data.turns, vec![f64::NAN; nf]);
            let mut pass = || -> Result<(), Error> {
                for k in 0..nt {
                    let (qk, qdk) = (&qs[k * n..(k + 1) * n], &qds[k * n..(k + 1) * n]);
                    outputs::body_outputs(model, qk, qdk, &mut bo[k * nb * bw..(k + 1) * nb * bw]);
                    if reactions {
                        outputs::reactions(model, &mut ws.data, ts[k], qk, qdk, &mut rx[k * nc * rw..(k + 1) * nc * rw])?;
                    }
                    mo[6 * k..6 * k + 6].copy_from_slice(&outputs::momentum(model, qk, qdk));
                    let bek = &mut be[k * nb * 3..(k + 1) * nb * 3];
                    sensors::energies_into(model, &mut ws.data, ts[k], qk, qdk, bek, &mut fp[k * nf..(k + 1) * nf]);
                    outputs::gravity_energies(model, qk, &mut gravity);
                    for (i, g) in gravity.iter().enumerate() {
                        bek[3 * i + 2] = *g;
                    }
                    outputs::count_turns(model, &ws.data.turns, &mut fp[k * nf..(k + 1) * nf]);
                    outputs::force_powers(model, &ws.data.turns, ts[k], qk, qdk, &mut v, &mut fw[k * nf..(k + 1) * nf]);
                    ke[k] = dynamics::kinetic_energy(model, &mut ws.data, qk, qdk);
                    // the force elements' potentials (gravity is one) and the flexible3 bodies'
                    // strain energies (rigid kinds carry none)
                    pe[k] = fp[k * nf..(k + 1) * nf].iter().sum::<f64>() + (0..nb).map(|i| bek[3 * i + 1]).sum::<f64>();
                    dp[k] = sensors::dissipation_power(model, &mut ws.data, ts[k], qk, qdk, &mut v, &mut f, &mut g)?;
                    dv[k * nc..(k + 1) * nc].copy_from_slice(&outputs::driver_values(model, ts[k], qk, &mut scratch));
                    for (e, &fi) in beams.iter().enumerate() {
                        if let ForceKind::Spatial(sf) = &model.forces[fi].kind {
                            let s = sf.section_forces(&model.bodies, qk).unwrap_or([f64::NAN; 6]);
                            sf6[(k * beams.len() + e) * 6..(k * beams.len() + e + 1) * 6].copy_from_slice(&s);
                        }
                    }
                }
                Ok(())
            };
            let pass = pass();
            ws.data.turns = saved;
            pass?;
            for (what, x) in [("spatial body outputs", &bo), ("spatial reactions", &rx), ("spatial energies", &be), ("spatial force potentials", &fp), ("spatial force powers", &fw), ("spatial dissipation power", &dp), ("beam section forces", &sf6)] {
                finite_out(what, x)?;
            }
            Ok::<(), Error>(())
        })?;
        let d = PyDict::new(py);
        d.set_item("bodies", PyArray1::from_vec(py, bo).reshape([nt, nb, bw])?)?;
        let mut cols: Vec<&str> = outputs::BODY_COLUMNS.to_vec();
        cols.extend(["R20", "R21", "R22"]);
        d.set_item("body_columns", cols)?;
        d.set_item("body_names", self.body_names())?;
        if reactions {
            d.set_item("reactions", PyArray1::from_vec(py, rx).reshape([nt, nc, rw])?)?;
        }
        d.set_item("reaction_columns", outputs::REACTION_COLUMNS.to_vec())?;
        d.set_item("reaction_names", self.model.constraints.iter().map(|c| c.name.clone()).collect::<Vec<_>>())?;
        let first: Vec<Option<String>> = self.model.constraints.iter().map(|c| c.first_body().map(|b| self.model.bodies[b].name.clone())).collect();
        d.set_item("reaction_bodies", first)?;
        d.set_item("momentum", PyArray1::from_vec(py, mo).reshape([nt, 6])?)?;
        d.set_item("kinetic_energy", PyArray1::from_vec(py, ke))?;
        d.set_item("potential_energy", PyArray1::from_vec(py, pe))?;
        d.set_item("body_energies", PyArray1::from_vec(py, be).reshape([nt, nb, 3])?)?;
        d.set_item("force_names", self.model.forces.iter().map(|f| f.name.clone()).collect::<Vec<_>>())?;
        let kinds: Vec<&str> = self
            .model
            .forces
            .iter()
            .map(|f| match &f.kind {
                ForceKind::Spatial(sf) => sf.kind(),
                ForceKind::Motor3(_) => "motor",
                ForceKind::SpatialLoad(_) => "load",
                ForceKind::JointFriction(_) => "joint_friction",
                _ => "planar",
            })
            .collect();
        d.set_item("force_kinds", kinds)?;
        d.set_item("force_potentials", mat(py, fp, nt, nf)?)?;
        d.set_item("force_powers", mat(py, fw, nt, nf)?)?;
        d.set_item("dissipation_power", PyArray1::from_vec(py, dp))?;
        d.set_item("driver_values", PyArray1::from_vec(py, dv).reshape([nt, nc])?)?;
        d.set_item("beam_element_names", beams.iter().map(|&i| self.model.forces[i].name.clone()).collect::<Vec<_>>())?;
        d.set_item("beam_forces", PyArray1::from_vec(py, sf6).reshape([nt, beams.len(), 6])?)?;
        d.set_item("beam_force_columns", vec!["N", "Q_y", "Q_z", "M_t", "M_y", "M_z"])?;
        Ok(d)
    }
}
