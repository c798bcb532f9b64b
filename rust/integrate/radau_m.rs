//! 3-stage Radau IIA (order 5, L-stable) on the constrained second-order equations
//! `M qdd + A^T lambda = Q(t, q, qd)`, `A qdd = b(t, q, qd)`, whose solution is the UK
//! acceleration: `RADAU5M`. The accuracy of `RADAU5` on the resolved (bending) modes, the
//! damping of the unresolved (axial, short-element) ones, at the per-iteration cost of
//! `GENALPHA`: the same structured iteration matrix, the same acceleration-level residual, the
//! same final UK evaluation and projection.
//!
//! **Stages.** With the Radau IIA matrix `a` (3 x 3, `c = ((4 - sqrt 6)/10, (4 + sqrt 6)/10, 1)`)
//! applied to `(q, qd)`, the stage accelerations `W_j` are the unknowns:
//! `V_i = qd_n + h sum_j a_ij W_j`, `Q_i = q_n + h c_i qd_n + h^2 sum_j (a^2)_ij W_j`, and each
//! stage satisfies the acceleration-level equations at `(t_n + c_i h, Q_i, V_i)` with its own
//! multipliers `Lambda_i`. The step ends at the last stage: `q_{n+1} = Q_3`, `qd_{n+1} = V_3`
//! (stiffly accurate), and its acceleration and multipliers are the UK solution there (one UK
//! evaluation per step, whose factorization also projects `q`, `qd` onto the constraints when
//! they drifted beyond the projection tolerance).
//!
//! **Newton.** Simplified Newton on all stages with one structure `M`, `K = -dQ/dq`,
//! `C = -dQ/dqd`, `A`, `db/dqd`. Its matrix is the sum of `I (x) [M, A^T; A, 0]`,
//! `h a (x) [C, 0; -db/dqd, 0]` and `h^2 a^2 (x) [K, 0; 0, 0]`. Hairer's transformation
//! `T^-1 a T` (block diagonal: one real eigenvalue `lambda`, one complex pair `mu`) decouples it
//! into `[M + h lambda C + h^2 lambda^2 K, A^T; A - h lambda db/dqd, 0]` (real) and the same
//! with `mu` (complex), each `(n+m)` square: GENALPHA's matrix with `(beta', gamma') =
//! (h^2 lambda^2, h lambda)`. `M`, `K`, `A` are read where the first residual evaluation of a
//! step left them (the last stage, the step's end), with the force elements' analytic damping
//! in `C` (`Force::add_damping`); the rest of `C` and `db/dqd` (a finite-difference pass) when
//! Newton fails, after an error-controlled step whose Newton contracted worse than
//! `REFRESH_CONTRACTION`, or after `VELOCITY_TERMS_AGE` steps. Starting values: the last
//! step's stage accelerations extrapolated (their quadratic in time). Stopping rule and
//! step-size control are Hairer's (`RADAU5`: `fnewt`, the contraction estimate, Gustafsson's
//! predictive control). The Newton norm takes the position corrections and the velocity
//! corrections times `h` (the position error they make within a step; velocity errors left by
//! Newton would add up over the steps: a double pendulum at fixed steps lost its fifth order
//! without them), weighted by `atol + rtol |q_{n+1} - q_n|` as in GENALPHA (with `rtol |q|` an
//! ANCF coupler's Newton error grew to its deformation's size: N = 8, peak 0.03 -> 0.13 %).
//!
//! **Error estimate.** Hairer's embedded estimate filtered by the real iteration matrix,
//! `(fac1 I - J)^-1 (f_n + sum_i d_i Z_i / h)`, in second-order form: with `e_q`, `e_v` the
//! position and velocity parts of the bracket, `x_q` solves the real iteration system (factored
//! already) with the right-hand side
//! `[h^2 lambda^2 (M e_v + C e_q) + h lambda M e_q; A (h^2 lambda^2 e_v + h lambda e_q)]`, and
//! `x_v = x_q / (h lambda) - e_q`. The test is on both, with the weights of solve_ivp
//! (`atol + rtol max(|y_n|, |y_{n+1}|)`), its rtol and atol transformed so that the achieved
//! (global) error is about the user's rtol (`error_test_rtol`). It was on `x_q` alone with
//! RADAU5's internal tolerances `0.1 rtol^(2/3)` (a mass on a 1e4 rad/s spring 3.7e-3 off in
//! units of its scale at rtol 1e-9), then on both with the user's tolerances as given (2-210 x
//! rtol); now 0.3-9 x rtol from rtol 1e-3 to 1e-9 (docs/integrators.md).
//!
//! **Dense output.** The quintic Hermite interpolant of `q` from `q`, `qd`, `qdd` at both ends
//! (error O(h^6)); `qd` its derivative.

