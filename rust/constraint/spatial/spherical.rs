//! Spherical joint (3 rows): `P_j - P_i = 0`.

use super::{prim, Pair};
use crate::body::marker3::{Marker3State, NO_POINT_RATE};
use crate::body::Body;
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct Spherical {
    pub pair: Pair,
}

impl Spherical {
    pub const ROWS: &'static [&'static str] = &["x", "y", "z"];
    /// The marker axes its rows read (none); not the points' rates.
    pub const AXES: [u8; 2] = [NO_POINT_RATE, NO_POINT_RATE];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
        prim::coincidence(bodies, si, sj, n, out, 0);
    }
}
