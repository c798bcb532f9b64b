//! A bushing: linear stiffness and damping in x, y and the angle between two markers. The
//! offset `d = R_b^T (r_a - r_b)` of `a` from `b` is measured in `b`'s frame, the angle is
//! `phi_a - phi_b`; both are zero-load at the initial guess. With `f = K (d - d_0) + C d'`,
//! `tau = k_phi (angle - angle_0) + c_phi w`, the generalized force is the virtual work of the
//! potential's gradient (its damping part on the same virtual displacements):
//! `Q = -(r_a - r_b)_q^T R_b f - phi_{b,q}^T (f_x d_y - f_y d_x) - (phi_a - phi_b)_q^T tau`,
//! so forces and moments balance between the two bodies.

use crate::body::{Body, Marker, MarkerState};
use crate::constraint::BuildContext;
use crate::description::MarkerDesc;
use crate::error::{non_negative, Result};

#[derive(Debug, Clone)]
pub struct Bushing {
    pub a: Marker,
    pub b: Marker,
    pub stiffness: [f64; 3],
    pub damping: [f64; 3],
    /// Offset and angle at the initial guess.
    pub rest: [f64; 3],
}

/// Offset (in `b`'s frame), its rate, the relative angle and rate.
#[inline]
fn kinematics(sa: &MarkerState, sb: &MarkerState) -> ([f64; 3], [f64; 3]) {
    let (c, s) = (sb.phi.cos(), sb.phi.sin());
    let (dx, dy) = (sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]);
    let (vx, vy) = (sa.v[0] - sb.v[0], sa.v[1] - sb.v[1]);
    let d = [c * dx + s * dy, -s * dx + c * dy, sa.phi - sb.phi];
    let dd = [c * vx + s * vy + sb.omega * d[1], -s * vx + c * vy - sb.omega * d[0], sa.omega - sb.omega];
    (d, dd)
}

impl Bushing {
    pub fn from_desc(ctx: &BuildContext, item: &str, a: &MarkerDesc, b: &MarkerDesc, stiffness: [f64; 3], damping: [f64; 3]) -> Result<Bushing> {
        let (a, b) = (ctx.oriented_marker(item, a)?, ctx.oriented_marker(item, b)?);
        let mut k = [0.0; 3];
        let mut c = [0.0; 3];
        for i in 0..3 {
            k[i] = non_negative(item, "stiffness", stiffness[i])?;
            c[i] = non_negative(item, "damping", damping[i])?;
        }
        let (rest, _) = kinematics(&ctx.state0(&a), &ctx.state0(&b));
        Ok(Bushing { a, b, stiffness: k, damping: c, rest })
    }

    #[inline]
    pub fn add_to(&self, bodies: &[Body], q: &[f64], qd: &[f64], qvec: &mut [f64]) {
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        let (d, dd) = kinematics(&sa, &sb);
        let mut f = [0.0; 3];
        for i in 0..3 {
            f[i] = self.stiffness[i] * (d[i] - self.rest[i]) + self.damping[i] * dd[i];
        }
        let (c, s) = (sb.phi.cos(), sb.phi.sin());
        let fw = [c * f[0] - s * f[1], s * f[0] + c * f[1]];
        self.a.add_point_jacobian(bodies, &sa, [-fw[0], -fw[1]], qvec);
        self.b.add_point_jacobian(bodies, &sb, fw, qvec);
        self.b.add_angle_jacobian(bodies, &sb, -(f[0] * d[1] - f[1] * d[0]), qvec);
        self.a.add_angle_jacobian(bodies, &sa, -f[2], qvec);
        self.b.add_angle_jacobian(bodies, &sb, f[2], qvec);
    }

    /// `K = sum_i k_i p_i p_i^T` with `p_i = (d_i)_q`, the rows whose products with `qd` are
    /// the rates of `kinematics` (`p`: an `n` scratch; see `Force::add_stiffness`).
    pub fn add_stiffness(&self, bodies: &[Body], q: &[f64], qd: &[f64], p: &mut [f64], add: &mut dyn FnMut(usize, usize, f64)) {
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        let (d, _) = kinematics(&sa, &sb);
        let (c, s) = (sb.phi.cos(), sb.phi.sin());
        for (i, &k) in self.stiffness.iter().enumerate().filter(|(_, k)| **k > 0.0) {
            p.fill(0.0);
            match i {
                0 => {
                    self.a.add_point_jacobian(bodies, &sa, [c, s], p);
                    self.b.add_point_jacobian(bodies, &sb, [-c, -s], p);
                    self.b.add_angle_jacobian(bodies, &sb, d[1], p);
                }
                1 => {
                    self.a.add_point_jacobian(bodies, &sa, [-s, c], p);
                    self.b.add_point_jacobian(bodies, &sb, [s, -c], p);
                    self.b.add_angle_jacobian(bodies, &sb, -d[0], p);
                }
                _ => {
                    self.a.add_angle_jacobian(bodies, &sa, 1.0, p);
                    self.b.add_angle_jacobian(bodies, &sb, -1.0, p);
                }
            }
            super::outer(p, p, k, add);
        }
    }

    pub fn potential(&self, bodies: &[Body], q: &[f64]) -> f64 {
        let zeros = vec![0.0; q.len()];
        let (d, _) = kinematics(&self.a.state(bodies, q, &zeros), &self.b.state(bodies, q, &zeros));
        (0..3).map(|i| 0.5 * self.stiffness[i] * (d[i] - self.rest[i]).powi(2)).sum()
    }

    /// `1/2 sum k_i d_i'^2` for the motion `v`.
    pub fn material_energy(&self, bodies: &[Body], q: &[f64], v: &[f64]) -> f64 {
        let (_, dd) = kinematics(&self.a.state(bodies, q, v), &self.b.state(bodies, q, v));
        (0..3).map(|i| 0.5 * self.stiffness[i] * dd[i] * dd[i]).sum()
    }
}
