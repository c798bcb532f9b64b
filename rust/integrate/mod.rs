//! Native integrators for the second-order system `qdd = g(t, q, qd)` written as
//! `y' = f(t, y)`, `y = [q, qd]`, `f = [qd, g]`:
//!
//! * `Dopri5`: Dormand-Prince 5(4) with Hairer's step-size control (PI, beta = 0.04) and his
//!   4th-order dense output (`DOPRI5`, Hairer, Norsett & Wanner, Solving ODEs I, II.5).
//! * `Radau5`: 3-stage Radau IIA (order 5), Hairer & Wanner's `RADAU5` (Solving ODEs II, IV.8):
//!   simplified Newton with the transformed real + complex iteration matrices, LU reused over
//!   steps while the Newton contraction stays small, Gustafsson's predictive step control,
//!   collocation dense output. The second-order structure `J = [[0, I], [Jq, Jv]]` reduces
//!   both iteration matrices from 2n x 2n to n x n (Hairer's `M1` trick):
//!   `(g I - J) [x1; x2] = [r1; r2]` <=> `(g^2 I - g Jv - Jq) x2 = g r2 + Jq r1`,
//!   `x1 = (r1 + x2) / g`.
//!
//! Both run on a `SecondOrderSystem` (the UK system: `UkSystem`), allocate their workspaces
//! once in `new`, and do not allocate per step (checked by a counting allocator in
//! `tests/integrators.rs`). `integrate` drives a stepper to `t_end`, writes outputs at the
//! accepted steps or at requested times (dense output), and calls the system's `post_step` hook
//! after every accepted step -- the place for a projection onto the constraint manifold; when
//! the hook changes `y` the stepper re-evaluates `f` there (`Stepper::restart_at`).

// Hairer's constants are kept with all their printed digits; index loops mirror the papers.
#![allow(clippy::excessive_precision, clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

mod dopri5;
mod galpha;
pub(crate) use crate::linalg::lu;
pub mod newton;
mod radau5;
mod radau_m;
pub mod singular;

pub use dopri5::{Dopri5, PROJECTION_MOVE_LIMIT};
pub use galpha::{GenAlpha, GenAlphaOptions};
pub use newton::{LinearSolver, NewtonMatrices};
pub use radau5::Radau5;
pub use radau_m::{RadauM, RadauMOptions};

use crate::correct::{self, ProjectOutcome, ProjectWorkspace, ProjectionTolerance};
use crate::data::RankInfo;
use crate::data::Data;
use crate::dynamics;
use crate::error::{check_finite, Error, Result};
use crate::jacobian::{uk_jacobian, Differences, JacobianWorkspace};
use crate::model::Model;
use crate::sparse_newton::{self, Pattern, Structure};
use crate::uk;

/// `qdd = g(t, q, qd)` with its Jacobians.
pub trait SecondOrderSystem {
    /// Number of coordinates n (the state has 2n entries).
    fn n(&self) -> usize;
    /// `qdd = g(t, q, qd)`.
    fn acc(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> Result<()>;
    /// `jq = dg/dq`, `jv = dg/dqd` (n x n, row-major).
    fn jac(&mut self, t: f64, q: &[f64], qd: &[f64], jq: &mut [f64], jv: &mut [f64]) -> Result<()>;
    /// Called after every accepted step with the new state; may change it (projection).
    /// Return `true` if `y` was changed.
    fn post_step(&mut self, _t: f64, _y: &mut [f64]) -> Result<bool> {
        Ok(false)
    }
    /// Whether `post_step` projects onto the constraints (then a method may filter its error
    /// estimate with `project_tangent`).
    fn projects(&self) -> bool {
        false
    }
    /// Number of constraint rows (the `A` of `structure`).
    fn n_constraints(&self) -> usize {
        0
    }
    /// The structure of the equations `M qdd + A^T lambda = Q(q, qd)`, `A qdd = b(q, qd)` at
    /// `(t, q, qd)` for an implicit method's iteration matrix, all row-major: the mass matrix
    /// `m` (n x n), the stiffness `k = -dQ/dq` (n x n, the parts known analytically), the
    /// damping `c = -dQ/dqd` (n x n), the constraint Jacobian `a` (m x n) and `bv = db/dqd`
    /// (m x n). `Ok(false)`: no such structure.
    fn structure(&mut self, _t: f64, _q: &[f64], _qd: &[f64], _m: &mut [f64], _k: &mut [f64], _c: &mut [f64], _a: &mut [f64], _bv: &mut [f64]) -> Result<bool> {
        Ok(false)
    }
    /// The residual of the acceleration-level equations for a trial `(qdd, lambda)` at
    /// `(t, q, qd)`: `r1 = M qdd + A^T lambda - Q` (n), `r2 = A qdd - b` (m). Its root is the
    /// acceleration `acc` returns (where `A` has full row rank), at a fraction of the cost: an
    /// implicit method may iterate on it and finish with `acc`. `Ok(false)`: not available.
    fn augmented_residual(&mut self, _t: f64, _q: &[f64], _qd: &[f64], _qdd: &[f64], _lambda: &[f64], _r1: &mut [f64], _r2: &mut [f64]) -> Result<bool> {
        Ok(false)
    }
    /// The multipliers of the last `acc` call (`M qdd + A^T lambda = Q`), length m.
    fn multipliers(&self, _out: &mut [f64]) {}
    /// `acc` at `(t, q, qd)`, then `(q, qd)` projected onto `Phi = 0`, `A qd + Phi_t = 0` where
    /// the residuals exceed `tol`, with the factorization that `acc` made (one kernel call for
    /// both). `qdd` is the acceleration at the state before the projection (which moves it by
    /// the drift, below the tolerances). Returns whether `(q, qd)` changed.
    fn acc_projected(&mut self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64], _tol: Option<ProjectionTolerance>) -> Result<ProjectOutcome> {
        self.acc(t, q, qd, qdd)?;
        Ok(ProjectOutcome::default())
    }
    /// Project `(q, qd)` onto the constraints as `tol` says, with the factorization of the last
    /// `acc` call when it was at `(t, q)` (otherwise after a fresh one). Returns what changed
    /// and `||Phi||` at the returned positions.
    fn project_step(&mut self, _t: f64, _q: &mut [f64], _qd: &mut [f64], _tol: ProjectionTolerance) -> Result<ProjectOutcome> {
        Ok(ProjectOutcome::default())
    }
    /// Remove from `v` (length n) its component across the constraint manifold at the state of
    /// the last `acc` call: `v <- v - M^-1 A^T (A M^-1 A^T)^+ A v`, the mass-orthogonal
    /// projection onto the tangent space `A v = 0` (a local error estimate filtered this way
    /// measures the error along the motion, not the error that the projection removes anyway).
    /// `keep`: the fraction of the part across the constraints that stays (0: the projection
    /// onto the tangent space; `normal_weight(...).sqrt()` for an error estimate).
    fn project_tangent(&mut self, _v: &mut [f64], _keep: f64) {}
    /// `sigma_min / sigma_max` of `B = A M^-1/2` at the last factorization (1 without
    /// constraints): against the run's best it weighs the part of an error estimate across the
    /// constraints (`normal_weight`).
    fn conditioning_ratio(&self) -> f64 {
        1.0
    }
    /// The numerical rank of the constraints at the last factorization (0 without constraints):
    /// `n` minus it is the number of degrees of freedom there.
    fn conditioning_rank(&self) -> usize {
        0
    }
    /// The conditioning of the constraints at `(t, q)`: the smallest kept and the largest
    /// singular value of the mass-weighted Jacobian `B = A M^-1/2`, and its numerical rank
    /// (`None` without constraints). From the last factorization when it was made at (about)
    /// these positions, else from a fresh one (which overwrites the workspace).
    fn conditioning(&mut self, _t: f64, _q: &[f64]) -> Result<Option<Conditioning>> {
        Ok(None)
    }
    /// How many singular values of `B = A M^-1/2` at `(t, q)` are at most `ratio` times the
    /// largest (the dimension that opens up at a singular configuration); `None` when not
    /// available (no constraints, or too many rows for a dense SVD).
    fn small_singular_values(&mut self, _t: f64, _q: &[f64], _ratio: f64) -> Result<Option<usize>> {
        Ok(None)
    }
    /// `||Phi(q, t)||` (Euclidean): known after a projection or an `acc` call at `(t, q)`,
    /// evaluated otherwise.
    fn constraint_residual(&mut self, _t: f64, _q: &[f64]) -> Result<f64> {
        Ok(0.0)
    }
    /// The cheap, fast-varying part of `structure` -- `M`, `K`, `A` -- at the state of the last
    /// `acc` or `augmented_residual` call `(q, qd)` (an implementation may reuse what that call
    /// computed).
    fn stiff_structure(&mut self, _q: &[f64], _qd: &[f64], _m: &mut [f64], _k: &mut [f64], _a: &mut [f64]) -> Result<bool> {
        Ok(false)
    }
    /// The structure in sparse form (`sparse_newton::Structure`: its pattern, values zero), or
    /// `None` when the system has none (the implicit methods then use the dense `structure`).
    fn sparse_structure(&mut self) -> Result<Option<Structure>> {
        Ok(None)
    }
    /// `structure` into the values of a `sparse_structure`.
    fn structure_sparse(&mut self, _t: f64, _q: &[f64], _qd: &[f64], _s: &mut Structure) -> Result<bool> {
        Ok(false)
    }
    /// `stiff_structure` into the values of a `sparse_structure`.
    fn stiff_structure_sparse(&mut self, _q: &[f64], _qd: &[f64], _s: &mut Structure) -> Result<bool> {
        Ok(false)
    }
    /// Refuse an allocation of `bytes` above the system's memory limit (`Error::Memory`).
    fn check_memory(&self, _what: &str, _bytes: u64) -> Result<()> {
        Ok(())
    }
    /// Whether `jac` is the structured linearization (saddle-point solves with `structure`):
    /// RADAU5 may then solve its iteration matrices as saddle points, sparse.
    fn structured_jacobian(&self) -> bool {
        false
    }
}

