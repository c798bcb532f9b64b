//! `System`'s runs: the first-order Jacobian, native integration, projections and the
//! initial-state correction (a second `#[pymethods]` block of `PySystem`).

use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::panic::{catch_unwind, AssertUnwindSafe};

use super::super::{arg_err, check_time, finite_out, mat, read_into, to_py, Real, SolverError, Vector};
use super::{implicit_bytes, passages_list, PySystem, Workspace};
use crate::uk;
use crate::correct::{self, CorrectOptions};
use crate::data::{Data, Stabilization};
use crate::error::Error;
use crate::integrate::singular::{Passage, SingularMonitor};
use crate::integrate::{integrate_uk_observed, LinearSolver, Progress, Method, NewtonMatrices, RunPlan, RunRequest, UkSystem};
use crate::jacobian::{assemble_first_order, Differences};

#[pymethods]
impl PySystem {
    /// Jacobian of rhs: d[qd, qdd]/d[q, qd] at (t, y), shape (2n, 2n) = [[0, I], [Jq, Jv]].
    /// Central finite differences in Rust (step eps^(1/3) max(|y_j|, 1e-2)); the velocity
    /// columns reuse the mass factor and the pseudoinverse of the base point. Runs with the GIL
    /// released. `scheme="forward"` halves the cost.
    #[pyo3(signature = (t, y, scheme="central"))]
    fn jac<'py>(&self, py: Python<'py>, t: Real, y: Vector<'py>, scheme: &str) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let t = t.0;
        let n = self.model.n;
        let scheme = match scheme {
            "central" => Differences::Central,
            "forward" => Differences::Forward,
            "structured" => Differences::Structured,
            other => return Err(arg_err("scheme", format!("unknown scheme '{other}' (use 'central', 'forward' or 'structured')"))),
        };
        let mut yv = vec![0.0; 2 * n];
        read_into("y", &y.as_array(), &mut yv).map_err(to_py)?;
        check_time(t).map_err(to_py)?;
        let out = py.detach(|| {
            self.with_ws(|model, ws| {
                ws.jws.scheme = scheme;
                if ws.jq.len() != n * n {
                    let hint = "the Jacobian of a system this large is dense n x n; use an explicit method (DOPRI5), or raise memory_limit";
                    Error::check_memory("System.jac (dense (2n)^2 Jacobian)", implicit_bytes(model, "jac"), ws.data.memory_limit, hint)?;
                    ws.jq = vec![0.0; n * n];
                    ws.jv = vec![0.0; n * n];
                }
                let Workspace { data, jws, jq, jv, .. } = ws;
                crate::jacobian::uk_jacobian(model, data, jws, t, &yv[..n], &yv[n..], jq, jv)?;
                let mut out = vec![0.0; 4 * n * n];
                assemble_first_order(n, jq, jv, &mut out);
                finite_out("jac(t, y)", &out)?;
                Ok(out)
            })
        })?;
        mat(py, out, 2 * n, 2 * n)
    }

    /// Integrate natively (Rust, GIL released) from (t0, y0) to t_end.
    ///
    /// method: "DOPRI5" (Dormand-Prince 5(4), dense output), "RADAU5" (Radau IIA order 5,
    /// Rust finite-difference Jacobian), "GENALPHA" (generalized-alpha with numerical
    /// dissipation `rho_inf`, structured Newton matrix; fixed `step` or error-controlled) or
    /// "RADAU5M" (Radau IIA order 5 on the constrained second-order equations with GENALPHA's
    /// structured Newton matrix; fixed `step` or error-controlled).
    /// atol: float or (2n,) array. t_eval: output times (dense output) or None for every
    /// accepted step. projection_tol: project onto the constraint manifold after every accepted
    /// step whose residuals exceed it (None: the method's default, 1e-11 for GENALPHA and RADAU5M,
    /// off for the others; 0: off). The run uses its own workspace (copying this System's pseudoinverse
    /// tolerance, stabilization and backend), so several threads can integrate the same System
    /// concurrently.
    ///
    /// Work budgets: max_steps (step attempts), max_nfev (right-hand-side evaluations),
    /// max_wall_time [s], min_step (smallest step size [s]); a run that exceeds one, or whose
    /// state or acceleration turns non-finite, ends with status -1 and the trajectory up to its
    /// last accepted step. dense: record every step's dense output (evaluate with
    /// `ukflex._core.dense_eval`). newton_local_error (GENALPHA): Newton may stop at this
    /// fraction of the local error estimate (None: at the rtol level only).
    ///
    /// Returns a dict: t (nt,), y (2n, nt), status (0 ok, -1 failed), message, failure (None,
    /// or a dict cause, t, stage, index), nfev, njev, nlu, naccept, nreject, jac_evals (UK calls
    /// inside Jacobians), wall_time [s], dense (None, or a dict meta (nseg, 3), data
    /// (nseg, width), part_len).
    ///
    /// progress: None or a callable `progress(t)`, called from the run (which takes the GIL
    /// only then) with the time of an accepted step every `progress_steps` accepted steps or
    /// every `progress_interval` seconds of wall time, whichever comes first; an exception it
    /// raises (or a pending Ctrl-C) ends the run and is raised here.
    #[pyo3(signature = (t0, y0, t_end, method="RADAU5", rtol=1e-6, atol=None, t_eval=None, first_step=None, max_step=None, max_steps=1_000_000, projection_tol=None, rho_inf=None, step=None, jacobian="structured", max_nfev=None, max_wall_time=None, min_step=0.0, dense=false, newton_local_error=None, linear_solver="auto", drift_limit=None, on_drift="stop", monitor_singular=true, progress=None, progress_steps=100, progress_interval=0.5))]
    #[allow(clippy::too_many_arguments)]
    fn integrate<'py>(
        &self,
        py: Python<'py>,
        t0: Real,
        y0: Vector<'py>,
        t_end: Real,
        method: &str,
        rtol: f64,
        atol: Option<Vector<'py>>,
        t_eval: Option<Vector<'py>>,
        first_step: Option<f64>,
        max_step: Option<f64>,
        max_steps: usize,
        projection_tol: Option<f64>,
        rho_inf: Option<f64>,
        step: Option<f64>,
        jacobian: &str,
        max_nfev: Option<usize>,
        max_wall_time: Option<f64>,
        min_step: f64,
        dense: bool,
        newton_local_error: Option<f64>,
        linear_solver: &str,
        drift_limit: Option<f64>,
        on_drift: &str,
        monitor_singular: bool,
        progress: Option<Py<PyAny>>,
        progress_steps: usize,
        progress_interval: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        if let Some(cb) = &progress {
            if !cb.bind(py).is_callable() {
                return Err(arg_err("progress", "must be None or a callable progress(t)"));
            }
        }
        // the checks of the settings (the report itself is set up inside the run)
        Progress::new(progress_steps, progress_interval, &mut |_| Ok(())).map_err(to_py)?;
        let (t0, t_end) = (t0.0, t_end.0);
        let n = self.model.n;
        let request = RunRequest {
            method: method.to_string(),
            rtol,
            atol: atol.map(|a| a.as_array().iter().copied().collect()),
            first_step,
            max_step,
            max_steps,
            max_nfev,
            max_wall_time,
            min_step,
            projection_tol,
            rho_inf,
            step,
            newton_local_error,
            jacobian: jacobian.to_string(),
            linear_solver: linear_solver.to_string(),
            drift_limit,
            on_drift: on_drift.to_string(),
            monitor_singular,
        };
        let RunPlan { method, opts, projection, jacobian } = request.plan(2 * n).map_err(to_py)?;
        let linear_solver = opts.linear_solver;
        let mut y = vec![0.0; 2 * n];
        read_into("y0", &y0.as_array(), &mut y).map_err(to_py)?;
        check_time(t0).map_err(to_py)?;
        check_time(t_end).map_err(to_py)?;
        let t_eval: Option<Vec<f64>> = t_eval.map(|a| a.as_array().iter().copied().collect());
        // a fresh workspace with this System's settings: the run does not hold the lock
        let (tolerance, stabilization, backend, solver, limit) =
            self.with_ws(|_, ws| Ok((ws.data.tolerance, ws.data.stabilization, ws.data.svd_backend, ws.data.uk_solver, ws.data.memory_limit)))?;
        let model = &self.model;
        // the run's own workspace (built before releasing the GIL so that a refusal is an error)
        let data = Data::build(model, solver, limit).map_err(to_py)?;
        // GENALPHA and RADAU5M: the sparse Newton matrices where they pay (or when asked for).
        // The run chooses (`NewtonMatrices::for_system`, one analysis of the pattern); the
        // choice is made here as well only where the dense matrices would not fit, so that they
        // are refused before the run unless the sparse ones take their place
        let early = |name: &str| linear_solver == LinearSolver::Auto && implicit_bytes(model, name) > limit;
        let mut opts = opts;
        if matches!(method, Method::GenAlpha(_) | Method::RadauM(_)) && early(method.name()) {
            opts.linear_solver = NewtonMatrices::resolve(model, &data, linear_solver, matches!(method, Method::RadauM(_)), method.name()).map_err(to_py)?;
        }
        if method == Method::Radau5 {
            // with the structured Jacobian RADAU5 solves its iteration matrices as saddle points
            opts.linear_solver = match jacobian {
                Differences::Structured if early("RADAU5") => NewtonMatrices::resolve(model, &data, linear_solver, true, method.name()).map_err(to_py)?,
                Differences::Structured => linear_solver,
                _ => LinearSolver::Dense,
            };
        }
        let implicit = match method {
            Method::Dopri5 => 0,
            _ if opts.linear_solver == LinearSolver::Sparse => 0,
            Method::Radau5 => implicit_bytes(model, "RADAU5"),
            Method::GenAlpha(_) => implicit_bytes(model, "GENALPHA"),
            Method::RadauM(_) => implicit_bytes(model, "RADAU5M"),
        };
        let hint = "implicit methods factor dense n x n matrices here; use method='DOPRI5' for a system this large, linear_solver='sparse', or raise memory_limit";
        Error::check_memory("the implicit integrator's n x n matrices", implicit, limit, hint).map_err(to_py)?;
        // an exception of the progress callback (or a pending signal), raised after the run
        let mut raised: Option<PyErr> = None;
        crate::bindings::callables::take_pending(); // nothing stale from an earlier call
        let result = py.detach(|| {
            catch_unwind(AssertUnwindSafe(|| {
                let mut data = data;
                data.tolerance = tolerance;
                data.stabilization = stabilization;
                data.svd_backend = backend;
                // the GIL is taken only when a report is due
                let mut report = |t: f64| -> Result<(), Error> {
                    let Some(cb) = &progress else { return Ok(()) };
                    Python::attach(|py| cb.call1(py, (t,)).and_then(|_| py.check_signals())).map_err(|e| {
                        raised = Some(e);
                        Error::Budget { what: "interrupted".into(), message: "the run was stopped by its progress callback".into() }
                    })
                };
                let mut observer = Progress::new(progress_steps, progress_interval, &mut report)?;
                let tic = std::time::Instant::now();
                let watch = if progress.is_some() { Some(&mut observer) } else { None };
                let r = integrate_uk_observed(model, data, method, opts, t0, &y, t_end, t_eval.as_deref(), projection, jacobian, dense, watch);
                r.map(|(sol, full, cheap)| (sol, full + cheap, tic.elapsed().as_secs_f64()))
            }))
        });
        if let Some(e) = raised {
            return Err(e);
        }
        let (sol, jac_evals, wall) = match result {
            Ok(r) => r.map_err(to_py)?,
            Err(_) => return Err(SolverError::new_err("internal error in the ukflex core (a bug: please report it)")),
        };
        // a load's callable failed and its NaN ended the run early: raise what it raised
        if let Some(e) = crate::bindings::callables::take_pending() {
            return Err(e);
        }
        solution_dict(py, sol, jac_evals, wall)
    }

    /// For each column `v` of `shapes` (n, k): `1/2 v^T K_m v` summed over the bodies' material
    /// stiffness (the strain energy of the motion's first-order strains, no stress terms) and the
    /// springs (`Body::material_energy`, `Force::material_energy`), at `q`. Of a mass-normalized
    /// mode of frequency `omega`, `2 E / omega^2` is the share of its stiffness that is elastic
    /// (`ukflex.choice`).
    fn material_energies<'py>(&self, py: Python<'py>, q: Vector<'py>, shapes: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.model.n;
        let mut qv = vec![0.0; n];
        read_into("q", &q.as_array(), &mut qv).map_err(to_py)?;
        let sa = shapes.as_array();
        if sa.shape()[0] != n {
            return Err(arg_err("material_energies", format!("expected shapes of shape ({n}, k), got {:?}", sa.shape())));
        }
        let k = sa.shape()[1];
        let mut v = vec![0.0; n];
        let mut out = Vec::with_capacity(k);
        for j in 0..k {
            for i in 0..n {
                v[i] = sa[[i, j]];
            }
            crate::error::check_finite("shapes", &v).map_err(to_py)?;
            let bodies: f64 = self.model.bodies.iter().map(|b| b.material_energy(&qv, &v)).sum();
            let springs: f64 = self.model.forces.iter().map(|f| f.material_energy(&self.model.bodies, &qv, &v)).sum();
            out.push(bodies + springs);
        }
        finite_out("material_energies", &out).map_err(to_py)?;
        Ok(PyArray1::from_vec(py, out))
    }

    /// The rigid motions of every body at `(q, qd)` (`Body::rigid_motions`): a basis `B`
    /// (n, r) and the centripetal acceleration `cen` (n,) of the rigid motion at that velocity;
    /// `B x + cen` is the acceleration of a motion in which no body deforms.
    fn rigid_motions<'py>(&self, py: Python<'py>, q: Vector<'py>, qd: Vector<'py>) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>)> {
        let n = self.model.n;
        let (mut qv, mut vv) = (vec![0.0; n], vec![0.0; n]);
        read_into("q", &q.as_array(), &mut qv).map_err(to_py)?;
        read_into("qd", &qd.as_array(), &mut vv).map_err(to_py)?;
        let mut entries = Vec::new();
        let mut cen = vec![0.0; n];
        let mut cols = 0;
        for b in &self.model.bodies {
            cols += b.rigid_motions(&qv, &vv, cols, &mut |i, j, x| entries.push((i, j, x)), &mut cen);
        }
        let mut basis = vec![0.0; n * cols];
        for (i, j, x) in entries {
            basis[i * cols + j] = x;
        }
        finite_out("rigid_motions", &basis).map_err(to_py)?;
        finite_out("rigid_motions", &cen).map_err(to_py)?;
        Ok((mat(py, basis, n, cols)?, PyArray1::from_vec(py, cen)))
    }

    /// The singular passages of a trajectory of accepted states (times `t` (k,), states `y`
    /// (2n, k)), as the native runs report them (`integrate(...)["singular"]`): for runs made
    /// elsewhere (the scipy methods, the NumPy references). One factorization per state.
    fn singular_passages<'py>(&self, py: Python<'py>, t: Vector<'py>, y: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyList>> {
        let n = self.model.n;
        let tv: Vec<f64> = t.as_array().to_vec();
        let ya = y.as_array();
        if ya.shape() != [2 * n, tv.len()] {
            return Err(arg_err("singular_passages", format!("expected y of shape ({}, {}), got {:?}", 2 * n, tv.len(), ya.shape())));
        }
        if tv.iter().any(|x| !x.is_finite()) || ya.iter().any(|x| !x.is_finite()) {
            return Err(to_py(Error::NonFinite { what: "singular_passages: t or y".into(), index: 0 }));
        }
        if tv.windows(2).any(|w| !(w[1] > w[0])) {
            return Err(arg_err("singular_passages", "t must be strictly increasing"));
        }
        let (tolerance, solver, limit) = self.with_ws(|_, ws| Ok((ws.data.tolerance, ws.data.uk_solver, ws.data.memory_limit)))?;
        let model = &self.model;
        let mut data = Data::build(model, solver, limit).map_err(to_py)?;
        data.tolerance = tolerance;
        let states: Vec<Vec<f64>> = (0..tv.len()).map(|k| (0..2 * n).map(|i| ya[[i, k]]).collect()).collect();
        let passages = py.detach(|| -> Result<Vec<Passage>, Error> {
            let mut sys = UkSystem::new(model, data);
            let mut mon = SingularMonitor::new(n);
            for (k, yk) in states.iter().enumerate() {
                mon.push(&mut sys, tv[k], yk)?;
            }
            Ok(mon.passages)
        });
        passages_list(py, &passages.map_err(to_py)?)
    }

    /// `V - M^-1 A^T (A M^-1 A^T)^+ A V` at `(t, q)`: the columns of `V` (n, k) projected onto
    /// the tangent space of the constraints in the mass metric (the filter of the explicit
    /// methods' error estimates, docs/integrators.md).
    /// Returns (the projected V, sigma_min / sigma_max of `A M^-1/2` at q).
    fn tangent_project<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, v: PyReadonlyArray2<'py, f64>) -> PyResult<(Bound<'py, PyArray2<f64>>, f64)> {
        let t = t.0;
        let n = self.model.n;
        let va = v.as_array();
        if va.shape().len() != 2 || va.shape()[0] != n {
            return Err(arg_err("tangent_project", format!("expected V of shape ({n}, k), got {:?}", va.shape())));
        }
        let k = va.shape()[1];
        let mut cols: Vec<Vec<f64>> = (0..k).map(|j| (0..n).map(|i| va[[i, j]]).collect()).collect();
        if cols.iter().flatten().any(|x| !x.is_finite()) {
            return Err(to_py(Error::NonFinite { what: "tangent_project: V".into(), index: 0 }));
        }
        let ratio = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, None)?;
            if model.m == 0 {
                return Ok(1.0);
            }
            let q = ws.q.clone();
            uk::evaluate(model, &mut ws.data, t, &q, &ws.qd.clone(), false)?;
            uk::factor_constraints(model, &mut ws.data)?;
            let info = ws.data.rank_info;
            let ratio = if info.sigma_max > 0.0 { info.sigma_min_kept / info.sigma_max } else { 1.0 };
            let mut r = vec![0.0; model.m];
            for c in cols.iter_mut() {
                for (i, ri) in r.iter_mut().enumerate() {
                    *ri = ws.data.ajac.row_dot(i, c);
                }
                uk::min_norm_correction(model, &mut ws.data, &r);
                for (x, d) in c.iter_mut().zip(&ws.data.qdd) {
                    *x -= d;
                }
            }
            Ok(ratio)
        })?;
        let mut out = vec![0.0; n * k];
        for (j, c) in cols.iter().enumerate() {
            for i in 0..n {
                out[i * k + j] = c[i];
            }
        }
        finite_out("tangent_project", &out).map_err(to_py)?;
        finite_out("tangent_project ratio", &[ratio]).map_err(to_py)?;
        Ok((mat(py, out, n, k)?, ratio))
    }

    /// The projection the native methods make after every accepted step
    /// (`correct::ProjectionTolerance`): Newton on the positions until the correction's largest
    /// entry is at most `position_tol` (at most `max_iter` steps), then the velocities.
    /// Returns (q, qd, ||Phi|| at the new q, whether Newton converged).
    #[pyo3(signature = (t, q, qd, position_tol, max_iter=3))]
    #[allow(clippy::type_complexity)]
    fn project_step<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, qd: Vector<'py>, position_tol: f64, max_iter: usize) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, f64, bool)> {
        let t = t.0;
        if !(position_tol >= 0.0) || !position_tol.is_finite() {
            return Err(arg_err("position_tol", format!("must be >= 0 and finite, got {position_tol}")));
        }
        let (qn, qdn, phi0, phi1) = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            let (mut qn, mut qdn) = (ws.q.clone(), ws.qd.clone());
            let mut pws = correct::ProjectWorkspace::new(model);
            let tol = correct::ProjectionTolerance { position_tol, velocity_tol: position_tol, max_iter };
            let out = correct::project_in_place(model, &mut ws.data, &mut pws, t, &mut qn, &mut qdn, tol)?;
            finite_out("project_step", &qn)?;
            finite_out("project_step", &qdn)?;
            finite_out("project_step ||Phi||", &[out.phi_norm])?;
            Ok((qn, qdn, out.phi_norm, out.converged))
        })?;
        Ok((PyArray1::from_vec(py, qn), PyArray1::from_vec(py, qdn), phi0, phi1))
    }

    /// Constraint stabilization inside qdd/rhs: kind "none" or "baumgarte" with alpha, beta
    /// (b <- gamma - 2 alpha (A qd + Phi_t) - beta^2 Phi).
    #[pyo3(signature = (kind="none", alpha=0.0, beta=0.0))]
    fn set_stabilization(&self, kind: &str, alpha: f64, beta: f64) -> PyResult<()> {
        let st = match kind {
            "none" => Stabilization::None,
            "baumgarte" => {
                if !alpha.is_finite() || !beta.is_finite() || alpha < 0.0 || beta < 0.0 {
                    return Err(arg_err("alpha", format!("Baumgarte alpha and beta must be >= 0 and finite, got {alpha}, {beta}")));
                }
                Stabilization::Baumgarte { alpha, beta }
            }
            other => return Err(arg_err("kind", format!("unknown stabilization '{other}' (use 'none' or 'baumgarte')"))),
        };
        self.with_ws(|_, ws| {
            ws.data.stabilization = st;
            Ok(())
        })
    }

    /// Project (q, qd) onto Phi = 0 and A qd + Phi_t = 0 in the mass metric. Returns
    /// (q, qd, report dict: iterations, position_residual, velocity_residual,
    /// position_correction, velocity_correction).
    #[pyo3(signature = (t, q, qd, tol=1e-12, max_iter=20))]
    #[allow(clippy::type_complexity)]
    fn project<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, qd: Vector<'py>, tol: f64, max_iter: usize) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyDict>)> {
        let t = t.0;
        if !tol.is_finite() || tol <= 0.0 {
            return Err(arg_err("tol", format!("must be positive and finite, got {tol}")));
        }
        let (qn, qdn, rep) = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            let (mut qn, mut qdn) = (ws.q.clone(), ws.qd.clone());
            let rep = correct::project(model, &mut ws.data, t, &mut qn, &mut qdn, tol, max_iter)?;
            finite_out("project q", &qn)?;
            finite_out("project qd", &qdn)?;
            finite_out("project residuals", &[rep.position_residual, rep.velocity_residual, rep.position_correction, rep.velocity_correction])?;
            Ok((qn, qdn, rep))
        })?;
        let d = PyDict::new(py);
        d.set_item("iterations", rep.iterations)?;
        d.set_item("position_residual", rep.position_residual)?;
        d.set_item("velocity_residual", rep.velocity_residual)?;
        d.set_item("position_correction", rep.position_correction)?;
        d.set_item("velocity_correction", rep.velocity_correction)?;
        Ok((PyArray1::from_vec(py, qn), PyArray1::from_vec(py, qdn), d))
    }

    /// Correct (q, qd) onto Phi(q, t) = 0 and A qd + Phi_t = 0 in the mass metric, holding the
    /// coordinates where `hold` is true (and with `rigid`, every body's deformation: an ANCF
    /// cable moves rigidly): damped Newton on the positions, then one velocity projection (the
    /// initial-state correction). Returns a dict: q, qd, iterations,
    /// position_residual_before/after, velocity_residual_before/after (NaN when the positions
    /// failed), phi (m,), velocity (m,), positions_ok, velocities_ok.
    #[pyo3(signature = (t, q, qd, hold, position_tol=1e-12, velocity_tol=1e-10, max_iterations=50, max_wall_time=None, rigid=false))]
    #[allow(clippy::too_many_arguments)]
    fn correct<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, qd: Vector<'py>, hold: Vec<bool>, position_tol: f64, velocity_tol: f64, max_iterations: usize, max_wall_time: Option<f64>, rigid: bool) -> PyResult<Bound<'py, PyDict>> {
        let t = t.0;
        let max_wall_time = max_wall_time.unwrap_or(f64::INFINITY);
        if !(max_wall_time > 0.0) {
            return Err(arg_err("max_wall_time", format!("must be positive, got {max_wall_time}")));
        }
        for (what, v) in [("position_tol", position_tol), ("velocity_tol", velocity_tol)] {
            if !(v > 0.0) || !v.is_finite() {
                return Err(arg_err(what, format!("must be positive and finite, got {v}")));
            }
        }
        let opts = CorrectOptions { hold, rigid, position_tol, velocity_tol, max_iterations };
        let c = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            let (qv, qdv) = (ws.q.clone(), ws.qd.clone());
            correct::correct_within(model, &mut ws.data, t, &qv, &qdv, &opts, max_wall_time)
        })?;
        let d = PyDict::new(py);
        d.set_item("q", PyArray1::from_vec(py, c.q))?;
        d.set_item("qd", PyArray1::from_vec(py, c.qd))?;
        d.set_item("iterations", c.iterations)?;
        d.set_item("position_residual_before", c.position_residual_before)?;
        d.set_item("position_residual_after", c.position_residual_after)?;
        d.set_item("velocity_residual_before", c.velocity_residual_before)?;
        d.set_item("velocity_residual_after", c.velocity_residual_after)?;
        d.set_item("phi", PyArray1::from_vec(py, c.phi))?;
        d.set_item("velocity", PyArray1::from_vec(py, c.velocity))?;
        d.set_item("positions_ok", c.positions_ok)?;
        d.set_item("velocities_ok", c.velocities_ok)?;
        Ok(d)
    }
}

