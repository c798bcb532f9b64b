//! `System`'s inspection of bodies: beam shapes and matrices, stiffness, axial and internal
//! forces, sensors, energies, body info and capabilities (a third `#[pymethods]` block).

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::super::sensors::{read_history, read_states};
use super::super::{arg_err, array, finite_out, json_to_py, mat, read_into, to_py, Real, Vector};
use super::PySystem;
use crate::dynamics;
use crate::error::Error;
use crate::sensors;

#[pymethods]
impl PySystem {
    /// Shape of a beam at xi in [0, 1] (`Body::shape`). FFRF beam: (S (2, n_f), N_psi (n_f,))
    /// with the elastic displacement u_f = S q_f in the beam frame and psi = N_psi q_f. ANCF
    /// beam: (S (2, n_b), S' (2, n_b)) over the body's n_b = 4 (N + 1) coordinates e, with the
    /// world position r = S e and the slope r' = S' e (d/dx) of the axis point.
    #[allow(clippy::type_complexity)]
    fn beam_shape<'py>(&self, py: Python<'py>, body: &str, xi: Real) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (s, p) = self.model.bodies[self.body(body)?].shape(xi.0).map_err(to_py)?;
        Ok((array(py, s)?, array(py, p)?))
    }

    /// Constant elastic blocks of a beam (`Body::matrices`): (M_ff, K_ff), each (n_f, n_f). ANCF
    /// beam: the constant mass matrix M and the tangent stiffness at the undeformed initial
    /// guess (the linear stiffness), each (n_b, n_b) over its n_b = 4 (N + 1) coordinates.
    #[allow(clippy::type_complexity)]
    fn beam_matrices<'py>(&self, py: Python<'py>, body: &str) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let b = &self.model.bodies[self.body(body)?];
        b.require_beam().map_err(to_py)?;
        self.check_square("System.beam_matrices (two dense square blocks)", b.n_coords, 2, "raise memory_limit")?;
        let (m, k) = b.matrices(&self.model.q0).map_err(to_py)?;
        Ok((array(py, m)?, array(py, k)?))
    }

    /// Axial force of each element of a beam at q (E a times the element's averaged axial strain,
    /// second-order with nonlinear strain; tension positive), shape (elements,).
    fn axial_forces<'py>(&self, py: Python<'py>, body: &str, q: Vector<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let bi = self.body(body)?;
        let b = &self.model.bodies[bi];
        if !b.capabilities().axial_forces {
            return Err(to_py(b.axial_forces(&b.new_data()).unwrap_err()));
        }
        let v = self.with_ws(|model, ws| {
            Self::load(ws, &q, None)?;
            dynamics::mass_and_forces(model, &mut ws.data, 0.0, &ws.q, &ws.qd);
            let v = model.bodies[bi].axial_forces(&ws.data.bodies[bi])?;
            finite_out("axial_forces", &v)?;
            Ok(v)
        })?;
        Ok(PyArray1::from_vec(py, v))
    }

    /// Tangent stiffness -dQ_el/dq_b of a body's elastic forces at q (n,), shape (n_b, n_b) over
    /// the body's coordinates (`Body::tangent_stiffness`): ANCF beam: the analytic
    /// K_t = d2U/dq_b2 (undamped); FFRF beam: the elastic block, K_ff plus, with nonlinear
    /// strain, the geometric and second-order axial stiffness of its averaged axial strain;
    /// flexible body: K_ff + k3 q_f + k4 q_f q_f / 2.
    fn tangent_stiffness<'py>(&self, py: Python<'py>, body: &str, q: Vector<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let b = &self.model.bodies[self.body(body)?];
        let nb = b.n_coords;
        let mut qv = vec![0.0; self.model.n];
        read_into("q", &q.as_array(), &mut qv).map_err(to_py)?;
        if b.capabilities().elastic {
            self.check_square("System.tangent_stiffness (dense n_b x n_b)", nb, 1, "raise memory_limit")?;
        }
        let k = b.tangent_stiffness(&qv).map_err(to_py)?;
        finite_out("tangent_stiffness", &k).map_err(to_py)?;
        mat(py, k, nb, nb)
    }

    /// World points (k, 2) drawing planar body `body` at `q` (animation): a beam's axis, a
    /// cable's axis, a flexible body's interface points (closed), a rigid body's star from its
    /// centre of mass to the points where joints and forces attach, a point mass's position;
    /// elastic displacements magnified by `deform_scale` in the body's reference frame
    /// (`rust/body/outline.rs`).
    #[pyo3(signature = (body, q, deform_scale=1.0, points_per_element=8))]
    fn outline<'py>(&self, py: Python<'py>, body: &str, q: Vector<'py>, deform_scale: f64, points_per_element: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
        crate::body::outline::check_drawing(deform_scale, points_per_element).map_err(to_py)?;
        let bi = self.body(body)?;
        let mut qv = vec![0.0; self.model.n];
        read_into("q", &q.as_array(), &mut qv).map_err(to_py)?;
        let attach = self.model.attachments(bi);
        let pts = self.model.bodies[bi].outline(&qv, deform_scale, points_per_element, &attach).map_err(to_py)?;
        let flat: Vec<f64> = pts.iter().flatten().copied().collect();
        finite_out("outline", &flat).map_err(to_py)?;
        mat(py, flat, pts.len(), 2)
    }

    /// World points of every joint's and driver's markers at `q` (animation), in the order of
    /// `constraint_names`' items: `{name: [point a or None, point b or None]}` (a point-on-line's
    /// point and line, a coordinate driver's point), elastic displacements magnified by
    /// `deform_scale`.
    #[pyo3(signature = (q, deform_scale=1.0))]
    fn marker_points<'py>(&self, py: Python<'py>, q: Vector<'py>, deform_scale: f64) -> PyResult<Bound<'py, PyDict>> {
        crate::body::outline::check_drawing(deform_scale, 1).map_err(to_py)?;
        if self.model.bodies.iter().any(|b| matches!(b.kind, crate::body::BodyKind::Rigid3(_) | crate::body::BodyKind::Point3(_))) {
            return Err(arg_err("marker_points", "planar scenes only (a spatial scene is drawn by the 3D animation)"));
        }
        let mut qv = vec![0.0; self.model.n];
        read_into("q", &q.as_array(), &mut qv).map_err(to_py)?;
        let d = PyDict::new(py);
        for c in &self.model.constraints {
            let pts: Vec<Option<[f64; 2]>> = c.markers().iter()
                .map(|m| m.map(|m| crate::body::outline::marker_point(&self.model.bodies, m, &qv, deform_scale)))
                .collect();
            d.set_item(&c.name, pts)?;
        }
        Ok(d)
    }

    /// Axis point `xi` of beam `body` at the states `q`: an array (5,) for q of shape (n,), or
    /// (5, nt) for q of shape (n, nt) (time along the last axis, as `SimulationResult.q`), with
    /// rows x, y (world position), u, v (displacement
    /// in the beam frame from the undeformed (xi L, 0)) and psi (section rotation relative to
    /// that frame). The beam frame is an FFRF beam's floating frame (pinned-pinned: the chord
    /// of the ends) and an ANCF beam's chord frame of the ends, so the two compare one to one.
    fn beam_point<'py>(&self, py: Python<'py>, body: &str, xi: Real, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let xi = xi.0;
        let b = &self.model.bodies[self.body(body)?];
        b.beam_point(xi, &self.model.q0).map_err(to_py)?;
        let n = self.model.n;
        let arr = py.import("numpy")?.call_method1("asarray", (q, "float64"))?.cast_into::<numpy::PyArrayDyn<f64>>()
            .map_err(|_| arg_err("q", "must be an array of floats"))?;
        let view = arr.readonly();
        let a = view.as_array();
        let (cols, one) = match a.shape() {
            [m] if *m == n => (1, true),
            [m, nt] if *m == n => (*nt, false),
            other => return Err(arg_err("q", format!("must have shape (n,) or (n, nt) with n = {n}, got {other:?}"))),
        };
        // one state per column: gather the transposed copy (state k contiguous)
        let flat: Vec<f64> = if one { a.iter().copied().collect() } else { a.t().iter().copied().collect() };
        crate::error::check_finite("q", &flat).map_err(to_py)?;
        let mut out = vec![0.0; 5 * cols];
        for k in 0..cols {
            let p = b.beam_point(xi, &flat[k * n..(k + 1) * n]).map_err(to_py)?;
            finite_out("beam_point", &p).map_err(to_py)?;
            for (r, v) in p.iter().enumerate() {
                out[r * cols + k] = *v;
            }
        }
        if one {
            Ok(PyArray1::from_vec(py, out).into_any())
        } else {
            Ok(mat(py, out, 5, cols)?.into_any())
        }
    }

    /// Sensors at the states `(t[k], q[k], qd[k])` (`t` (nt,), `q`, `qd` (nt, n)), computed in
    /// Rust (`rust/sensors/mod.rs`): a dict with `reactions` (nt, n_items, 6: fx, fy, torque in the
    /// world frame on the first marker's body, fx_local, fy_local in the joint frame, power),
    /// `reaction_names`, `reaction_bodies` (body of the first marker, None = ground),
    /// `body_energies` (nt, n_bodies, 3: kinetic, strain, gravity), `body_names`,
    /// `force_potentials` (nt, n_forces), `force_names`, `dissipation_power` (nt,),
    /// `load_power` (nt,: the power of the loads that are functions and of motors),
    /// `clearance` (nt, n_clearance, 5: eccentricity, penetration, normal force, tangential
    /// force, contact force of each revolute joint with clearance), `clearance_names`.
    #[pyo3(signature = (t, q, qd, reactions=true))]
    fn sensors<'py>(&self, py: Python<'py>, t: Vector<'py>, q: &Bound<'py, PyAny>, qd: &Bound<'py, PyAny>, reactions: bool) -> PyResult<Bound<'py, PyDict>> {
        let n = self.model.n;
        let (ts, qs, qds, nt) = read_history(&t, q, qd, n)?;
        let (nc, nb, nf) = (self.model.constraints.len(), self.model.bodies.len(), self.model.forces.len());
        let mut rx = vec![0.0; if reactions { nt * nc * 6 } else { 0 }];
        let mut be = vec![0.0; nt * nb * 3];
        let mut fp = vec![0.0; nt * nf];
        let mut dp = vec![0.0; nt];
        let mut lp = vec![0.0; nt];
        let ncl = self.model.forces.iter().filter(|f| sensors::is_contact(f)).count();
        let nccol = sensors::CLEARANCE_COLUMNS.len();
        let mut cl = vec![0.0; nt * ncl * nccol];
        self.with_ws(|model, ws| {
            let (mut v, mut f, mut g) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            for k in 0..nt {
                let (qk, qdk) = (&qs[k * n..(k + 1) * n], &qds[k * n..(k + 1) * n]);
                if reactions {
                    sensors::reactions_into(model, &mut ws.data, ts[k], qk, qdk, &mut rx[k * nc * 6..(k + 1) * nc * 6])?;
                }
                sensors::energies_into(model, &mut ws.data, ts[k], qk, qdk, &mut be[k * nb * 3..(k + 1) * nb * 3], &mut fp[k * nf..(k + 1) * nf]);
                dp[k] = sensors::dissipation_power(model, &mut ws.data, ts[k], qk, qdk, &mut v, &mut f, &mut g)?;
                lp[k] = sensors::load_power(model, &mut ws.data, ts[k], qk, qdk, qdk, &mut g);
                sensors::clearance_into(model, qk, qdk, &mut cl[k * ncl * nccol..(k + 1) * ncl * nccol]);
            }
            sensors::unwrap_torque_potentials(model, &mut fp, nt);
            finite_out("sensors reactions", &rx)?;
            finite_out("sensors body energies", &be)?;
            finite_out("sensors force potentials", &fp)?;
            finite_out("sensors dissipation power", &dp)?;
            finite_out("sensors load power", &lp)?;
            Ok(())
        })?;
        let d = PyDict::new(py);
        if reactions {
            d.set_item("reactions", PyArray1::from_vec(py, rx).reshape([nt, nc, 6])?)?;
        }
        let names = |it: &mut dyn Iterator<Item = String>| it.collect::<Vec<String>>();
        d.set_item("reaction_names", names(&mut self.model.constraints.iter().map(|c| c.name.clone())))?;
        let bodies: Vec<Option<String>> = self.model.constraints.iter().map(|c| c.first_body().map(|b| self.model.bodies[b].name.clone())).collect();
        d.set_item("reaction_bodies", bodies)?;
        d.set_item("reaction_columns", sensors::REACTION_COLUMNS.to_vec())?;
        d.set_item("body_energies", PyArray1::from_vec(py, be).reshape([nt, nb, 3])?)?;
        d.set_item("energy_columns", sensors::ENERGY_COLUMNS.to_vec())?;
        d.set_item("body_names", self.body_names())?;
        d.set_item("force_potentials", mat(py, fp, nt, nf)?)?;
        d.set_item("force_names", names(&mut self.model.forces.iter().map(|f| f.name.clone())))?;
        d.set_item("dissipation_power", PyArray1::from_vec(py, dp))?;
        d.set_item("load_power", PyArray1::from_vec(py, lp))?;
        d.set_item("clearance", PyArray1::from_vec(py, cl).reshape([nt, ncl, nccol])?)?;
        d.set_item("clearance_names", names(&mut self.model.forces.iter().filter(|f| sensors::is_contact(f)).map(|f| f.name.clone())))?;
        d.set_item("clearance_columns", sensors::CLEARANCE_COLUMNS.to_vec())?;
        Ok(d)
    }

    /// Internal forces and strains of beam `body` at the axis points `xi` (nx,) for the states
    /// `q` (nt, n): shape (nt, nx, 5) with columns N (axial force, tension positive), V (shear
    /// force), M (bending moment), eps (axial strain), kappa (curvature), in the beam frame,
    /// from the body's kinematics and elastic law (`Beam::internal_forces`).
    fn beam_internal_forces<'py>(&self, py: Python<'py>, body: &str, xi: Vector<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let b = &self.model.bodies[self.body(body)?];
        b.require_beam().map_err(to_py)?;
        let xs: Vec<f64> = xi.as_array().iter().copied().collect();
        for &x in &xs {
            crate::body::inspect::check_xi(x).map_err(to_py)?;
        }
        let n = self.model.n;
        let (qs, nt) = read_states(q, n, "q")?;
        let nx = xs.len();
        let mut out = Vec::with_capacity(nt * nx * 5);
        for k in 0..nt {
            for &x in &xs {
                let f = b.internal_forces(x, &qs[k * n..(k + 1) * n]).map_err(to_py)?;
                finite_out("beam_internal_forces", &f).map_err(to_py)?;
                out.extend_from_slice(&f);
            }
        }
        Ok(PyArray1::from_vec(py, out).reshape([nt, nx, 5])?.into_any())
    }

    /// Kinetic energy 1/2 qd^T M(q) qd (from the body blocks).
    fn kinetic_energy(&self, q: Vector<'_>, qd: Vector<'_>) -> PyResult<f64> {
        self.with_ws(|model, ws| {
            Self::load(ws, &q, Some(&qd))?;
            let e = dynamics::kinetic_energy(model, &mut ws.data, &ws.q, &ws.qd);
            finite_out("kinetic_energy(q, qd)", &[e])?;
            Ok(e)
        })
    }

    /// Potential energy: gravity + elastic strain + springs (and -F.r of constant loads).
    fn potential_energy(&self, q: Vector<'_>) -> PyResult<f64> {
        self.with_ws(|model, ws| {
            Self::load(ws, &q, None)?;
            let e = dynamics::potential_energy(model, &ws.q);
            finite_out("potential_energy(q)", &[e])?;
            Ok(e)
        })
    }

    /// Kind of a body, as in the description: "rigid", "beam" (FFRF), "cable" (ANCF),
    /// "point_mass" or "flexible".
    fn body_kind(&self, body: &str) -> PyResult<&'static str> {
        Ok(self.model.bodies[self.body(body)?].kind_name())
    }

    /// (start, stop) of a body's elastic coordinates in q (start == stop for rigid kinds).
    fn elastic_range(&self, body: &str) -> PyResult<(usize, usize)> {
        let r = self.model.bodies[self.body(body)?].elastic_range();
        Ok((r.start, r.end))
    }

    /// Properties of a body as the core derived them (`Body::info`): kind, mass, n_coords, n_f,
    /// and each kind's own entries: for beams and cables formulation ("ffrf", "ancf"), length, elements,
    /// element_length, theory, area, second_moment, density, youngs_modulus, rotary_inertia,
    /// damping; FFRF beams also frame, shear_stiffness (k G), shear_parameter (phi), strain; ANCF
    /// beams axial_quadrature and bending_quadrature (the element's integration rules).
    fn body_info<'py>(&self, py: Python<'py>, body: &str) -> PyResult<Bound<'py, PyAny>> {
        let info = self.model.bodies[self.body(body)?].info();
        json_to_py(py, &serde_json::Value::Object(info))
    }

    /// What a body can be asked (`Body::capabilities`): a dict of booleans (beam, elastic,
    /// elastic_coordinates, axial_forces, named_markers, oriented), so that Python keeps no
    /// lists of kinds.
    fn body_capabilities<'py>(&self, py: Python<'py>, body: &str) -> PyResult<Bound<'py, PyAny>> {
        let caps = serde_json::to_value(self.model.bodies[self.body(body)?].capabilities()).map_err(|e| to_py(Error::Solver(e.to_string())))?;
        json_to_py(py, &caps)
    }

}