/// A non-finite state or acceleration ends a run: `Error::NonFinite` with `what` naming the
/// stage (`"q"`, `"qd"`, `"qdd"`) and the time, `index` the coordinate (the bindings add names).
fn check_state_finite(t: f64, q: &[f64], qd: &[f64], qdd: &[f64]) -> Result<()> {
    for (what, v) in [("q", q), ("qd", qd), ("qdd", qdd)] {
        if let Some(index) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::NonFinite { what: format!("{what} at t = {}", fmt_t(t)), index });
        }
    }
    Ok(())
}

/// `dy = f(t, y) = [qd, g(t, q, qd)]`.
#[inline]
fn rhs<S: SecondOrderSystem + ?Sized>(sys: &mut S, t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
    let n = sys.n();
    let (dq, dqd) = dy.split_at_mut(n);
    dq.copy_from_slice(&y[n..]);
    sys.acc(t, &y[..n], &y[n..], dqd)
}

/// The conditioning of the constraint Jacobian at a state (`SecondOrderSystem::conditioning`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Conditioning {
    /// Smallest kept and largest singular value of `B = A M^-1/2` (exact after an SVD; the
    /// certified bounds after the full-rank QR and sparse paths: `RankInfo`).
    pub sigma_min: f64,
    pub sigma_max: f64,
    pub rank: usize,
}

impl Conditioning {
    fn from_rank_info(r: &RankInfo) -> Self {
        Conditioning { sigma_min: r.sigma_min_kept, sigma_max: r.sigma_max, rank: r.rank }
    }
    /// `sigma_min / sigma_max` (1 without kept singular values).
    pub fn ratio(&self) -> f64 {
        if self.sigma_max > 0.0 && self.sigma_min.is_finite() { self.sigma_min / self.sigma_max } else { 1.0 }
    }
}

/// The UK equations of motion of a model as a `SecondOrderSystem`.
pub struct UkSystem<'a> {
    pub model: &'a Model,
    pub data: Data,
    pub jws: JacobianWorkspace,
    /// Projection onto `Phi = 0`, `A qd + Phi_t = 0` after each accepted step
    /// (`correct::ProjectionTolerance`); the steppers that project with their own last kernel
    /// call take it over (`integrate_uk`).
    pub projection: Option<ProjectionTolerance>,
    pws: ProjectWorkspace,
    /// UK evaluations spent inside finite-difference Jacobians (full, factorization-reusing).
    pub jac_full_evals: usize,
    pub jac_cheap_evals: usize,
    /// Positions and time of the last `acc` call; `ready`: `data` still holds its
    /// factorization and `Phi` (nothing else has written the workspace since).
    acc_q: Vec<f64>,
    acc_t: f64,
    ready: bool,
    /// The rank report of the last factorization of `B` and its positions (for `conditioning`).
    fact_q: Vec<f64>,
    fact_info: Option<RankInfo>,
    /// `||Phi||` at `res_q`, `res_t` when `res_valid`.
    res_q: Vec<f64>,
    res_t: f64,
    res_norm: f64,
    res_valid: bool,
    zeros: Vec<f64>,
    rm: Vec<f64>,
    lam: Vec<f64>,
}

/// Positions this close (relative to their size) share their conditioning for
/// `SecondOrderSystem::conditioning` (the projection after a step moves them by the drift).
const CONDITIONING_SAME_Q: f64 = 1e-6;

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl<'a> UkSystem<'a> {
    pub fn new(model: &'a Model, data: Data) -> Self {
        let (n, m) = (model.n, model.m);
        let jws = JacobianWorkspace::new(model);
        UkSystem {
            model, data, jws, projection: None, pws: ProjectWorkspace::new(model), jac_full_evals: 0, jac_cheap_evals: 0,
            acc_q: vec![0.0; n], acc_t: f64::NAN, ready: false, fact_q: vec![0.0; n], fact_info: None,
            res_q: vec![0.0; n], res_t: f64::NAN, res_norm: 0.0, res_valid: false, zeros: vec![0.0; n], rm: vec![0.0; m], lam: vec![0.0; m],
        }
    }

    /// After a kernel call that factored `B` at `(t, q)` with `Phi`.
    fn record_factorization(&mut self, t: f64, q: &[f64]) {
        if self.model.m == 0 {
            return;
        }
        self.acc_q.copy_from_slice(q);
        self.acc_t = t;
        self.ready = true;
        self.fact_q.copy_from_slice(q);
        self.fact_info = Some(self.data.rank_info);
        self.res_q.copy_from_slice(q);
        self.res_t = t;
        self.res_norm = norm2(&self.data.phi);
        self.res_valid = true;
    }

    fn at_last_acc(&self, t: f64, q: &[f64]) -> bool {
        self.ready && t == self.acc_t && q == &self.acc_q[..]
    }
}

