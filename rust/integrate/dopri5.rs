//! Dormand-Prince 5(4) with Hairer's step-size control (PI, beta = 0.04) and his 4th-order
//! dense output (`DOPRI5`, Hairer, Norsett & Wanner, Solving ODEs I, II.5).
//!
//! On a constrained system, with a projection (the default): after every accepted step the
//! state is projected onto the constraints with the factorization of the step's last stage
//! (FSAL, at the new state); a projection whose Newton does not converge rejects the step. The
//! part of the local error estimate across the constraints counts with the weight
//! `normal_weight`: in full away from singular configurations, less and less near one, where it
//! is amplified by `1 / sigma_min` and measured in full it would shrink the step without end and
//! drive the state into the singular configuration, where it may leave its branch
//! (docs/integrators.md, singular configurations).

use super::{initial_step, normal_weight, rhs, weigh_error, DenseParts, Options, SecondOrderSystem, StepState, Stepper};
use crate::correct::ProjectionTolerance;
use crate::error::Result;

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
    st: StepState,
    y1: Vec<f64>,
    ysti: Vec<f64>,
    k: [Vec<f64>; 7],
    /// Dense output coefficients of the last step (5 x dim).
    rcont: [Vec<f64>; 5],
    facold: f64,
    reject: bool,
    /// Projection after every accepted step (and the filtered error estimate), on constrained
    /// systems.
    pub projection: Option<ProjectionTolerance>,
    /// The best conditioning of the constraints over the run's steps (`normal_weight`).
    kappa_ref: f64,
    /// The last accepted step away from singular configurations, and the steps taken near one.
    h_far: f64,
    pub near_steps: usize,
}

/// At a singular configuration -- the conditioning of the constraints below `AT_SINGULAR`
/// times the run's best -- the step does not shrink below `NEAR_STEP_FLOOR` times the last step
/// away from one (`normal_weight` = 1): there even the filtered error estimate is the rounding of
/// the right-hand side amplified by `1 / kappa^2` (docs/integrators.md, singular configurations).
pub const NEAR_STEP_FLOOR: f64 = 0.5;
/// Away from singular configurations a step whose projection moves the state by more than this
/// many units of the error tolerance (weighted RMS) is rejected.
pub const PROJECTION_MOVE_LIMIT: f64 = 10.0;
const ROUNDING_UNITS: f64 = 100.0;
pub const AT_SINGULAR: f64 = 1e-3;

impl Dopri5 {
    pub fn new(dim: usize, opts: Options) -> Result<Self> {
        let atol = opts.validate(dim)?;
        let z = || vec![0.0; dim];
        Ok(Dopri5 {
            opts,
            atol,
            st: StepState::new(dim),
            y1: z(),
            ysti: z(),
            k: [z(), z(), z(), z(), z(), z(), z()],
            rcont: [z(), z(), z(), z(), z()],
            facold: 1e-4,
            reject: false,
            projection: None,
            kappa_ref: 0.0,
            h_far: 0.0,
            near_steps: 0,
        })
    }
}

