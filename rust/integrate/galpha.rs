//! Generalized-alpha (Chung & Hulbert 1993, in the form of Arnold & Bruls 2007) for
//! `qdd = g(t, q, qd)`, the UK acceleration: second order, numerical dissipation of the high
//! frequencies set by `rho_inf` (1: none; 0: annihilation in one step). Made for stiff flexible
//! multibody systems, whose fast elastic modes (axial, short-element bending) are excited by a
//! sudden start and carry nothing the user asked for: they are damped instead of resolved.
//!
//! Step `n -> n+1` with the acceleration-like variable `a`:
//! * `(1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) qdd_{n+1} + alpha_f qdd_n`,
//! * `q_{n+1} = q_n + h qd_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}`,
//! * `qd_{n+1} = qd_n + h (1 - gamma) a_n + h gamma a_{n+1}`,
//! * `qdd_{n+1} = g(t_{n+1}, q_{n+1}, qd_{n+1})`: the UK acceleration.
//!
//! **Newton.** The unknowns are `qdd_{n+1}` and the multipliers; the iterations run on the
//! acceleration-level equations `M qdd + A^T lambda = Q`, `A qdd = b` at the trial state
//! (`SecondOrderSystem::augmented_residual`: assembly only), whose root is the UK acceleration,
//! with the iteration matrix of the constrained linearization
//!
//! `[M + gamma' C + beta' K, A^T; A - gamma' db/dqd, 0]`,
//!
//! `beta' = h^2 beta (1 - alpha_f) / (1 - alpha_m)` (`dq/dqdd`), `gamma' = h gamma
//! (1 - alpha_f) / (1 - alpha_m)` (`dqd/dqdd`), `K = -dQ/dq` the bodies' analytic stiffness,
//! `C = -dQ/dqd` and `db/dqd` exact differences of functions quadratic in the velocities. For
//! constant `M`, `A` it is exactly the Newton matrix `I + P M^-1 (beta' K + gamma' C) + ...` of
//! `qdd - g(q(qdd), qd(qdd))` (`P` the `M`-orthogonal projector onto the constraint null
//! space). The stiff directions turn with the bodies and the constraints (a rotating beam's
//! axial stiffness against a slider's fixed direction), so `M`, `K`, `A` are read at the
//! predicted state, where the first residual evaluation leaves them, and the factored matrix is
//! kept for the next steps only while Newton contracts fast with it; `C`, `db/dqd` vary slowly
//! and are re-read when Newton slows (or after 1024 steps). The converged iterate is finished by
//! one UK evaluation, `qdd_{n+1} = g(q_{n+1}, qd_{n+1})`: the accepted accelerations and
//! multipliers are the UK solution (the difference is the Newton error, below the tolerance).
//! Newton stops when its estimated remaining position error is below `NEWTON_KAPPA` in the
//! error-test units of `rtol`, or (`GenAlphaOptions::newton_local_error`, what `method="auto"`
//! uses), while it contracts fast, below a fraction of the last step's local error estimate:
//! an error far below what the step size already commits changes nothing.
//! As the UK evaluation amplifies a Newton error in the stiff directions by `~beta' omega^2`,
//! its change of the iterate (as a position change `beta' (g - x)`) is held to the same
//! tolerance, or Newton goes on.
//!
//! **Constraint drift.** The UK acceleration satisfies `A qdd = b` exactly, so positions and
//! velocities drift only by the discretization error. With a projection tolerance the final UK
//! evaluation's factorization also projects `q` and `qd` back (minimum mass-norm corrections,
//! `correct::project_with_factorization`) whenever the drift exceeds it: no extra kernel call.
//!
//! **Step size.** Fixed (`GenAlphaOptions::step`; a step whose Newton iteration fails is
//! halved, then the fixed step resumes), or controlled by the local error estimate of the
//! positions `h^2 |beta - 1/6| |a_{n+1} - a_n|` (Zienkiewicz & Xie 1991) against
//! `atol + rtol |q|`. Dense output: the cubic Hermite interpolant of `(q, qd)` at both ends.

use super::newton::NewtonMatrices;
use super::{acc_and_multipliers, fixed_step_count, initial_step_second_order, DenseParts, Options, SecondOrderSystem, StepState, Stepper};
use crate::correct::ProjectionTolerance;
use crate::error::{Error, Result};

