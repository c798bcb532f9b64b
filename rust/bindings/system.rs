//! `ukflex._core.System`: a compiled model with its workspace behind a lock.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use super::sensors::read_states;
use super::{check_time, finite_out, mat, read_into, to_py, Real, SolverError, Vector};
use crate::body::{ancf_cable, BodyKind};
use crate::linalg::Banded;
use crate::correct::{self, CorrectOptions};
use crate::data::{Data, RankTolerance, Stabilization, SvdBackend, UkSolver};
use crate::dynamics;
use crate::error::Error;
use crate::integrate::singular::{Passage, SingularMonitor};
use crate::integrate::{integrate_uk, LinearSolver, Method, NewtonMatrices, Options, UkSystem};
use crate::jacobian::{assemble_first_order, Differences, JacobianWorkspace};
use crate::model::Model;
use crate::sensors;
use crate::uk;

/// Workspace behind the lock: the kernel buffers plus contiguous copies of the inputs.
struct Workspace {
    data: Data,
    q: Vec<f64>,
    qd: Vec<f64>,
    /// Finite-difference Jacobian workspace and its two n x n blocks (allocated on the first
    /// `jac` call, not at build: most runs never need them).
    jws: JacobianWorkspace,
    jq: Vec<f64>,
    jv: Vec<f64>,
}

/// Default `memory_limit` of a System: 2 GiB per lazily sized group of buffers.
pub const DEFAULT_MEMORY_LIMIT: u64 = 2 << 30;

/// Bytes of the dense n x n buffers of the implicit paths: `System.jac` (`jq`, `jv`, the
/// (2n)^2 result and the structured blocks) and the native RADAU5 / GENALPHA runs.
fn implicit_bytes(model: &Model, what: &str) -> u64 {
    let (n, m) = (model.n as u64, model.m as u64);
    let saddle = (n + m) * (n + m) + 3 * n * n + m * n;
    8 * match what {
        "jac" => 6 * n * n + saddle,
        "RADAU5" => 5 * n * n + saddle,
        "GENALPHA" => 3 * n * n + saddle,
        // the complex iteration matrix (two parts) beside GENALPHA's buffers
        "RADAU5M" => 3 * n * n + 3 * saddle,
        _ => 0,
    }
}

/// The singular passages of a run as a list of dicts (t, sigma_ratio, sigma_ratio_ref,
/// rank_before, rank_at, rank_after).
fn passages_list<'py>(py: Python<'py>, passages: &[Passage]) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for p in passages {
        let pd = PyDict::new(py);
        pd.set_item("t", p.t)?;
        pd.set_item("sigma_ratio", p.ratio)?;
        pd.set_item("sigma_ratio_ref", p.ratio_ref)?;
        pd.set_item("rank_before", p.rank_before)?;
        pd.set_item("rank_at", p.rank_at)?;
        pd.set_item("rank_after", p.rank_after)?;
        out.append(pd)?;
    }
    Ok(out)
}

/// A compiled scene: the immutable model and its workspace. Safe to share between threads
/// (the workspace is behind a lock; run independent simulations on separate Systems to run
/// them in parallel).
#[pyclass(name = "System", module = "ukflex._core", frozen)]
pub struct PySystem {
    model: Model,
    ws: Mutex<Workspace>,
}

impl PySystem {
    /// Run `f` on the workspace; panics become `SolverError`, never a Python panic.
    fn with_ws<R>(&self, f: impl FnOnce(&Model, &mut Workspace) -> Result<R, Error>) -> PyResult<R> {
        let mut guard = match self.ws.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        let model = &self.model;
        match catch_unwind(AssertUnwindSafe(|| f(model, &mut guard))) {
            Ok(r) => r.map_err(to_py),
            Err(_) => Err(SolverError::new_err("internal error in the ukflex core (a bug: please report it)")),
        }
    }

    fn load(ws: &mut Workspace, q: &Vector<'_>, qd: Option<&Vector<'_>>) -> Result<(), Error> {
        read_into("q", &q.as_array(), &mut ws.q)?;
        match qd {
            Some(qd) => read_into("qd", &qd.as_array(), &mut ws.qd),
            None => {
                ws.qd.fill(0.0);
                Ok(())
            }
        }
    }

    fn body(&self, name: &str) -> PyResult<usize> {
        self.model
            .body_index(name)
            .ok_or_else(|| to_py(Error::UnknownName { what: "body".into(), name: name.to_string(), valid: self.body_names() }))
    }

    fn body_names(&self) -> Vec<String> {
        self.model.bodies.iter().map(|b| b.name.clone()).collect()
    }

    /// Refuse a dense `count` arrays of `k x k` above the memory limit (before allocating).
    fn check_square(&self, what: &str, k: usize, count: u64, hint: &str) -> PyResult<()> {
        let limit = self.with_ws(|_, ws| Ok(ws.data.memory_limit))?;
        Error::check_memory(what, 8 * count * (k as u64) * (k as u64), limit, hint).map_err(to_py)
    }
}

#[pymethods]
impl PySystem {
    /// Build the model from a JSON scene description (see docs/scene-format.md).
    ///
    /// uk_solver: "auto" (sparse for long chains, ropes, tracks; dense otherwise), "dense"
    /// (the pseudoinverse of B^T) or "sparse" (band Cholesky of A M^-1 A^T with a full-rank
    /// certificate, dense fallback); see docs/scale.md. memory_limit: bytes any lazily sized
    /// group of buffers may take (None: 2 GiB); above it a MemoryLimitError is raised before
    /// allocating.
    #[new]
    #[pyo3(signature = (description_json, uk_solver="auto", memory_limit=None))]
    fn new(description_json: &str, uk_solver: &str, memory_limit: Option<f64>) -> PyResult<Self> {
        let solver = UkSolver::parse(uk_solver).map_err(to_py)?;
        let memory_limit = match memory_limit {
            None => DEFAULT_MEMORY_LIMIT,
            Some(b) if b > 0.0 && !b.is_nan() => if b.is_finite() { b as u64 } else { u64::MAX },
            Some(b) => return Err(PyValueError::new_err(format!("memory_limit must be a positive number of bytes, got {b}"))),
        };
        let model = catch_unwind(|| Model::from_json(description_json))
            .map_err(|_| SolverError::new_err("internal error while building the model"))?
            .map_err(to_py)?;
        let data = Data::build(&model, solver, memory_limit).map_err(to_py)?;
        let n = model.n;
        let ws = Workspace { data, q: vec![0.0; n], qd: vec![0.0; n], jws: JacobianWorkspace::new(&model), jq: Vec::new(), jv: Vec::new() };
        Ok(PySystem { model, ws: Mutex::new(ws) })
    }

