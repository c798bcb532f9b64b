//! RADAU5M's simplified Newton iteration on the stages and its error estimate (filtered onto
//! the constraints' tangent space near singular configurations).

use super::*;

/// With error control, from this user rtol up, Newton's stop also asks the velocity corrections to
/// be small, against `NEWTON_VELOCITY_SLACK` x the error test's velocity weights at Newton's
/// tolerances: after the position test passes it iterates on (at most `NEWTON_VELOCITY_EXTRA`
/// times) while the velocity norm, times its contraction factor (`theta_v / (1 - theta_v)`,
/// remembered from the last velocity iteration and relaxed like `faccon`), is above `fnewt` and
/// still contracts by `NEWTON_VELOCITY_CONTRACTION`. The position test alone decides contraction,
/// divergence, rejection and the iteration count the step control sees; corrections at their
/// rounding floor stop contracting, so the extra iteration moves the answer by rounding only. A
/// velocity contraction worse than `REFRESH_CONTRACTION` reads the velocity terms again. Without it
/// the damped cantilever's Newton left its fast overdamped modes' velocities off their slow path,
/// which the error test read as errors (docs/integrators.md, "The damped cantilever"). Below 1e-8
/// the spring of `test_rtol_means_what_solve_ivp_means` lost its tolerance proportionality (at rtol
/// 1e-9: 0.13 -> 0.26 rtol).
const NEWTON_VELOCITY_RTOL: f64 = 1e-8;
const NEWTON_VELOCITY_SLACK: f64 = 4.0;
const NEWTON_VELOCITY_EXTRA: usize = 2;
const NEWTON_VELOCITY_CONTRACTION: f64 = 0.5;

