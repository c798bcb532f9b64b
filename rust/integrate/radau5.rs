//! 3-stage Radau IIA (order 5), Hairer & Wanner's `RADAU5` (Solving ODEs II, IV.8): simplified
//! Newton with the transformed real + complex iteration matrices, LU reused over steps while
//! the Newton contraction stays small, Gustafsson's predictive step control, collocation dense
//! output; the iteration matrices reduced to n x n by the second-order structure (module docs
//! of `integrate`).

use super::lu::{lu_cm, lu_cm_solve, lu_cplx, lu_cplx_solve};
use super::newton::NewtonMatrices;
use crate::band_lu::C64;
use crate::sparse_newton::BandNewton;
use super::{initial_step, rhs, rms_norm, weigh_error, DenseParts, Options, SecondOrderSystem, StepState, Stepper};
use crate::error::{Error, Result};

pub(super) mod rc {
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
    st: StepState,
    h_old: f64,
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
    /// The best conditioning of the constraints over the run's steps (`normal_weight`).
    kappa_ref: f64,
    first: bool,
    reject: bool,
    caljac: bool,
    need_jac: bool,
    need_dec: bool,
    nsing: usize,
    /// With the structured Jacobian of a system that has the sparse structure: the saddle-point
    /// form of both iteration matrices in band storage (`BandNewton::solve_first_order_*`;
    /// `jq`, `jv`, `e1`, `e2r`, `e2i` then stay empty). Chosen in `init`.
    band: Option<Box<BandNewton>>,
}

pub(super) const NIT: usize = 7;
/// Re-evaluate the Jacobian after a step only if the Newton contraction exceeded this.
/// RADAU5's default is 0.001 (cheap Jacobians); Hairer recommends 0.1 when the Jacobian is
/// costly, as here (a finite-difference Jacobian is ~4n UK calls). Measured on the paper scene:
/// 20x fewer Jacobians, 3x faster with beam damping (docs/performance.md).
const THET: f64 = 0.1;
pub(super) const SAFE: f64 = 0.9;
pub(super) const FACL: f64 = 5.0;
pub(super) const FACR: f64 = 0.125;
pub(super) const QUOT1: f64 = 1.0;
pub(super) const QUOT2: f64 = 1.2;