impl SecondOrderSystem for UkSystem<'_> {
    fn n(&self) -> usize {
        self.model.n
    }
    #[inline]
    fn acc(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> Result<()> {
        self.ready = false;
        if self.model.m == 0 {
            uk::acceleration(self.model, &mut self.data, t, q, qd)?;
        } else {
            uk::acceleration_with_phi(self.model, &mut self.data, t, q, qd)?;
            self.record_factorization(t, q);
        }
        qdd.copy_from_slice(&self.data.qdd);
        check_state_finite(t, q, qd, qdd)
    }
    fn jac(&mut self, t: f64, q: &[f64], qd: &[f64], jq: &mut [f64], jv: &mut [f64]) -> Result<()> {
        self.ready = false;
        uk_jacobian(self.model, &mut self.data, &mut self.jws, t, q, qd, jq, jv)?;
        self.jac_full_evals += self.jws.full_evals;
        self.jac_cheap_evals += self.jws.cheap_evals;
        Ok(())
    }
    fn post_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool> {
        let Some(p) = self.projection else { return Ok(false) };
        self.ready = false;
        let n = self.model.n;
        let (q, qd) = y.split_at_mut(n);
        let out = correct::project_in_place(self.model, &mut self.data, &mut self.pws, t, q, qd, p)?;
        self.res_q.copy_from_slice(q);
        self.res_t = t;
        self.res_norm = out.phi_norm;
        self.res_valid = true;
        Ok(out.changed)
    }
    fn n_constraints(&self) -> usize {
        self.model.m
    }
    fn projects(&self) -> bool {
        self.projection.is_some() && self.model.m > 0
    }
    fn augmented_residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], lambda: &[f64], r1: &mut [f64], r2: &mut [f64]) -> Result<bool> {
        self.ready = false;
        let (model, data) = (self.model, &mut self.data);
        let n = model.n;
        dynamics::mass_and_forces(model, data, q, qd);
        dynamics::constraints(model, data, t, q, qd, false);
        dynamics::mass_times(model, data, qdd, r1);
        for i in 0..n {
            r1[i] -= data.force[i];
        }
        for (r, &l) in lambda.iter().enumerate() {
            data.ajac.add_row(r, l, r1);
            r2[r] = data.ajac.row_dot(r, qdd) - data.gamma[r];
        }
        Ok(true)
    }
    fn multipliers(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.data.lambda);
    }
    fn acc_projected(&mut self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64], tol: Option<ProjectionTolerance>) -> Result<ProjectOutcome> {
        self.acc(t, q, qd, qdd)?;
        match tol {
            Some(tol) => self.project_step(t, q, qd, tol),
            None => Ok(ProjectOutcome { phi_norm: self.res_norm, ..Default::default() }),
        }
    }
    fn project_step(&mut self, t: f64, q: &mut [f64], qd: &mut [f64], tol: ProjectionTolerance) -> Result<ProjectOutcome> {
        if self.model.m == 0 {
            return Ok(ProjectOutcome::default());
        }
        if !self.at_last_acc(t, q) {
            uk::acceleration_with_phi(self.model, &mut self.data, t, q, qd)?;
            self.record_factorization(t, q);
        }
        self.ready = false;
        let out = correct::project_with_factorization(self.model, &mut self.data, &mut self.pws, t, q, qd, tol)?;
        self.res_q.copy_from_slice(q);
        self.res_t = t;
        self.res_norm = out.phi_norm;
        self.res_valid = true;
        Ok(out)
    }
    fn project_tangent(&mut self, v: &mut [f64], keep: f64) {
        let (model, data) = (self.model, &mut self.data);
        if model.m == 0 {
            return;
        }
        for (i, r) in self.rm.iter_mut().enumerate() {
            *r = data.ajac.row_dot(i, v);
        }
        self.lam.copy_from_slice(&data.lambda);
        uk::min_norm_correction(model, data, &self.rm);
        for (x, d) in v.iter_mut().zip(&data.qdd) {
            *x -= (1.0 - keep) * d;
        }
        data.lambda.copy_from_slice(&self.lam);
    }
    fn conditioning_ratio(&self) -> f64 {
        if self.model.m == 0 {
            return 1.0;
        }
        Conditioning::from_rank_info(&self.data.rank_info).ratio()
    }
    fn conditioning_rank(&self) -> usize {
        if self.model.m == 0 { 0 } else { self.data.rank_info.rank }
    }
    fn conditioning(&mut self, t: f64, q: &[f64]) -> Result<Option<Conditioning>> {
        if self.model.m == 0 {
            return Ok(None);
        }
        if let Some(info) = self.fact_info {
            let size = q.iter().fold(1.0f64, |s, x| s.max(x.abs()));
            if q.iter().zip(&self.fact_q).all(|(a, b)| (a - b).abs() <= CONDITIONING_SAME_Q * size) {
                return Ok(Some(Conditioning::from_rank_info(&info)));
            }
        }
        self.ready = false;
        let (model, data) = (self.model, &mut self.data);
        uk::evaluate(model, data, t, q, &self.zeros, false)?;
        // the sparse path's estimate where its Cholesky succeeds (no dense fallback near a
        // singular configuration: that is where the monitor looks)
        // singular configuration: that is where the monitor looks). Where the steps have full
        // rank a failed Cholesky means sigma_min^2 below its rounding: singular to working
        // precision. With redundant rows it always fails: the dense path decides.
        let full_rank = self.fact_info.is_none_or(|i| i.rank == model.m);
        if let (Some(sp), true) = (data.sparse.as_mut(), full_rank) {
            let info = sp.factor(model, &data.bodies, &data.ajac, &data.tolerance);
            self.fact_info = None;
            let (sigma_min, sigma_max) = sp.conditioning_estimate().unwrap_or((0.0, sp.trace_s.sqrt()));
            let rank = info.map_or(model.m, |i| i.rank);
            return Ok(Some(Conditioning { sigma_min, sigma_max, rank }));
        }
        uk::factor_constraints(model, data)?;
        self.fact_q.copy_from_slice(q);
        self.fact_info = Some(data.rank_info);
        Ok(Some(Conditioning::from_rank_info(&data.rank_info)))
    }
    fn small_singular_values(&mut self, t: f64, q: &[f64], ratio: f64) -> Result<Option<usize>> {
        if self.model.m == 0 {
            return Ok(None);
        }
        self.ready = false;
        self.fact_info = None;
        let (model, data) = (self.model, &mut self.data);
        uk::evaluate(model, data, t, q, &self.zeros, false)?;
        // the sparse path: Sylvester's inertia of S - tau^2 I (tau: ratio x the upper bound
        // sqrt(trace S) of sigma_max); else every singular value from the dense SVD
        if let Some(sp) = data.sparse.as_mut() {
            sp.factor(model, &data.bodies, &data.ajac, &data.tolerance);
            let tau = ratio * sp.trace_s.sqrt();
            return Ok(Some(sp.count_below(tau * tau)));
        }
        let Some(s) = uk::singular_values(model, data)? else { return Ok(None) };
        let top = s.first().copied().unwrap_or(0.0);
        Ok(Some(s.iter().filter(|x| **x <= ratio * top).count()))
    }
    fn constraint_residual(&mut self, t: f64, q: &[f64]) -> Result<f64> {
        if self.model.m == 0 {
            return Ok(0.0);
        }
        if self.res_valid && t == self.res_t && q == &self.res_q[..] {
            return Ok(self.res_norm);
        }
        self.ready = false;
        dynamics::constraints(self.model, &mut self.data, t, q, &self.zeros, true);
        self.res_q.copy_from_slice(q);
        self.res_t = t;
        self.res_norm = norm2(&self.data.phi);
        self.res_valid = true;
        Ok(self.res_norm)
    }
    fn stiff_structure(&mut self, q: &[f64], qd: &[f64], m: &mut [f64], k: &mut [f64], a: &mut [f64]) -> Result<bool> {
        // `uk::acceleration` / `augmented_residual` left the body blocks and A of (q, qd) in `data`
        self.ready = false;
        let (model, data) = (self.model, &mut self.data);
        data.ensure_dense_jac()?;
        dynamics::dense_mass_into(model, data, m);
        dynamics::stiffness_into(model, data, q, qd, k);
        a.copy_from_slice(&data.jac);
        Ok(true)
    }
    fn sparse_structure(&mut self) -> Result<Option<Structure>> {
        let p = Pattern::new(self.model, &self.data.ajac, false, self.data.memory_limit)?;
        Ok(Some(Structure::new(p)))
    }
    fn structure_sparse(&mut self, t: f64, q: &[f64], qd: &[f64], s: &mut Structure) -> Result<bool> {
        self.ready = false;
        sparse_newton::fill_structure(self.model, &mut self.data, t, q, qd, s);
        Ok(true)
    }
    fn stiff_structure_sparse(&mut self, q: &[f64], qd: &[f64], s: &mut Structure) -> Result<bool> {
        // `uk::acceleration` / `augmented_residual` left the body blocks and A of (q, qd) in `data`
        self.ready = false;
        sparse_newton::fill_mass(self.model, &self.data, s);
        sparse_newton::fill_stiffness(self.model, &self.data, q, qd, s);
        sparse_newton::fill_a(&self.data, s);
        Ok(true)
    }
    fn check_memory(&self, what: &str, bytes: u64) -> Result<()> {
        Error::check_memory(what, bytes, self.data.memory_limit, "raise memory_limit")
    }
    fn structured_jacobian(&self) -> bool {
        self.jws.scheme == Differences::Structured
    }
    fn structure(&mut self, t: f64, q: &[f64], qd: &[f64], m: &mut [f64], k: &mut [f64], c: &mut [f64], a: &mut [f64], bv: &mut [f64]) -> Result<bool> {
        self.ready = false;
        let (model, data) = (self.model, &mut self.data);
        data.ensure_dense_jac()?;
        dynamics::mass_and_forces(model, data, q, qd);
        dynamics::dense_mass_into(model, data, m);
        dynamics::tangent_into(model, data, q, qd, k, c);
        dynamics::constraints(model, data, t, q, qd, false);
        a.copy_from_slice(&data.jac);
        dynamics::velocity_jacobians_into(model, data, t, q, qd, &mut self.pws.v, c, bv);
        Ok(true)
    }
}

