//! Planar joint (3 rows): `P_j` in the `x_i y_i` plane, rotation about `z` only: `x_i . z_j = 0`, `y_i . z_j = 0`, `z_i . d = 0`.

use super::{prim, Pair};
use crate::body::marker3::Marker3State;
use crate::body::Body;
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct Planar {
    pub pair: Pair,
}

impl Planar {
    pub const ROWS: &'static [&'static str] = &["xz", "yz", "zd"];
    /// The marker axes its rows read (x_i, y_i, z_i; z_j).
    pub const AXES: [u8; 2] = [0b111, 0b100];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
        prim::dot1(bodies, si, 0, sj, 2, n, out, 0);
        prim::dot1(bodies, si, 1, sj, 2, n, out, 1);
        prim::dot2(bodies, si, 2, sj, n, out, 2);
    }
}