impl RadauM {
    /// One Newton attempt of step `h`. `Ok(Some(iterations))` on convergence, `Ok(None)` on
    /// divergence or slow convergence (`self.st.h` is then the step to retry with).
    pub(super) fn newton<S: SecondOrderSystem>(&mut self, sys: &mut S, h: f64) -> Result<Option<usize>> {
        let (n, m) = (self.n, self.m);
        let nm = n + m;
        let t0 = self.st.t;
        self.faccon = self.faccon.max(f64::EPSILON).powf(0.8);
        self.theta = self.theta.abs();
        self.theta_v = self.theta_v.max(f64::EPSILON).powf(0.8);
        let fv = if self.theta_v < 0.99 { self.theta_v / (1.0 - self.theta_v) } else { 1.0 };
        let mut dynold = 0.0f64;
        let mut thqold = 0.0f64;
        let velocity = self.ro.step.is_none() && self.opts.rtol >= NEWTON_VELOCITY_RTOL;
        // the velocity norm of the last iteration; the iteration where the positions converged
        let mut dvnold = f64::INFINITY;
        let mut converged: Option<usize> = None;
        for k in 1..=NIT + NEWTON_VELOCITY_EXTRA {
            if converged.is_none() && k > NIT {
                break;
            }
            self.stages(h);
            for i in 0..3 {
                let (r1, r2) = self.res[i].split_at_mut(n);
                let ok = sys.augmented_residual(t0 + self.c[i] * h, &self.qs[i], &self.vs[i], &self.w[i], &self.ls[i], r1, r2)?;
                if !ok {
                    return Err(Error::argument("method", "RADAU5M needs a system with the acceleration-level residual"));
                }
                self.st.stats.nfev += 1;
            }
            if !self.res.iter().all(|r| r.iter().all(|x| x.is_finite())) {
                let (q, qd) = (&self.qs, &self.vs);
                self.st.nonfinite = [("q", &q[2]), ("qd", &qd[2])]
                    .iter()
                    .find_map(|(w, v)| v.iter().position(|x| !x.is_finite()).map(|i| (*w, i)))
                    .or(Some(("qdd", 0)));
                return Ok(None);
            }
            if k == 1 && !(self.reuse && h == self.lu_h) {
                self.refresh_matrices(sys, h)?;
            }
            if !self.corot.is_empty() {
                self.corot.follow(&self.qs);
                self.corot.to_reference(&mut self.res);
            }
            // transformed right-hand sides: -(T^-1 (x) I) R
            for k2 in 0..nm {
                let (r0, r1, r2) = (self.res[0][k2], self.res[1][k2], self.res[2][k2]);
                self.xr[k2] = -(self.ti[0][0] * r0 + self.ti[0][1] * r1 + self.ti[0][2] * r2);
                self.xc[k2] = -(self.ti[1][0] * r0 + self.ti[1][1] * r1 + self.ti[1][2] * r2);
                self.xi[k2] = -(self.ti[2][0] * r0 + self.ti[2][1] * r1 + self.ti[2][2] * r2);
            }
            let nw = self.newton.as_mut().expect("RADAU5M: init first");
            nw.solve_pair(&mut self.xr, &mut self.xc, &mut self.xi);
            self.st.stats.newton += 1;
            // back: (T (x) I) X (turned to the stages: co-rotation); the norm of the position and
            // velocity corrections of all stages (one division per coordinate: six in the chain
            // of the sum cost their latency)
            let mut dyno = 0.0;
            let mut dvn = 0.0;
            for k2 in 0..nm {
                let (x0, x1, x2) = (self.xr[k2], self.xc[k2], self.xi[k2]);
                for i in 0..3 {
                    self.dw[i][k2] = self.t[i][0] * x0 + self.t[i][1] * x1 + self.t[i][2] * x2;
                }
            }
            if !self.corot.is_empty() {
                self.corot.from_reference(&mut self.dw);
            }
            for i in 0..3 {
                for k2 in 0..nm {
                    if k2 < n {
                        self.w[i][k2] += self.dw[i][k2];
                    } else {
                        self.ls[i][k2 - n] += self.dw[i][k2];
                    }
                }
            }
            for k2 in 0..n {
                let d: [f64; 3] = std::array::from_fn(|i| self.dw[i][k2]);
                let s = 1.0 / self.newton_scal(k2);
                for i in 0..3 {
                    let dq = h * h * (self.a2[i][0] * d[0] + self.a2[i][1] * d[1] + self.a2[i][2] * d[2]) * s;
                    let dv = h * h * (self.a[i][0] * d[0] + self.a[i][1] * d[1] + self.a[i][2] * d[2]) * s;
                    dyno += dq * dq + dv * dv;
                }
                if velocity {
                    let sc = self.newton_atol[n + k2] + self.newton_rtol * self.v0[k2].abs().max(self.vs[2][k2].abs());
                    let sv = 1.0 / (NEWTON_VELOCITY_SLACK * sc);
                    for i in 0..3 {
                        let dv = h * (self.a[i][0] * d[0] + self.a[i][1] * d[1] + self.a[i][2] * d[2]) * sv;
                        dvn += dv * dv;
                    }
                }
            }
            let dyno = (dyno / (6 * n) as f64).sqrt();
            let dvn = (dvn / (3 * n) as f64).sqrt();
            if !dyno.is_finite() || !dvn.is_finite() {
                self.st.nonfinite = Some(("qdd", 0));
                return Ok(None);
            }
            if let Some(kc) = converged {
                // past the positions' stop: on while the velocities contract
                self.theta_v = (dvn / dvnold).min(1.0);
                if self.theta_v > REFRESH_CONTRACTION {
                    self.refresh = true;
                }
                let fvk = if self.theta_v < 0.99 { self.theta_v / (1.0 - self.theta_v) } else { self.faccon };
                if fvk * dvn <= self.fnewt || k - kc >= NEWTON_VELOCITY_EXTRA || dvn > NEWTON_VELOCITY_CONTRACTION * dvnold {
                    self.stages(h);
                    return Ok(Some(kc));
                }
                dvnold = dvn;
                continue;
            }
            if k >= 2 {
                let thq = dyno / dynold;
                self.theta = if k == 2 { thq } else { (thq * thqold).sqrt() };
                thqold = thq;
                if self.theta < 0.99 {
                    self.faccon = self.theta / (1.0 - self.theta);
                    let dyth = self.faccon * dyno * self.theta.powi((NIT - 1 - k) as i32) / self.fnewt;
                    // with a fixed step there is no smaller step to move to: Newton goes on while
                    // it contracts (up to NIT iterations) instead of giving up on the prediction
                    if dyth >= 1.0 && self.ro.step.is_none() {
                        let qnewt = dyth.clamp(1e-4, 20.0);
                        self.st.h = 0.8 * h * qnewt.powf(-1.0 / (4.0 + NIT as f64 - 1.0 - k as f64));
                        return Ok(None);
                    }
                } else {
                    self.st.h = 0.5 * h;
                    return Ok(None);
                }
            }
            dynold = dyno.max(f64::EPSILON);
            if self.faccon * dyno <= self.fnewt {
                if velocity && self.faccon.min(fv) * dvn > self.fnewt && dvn <= NEWTON_VELOCITY_CONTRACTION * dvnold {
                    converged = Some(k);
                    dvnold = dvn;
                    continue;
                }
                self.stages(h);
                return Ok(Some(k));
            }
            dvnold = dvn;
        }
        self.st.h = 0.5 * h;
        Ok(None)
    }