/// Tolerances and limits shared by the integrators.
#[derive(Debug, Clone)]
pub struct Options {
    pub rtol: f64,
    /// Absolute tolerance: one value, or one per state entry (2n).
    pub atol: Vec<f64>,
    /// Initial step (default: Hairer's estimate).
    pub first_step: Option<f64>,
    pub max_step: f64,
    /// Maximum number of step attempts.
    pub max_steps: usize,
    /// Maximum number of right-hand-side evaluations (`Stats::nfev`).
    pub max_nfev: usize,
    /// Wall-clock budget of the run [s] (checked before every step attempt).
    pub max_wall_time: f64,
    /// Smallest step size allowed [s]: a step below it ends the run (0: only the rounding
    /// limit `|t| eps`).
    pub min_step: f64,
    /// The drift bound: an accepted step whose `||Phi||` exceeds it ends the run
    /// (`Error::Drift`) when `stop_on_drift`, else is reported in `Solution::drift`
    /// (infinite: no check).
    pub drift_limit: f64,
    pub stop_on_drift: bool,
    /// Watch the conditioning of the constraints for singular passages (`Solution::singular`).
    pub monitor_singular: bool,
    /// How the implicit methods factor their Newton matrices (`newton::LinearSolver`).
    pub linear_solver: LinearSolver,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            rtol: 1e-6, atol: vec![1e-9], first_step: None, max_step: f64::INFINITY, max_steps: 1_000_000, max_nfev: usize::MAX,
            max_wall_time: f64::INFINITY, min_step: 0.0, linear_solver: LinearSolver::Auto, drift_limit: f64::INFINITY,
            stop_on_drift: true, monitor_singular: true,
        }
    }
}

impl Options {
    /// Check every setting once (the bindings and the steppers rely on it); returns the
    /// absolute tolerance expanded to `dim` entries.
    pub fn validate(&self, dim: usize) -> Result<Vec<f64>> {
        let bad = |m: String| Err(Error::argument("integrator", m));
        let v = match self.atol.len() {
            1 => vec![self.atol[0]; dim],
            k if k == dim => self.atol.clone(),
            k => return Err(Error::Shape { what: "atol".into(), expected: dim, got: k }),
        };
        if !(self.rtol > 0.0) || !self.rtol.is_finite() || v.iter().any(|a| !(*a >= 0.0) || !a.is_finite()) {
            return bad("rtol must be positive and finite, atol >= 0 and finite".into());
        }
        if let Some(h) = self.first_step {
            if !(h > 0.0) || !h.is_finite() {
                return bad(format!("first_step must be positive and finite, got {h}"));
            }
        }
        if !(self.max_step > 0.0) {
            return bad(format!("max_step must be positive, got {}", self.max_step));
        }
        if !(self.min_step >= 0.0) || !self.min_step.is_finite() {
            return bad(format!("min_step must be >= 0 and finite, got {}", self.min_step));
        }
        if self.max_step < self.min_step || self.first_step.is_some_and(|h| h < self.min_step) {
            return bad(format!("max_step and first_step must be >= min_step = {:e}", self.min_step));
        }
        if !(self.max_wall_time > 0.0) {
            return bad(format!("max_wall_time must be positive, got {}", self.max_wall_time));
        }
        if !(self.drift_limit > 0.0) {
            return bad(format!("drift_limit must be positive, got {}", self.drift_limit));
        }
        Ok(v)
    }
}

