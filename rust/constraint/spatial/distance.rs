//! Distance joint (1 row): `d . d - L^2 = 0` (`L`: given, or the distance at the initial guess).

use super::{prim, Pair};
use crate::body::marker3::Marker3State;
use crate::body::Body;
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct Distance3 {
    pub pair: Pair,
    pub length: f64,
}

impl Distance3 {
    pub const ROWS: &'static [&'static str] = &[""];
    /// The marker axes its rows read (none).
    pub const AXES: [u8; 2] = [0, 0];

    #[inline]
    pub fn eval(&self, bodies: &[Body], si: &Marker3State, sj: &Marker3State, n: usize, out: &mut ConstraintOut) {
        prim::distance(bodies, si, sj, self.length, n, out, 0);
    }
}