/// Settings of the generalized-alpha method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GenAlphaOptions {
    /// Spectral radius at infinite frequency, in [0, 1].
    pub rho_inf: f64,
    /// Fixed step size; `None`: error-controlled steps (`rtol`, `atol`, `first_step`,
    /// `max_step` of `Options`).
    pub step: Option<f64>,
    /// Newton iterations per attempt.
    pub max_newton: usize,
    /// Projection onto the constraints after each step (with the factorization of the step's
    /// final kernel call).
    pub projection: Option<ProjectionTolerance>,
    /// Let Newton stop, while it contracts fast, once its remaining position error is below
    /// this fraction of the last step's local error estimate `h^2 |beta - 1/6| |a_{n+1} - a_n|`
    /// (same norm) instead of the `rtol` level: a Newton error well below the discretization
    /// error changes nothing the step size does not decide (paper scene, nonlinear FFRF N = 4:
    /// 4.4 -> 2.3 iterations per step, errors against the geometrically exact reference
    /// unchanged to 0.01 % of the peak). The Newton error then scales with the local error, not
    /// with `rtol`: a convergence study at a tight `rtol` sees an order below 2 (double
    /// pendulum: 1.4-1.8 at 0.01-0.3). `None`: the `rtol` level only.
    pub newton_local_error: Option<f64>,
}

impl Default for GenAlphaOptions {
    fn default() -> Self {
        GenAlphaOptions { rho_inf: 0.9, step: None, max_newton: 8, projection: None, newton_local_error: None }
    }
}

/// Keep the factored iteration matrix for the next step while Newton contracts at least this
/// well with it (the stiff directions turn with the bodies, so it ages within a few steps).
const REUSE_CONTRACTION: f64 = 0.2;
/// Re-read the slowly varying velocity terms (`C`, `db/dqd`) of the iteration matrix when Newton
/// contracts worse than `REFRESH_CONTRACTION`, or at the latest after this many steps (a read
/// is a finite-difference pass costing ~12 UK calls; every 64 steps it took 5 % of a run).
const VELOCITY_TERMS_AGE: usize = 1024;
const REFRESH_CONTRACTION: f64 = 0.3;
/// Newton stops when the estimated remaining position error, in the error-test units of
/// `rtol`/`atol`, falls below this ...
const NEWTON_KAPPA: f64 = 0.1;
/// ... or, with `GenAlphaOptions::newton_local_error` and while Newton contracts at least as
/// fast as this, below that fraction of the last step's local error estimate (a slower
/// contraction keeps the strict tolerance: with one ratio measured, the estimate of the
/// remaining error is not trustworthy; an ANCF coupler at h = 2e-4 diverged without this guard).
const LOOSE_CONTRACTION: f64 = 0.1;

pub struct GenAlpha {
    opts: Options,
    go: GenAlphaOptions,
    atol: Vec<f64>,
    n: usize,
    m: usize,
    st: StepState,
    /// Method coefficients.
    alpha_m: f64,
    alpha_f: f64,
    beta: f64,
    gamma: f64,
    /// `qdd` and `a` at `t`, and their values at the start of the step.
    qdd: Vec<f64>,
    a: Vec<f64>,
    /// The step's start: `q_n`, `qd_n` (for the dense output and retries).
    q0: Vec<f64>,
    qd0: Vec<f64>,
    qdd_prev: Vec<f64>,
    a_prev: Vec<f64>,
    /// Newton unknown and trial state.
    x: Vec<f64>,
    a_new: Vec<f64>,
    q_new: Vec<f64>,
    qd_new: Vec<f64>,
    g: Vec<f64>,
    /// The residual `[-r1; -r2]` and the correction.
    res: Vec<f64>,
    rhs: Vec<f64>,
    /// Multipliers: the Newton unknown beside `qdd` (augmented iteration), and their value at
    /// the start of the step.
    lam: Vec<f64>,
    lam_prev: Vec<f64>,
    r2: Vec<f64>,
    /// The structure at the last refresh (`M`, `K`, `C`, `A`, `db/dqd`) and the factored
    /// iteration matrix, dense or sparse (`newton.rs`; made in `init`, when the system is known);
    /// the `h` it was built for.
    newton: Option<NewtonMatrices>,
    lu_h: f64,
    /// Re-read the velocity terms before the next attempt; steps since they were read.
    refresh: bool,
    age: usize,
    /// The factored matrix may serve the next step.
    reuse: bool,
    /// Refreshes of the structure (`njev`) and factorizations (`nlu`) are in `stats`.
    reject: bool,
    /// Local error estimate of the last accepted step (error-test units).
    err_prev: f64,
    /// Local error estimate of the last accepted step in the Newton norm: the scale of the
    /// looser Newton tolerance (`NEWTON_LOCAL_ERROR`).
    le_prev: f64,
}

