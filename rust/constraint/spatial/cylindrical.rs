//! Cylindrical joint along the `z` axes (4 rows): `x_i . z_j = 0`, `y_i . z_j = 0`, `x_i . d = 0`, `y_i . d = 0`.

use super::{prim, Pair};
use crate::body::marker3::Marker3State;
use crate::body::Body;
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct Cylindrical {
    pub pair: Pair,
}

impl Cylindrical {
    pub const ROWS: &'static [&'static str] = &["xz", "yz", "xd", "yd"];
    /// The marker axes its rows read (x_i, y_i; z_j).
    pub const AXES: [u8; 2] = [0b011, 0b100];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
        rows(bodies, si, sj, n, out);
    }
}

/// The four cylindrical rows (also the first four of a prismatic joint).
#[inline]
pub fn rows(bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
    prim::dot1(bodies, si, 0, sj, 2, n, out, 0);
    prim::dot1(bodies, si, 1, sj, 2, n, out, 1);
    prim::dot2(bodies, si, 0, sj, n, out, 2);
    prim::dot2(bodies, si, 1, sj, n, out, 3);
}