mod corotate;
mod iteration;

use super::newton::NewtonMatrices;
// Hairer's Newton iterations per attempt and step-size control constants, as RADAU5 has them
use super::radau5::{rc, FACL, FACR, NIT, QUOT1, QUOT2, SAFE};
use super::{acc_and_multipliers, fixed_step_count, initial_step_second_order, weigh_error, DenseParts, Options, SecondOrderSystem, StepState, Stepper};
use crate::band_lu::C64;
use crate::correct::ProjectionTolerance;
use crate::error::{Error, Result};

/// Settings of `RADAU5M`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RadauMOptions {
    /// Fixed step size; `None`: error-controlled steps.
    pub step: Option<f64>,
    /// Projection onto the constraints after each step (with the final UK evaluation's
    /// factorization).
    pub projection: Option<ProjectionTolerance>,
}

/// Keep the factored matrices for the next step when Newton contracted at least this well and
/// the step size did not change.
const REUSE_CONTRACTION: f64 = 0.1;
/// With error control, read the velocity terms again (by differences) after a step whose Newton
/// contracted worse than this. The dampers' share of `C` is analytic and follows every
/// factorization (`SecondOrderSystem::stiff_structure`); what is left to the differences (the
/// inertial velocity terms, `db/dqd`) turns slowly. On A05 at rtol 1e-3 (adaptive, 2 s): at 0.1,
/// 78 difference passes in 100 steps (25 ms CPU); at 0.3, 36 in 99 (18 ms); never, 3 in 106 with
/// 27 rejected (14 ms).
const REFRESH_CONTRACTION: f64 = 0.3;
/// With a fixed step: steps taken at a reduced size (after a Newton failure) before the size
/// doubles back towards the fixed one (doubled after each doubling that fails).
const FIXED_STEP_PATIENCE: usize = 8;
/// Re-read the velocity terms (`C`, `db/dqd`) at the latest after this many steps (and after a
/// failed Newton iteration, or with error control after a step whose Newton contracted worse
/// than `REFRESH_CONTRACTION`): as in GENALPHA.
const VELOCITY_TERMS_AGE: usize = 1024;