    /// The UK path asked for at build ("auto", "dense", "sparse") and the one the last
    /// acceleration took ("dense", "sparse" or "none").
    #[getter]
    fn uk_solver(&self) -> PyResult<(String, String)> {
        self.with_ws(|_, ws| {
            let asked = match ws.data.uk_solver {
                UkSolver::Auto => "auto",
                UkSolver::Dense => "dense",
                UkSolver::Sparse => "sparse",
            };
            Ok((asked.to_string(), ws.data.uk_path().to_string()))
        })
    }

    /// Memory limit in bytes (see the constructor).
    #[getter]
    fn memory_limit(&self) -> PyResult<u64> {
        self.with_ws(|_, ws| Ok(ws.data.memory_limit))
    }

    /// Number of coordinates n.
    #[getter]
    fn n_coords(&self) -> usize {
        self.model.n
    }

    /// Number of constraint rows m.
    #[getter]
    fn n_constraints(&self) -> usize {
        self.model.m
    }

    #[getter(body_names)]
    fn py_body_names(&self) -> Vec<String> {
        self.body_names()
    }

    /// name -> (start, stop) of the body's coordinates in q.
    #[getter]
    fn body_slices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for b in &self.model.bodies {
            d.set_item(&b.name, (b.offset, b.offset + b.n_coords))?;
        }
        Ok(d)
    }

    #[getter]
    fn coordinate_names(&self) -> Vec<String> {
        self.model.coordinate_names.clone()
    }

    /// One name per constraint row.
    #[getter]
    fn constraint_names(&self) -> Vec<String> {
        self.model.constraint_row_names.clone()
    }

    /// Names of the joints and drivers (one per item, joints first), as sensors report them.
    #[getter]
    fn constraint_items(&self) -> Vec<String> {
        self.model.constraints.iter().map(|c| c.name.clone()).collect()
    }

    /// Names of the drivers.
    #[getter]
    fn driver_names(&self) -> Vec<String> {
        self.model.constraints.iter().filter(|c| c.is_driver()).map(|c| c.name.clone()).collect()
    }

    /// (q0, qd0) as given by the description (not corrected).
    fn initial_guess<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        (PyArray1::from_slice(py, &self.model.q0), PyArray1::from_slice(py, &self.model.qd0))
    }

    /// Mass matrix M(q), shape (n, n).
    #[allow(non_snake_case)]
    fn M<'py>(&self, py: Python<'py>, q: Vector<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.model.n;
        self.check_square("System.M (dense n x n)", n, 1, "M is n x n dense; use System.M_sparse (scipy.sparse), or raise memory_limit")?;
        let m = self.with_ws(|model, ws| {
            Self::load(ws, &q, None)?;
            dynamics::mass_and_forces(model, &mut ws.data, &ws.q, &ws.qd);
            let m = dynamics::dense_mass(model, &ws.data);
            finite_out("M(q)", &m)?;
            Ok(m)
        })?;
        mat(py, m, n, n)
    }

    /// The mass matrix M(q) in coordinate form: (rows, cols, values), the entries of the body
    /// blocks (O(nnz), no n x n allocation; `scipy.sparse.coo_array((v, (r, c)), (n, n))`).
    #[allow(non_snake_case)]
    #[allow(clippy::type_complexity)]
    fn M_sparse<'py>(&self, py: Python<'py>, q: Vector<'py>) -> PyResult<(Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<f64>>)> {
        let (r, c, v) = self.with_ws(|model, ws| {
            Self::load(ws, &q, None)?;
            dynamics::mass_and_forces(model, &mut ws.data, &ws.q, &ws.qd);
            let (mut r, mut c, mut v) = (Vec::new(), Vec::new(), Vec::new());
            for (body, bd) in model.bodies.iter().zip(&ws.data.bodies) {
                let o = body.offset as i64;
                body.dense_block(bd, &mut |i, j, x| {
                    if x != 0.0 {
                        r.push(o + i as i64);
                        c.push(o + j as i64);
                        v.push(x);
                    }
                });
            }
            finite_out("M(q)", &v)?;
            Ok((r, c, v))
        })?;
        Ok((PyArray1::from_vec(py, r), PyArray1::from_vec(py, c), PyArray1::from_vec(py, v)))
    }

    /// The constrained linearization at (t, q, qd) in sparse form, for the modal analysis
    /// (`System.frequencies`): a dict with rows, cols (the coordinate pattern: bodies, forces,
    /// the coordinates of each constraint row), M and K there (K = -d/dq (Q - M qdd -
    /// A^T lambda) at the UK acceleration and multipliers of the state, central differences
    /// coloured by the pattern: O(n)), a_rows, a_cols, A (the structural entries of A), qdd,
    /// lambda, and colors (difference pairs used). On the constraints' tangent space K is the
    /// stiffness of the dense modal analysis, `-N^T M dqdd/dq N`. With `qdd` and `lam` given,
    /// those are held instead of the UK solution's (`System.equilibrium`: zero and the Newton
    /// iterate); `stiffness=False` skips K (then all zero): M and A alone, one evaluation.
    #[pyo3(signature = (t, q, qd, qdd=None, lam=None, stiffness=true))]
    #[allow(clippy::too_many_arguments)]
    fn linearization<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, qd: Vector<'py>, qdd: Option<Vector<'py>>, lam: Option<Vector<'py>>, stiffness: bool) -> PyResult<Bound<'py, PyDict>> {
        let t = t.0;
        use crate::sparse_newton::{fill_a, fill_linearized_stiffness, fill_mass, Pattern, Structure};
        let (n, m) = (self.model.n, self.model.m);
        let mut held = (vec![0.0; n], vec![0.0; m]);
        match (&qdd, &lam) {
            (Some(a), Some(l)) => {
                read_into("qdd", &a.as_array(), &mut held.0).map_err(to_py)?;
                read_into("lam", &l.as_array(), &mut held.1).map_err(to_py)?;
            }
            (None, None) => {}
            _ => return Err(PyValueError::new_err("linearization: give both qdd and lam, or neither (the UK solution at the state)")),
        }
        let given = qdd.is_some();
        let out = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            let p = Pattern::new(model, &ws.data.ajac, true, ws.data.memory_limit)?;
            let (qdd, lambda) = if given {
                crate::uk::evaluate(model, &mut ws.data, t, &ws.q, &ws.qd, false)?;
                held
            } else {
                uk::acceleration(model, &mut ws.data, t, &ws.q, &ws.qd)?;
                (ws.data.qdd.clone(), ws.data.lambda.clone())
            };
            let mut s = Structure::new(p);
            fill_mass(model, &ws.data, &mut s);
            fill_a(&ws.data, &mut s);
            let (mut qv, mut f, mut k) = (vec![0.0; n], vec![0.0; n], vec![0.0; s.pattern.nnz()]);
            if stiffness {
                fill_linearized_stiffness(model, &mut ws.data, t, &ws.q, &ws.qd, &qdd, &lambda, &s.pattern, &mut qv, &mut f, &mut k);
                finite_out("the linearized stiffness", &k)?;
            }
            finite_out("linearization M", &s.m)?;
            finite_out("linearization A", &s.a)?;
            finite_out("linearization qdd", &qdd)?;
            finite_out("linearization lambda", &lambda)?;
            Ok((s, k, qdd, lambda))
        })?;
        let (s, k, qdd, lambda) = out;
        let p = &s.pattern;
        let (rows, cols): (Vec<i64>, Vec<i64>) = p.entries().map(|(i, j)| (i as i64, j as i64)).unzip();
        let (ar, ac): (Vec<i64>, Vec<i64>) = p.a_entries().map(|(r, j)| (r as i64, j as i64)).unzip();
        let d = PyDict::new(py);
        d.set_item("rows", PyArray1::from_vec(py, rows))?;
        d.set_item("cols", PyArray1::from_vec(py, cols))?;
        d.set_item("colors", p.colors())?;
        d.set_item("a_rows", PyArray1::from_vec(py, ar))?;
        d.set_item("a_cols", PyArray1::from_vec(py, ac))?;
        d.set_item("M", PyArray1::from_vec(py, s.m))?;
        d.set_item("K", PyArray1::from_vec(py, k))?;
        d.set_item("A", PyArray1::from_vec(py, s.a))?;
        d.set_item("qdd", PyArray1::from_vec(py, qdd))?;
        d.set_item("lambda", PyArray1::from_vec(py, lambda))?;
        Ok(d)
    }

    /// Generalized forces Q(t, q, qd) = applied + quadratic velocity + elastic, shape (n,).
    #[allow(non_snake_case)]
    fn Q<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, qd: Vector<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = t.0;
        let v = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            dynamics::mass_and_forces(model, &mut ws.data, &ws.q, &ws.qd);
            finite_out("Q(t, q, qd)", &ws.data.force)?;
            Ok(ws.data.force.clone())
        })?;
        Ok(PyArray1::from_vec(py, v))
    }

    /// Constraint Jacobian A = Phi_q(q), shape (m, n).
    #[allow(non_snake_case)]
    fn A<'py>(&self, py: Python<'py>, q: Vector<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (m, n) = (self.model.m, self.model.n);
        let v = self.with_ws(|model, ws| {
            Self::load(ws, &q, None)?;
            dynamics::constraints(model, &mut ws.data, 0.0, &ws.q, &ws.qd, false);
            // a fresh dense copy from the segment form (the workspace keeps no dense A for this)
            Error::check_memory("System.A (dense m x n)", 8 * m as u64 * n as u64, ws.data.memory_limit, "A is m x n dense; raise memory_limit")?;
            let mut a = vec![0.0; m * n];
            ws.data.ajac.scatter(&mut a);
            finite_out("A(q)", &a)?;
            Ok(a)
        })?;
        mat(py, v, m, n)
    }

    /// Constraint values Phi(q, t), shape (m,).
    fn phi<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = t.0;
        let v = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, None)?;
            dynamics::constraints(model, &mut ws.data, t, &ws.q, &ws.qd, true);
            finite_out("phi(t, q)", &ws.data.phi)?;
            Ok(ws.data.phi.clone())
        })?;
        Ok(PyArray1::from_vec(py, v))
    }

    /// Partial time derivative Phi_t(t), shape (m,) (nonzero only for drivers).
    fn phi_t<'py>(&self, py: Python<'py>, t: Real) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = t.0;
        let v = self.with_ws(|model, ws| {
            check_time(t)?;
            ws.q.copy_from_slice(&model.q0);
            ws.qd.fill(0.0);
            dynamics::constraints(model, &mut ws.data, t, &ws.q, &ws.qd, false);
            finite_out("phi_t(t)", &ws.data.phi_t)?;
            Ok(ws.data.phi_t.clone())
        })?;
        Ok(PyArray1::from_vec(py, v))
    }

    /// b = gamma(t, q, qd) (paper eq. 43), shape (m,).
    fn b<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, qd: Vector<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = t.0;
        let v = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            dynamics::constraints(model, &mut ws.data, t, &ws.q, &ws.qd, false);
            finite_out("b(t, q, qd)", &ws.data.gamma)?;
            Ok(ws.data.gamma.clone())
        })?;
        Ok(PyArray1::from_vec(py, v))
    }

    /// UK acceleration qdd(t, q, qd), shape (n,).
    fn qdd<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, qd: Vector<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = t.0;
        let out = PyArray1::<f64>::zeros(py, self.model.n, false);
        self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            uk::acceleration(model, &mut ws.data, t, &ws.q, &ws.qd)?;
            finite_out("qdd(t, q, qd)", &ws.data.qdd)?;
            let mut w = out.readwrite();
            w.as_slice_mut().expect("fresh array is contiguous").copy_from_slice(&ws.data.qdd);
            Ok(())
        })?;
        Ok(out)
    }

    /// Right-hand side for integrators: y = [q, qd] -> [qd, qdd], shape (2n,).
    fn rhs<'py>(&self, py: Python<'py>, t: Real, y: Vector<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = t.0;
        let n = self.model.n;
        let out = PyArray1::<f64>::zeros(py, 2 * n, false);
        self.with_ws(|model, ws| {
            check_time(t)?;
            let ya = y.as_array();
            if ya.len() != 2 * n {
                return Err(Error::Shape { what: "y".into(), expected: 2 * n, got: ya.len() });
            }
            read_into("y[:n]", &ya.slice(numpy::ndarray::s![..n]), &mut ws.q)?;
            read_into("y[n:]", &ya.slice(numpy::ndarray::s![n..]), &mut ws.qd)?;
            uk::acceleration(model, &mut ws.data, t, &ws.q, &ws.qd)?;
            finite_out("rhs(t, y)", &ws.data.qdd)?;
            let mut w = out.readwrite();
            let o = w.as_slice_mut().expect("fresh array is contiguous");
            o[..n].copy_from_slice(&ws.qd);
            o[n..].copy_from_slice(&ws.data.qdd);
            Ok(())
        })?;
        Ok(out)
    }

    /// Benchmark helper: seconds per call of the Rust UK acceleration alone at
    /// (t, q, qd), the minimum over `batches` batches of `reps` calls, GIL released. Lets a
    /// Python benchmark separate the core's time from the binding's overhead in one run.
    #[pyo3(signature = (t, q, qd, reps=1000, batches=21))]
    fn time_acceleration(&self, py: Python<'_>, t: Real, q: Vector<'_>, qd: Vector<'_>, reps: usize, batches: usize) -> PyResult<f64> {
        let t = t.0;
        let n = self.model.n;
        let (mut qv, mut qdv) = (vec![0.0; n], vec![0.0; n]);
        read_into("q", &q.as_array(), &mut qv).map_err(to_py)?;
        read_into("qd", &qd.as_array(), &mut qdv).map_err(to_py)?;
        py.detach(|| {
            self.with_ws(|model, ws| {
                let mut best = f64::INFINITY;
                for _ in 0..batches.max(1) {
                    let tic = std::time::Instant::now();
                    for _ in 0..reps.max(1) {
                        uk::acceleration(model, &mut ws.data, std::hint::black_box(t), std::hint::black_box(&qv), std::hint::black_box(&qdv))?;
                    }
                    best = best.min(tic.elapsed().as_secs_f64() / reps.max(1) as f64);
                }
                Ok(best)
            })
        })
    }

    /// Lagrange multipliers (M qdd + A^T lambda = Q), shape (m,).
    fn multipliers<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, qd: Vector<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = t.0;
        let v = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            uk::acceleration(model, &mut ws.data, t, &ws.q, &ws.qd)?;
            finite_out("multipliers(t, q, qd)", &ws.data.lambda)?;
            Ok(ws.data.lambda.clone())
        })?;
        Ok(PyArray1::from_vec(py, v))
    }

    /// Euclidean norms of the position, velocity and acceleration residuals along a trajectory:
    /// t (nt,), q and qd (n, nt) -> (3, nt), in one call with the GIL released (a result's
    /// residual histories). A non-finite input or norm is a `NonFiniteError` naming the state.
    fn residual_norms<'py>(&self, py: Python<'py>, t: Vector<'py>, q: PyReadonlyArray2<'py, f64>, qd: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (n, m) = (self.model.n, self.model.m);
        let tv: Vec<f64> = t.as_array().to_vec();
        let nt = tv.len();
        let (qa, qda) = (q.as_array().to_owned(), qd.as_array().to_owned());
        if qa.shape() != [n, nt] || qda.shape() != [n, nt] {
            return Err(PyValueError::new_err(format!(
                "residual_norms: expected q and qd of shape ({n}, {nt}), got {:?} and {:?}", qa.shape(), qda.shape())));
        }
        let out = py.detach(|| {
            self.with_ws(|model, ws| {
                let mut out = vec![0.0; 3 * nt];
                let (mut p, mut v, mut a) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
                let (mut qc, mut qdc) = (vec![0.0; n], vec![0.0; n]);
                let norm = |x: &[f64]| x.iter().map(|e| e * e).sum::<f64>().sqrt();
                for k in 0..nt {
                    for i in 0..n {
                        qc[i] = qa[[i, k]];
                        qdc[i] = qda[[i, k]];
                    }
                    if !tv[k].is_finite() || qc.iter().chain(qdc.iter()).any(|x| !x.is_finite()) {
                        return Err(Error::NonFinite { what: "residual_norms: t, q or qd of the state".into(), index: k });
                    }
                    uk::residuals(model, &mut ws.data, tv[k], &qc, &qdc, &mut p, &mut v, &mut a)?;
                    out[k] = norm(&p);
                    out[nt + k] = norm(&v);
                    out[2 * nt + k] = norm(&a);
                    if !(out[k].is_finite() && out[nt + k].is_finite() && out[2 * nt + k].is_finite()) {
                        return Err(Error::NonFinite { what: "residual_norms result (inputs out of double-precision range?) at the state".into(), index: k });
                    }
                }
                Ok(out)
            })
        })?;
        mat(py, out, 3, nt)
    }

    /// (position Phi, velocity A qd + Phi_t, acceleration A qdd - b), each shape (m,).
    #[allow(clippy::type_complexity)]
    fn residuals<'py>(&self, py: Python<'py>, t: Real, q: Vector<'py>, qd: Vector<'py>) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
        let t = t.0;
        let m = self.model.m;
        let (p, v, a) = self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            let (mut p, mut v, mut a) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
            let (q, qd) = (ws.q.clone(), ws.qd.clone());
            uk::residuals(model, &mut ws.data, t, &q, &qd, &mut p, &mut v, &mut a)?;
            finite_out("residuals(t, q, qd)", &p)?;
            finite_out("residuals(t, q, qd)", &v)?;
            finite_out("residuals(t, q, qd)", &a)?;
            Ok((p, v, a))
        })?;
        Ok((PyArray1::from_vec(py, p), PyArray1::from_vec(py, v), PyArray1::from_vec(py, a)))
    }

    /// (rank, smallest kept singular value) of the last UK pseudoinverse.
    fn rank(&self) -> PyResult<(usize, f64)> {
        self.with_ws(|model, ws| {
            let info = uk::exact_rank_info(model, &mut ws.data)?;
            Ok((info.rank, info.sigma_min_kept))
        })
    }

    /// Everything a pseudoinverse decided: uk_path ("sparse" or "dense", the path the solve
    /// took), rank, sigma_max, sigma_min_kept, sigma_max_dropped, tolerance, exact. The
    /// singular values are exact (`exact` True) except after the sparse path with more than
    /// 256 constraint rows: there the rank is the certified m and sigma_max / sigma_min_kept
    /// are the certificate's upper / lower bounds (`exact` False; no dense SVD is run). After a
    /// certified full-rank path of a smaller system the exact values are computed here, on
    /// demand, by the dense path. With a state `(t, q, qd)` the UK solve at that state and its
    /// rank report happen under one lock, so the answer belongs to that state even when other
    /// threads use the System; without one it describes the last solve of any thread.
    /// `exact=False` skips the on-demand singular values: after a certified full-rank solve the
    /// report then holds the certificate's bounds (`exact` says which), at no extra cost.
    #[pyo3(signature = (t=None, q=None, qd=None, exact=true))]
    fn rank_info<'py>(&self, py: Python<'py>, t: Option<Real>, q: Option<Vector<'py>>, qd: Option<Vector<'py>>, exact: bool) -> PyResult<Bound<'py, PyDict>> {
        let t = t.map(|t| t.0);
        let state = match (t, &q, &qd) {
            (Some(t), Some(q), Some(qd)) => Some((t, q, qd)),
            (None, None, None) => None,
            _ => return Err(PyValueError::new_err("rank_info: give all of t, q, qd (a state) or none of them (the last solve)")),
        };
        let (info, path) = self.with_ws(|model, ws| {
            if let Some((t, q, qd)) = state {
                check_time(t)?;
                Self::load(ws, q, Some(qd))?;
                uk::acceleration(model, &mut ws.data, t, &ws.q, &ws.qd)?;
            }
            let path = ws.data.uk_path();
            let info = if exact { uk::exact_rank_info(model, &mut ws.data)? } else { ws.data.rank_info };
            finite_out("rank_info", &[info.sigma_max, info.sigma_min_kept, info.sigma_max_dropped, info.tolerance])?;
            Ok((info, path))
        })?;
        let d = PyDict::new(py);
        d.set_item("uk_path", path)?;
        d.set_item("rank", info.rank)?;
        d.set_item("sigma_max", info.sigma_max)?;
        d.set_item("sigma_min_kept", info.sigma_min_kept)?;
        d.set_item("sigma_max_dropped", info.sigma_max_dropped)?;
        d.set_item("tolerance", info.tolerance)?;
        d.set_item("exact", info.exact)?;
        Ok(d)
    }

    /// Set the pseudoinverse rank tolerance: drop singular values below
    /// max(atol, rcond * sigma_max); rcond=None means max(m, n) * eps.
    #[pyo3(signature = (rcond=None, atol=0.0))]
    fn set_rank_tolerance(&self, rcond: Option<f64>, atol: f64) -> PyResult<()> {
        if let Some(r) = rcond {
            if !r.is_finite() || r < 0.0 {
                return Err(PyValueError::new_err(format!("rcond must be >= 0 and finite, got {r}")));
            }
        }
        if !atol.is_finite() || atol < 0.0 {
            return Err(PyValueError::new_err(format!("atol must be >= 0 and finite, got {atol}")));
        }
        self.with_ws(|_, ws| {
            ws.data.tolerance = RankTolerance { rcond, atol };
            Ok(())
        })
    }

    /// How the UK pseudoinverse is computed: "auto" (default: certified full-rank QR, Jacobi
    /// SVD otherwise), "qr-jacobi" (QR + Jacobi SVD every call) or "faer" (faer's SVD).
    /// Same results to rounding; see docs/performance.md.
    #[pyo3(signature = (kind="auto"))]
    fn set_pseudoinverse(&self, kind: &str) -> PyResult<()> {
        let b = match kind {
            "auto" => SvdBackend::Auto,
            "qr-jacobi" => SvdBackend::QrJacobi,
            "faer" => SvdBackend::Faer,
            other => return Err(PyValueError::new_err(format!("unknown pseudoinverse kind '{other}' (use 'auto', 'qr-jacobi' or 'faer')"))),
        };
        self.with_ws(|_, ws| {
            ws.data.svd_backend = b;
            Ok(())
        })
    }

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
            other => return Err(PyValueError::new_err(format!("unknown scheme '{other}' (use 'central', 'forward' or 'structured')"))),
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
    #[pyo3(signature = (t0, y0, t_end, method="RADAU5", rtol=1e-6, atol=None, t_eval=None, first_step=None, max_step=None, max_steps=1_000_000, projection_tol=None, rho_inf=None, step=None, jacobian="structured", max_nfev=None, max_wall_time=None, min_step=0.0, dense=false, newton_local_error=None, linear_solver="auto", drift_limit=None, on_drift="stop", monitor_singular=true))]
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
    ) -> PyResult<Bound<'py, PyDict>> {
        let (t0, t_end) = (t0.0, t_end.0);
        let linear_solver = LinearSolver::parse(linear_solver).map_err(to_py)?;
        let jacobian = match jacobian {
            "central" => Differences::Central,
            "forward" => Differences::Forward,
            "structured" => Differences::Structured,
            other => return Err(PyValueError::new_err(format!("unknown jacobian '{other}' (use 'structured', 'central' or 'forward')"))),
        };
        let n = self.model.n;
        let mut method = Method::from_name(method)
            .ok_or_else(|| PyValueError::new_err(format!("unknown native method '{method}' (use 'DOPRI5', 'RADAU5', 'GENALPHA' or 'RADAU5M')")))?;
        match &mut method {
            Method::GenAlpha(go) => {
                go.rho_inf = rho_inf.unwrap_or(go.rho_inf);
                go.step = step;
                go.newton_local_error = newton_local_error;
            }
            Method::RadauM(ro) if newton_local_error.is_none() && rho_inf.is_none() => ro.step = step,
            Method::RadauM(_) => return Err(PyValueError::new_err("rho_inf and newton_local_error apply to GENALPHA only (RADAU5M is L-stable: no dissipation setting)")),
            _ if step.is_some() || newton_local_error.is_some() || rho_inf.is_some() => {
                return Err(PyValueError::new_err("step (a fixed step size) applies to GENALPHA and RADAU5M, rho_inf and newton_local_error to GENALPHA only"));
            }
            _ => {}
        }
        let mut y = vec![0.0; 2 * n];
        read_into("y0", &y0.as_array(), &mut y).map_err(to_py)?;
        check_time(t0).map_err(to_py)?;
        check_time(t_end).map_err(to_py)?;
        let atol = match atol {
            None => vec![1e-3 * rtol],
            Some(a) => a.as_array().iter().copied().collect(),
        };
        let t_eval: Option<Vec<f64>> = t_eval.map(|a| a.as_array().iter().copied().collect());
        let max_step = max_step.unwrap_or(f64::INFINITY);
        let stop_on_drift = match on_drift {
            "stop" => true,
            "warn" => false,
            other => return Err(PyValueError::new_err(format!("on_drift must be 'stop' or 'warn', got {other:?}"))),
        };
        let opts = Options {
            rtol,
            atol,
            first_step,
            max_step,
            max_steps,
            max_nfev: max_nfev.unwrap_or(usize::MAX),
            max_wall_time: max_wall_time.unwrap_or(f64::INFINITY),
            min_step,
            linear_solver,
            drift_limit: drift_limit.unwrap_or(f64::INFINITY),
            stop_on_drift,
            monitor_singular,
        };
        let atol_full = opts.validate(2 * n).map_err(to_py)?;
        let projection = match projection_tol {
            None => Some(crate::integrate::default_projection(&atol_full)),
            Some(0.0) => None,
            Some(p) if p > 0.0 && p.is_finite() => Some(crate::correct::ProjectionTolerance { position_tol: p, velocity_tol: p, max_iter: 20 }),
            Some(p) => return Err(PyValueError::new_err(format!("projection_tol must be >= 0 and finite, got {p}"))),
        };
        // a fresh workspace with this System's settings: the run does not hold the lock
        let (tolerance, stabilization, backend, solver, limit) =
            self.with_ws(|_, ws| Ok((ws.data.tolerance, ws.data.stabilization, ws.data.svd_backend, ws.data.uk_solver, ws.data.memory_limit)))?;
        let model = &self.model;
        // the run's own workspace (built before releasing the GIL so that a refusal is an error)
        let data = Data::build(model, solver, limit).map_err(to_py)?;
        // GENALPHA and RADAU5M: the sparse Newton matrices where they pay (or when asked for),
        // decided here so that the dense ones are refused before the run when too large
        let mut opts = opts;
        if let Method::GenAlpha(_) | Method::RadauM(_) = method {
            opts.linear_solver = NewtonMatrices::resolve(model, &data, linear_solver, matches!(method, Method::RadauM(_))).map_err(to_py)?;
        }
        if method == Method::Radau5 {
            // with the structured Jacobian RADAU5 solves its iteration matrices as saddle points
            opts.linear_solver = match jacobian {
                Differences::Structured => NewtonMatrices::resolve(model, &data, linear_solver, true).map_err(to_py)?,
                _ if linear_solver == LinearSolver::Sparse => {
                    return Err(PyValueError::new_err("linear_solver='sparse' with RADAU5 needs jacobian='structured' (a difference Jacobian is dense)"));
                }
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
        let result = py.detach(|| {
            catch_unwind(AssertUnwindSafe(|| {
                let mut data = data;
                data.tolerance = tolerance;
                data.stabilization = stabilization;
                data.svd_backend = backend;
                let tic = std::time::Instant::now();
                let r = integrate_uk(model, data, method, opts, t0, &y, t_end, t_eval.as_deref(), projection, jacobian, dense);
                r.map(|(sol, full, cheap)| (sol, full + cheap, tic.elapsed().as_secs_f64()))
            }))
        });
        let (sol, jac_evals, wall) = match result {
            Ok(r) => r.map_err(to_py)?,
            Err(_) => return Err(SolverError::new_err("internal error in the ukflex core (a bug: please report it)")),
        };
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
            return Err(PyValueError::new_err(format!("material_energies: expected shapes of shape ({n}, k), got {:?}", sa.shape())));
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
            return Err(PyValueError::new_err(format!("singular_passages: expected y of shape ({}, {}), got {:?}", 2 * n, tv.len(), ya.shape())));
        }
        if tv.iter().any(|x| !x.is_finite()) || ya.iter().any(|x| !x.is_finite()) {
            return Err(to_py(Error::NonFinite { what: "singular_passages: t or y".into(), index: 0 }));
        }
        if tv.windows(2).any(|w| !(w[1] > w[0])) {
            return Err(PyValueError::new_err("singular_passages: t must be strictly increasing"));
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
            return Err(PyValueError::new_err(format!("tangent_project: expected V of shape ({n}, k), got {:?}", va.shape())));
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
            return Err(PyValueError::new_err(format!("position_tol must be >= 0 and finite, got {position_tol}")));
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
                    return Err(PyValueError::new_err(format!("Baumgarte alpha and beta must be >= 0 and finite, got {alpha}, {beta}")));
                }
                Stabilization::Baumgarte { alpha, beta }
            }
            other => return Err(PyValueError::new_err(format!("unknown stabilization '{other}' (use 'none' or 'baumgarte')"))),
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
            return Err(PyValueError::new_err(format!("tol must be positive and finite, got {tol}")));
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

    /// Shape of a beam at xi in [0, 1]. FFRF beam: (S (2, n_f), N_psi (n_f,)) with the elastic
    /// displacement u_f = S q_f in the beam frame and psi = N_psi q_f. ANCF beam:
    /// (S (2, n_b), S' (2, n_b)) over the body's n_b = 4 (N + 1) coordinates e, with the world
    /// position r = S e and the slope r' = S' e (d/dx) of the axis point.
    #[allow(clippy::type_complexity)]
    fn beam_shape<'py>(&self, py: Python<'py>, body: &str, xi: Real) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyAny>)> {
        let xi = xi.0;
        let bi = self.body(body)?;
        if !xi.is_finite() || !(0.0..=1.0).contains(&xi) {
            return Err(PyValueError::new_err(format!("xi must be in [0, 1], got {xi}")));
        }
        let beam = match &self.model.bodies[bi].kind {
            BodyKind::Beam(beam) => beam,
            BodyKind::AncfBeam(cable) => {
                let nb = cable.n_coords();
                let p = cable.point(xi);
                let (mut s, mut d) = (vec![0.0; 2 * nb], vec![0.0; 2 * nb]);
                for a in 0..4 {
                    for c in 0..2 {
                        s[c * nb + p.first + 2 * a + c] = p.s[a];
                        d[c * nb + p.first + 2 * a + c] = p.d[a];
                    }
                }
                return Ok((mat(py, s, 2, nb)?, mat(py, d, 2, nb)?.into_any()));
            }
            _ => return Err(PyValueError::new_err(format!("body '{body}' is not a beam"))),
        };
        let nf = beam.n_f;
        let ps = beam.point_shape(xi);
        let (mut s, mut npsi) = (vec![0.0; 2 * nf], vec![0.0; nf]);
        for &(i, su, sv, sp) in &ps.entries {
            s[i] = su;
            s[nf + i] = sv;
            npsi[i] = sp;
        }
        Ok((mat(py, s, 2, nf)?, PyArray1::from_vec(py, npsi).into_any()))
    }

    /// Constant elastic blocks of a beam: (M_ff, K_ff), each (n_f, n_f). ANCF beam: the
    /// constant mass matrix M and the tangent stiffness at the undeformed initial guess (the
    /// linear stiffness), each (n_b, n_b) over its n_b = 4 (N + 1) coordinates.
    #[allow(clippy::type_complexity)]
    fn beam_matrices<'py>(&self, py: Python<'py>, body: &str) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
        let bi = self.body(body)?;
        let b = &self.model.bodies[bi];
        let beam = match &b.kind {
            BodyKind::Beam(beam) => beam,
            BodyKind::AncfBeam(cable) => {
                let nb = b.n_coords;
                self.check_square("System.beam_matrices (two dense n_b x n_b)", nb, 2, "raise memory_limit")?;
                let mut m = vec![0.0; nb * nb];
                cable.dense_block(&Default::default(), &mut |i, j, v| m[i * nb + j] = v);
                let mut k = Banded::zeros(nb, ancf_cable::HB);
                cable.add_tangent_stiffness(&self.model.q0[b.offset..b.offset + nb], &mut k);
                return Ok((mat(py, m, nb, nb)?, mat(py, k.to_dense(), nb, nb)?));
            }
            _ => return Err(PyValueError::new_err(format!("body '{body}' is not a beam"))),
        };
        let nf = beam.n_f;
        self.check_square("System.beam_matrices (two dense n_f x n_f)", nf, 2, "raise memory_limit")?;
        Ok((mat(py, beam.m_ff.to_dense(), nf, nf)?, mat(py, beam.k_ff.to_dense(), nf, nf)?))
    }

    /// Axial force of each element of a beam at q (E a times the element's averaged axial strain,
    /// second-order with nonlinear strain; tension positive), shape (elements,).
    fn axial_forces<'py>(&self, py: Python<'py>, body: &str, q: Vector<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let bi = self.body(body)?;
        if !matches!(self.model.bodies[bi].kind, BodyKind::Beam(_)) {
            return Err(PyValueError::new_err(format!("body '{body}' is not a beam")));
        }
        let v = self.with_ws(|model, ws| {
            Self::load(ws, &q, None)?;
            dynamics::mass_and_forces(model, &mut ws.data, &ws.q, &ws.qd);
            let crate::body::BodyData::Beam(bd) = &ws.data.bodies[bi] else {
                return Err(Error::Solver("axial_forces: the workspace of a beam is not a beam's".into()));
            };
            finite_out("axial_forces", &bd.axial_force)?;
            Ok(bd.axial_force.clone())
        })?;
        Ok(PyArray1::from_vec(py, v))
    }

    /// Tangent stiffness -dQ_el/dq_b of a beam's elastic forces at q (n,), shape (n_b, n_b) over
    /// the body's coordinates: ANCF beam: the analytic K_t = d2U/dq_b2 (undamped); FFRF beam:
    /// the elastic block, K_ff plus, with nonlinear strain, the geometric and second-order axial
    /// stiffness of its averaged axial strain; flexible body: K_ff + k3 q_f + k4 q_f q_f / 2.
    fn tangent_stiffness<'py>(&self, py: Python<'py>, body: &str, q: Vector<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let bi = self.body(body)?;
        let b = &self.model.bodies[bi];
        let nb = b.n_coords;
        let mut qv = vec![0.0; self.model.n];
        read_into("q", &q.as_array(), &mut qv).map_err(to_py)?;
        if matches!(b.kind, BodyKind::AncfBeam(_) | BodyKind::Beam(_) | BodyKind::Flexible(_)) {
            self.check_square("System.tangent_stiffness (dense n_b x n_b)", nb, 1, "raise memory_limit")?;
        }
        let k = match &b.kind {
            BodyKind::AncfBeam(cable) => {
                let mut k = Banded::zeros(nb, ancf_cable::HB);
                cable.add_tangent_stiffness(&qv[b.offset..b.offset + nb], &mut k);
                k.to_dense()
            }
            BodyKind::Beam(beam) => {
                let mut k = vec![0.0; nb * nb];
                beam.elastic_tangent(&qv[b.elastic_range()], &mut |i, j, v| k[(3 + i) * nb + 3 + j] += v);
                k
            }
            BodyKind::Flexible(flex) => {
                let mut k = vec![0.0; nb * nb];
                flex.elastic_tangent(&qv[b.elastic_range()], &mut |i, j, v| k[(3 + i) * nb + 3 + j] += v);
                k
            }
            _ => return Err(PyValueError::new_err(format!("body '{body}' is not a beam or a flexible body"))),
        };
        finite_out("tangent_stiffness", &k).map_err(to_py)?;
        mat(py, k, nb, nb)
    }

    /// Axis point `xi` of beam `body` at the states `q`: an array (5,) for q of shape (n,), or
    /// (5, nt) for q of shape (n, nt) (time along the last axis, as `SimulationResult.q`), with
    /// rows x, y (world position), u, v (displacement
    /// in the beam frame from the undeformed (xi L, 0)) and psi (section rotation relative to
    /// that frame). The beam frame is an FFRF beam's floating frame (pinned-pinned: the chord
    /// of the ends) and an ANCF beam's chord frame of the ends, so the two compare one to one.
    fn beam_point<'py>(&self, py: Python<'py>, body: &str, xi: Real, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let xi = xi.0;
        let bi = self.body(body)?;
        if !xi.is_finite() || !(0.0..=1.0).contains(&xi) {
            return Err(PyValueError::new_err(format!("xi must be in [0, 1], got {xi}")));
        }
        let b = &self.model.bodies[bi];
        if b.beam_point(xi, &self.model.q0).is_none() {
            return Err(PyValueError::new_err(format!("body '{body}' is not a beam")));
        }
        let n = self.model.n;
        let arr = py.import("numpy")?.call_method1("asarray", (q, "float64"))?.cast_into::<numpy::PyArrayDyn<f64>>()
            .map_err(|_| PyValueError::new_err("q must be an array of floats"))?;
        let view = arr.readonly();
        let a = view.as_array();
        let (cols, one) = match a.shape() {
            [m] if *m == n => (1, true),
            [m, nt] if *m == n => (*nt, false),
            other => return Err(PyValueError::new_err(format!("q must have shape (n,) or (n, nt) with n = {n}, got {other:?}"))),
        };
        // one state per column: gather the transposed copy (state k contiguous)
        let flat: Vec<f64> = if one { a.iter().copied().collect() } else { a.t().iter().copied().collect() };
        crate::error::check_finite("q", &flat).map_err(to_py)?;
        let mut out = vec![0.0; 5 * cols];
        for k in 0..cols {
            let Some(p) = b.beam_point(xi, &flat[k * n..(k + 1) * n]) else {
                return Err(PyValueError::new_err(format!("body '{body}' is not a beam")));
            };
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
    /// Rust (`rust/sensors.rs`): a dict with `reactions` (nt, n_items, 6: fx, fy, torque in the
    /// world frame on the first marker's body, fx_local, fy_local in the joint frame, power),
    /// `reaction_names`, `reaction_bodies` (body of the first marker, None = ground),
    /// `body_energies` (nt, n_bodies, 3: kinetic, strain, gravity), `body_names`,
    /// `force_potentials` (nt, n_forces), `force_names`, `dissipation_power` (nt,).
    #[pyo3(signature = (t, q, qd, reactions=true))]
    fn sensors<'py>(&self, py: Python<'py>, t: Vector<'py>, q: &Bound<'py, PyAny>, qd: &Bound<'py, PyAny>, reactions: bool) -> PyResult<Bound<'py, PyDict>> {
        let n = self.model.n;
        let (qs, nt) = read_states(q, n, "q")?;
        let (qds, nt2) = read_states(qd, n, "qd")?;
        let ts: Vec<f64> = t.as_array().iter().copied().collect();
        if nt2 != nt || ts.len() != nt {
            return Err(PyValueError::new_err(format!("t, q and qd must hold the same number of states, got {}, {nt} and {nt2}", ts.len())));
        }
        crate::error::check_finite("t", &ts).map_err(to_py)?;
        let (nc, nb, nf) = (self.model.constraints.len(), self.model.bodies.len(), self.model.forces.len());
        let mut rx = vec![0.0; if reactions { nt * nc * 6 } else { 0 }];
        let mut be = vec![0.0; nt * nb * 3];
        let mut fp = vec![0.0; nt * nf];
        let mut dp = vec![0.0; nt];
        self.with_ws(|model, ws| {
            let (mut v, mut f) = (vec![0.0; n], vec![0.0; n]);
            for k in 0..nt {
                let (qk, qdk) = (&qs[k * n..(k + 1) * n], &qds[k * n..(k + 1) * n]);
                if reactions {
                    sensors::reactions_into(model, &mut ws.data, ts[k], qk, qdk, &mut rx[k * nc * 6..(k + 1) * nc * 6])?;
                }
                sensors::energies_into(model, &mut ws.data, qk, qdk, &mut be[k * nb * 3..(k + 1) * nb * 3], &mut fp[k * nf..(k + 1) * nf]);
                dp[k] = sensors::dissipation_power(model, &mut ws.data, qk, qdk, &mut v, &mut f);
            }
            sensors::unwrap_torque_potentials(model, &mut fp, nt);
            finite_out("sensors reactions", &rx)?;
            finite_out("sensors body energies", &be)?;
            finite_out("sensors force potentials", &fp)?;
            finite_out("sensors dissipation power", &dp)?;
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
        Ok(d)
    }

    /// Internal forces and strains of beam `body` at the axis points `xi` (nx,) for the states
    /// `q` (nt, n): shape (nt, nx, 5) with columns N (axial force, tension positive), V (shear
    /// force), M (bending moment), eps (axial strain), kappa (curvature), in the beam frame,
    /// from the body's kinematics and elastic law (`Beam::internal_forces`).
    fn beam_internal_forces<'py>(&self, py: Python<'py>, body: &str, xi: Vector<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let bi = self.body(body)?;
        let b = &self.model.bodies[bi];
        if b.internal_forces(0.0, &self.model.q0).is_none() {
            return Err(PyValueError::new_err(format!("body '{body}' is not a beam")));
        }
        let xs: Vec<f64> = xi.as_array().iter().copied().collect();
        if let Some(x) = xs.iter().find(|x| !x.is_finite() || !(0.0..=1.0).contains(*x)) {
            return Err(PyValueError::new_err(format!("xi must be in [0, 1], got {x}")));
        }
        let n = self.model.n;
        let (qs, nt) = read_states(q, n, "q")?;
        let nx = xs.len();
        let mut out = Vec::with_capacity(nt * nx * 5);
        for k in 0..nt {
            for &x in &xs {
                let Some(f) = b.internal_forces(x, &qs[k * n..(k + 1) * n]) else {
                    return Err(PyValueError::new_err(format!("body '{body}' is not a beam")));
                };
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

    /// Kind of a body: "rigid", "beam" (FFRF), "ancf_beam" or "point_mass".
    fn body_kind(&self, body: &str) -> PyResult<&'static str> {
        Ok(self.model.bodies[self.body(body)?].kind_name())
    }

    /// (start, stop) of a body's elastic coordinates in q (start == stop for rigid kinds).
    fn elastic_range(&self, body: &str) -> PyResult<(usize, usize)> {
        let r = self.model.bodies[self.body(body)?].elastic_range();
        Ok((r.start, r.end))
    }

    /// Properties of a body as the core derived them: kind, mass, n_coords, n_f, and for
    /// beams formulation ("ffrf", "ancf"), length, elements, element_length, theory, area,
    /// second_moment, density, youngs_modulus, rotary_inertia, damping; FFRF beams also frame,
    /// shear_stiffness (k G), shear_parameter (phi); ANCF beams axial_quadrature and
    /// bending_quadrature (the element's integration rules).
    fn body_info<'py>(&self, py: Python<'py>, body: &str) -> PyResult<Bound<'py, PyDict>> {
        let b = &self.model.bodies[self.body(body)?];
        let d = PyDict::new(py);
        d.set_item("kind", b.kind_name())?;
        d.set_item("mass", b.total_mass())?;
        d.set_item("n_coords", b.n_coords)?;
        d.set_item("n_f", b.n_f())?;
        match &b.kind {
            BodyKind::Rigid(r) => {
                d.set_item("inertia", r.inertia)?;
                d.set_item("com", r.com.to_vec())?;
            }
            BodyKind::Beam(beam) => {
                let sec = &beam.section;
                d.set_item("formulation", "ffrf")?;
                d.set_item("length", beam.length)?;
                d.set_item("elements", beam.elements)?;
                d.set_item("element_length", beam.element_length)?;
                d.set_item("theory", match sec.theory {
                    crate::description::BeamTheory::Timoshenko => "timoshenko",
                    crate::description::BeamTheory::EulerBernoulli => "euler-bernoulli",
                })?;
                d.set_item("frame", match beam.reference {
                    crate::description::ReferenceConditions::PinnedPinned => "pinned-pinned",
                    crate::description::ReferenceConditions::Clamped => "clamped",
                })?;
                d.set_item("area", sec.area)?;
                d.set_item("second_moment", sec.second_moment)?;
                d.set_item("density", sec.density)?;
                d.set_item("youngs_modulus", sec.youngs_modulus)?;
                d.set_item("shear_stiffness", sec.shear_stiffness)?;
                d.set_item("rotary_inertia", sec.rotary_inertia)?;
                d.set_item("damping", beam.damping)?;
                d.set_item("shear_parameter", beam.phi)?;
                d.set_item("strain", match beam.strain {
                    crate::description::Strain::Linear => "linear",
                    crate::description::Strain::Nonlinear => "nonlinear",
                })?;
            }
            BodyKind::AncfBeam(cable) => {
                let sec = &cable.section;
                d.set_item("formulation", "ancf")?;
                d.set_item("length", cable.length)?;
                d.set_item("elements", cable.elements)?;
                d.set_item("element_length", cable.element_length)?;
                d.set_item("theory", "euler-bernoulli")?;
                d.set_item("area", sec.area)?;
                d.set_item("second_moment", sec.second_moment)?;
                d.set_item("density", sec.density)?;
                d.set_item("youngs_modulus", sec.youngs_modulus)?;
                d.set_item("rotary_inertia", false)?;
                d.set_item("damping", cable.damping)?;
                d.set_item("axial_quadrature", "lobatto-3")?;
                d.set_item("bending_quadrature", "gauss-2")?;
            }
            BodyKind::Flexible(f) => {
                d.set_item("markers", f.markers.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>())?;
                d.set_item("strain", match f.strain {
                    crate::description::Strain::Linear => "linear",
                    crate::description::Strain::Nonlinear => "nonlinear",
                })?;
                d.set_item("damping", f.d_ff.is_some())?;
            }
            BodyKind::PointMass(_) | BodyKind::Point3(_) => {}
            BodyKind::Rigid3(r) => {
                d.set_item("inertia", r.inertia.iter().map(|row| row.to_vec()).collect::<Vec<_>>())?;
                d.set_item("com", r.com.to_vec())?;
            }
        }
        Ok(d)
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
            return Err(PyValueError::new_err(format!("max_wall_time must be positive, got {max_wall_time}")));
        }
        for (what, v) in [("position_tol", position_tol), ("velocity_tol", velocity_tol)] {
            if !(v > 0.0) || !v.is_finite() {
                return Err(PyValueError::new_err(format!("{what} must be positive and finite, got {v}")));
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