/// Counters of one run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Right-hand-side evaluations by the integrator (Jacobian evaluations excluded).
    pub nfev: usize,
    pub njev: usize,
    /// LU decompositions (Radau: real and complex counted separately, as scipy does).
    pub nlu: usize,
    pub naccept: usize,
    pub nreject: usize,
    /// Newton iterations (implicit methods: GENALPHA counts its iterations on accepted and
    /// rejected attempts; RADAU5 its simplified-Newton iterations).
    pub newton: usize,
}

/// The state every stepper keeps: the current and previous time, the next step size, the
/// state vector and the counters.
#[derive(Debug, Clone, Default)]
pub struct StepState {
    pub t: f64,
    pub t_old: f64,
    /// Next step size to try.
    pub h: f64,
    pub y: Vec<f64>,
    pub stats: Stats,
    /// Step attempts so far (bounded by `Options::max_steps`).
    pub steps: usize,
    /// Start of the run (for `Options::max_wall_time`).
    pub started: Option<std::time::Instant>,
    /// The last attempt was rejected for a non-finite trial value (stage, coordinate): named
    /// if the step size then shrinks to nothing.
    pub nonfinite: Option<(&'static str, usize)>,
}

/// A time for a message: plain below 1e6 s, in exponent notation above (no 90-digit times).
pub(crate) fn fmt_t(t: f64) -> String {
    if t != 0.0 && (t.abs() >= 1e6 || t.abs() < 1e-4) { format!("{t:.9e}") } else { format!("{t}") }
}

impl StepState {
    fn new(dim: usize) -> Self {
        StepState { y: vec![0.0; dim], ..Default::default() }
    }

    fn start(&mut self, t0: f64, y0: &[f64]) {
        self.t = t0;
        self.t_old = t0;
        self.y.copy_from_slice(y0);
        self.stats = Stats::default();
        self.steps = 0;
        self.started = Some(std::time::Instant::now());
        self.nonfinite = None;
    }

    /// The checks every method makes before a step attempt: the work budgets
    /// (`Error::Budget`) and the step-size floor.
    fn check_attempt(&mut self, method: &str, opts: &Options) -> Result<()> {
        self.steps += 1;
        // formatted only on the way out: no allocation per attempt
        let t = || fmt_t(self.t);
        if self.steps > opts.max_steps {
            return Err(Error::Budget { what: "max_steps".into(), message: format!("{method}: more than max_steps = {} step attempts at t = {}", opts.max_steps, t()) });
        }
        if self.stats.nfev > opts.max_nfev {
            return Err(Error::Budget { what: "max_nfev".into(), message: format!("{method}: more than max_nfev = {} evaluations at t = {}", opts.max_nfev, t()) });
        }
        if opts.max_wall_time.is_finite() && self.started.is_some_and(|s| s.elapsed().as_secs_f64() > opts.max_wall_time) {
            return Err(Error::Budget { what: "max_wall_time".into(), message: format!("{method}: wall time over max_wall_time = {} s at t = {}", opts.max_wall_time, t()) });
        }
        if 0.1 * self.h.abs() <= self.t.abs() * f64::EPSILON || !self.h.is_finite() || self.h < opts.min_step {
            if let Some((stage, index)) = self.nonfinite {
                return Err(Error::NonFinite { what: format!("{stage} at t = {} (trial steps down to h = {:.3e} all non-finite)", t(), self.h), index });
            }
            return Err(Error::Budget { what: "min_step".into(), message: format!("{method}: step size too small (h = {:.3e}, min_step = {:.3e}) at t = {}", self.h, opts.min_step, t()) });
        }
        Ok(())
    }
}

/// One-step integrator with dense output.
pub trait Stepper {
    /// Start at `(t0, y0)`; `t_end` bounds the first step.
    fn init<S: SecondOrderSystem>(&mut self, sys: &mut S, t0: f64, y0: &[f64], t_end: f64) -> Result<()>;
    /// One accepted step (rejected attempts are retried inside), never beyond `t_end`.
    fn step<S: SecondOrderSystem>(&mut self, sys: &mut S, t_end: f64) -> Result<()>;
    /// The data of the last step's dense output: `meta = [t_old, t, aux]` and up to five
    /// vectors (`count` of them); `dense_eval` evaluates them.
    fn dense_parts(&self) -> DenseParts<'_>;
    /// The dense output defined by `meta` and `parts` (as `dense_parts` gives them) at `t`.
    fn dense_eval(meta: [f64; 3], parts: &[&[f64]], t: f64, out: &mut [f64]);
    /// The dimension of the states `dense_eval` writes when `part_len` (the lengths of
    /// `dense_parts`) is this method's layout; `None` otherwise (`DenseView::check`).
    fn dense_dim(part_len: &[usize]) -> Option<usize>;
    /// State at `t` in `[t_old, t]` from the dense output of the last step.
    fn dense(&self, t: f64, out: &mut [f64]) {
        let d = self.dense_parts();
        Self::dense_eval(d.meta, &d.parts[..d.count], t, out);
    }
    /// `y` was changed (post-step hook): re-evaluate what depends on it.
    fn restart_at<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<()>;
    /// The number of steps from `t0` to `t_end` when the method knows it in advance (a fixed
    /// step): the recorded trajectory is then sized once instead of growing.
    fn expected_steps(&self, _t0: f64, _t_end: f64) -> Option<usize> {
        None
    }
    fn state(&self) -> &StepState;
    fn state_mut(&mut self) -> &mut StepState;
    /// The run's settings.
    fn options(&self) -> &Options;

