//! Universal joint (4 rows): `d = 0`, `x_i . y_j = 0` (cross arms `x_i` on body `i`, `y_j` on body `j`).

use super::{prim, Pair};
use crate::body::marker3::{Marker3State, NO_POINT_RATE};
use crate::body::Body;
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct Universal {
    pub pair: Pair,
}

impl Universal {
    pub const ROWS: &'static [&'static str] = &["x", "y", "z", "xy"];
    /// The marker axes its rows read (x_i; y_j); not the points' rates.
    pub const AXES: [u8; 2] = [0b001 | NO_POINT_RATE, 0b010 | NO_POINT_RATE];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
        prim::coincidence(bodies, si, sj, n, out, 0);
        prim::dot1(bodies, si, 0, sj, 1, n, out, 3);
    }
}
