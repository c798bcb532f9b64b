//! Prismatic joint: `a`'s origin on `b`'s x axis and no relative rotation,
//! `phi_a - phi_b - phi0 = 0` with `phi0` from the initial guess (2 rows).

use super::{Reaction, rows, BuildContext, ConstraintOut};
use crate::body::{Body, Marker};
use crate::description::MarkerDesc;
use crate::error::Result;

#[derive(Debug, Clone)]
pub struct Prismatic {
    pub a: Marker,
    pub b: Marker,
    pub phi0: f64,
}

impl Prismatic {
    pub const ROWS: &'static [&'static str] = &["line", "angle"];

    pub fn from_desc(ctx: &BuildContext, item: &str, a: &MarkerDesc, b: &MarkerDesc) -> Result<Self> {
        let (a, b) = ctx.oriented_pair(item, a, b)?;
        let phi0 = ctx.state0(&a).phi - ctx.state0(&b).phi;
        Ok(Prismatic { a, b, phi0 })
    }

    #[inline]
    pub fn eval(&self, bodies: &[Body], q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        rows::point_on_line(bodies, &self.a, &self.b, &sa, &sb, n, out, 0);
        rows::angle(bodies, &self.a, &self.b, &sa, &sb, (self.phi0, 0.0, 0.0), n, out, 1);
    }

    /// Reaction on `a`'s body (force `-lambda_line n` normal to `b`'s axis, torque `-lambda_angle`; joint frame: `b`'s axis).
    pub fn reaction(&self, bodies: &[Body], q: &[f64], qd: &[f64], lam: &[f64]) -> Reaction {
        let sb = self.b.state(bodies, q, qd);
        let (s, c) = sb.phi.sin_cos();
        Reaction { force: [lam[0] * s, -lam[0] * c], torque: -lam[1], frame: sb.phi }
    }
}
