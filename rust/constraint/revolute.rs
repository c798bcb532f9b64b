//! Revolute joint: the two marker points coincide, `r_a - r_b = 0` (2 rows).

use super::{Reaction, rows, BuildContext, ConstraintOut};
use crate::body::{Body, Marker};
use crate::description::MarkerDesc;
use crate::error::Result;

#[derive(Debug, Clone)]
pub struct Revolute {
    pub a: Marker,
    pub b: Marker,
}

impl Revolute {
    pub const ROWS: &'static [&'static str] = &["x", "y"];

    pub fn from_desc(ctx: &BuildContext, item: &str, a: &MarkerDesc, b: &MarkerDesc) -> Result<Self> {
        let (a, b) = ctx.marker_pair(item, a, b)?;
        Ok(Revolute { a, b })
    }

    #[inline]
    pub fn eval(&self, bodies: &[Body], q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        rows::coincidence(bodies, &self.a, &self.b, &sa, &sb, n, out, 0);
    }

    /// Reaction on `a`'s body (force `-lambda`, no torque; joint frame: marker `a`).
    pub fn reaction(&self, bodies: &[Body], q: &[f64], qd: &[f64], lam: &[f64]) -> Reaction {
        let sa = self.a.state(bodies, q, qd);
        Reaction { force: [-lam[0], -lam[1]], torque: 0.0, frame: sa.phi }
    }
}
