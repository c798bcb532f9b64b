//! Weld (fixed joint): coincident points and no relative rotation,
//! `r_a - r_b = 0`, `phi_a - phi_b - phi0 = 0` with `phi0` from the initial guess (3 rows).

use super::{Reaction, rows, BuildContext, ConstraintOut};
use crate::body::{Body, Marker};
use crate::description::MarkerDesc;
use crate::error::Result;

#[derive(Debug, Clone)]
pub struct Weld {
    pub a: Marker,
    pub b: Marker,
    pub phi0: f64,
}

impl Weld {
    pub const ROWS: &'static [&'static str] = &["x", "y", "angle"];

    pub fn from_desc(ctx: &BuildContext, item: &str, a: &MarkerDesc, b: &MarkerDesc) -> Result<Self> {
        let (a, b) = ctx.oriented_pair(item, a, b)?;
        let phi0 = ctx.state0(&a).phi - ctx.state0(&b).phi;
        Ok(Weld { a, b, phi0 })
    }

    #[inline]
    pub fn eval(&self, bodies: &[Body], q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        rows::coincidence(bodies, &self.a, &self.b, &sa, &sb, n, out, 0);
        rows::angle(bodies, &self.a, &self.b, &sa, &sb, (self.phi0, 0.0, 0.0), n, out, 2);
    }

    /// Reaction on `a`'s body (force `-lambda_xy`, torque `-lambda_angle`; joint frame: marker `a`).
    pub fn reaction(&self, bodies: &[Body], q: &[f64], qd: &[f64], lam: &[f64]) -> Reaction {
        let sa = self.a.state(bodies, q, qd);
        Reaction { force: [-lam[0], -lam[1]], torque: -lam[2], frame: sa.phi }
    }
}