pub struct RadauM {
    opts: Options,
    ro: RadauMOptions,
    n: usize,
    m: usize,
    st: StepState,
    /// The tolerances (the user's, as solve_ivp means them; `atol`: 2n entries) and Newton's
    /// (RADAU5's internal ones, `0.1 rtol^(2/3)`, 2n entries).
    rtol: f64,
    newton_rtol: f64,
    newton_atol: Vec<f64>,
    atol: Vec<f64>,
    fnewt: f64,
    /// Radau IIA matrix, its square, nodes; the transformation `T`, `T^-1` and the eigenvalues
    /// of `a`: `lambda` (real), `mu = mu_re + i mu_im`.
    a: [[f64; 3]; 3],
    a2: [[f64; 3]; 3],
    c: [f64; 3],
    t: [[f64; 3]; 3],
    ti: [[f64; 3]; 3],
    lambda: f64,
    mu: (f64, f64),
    /// Acceleration and multipliers at `t` (the UK solution), and the step's start.
    qdd: Vec<f64>,
    lam: Vec<f64>,
    q0: Vec<f64>,
    v0: Vec<f64>,
    a0: Vec<f64>,
    /// The accepted step's position increment `q1 - q0`, summed from its terms (not the
    /// difference of the rounded ends: the dense output's velocity divides it by `h`).
    dq: Vec<f64>,
    /// Stage accelerations and multipliers (Newton unknowns), those of the last accepted step
    /// (for the starting values) and its step size.
    w: [Vec<f64>; 3],
    ls: [Vec<f64>; 3],
    w_old: [Vec<f64>; 3],
    ls_old: [Vec<f64>; 3],
    h_old: f64,
    have_old: bool,
    /// Stage states and residuals ((n+m) each; the error estimate's scratch `r1`, n).
    qs: [Vec<f64>; 3],
    vs: [Vec<f64>; 3],
    res: [Vec<f64>; 3],
    r1: Vec<f64>,
    /// Transformed right-hand sides / solutions: real, complex (re, im); (n+m) each.
    xr: Vec<f64>,
    xc: Vec<f64>,
    xi: Vec<f64>,
    tmp: Vec<f64>,
    eq: Vec<f64>,
    ev: Vec<f64>,
    /// Newton's corrections of the stages ((n+m) each) and the co-rotation of the matrices
    /// (`radau_m/corotate.rs`: a beam's nodes, a mechanism spinning about gravity's axis).
    dw: [Vec<f64>; 3],
    corot: corotate::Corotation,
    /// The structure (`M`, `K`, `C`, `A`, `db/dqd`) and the real and complex iteration
    /// matrices, dense or sparse (`newton.rs`; made in `init`, when the system is known).
    newton: Option<NewtonMatrices>,
    lu_h: f64,
    reuse: bool,
    refresh: bool,
    age: usize,
    /// Step control state (Hairer).
    faccon: f64,
    theta: f64,
    theta_v: f64, // the velocity corrections' last measured contraction (`iteration`)
    hacc: f64,
    erracc: f64,
    first: bool,
    reject: bool,
    /// The best conditioning of the constraints over the run's steps (`normal_weight`).
    kappa_ref: f64,
    /// Fixed step: steps taken below it since the last change of size, the steps to wait
    /// before doubling back, and whether the last change was a doubling.
    short_steps: usize,
    patience: usize,
    doubled: bool,
    /// Fixed step: the times a step ends at (the loads' kinks and jumps, `integrate::switches`).
    stops: Vec<f64>,
}

/// 3 x 3 matrix product.
fn mul3(x: &[[f64; 3]; 3], y: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut z = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            z[i][j] = (0..3).map(|k| x[i][k] * y[k][j]).sum();
        }
    }
    z
}

/// The error test's relative tolerance for the user's `rtol`: `TOL_SCALE rtol^TOL_POWER`, not
/// below `min(rtol, TOL_FLOOR)` (`atol` scales with it). The local test at the user's rtol left
/// global errors of 2-210 rtol (a 1e4 rad/s spring 21 at rtol 1e-3, Simeon's crank 150, the
/// paper's scene 73; falling as rtol^1.15); transformed, the achieved error is 0.3-9 rtol from
/// rtol 1e-3 to 1e-9 on the three (benches/radau5m_rtol.py), at about twice the steps. Below
/// `TOL_FLOOR` the step size collapses on stiff scenes before the test is met: the double
/// precision floor of these problems (~1e-9 relative), which the transformation cannot move.
pub fn error_test_rtol(rtol: f64) -> f64 {
    (TOL_SCALE * rtol.powf(TOL_POWER)).max(rtol.min(TOL_FLOOR))
}
const TOL_SCALE: f64 = 0.01;
const TOL_POWER: f64 = 0.87;
const TOL_FLOOR: f64 = 1e-10;

