//! Prismatic joint along the `z` axes (5 rows): the cylindrical rows and `x_i . y_j = 0`.

use super::{prim, Pair};
use crate::body::marker3::Marker3State;
use crate::body::Body;
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct Prismatic3 {
    pub pair: Pair,
}

impl Prismatic3 {
    pub const ROWS: &'static [&'static str] = &["xz", "yz", "xd", "yd", "xy"];
    /// The marker axes its rows read (x_i, y_i; y_j, z_j).
    pub const AXES: [u8; 2] = [0b011, 0b110];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
        super::cylindrical::rows(bodies, si, sj, n, out);
        prim::dot1(bodies, si, 0, sj, 1, n, out, 4);
    }
}
