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

use crate::data::Data;
use crate::error::{Error, Result};
use crate::jacobian::{uk_jacobian, JacobianWorkspace};
use crate::model::Model;
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
}

/// `dy = f(t, y) = [qd, g(t, q, qd)]`.
#[inline]
fn rhs<S: SecondOrderSystem + ?Sized>(sys: &mut S, t: f64, y: &[f64], dy: &mut [f64]) -> Result<()> {
    let n = sys.n();
    let (dq, dqd) = dy.split_at_mut(n);
    dq.copy_from_slice(&y[n..]);
    sys.acc(t, &y[..n], &y[n..], dqd)
}

/// The UK equations of motion of a model as a `SecondOrderSystem`.
pub struct UkSystem<'a> {
    pub model: &'a Model,
    pub data: Data,
    pub jws: JacobianWorkspace,
    /// Optional projection onto `Phi = 0`, `A qd + Phi_t = 0` after each accepted step:
    /// `(tol, max_iter)` for `uk::project` (which allocates its report buffers).
    pub projection: Option<(f64, usize)>,
    /// UK evaluations spent inside finite-difference Jacobians (full, factorization-reusing).
    pub jac_full_evals: usize,
    pub jac_cheap_evals: usize,
}

impl<'a> UkSystem<'a> {
    pub fn new(model: &'a Model, data: Data) -> Self {
        let jws = JacobianWorkspace::new(model);
        UkSystem { model, data, jws, projection: None, jac_full_evals: 0, jac_cheap_evals: 0 }
    }
}