impl GenAlpha {
    /// `n` coordinates, `m` constraint rows of the system to be integrated.
    pub fn new(n: usize, m: usize, opts: Options, go: GenAlphaOptions) -> Result<Self> {
        let atol = opts.validate(2 * n)?;
        if !(0.0..=1.0).contains(&go.rho_inf) {
            return Err(Error::argument("rho_inf", format!("must lie in [0, 1], got {}", go.rho_inf)));
        }
        if let Some(h) = go.step {
            if !(h > 0.0) || !h.is_finite() {
                return Err(Error::argument("step", format!("must be positive and finite, got {h}")));
            }
        }
        if let Some(k) = go.newton_local_error {
            if !(k >= 0.0) || !k.is_finite() {
                return Err(Error::argument("newton_local_error", format!("must be >= 0 and finite, got {k}")));
            }
        }
        if go.max_newton == 0 {
            return Err(Error::argument("max_newton", "must be at least 1"));
        }
        let r = go.rho_inf;
        let alpha_m = (2.0 * r - 1.0) / (r + 1.0);
        let alpha_f = r / (r + 1.0);
        let gamma = 0.5 - alpha_m + alpha_f;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        let z = |k: usize| vec![0.0; k];
        let nm = n + m;
        Ok(GenAlpha {
            opts,
            go,
            atol,
            n,
            m,
            st: StepState::new(2 * n),
            alpha_m,
            alpha_f,
            beta,
            gamma,
            qdd: z(n),
            a: z(n),
            q0: z(n),
            qd0: z(n),
            qdd_prev: z(n),
            a_prev: z(n),
            x: z(n),
            a_new: z(n),
            q_new: z(n),
            qd_new: z(n),
            g: z(n),
            res: z(nm),
            rhs: z(nm),
            lam: z(m),
            lam_prev: z(m),
            r2: z(m),
            newton: None,
            lu_h: 0.0,
            refresh: true,
            age: 0,
            reuse: false,
            reject: false,
            err_prev: 0.0,
            le_prev: 0.0,
        })
    }

    /// `(beta', gamma')` for step `h`.
    fn primes(&self, h: f64) -> (f64, f64) {
        let c = (1.0 - self.alpha_f) / (1.0 - self.alpha_m);
        (h * h * self.beta * c, h * self.gamma * c)
    }

    /// Re-read `M`, `K`, `C`, `A`, `db/dqd` at `(t, q, qd)`.
    fn read_structure<S: SecondOrderSystem>(&mut self, sys: &mut S, t: f64, at_iterate: bool) -> Result<()> {
        let n = self.n;
        let (q, qd) = if at_iterate { (&self.q_new[..], &self.qd_new[..]) } else { (&self.st.y[..n], &self.st.y[n..]) };
        if !self.newton.as_mut().expect("GENALPHA: init first").read(sys, t, q, qd)? {
            return Err(Error::argument("method", "GENALPHA needs a system with a structured Jacobian (mass, stiffness, constraints)"));
        }
        self.st.stats.njev += 1;
        Ok(())
    }

    /// Read `M`, `K`, `A` where the system's last residual evaluation left them and factor the
    /// iteration matrix for step `h`.
    fn refresh_matrix<S: SecondOrderSystem>(&mut self, sys: &mut S, h: f64) -> Result<()> {
        if !self.newton.as_mut().expect("GENALPHA: init first").read_stiff(sys, &self.q_new, &self.qd_new)? {
            return Err(Error::argument("method", "GENALPHA needs a system with a structured Jacobian (mass, stiffness, constraints)"));
        }
        self.factor(h, sys.conditioning_rank() < sys.n_constraints())
    }

