//! Applied forces other than gravity (which is a body-level term in `dynamics.rs`).
//! Each adds its generalized force `J^T F` to `Q` (paper eqs. 34-37).

use crate::body::{Body, Marker};
use crate::constraint::BuildContext;
use crate::description::ForceDesc;
use crate::error::{check_finite_item, non_negative, Result};

#[derive(Debug, Clone)]
pub enum ForceKind {
    /// Constant world-frame force at a marker: `Q += r_q^T F`.
    PointForce { point: Marker, force: [f64; 2] },
    /// Constant torque on a marker frame: `Q += phi_q^T tau`.
    Torque { frame: Marker, torque: f64 },
    /// Linear spring-damper between two markers:
    /// `Q -= (k (l - l0) + c l_dot) (r_a - r_b)_q^T e`, `e = (r_a - r_b) / l`.
    SpringDamper { a: Marker, b: Marker, stiffness: f64, damping: f64, rest_length: f64 },
    /// Spatial force elements, gravity included (`spatial/force.rs`).
    Spatial(crate::spatial::force::SpatialForce),
}

#[derive(Debug, Clone)]
pub struct Force {
    pub name: String,
    pub kind: ForceKind,
}

impl Force {
    /// Write the defaults this force resolved into its description (a spring-damper's rest
    /// length taken at the initial guess).
    pub fn fill_defaults(&self, d: &mut ForceDesc) {
        if let (ForceKind::SpringDamper { rest_length: r, .. }, ForceDesc::SpringDamper { rest_length, .. }) = (&self.kind, d) {
            *rest_length = Some(*r);
        }
    }

    /// Build a force element; `item` names it in errors.
    pub fn from_desc(ctx: &BuildContext, item: &str, name: String, d: &ForceDesc) -> Result<Force> {
        let kind = match d {
            ForceDesc::PointForce { point, force, .. } => {
                check_finite_item(item, "force", force)?;
                ForceKind::PointForce { point: ctx.marker(item, point)?, force: *force }
            }
            ForceDesc::Torque { frame, torque, .. } => {
                check_finite_item(item, "torque", &[*torque])?;
                ForceKind::Torque { frame: ctx.oriented_marker(item, frame)?, torque: *torque }
            }
            ForceDesc::SpringDamper { a, b, stiffness, damping, rest_length, .. } => {
                let (a, b) = (ctx.marker(item, a)?, ctx.marker(item, b)?);
                let rest_length = match rest_length {
                    Some(l) => *l,
                    None => {
                        let (sa, sb) = (ctx.state0(&a), ctx.state0(&b));
                        (sa.r[0] - sb.r[0]).hypot(sa.r[1] - sb.r[1])
                    }
                };
                ForceKind::SpringDamper {
                    a,
                    b,
                    stiffness: non_negative(item, "stiffness", *stiffness)?,
                    damping: non_negative(item, "damping", *damping)?,
                    rest_length: non_negative(item, "rest_length", rest_length)?,
                }
            }
        };
        Ok(Force { name, kind })
    }

    /// The markers this force acts through (its generalized force depends on their states only).
    pub fn markers(&self) -> [Option<&Marker>; 2] {
        match &self.kind {
            ForceKind::PointForce { point, .. } => [Some(point), None],
            ForceKind::Torque { frame, .. } => [Some(frame), None],
            ForceKind::SpringDamper { a, b, .. } => [Some(a), Some(b)],
            ForceKind::Spatial(f) => f.markers(),
        }
    }

    /// Add this force's generalized force to `qvec` (length n).
    #[inline]
    pub fn add_to(&self, bodies: &[Body], q: &[f64], qd: &[f64], qvec: &mut [f64]) {
        match &self.kind {
            ForceKind::PointForce { point, force } => {
                let s = point.state(bodies, q, qd);
                point.add_point_jacobian(bodies, &s, *force, qvec);
            }
            ForceKind::Torque { frame, torque } => {
                let s = frame.state(bodies, q, qd);
                frame.add_angle_jacobian(bodies, &s, *torque, qvec);
            }
            ForceKind::SpringDamper { a, b, stiffness, damping, rest_length } => {
                let (sa, sb) = (a.state(bodies, q, qd), b.state(bodies, q, qd));
                let d = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
                let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
                if l == 0.0 {
                    // direction undefined at zero length: no force (documented limitation)
                    return;
                }
                let e = [d[0] / l, d[1] / l];
                let ldot = e[0] * (sa.v[0] - sb.v[0]) + e[1] * (sa.v[1] - sb.v[1]);
                let f = stiffness * (l - rest_length) + damping * ldot;
                a.add_point_jacobian(bodies, &sa, [-f * e[0], -f * e[1]], qvec);
                b.add_point_jacobian(bodies, &sb, [f * e[0], f * e[1]], qvec);
            }
            ForceKind::Spatial(f) => f.add_to(bodies, q, qd, qvec),
        }
    }

    /// `1/2 k ldot^2` of a spring-damper for the motion `v` at `q` (its length's first-order
    /// change squared: the spring's share of a mode's stiffness; 0 for the loads).
    pub fn material_energy(&self, bodies: &[Body], q: &[f64], v: &[f64]) -> f64 {
        match &self.kind {
            ForceKind::SpringDamper { a, b, stiffness, .. } => {
                let (sa, sb) = (a.state(bodies, q, v), b.state(bodies, q, v));
                let d = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
                let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
                if l == 0.0 {
                    return 0.0;
                }
                let ldot = (d[0] * (sa.v[0] - sb.v[0]) + d[1] * (sa.v[1] - sb.v[1])) / l;
                0.5 * stiffness * ldot * ldot
            }
            ForceKind::PointForce { .. } | ForceKind::Torque { .. } => 0.0,
            ForceKind::Spatial(f) => f.material_energy(bodies, q, v),
        }
    }

    /// Potential energy stored in this force element (springs only).
    pub fn potential(&self, bodies: &[Body], q: &[f64]) -> f64 {
        match &self.kind {
            ForceKind::SpringDamper { a, b, stiffness, rest_length, .. } => {
                let zeros = vec![0.0; q.len()];
                let (sa, sb) = (a.state(bodies, q, &zeros), b.state(bodies, q, &zeros));
                let l = ((sa.r[0] - sb.r[0]).powi(2) + (sa.r[1] - sb.r[1]).powi(2)).sqrt();
                0.5 * stiffness * (l - rest_length).powi(2)
            }
            // constant forces are not potential-free in general (follower frames); they are
            // world-fixed here, so their potential is -F . r
            ForceKind::PointForce { point, force } => {
                let zeros = vec![0.0; q.len()];
                let s = point.state(bodies, q, &zeros);
                -(force[0] * s.r[0] + force[1] * s.r[1])
            }
            ForceKind::Torque { frame, torque } => {
                let zeros = vec![0.0; q.len()];
                -torque * frame.state(bodies, q, &zeros).phi
            }
            ForceKind::Spatial(f) => f.potential(bodies, q),
        }
    }
}