    fn t(&self) -> f64 {
        self.state().t
    }
    fn t_old(&self) -> f64 {
        self.state().t_old
    }
    fn y(&self) -> &[f64] {
        &self.state().y
    }
    fn y_mut(&mut self) -> &mut [f64] {
        &mut self.state_mut().y
    }
    fn stats(&self) -> Stats {
        self.state().stats
    }
}

fn rms_norm(v: &[f64], scale: &[f64]) -> f64 {
    (v.iter().zip(scale).map(|(x, s)| (x / s) * (x / s)).sum::<f64>() / v.len() as f64).sqrt()
}

/// Hairer's initial step guess (HINIT) for a method whose error estimate has order `iord`.
#[allow(clippy::too_many_arguments)]
fn initial_step<S: SecondOrderSystem>(sys: &mut S, t0: f64, y0: &[f64], f0: &[f64], rtol: f64, atol: &[f64], iord: i32, hmax: f64, y1: &mut [f64], f1: &mut [f64], nfev: &mut usize) -> Result<f64> {
    let (mut dnf, mut dny) = (0.0, 0.0);
    for i in 0..y0.len() {
        let sk = atol[i] + rtol * y0[i].abs();
        dnf += (f0[i] / sk).powi(2);
        dny += (y0[i] / sk).powi(2);
    }
    let mut h = if dnf <= 1e-10 || dny <= 1e-10 { 1e-6 } else { (dny / dnf).sqrt() * 0.01 };
    h = h.min(hmax);
    for i in 0..y0.len() {
        y1[i] = y0[i] + h * f0[i];
    }
    rhs(sys, t0 + h, y1, f1)?;
    *nfev += 1;
    let mut der2 = 0.0;
    for i in 0..y0.len() {
        let sk = atol[i] + rtol * y0[i].abs();
        der2 += ((f1[i] - f0[i]) / sk).powi(2);
    }
    let der2 = der2.sqrt() / h;
    let der12 = der2.abs().max(dnf.sqrt());
    let h1 = if der12 <= 1e-15 { (h * 1e-3).max(1e-6) } else { (0.01 / der12).powf(1.0 / iord as f64) };
    Ok((100.0 * h).min(h1).min(hmax))
}

/// `initial_step` for a second-order system at `(t0, y0 = [q, qd])` with the acceleration
/// `qdd` there (the implicit methods' first step when neither a fixed step nor `first_step` is
/// given; allocates its three 2n buffers once per run).
#[allow(clippy::too_many_arguments)]
fn initial_step_second_order<S: SecondOrderSystem>(sys: &mut S, t0: f64, y0: &[f64], qdd: &[f64], rtol: f64, atol: &[f64], iord: i32, hmax: f64, nfev: &mut usize) -> Result<f64> {
    let n = qdd.len();
    let mut f0 = vec![0.0; 2 * n];
    f0[..n].copy_from_slice(&y0[n..]);
    f0[n..].copy_from_slice(qdd);
    let (mut y1, mut f1) = (vec![0.0; 2 * n], vec![0.0; 2 * n]);
    initial_step(sys, t0, y0, &f0, rtol, atol, iord, hmax, &mut y1, &mut f1, nfev)
}

/// Steps from `t0` to `t_end` with a fixed step `h` (`Stepper::expected_steps`).
fn fixed_step_count(t0: f64, t_end: f64, h: Option<f64>) -> Option<usize> {
    let k = ((t_end - t0) / h?).ceil();
    (k.is_finite() && k >= 0.0).then_some(k as usize)
}

/// The acceleration and multipliers at the stepper's state (`Stepper::restart_at` of the
/// implicit methods: a post-step hook moved `(q, qd)` onto the constraints).
fn acc_and_multipliers<S: SecondOrderSystem>(sys: &mut S, st: &mut StepState, qdd: &mut [f64], lam: &mut [f64]) -> Result<()> {
    let (q, qd) = st.y.split_at(qdd.len());
    sys.acc(st.t, q, qd, qdd)?;
    st.stats.nfev += 1;
    sys.multipliers(lam);
    Ok(())
}

/// What defines one step's dense output (`Stepper::dense_parts`).
pub struct DenseParts<'a> {
    /// `[t_old, t, aux]` (`aux`: a method's extra scalar, e.g. RADAU5's step size).
    pub meta: [f64; 3],
    pub parts: [&'a [f64]; 5],
    pub count: usize,
}

/// The dense output of a whole run, one segment per accepted step (`integrate` with
/// `dense = true`): `meta` (3 per segment, `[t_old, t, aux]`) and the parts' data, concatenated
/// (`width` values per segment, split by `part_len`). Grown by amortized doubling, no per-step
/// allocation in the steady state.
#[derive(Debug, Clone, Default)]
pub struct DenseRecord {
    pub meta: Vec<f64>,
    pub data: Vec<f64>,
    pub part_len: Vec<usize>,
}

impl DenseRecord {
    fn push(&mut self, d: &DenseParts<'_>) {
        if self.part_len.is_empty() {
            self.part_len = d.parts[..d.count].iter().map(|p| p.len()).collect();
        }
        self.meta.extend_from_slice(&d.meta);
        for p in &d.parts[..d.count] {
            self.data.extend_from_slice(p);
        }
    }

    /// Values per segment.
    pub fn width(&self) -> usize {
        self.part_len.iter().sum()
    }

    pub fn view(&self) -> DenseView<'_> {
        DenseView { meta: &self.meta, data: &self.data, part_len: &self.part_len }
    }
}

/// A dense record to evaluate (a run's own, or arrays handed back by Python: `dense_eval`),
/// checked against its method's layout before any evaluation.
#[derive(Debug, Clone, Copy)]
pub struct DenseView<'a> {
    pub meta: &'a [f64],
    pub data: &'a [f64],
    pub part_len: &'a [usize],
}

impl DenseView<'_> {
    /// Check the record as a run of `method` writes it: at least one segment, `meta` 3 per
    /// segment, the parts of the method's layout (`Stepper::dense_dim`), `data` the width per
    /// segment, every value finite, each segment forward in time and the segments in order (the
    /// search in `eval` relies on it). Returns the dimension of an evaluated state.
    pub fn check(&self, method: &Method) -> Result<usize> {
        let bad = |m: String| Err(Error::argument("dense output", m));
        let dim = match method {
            Method::Dopri5 => Dopri5::dense_dim(self.part_len),
            Method::Radau5 => Radau5::dense_dim(self.part_len),
            Method::GenAlpha(_) => GenAlpha::dense_dim(self.part_len),
            Method::RadauM(_) => RadauM::dense_dim(self.part_len),
        };
        let Some(dim) = dim else {
            return bad(format!("part lengths {:?} are not the layout of a {} record", self.part_len, method.name()));
        };
        let nseg = self.meta.len() / 3;
        if nseg == 0 || self.meta.len() % 3 != 0 {
            return bad(format!("meta must hold 3 values per segment (at least one), got {}", self.meta.len()));
        }
        let width = self.part_len.iter().try_fold(0usize, |a, &b| a.checked_add(b));
        if width.filter(|w| nseg.checked_mul(*w) == Some(self.data.len())).is_none() {
            return bad(format!("data must hold {nseg} segments of {:?} values, got {} values", self.part_len, self.data.len()));
        }
        check_finite("dense output meta", self.meta)?;
        check_finite("dense output data", self.data)?;
        for k in 0..nseg {
            let (t_old, t) = (self.meta[3 * k], self.meta[3 * k + 1]);
            let next = if k + 1 < nseg { self.meta[3 * k + 3] } else { t };
            if !(t_old <= t) || !(next >= t) {
                return bad(format!("segment {k} [{t_old}, {t}] runs backwards or out of order"));
            }
        }
        Ok(dim)
    }

    /// Evaluate at `t` into `out` (`check`ed record, `out` of its dimension): the segment whose
    /// interval holds `t`; before the first or after the last segment, that segment's polynomial
    /// extrapolated.
    pub fn eval(&self, method: &Method, t: f64, out: &mut [f64]) {
        let nseg = self.meta.len() / 3;
        if nseg == 0 {
            out.fill(f64::NAN);
            return;
        }
        // first segment whose end is >= t
        let (mut lo, mut hi) = (0usize, nseg - 1);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.meta[3 * mid + 1] < t {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let w: usize = self.part_len.iter().sum();
        let seg = &self.data[lo * w..(lo + 1) * w];
        let mut parts: [&[f64]; 5] = [&[]; 5];
        let mut at = 0;
        for (k, len) in self.part_len.iter().enumerate().take(5) {
            parts[k] = &seg[at..at + len];
            at += len;
        }
        let meta = [self.meta[3 * lo], self.meta[3 * lo + 1], self.meta[3 * lo + 2]];
        let parts = &parts[..self.part_len.len().min(5)];
        match method {
            Method::Dopri5 => Dopri5::dense_eval(meta, parts, t, out),
            Method::Radau5 => Radau5::dense_eval(meta, parts, t, out),
            Method::GenAlpha(_) => GenAlpha::dense_eval(meta, parts, t, out),
            Method::RadauM(_) => RadauM::dense_eval(meta, parts, t, out),
        }
    }
}