    /// Assemble and factor `[M + gamma' C + beta' K, A^T; A - gamma' db/dqd, 0]` for step `h`;
    /// regularized at once when `deficient` (the UK solve's rank below m: the LU may keep a
    /// rounding pivot of the singular matrix, `RadauM::factor`).
    fn factor(&mut self, h: f64, deficient: bool) -> Result<()> {
        self.st.stats.nlu += 1;
        self.lu_h = h;
        let (bp, gp) = self.primes(h);
        let nw = self.newton.as_mut().expect("GENALPHA: init first");
        if !deficient && nw.factor_real(bp, gp, 0.0) {
            return Ok(());
        }
        // redundant constraint rows make the saddle-point matrix singular: regularize the
        // multiplier block (the correction dx is unaffected where A has full row rank)
        let scale = nw.mass_scale();
        self.st.stats.nlu += usize::from(!deficient);
        if !nw.factor_real(bp, gp, -1e-12 * scale) {
            return Err(Error::Solver(format!("GENALPHA: iteration matrix singular at t = {}", self.st.t)));
        }
        Ok(())
    }

    /// `rhs = (iteration matrix)^-1 res` (on a small dense matrix with its inverse from the
    /// third solve of a factorization on: `NewtonMatrices::solve_real_reusing`).
    fn solve_newton(&mut self) {
        self.newton.as_mut().expect("GENALPHA: init first").solve_real_reusing(&self.res, &mut self.rhs);
    }

    /// Positions and velocities of the step for the unknown `x = qdd_{n+1}`.
    fn trial(&mut self, h: f64) {
        let (am, af, b, g) = (self.alpha_m, self.alpha_f, self.beta, self.gamma);
        for i in 0..self.n {
            let a1 = ((1.0 - af) * self.x[i] + af * self.qdd_prev[i] - am * self.a_prev[i]) / (1.0 - am);
            self.a_new[i] = a1;
            self.q_new[i] = self.q0[i] + h * self.qd0[i] + h * h * ((0.5 - b) * self.a_prev[i] + b * a1);
            self.qd_new[i] = self.qd0[i] + h * ((1.0 - g) * self.a_prev[i] + g * a1);
        }
    }

    /// Weighted RMS of a Newton correction `v` with the weights `atol + rtol |q_{n+1} - q_n|`:
    /// relative to how far the step moves each coordinate (absolute coordinates, like an ANCF
    /// beam's, move little per step against their size, and their deformation is a tiny part
    /// of them: `rtol |q|` would accept Newton errors larger than the deformation).
    fn newton_norm(&self, v: &[f64]) -> f64 {
        let n = self.n;
        let mut s = 0.0;
        for i in 0..n {
            let w = self.atol[i] + self.opts.rtol * (self.q_new[i] - self.q0[i]).abs();
            s += (v[i] / w) * (v[i] / w);
        }
        (s / n as f64).sqrt()
    }

    /// Weighted RMS of `v` with the position weights `atol + rtol |q|`.
    fn position_norm(&self, v: &[f64]) -> f64 {
        let n = self.n;
        let mut s = 0.0;
        for i in 0..n {
            let w = self.atol[i] + self.opts.rtol * self.q0[i].abs().max(self.q_new[i].abs());
            s += (v[i] / w) * (v[i] / w);
        }
        (s / n as f64).sqrt()
    }

