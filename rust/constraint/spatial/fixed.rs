//! Fixed joint (weld, 6 rows): `d = 0`, `x_i . z_j = 0`, `y_i . z_j = 0`, `x_i . y_j = 0`.

use super::{prim, Pair};
use crate::body::marker3::{Marker3State, NO_POINT_RATE};
use crate::body::Body;
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct Fixed {
    pub pair: Pair,
}

impl Fixed {
    pub const ROWS: &'static [&'static str] = &["x", "y", "z", "xz", "yz", "xy"];
    /// The marker axes its rows read (x_i, y_i; y_j, z_j); not the points' rates.
    pub const AXES: [u8; 2] = [0b011 | NO_POINT_RATE, 0b110 | NO_POINT_RATE];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
        prim::coincidence(bodies, si, sj, n, out, 0);
        prim::dot1(bodies, si, 0, sj, 2, n, out, 3);
        prim::dot1(bodies, si, 1, sj, 2, n, out, 4);
        prim::dot1(bodies, si, 0, sj, 1, n, out, 5);
    }
}