/// A native run's `Solution` as the dict `System.integrate` returns (see its docs).
fn solution_dict<'py>(py: Python<'py>, sol: crate::integrate::Solution, jac_evals: usize, wall: f64) -> PyResult<Bound<'py, PyDict>> {
    let nt = sol.t.len();
    let dim = sol.dim;
    let mut yt = vec![0.0; dim * nt];
    for k in 0..nt {
        for i in 0..dim {
            yt[i * nt + k] = sol.y[k * dim + i];
        }
    }
    let d = PyDict::new(py);
    d.set_item("t", PyArray1::from_vec(py, sol.t))?;
    d.set_item("y", mat(py, yt, dim, nt)?)?;
    d.set_item("status", sol.status)?;
    d.set_item("message", sol.message)?;
    match &sol.failure {
        None => d.set_item("failure", py.None())?,
        Some(f) => {
            let fd = PyDict::new(py);
            fd.set_item("cause", &f.cause)?;
            fd.set_item("t", f.t)?;
            fd.set_item("stage", &f.stage)?;
            fd.set_item("index", f.index)?;
            d.set_item("failure", fd)?;
        }
    }
    match sol.dense {
        None => d.set_item("dense", py.None())?,
        Some(rec) => {
            let (nseg, w) = (rec.meta.len() / 3, rec.width());
            let dd = PyDict::new(py);
            dd.set_item("part_len", rec.part_len.clone())?;
            dd.set_item("meta", mat(py, rec.meta, nseg, 3)?)?;
            dd.set_item("data", mat(py, rec.data, nseg, w)?)?;
            d.set_item("dense", dd)?;
        }
    }
    d.set_item("nfev", sol.stats.nfev)?;
    d.set_item("njev", sol.stats.njev)?;
    d.set_item("nlu", sol.stats.nlu)?;
    d.set_item("naccept", sol.stats.naccept)?;
    d.set_item("nreject", sol.stats.nreject)?;
    d.set_item("newton_iterations", sol.stats.newton)?;
    d.set_item("jac_evals", jac_evals)?;
    d.set_item("wall_time", wall)?;
    d.set_item("singular", passages_list(py, &sol.singular)?)?;
    match sol.drift {
        None => d.set_item("drift", py.None())?,
        Some(r) => {
            let dd = PyDict::new(py);
            dd.set_item("t_first", r.t_first)?;
            dd.set_item("max_residual", r.max_residual)?;
            dd.set_item("t_max", r.t_max)?;
            d.set_item("drift", dd)?;
        }
    }
    Ok(d)
}
