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
//! the hook changes `y` the stepper re-evaluates `f` there (`Stepper::restart_at`). The same
//! loop, for every method, reports progress when asked (`Progress`: every k accepted steps or
//! every so many seconds; `integrate_observed`).

// Hairer's constants are kept with all their printed digits; index loops mirror the papers.
#![allow(clippy::excessive_precision, clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

mod dopri5;
mod galpha;
pub(crate) use crate::linalg::lu;
pub mod newton;
mod radau5;
mod radau_m;
pub mod corotation;
mod switches;
pub mod singular;
mod dense;
mod options;
pub mod choice;
mod uk_system;

pub use dopri5::{Dopri5, PROJECTION_MOVE_LIMIT};
pub use newton::{LinearSolver, NewtonMatrices};
pub use {galpha::{GenAlpha, GenAlphaOptions}, radau5::Radau5, radau_m::{RadauM, RadauMOptions}};
pub use dense::{DenseParts, DenseRecord, DenseView};
pub use options::{check_tolerances, default_projection, options_of, Method, Options, RunPlan, RunRequest, ATOL_PER_RTOL, COMMON_OPTIONS, DEFAULT_RTOL, METHOD_OPTIONS, NATIVE_METHODS, PROJECTION_MAX_ITER, PROJECTION_PER_ATOL, RTOL_MIN};
pub use uk_system::{Conditioning, UkSystem};

use crate::correct::{self, ProjectOutcome, ProjectWorkspace, ProjectionTolerance};
use crate::data::{Data, RankInfo};
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
    /// What RADAU5M's Newton matrices turn with (`corotation.rs`, `radau_m/corotate.rs`).
    fn corotated_bodies(&self) -> corotation::Corotated {
        Default::default()
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
    /// The cheap, fast-varying part of `structure` -- `M`, `K`, `A`, and the analytic part of
    /// `C` (the force elements' damping, moved in `c` to `(q, qd)`) -- at the state of the last
    /// `acc` or `augmented_residual` call `(q, qd)` (an implementation may reuse what that call
    /// computed).
    fn stiff_structure(&mut self, _q: &[f64], _qd: &[f64], _m: &mut [f64], _k: &mut [f64], _c: &mut [f64], _a: &mut [f64]) -> Result<bool> {
        Ok(false)
    }
    /// The forces that read the multipliers (joint friction) in the Newton matrices: `af`
    /// (m x n, as `structure`'s `a`) receives `-dQ/dlambda` at `(q, qd)` and the multipliers of
    /// the last `augmented_residual` (or `acc`) call, the part the top-right block adds to
    /// `A^T`. `false`: no such forces (`af` untouched).
    fn multiplier_terms(&mut self, _q: &[f64], _qd: &[f64], _af: &mut [f64]) -> bool {
        false
    }
    /// `multiplier_terms` into `s.af` of a `sparse_structure`.
    fn multiplier_terms_sparse(&mut self, _q: &[f64], _qd: &[f64], _s: &mut Structure) -> bool {
        false
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
    integrate_observed(stepper, sys, t0, y0, t_end, t_eval, dense, None)
}

/// Progress reports of a native run, the same for every method (`integrate_observed` calls
/// `tick` after every accepted step): `report(t)` with the time of the accepted step, once
/// `every_steps` steps or `interval` seconds of wall time have passed since the last report.
/// An `Err` from `report` ends the run there (a failure with that error's cause: the caller
/// stops a run this way, e.g. on Ctrl-C). A run without one pays one `None` check per step.
pub struct Progress<'a> {
    every_steps: usize,
    interval: f64,
    report: &'a mut dyn FnMut(f64) -> Result<()>,
    steps: usize,
    last: std::time::Instant,
}