impl RadauM {
    /// `n` coordinates, `m` constraint rows.
    pub fn new(n: usize, m: usize, opts: Options, ro: RadauMOptions) -> Result<Self> {
        let atol_user = opts.validate(2 * n)?;
        if let Some(h) = ro.step {
            if !(h > 0.0) || !h.is_finite() {
                return Err(Error::argument("step", format!("must be positive and finite, got {h}")));
            }
        }
        // the error test: the user's rtol and atol transformed for tolerance proportionality
        // (`error_test_rtol`); Newton: RADAU5's internal tolerances `0.1 rtol^(2/3)` (its
        // stopping rule is calibrated on them; with a fixed step rtol sets only these)
        let rtol = error_test_rtol(opts.rtol);
        let newton_rtol = 0.1 * opts.rtol.powf(2.0 / 3.0);
        let newton_atol: Vec<f64> = atol_user.iter().map(|a| newton_rtol * a / opts.rtol).collect();
        let atol: Vec<f64> = atol_user.iter().map(|a| a * rtol / opts.rtol).collect();
        let fnewt = (10.0 * f64::EPSILON / newton_rtol).max(0.03f64.min(newton_rtol.sqrt()));
        let s6 = 6f64.sqrt();
        let a = [
            [(88.0 - 7.0 * s6) / 360.0, (296.0 - 169.0 * s6) / 1800.0, (-2.0 + 3.0 * s6) / 225.0],
            [(296.0 + 169.0 * s6) / 1800.0, (88.0 + 7.0 * s6) / 360.0, (-2.0 - 3.0 * s6) / 225.0],
            [(16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0],
        ];
        let a2 = mul3(&a, &a);
        let t = [[rc::T11, rc::T12, rc::T13], [rc::T21, rc::T22, rc::T23], [rc::T31, 1.0, 0.0]];
        let ti = [[rc::TI11, rc::TI12, rc::TI13], [rc::TI21, rc::TI22, rc::TI23], [rc::TI31, rc::TI32, rc::TI33]];
        // T^-1 a T = [[lambda, 0, 0], [0, p, -q], [0, q, p]]: read off, not assumed
        let d = mul3(&ti, &mul3(&a, &t));
        let lambda = d[0][0];
        let mu = (d[1][1], d[2][1]);
        let z = |k: usize| vec![0.0; k];
        let nm = n + m;
        let z3 = |k: usize| [z(k), z(k), z(k)];
        Ok(RadauM {
            opts,
            ro,
            n,
            m,
            st: StepState::new(2 * n),
            rtol,
            newton_rtol,
            newton_atol,
            atol,
            fnewt,
            a,
            a2,
            c: [rc::C1, rc::C2, 1.0],
            t,
            ti,
            lambda,
            mu,
            qdd: z(n),
            lam: z(m),
            q0: z(n),
            v0: z(n),
            a0: z(n),
            dq: z(n),
            w: z3(n),
            ls: z3(m),
            w_old: z3(n),
            ls_old: z3(m),
            h_old: 0.0,
            have_old: false,
            qs: z3(n),
            vs: z3(n),
            res: z3(nm),
            r1: z(n),
            xr: z(nm),
            xc: z(nm),
            xi: z(nm),
            tmp: z(nm),
            eq: z(n),
            ev: z(n),
            dw: z3(nm),
            corot: corotate::Corotation::new(Default::default(), &a2),
            newton: None,
            lu_h: 0.0,
            reuse: false,
            refresh: true,
            age: 0,
            faccon: 1.0,
            theta: 1.0,
            theta_v: 1.0,
            hacc: 0.0,
            erracc: 0.0,
            first: true,
            reject: false,
            kappa_ref: 0.0,
            short_steps: 0,
            patience: FIXED_STEP_PATIENCE,
            doubled: false,
            stops: Vec::new(),
        })
    }

    /// With a fixed step, end a step at each of `stops` it would straddle (a load's kink inside
    /// a step costs the collocation its order: `integrate::switches`).
    pub fn with_stops(mut self, stops: Vec<f64>) -> Self {
        self.stops = stops;
        self
    }

    /// Re-read `M`, `K`, `C`, `A`, `db/dqd` at the step's start.
    fn read_structure<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<()> {
        let t = self.st.t;
        let (q, qd) = self.st.y.split_at(self.n);
        if !self.newton.as_mut().expect("RADAU5M: init first").read(sys, t, q, qd)? {
            return Err(Error::argument("method", "RADAU5M needs a system with a structured Jacobian (mass, stiffness, constraints)"));
        }
        self.st.stats.njev += 1;
        self.refresh = false;
        self.age = 0;
        Ok(())
    }

    /// `M`, `K`, `A` where the last residual evaluation left them, and both factorizations for `h`.
    fn refresh_matrices<S: SecondOrderSystem>(&mut self, sys: &mut S, h: f64) -> Result<()> {
        let (q, qd) = (&self.qs[2], &self.vs[2]);
        if !self.newton.as_mut().expect("RADAU5M: init first").read_stiff(sys, q, qd)? {
            return Err(Error::argument("method", "RADAU5M needs a system with a structured Jacobian (mass, stiffness, constraints)"));
        }
        self.corot.set_reference(&self.qs[2]);
        // the UK solve's rank at the last step's end: redundant rows (rank below m) make the
        // saddle-point matrices singular
        let deficient = sys.conditioning_rank() < self.m;
        self.factor(h, deficient)
    }

    /// Assemble and factor the real and the complex iteration matrices for step `h`:
    /// `[M + g C + g^2 K, A^T; A - g Bv, reg I]` with `g = h lambda` and `g = h mu`: `reg = 0`
    /// first, unless `deficient` (the UK solve found redundant rows): then regularized at once.
    /// A singular matrix is not always refused by the LU: rounding leaves pivots of 1e-33 to
    /// 1e-26 of their column's scale where an exact elimination gives zero (the continuous-beam
    /// lattice, docs/integrators.md "Redundant constraints"), and Newton diverges on them.
    fn factor(&mut self, h: f64, deficient: bool) -> Result<()> {
        self.lu_h = h;
        self.st.stats.nlu += 2;
        let nw = self.newton.as_mut().expect("RADAU5M: init first");
        let scale = nw.mass_scale();
        let g = h * self.lambda;
        let (p, q) = (h * self.mu.0, h * self.mu.1);
        let (g2r, gr, gi) = (p * p - q * q, p, q);
        let g2i = 2.0 * gr * gi;
        let regs = [0.0, -1e-12 * scale];
        for &reg in &regs[usize::from(deficient)..] {
            if nw.factor_real(g * g, g, reg) && nw.factor_complex(C64::new(g2r, g2i), C64::new(gr, gi), reg) {
                return Ok(());
            }
            // redundant constraint rows make the saddle-point matrices singular: regularize
            // the multiplier block (the corrections are unaffected where A has full row rank)
            self.st.stats.nlu += 2;
        }
        Err(Error::Solver(format!("RADAU5M: iteration matrix singular at t = {}", self.st.t)))
    }

    /// Stage states from the stage accelerations.
    fn stages(&mut self, h: f64) {
        let n = self.n;
        for i in 0..3 {
            let (ci, ai, a2i) = (self.c[i], self.a[i], self.a2[i]);
            let (qs, vs) = (&mut self.qs[i], &mut self.vs[i]);
            for k in 0..n {
                let (w0, w1, w2) = (self.w[0][k], self.w[1][k], self.w[2][k]);
                vs[k] = self.v0[k] + h * (ai[0] * w0 + ai[1] * w1 + ai[2] * w2);
                qs[k] = self.q0[k] + h * ci * self.v0[k] + h * h * (a2i[0] * w0 + a2i[1] * w1 + a2i[2] * w2);
            }
        }
    }

    /// Weights of the error test: `atol + rtol max(|q_n|, |q_{n+1}|)`.
    fn scal(&self, i: usize) -> f64 {
        self.atol[i] + self.rtol * self.q0[i].abs().max(self.qs[2][i].abs())
    }

    /// Weights of the Newton norm: `atol + rtol |q_{n+1} - q_n|`, relative to how far the step
    /// moves each coordinate (as GENALPHA's): an ANCF beam's absolute coordinates move little
    /// per step against their size, and their deformation is a tiny part of them, so `rtol |q|`
    /// would let Newton errors of the size of the deformation through.
    fn newton_scal(&self, i: usize) -> f64 {
        self.newton_atol[i] + self.newton_rtol * (self.qs[2][i] - self.q0[i]).abs()
    }


    /// Starting values: the last step's stage accelerations and multipliers extrapolated
    /// (quadratic through its three stages) to this step's stage times; on the first step (or
    /// after a restart) the acceleration and multipliers at `t`.
    fn predict(&mut self, h: f64) {
        if !self.have_old {
            for i in 0..3 {
                self.w[i].copy_from_slice(&self.qdd);
                self.ls[i].copy_from_slice(&self.lam);
            }
            return;
        }
        // old stage times relative to t: (c_j - 1) h_old; new ones: c_i h
        let s: [f64; 3] = [(self.c[0] - 1.0) * self.h_old, (self.c[1] - 1.0) * self.h_old, 0.0];
        for i in 0..3 {
            let x = self.c[i] * h;
            let l = [
                (x - s[1]) * (x - s[2]) / ((s[0] - s[1]) * (s[0] - s[2])),
                (x - s[0]) * (x - s[2]) / ((s[1] - s[0]) * (s[1] - s[2])),
                (x - s[0]) * (x - s[1]) / ((s[2] - s[0]) * (s[2] - s[1])),
            ];
            for k in 0..self.n {
                self.w[i][k] = l[0] * self.w_old[0][k] + l[1] * self.w_old[1][k] + l[2] * self.w_old[2][k];
            }
            for k in 0..self.m {
                self.ls[i][k] = l[0] * self.ls_old[0][k] + l[1] * self.ls_old[1][k] + l[2] * self.ls_old[2][k];
            }
        }
    }

}

impl Stepper for RadauM {
    fn init<S: SecondOrderSystem>(&mut self, sys: &mut S, t0: f64, y0: &[f64], t_end: f64) -> Result<()> {
        let n = self.n;
        self.st.start(t0, y0);
        self.first = true;
        self.reject = false;
        self.have_old = false;
        self.reuse = false;
        self.faccon = 1.0;
        self.theta = 1.0;
        let (q, qd) = y0.split_at(n);
        self.newton = Some(NewtonMatrices::for_system(sys, self.opts.linear_solver, true, false, "RADAU5M")?);
        self.corot = corotate::Corotation::new(sys.corotated_bodies(), &self.a2);
        sys.acc(t0, q, qd, &mut self.qdd)?;
        self.st.stats.nfev += 1;
        sys.multipliers(&mut self.lam);
        self.kappa_ref = sys.conditioning_ratio();
        self.read_structure(sys)?;
        let hmax = self.opts.max_step.min((t_end - t0).abs());
        self.st.h = match (self.ro.step, self.opts.first_step) {
            (Some(h), _) => h,
            (None, Some(h)) => h.min(hmax),
            (None, None) => {
                let atol = self.opts.validate(2 * n)?;
                initial_step_second_order(sys, t0, y0, &self.qdd, self.opts.rtol, &atol, 3, hmax, &mut self.st.stats.nfev)?
            }
        };
        Ok(())
    }

