//! Point on line (2 rows): `P_j` on the `z_i` line: `x_i . d = 0`, `y_i . d = 0`.

use super::{prim, Pair};
use crate::body::marker3::Marker3State;
use crate::body::Body;
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct PointOnLine3 {
    pub pair: Pair,
}

impl PointOnLine3 {
    pub const ROWS: &'static [&'static str] = &["xd", "yd"];
    /// The marker axes its rows read (x_i, y_i).
    pub const AXES: [u8; 2] = [0b011, 0];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
        prim::dot2(bodies, si, 0, sj, n, out, 0);
        prim::dot2(bodies, si, 1, sj, n, out, 1);
    }
}