impl<'a> Progress<'a> {
    /// Reports every `every_steps` accepted steps (at least 1) or every `interval` seconds
    /// (positive; infinite: by steps only), whichever comes first.
    pub fn new(every_steps: usize, interval: f64, report: &'a mut dyn FnMut(f64) -> Result<()>) -> Result<Self> {
        if every_steps == 0 {
            return Err(Error::argument("progress_steps", "must be at least 1"));
        }
        if !(interval > 0.0) {
            return Err(Error::argument("progress_interval", format!("must be positive, got {interval}")));
        }
        Ok(Progress { every_steps, interval, report, steps: 0, last: std::time::Instant::now() })
    }

    /// One accepted step at `t`: report it if it is due.
    #[inline]
    fn tick(&mut self, t: f64) -> Result<()> {
        self.steps += 1;
        if self.steps >= self.every_steps || self.last.elapsed().as_secs_f64() >= self.interval {
            self.steps = 0;
            self.last = std::time::Instant::now();
            (self.report)(t)?;
        }
        Ok(())
    }
}

/// `integrate_dense` with progress reports (`Progress`) after the accepted steps.
#[allow(clippy::too_many_arguments)]
pub fn integrate_observed<St: Stepper, S: SecondOrderSystem>(stepper: &mut St, sys: &mut S, t0: f64, y0: &[f64], t_end: f64, t_eval: Option<&[f64]>, dense: bool, mut progress: Option<&mut Progress<'_>>) -> Result<Solution> {
    crate::linalg::simd_state::clean_upper(); // whatever ran before: the SSE kernels on clean registers
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
            if let Some(p) = progress.as_deref_mut() {
                p.tick(t)?;
            }
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

/// Convenience: run `method` on the UK system of `model` with a workspace `data`.
#[allow(clippy::too_many_arguments)]
pub fn integrate_uk(model: &Model, data: Data, method: Method, opts: Options, t0: f64, y0: &[f64], t_end: f64, t_eval: Option<&[f64]>, projection: Option<ProjectionTolerance>, jacobian: Differences, dense: bool) -> Result<(Solution, usize, usize)> {
    integrate_uk_observed(model, data, method, opts, t0, y0, t_end, t_eval, projection, jacobian, dense, None)
}

/// `integrate_uk` with progress reports after the accepted steps (`Progress`).
#[allow(clippy::too_many_arguments)]
pub fn integrate_uk_observed(model: &Model, data: Data, method: Method, opts: Options, t0: f64, y0: &[f64], t_end: f64, t_eval: Option<&[f64]>, projection: Option<ProjectionTolerance>, jacobian: Differences, dense: bool, progress: Option<&mut Progress<'_>>) -> Result<(Solution, usize, usize)> {
    let mut sys = UkSystem::new(model, data);
    sys.projection = projection;
    sys.jws.scheme = jacobian;
    let sol = match method {
        Method::Dopri5 => {
            let mut st = Dopri5::new(2 * model.n, opts)?;
            // projects with the factorization of its last stage
            st.projection = sys.projection.take();
            integrate_observed(&mut st, &mut sys, t0, y0, t_end, t_eval, dense, progress)?
        }
        Method::Radau5 => {
            let mut st = Radau5::new(model.n, opts)?;
            integrate_observed(&mut st, &mut sys, t0, y0, t_end, t_eval, dense, progress)?
        }
        Method::GenAlpha(mut go) => {
            // the method projects with the factorization of its own last kernel call
            go.projection = sys.projection.take();
            let mut st = GenAlpha::new(model.n, model.m, opts, go)?;
            integrate_observed(&mut st, &mut sys, t0, y0, t_end, t_eval, dense, progress)?
        }
        Method::RadauM(mut ro) => {
            ro.projection = sys.projection.take();
            let mut st = RadauM::new(model.n, model.m, opts, ro)?.with_stops(if ro.step.is_some() { switches::load_switches(model, t0, t_end) } else { Vec::new() });
            integrate_observed(&mut st, &mut sys, t0, y0, t_end, t_eval, dense, progress)?
        }
    };
    Ok((sol, sys.jac_full_evals, sys.jac_cheap_evals))
}