    fn step<S: SecondOrderSystem>(&mut self, sys: &mut S, t_end: f64) -> Result<()> {
        let n = self.n;
        let fixed = self.ro.step.is_some();
        self.q0.copy_from_slice(&self.st.y[..n]);
        self.v0.copy_from_slice(&self.st.y[n..]);
        self.a0.copy_from_slice(&self.qdd);
        let cfac = SAFE * (1.0 + 2.0 * NIT as f64);
        let mut fresh = false;
        loop {
            self.st.check_attempt("RADAU5M", &self.opts)?;
            let (h_try, mut h) = (self.st.h, self.st.h);
            let last = self.st.t + 1.01 * h >= t_end;
            if last {
                h = t_end - self.st.t;
            }
            // a fixed step ends at the next stop it would straddle (and takes up its size after)
            let next = self.stops.iter().find(|&&s| s > self.st.t + 1e-9 * h_try).copied();
            let clipped = fixed && !last && next.is_some_and(|s| self.st.t + h > s);
            if clipped {
                h = next.expect("clipped") - self.st.t;
            }
            if self.refresh || self.age >= VELOCITY_TERMS_AGE {
                self.read_structure(sys)?;
                self.reuse = false;
                fresh = true;
            }
            self.predict(h);
            let Some(newt) = self.newton(sys, h)? else {
                // Newton failed: fresh velocity terms at the same step first, then a smaller step
                self.reuse = false;
                if !fresh {
                    self.refresh = true;
                    self.st.h = h;
                    continue;
                }
                if fixed {
                    if h < 1e-3 * self.ro.step.expect("fixed") {
                        return Err(Error::Solver(format!("RADAU5M: Newton did not converge at t = {} even with h = {h:e} (1/1000 of the fixed step)", self.st.t)));
                    }
                    self.st.h = 0.5 * h;
                    if self.doubled {
                        // the step it doubled back to failed: wait twice as long next time
                        self.doubled = false;
                        self.patience = (2 * self.patience).min(1 << 16);
                    }
                    self.short_steps = 0;
                } else {
                    self.st.h = self.st.h.min(0.5 * h);
                }
                self.reject = true;
                if self.st.stats.naccept >= 1 {
                    self.st.stats.nreject += 1;
                }
                continue;
            };
            // the UK evaluation at the step's end first: with a projection its factorization
            // filters the error estimate onto the constraints' tangent space (see DOPRI5), and on
            // acceptance it is the step's final acceleration
            let t1 = if last { t_end } else { self.st.t + h };
            let project = self.ro.projection.is_some() && self.m > 0;
            let mut kappa = 1.0;
            if project {
                sys.acc(t1, &self.qs[2], &self.vs[2], &mut self.qdd)?;
                self.st.stats.nfev += 1;
                sys.multipliers(&mut self.lam);
                kappa = sys.conditioning_ratio();
            }
            let err = if fixed { 0.0 } else { self.error_estimate(sys, h, project)? };
            let fac = SAFE.min(cfac / (newt + 2 * NIT) as f64);
            let mut quot = FACR.max(FACL.min(err.powf(0.25) / fac));
            let mut hnew = h / quot;
            if err >= 1.0 {
                // rejected
                self.reject = true;
                if self.first {
                    self.st.h = 0.1 * h;
                } else {
                    self.st.h = hnew;
                }
                if self.st.stats.naccept >= 1 {
                    self.st.stats.nreject += 1;
                }
                // keep the factorization only if h comes back to it
                continue;
            }
            // accepted: the projection with the factorization of the final UK evaluation
            self.first = false;
            self.kappa_ref = self.kappa_ref.max(kappa);
            let (mut q1, mut v1) = (std::mem::take(&mut self.qs[2]), std::mem::take(&mut self.vs[2]));
            let a2e = self.a2[2];
            for k in 0..n {
                self.dq[k] = h * self.c[2] * self.v0[k] + h * h * (a2e[0] * self.w[0][k] + a2e[1] * self.w[1][k] + a2e[2] * self.w[2][k]);
            }
            let r = match self.ro.projection {
                Some(tol) if project => sys.project_step(t1, &mut q1, &mut v1, tol).map(|_| ()),
                _ => {
                    self.st.stats.nfev += 1;
                    sys.acc(t1, &q1, &v1, &mut self.qdd).map(|_| sys.multipliers(&mut self.lam))
                }
            };
            for k in 0..n {
                // a projection's move (beyond the rounding of the sum) is part of the increment
                let moved = q1[k] - (self.q0[k] + self.dq[k]);
                if moved.abs() > 4.0 * f64::EPSILON * q1[k].abs() {
                    self.dq[k] += moved;
                }
            }
            self.st.y[..n].copy_from_slice(&q1);
            self.st.y[n..].copy_from_slice(&v1);
            self.qs[2] = q1;
            self.vs[2] = v1;
            r?;
            self.st.stats.naccept += 1;
            self.st.nonfinite = None;
            self.st.t_old = self.st.t;
            self.st.t = t1;
            for i in 0..3 {
                std::mem::swap(&mut self.w[i], &mut self.w_old[i]);
                std::mem::swap(&mut self.ls[i], &mut self.ls_old[i]);
            }
            self.h_old = h;
            self.have_old = true;
            self.age += 1;
            // error-controlled steps: a Newton that contracted worse than REFRESH_CONTRACTION ran
            // on stale velocity terms; read them at the next step instead of waiting for a
            // failure (A05's dampers turn with the governor: read only on failures, their
            // directions went stale within ~0.03 s, Newton failed 105 times in 574 steps at rtol
            // 1e-3 and the steps hardly followed rtol; docs/spatial.md). A Newton that converged
            // at its first iteration measured no contraction (`theta` is an older step's, or the
            // start's 1.0): the matrices served, nothing to read (A05's first 14 steps, the
            // growth out of its stiff start, read them at every step: 14 of 36 passes)
            if !fixed && newt > 1 && self.theta > REFRESH_CONTRACTION {
                self.refresh = true;
            }
            if fixed && clipped {
                self.st.h = h_try;
                self.reuse = false;
                return Ok(());
            }
            if fixed {
                // a step that Newton could not take at the fixed size is kept at the size it
                // took for `patience` steps before it doubles back; a doubling that fails again
                // doubles the patience (an ANCF cable spinning fast: its stiff axial directions
                // turn between the stages, and the step Newton can take shrinks like
                // (omega_axial^2 omega_spin)^(-1/3): it retried the full step after every failure
                // on 70 % of its attempts, then every 8 steps on 11 %)
                let full = self.ro.step.expect("fixed");
                if !last {
                    if self.doubled {
                        // the step it doubled back to held: back to the first patience
                        self.doubled = false;
                        self.patience = FIXED_STEP_PATIENCE;
                    }
                    if h < full * (1.0 - 1e-12) {
                        self.short_steps += 1;
                        if self.short_steps >= self.patience {
                            self.short_steps = 0;
                            self.doubled = true;
                            self.st.h = (2.0 * h).min(full);
                        } else {
                            self.st.h = h;
                        }
                    } else {
                        self.short_steps = 0;
                        self.st.h = full;
                    }
                }
                self.reuse = self.theta <= REUSE_CONTRACTION && self.st.h == h;
                return Ok(());
            }
            // Gustafsson's predictive control
            if self.st.stats.naccept > 1 {
                let facgus = ((self.hacc / h) * (err * err / self.erracc).powf(0.25) / SAFE).clamp(FACR, FACL);
                quot = quot.max(facgus);
                hnew = h / quot;
            }
            self.hacc = h;
            self.erracc = err.max(1e-2);
            hnew = hnew.min(self.opts.max_step);
            if self.reject {
                hnew = hnew.min(h);
            }
            self.reject = false;
            let qt = hnew / h;
            if self.theta <= REUSE_CONTRACTION && (QUOT1..=QUOT2).contains(&qt) {
                self.st.h = h;
                self.reuse = true;
            } else {
                self.st.h = hnew;
                self.reuse = false;
            }
            return Ok(());
        }
    }

