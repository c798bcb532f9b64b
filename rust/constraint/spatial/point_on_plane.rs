//! Point on plane (1 row): `P_j` on the `x_i y_i` plane: `z_i . d = 0`.

use super::{prim, Pair};
use crate::body::marker3::Marker3State;
use crate::body::Body;
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct PointOnPlane {
    pub pair: Pair,
}

impl PointOnPlane {
    pub const ROWS: &'static [&'static str] = &[""];
    /// The marker axes its rows read (z_i).
    pub const AXES: [u8; 2] = [0b100, 0];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
        prim::dot2(bodies, si, 2, sj, n, out, 0);
    }
}
