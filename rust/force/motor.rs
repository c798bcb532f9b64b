//! A motor: a torque `tau` between two marker frames, `+tau` on `a` (the rotor side) and
//! `-tau` on `b` (the stator, the ground when absent), given as a [`Value`] that may read the
//! relative angle `angle = phi_a - phi_b` and rate `w = omega_a - omega_b` besides `t` and the
//! state quantities: a DC motor `k (V - k w) / R`, a torque-speed table, a PI speed controller
//! (docs/loads.md). The rotor's inertia is added to the body of `a` at build
//! (`ModelBuilder::add_force`; rigid bodies only).

use super::value::{Env, Scope, Value};
use crate::body::{Body, Marker};
use crate::constraint::BuildContext;
use crate::description::{LoadValueDesc, MarkerDesc};
use crate::error::{non_negative, Result};

/// The names a motor's torque reads besides `t` and the coordinates.
pub const LOCAL: [&str; 2] = ["angle", "w"];

#[derive(Debug, Clone)]
pub struct Motor {
    pub a: Marker,
    pub b: Marker,
    pub torque: Value,
    pub rotor_inertia: f64,
}

/// `b`, or the ground frame when absent.
pub fn frame_or_ground(ctx: &BuildContext, item: &str, b: Option<&MarkerDesc>) -> Result<Marker> {
    match b {
        Some(b) => ctx.oriented_marker(item, b),
        None => Ok(Marker::ground([0.0, 0.0], 0.0)),
    }
}

/// Relative angle and rate of two marker frames, and their states.
#[inline]
pub fn relative(bodies: &[Body], a: &Marker, b: &Marker, q: &[f64], qd: &[f64]) -> (crate::body::MarkerState, crate::body::MarkerState, [f64; 2]) {
    let (sa, sb) = (a.state(bodies, q, qd), b.state(bodies, q, qd));
    let rel = [sa.phi - sb.phi, sa.omega - sb.omega];
    (sa, sb, rel)
}

impl Motor {
    pub fn from_desc(ctx: &BuildContext, item: &str, a: &MarkerDesc, b: Option<&MarkerDesc>, torque: &LoadValueDesc, rotor_inertia: f64) -> Result<Motor> {
        let scope = Scope { coordinate_names: ctx.coordinate_names, local: &LOCAL, ctx: Some(ctx), spatial: None };
        Ok(Motor {
            a: ctx.oriented_marker(item, a)?,
            b: frame_or_ground(ctx, item, b)?,
            torque: Value::new(item, "torque", &scope, torque)?,
            rotor_inertia: non_negative(item, "rotor_inertia", rotor_inertia)?,
        })
    }

    #[inline]
    pub fn add_to(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], scratch: &mut [f64], qvec: &mut [f64]) {
        let (sa, sb, local) = relative(bodies, &self.a, &self.b, q, qd);
        let tau = self.torque.eval(&Env { bodies, t, q, qd, local }, scratch);
        self.a.add_angle_jacobian(bodies, &sa, tau, qvec);
        self.b.add_angle_jacobian(bodies, &sb, -tau, qvec);
    }
}