/// Why a run ended early (`Solution::failure`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Failure {
    /// `"max_steps"`, `"max_nfev"`, `"max_wall_time"`, `"min_step"`, `"non_finite"` or
    /// `"solver"` (Newton failure, singular matrix, ...).
    pub cause: String,
    /// Time of the last accepted state.
    pub t: f64,
    /// `non_finite`: the stage (`"q"`, `"qd"` or `"qdd"`) and the coordinate index.
    pub stage: String,
    pub index: Option<usize>,
}

/// Trajectory of a run: `t` (nt) and `y` (nt x dim, row-major).
#[derive(Debug, Clone, Default)]
pub struct Solution {
    pub t: Vec<f64>,
    pub y: Vec<f64>,
    pub dim: usize,
    pub stats: Stats,
    /// 0: reached `t_end`; -1: failed (see `message` and `failure`).
    pub status: i32,
    pub message: String,
    pub failure: Option<Failure>,
    /// The dense output of every accepted step (when asked for).
    pub dense: Option<DenseRecord>,
    /// Singular passages (`singular::SingularMonitor`).
    pub singular: Vec<singular::Passage>,
    /// With `stop_on_drift = false`: the first accepted step beyond the drift bound and the
    /// largest `||Phi||` of the run's steps.
    pub drift: Option<DriftReport>,
}

/// Where a run that was allowed to go on left its drift bound (`Options::stop_on_drift`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftReport {
    pub t_first: f64,
    pub max_residual: f64,
    pub t_max: f64,
}

/// Integrate from `(t0, y0)` to `t_end`. Outputs at `t_eval` (strictly increasing, within
/// `[t0, t_end]`) from the dense output, or at every accepted step when `t_eval` is `None`.
/// A failure inside the run ends it with `status = -1` and the trajectory up to there; only
/// invalid arguments are returned as `Err`.
pub fn integrate<St: Stepper, S: SecondOrderSystem>(stepper: &mut St, sys: &mut S, t0: f64, y0: &[f64], t_end: f64, t_eval: Option<&[f64]>) -> Result<Solution> {
    integrate_dense(stepper, sys, t0, y0, t_end, t_eval, false)
}

/// `integrate`, and with `dense = true` the dense output of every accepted step in
/// `Solution::dense` (recorded after the post-step hook, so that it reproduces the `t_eval`
/// outputs exactly).
pub fn integrate_dense<St: Stepper, S: SecondOrderSystem>(stepper: &mut St, sys: &mut S, t0: f64, y0: &[f64], t_end: f64, t_eval: Option<&[f64]>, dense: bool) -> Result<Solution> {
    let dim = y0.len();
    if dim != 2 * sys.n() {
        return Err(Error::Shape { what: "y0".into(), expected: 2 * sys.n(), got: dim });
    }
    if !(t_end > t0) || !t_end.is_finite() || !t0.is_finite() {
        return Err(Error::argument("t_end", format!("must be finite and greater than t0 = {t0}, got {t_end}")));
    }
    if let Some(te) = t_eval {
        if te.windows(2).any(|w| !(w[1] > w[0])) || te.iter().any(|x| !(*x >= t0 && *x <= t_end)) {
            return Err(Error::argument("t_eval", format!("must be strictly increasing within [t0, t_end] = [{t0}, {t_end}]")));
        }
    }
    let mut sol = Solution { dim, ..Default::default() };
    // the trajectory's storage: sized once where the number of outputs is known (at most 8 MB
    // ahead of time: beyond that it grows as it goes)
    let cap = t_eval.map(|te| te.len()).or_else(|| stepper.expected_steps(t0, t_end).map(|k| k + 1)).unwrap_or(1024).min((1 << 20) / dim.max(1)).max(1);
    sol.t.reserve(cap);
    sol.y.reserve(cap * dim);
    let mut next = 0usize;
    let mut buf = vec![0.0; dim];
    let mut record = if dense { Some(DenseRecord::default()) } else { None };
    // the last accepted (finite) state's time: where a failed run's trajectory ends
    let mut t_good = t0;
    let (drift_limit, stop_on_drift, monitor_singular) = {
        let o = stepper.options();
        (o.drift_limit, o.stop_on_drift, o.monitor_singular)
    };
    let mut monitor = (monitor_singular && sys.n_constraints() > 0).then(|| singular::SingularMonitor::new(dim / 2));
    let mut drift: Option<DriftReport> = None;
    // the run; a failure ends it with the trajectory up to there
    let mut run = |sol: &mut Solution| -> Result<()> {
        stepper.init(sys, t0, y0, t_end)?;
        if let Some(mon) = monitor.as_mut() {
            mon.push(sys, t0, y0)?;
        }
        match t_eval {
            None => {
                sol.t.push(t0);
                sol.y.extend_from_slice(y0);
            }
            Some(te) => {
                while next < te.len() && te[next] == t0 {
                    sol.t.push(t0);
                    sol.y.extend_from_slice(y0);
                    next += 1;
                }
            }
        }
        while stepper.t() < t_end {
            let step = stepper.step(sys, t_end);
            sol.stats = stepper.stats();
            step?;
            let t = stepper.t();
            // an accepted step must be finite (an implicit method's converged iterate can
            // overflow in the positions): the run ends before it
            let n = dim / 2;
            if let Some(i) = stepper.y().iter().position(|x| !x.is_finite()) {
                let stage = if i < n { "q" } else { "qd" };
                return Err(Error::NonFinite { what: format!("{stage} at t = {}", fmt_t(t)), index: i % n });
            }
            if sys.post_step(t, stepper.y_mut())? {
                stepper.restart_at(sys)?;
            }
            // no success on garbage: the accepted state within the drift bound
            if drift_limit.is_finite() && sys.n_constraints() > 0 {
                let r = sys.constraint_residual(t, &stepper.y()[..n])?;
                if !(r <= drift_limit) {
                    if stop_on_drift {
                        return Err(Error::Drift { t, residual: r, limit: drift_limit });
                    }
                    let d = drift.get_or_insert(DriftReport { t_first: t, max_residual: r, t_max: t });
                    if r > d.max_residual {
                        d.max_residual = r;
                        d.t_max = t;
                    }
                }
            }
            if let Some(mon) = monitor.as_mut() {
                mon.push(sys, t, stepper.y())?;
            }
            if let Some(rec) = record.as_mut() {
                rec.push(&stepper.dense_parts());
            }
            match t_eval {
                None => {
                    sol.t.push(t);
                    sol.y.extend_from_slice(stepper.y());
                }
                Some(te) => {
                    while next < te.len() && te[next] <= t {
                        if te[next] == t {
                            sol.y.extend_from_slice(stepper.y());
                        } else {
                            stepper.dense(te[next], &mut buf);
                            sol.y.extend_from_slice(&buf);
                        }
                        sol.t.push(te[next]);
                        next += 1;
                    }
                }
            }
            t_good = t;
        }
        Ok(())
    };
    match run(&mut sol) {
        Ok(()) => sol.message = "The solver successfully reached the end of the integration interval.".into(),
        Err(e) => {
            sol.status = -1;
            sol.message = e.to_string();
            let t = t_good;
            sol.failure = Some(match e {
                Error::Budget { what, .. } => Failure { cause: what, t, ..Default::default() },
                Error::Drift { .. } => Failure { cause: "drift".into(), t, ..Default::default() },
                Error::NonFinite { what, index } => {
                    let stage = what.split(' ').next().unwrap_or("").to_string();
                    Failure { cause: "non_finite".into(), t, stage, index: Some(index) }
                }
                _ => Failure { cause: "solver".into(), t, ..Default::default() },
            });
        }
    }
    sol.stats = stepper.stats();
    sol.dense = record;
    sol.singular = monitor.map(|m| m.passages).unwrap_or_default();
    sol.drift = drift;
    Ok(sol)
}

