//! `ukflex._core.System`: a compiled model with its workspace behind a lock.

mod choice;
mod inspect;
mod run;
mod spatial;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use super::{arg_err, check_time, finite_out, mat, read_into, to_py, Real, SolverError, Vector};
use crate::data::{Data, RankTolerance, SvdBackend, UkSolver};
use crate::dynamics;
use crate::error::Error;
use crate::integrate::singular::Passage;
use crate::jacobian::JacobianWorkspace;
use crate::model::Model;
use crate::uk;

/// Workspace behind the lock: the kernel buffers plus contiguous copies of the inputs.
pub(super) struct Workspace {
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
pub(super) fn implicit_bytes(model: &Model, what: &str) -> u64 {
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
pub(super) fn passages_list<'py>(py: Python<'py>, passages: &[Passage]) -> PyResult<Bound<'py, PyList>> {
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
    /// What `method="auto"` reads from the description (dampers, springs).
    traits: crate::integrate::choice::SceneTraits,
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
        // the kernels' SSE code on clean vector registers, whatever ran before (linalg::simd_state)
        crate::linalg::simd_state::clean_upper();
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
    #[pyo3(signature = (description_json, uk_solver="auto", memory_limit=None, callables=None))]
    fn new(description_json: &str, uk_solver: &str, memory_limit: Option<f64>, callables: Option<&Bound<'_, pyo3::types::PyDict>>) -> PyResult<Self> {
        let solver = UkSolver::parse(uk_solver).map_err(to_py)?;
        let memory_limit = match memory_limit {
            None => DEFAULT_MEMORY_LIMIT,
            Some(b) if b > 0.0 && !b.is_nan() => if b.is_finite() { b as u64 } else { u64::MAX },
            Some(b) => return Err(arg_err("memory_limit", format!("must be a positive number of bytes, got {b}"))),
        };
        let model = catch_unwind(|| Model::from_json(description_json))
            .map_err(|_| SolverError::new_err("internal error while building the model"))?
            .map_err(to_py)?;
        let mut model = model;
        super::callables::attach(&mut model, callables).map_err(to_py)?;
        let data = Data::build(&model, solver, memory_limit).map_err(to_py)?;
        let n = model.n;
        let ws = Workspace { data, q: vec![0.0; n], qd: vec![0.0; n], jws: JacobianWorkspace::new(&model), jq: Vec::new(), jv: Vec::new() };
        let desc: serde_json::Value = serde_json::from_str(description_json).map_err(|e| to_py(Error::Description(e.to_string())))?;
        let traits = crate::integrate::choice::SceneTraits::of(&model, &desc);
        Ok(PySystem { model, traits, ws: Mutex::new(ws) })
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

    /// The scene's length scale [m] (`rust/model/scale.rs`, `rust/correct/conditioning.rs`): the largest body dimension.
    #[getter]
    fn length_scale(&self) -> f64 {
        self.model.length_scale
    }

    /// Refuse a state double precision cannot resolve (`rust/model/scale.rs`, `rust/correct/conditioning.rs`): positions or angles too
    /// far from the origin, masses too disparate for the rank decision (InvalidSceneError).
    fn check_state(&self, t: Real, q: Vector<'_>, qd: Vector<'_>) -> PyResult<()> {
        let t = t.0;
        self.with_ws(|model, ws| {
            check_time(t)?;
            Self::load(ws, &q, Some(&qd))?;
            crate::correct::check_state(model, &mut ws.data, t, &ws.q, &ws.qd)
        })
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
            dynamics::mass_and_forces(model, &mut ws.data, 0.0, &ws.q, &ws.qd);
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
            dynamics::mass_and_forces(model, &mut ws.data, 0.0, &ws.q, &ws.qd);
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
            _ => return Err(arg_err("linearization", "give both qdd and lam, or neither (the UK solution at the state)")),
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
            dynamics::mass_and_forces(model, &mut ws.data, t, &ws.q, &ws.qd);
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
            return Err(arg_err("q", format!(
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
            _ => return Err(arg_err("rank_info", "give all of t, q, qd (a state) or none of them (the last solve)")),
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
                return Err(arg_err("rcond", format!("must be >= 0 and finite, got {r}")));
            }
        }
        if !atol.is_finite() || atol < 0.0 {
            return Err(arg_err("atol", format!("must be >= 0 and finite, got {atol}")));
        }
        self.with_ws(|_, ws| {
            ws.data.tolerance = RankTolerance { rcond, atol };
            Ok(())
        })
    }

    /// How the UK pseudoinverse is computed: "auto" (default: certified full-rank QR, Jacobi
    /// SVD otherwise), "qr-jacobi" (QR + Jacobi SVD every call), "faer" (faer's SVD) or "cod"
    /// ("auto" with the certified complete orthogonal decomposition instead of the SVD for a
    /// rank-deficient B: same rank, the correction differs off the manifold by about the
    /// drift; docs/spatial.md). Same results to rounding otherwise; see docs/performance.md.
    #[pyo3(signature = (kind="auto"))]
    fn set_pseudoinverse(&self, kind: &str) -> PyResult<()> {
        let b = match kind {
            "auto" => SvdBackend::Auto,
            "qr-jacobi" => SvdBackend::QrJacobi,
            "faer" => SvdBackend::Faer,
            "cod" => SvdBackend::Cod,
            other => return Err(arg_err("kind", format!("unknown pseudoinverse kind '{other}' (use 'auto', 'qr-jacobi', 'faer' or 'cod')"))),
        };
        self.with_ws(|_, ws| {
            ws.data.svd_backend = b;
            Ok(())
        })
    }

}

