//! Drivers (one row each) between two markers whose `z` axes a joint keeps parallel, with any
//! `Motion` (`f, f', f''`):
//!
//! * rotation of `x_j` about `z_i` from `x_i`: with `s = y_i . x_j`, `c = x_i . x_j`,
//!   `rho^2 = s^2 + c^2` (1 on the joint), the angle `theta = atan2(s, c)` and
//!   `Phi = wrap(theta - f)` = `atan2(s cos f - c sin f, s sin f + c cos f)`, the angle error
//!   wrapped to the nearest turn: smooth through any number of turns, with one root per turn
//!   (the former row `rho sin(theta - f)` also vanished at `theta = f + pi`, where a correction
//!   from a guess more than a quarter turn off landed). `Phi_q = (c J_s - s J_c) / rho^2`,
//!   `Phi_t = -f'`, `gamma = f'' - (c h_s - s h_c) / rho^2 + 2 (c sd - s cd)(s sd + c cd) / rho^4`.
//! * translation of `P_j` along `z_i`: `Phi = z_i . d - f`, `Phi_t = -f'`, `gamma = -h + f''`.

use super::{prim, Pair};
use crate::body::marker3::{Marker3State, NO_POINT_RATE};
use crate::body::Body;
use crate::constraint::{ConstraintOut, Motion};

#[derive(Debug, Clone)]
pub struct RotationDriver {
    pub pair: Pair,
    pub motion: Motion,
}

impl RotationDriver {
    /// The marker axes its row reads (`x_i`, `y_i`; `x_j`); not the points' rates.
    pub const AXES: [u8; 2] = [0b011 | NO_POINT_RATE, 0b001 | NO_POINT_RATE];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, t: f64, n: usize, out: &mut ConstraintOut) {
        let (f, fd, fdd) = self.motion.eval(t, out.scratch);
        let (sf, cf) = f.sin_cos();
        let (xi, yi, xj) = (&si.axes[0], &si.axes[1], &sj.axes[0]);
        let (s, sd, hs) = prim::dot_terms(yi, xj);
        let (c, cd, hc) = prim::dot_terms(xi, xj);
        let rho2 = s * s + c * c;
        let layout = Some(out.layout);
        let row = &mut out.jac[0..n];
        prim::dot_jacobian(bodies, si, yi, sj, xj, c / rho2, row, layout);
        prim::dot_jacobian(bodies, si, xi, sj, xj, -s / rho2, row, layout);
        if let Some(p) = out.phi.as_deref_mut() {
            p[0] = (s * cf - c * sf).atan2(s * sf + c * cf);
        }
        out.phi_t[0] = -fd;
        out.gamma[0] = fdd - (c * hs - s * hc) / rho2 + 2.0 * (c * sd - s * cd) * (s * sd + c * cd) / (rho2 * rho2);
    }

    /// The driven angle `f + Phi` at `(t, q)` (continuous while `|theta - f| < pi`).
    pub fn angle(&self, bodies: &[Body], t: f64, q: &[f64], scratch: &mut [f64]) -> f64 {
        let zero = vec![0.0; q.len()];
        let (si, sj) = self.pair.states(bodies, q, &zero);
        let f = self.motion.eval(t, scratch).0;
        let (sf, cf) = f.sin_cos();
        let s = crate::linalg::rot3::dot(&si.axes[1].v, &sj.axes[0].v);
        let c = crate::linalg::rot3::dot(&si.axes[0].v, &sj.axes[0].v);
        f + (s * cf - c * sf).atan2(s * sf + c * cf)
    }
}

#[derive(Debug, Clone)]
pub struct TranslationDriver {
    pub pair: Pair,
    pub motion: Motion,
}

impl TranslationDriver {
    /// The marker axes its row reads (`z_i`).
    pub const AXES: [u8; 2] = [0b100, 0];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, t: f64, n: usize, out: &mut ConstraintOut) {
        let (f, fd, fdd) = self.motion.eval(t, out.scratch);
        let a = &si.axes[2];
        let (v, _, h) = prim::dot2_terms(a, si, sj);
        let layout = Some(out.layout);
        prim::dot2_jacobian(bodies, a, si, sj, 1.0, &mut out.jac[0..n], layout);
        if let Some(p) = out.phi.as_deref_mut() {
            p[0] = v - f;
        }
        out.phi_t[0] = -fd;
        out.gamma[0] = -h + fdd;
    }
}