    fn dense_parts(&self) -> DenseParts<'_> {
        DenseParts { meta: [self.st.t_old, self.st.t, 0.0], parts: [&self.st.y, &self.dq, &self.v0, &self.a0, &self.qdd], count: 5 }
    }

    /// Quintic Hermite interpolation of `q` from `q`, `qd`, `qdd` at both ends (error O(h^6)),
    /// `qd` from its derivative, written on the step's increment `dq = q1 - q0` (`h0 + h5 = 1`,
    /// `d0 = -d5`): the velocity's `d5 dq / h` then carries the rounding of the increment, not
    /// that of positions far from the origin divided by `h` (a 1e-5 m vibration at 0.3 m had a
    /// velocity floor of 1e-9 relative at the outputs, ten times the steps').
    fn dense_eval(meta: [f64; 3], parts: &[&[f64]], t: f64, out: &mut [f64]) {
        let n = out.len() / 2;
        let [t0, t1, _] = meta;
        let (y, dq, v0, a0, a1) = (parts[0], parts[1], parts[2], parts[3], parts[4]);
        let h = t1 - t0;
        if h == 0.0 {
            out.copy_from_slice(y);
            return;
        }
        let s = (t - t0) / h;
        let (s2, s3) = (s * s, s * s * s);
        let (s4, s5) = (s3 * s, s3 * s2);
        // quintic Hermite basis and derivatives (d/ds)
        let h0 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5;
        let h1 = s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5;
        let h2 = 0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5;
        let h3 = 0.5 * s3 - s4 + 0.5 * s5;
        let h4 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5;
        let d1 = 1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4;
        let d2 = s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4;
        let d3 = 1.5 * s2 - 4.0 * s3 + 2.5 * s4;
        let d4 = -12.0 * s2 + 28.0 * s3 - 15.0 * s4;
        let d5 = 30.0 * s2 - 60.0 * s3 + 30.0 * s4;
        let (q1, v1) = y.split_at(n);
        for i in 0..n {
            out[i] = q1[i] - h0 * dq[i] + h1 * h * v0[i] + h2 * h * h * a0[i] + h3 * h * h * a1[i] + h4 * h * v1[i];
            out[n + i] = d5 * dq[i] / h + d1 * v0[i] + d4 * v1[i] + h * (d2 * a0[i] + d3 * a1[i]);
        }
    }

    /// The state `y` (2n), then `dq`, `v0`, `a0`, `a1` (n each).
    fn dense_dim(part_len: &[usize]) -> Option<usize> {
        match *part_len {
            [y, n, b, c, d] if [b, c, d].iter().all(|x| *x == n) && n.checked_mul(2) == Some(y) => Some(y),
            _ => None,
        }
    }

    fn restart_at<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<()> {
        acc_and_multipliers(sys, &mut self.st, &mut self.qdd, &mut self.lam)
    }

    fn expected_steps(&self, t0: f64, t_end: f64) -> Option<usize> {
        fixed_step_count(t0, t_end, self.ro.step)
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