    /// One attempt of step `h` from the saved start: Newton on `qdd_{n+1}` (and the
    /// multipliers), starting from `qdd_n`, `lambda_n`.
    ///
    /// The iterations run on the acceleration-level equations `M qdd + A^T lambda = Q`,
    /// `A qdd = b` at the trial state (assembly only); their root is the UK acceleration. The
    /// converged iterate is then replaced by the UK acceleration itself, `qdd = g(q, qd)` (one UK
    /// evaluation per step: the accepted accelerations and multipliers are the UK solution, and
    /// the difference is the Newton error). The fast-varying part of the iteration matrix (`M`,
    /// `K`, `A`: the stiff directions turn with the bodies and the constraints) is read at the
    /// predicted state and factored once per attempt; `C` and `db/dqd` come from the last full
    /// refresh. `Ok(Some((k, theta)))`: converged after `k` iterations, last contraction
    /// `theta`; `Ok(None)`: no convergence.
    fn attempt<S: SecondOrderSystem>(&mut self, sys: &mut S, h: f64, tol: f64) -> Result<Option<(usize, f64)>> {
        let (n, m) = (self.n, self.m);
        let (bp, _) = self.primes(h);
        self.x.copy_from_slice(&self.qdd_prev);
        self.lam.copy_from_slice(&self.lam_prev);
        let t1 = self.st.t + h;
        let mut prev = f64::INFINITY;
        let mut theta = 0.0;
        let mut refreshed = false;
        let (am, af) = (self.alpha_m, self.alpha_f);
        let c_le = h * h * (self.beta - 1.0 / 6.0).abs();
        for k in 1..=self.go.max_newton {
            self.trial(h);
            let (r1, r2) = (&mut self.g, &mut self.r2);
            if !sys.augmented_residual(t1, &self.q_new, &self.qd_new, &self.x, &self.lam, r1, r2)? {
                return Err(Error::argument("method", "GENALPHA needs a system with the acceleration-level residual"));
            }
            self.st.stats.nfev += 1;
            if k == 1 && !(self.reuse && h == self.lu_h) {
                self.refresh_matrix(sys, h)?;
                refreshed = true;
            }
            for i in 0..n {
                self.res[i] = -self.g[i];
            }
            for r in 0..m {
                self.res[n + r] = -self.r2[r];
            }
            self.solve_newton();
            for i in 0..n {
                self.x[i] += self.rhs[i];
            }
            for r in 0..m {
                self.lam[r] += self.rhs[n + r];
            }
            // convergence on the position correction beta' dx
            for i in 0..n {
                self.g[i] = bp * self.rhs[i];
            }
            let d = self.newton_norm(&self.g);
            // the looser tolerance: a fraction of the last step's local error estimate
            let tol_le = tol.max(self.go.newton_local_error.unwrap_or(0.0) * self.le_prev);
            if !d.is_finite() {
                // remembered: if the step size then shrinks to nothing, the run ends naming it
                let (q, qd, qdd) = (&self.q_new, &self.qd_new, &self.x);
                self.st.nonfinite = [("q", q), ("qd", qd), ("qdd", qdd)]
                    .iter()
                    .find_map(|(w, v)| v.iter().position(|x| !x.is_finite()).map(|i| (*w, i)))
                    .or(Some(("qdd", 0)));
                return Ok(None);
            }
            let converged = if d <= 1e-3 * tol {
                true
            } else if prev.is_finite() {
                theta = d / prev;
                if theta > REUSE_CONTRACTION && !refreshed {
                    // the reused matrix is too old for this step: read it at the current iterate
                    self.refresh_matrix(sys, h)?;
                    refreshed = true;
                    prev = f64::INFINITY;
                    continue;
                }
                if theta >= 1.0 {
                    return Ok(None);
                }
                // a fast contraction makes the estimate of the remaining error trustworthy:
                // then the Newton error may be a fraction of the discretization error
                theta / (1.0 - theta) * d <= if theta <= LOOSE_CONTRACTION { tol_le } else { tol }
            } else {
                false
            };
            if converged {
                // the UK acceleration at the converged state (the accepted solution; the
                // difference is the Newton error), and the projection with its factorization
                self.trial(h);
                for i in 0..n {
                    let a1 = ((1.0 - af) * self.x[i] + af * self.qdd_prev[i] - am * self.a_prev[i]) / (1.0 - am);
                    self.g[i] = c_le * (a1 - self.a_prev[i]);
                }
                let le = self.newton_norm(&self.g);
                sys.acc_projected(t1, &mut self.q_new, &mut self.qd_new, &mut self.g, self.go.projection)?;
                self.st.stats.nfev += 1;
                // the UK acceleration replaces the iterate: in the stiff directions it amplifies
                // the Newton error by ~beta' omega^2, so its change, as a position change
                // beta' (g - x), must itself be within the tolerance, or Newton goes on
                if k < self.go.max_newton && tol_le > tol {
                    for i in 0..n {
                        self.rhs[i] = bp * (self.g[i] - self.x[i]);
                    }
                    if self.newton_norm(&self.rhs[..n]) > tol_le {
                        prev = d.max(f64::MIN_POSITIVE);
                        continue;
                    }
                }
                self.le_prev = le;
                sys.multipliers(&mut self.lam);
                for i in 0..n {
                    self.x[i] = self.g[i];
                    self.a_new[i] = ((1.0 - af) * self.g[i] + af * self.qdd_prev[i] - am * self.a_prev[i]) / (1.0 - am);
                }
                self.reuse = theta <= REUSE_CONTRACTION;
                return Ok(Some((k, theta)));
            }
            prev = d.max(f64::MIN_POSITIVE);
        }
        Ok(None)
    }
}