impl Radau5 {
    pub fn new(n: usize, opts: Options) -> Result<Self> {
        let dim = 2 * n;
        let atol_user = opts.validate(dim)?;
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
            st: StepState::new(dim),
            h_old: 0.0,
            f0: z(),
            z: [z(), z(), z()],
            w: [z(), z(), z()],
            cont: [z(), z(), z(), z()],
            scal: z(),
            tmp: z(),
            tmp2: z(),
            ystage: z(),
            jq: Vec::new(),
            jv: Vec::new(),
            e1: Vec::new(),
            e2r: Vec::new(),
            e2i: Vec::new(),
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
            kappa_ref: 0.0,
            first: true,
            reject: false,
            caljac: false,
            need_jac: true,
            need_dec: true,
            nsing: 0,
            band: None,
        })
    }

    fn update_scal(&mut self) {
        for i in 0..self.st.y.len() {
            self.scal[i] = self.atol[i] + self.rtol * self.st.y[i].abs();
        }
    }

    /// Real and complex reduced iteration matrices for the current h.
    fn decompose(&mut self) -> bool {
        let n = self.n;
        self.fac1 = self.u1 / self.st.h;
        self.alphn = self.alph / self.st.h;
        self.betan = self.beta / self.st.h;
        let (f, a, b) = (self.fac1, self.alphn, self.betan);
        if let Some(band) = self.band.as_mut() {
            // the saddle-point forms [M + C/g + K/g^2, A^T; A - Bv/g, reg I] for g = f, a + i b
            self.st.stats.nlu += 2;
            let g = C64::new(a, b);
            let gi = C64::new(1.0, 0.0) / g;
            let scale = band.s.mass_scale();
            return [0.0, -1e-12 * scale].into_iter().any(|reg| band.factor_real(1.0 / (f * f), 1.0 / f, reg) && band.factor_complex(gi * gi, gi, reg));
        }
        // E1 = f^2 I - f Jv - Jq ; E2 = g^2 I - g Jv - Jq, g = a + i b
        let (g2r, g2i) = (a * a - b * b, 2.0 * a * b);
        for i in 0..n {
            for j in 0..n {
                let (jq, jv) = (self.jq[i * n + j], self.jv[i * n + j]);
                self.e1[i + j * n] = -f * jv - jq; // column-major for lu_cm
                self.e2r[i * n + j] = -a * jv - jq;
                self.e2i[i * n + j] = -b * jv;
            }
            self.e1[i * n + i] += f * f;
            self.e2r[i * n + i] += g2r;
            self.e2i[i * n + i] += g2i;
        }
        self.st.stats.nlu += 2;
        lu_cm(&mut self.e1, &mut self.piv1, n) && lu_cplx(&mut self.e2r, &mut self.e2i, &mut self.piv2, n)
    }

    /// `x <- (fac1 I - J)^-1 x` for a 2n vector.
    fn solve_real(&mut self, x: &mut [f64]) {
        let n = self.n;
        let f = self.fac1;
        if let Some(band) = self.band.as_mut() {
            band.solve_first_order_real(f, x);
            return;
        }
        let (r1, r2) = x.split_at_mut(n);
        // rhs = f r2 + Jq r1
        for i in 0..n {
            let s: f64 = self.jq[i * n..(i + 1) * n].iter().zip(r1.iter()).map(|(a, b)| a * b).sum();
            self.br[i] = f * r2[i] + s;
        }
        lu_cm_solve(&self.e1, &self.piv1, n, &mut self.br);
        for i in 0..n {
            r2[i] = self.br[i];
            r1[i] = (r1[i] + self.br[i]) / f;
        }
    }

    /// `(xr + i xi) <- ((alphn + i betan) I - J)^-1 (xr + i xi)`.
    fn solve_cplx(&mut self, xr: &mut [f64], xi: &mut [f64]) {
        let n = self.n;
        let (a, b) = (self.alphn, self.betan);
        if let Some(band) = self.band.as_mut() {
            band.solve_first_order_complex(C64::new(a, b), xr, xi);
            return;
        }
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
        let dim = self.st.y.len();
        let (hee1, hee2, hee3) = (rc::DD1 / self.st.h, rc::DD2 / self.st.h, rc::DD3 / self.st.h);
        let mut tmp = std::mem::take(&mut self.tmp);
        let mut tmp2 = std::mem::take(&mut self.tmp2);
        for i in 0..dim {
            tmp2[i] = hee1 * self.z[0][i] + hee2 * self.z[1][i] + hee3 * self.z[2][i];
            tmp[i] = tmp2[i] + self.f0[i];
        }
        self.solve_real(&mut tmp);
        // with a projection after each step: the part across the constraints weighed by
        // `normal_weight` (the last kernel call was the third stage, at about y_{n+1})
        let filter = sys.projects();
        if filter {
            weigh_error(sys, &mut tmp, dim / 2, self.kappa_ref);
        }
        let mut err = rms_norm(&tmp, &self.scal).max(1e-10);
        if err >= 1.0 && (self.first || self.reject) {
            for i in 0..dim {
                self.ystage[i] = self.st.y[i] + tmp[i];
            }
            let mut ystage = std::mem::take(&mut self.ystage);
            let r = rhs(sys, self.st.t, &ystage, &mut tmp);
            self.st.stats.nfev += 1;
            for i in 0..dim {
                tmp[i] += tmp2[i];
            }
            std::mem::swap(&mut self.ystage, &mut ystage);
            r?;
            self.solve_real(&mut tmp);
            if filter {
                weigh_error(sys, &mut tmp, dim / 2, self.kappa_ref);
            }
            err = rms_norm(&tmp, &self.scal).max(1e-10);
        }
        self.tmp = tmp;
        self.tmp2 = tmp2;
        Ok(err)
    }

    fn fail_newton(&mut self, factor: f64) {
        self.st.h *= factor;
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
        self.st.start(t0, y0);
        self.first = true;
        self.reject = false;
        self.caljac = false;
        self.need_jac = true;
        self.need_dec = true;
        self.faccon = 1.0;
        self.theta = THET;
        self.nsing = 0;
        // the structured Jacobian is a saddle-point solve: sparse where it pays
        self.band = if sys.structured_jacobian() { NewtonMatrices::band_for_system(sys, self.opts.linear_solver, true, "RADAU5")?.map(Box::new) } else { None };
        if self.band.is_none() && self.jq.len() != self.n * self.n {
            let nn = self.n * self.n;
            for v in [&mut self.jq, &mut self.jv, &mut self.e1, &mut self.e2r, &mut self.e2i] {
                *v = vec![0.0; nn];
            }
        }
        rhs(sys, t0, &self.st.y, &mut self.f0)?;
        self.kappa_ref = sys.conditioning_ratio();
        self.st.stats.nfev += 1;
        self.update_scal();
        let hmax = self.opts.max_step.min((t_end - t0).abs());
        self.st.h = match self.opts.first_step {
            Some(h) => h.min(hmax),
            None => {
                let (mut a, mut b) = (std::mem::take(&mut self.tmp), std::mem::take(&mut self.tmp2));
                let r = initial_step(sys, t0, &self.st.y, &self.f0, self.opts.rtol, &self.opts.validate(self.st.y.len())?, 3, hmax, &mut a, &mut b, &mut self.st.stats.nfev);
                self.tmp = a;
                self.tmp2 = b;
                r?
            }
        };
        self.h_old = self.st.h;
        for c in self.cont.iter_mut() {
            c.fill(0.0);
        }
        self.cont[0].copy_from_slice(y0);
        Ok(())
    }

    fn step<S: SecondOrderSystem>(&mut self, sys: &mut S, t_end: f64) -> Result<()> {
        use rc::*;
        let dim = self.st.y.len();
        let cfac = SAFE * (1.0 + 2.0 * NIT as f64);
        let hmax = self.opts.max_step;
        loop {
            if self.st.t + self.st.h > t_end {
                self.st.h = t_end - self.st.t;
                self.need_dec = true;
            }
            if self.need_jac {
                let n = self.n;
                let (q, qd) = self.st.y.split_at(n);
                match self.band.as_mut() {
                    Some(band) => {
                        sys.structure_sparse(self.st.t, q, qd, &mut band.s)?;
                    }
                    None => sys.jac(self.st.t, q, qd, &mut self.jq, &mut self.jv)?,
                }
                self.st.stats.njev += 1;
                self.caljac = true;
                self.need_jac = false;
                self.need_dec = true;
            }
            if self.need_dec {
                self.need_dec = false;
                if !self.decompose() {
                    self.nsing += 1;
                    if self.nsing >= 5 {
                        return Err(Error::Solver(format!("RADAU5: iteration matrix repeatedly singular at t = {}", self.st.t)));
                    }
                    self.st.h *= 0.5;
                    self.reject = true;
                    self.need_dec = true;
                    continue;
                }
            }
            self.st.check_attempt("RADAU5", &self.opts)?;
            let (t, h) = (self.st.t, self.st.h);
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
                        self.ystage[i] = self.st.y[i] + self.z[k][i];
                    }
                    let mut ystage = std::mem::take(&mut self.ystage);
                    let r = rhs(sys, t + c * h, &ystage, &mut self.z[k]);
                    std::mem::swap(&mut self.ystage, &mut ystage);
                    r?;
                }
                self.st.stats.nfev += 3;
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
                self.st.stats.newton += 1;
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
                if self.st.stats.naccept >= 1 {
                    self.st.stats.nreject += 1;
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
                self.st.stats.naccept += 1;
                self.nsing = 0;
                self.kappa_ref = self.kappa_ref.max(sys.conditioning_ratio());
                // Gustafsson's predictive controller
                if self.st.stats.naccept > 1 {
                    let facgus = ((self.hacc / h) * (err * err / self.erracc).powf(0.25) / SAFE).clamp(FACR, FACL);
                    quot = quot.max(facgus);
                    hnew = h / quot;
                }
                self.hacc = h;
                self.erracc = err.max(1e-2);
                self.st.t_old = t;
                self.h_old = h;
                self.st.t = if xph >= t_end { t_end } else { xph };
                let [z1, z2, z3] = &self.z;
                let [c0, c1, c2, c3] = &mut self.cont;
                for i in 0..dim {
                    self.st.y[i] += z3[i];
                    let (z1i, z2i, z3i) = (z1[i], z2[i], z3[i]);
                    c1[i] = (z2i - z3i) / C2M1;
                    let ak = (z1i - z2i) / C1MC2;
                    let acont3 = (ak - z1i / C1) / C2;
                    c2[i] = (ak - c1[i]) / C1M1;
                    c3[i] = c2[i] - acont3;
                    c0[i] = self.st.y[i];
                }
                self.update_scal();
                rhs(sys, self.st.t, &self.st.y, &mut self.f0)?;
                self.st.stats.nfev += 1;
                hnew = hnew.abs().min(hmax);
                if self.reject {
                    hnew = hnew.min(h.abs());
                }
                self.reject = false;
                let keep = if self.st.t + hnew / QUOT1 >= t_end {
                    self.st.h = t_end - self.st.t;
                    false
                } else {
                    let qt = hnew / h;
                    if self.theta <= THET && (QUOT1..=QUOT2).contains(&qt) {
                        true
                    } else {
                        self.st.h = hnew;
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
                self.st.h *= 0.1;
            } else {
                self.st.h = hnew;
            }
            if self.st.stats.naccept >= 1 {
                self.st.stats.nreject += 1;
            }
            self.need_dec = true;
        }
    }

    fn dense_parts(&self) -> DenseParts<'_> {
        let [c0, c1, c2, c3] = &self.cont;
        let h = if self.st.t == self.st.t_old { 0.0 } else { self.h_old };
        DenseParts { meta: [self.st.t_old, self.st.t, h], parts: [c0, c1, c2, c3, &[]], count: 4 }
    }
    /// The collocation polynomial of the step (Hairer's CONTR5, order 3 in between the nodes,
    /// the step's order 5 at its end): `s = (t - t_new) / h`,
    /// `y = c0 + s (c1 + (s - c2 + 1) (c2' + (s - c1 + 1) c3))`.
    fn dense_eval(meta: [f64; 3], parts: &[&[f64]], t: f64, out: &mut [f64]) {
        use rc::*;
        let [_, t_new, h] = meta;
        let [c0, c1, c2, c3] = [parts[0], parts[1], parts[2], parts[3]];
        if h == 0.0 {
            out.copy_from_slice(c0);
            return;
        }
        let s = (t - t_new) / h;
        for i in 0..out.len() {
            out[i] = c0[i] + s * (c1[i] + (s - C2M1) * (c2[i] + (s - C1M1) * c3[i]));
        }
    }
    /// Four parts `c0..c3` of the state's dimension.
    fn dense_dim(part_len: &[usize]) -> Option<usize> {
        match part_len {
            [d, rest @ ..] if rest.len() == 3 && rest.iter().all(|r| r == d) => Some(*d),
            _ => None,
        }
    }
    fn restart_at<S: SecondOrderSystem>(&mut self, sys: &mut S) -> Result<()> {
        // the post-step hook moved y: the collocation polynomial follows by (1 + s) (y - c0),
        // so the dense output still ends at the state
        let [c0, c1, ..] = &mut self.cont;
        for i in 0..c0.len() {
            let d = self.st.y[i] - c0[i];
            c0[i] += d;
            c1[i] += d;
        }
        rhs(sys, self.st.t, &self.st.y, &mut self.f0)?;
        self.st.stats.nfev += 1;
        self.update_scal();
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

