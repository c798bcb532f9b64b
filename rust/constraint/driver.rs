//! Drivers (rheonomic constraints, 1 row each): a relative angle `phi_a - phi_b - f(t) = 0`
//! (`b` defaults to the ground frame) or a world coordinate of a point `r[axis] - f(t) = 0`.

use super::{rows, BuildContext, ConstraintOut, Motion, Reaction};
use crate::body::{Body, Marker};
use crate::description::{Axis, MarkerDesc, MotionDesc};
use crate::error::{Error, Result};

#[derive(Debug, Clone)]
pub struct AngleDriver {
    pub a: Marker,
    pub b: Marker,
    pub motion: Motion,
}

impl AngleDriver {
    pub const ROWS: &'static [&'static str] = &[""];

    pub fn from_desc(ctx: &BuildContext, item: &str, a: &MarkerDesc, b: Option<&MarkerDesc>, motion: &MotionDesc) -> Result<Self> {
        let (a, b) = match b {
            Some(b) => ctx.oriented_pair(item, a, b)?,
            None => {
                let a = ctx.oriented_marker(item, a)?;
                if a.body.is_none() {
                    return Err(Error::invalid(item, "marker a is on the ground (the driver would constrain nothing)"));
                }
                (a, Marker::ground([0.0, 0.0], 0.0))
            }
        };
        Ok(AngleDriver { a, b, motion: Motion::from_desc(item, motion)? })
    }

    #[inline]
    pub fn eval(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        let f = self.motion.eval(t, out.scratch);
        rows::angle(bodies, &self.a, &self.b, &sa, &sb, f, n, out, 0);
    }

    /// Reaction on `a`'s body: the driving torque `-lambda`; joint frame: marker `a`.
    pub fn reaction(&self, bodies: &[Body], q: &[f64], qd: &[f64], lam: &[f64]) -> Reaction {
        let sa = self.a.state(bodies, q, qd);
        Reaction { force: [0.0, 0.0], torque: -lam[0], frame: sa.phi }
    }
}

#[derive(Debug, Clone)]
pub struct CoordinateDriver {
    pub point: Marker,
    pub axis: Axis,
    pub motion: Motion,
}

impl CoordinateDriver {
    pub const ROWS: &'static [&'static str] = &[""];

    pub fn from_desc(ctx: &BuildContext, item: &str, point: &MarkerDesc, axis: Axis, motion: &MotionDesc) -> Result<Self> {
        let point = ctx.marker(item, point)?;
        if point.body.is_none() {
            return Err(Error::invalid(item, "the point is on the ground (the driver would constrain nothing)"));
        }
        Ok(CoordinateDriver { point, axis, motion: Motion::from_desc(item, motion)? })
    }

    #[inline]
    pub fn eval(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
        let sp = self.point.state(bodies, q, qd);
        let k = match self.axis {
            Axis::X => 0,
            Axis::Y => 1,
        };
        let f = self.motion.eval(t, out.scratch);
        if let Some(phi) = out.phi.as_deref_mut() {
            phi[0] = sp.r[k] - f.0;
        }
        let mut w = [0.0; 2];
        w[k] = 1.0;
        self.point.add_point_jacobian_in(bodies, &sp, w, &mut out.jac[0..n], Some(out.layout));
        out.phi_t[0] = -f.1;
        out.gamma[0] = -sp.h[k] + f.2;
    }

    /// Reaction on the point's body: the driving force `-lambda` along the axis; joint frame:
    /// the world.
    pub fn reaction(&self, _bodies: &[Body], _q: &[f64], _qd: &[f64], lam: &[f64]) -> Reaction {
        let mut force = [0.0; 2];
        force[matches!(self.axis, Axis::Y) as usize] = -lam[0];
        Reaction { force, torque: 0.0, frame: 0.0 }
    }
}