impl Stepper for GenAlpha {
    fn init<S: SecondOrderSystem>(&mut self, sys: &mut S, t0: f64, y0: &[f64], t_end: f64) -> Result<()> {
        let n = self.n;
        self.st.start(t0, y0);
        self.reject = false;
        self.le_prev = 0.0;
        let (q, qd) = y0.split_at(n);
        self.newton = Some(NewtonMatrices::for_system(sys, self.opts.linear_solver, false, true, "GENALPHA")?);
        sys.acc(t0, q, qd, &mut self.qdd)?;
        self.st.stats.nfev += 1;
        sys.multipliers(&mut self.lam);
        self.a.copy_from_slice(&self.qdd);
        self.q0.copy_from_slice(q);
        self.qd0.copy_from_slice(qd);
        self.read_structure(sys, t0, false)?;
        self.refresh = false;
        self.age = 0;
        let hmax = self.opts.max_step.min((t_end - t0).abs());
        self.st.h = match (self.go.step, self.opts.first_step) {
            (Some(h), _) => h,
            (None, Some(h)) => h.min(hmax),
            (None, None) => {
                // Hairer's estimate for an order-2 error estimate, on the first-order system
                initial_step_second_order(sys, t0, y0, &self.qdd, self.opts.rtol, &self.atol, 2, hmax, &mut self.st.stats.nfev)?
            }
        };
        self.factor(self.st.h, sys.conditioning_rank() < sys.n_constraints())?;
        Ok(())
    }

    fn step<S: SecondOrderSystem>(&mut self, sys: &mut S, t_end: f64) -> Result<()> {
        let n = self.n;
        let fixed = self.go.step.is_some();
        // the step's start
        self.q0.copy_from_slice(&self.st.y[..n]);
        self.qd0.copy_from_slice(&self.st.y[n..]);
        self.qdd_prev.copy_from_slice(&self.qdd);
        self.a_prev.copy_from_slice(&self.a);
        self.lam_prev.copy_from_slice(&self.lam);
        let mut fresh = false;
        loop {
            self.st.check_attempt("GENALPHA", &self.opts)?;
            let mut h = self.st.h;
            let last = self.st.t + 1.01 * h >= t_end;
            if last {
                h = t_end - self.st.t;
            }
            if self.refresh || self.age >= VELOCITY_TERMS_AGE {
                let t = self.st.t;
                self.read_structure(sys, t, false)?;
                self.refresh = false;
                self.age = 0;
                fresh = true;
            }
            let tol = NEWTON_KAPPA;
            let result = self.attempt(sys, h, tol)?;
            let Some((iters, theta)) = result else {
                // Newton failed: fresh velocity terms first, then a smaller step
                if !fresh {
                    self.refresh = true;
                    continue;
                }
                if fixed && h < 1e-3 * self.go.step.expect("fixed") {
                    return Err(Error::Solver(format!("GENALPHA: Newton did not converge at t = {} even with h = {h:e} (1/1000 of the fixed step)", self.st.t)));
                }
                // a shorter step (with a fixed step size, the next step returns to it)
                self.st.h = 0.5 * h;
                self.reject = true;
                if self.st.stats.naccept >= 1 {
                    self.st.stats.nreject += 1;
                }
                continue;
            };
            self.st.stats.newton += iters;
            // local error estimate of the positions
            let c = h * h * (self.beta - 1.0 / 6.0).abs();
            for i in 0..n {
                self.g[i] = c * (self.a_new[i] - self.a_prev[i]);
            }
            let err = self.position_norm(&self.g).max(1e-10);
            let mut hnew = h;
            if !fixed {
                if err > 1.0 {
                    let fac = (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 1.0);
                    hnew = (h * fac).min(self.opts.max_step);
                    self.st.h = hnew;
                    self.reject = true;
                    if self.st.stats.naccept >= 1 {
                        self.st.stats.nreject += 1;
                    }
                    continue;
                }
                // PI control (Gustafsson) of an O(h^3) estimate: smoother step sequences, fewer
                // rejections; a dead band keeps h (and the factored matrix) for small changes
                let fac = if self.err_prev > 0.0 {
                    0.9 * err.powf(-0.7 / 3.0) * self.err_prev.powf(0.4 / 3.0)
                } else {
                    0.9 * err.powf(-1.0 / 3.0)
                }
                .clamp(0.2, 2.0);
                hnew = if (1.0..=1.2).contains(&fac) { h } else { (h * fac).min(self.opts.max_step) };
                if self.reject {
                    hnew = hnew.min(h);
                }
            }
            // accept
            self.err_prev = err;
            self.reject = false;
            self.st.stats.naccept += 1;
            self.st.nonfinite = None;
            self.st.t_old = self.st.t;
            self.st.t = if last { t_end } else { self.st.t + h };
            self.st.y[..n].copy_from_slice(&self.q_new);
            self.st.y[n..].copy_from_slice(&self.qd_new);
            self.qdd.copy_from_slice(&self.x);
            self.a.copy_from_slice(&self.a_new);
            if fixed {
                // keep the fixed step (the last one may have been shortened to hit t_end)
                self.st.h = self.go.step.expect("fixed");
            } else {
                self.st.h = hnew;
            }
            self.age += 1;
            if iters > 2 && theta > REFRESH_CONTRACTION {
                self.refresh = true;
            }
            return Ok(());
        }
    }

