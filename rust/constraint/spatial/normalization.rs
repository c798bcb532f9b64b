//! The normalization row of a rigid3 body's Euler parameters, `p . p - 1 = 0`
//! (`A = [0, 2 p^T]`, `gamma = -2 pd . pd`), appended by the model after the joint and driver
//! rows (docs/spatial-design.md, section 3): an ordinary UK row, exact with the regularized
//! mass block.

use crate::body::{Body, Marker};
use crate::constraint::ConstraintOut;

#[derive(Debug, Clone)]
pub struct Normalization {
    pub body: usize,
    pub base: Marker,
}

impl Normalization {
    /// The coordinate `c` with `F^-1 A_n^T = e_c / sqrt k`: the rigid body's factor maps its
    /// normalization row onto one unit vector (`Rigid3::NORMALIZATION_COORD`), so the UK
    /// kernel eliminates the row in closed form (`Model::unit_columns`).
    pub fn unit_coordinate(&self, bodies: &[Body]) -> usize {
        bodies[self.body].offset + crate::body::rigid3::NORMALIZATION_COORD
    }

    #[inline]
    pub fn eval(&self, bodies: &[Body], q: &[f64], qd: &[f64], _n: usize, out: &mut ConstraintOut) {
        let o = bodies[self.body].offset;
        let (p, pd) = (&q[o + 3..o + 7], &qd[o + 3..o + 7]);
        let start = out.layout.iter().find(|e| e.0 == self.body).expect("its body is in the layout").1;
        let mut pp = 0.0;
        let mut dd = 0.0;
        for l in 0..4 {
            out.jac[start + 3 + l] = 2.0 * p[l];
            pp += p[l] * p[l];
            dd += pd[l] * pd[l];
        }
        if let Some(phi) = out.phi.as_deref_mut() {
            phi[0] = pp - 1.0;
        }
        out.phi_t[0] = 0.0;
        out.gamma[0] = -2.0 * dd;
    }
}
