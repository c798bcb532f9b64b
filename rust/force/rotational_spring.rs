//! A rotational spring-damper between two marker frames (`b`: the ground when absent):
//! `tau = -k (angle - rest_angle) - c w` on `a`, `-tau` on `b`, with `angle = phi_a - phi_b`
//! and `w = omega_a - omega_b`. With `k = 0` it is the viscous friction of a hinge.

use super::motor::{frame_or_ground, relative};
use crate::body::{Body, Marker};
use crate::constraint::BuildContext;
use crate::description::MarkerDesc;
use crate::error::{check_finite_item, non_negative, Result};

#[derive(Debug, Clone)]
pub struct RotationalSpringDamper {
    pub a: Marker,
    pub b: Marker,
    pub stiffness: f64,
    pub damping: f64,
    pub rest_angle: f64,
}

impl RotationalSpringDamper {
    pub fn from_desc(ctx: &BuildContext, item: &str, a: &MarkerDesc, b: Option<&MarkerDesc>, stiffness: f64, damping: f64, rest_angle: Option<f64>) -> Result<Self> {
        let (a, b) = (ctx.oriented_marker(item, a)?, frame_or_ground(ctx, item, b)?);
        let rest_angle = match rest_angle {
            Some(r) => {
                check_finite_item(item, "rest_angle", &[r])?;
                r
            }
            None => ctx.state0(&a).phi - ctx.state0(&b).phi,
        };
        Ok(RotationalSpringDamper { a, b, stiffness: non_negative(item, "stiffness", stiffness)?, damping: non_negative(item, "damping", damping)?, rest_angle })
    }

    #[inline]
    pub fn add_to(&self, bodies: &[Body], q: &[f64], qd: &[f64], qvec: &mut [f64]) {
        let (sa, sb, [angle, w]) = relative(bodies, &self.a, &self.b, q, qd);
        let tau = -self.stiffness * (angle - self.rest_angle) - self.damping * w;
        self.a.add_angle_jacobian(bodies, &sa, tau, qvec);
        self.b.add_angle_jacobian(bodies, &sb, -tau, qvec);
    }

    /// `K = k p p^T`, `p = (phi_a - phi_b)_q` (`p`: an `n` scratch; see `Force::add_stiffness`).
    pub fn add_stiffness(&self, bodies: &[Body], q: &[f64], qd: &[f64], p: &mut [f64], add: &mut dyn FnMut(usize, usize, f64)) {
        let (sa, sb, _) = relative(bodies, &self.a, &self.b, q, qd);
        p.fill(0.0);
        self.a.add_angle_jacobian(bodies, &sa, 1.0, p);
        self.b.add_angle_jacobian(bodies, &sb, -1.0, p);
        super::outer(p, p, self.stiffness, add);
    }

    pub fn potential(&self, bodies: &[Body], q: &[f64]) -> f64 {
        let zeros = vec![0.0; q.len()];
        let (_, _, [angle, _]) = relative(bodies, &self.a, &self.b, q, &zeros);
        0.5 * self.stiffness * (angle - self.rest_angle).powi(2)
    }

    /// `1/2 k wdot^2` for the motion `v` (the spring's share of a mode's stiffness).
    pub fn material_energy(&self, bodies: &[Body], q: &[f64], v: &[f64]) -> f64 {
        let (_, _, [_, w]) = relative(bodies, &self.a, &self.b, q, v);
        0.5 * self.stiffness * w * w
    }
}
