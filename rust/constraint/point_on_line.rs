//! Point on line (slider): the point marker stays on the line through the line marker with
//! direction `phi_line`, `n . (r_point - r_line) = 0` (1 row).

use super::{Reaction, rows, BuildContext, ConstraintOut};
use crate::body::{Body, Marker};
use crate::description::MarkerDesc;
use crate::error::Result;

#[derive(Debug, Clone)]
pub struct PointOnLine {
    pub point: Marker,
    pub line: Marker,
}

impl PointOnLine {
    pub const ROWS: &'static [&'static str] = &[""];

    pub fn from_desc(ctx: &BuildContext, item: &str, point: &MarkerDesc, line: &MarkerDesc) -> Result<Self> {
        let (point, line) = ctx.marker_pair(item, point, line)?;
        Ok(PointOnLine { point, line })
    }

    #[inline]
    pub fn eval(&self, bodies: &[Body], q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
        let (sp, sl) = (self.point.state(bodies, q, qd), self.line.state(bodies, q, qd));
        rows::point_on_line(bodies, &self.point, &self.line, &sp, &sl, n, out, 0);
    }

    /// Reaction on `point`'s body (force `-lambda n` normal to the line; joint frame: the line (x along it)).
    pub fn reaction(&self, bodies: &[Body], q: &[f64], qd: &[f64], lam: &[f64]) -> Reaction {
        let sl = self.line.state(bodies, q, qd);
        let (s, c) = sl.phi.sin_cos();
        Reaction { force: [lam[0] * s, -lam[0] * c], torque: 0.0, frame: sl.phi }
    }
}