/// The native methods by name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    Dopri5,
    Radau5,
    GenAlpha(GenAlphaOptions),
    RadauM(RadauMOptions),
}

/// The weight of the part of a local error estimate across the constraints, for the methods
/// that project after every step: 1 while the conditioning `kappa = sigma_min / sigma_max` of
/// the constraints at the step's end is at least `NEAR_SINGULAR` times the run's best
/// `kappa_ref`, 0 below (the estimate filtered onto the constraints' tangent space).
///
/// Near a singular configuration that part is amplified by `1 / kappa` and more; the
/// projection removes it, and counted it shrinks the step without end and drives the state
/// into the singular configuration, where it may leave its branch (docs/integrators.md,
/// singular configurations; a weight `(kappa / kappa_ref)^2` instead of the cut still did, at
/// rtol 1e-10 on the N four-bar). Away from one it counts in full: the dense output between
/// the steps is not projected, so a driven mechanism without degrees of freedom (whose whole
/// error lies across the constraints) keeps its outputs on the constraints.
pub fn normal_weight(kappa: f64, kappa_ref: f64) -> f64 {
    if kappa.is_finite() && kappa < NEAR_SINGULAR * kappa_ref {
        0.0
    } else {
        1.0
    }
}

/// `normal_weight`'s cut, against the run's best conditioning.
pub const NEAR_SINGULAR: f64 = 0.5;

/// `e` (halves of length `n`: positions, velocities) with its part across the constraints kept
/// at the weight `normal_weight(kappa, kappa_ref)` (`project_tangent` at the last kernel call).
fn weigh_error<S: SecondOrderSystem + ?Sized>(sys: &mut S, e: &mut [f64], n: usize, kappa_ref: f64) {
    let keep = normal_weight(sys.conditioning_ratio(), kappa_ref).sqrt();
    if keep < 1.0 {
        for chunk in e.chunks_mut(n) {
            sys.project_tangent(chunk, keep);
        }
    }
}

/// The default projection after every accepted step, for every method on a constrained
/// system: Newton on the positions until the correction's largest entry is at most
/// `PROJECTION_PER_ATOL` times the smallest absolute tolerance of the positions (1e-11 m at the
/// default `atol = 1e-9`), at most `PROJECTION_MAX_ITER` steps; the velocities in one step,
/// when their correction exceeds the same fraction of the velocities' smallest atol. Its cost
/// is two corrections with the step's own factorization and one evaluation of the constraints
/// per step; it keeps the drift of long runs at the tolerance and the motion on its branch at
/// singular configurations (`correct::ProjectionTolerance`).
pub const PROJECTION_PER_ATOL: f64 = 1e-2;
pub const PROJECTION_MAX_ITER: usize = 3;

/// `default_projection` for the expanded absolute tolerance `atol` (2n entries).
pub fn default_projection(atol: &[f64]) -> ProjectionTolerance {
    let n = atol.len() / 2;
    let tol = |part: &[f64]| {
        let smallest = part.iter().fold(f64::INFINITY, |m, a| m.min(*a));
        if smallest.is_finite() && smallest > 0.0 { PROJECTION_PER_ATOL * smallest } else { 0.0 }
    };
    ProjectionTolerance { position_tol: tol(&atol[..n]), velocity_tol: tol(&atol[n..]), max_iter: PROJECTION_MAX_ITER }
}

impl Method {
    pub fn from_name(name: &str) -> Option<Method> {
        match name.to_ascii_uppercase().as_str() {
            "DOPRI5" => Some(Method::Dopri5),
            "RADAU5" => Some(Method::Radau5),
            "GENALPHA" => Some(Method::GenAlpha(GenAlphaOptions::default())),
            "RADAU5M" => Some(Method::RadauM(RadauMOptions::default())),
            _ => None,
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Method::Dopri5 => "DOPRI5",
            Method::Radau5 => "RADAU5",
            Method::GenAlpha(_) => "GENALPHA",
            Method::RadauM(_) => "RADAU5M",
        }
    }
}

/// Convenience: run `method` on the UK system of `model` with a workspace `data`.
#[allow(clippy::too_many_arguments)]
pub fn integrate_uk(model: &Model, data: Data, method: Method, opts: Options, t0: f64, y0: &[f64], t_end: f64, t_eval: Option<&[f64]>, projection: Option<ProjectionTolerance>, jacobian: Differences, dense: bool) -> Result<(Solution, usize, usize)> {
    let mut sys = UkSystem::new(model, data);
    sys.projection = projection;
    sys.jws.scheme = jacobian;
    let sol = match method {
        Method::Dopri5 => {
            let mut st = Dopri5::new(2 * model.n, opts)?;
            // projects with the factorization of its last stage
            st.projection = sys.projection.take();
            integrate_dense(&mut st, &mut sys, t0, y0, t_end, t_eval, dense)?
        }
        Method::Radau5 => {
            let mut st = Radau5::new(model.n, opts)?;
            integrate_dense(&mut st, &mut sys, t0, y0, t_end, t_eval, dense)?
        }
        Method::GenAlpha(mut go) => {
            // the method projects with the factorization of its own last kernel call
            go.projection = sys.projection.take();
            let mut st = GenAlpha::new(model.n, model.m, opts, go)?;
            integrate_dense(&mut st, &mut sys, t0, y0, t_end, t_eval, dense)?
        }
        Method::RadauM(mut ro) => {
            ro.projection = sys.projection.take();
            let mut st = RadauM::new(model.n, model.m, opts, ro)?;
            integrate_dense(&mut st, &mut sys, t0, y0, t_end, t_eval, dense)?
        }
    };
    Ok((sol, sys.jac_full_evals, sys.jac_cheap_evals))
}