impl SecondOrderSystem for UkSystem<'_> {
    fn n(&self) -> usize {
        self.model.n
    }
    #[inline]
    fn acc(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> Result<()> {
        uk::acceleration(self.model, &mut self.data, t, q, qd)?;
        qdd.copy_from_slice(&self.data.qdd);
        Ok(())
    }
    fn jac(&mut self, t: f64, q: &[f64], qd: &[f64], jq: &mut [f64], jv: &mut [f64]) -> Result<()> {
        uk_jacobian(self.model, &mut self.data, &mut self.jws, t, q, qd, jq, jv)?;
        self.jac_full_evals += self.jws.full_evals;
        self.jac_cheap_evals += self.jws.cheap_evals;
        Ok(())
    }
    fn post_step(&mut self, t: f64, y: &mut [f64]) -> Result<bool> {
        let Some((tol, max_iter)) = self.projection else { return Ok(false) };
        let n = self.model.n;
        let (q, qd) = y.split_at_mut(n);
        uk::project(self.model, &mut self.data, t, q, qd, tol, max_iter)?;
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
}

impl Default for Options {
    fn default() -> Self {
        Options { rtol: 1e-6, atol: vec![1e-9], first_step: None, max_step: f64::INFINITY, max_steps: 1_000_000 }
    }
}

impl Options {
    fn atol_vec(&self, dim: usize) -> Result<Vec<f64>> {
        let v = match self.atol.len() {
            1 => vec![self.atol[0]; dim],
            k if k == dim => self.atol.clone(),
            k => return Err(Error::Shape { what: "atol".into(), expected: dim, got: k }),
        };
        if !(self.rtol >= 0.0) || !self.rtol.is_finite() || v.iter().any(|a| !(*a >= 0.0) || !a.is_finite()) {
            return Err(Error::invalid("integrator", "tolerances must be >= 0 and finite"));
        }
        if self.rtol == 0.0 && v.contains(&0.0) {
            return Err(Error::invalid("integrator", "rtol and atol cannot both be zero"));
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
}

/// One-step integrator with dense output.
pub trait Stepper {
    /// Start at `(t0, y0)`; `t_end` bounds the first step.
    fn init<S: SecondOrderSystem>(&mut self, sys: &mut S, t0: f64, y0: &[f64], t_end: f64) -> Result<()>;
    /// One accepted step (rejected attempts are retried inside), never beyond `t_end`.
    fn step<S: SecondOrderSystem>(&mut self, sys: &mut S, t_end: f64) -> Result<()>;
    fn t(&self) -> f64;
    fn t_old(&self) -> f64;
    fn y(&self) -> &[f64];
    fn y_mut(&mut self) -> &mut [f64];
    /// State at `t` in `[t_old, t]` from the dense output of the last step.
    fn dense(&self, t: f64, out: &mut [f64]);
    /// `y` was changed (post-step hook): re-evaluate what depends on it.
    fn restart_at<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<()>;
    fn stats(&self) -> Stats;
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

// ------------------------------------------------------------------------------------------
// Dormand-Prince 5(4)
// ------------------------------------------------------------------------------------------

mod dp {
    pub const C2: f64 = 1.0 / 5.0;
    pub const C3: f64 = 3.0 / 10.0;
    pub const C4: f64 = 4.0 / 5.0;
    pub const C5: f64 = 8.0 / 9.0;
    pub const A21: f64 = 1.0 / 5.0;
    pub const A31: f64 = 3.0 / 40.0;
    pub const A32: f64 = 9.0 / 40.0;
    pub const A41: f64 = 44.0 / 45.0;
    pub const A42: f64 = -56.0 / 15.0;
    pub const A43: f64 = 32.0 / 9.0;
    pub const A51: f64 = 19372.0 / 6561.0;
    pub const A52: f64 = -25360.0 / 2187.0;
    pub const A53: f64 = 64448.0 / 6561.0;
    pub const A54: f64 = -212.0 / 729.0;
    pub const A61: f64 = 9017.0 / 3168.0;
    pub const A62: f64 = -355.0 / 33.0;
    pub const A63: f64 = 46732.0 / 5247.0;
    pub const A64: f64 = 49.0 / 176.0;
    pub const A65: f64 = -5103.0 / 18656.0;
    pub const A71: f64 = 35.0 / 384.0;
    pub const A73: f64 = 500.0 / 1113.0;
    pub const A74: f64 = 125.0 / 192.0;
    pub const A75: f64 = -2187.0 / 6784.0;
    pub const A76: f64 = 11.0 / 84.0;
    pub const E1: f64 = 71.0 / 57600.0;
    pub const E3: f64 = -71.0 / 16695.0;
    pub const E4: f64 = 71.0 / 1920.0;
    pub const E5: f64 = -17253.0 / 339200.0;
    pub const E6: f64 = 22.0 / 525.0;
    pub const E7: f64 = -1.0 / 40.0;
    pub const D1: f64 = -12715105075.0 / 11282082432.0;
    pub const D3: f64 = 87487479700.0 / 32700410799.0;
    pub const D4: f64 = -10690763975.0 / 1880347072.0;
    pub const D5: f64 = 701980252875.0 / 199316789632.0;
    pub const D6: f64 = -1453857185.0 / 822651844.0;
    pub const D7: f64 = 69997945.0 / 29380423.0;
}

/// Dormand-Prince 5(4) with dense output (Hairer's DOPRI5).
pub struct Dopri5 {
    opts: Options,
    atol: Vec<f64>,
    t: f64,
    t_old: f64,
    h: f64,
    y: Vec<f64>,
    y1: Vec<f64>,
    ysti: Vec<f64>,
    k: [Vec<f64>; 7],
    /// Dense output coefficients of the last step (5 x dim).
    rcont: [Vec<f64>; 5],
    facold: f64,
    reject: bool,
    stats: Stats,
    steps: usize,
}

impl Dopri5 {
    pub fn new(dim: usize, opts: Options) -> Result<Self> {
        let atol = opts.atol_vec(dim)?;
        let z = || vec![0.0; dim];
        Ok(Dopri5 {
            opts,
            atol,
            t: 0.0,
            t_old: 0.0,
            h: 0.0,
            y: z(),
            y1: z(),
            ysti: z(),
            k: [z(), z(), z(), z(), z(), z(), z()],
            rcont: [z(), z(), z(), z(), z()],
            facold: 1e-4,
            reject: false,
            stats: Stats::default(),
            steps: 0,
        })
    }
}

impl Stepper for Dopri5 {
    fn init<S: SecondOrderSystem>(&mut self, sys: &mut S, t0: f64, y0: &[f64], t_end: f64) -> Result<()> {
        self.t = t0;
        self.t_old = t0;
        self.y.copy_from_slice(y0);
        self.stats = Stats::default();
        self.steps = 0;
        self.facold = 1e-4;
        self.reject = false;
        rhs(sys, t0, &self.y, &mut self.k[0])?;
        self.stats.nfev += 1;
        let hmax = self.opts.max_step.min((t_end - t0).abs());
        self.h = match self.opts.first_step {
            Some(h) => h.min(hmax),
            None => {
                let [k0, k1, ..] = &mut self.k;
                initial_step(sys, t0, &self.y, k0, self.opts.rtol, &self.atol, 5, hmax, &mut self.y1, k1, &mut self.stats.nfev)?
            }
        };
        for r in self.rcont.iter_mut() {
            r.fill(0.0);
        }
        self.rcont[0].copy_from_slice(y0);
        Ok(())
    }

    fn step<S: SecondOrderSystem>(&mut self, sys: &mut S, t_end: f64) -> Result<()> {
        use dp::*;
        const BETA: f64 = 0.04;
        const EXPO1: f64 = 0.2 - BETA * 0.75;
        const SAFE: f64 = 0.9;
        const FACC1: f64 = 5.0; // hnew >= h / 5
        const FACC2: f64 = 0.1; // hnew <= 10 h
        let dim = self.y.len();
        let hmax = self.opts.max_step;
        loop {
            if self.steps >= self.opts.max_steps {
                return Err(Error::Solver(format!("DOPRI5: more than {} steps at t = {}", self.opts.max_steps, self.t)));
            }
            if 0.1 * self.h.abs() <= self.t.abs() * f64::EPSILON || !self.h.is_finite() {
                return Err(Error::Solver(format!("DOPRI5: step size too small (h = {:e}) at t = {}", self.h, self.t)));
            }
            if self.t + 1.01 * self.h >= t_end {
                self.h = t_end - self.t;
            }
            self.steps += 1;
            let (t, h) = (self.t, self.h);
            let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
            let (y, ys) = (&self.y, &mut self.ysti);
            for i in 0..dim {
                ys[i] = y[i] + h * A21 * k1[i];
            }
            rhs(sys, t + C2 * h, ys, k2)?;
            for i in 0..dim {
                ys[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
            }
            rhs(sys, t + C3 * h, ys, k3)?;
            for i in 0..dim {
                ys[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
            }
            rhs(sys, t + C4 * h, ys, k4)?;
            for i in 0..dim {
                ys[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
            }
            rhs(sys, t + C5 * h, ys, k5)?;
            for i in 0..dim {
                ys[i] = y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
            }
            let tph = t + h;
            rhs(sys, tph, ys, k6)?;
            let y1 = &mut self.y1;
            for i in 0..dim {
                y1[i] = y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
            }
            rhs(sys, tph, y1, k7)?;
            self.stats.nfev += 6;
            let mut err = 0.0;
            for i in 0..dim {
                let e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
                let sk = self.atol[i] + self.opts.rtol * y[i].abs().max(y1[i].abs());
                err += (e / sk) * (e / sk);
            }
            let err = (err / dim as f64).sqrt();
            if !err.is_finite() {
                // treat like a failed step: shrink hard
                self.h *= 0.1;
                self.reject = true;
                continue;
            }
            let fac11 = err.powf(EXPO1);
            let fac = (fac11 / self.facold.powf(BETA) / SAFE).clamp(FACC2, FACC1);
            let mut hnew = h / fac;
            if err <= 1.0 {
                self.facold = err.max(1e-4);
                self.stats.naccept += 1;
                // dense output
                let [r0, r1, r2, r3, r4] = &mut self.rcont;
                for i in 0..dim {
                    let ydiff = y1[i] - y[i];
                    let bspl = h * k1[i] - ydiff;
                    r0[i] = y[i];
                    r1[i] = ydiff;
                    r2[i] = bspl;
                    r3[i] = ydiff - h * k7[i] - bspl;
                    r4[i] = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
                }
                std::mem::swap(k1, k7);
                std::mem::swap(&mut self.y, &mut self.y1);
                self.t_old = t;
                self.t = if tph >= t_end { t_end } else { tph };
                hnew = hnew.abs().min(hmax);
                if self.reject {
                    hnew = hnew.min(h.abs());
                }
                self.reject = false;
                self.h = hnew;
                return Ok(());
            }
            hnew = h / FACC1.min(fac11 / SAFE);
            self.reject = true;
            if self.stats.naccept >= 1 {
                self.stats.nreject += 1;
            }
            self.h = hnew;
        }
    }

    fn t(&self) -> f64 {
        self.t
    }
    fn t_old(&self) -> f64 {
        self.t_old
    }
    fn y(&self) -> &[f64] {
        &self.y
    }
    fn y_mut(&mut self) -> &mut [f64] {
        &mut self.y
    }
    fn dense(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_old;
        if h == 0.0 {
            out.copy_from_slice(&self.y);
            return;
        }
        let theta = (t - self.t_old) / h;
        let theta1 = 1.0 - theta;
        let [r0, r1, r2, r3, r4] = &self.rcont;
        for i in 0..out.len() {
            out[i] = r0[i] + theta * (r1[i] + theta1 * (r2[i] + theta * (r3[i] + theta1 * r4[i])));
        }
    }
    fn restart_at<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<()> {
        rhs(sys, self.t, &self.y, &mut self.k[0])?;
        self.stats.nfev += 1;
        Ok(())
    }
    fn stats(&self) -> Stats {
        self.stats
    }
}

// ------------------------------------------------------------------------------------------
// Dense LU (real and complex), allocation free after construction
// ------------------------------------------------------------------------------------------

/// In-place LU with partial pivoting of an n x n row-major matrix. `false` if singular.
fn lu_real(a: &mut [f64], piv: &mut [usize], n: usize) -> bool {
    for k in 0..n {
        let mut p = k;
        let mut best = a[k * n + k].abs();
        for i in k + 1..n {
            let v = a[i * n + k].abs();
            if v > best {
                best = v;
                p = i;
            }
        }
        piv[k] = p;
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
        }
        let inv = 1.0 / a[k * n + k];
        let (top, bottom) = a.split_at_mut((k + 1) * n);
        let rowk = &top[k * n..];
        for i in 0..n - k - 1 {
            let row = &mut bottom[i * n..(i + 1) * n];
            let l = row[k] * inv;
            row[k] = l;
            if l != 0.0 {
                for (x, r) in row[k + 1..].iter_mut().zip(&rowk[k + 1..]) {
                    *x -= l * r;
                }
            }
        }
    }
    true
}

fn lu_real_solve(a: &[f64], piv: &[usize], n: usize, x: &mut [f64]) {
    for k in 0..n {
        x.swap(k, piv[k]);
    }
    for i in 0..n {
        let s: f64 = a[i * n..i * n + i].iter().zip(&x[..i]).map(|(l, v)| l * v).sum();
        x[i] -= s;
    }
    for i in (0..n).rev() {
        let s: f64 = a[i * n + i + 1..(i + 1) * n].iter().zip(&x[i + 1..]).map(|(u, v)| u * v).sum();
        x[i] = (x[i] - s) / a[i * n + i];
    }
}

/// Complex LU (separate real and imaginary parts), partial pivoting by modulus.
fn lu_cplx(ar: &mut [f64], ai: &mut [f64], piv: &mut [usize], n: usize) -> bool {
    for k in 0..n {
        let mut p = k;
        let mut best = ar[k * n + k].hypot(ai[k * n + k]);
        for i in k + 1..n {
            let v = ar[i * n + k].hypot(ai[i * n + k]);
            if v > best {
                best = v;
                p = i;
            }
        }
        piv[k] = p;
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        if p != k {
            for j in 0..n {
                ar.swap(k * n + j, p * n + j);
                ai.swap(k * n + j, p * n + j);
            }
        }
        let (pr, pi) = (ar[k * n + k], ai[k * n + k]);
        let d = pr * pr + pi * pi;
        let (ir, ii) = (pr / d, -pi / d);
        for i in k + 1..n {
            let (xr, xi) = (ar[i * n + k], ai[i * n + k]);
            let (lr, li) = (xr * ir - xi * ii, xr * ii + xi * ir);
            ar[i * n + k] = lr;
            ai[i * n + k] = li;
            if lr != 0.0 || li != 0.0 {
                for j in k + 1..n {
                    let (ur, ui) = (ar[k * n + j], ai[k * n + j]);
                    ar[i * n + j] -= lr * ur - li * ui;
                    ai[i * n + j] -= lr * ui + li * ur;
                }
            }
        }
    }
    true
}

fn lu_cplx_solve(ar: &[f64], ai: &[f64], piv: &[usize], n: usize, xr: &mut [f64], xi: &mut [f64]) {
    for k in 0..n {
        xr.swap(k, piv[k]);
        xi.swap(k, piv[k]);
    }
    for i in 0..n {
        let (mut sr, mut si) = (0.0, 0.0);
        for j in 0..i {
            let (lr, li) = (ar[i * n + j], ai[i * n + j]);
            sr += lr * xr[j] - li * xi[j];
            si += lr * xi[j] + li * xr[j];
        }
        xr[i] -= sr;
        xi[i] -= si;
    }
    for i in (0..n).rev() {
        let (mut sr, mut si) = (xr[i], xi[i]);
        for j in i + 1..n {
            let (ur, ui) = (ar[i * n + j], ai[i * n + j]);
            sr -= ur * xr[j] - ui * xi[j];
            si -= ur * xi[j] + ui * xr[j];
        }
        let (pr, pi) = (ar[i * n + i], ai[i * n + i]);
        let d = pr * pr + pi * pi;
        xr[i] = (sr * pr + si * pi) / d;
        xi[i] = (si * pr - sr * pi) / d;
    }
}

// ------------------------------------------------------------------------------------------
// Radau IIA (order 5)
// ------------------------------------------------------------------------------------------

mod rc {
    // Hairer & Wanner, RADAU5 (radau5.f), constants of the 3-stage Radau IIA method.
    pub const SQ6: f64 = 2.449_489_742_783_178;
    pub const C1: f64 = (4.0 - SQ6) / 10.0;
    pub const C2: f64 = (4.0 + SQ6) / 10.0;
    pub const C1M1: f64 = C1 - 1.0;
    pub const C2M1: f64 = C2 - 1.0;
    pub const C1MC2: f64 = C1 - C2;
    pub const DD1: f64 = -(13.0 + 7.0 * SQ6) / 3.0;
    pub const DD2: f64 = (-13.0 + 7.0 * SQ6) / 3.0;
    pub const DD3: f64 = -1.0 / 3.0;
    pub const T11: f64 = 9.123_239_487_089_294_279e-2;
    pub const T12: f64 = -0.141_255_295_020_954_208_43;
    pub const T13: f64 = -3.002_919_410_514_742_449_2e-2;
    pub const T21: f64 = 0.241_717_932_707_107_018_96;
    pub const T22: f64 = 0.204_129_352_293_799_931_99;
    pub const T23: f64 = 0.382_942_112_757_261_937_79;
    pub const T31: f64 = 0.966_048_182_615_092_936_19;
    pub const TI11: f64 = 4.325_579_890_063_155_351;
    pub const TI12: f64 = 0.339_199_251_815_809_869_54;
    pub const TI13: f64 = 0.541_770_539_935_874_871_19;
    pub const TI21: f64 = -4.178_718_591_551_904_727_3;
    pub const TI22: f64 = -0.327_682_820_761_062_387_08;
    pub const TI23: f64 = 0.476_623_554_500_550_451_96;
    pub const TI31: f64 = -0.502_872_634_945_786_875_95;
    pub const TI32: f64 = 2.571_926_949_855_605_429_2;
    pub const TI33: f64 = -0.596_039_204_828_224_924_97;

    /// (u1, alpha, beta): the real eigenvalue and the complex pair of A^-1 (scaled by 1/h).
    pub fn eigen() -> (f64, f64, f64) {
        let c81 = 81f64.cbrt();
        let c9 = 9f64.cbrt();
        let u1 = (6.0 + c81 - c9) / 30.0;
        let mut alph = (12.0 - c81 + c9) / 60.0;
        let mut beta = (c81 + c9) * 3f64.sqrt() / 60.0;
        let cno = alph * alph + beta * beta;
        alph /= cno;
        beta /= cno;
        (1.0 / u1, alph, beta)
    }
}

/// Radau IIA of order 5 with Hairer's RADAU5 control (see the module docs).
pub struct Radau5 {
    opts: Options,
    /// Tolerances as RADAU5 uses them internally: `rtol' = 0.1 rtol^(2/3)`,
    /// `atol' = rtol' atol / rtol`.
    rtol: f64,
    atol: Vec<f64>,
    n: usize,
    t: f64,
    t_old: f64,
    h: f64,
    h_old: f64,
    y: Vec<f64>,
    /// `f(t, y)` at the start of the step.
    f0: Vec<f64>,
    z: [Vec<f64>; 3],
    w: [Vec<f64>; 3],
    /// Collocation polynomial of the last step: `[y_new, c1, c2, c3]`.
    cont: [Vec<f64>; 4],
    scal: Vec<f64>,
    tmp: Vec<f64>,
    tmp2: Vec<f64>,
    ystage: Vec<f64>,
    jq: Vec<f64>,
    jv: Vec<f64>,
    e1: Vec<f64>,
    e2r: Vec<f64>,
    e2i: Vec<f64>,
    piv1: Vec<usize>,
    piv2: Vec<usize>,
    br: Vec<f64>,
    bi: Vec<f64>,
    u1: f64,
    alph: f64,
    beta: f64,
    fac1: f64,
    alphn: f64,
    betan: f64,
    fnewt: f64,
    faccon: f64,
    theta: f64,
    hacc: f64,
    erracc: f64,
    first: bool,
    reject: bool,
    caljac: bool,
    need_jac: bool,
    need_dec: bool,
    nsing: usize,
    steps: usize,
    stats: Stats,
}

const NIT: usize = 7;
/// Re-evaluate the Jacobian after a step only if the Newton contraction exceeded this.
/// RADAU5's default is 0.001 (cheap Jacobians); Hairer recommends 0.1 when the Jacobian is
/// costly, as here (a finite-difference Jacobian is ~4n UK calls). Measured on the paper scene:
/// 20x fewer Jacobians, 3x faster with beam damping (docs/performance.md).
const THET: f64 = 0.1;
const SAFE: f64 = 0.9;
const FACL: f64 = 5.0;
const FACR: f64 = 0.125;
const QUOT1: f64 = 1.0;
const QUOT2: f64 = 1.2;

impl Radau5 {
    pub fn new(n: usize, opts: Options) -> Result<Self> {
        let dim = 2 * n;
        let atol_user = opts.atol_vec(dim)?;
        if !(opts.rtol > 0.0) {
            return Err(Error::invalid("RADAU5", "rtol must be positive"));
        }
        let rtol = 0.1 * opts.rtol.powf(2.0 / 3.0);
        let atol = atol_user.iter().map(|a| rtol * a / opts.rtol).collect();
        let (u1, alph, beta) = rc::eigen();
        let fnewt = (10.0 * f64::EPSILON / rtol).max(0.03f64.min(rtol.sqrt()));
        let z = || vec![0.0; dim];
        Ok(Radau5 {
            opts,
            rtol,
            atol,
            n,
            t: 0.0,
            t_old: 0.0,
            h: 0.0,
            h_old: 0.0,
            y: z(),
            f0: z(),
            z: [z(), z(), z()],
            w: [z(), z(), z()],
            cont: [z(), z(), z(), z()],
            scal: z(),
            tmp: z(),
            tmp2: z(),
            ystage: z(),
            jq: vec![0.0; n * n],
            jv: vec![0.0; n * n],
            e1: vec![0.0; n * n],
            e2r: vec![0.0; n * n],
            e2i: vec![0.0; n * n],
            piv1: vec![0; n],
            piv2: vec![0; n],
            br: vec![0.0; n],
            bi: vec![0.0; n],
            u1,
            alph,
            beta,
            fac1: 0.0,
            alphn: 0.0,
            betan: 0.0,
            fnewt,
            faccon: 1.0,
            theta: THET,
            hacc: 0.0,
            erracc: 0.0,
            first: true,
            reject: false,
            caljac: false,
            need_jac: true,
            need_dec: true,
            nsing: 0,
            steps: 0,
            stats: Stats::default(),
        })
    }

    fn update_scal(&mut self) {
        for i in 0..self.y.len() {
            self.scal[i] = self.atol[i] + self.rtol * self.y[i].abs();
        }
    }

    /// Real and complex reduced iteration matrices for the current h.
    fn decompose(&mut self) -> bool {
        let n = self.n;
        self.fac1 = self.u1 / self.h;
        self.alphn = self.alph / self.h;
        self.betan = self.beta / self.h;
        let (f, a, b) = (self.fac1, self.alphn, self.betan);
        // E1 = f^2 I - f Jv - Jq ; E2 = g^2 I - g Jv - Jq, g = a + i b
        let (g2r, g2i) = (a * a - b * b, 2.0 * a * b);
        for i in 0..n {
            for j in 0..n {
                let (jq, jv) = (self.jq[i * n + j], self.jv[i * n + j]);
                self.e1[i * n + j] = -f * jv - jq;
                self.e2r[i * n + j] = -a * jv - jq;
                self.e2i[i * n + j] = -b * jv;
            }
            self.e1[i * n + i] += f * f;
            self.e2r[i * n + i] += g2r;
            self.e2i[i * n + i] += g2i;
        }
        self.stats.nlu += 2;
        lu_real(&mut self.e1, &mut self.piv1, n) && lu_cplx(&mut self.e2r, &mut self.e2i, &mut self.piv2, n)
    }

    /// `x <- (fac1 I - J)^-1 x` for a 2n vector.
    fn solve_real(&mut self, x: &mut [f64]) {
        let n = self.n;
        let f = self.fac1;
        let (r1, r2) = x.split_at_mut(n);
        // rhs = f r2 + Jq r1
        for i in 0..n {
            let s: f64 = self.jq[i * n..(i + 1) * n].iter().zip(r1.iter()).map(|(a, b)| a * b).sum();
            self.br[i] = f * r2[i] + s;
        }
        lu_real_solve(&self.e1, &self.piv1, n, &mut self.br);
        for i in 0..n {
            r2[i] = self.br[i];
            r1[i] = (r1[i] + self.br[i]) / f;
        }
    }

    /// `(xr + i xi) <- ((alphn + i betan) I - J)^-1 (xr + i xi)`.
    fn solve_cplx(&mut self, xr: &mut [f64], xi: &mut [f64]) {
        let n = self.n;
        let (a, b) = (self.alphn, self.betan);
        let (r1r, r2r) = xr.split_at_mut(n);
        let (r1i, r2i) = xi.split_at_mut(n);
        for i in 0..n {
            let row = &self.jq[i * n..(i + 1) * n];
            let sr: f64 = row.iter().zip(r1r.iter()).map(|(p, q)| p * q).sum();
            let si: f64 = row.iter().zip(r1i.iter()).map(|(p, q)| p * q).sum();
            self.br[i] = a * r2r[i] - b * r2i[i] + sr;
            self.bi[i] = a * r2i[i] + b * r2r[i] + si;
        }
        lu_cplx_solve(&self.e2r, &self.e2i, &self.piv2, n, &mut self.br, &mut self.bi);
        // x1 = (r1 + x2) / g, 1/g = (a - i b) / (a^2 + b^2)
        let d = a * a + b * b;
        let (gr, gi) = (a / d, -b / d);
        for i in 0..n {
            let (pr, pi) = (r1r[i] + self.br[i], r1i[i] + self.bi[i]);
            r1r[i] = pr * gr - pi * gi;
            r1i[i] = pr * gi + pi * gr;
            r2r[i] = self.br[i];
            r2i[i] = self.bi[i];
        }
    }

    fn error_estimate<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<f64> {
        let dim = self.y.len();
        let (hee1, hee2, hee3) = (rc::DD1 / self.h, rc::DD2 / self.h, rc::DD3 / self.h);
        let mut tmp = std::mem::take(&mut self.tmp);
        let mut tmp2 = std::mem::take(&mut self.tmp2);
        for i in 0..dim {
            tmp2[i] = hee1 * self.z[0][i] + hee2 * self.z[1][i] + hee3 * self.z[2][i];
            tmp[i] = tmp2[i] + self.f0[i];
        }
        self.solve_real(&mut tmp);
        let mut err = rms_norm(&tmp, &self.scal).max(1e-10);
        if err >= 1.0 && (self.first || self.reject) {
            for i in 0..dim {
                self.ystage[i] = self.y[i] + tmp[i];
            }
            let mut ystage = std::mem::take(&mut self.ystage);
            let r = rhs(sys, self.t, &ystage, &mut tmp);
            self.stats.nfev += 1;
            for i in 0..dim {
                tmp[i] += tmp2[i];
            }
            std::mem::swap(&mut self.ystage, &mut ystage);
            r?;
            self.solve_real(&mut tmp);
            err = rms_norm(&tmp, &self.scal).max(1e-10);
        }
        self.tmp = tmp;
        self.tmp2 = tmp2;
        Ok(err)
    }

    fn fail_newton(&mut self, factor: f64) {
        self.h *= factor;
        self.reject = true;
        if self.caljac {
            self.need_dec = true;
        } else {
            self.need_jac = true;
        }
    }
}

impl Stepper for Radau5 {
    fn init<S: SecondOrderSystem>(&mut self, sys: &mut S, t0: f64, y0: &[f64], t_end: f64) -> Result<()> {
        self.t = t0;
        self.t_old = t0;
        self.y.copy_from_slice(y0);
        self.stats = Stats::default();
        self.steps = 0;
        self.first = true;
        self.reject = false;
        self.caljac = false;
        self.need_jac = true;
        self.need_dec = true;
        self.faccon = 1.0;
        self.theta = THET;
        self.nsing = 0;
        rhs(sys, t0, &self.y, &mut self.f0)?;
        self.stats.nfev += 1;
        self.update_scal();
        let hmax = self.opts.max_step.min((t_end - t0).abs());
        self.h = match self.opts.first_step {
            Some(h) => h.min(hmax),
            None => {
                let (mut a, mut b) = (std::mem::take(&mut self.tmp), std::mem::take(&mut self.tmp2));
                let r = initial_step(sys, t0, &self.y, &self.f0, self.opts.rtol, &self.opts.atol_vec(self.y.len())?, 3, hmax, &mut a, &mut b, &mut self.stats.nfev);
                self.tmp = a;
                self.tmp2 = b;
                r?
            }
        };
        self.h_old = self.h;
        for c in self.cont.iter_mut() {
            c.fill(0.0);
        }
        self.cont[0].copy_from_slice(y0);
        Ok(())
    }

    fn step<S: SecondOrderSystem>(&mut self, sys: &mut S, t_end: f64) -> Result<()> {
        use rc::*;
        let dim = self.y.len();
        let cfac = SAFE * (1.0 + 2.0 * NIT as f64);
        let hmax = self.opts.max_step;
        loop {
            if self.t + self.h > t_end {
                self.h = t_end - self.t;
                self.need_dec = true;
            }
            if self.need_jac {
                let n = self.n;
                let (q, qd) = self.y.split_at(n);
                sys.jac(self.t, q, qd, &mut self.jq, &mut self.jv)?;
                self.stats.njev += 1;
                self.caljac = true;
                self.need_jac = false;
                self.need_dec = true;
            }
            if self.need_dec {
                self.need_dec = false;
                if !self.decompose() {
                    self.nsing += 1;
                    if self.nsing >= 5 {
                        return Err(Error::Solver(format!("RADAU5: iteration matrix repeatedly singular at t = {}", self.t)));
                    }
                    self.h *= 0.5;
                    self.reject = true;
                    self.need_dec = true;
                    continue;
                }
            }
            self.steps += 1;
            if self.steps > self.opts.max_steps {
                return Err(Error::Solver(format!("RADAU5: more than {} steps at t = {}", self.opts.max_steps, self.t)));
            }
            if 0.1 * self.h.abs() <= self.t.abs() * f64::EPSILON || !self.h.is_finite() {
                return Err(Error::Solver(format!("RADAU5: step size too small (h = {:e}) at t = {}", self.h, self.t)));
            }
            let (t, h) = (self.t, self.h);
            let xph = t + h;
            // starting values for Newton
            if self.first {
                for k in 0..3 {
                    self.z[k].fill(0.0);
                    self.w[k].fill(0.0);
                }
            } else {
                let c3q = h / self.h_old;
                let (c1q, c2q) = (C1 * c3q, C2 * c3q);
                let [_, a1, a2, a3] = &self.cont;
                for i in 0..dim {
                    let (ak1, ak2, ak3) = (a1[i], a2[i], a3[i]);
                    let z1 = c1q * (ak1 + (c1q - C2M1) * (ak2 + (c1q - C1M1) * ak3));
                    let z2 = c2q * (ak1 + (c2q - C2M1) * (ak2 + (c2q - C1M1) * ak3));
                    let z3 = c3q * (ak1 + (c3q - C2M1) * (ak2 + (c3q - C1M1) * ak3));
                    self.z[0][i] = z1;
                    self.z[1][i] = z2;
                    self.z[2][i] = z3;
                    self.w[0][i] = TI11 * z1 + TI12 * z2 + TI13 * z3;
                    self.w[1][i] = TI21 * z1 + TI22 * z2 + TI23 * z3;
                    self.w[2][i] = TI31 * z1 + TI32 * z2 + TI33 * z3;
                }
            }
            // simplified Newton
            self.faccon = self.faccon.max(f64::EPSILON).powf(0.8);
            self.theta = THET.abs();
            let mut newt = 0usize;
            let mut dynold = 0.0f64;
            let mut thqold = 0.0f64;
            let mut restart = false;
            loop {
                if newt >= NIT {
                    self.fail_newton(0.5);
                    restart = true;
                    break;
                }
                // stage values f(t + c_i h, y + z_i) into z_i
                for (k, c) in [C1, C2, 1.0].into_iter().enumerate() {
                    for i in 0..dim {
                        self.ystage[i] = self.y[i] + self.z[k][i];
                    }
                    let mut ystage = std::mem::take(&mut self.ystage);
                    let r = rhs(sys, t + c * h, &ystage, &mut self.z[k]);
                    std::mem::swap(&mut self.ystage, &mut ystage);
                    r?;
                }
                self.stats.nfev += 3;
                let [z1, z2, z3] = &mut self.z;
                let [w1, w2, w3] = &self.w;
                let (fac1, an, bn) = (self.fac1, self.alphn, self.betan);
                for i in 0..dim {
                    let (a1, a2, a3) = (z1[i], z2[i], z3[i]);
                    let r1 = TI11 * a1 + TI12 * a2 + TI13 * a3;
                    let r2 = TI21 * a1 + TI22 * a2 + TI23 * a3;
                    let r3 = TI31 * a1 + TI32 * a2 + TI33 * a3;
                    // SLVRAD right-hand sides
                    z1[i] = r1 - fac1 * w1[i];
                    z2[i] = r2 - (an * w2[i] - bn * w3[i]);
                    z3[i] = r3 - (an * w3[i] + bn * w2[i]);
                }
                let mut za = std::mem::take(&mut self.z[0]);
                self.solve_real(&mut za);
                self.z[0] = za;
                let (mut zb, mut zc) = (std::mem::take(&mut self.z[1]), std::mem::take(&mut self.z[2]));
                self.solve_cplx(&mut zb, &mut zc);
                self.z[1] = zb;
                self.z[2] = zc;
                newt += 1;
                let mut dyno = 0.0;
                for i in 0..dim {
                    let s = self.scal[i];
                    dyno += (self.z[0][i] / s).powi(2) + (self.z[1][i] / s).powi(2) + (self.z[2][i] / s).powi(2);
                }
                let dyno = (dyno / (3 * dim) as f64).sqrt();
                if !dyno.is_finite() {
                    self.fail_newton(0.5);
                    restart = true;
                    break;
                }
                if newt > 1 && newt < NIT {
                    let thq = dyno / dynold;
                    self.theta = if newt == 2 { thq } else { (thq * thqold).sqrt() };
                    thqold = thq;
                    if self.theta < 0.99 {
                        self.faccon = self.theta / (1.0 - self.theta);
                        let dyth = self.faccon * dyno * self.theta.powi((NIT - 1 - newt) as i32) / self.fnewt;
                        if dyth >= 1.0 {
                            let qnewt = dyth.clamp(1e-4, 20.0);
                            let hhfac = 0.8 * qnewt.powf(-1.0 / (4.0 + NIT as f64 - 1.0 - newt as f64));
                            self.fail_newton(hhfac);
                            restart = true;
                            break;
                        }
                    } else {
                        self.fail_newton(0.5);
                        restart = true;
                        break;
                    }
                }
                dynold = dyno.max(f64::EPSILON);
                let [z1, z2, z3] = &mut self.z;
                let [w1, w2, w3] = &mut self.w;
                for i in 0..dim {
                    w1[i] += z1[i];
                    w2[i] += z2[i];
                    w3[i] += z3[i];
                    let (f1, f2, f3) = (w1[i], w2[i], w3[i]);
                    z1[i] = T11 * f1 + T12 * f2 + T13 * f3;
                    z2[i] = T21 * f1 + T22 * f2 + T23 * f3;
                    z3[i] = T31 * f1 + f2;
                }
                if self.faccon * dyno <= self.fnewt {
                    break;
                }
            }
            if restart {
                if self.stats.naccept >= 1 {
                    self.stats.nreject += 1;
                }
                continue;
            }
            // error estimate and new step size
            let err = self.error_estimate(sys)?;
            let fac = SAFE.min(cfac / (newt as f64 + 2.0 * NIT as f64));
            let mut quot = FACR.max(FACL.min(err.powf(0.25) / fac));
            let mut hnew = h / quot;
            if err < 1.0 {
                self.first = false;
                self.stats.naccept += 1;
                self.nsing = 0;
                // Gustafsson's predictive controller
                if self.stats.naccept > 1 {
                    let facgus = ((self.hacc / h) * (err * err / self.erracc).powf(0.25) / SAFE).clamp(FACR, FACL);
                    quot = quot.max(facgus);
                    hnew = h / quot;
                }
                self.hacc = h;
                self.erracc = err.max(1e-2);
                self.t_old = t;
                self.h_old = h;
                self.t = if xph >= t_end { t_end } else { xph };
                let [z1, z2, z3] = &self.z;
                let [c0, c1, c2, c3] = &mut self.cont;
                for i in 0..dim {
                    self.y[i] += z3[i];
                    let (z1i, z2i, z3i) = (z1[i], z2[i], z3[i]);
                    c1[i] = (z2i - z3i) / C2M1;
                    let ak = (z1i - z2i) / C1MC2;
                    let acont3 = (ak - z1i / C1) / C2;
                    c2[i] = (ak - c1[i]) / C1M1;
                    c3[i] = c2[i] - acont3;
                    c0[i] = self.y[i];
                }
                self.update_scal();
                rhs(sys, self.t, &self.y, &mut self.f0)?;
                self.stats.nfev += 1;
                hnew = hnew.abs().min(hmax);
                if self.reject {
                    hnew = hnew.min(h.abs());
                }
                self.reject = false;
                let keep = if self.t + hnew / QUOT1 >= t_end {
                    self.h = t_end - self.t;
                    false
                } else {
                    let qt = hnew / h;
                    if self.theta <= THET && (QUOT1..=QUOT2).contains(&qt) {
                        true
                    } else {
                        self.h = hnew;
                        false
                    }
                };
                if !keep {
                    if self.theta <= THET {
                        self.need_dec = true;
                    } else {
                        self.need_jac = true;
                    }
                }
                self.caljac = false;
                return Ok(());
            }
            // rejected by the error test: Newton converged, so the Jacobian is still good
            // (scipy's policy; RADAU5 would re-evaluate it unless fresh): refactor only
            self.reject = true;
            if self.first {
                self.h *= 0.1;
            } else {
                self.h = hnew;
            }
            if self.stats.naccept >= 1 {
                self.stats.nreject += 1;
            }
            self.need_dec = true;
        }
    }

    fn t(&self) -> f64 {
        self.t
    }
    fn t_old(&self) -> f64 {
        self.t_old
    }
    fn y(&self) -> &[f64] {
        &self.y
    }
    fn y_mut(&mut self) -> &mut [f64] {
        &mut self.y
    }
    fn dense(&self, t: f64, out: &mut [f64]) {
        use rc::*;
        if self.t == self.t_old {
            out.copy_from_slice(&self.y);
            return;
        }
        let s = (t - self.t) / self.h_old;
        let [c0, c1, c2, c3] = &self.cont;
        for i in 0..out.len() {
            out[i] = c0[i] + s * (c1[i] + (s - C2M1) * (c2[i] + (s - C1M1) * c3[i]));
        }
    }
    fn restart_at<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<()> {
        rhs(sys, self.t, &self.y, &mut self.f0)?;
        self.stats.nfev += 1;
        self.update_scal();
        Ok(())
    }
    fn stats(&self) -> Stats {
        self.stats
    }
}

// ------------------------------------------------------------------------------------------
// Driver
// ------------------------------------------------------------------------------------------

/// Trajectory of a run: `t` (nt) and `y` (nt x dim, row-major).
#[derive(Debug, Clone, Default)]
pub struct Solution {
    pub t: Vec<f64>,
    pub y: Vec<f64>,
    pub dim: usize,
    pub stats: Stats,
    /// 0: reached `t_end`; -1: failed (see `message`).
    pub status: i32,
    pub message: String,
}

/// Integrate from `(t0, y0)` to `t_end`. Outputs at `t_eval` (strictly increasing, within
/// `[t0, t_end]`) from the dense output, or at every accepted step when `t_eval` is `None`.
/// A failure inside the run ends it with `status = -1` and the trajectory up to there; only
/// invalid arguments are returned as `Err`.
pub fn integrate<St: Stepper, S: SecondOrderSystem>(stepper: &mut St, sys: &mut S, t0: f64, y0: &[f64], t_end: f64, t_eval: Option<&[f64]>) -> Result<Solution> {
    let dim = y0.len();
    if dim != 2 * sys.n() {
        return Err(Error::Shape { what: "y0".into(), expected: 2 * sys.n(), got: dim });
    }
    if !(t_end > t0) || !t_end.is_finite() || !t0.is_finite() {
        return Err(Error::invalid("integrator", format!("need finite t_end > t0, got t0 = {t0}, t_end = {t_end}")));
    }
    if let Some(te) = t_eval {
        if te.windows(2).any(|w| !(w[1] > w[0])) || te.iter().any(|x| !(*x >= t0 && *x <= t_end)) {
            return Err(Error::invalid("integrator", "t_eval must be strictly increasing within [t0, t_end]"));
        }
    }
    let mut sol = Solution { dim, ..Default::default() };
    let cap = t_eval.map(|te| te.len()).unwrap_or(1024);
    sol.t.reserve(cap);
    sol.y.reserve(cap * dim);
    let mut next = 0usize;
    let mut buf = vec![0.0; dim];
    if let Err(e) = stepper.init(sys, t0, y0, t_end) {
        sol.status = -1;
        sol.message = e.to_string();
        return Ok(sol);
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
        if let Err(e) = stepper.step(sys, t_end) {
            sol.status = -1;
            sol.message = e.to_string();
            break;
        }
        let t = stepper.t();
        match sys.post_step(t, stepper.y_mut()) {
            Ok(true) => {
                if let Err(e) = stepper.restart_at(sys) {
                    sol.status = -1;
                    sol.message = e.to_string();
                    break;
                }
            }
            Ok(false) => {}
            Err(e) => {
                sol.status = -1;
                sol.message = e.to_string();
                break;
            }
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
    }
    if sol.status == 0 {
        sol.message = "The solver successfully reached the end of the integration interval.".into();
    }
    sol.stats = stepper.stats();
    Ok(sol)
}

/// The native methods by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    Dopri5,
    Radau5,
}

impl Method {
    pub fn from_name(name: &str) -> Option<Method> {
        match name.to_ascii_uppercase().as_str() {
            "DOPRI5" => Some(Method::Dopri5),
            "RADAU5" => Some(Method::Radau5),
            _ => None,
        }
    }
}

/// Convenience: run `method` on the UK system of `model` with a workspace `data`.
pub fn integrate_uk(model: &Model, data: Data, method: Method, opts: Options, t0: f64, y0: &[f64], t_end: f64, t_eval: Option<&[f64]>, projection: Option<(f64, usize)>) -> Result<(Solution, usize, usize)> {
    let mut sys = UkSystem::new(model, data);
    sys.projection = projection;
    let sol = match method {
        Method::Dopri5 => {
            let mut st = Dopri5::new(2 * model.n, opts)?;
            integrate(&mut st, &mut sys, t0, y0, t_end, t_eval)?
        }
        Method::Radau5 => {
            let mut st = Radau5::new(model.n, opts)?;
            integrate(&mut st, &mut sys, t0, y0, t_end, t_eval)?
        }
    };
    Ok((sol, sys.jac_full_evals, sys.jac_cheap_evals))
}
