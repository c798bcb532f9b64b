//! Drivers (one row each) between two markers whose `z` axes a joint keeps parallel, with any
//! `Motion` (`f, f', f''`):
//!
//! * rotation of `x_j` about `z_i` from `x_i`: with `s = y_i . x_j`, `c = x_i . x_j`,
//!   `Phi = s cos f - c sin f` (`= rho sin(theta - f)`), `Phi_q = cos f J_s - sin f J_c`,
//!   `Phi_t = -f' w` (`w = s sin f + c cos f`),
//!   `gamma = -(cos f h_s - sin f h_c) + 2 f' (sin f sd + cos f cd) + f'' w + f'^2 Phi`.
//!   No angle is computed: the row is smooth through `theta = +-pi` and any number of turns.
//! * translation of `P_j` along `z_i`: `Phi = z_i . d - f`, `Phi_t = -f'`, `gamma = -h + f''`.

use super::{prim, Pair};
use crate::body::Body;
use crate::constraint::{ConstraintOut, Motion};

#[derive(Debug, Clone)]
pub struct RotationDriver {
    pub pair: Pair,
    pub motion: Motion,
}

impl RotationDriver {
    /// The marker axes its row reads (`x_i`, `y_i`; `x_j`).
    pub const AXES: [u8; 2] = [0b011, 0b001];

    #[inline]
    pub fn eval(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
        let (si, sj) = self.pair.states_axes(bodies, q, qd, Self::AXES);
        let (f, fd, fdd) = self.motion.eval(t, out.scratch);
        let (sf, cf) = f.sin_cos();
        let (xi, yi, xj) = (&si.axes[0], &si.axes[1], &sj.axes[0]);
        let (s, sd, hs) = prim::dot_terms(yi, xj);
        let (c, cd, hc) = prim::dot_terms(xi, xj);
        let phi = s * cf - c * sf;
        let w = s * sf + c * cf;
        let layout = Some(out.layout);
        let row = &mut out.jac[0..n];
        prim::dot_jacobian(bodies, &si, yi, &sj, xj, cf, row, layout);
        prim::dot_jacobian(bodies, &si, xi, &sj, xj, -sf, row, layout);
        if let Some(p) = out.phi.as_deref_mut() {
            p[0] = phi;
        }
        out.phi_t[0] = -fd * w;
        out.gamma[0] = -(cf * hs - sf * hc) + 2.0 * fd * (sf * sd + cf * cd) + fdd * w + fd * fd * phi;
    }

    /// The driven angle `f + atan2(Phi, w)` at `(t, q)` (continuous while `|theta - f| < pi`).
    pub fn angle(&self, bodies: &[Body], t: f64, q: &[f64], scratch: &mut [f64]) -> f64 {
        let zero = vec![0.0; q.len()];
        let (si, sj) = self.pair.states(bodies, q, &zero);
        let f = self.motion.eval(t, scratch).0;
        let (sf, cf) = f.sin_cos();
        let s = crate::spatial::rot::dot(&si.axes[1].v, &sj.axes[0].v);
        let c = crate::spatial::rot::dot(&si.axes[0].v, &sj.axes[0].v);
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
    pub fn eval(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
        let (si, sj) = self.pair.states_axes(bodies, q, qd, Self::AXES);
        let (f, fd, fdd) = self.motion.eval(t, out.scratch);
        let a = &si.axes[2];
        let (v, _, h) = prim::dot2_terms(a, &si, &sj);
        let layout = Some(out.layout);
        prim::dot2_jacobian(bodies, a, &si, &sj, 1.0, &mut out.jac[0..n], layout);
        if let Some(p) = out.phi.as_deref_mut() {
            p[0] = v - f;
        }
        out.phi_t[0] = -fd;
        out.gamma[0] = -h + fdd;
    }
}