impl Stepper for Dopri5 {
    fn init<S: SecondOrderSystem>(&mut self, sys: &mut S, t0: f64, y0: &[f64], t_end: f64) -> Result<()> {
        self.st.start(t0, y0);
        self.facold = 1e-4;
        self.reject = false;
        rhs(sys, t0, &self.st.y, &mut self.k[0])?;
        self.kappa_ref = sys.conditioning_ratio();
        self.h_far = 0.0;
        self.near_steps = 0;
        self.st.stats.nfev += 1;
        let hmax = self.opts.max_step.min((t_end - t0).abs());
        self.st.h = match self.opts.first_step {
            Some(h) => h.min(hmax),
            None => {
                let [k0, k1, ..] = &mut self.k;
                initial_step(sys, t0, &self.st.y, k0, self.opts.rtol, &self.atol, 5, hmax, &mut self.y1, k1, &mut self.st.stats.nfev)?
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
        let dim = self.st.y.len();
        let hmax = self.opts.max_step;
        loop {
            self.st.check_attempt("DOPRI5", &self.opts)?;
            if self.st.t + 1.01 * self.st.h >= t_end {
                self.st.h = t_end - self.st.t;
            }
            let (t, h) = (self.st.t, self.st.h);
            let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
            let (y, ys) = (&self.st.y, &mut self.ysti);
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
            self.st.stats.nfev += 6;
            // the local error estimate (into ysti), filtered onto the tangent space at y1
            for i in 0..dim {
                ys[i] = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
            }
            // the part of the estimate across the constraints weighed by `normal_weight`
            let project = self.projection.is_some() && sys.n_constraints() > 0;
            let kappa = sys.conditioning_ratio();
            if project {
                weigh_error(sys, ys, dim / 2, self.kappa_ref);
            }
            let mut err = 0.0;
            for i in 0..dim {
                let sk = self.atol[i] + self.opts.rtol * y[i].abs().max(y1[i].abs());
                err += (ys[i] / sk) * (ys[i] / sk);
            }
            let err = (err / dim as f64).sqrt();
            if !err.is_finite() {
                // treat like a failed step: shrink hard
                self.st.h *= 0.1;
                self.reject = true;
                continue;
            }
            let fac11 = err.powf(EXPO1);
            let fac = (fac11 / self.facold.powf(BETA) / SAFE).clamp(FACC2, FACC1);
            let mut hnew = h / fac;
            // at a singular configuration the estimate cannot be trusted below a fraction of the
            // step the motion had away from it: the step goes over the configuration instead of
            // into it, and the projection lands it on its branch
            let near = project && normal_weight(kappa, self.kappa_ref) < 1.0;
            let at = project && kappa < AT_SINGULAR * self.kappa_ref;
            let floor = if at { NEAR_STEP_FLOOR * self.h_far } else { 0.0 };
            if err <= 1.0 || h.abs() <= floor {
                // the projection with the factorization of the last stage (at y1): the filtered
                // estimate leaves the error across the constraints to it, so a projection that
                // does not converge (that error beyond the reach of Newton) rejects the step
                let mut moved = 0.0;
                if let (true, Some(tol)) = (project, self.projection) {
                    ys.copy_from_slice(y1);
                    let n = dim / 2;
                    let (q1, v1) = y1.split_at_mut(n);
                    let out = sys.project_step(tph, q1, v1, tol)?;
                    if !out.converged {
                        self.st.h = 0.3 * h;
                        self.reject = true;
                        if self.st.stats.naccept >= 1 {
                            self.st.stats.nreject += 1;
                        }
                        continue;
                    }
                    // (weights with the rounding of the largest entry: a projection only
                    // moves below it at the rounding level)
                    let floor = ROUNDING_UNITS * f64::EPSILON * y1.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    for i in 0..dim {
                        let sk = self.atol[i] + self.opts.rtol * y1[i].abs() + floor;
                        moved += ((y1[i] - ys[i]) / sk).powi(2);
                    }
                    moved = (moved / dim as f64).sqrt();
                    // away from singular configurations the estimate measured the error across
                    // the constraints too: a projection far beyond it means the estimate was
                    // blind (an acceleration error the same in every stage, e.g. a huge force
                    // cancelled to its rounding), and the projection would land the state on a
                    // wrong point of the constraints
                    // (from the second step on: a start off the constraints moves the first)
                    if !near && moved > PROJECTION_MOVE_LIMIT && self.st.stats.naccept > 0 {
                        self.st.h = 0.3 * h;
                        self.reject = true;
                        if self.st.stats.naccept >= 1 {
                            self.st.stats.nreject += 1;
                        }
                        continue;
                    }
                } else {
                    ys.copy_from_slice(y1);
                }
                self.facold = err.max(1e-4);
                self.kappa_ref = self.kappa_ref.max(kappa);
                self.st.stats.naccept += 1;
                // dense output (ys: the step's own end); a projection moves the end point, and
                // the interpolant with it by theta (y1 - ys)
                let [r0, r1, r2, r3, r4] = &mut self.rcont;
                for i in 0..dim {
                    let ydiff = ys[i] - y[i];
                    let bspl = h * k1[i] - ydiff;
                    r0[i] = y[i];
                    r1[i] = y1[i] - y[i];
                    r2[i] = bspl;
                    r3[i] = ydiff - h * k7[i] - bspl;
                    r4[i] = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
                }
                std::mem::swap(k1, k7);
                std::mem::swap(&mut self.st.y, &mut self.y1);
                if moved > 1.0 {
                    rhs(sys, tph, &self.st.y, &mut self.k[0])?;
                    self.st.stats.nfev += 1;
                }
                self.st.t_old = t;
                self.st.t = if tph >= t_end { t_end } else { tph };
                hnew = hnew.abs().min(hmax);
                if self.reject {
                    hnew = hnew.min(h.abs());
                }
                if near {
                    // without a degree of freedom (a driven mechanism) the filtered estimate is
                    // zero: no step longer than the last one away from the singular configuration
                    self.near_steps += 1;
                    if self.h_far > 0.0 && sys.conditioning_rank() >= dim / 2 {
                        hnew = hnew.min(self.h_far);
                    }
                    hnew = hnew.max(floor);
                } else {
                    self.h_far = h.abs();
                }
                self.reject = false;
                self.st.h = hnew;
                return Ok(());
            }
            hnew = (h / FACC1.min(fac11 / SAFE)).max(floor);
            self.reject = true;
            if self.st.stats.naccept >= 1 {
                self.st.stats.nreject += 1;
            }
            self.st.h = hnew;
        }
    }

    fn dense_parts(&self) -> DenseParts<'_> {
        let [r0, r1, r2, r3, r4] = &self.rcont;
        DenseParts { meta: [self.st.t_old, self.st.t, 0.0], parts: [r0, r1, r2, r3, r4], count: 5 }
    }
    /// Hairer's 4th-order continuous extension (CONTD5):
    /// `y(t_old + theta h) = r0 + theta (r1 + (1 - theta) (r2 + theta (r3 + (1 - theta) r4)))`.
    fn dense_eval(meta: [f64; 3], parts: &[&[f64]], t: f64, out: &mut [f64]) {
        let [t_old, t_new, _] = meta;
        let h = t_new - t_old;
        let theta = if h == 0.0 { 1.0 } else { (t - t_old) / h };
        let theta1 = 1.0 - theta;
        let [r0, r1, r2, r3, r4] = [parts[0], parts[1], parts[2], parts[3], parts[4]];
        for i in 0..out.len() {
            out[i] = r0[i] + theta * (r1[i] + theta1 * (r2[i] + theta * (r3[i] + theta1 * r4[i])));
        }
    }
    /// Five parts `r0..r4` of the state's dimension.
    fn dense_dim(part_len: &[usize]) -> Option<usize> {
        match part_len {
            [d, rest @ ..] if rest.len() == 4 && rest.iter().all(|r| r == d) => Some(*d),
            _ => None,
        }
    }
    fn restart_at<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<()> {
        rhs(sys, self.st.t, &self.st.y, &mut self.k[0])?;
        self.st.stats.nfev += 1;
        Ok(())
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