    /// Hairer's filtered error estimate on the positions (module docs); `second`: the variant
    /// with a fresh evaluation at the estimated point (first step, after a rejection).
    pub(super) fn error_estimate<S: SecondOrderSystem>(&mut self, sys: &mut S, h: f64, filter: bool) -> Result<f64> {
        let n = self.n;
        let (hee1, hee2, hee3) = (rc::DD1 / h, rc::DD2 / h, rc::DD3 / h);
        // e = f_n + sum_i d_i Z_i / h, Z_i the stage increments
        for k in 0..n {
            let zq = |i: usize| self.qs[i][k] - self.q0[k];
            let zv = |i: usize| self.vs[i][k] - self.v0[k];
            self.eq[k] = self.v0[k] + hee1 * zq(0) + hee2 * zq(1) + hee3 * zq(2);
            self.ev[k] = self.a0[k] + hee1 * zv(0) + hee2 * zv(1) + hee3 * zv(2);
        }
        let mut err = self.filtered_norm(sys, h, filter);
        if err >= 1.0 && (self.first || self.reject) {
            // Hairer's second estimate: f at y_n + x instead of f_n (e_q += x_v, e_v += g(y_n + x) - a_n)
            let g = h * self.lambda;
            for k in 0..n {
                let xq = self.tmp[k];
                let xv = xq / g - self.eq[k];
                self.r1[k] = self.q0[k] + xq;
                // the velocities of the estimated point in the stage-1 buffer (rebuilt below)
                self.vs[0][k] = self.v0[k] + xv;
                self.eq[k] += xv;
            }
            sys.acc(self.st.t, &self.r1, &self.vs[0], &mut self.xc[..n])?;
            self.st.stats.nfev += 1;
            for k in 0..n {
                self.ev[k] += self.xc[k] - self.a0[k];
            }
            err = self.filtered_norm(sys, h, filter);
            self.stages(h);
        }
        Ok(err.max(1e-10))
    }

    /// `x_q` of the filtered estimate for the bracket in `eq`, `ev` (into `tmp[..n]`) and its
    /// weighted RMS norm.
    pub(super) fn filtered_norm<S: SecondOrderSystem>(&mut self, sys: &mut S, h: f64, tangent: bool) -> f64 {
        let n = self.n;
        let g = h * self.lambda;
        let nw = self.newton.as_mut().expect("RADAU5M: init first");
        if self.corot.is_empty() {
            nw.filtered_rhs(g, &self.eq, &self.ev, &mut self.tmp);
            nw.solve_real(&mut self.tmp);
        } else {
            // co-rotated: the bracket turned back to the reference, where the matrices were read,
            // and the filtered estimate forward to the step's end
            let [d0, d1, _] = &mut self.dw;
            let (eq, ev) = (&mut d0[..n], &mut d1[..n]);
            eq.copy_from_slice(&self.eq);
            ev.copy_from_slice(&self.ev);
            self.corot.turn_end(eq, false);
            self.corot.turn_end(ev, false);
            nw.filtered_rhs(g, eq, ev, &mut self.tmp);
            nw.solve_real(&mut self.tmp);
            self.corot.turn_end(&mut self.tmp[..n], true);
        }
        if tangent {
            weigh_error(sys, &mut self.tmp[..n], n, self.kappa_ref);
        }
        let mut s = 0.0;
        for i in 0..n {
            let v = self.tmp[i] / self.scal(i);
            s += v * v;
        }
        // the velocities' estimate: x_v = x_q / g - e_q (the second-order form of the filter)
        for i in 0..n {
            let xv = self.tmp[i] / g - self.eq[i];
            let sc = self.atol[n + i] + self.rtol * self.v0[i].abs().max(self.vs[2][i].abs());
            s += (xv / sc) * (xv / sc);
        }
        (s / (2 * n) as f64).sqrt()
    }
}