    fn dense_parts(&self) -> DenseParts<'_> {
        DenseParts { meta: [self.st.t_old, self.st.t, 0.0], parts: [&self.q0, &self.qd0, &self.st.y, &[], &[]], count: 3 }
    }
    /// Cubic Hermite interpolation of `q` from `q`, `qd` at both ends of the step (error
    /// O(h^4) in `q`, O(h^3) in `qd`: above the method's own order 2), `qd` from its derivative.
    fn dense_eval(meta: [f64; 3], parts: &[&[f64]], t: f64, out: &mut [f64]) {
        let n = out.len() / 2;
        let [t0, t1, _] = meta;
        let (q0, qd0, y) = (parts[0], parts[1], parts[2]);
        let h = t1 - t0;
        if h == 0.0 {
            out.copy_from_slice(y);
            return;
        }
        let s = (t - t0) / h;
        // cubic Hermite of q with slopes qd; qd from its derivative
        let (h00, h10, h01, h11) = (2.0 * s * s * s - 3.0 * s * s + 1.0, s * s * s - 2.0 * s * s + s, -2.0 * s * s * s + 3.0 * s * s, s * s * s - s * s);
        let (d00, d10, d01, d11) = (6.0 * s * s - 6.0 * s, 3.0 * s * s - 4.0 * s + 1.0, -6.0 * s * s + 6.0 * s, 3.0 * s * s - 2.0 * s);
        let (q1, qd1) = y.split_at(n);
        for i in 0..n {
            let (p0, v0, p1, v1) = (q0[i], qd0[i], q1[i], qd1[i]);
            out[i] = h00 * p0 + h10 * h * v0 + h01 * p1 + h11 * h * v1;
            out[n + i] = (d00 * p0 + d01 * p1) / h + d10 * v0 + d11 * v1;
        }
    }

    /// `q0`, `qd0` (n each) and the state `y` (2n).
    fn dense_dim(part_len: &[usize]) -> Option<usize> {
        match *part_len {
            [n, m, y] if n == m && n.checked_mul(2) == Some(y) => Some(y),
            _ => None,
        }
    }

    fn restart_at<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<()> {
        acc_and_multipliers(sys, &mut self.st, &mut self.qdd, &mut self.lam)
    }

    fn expected_steps(&self, t0: f64, t_end: f64) -> Option<usize> {
        fixed_step_count(t0, t_end, self.go.step)
    }

    fn state(&self) -> &StepState {
        &self.st
    }
    fn state_mut(&mut self) -> &mut StepState {
        &mut self.st
    }
    fn options(&self) -> &Options {
        &self.opts
    }
}
