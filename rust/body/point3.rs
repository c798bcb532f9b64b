//! Spatial point mass: coordinates `r` (3), mass block `m I`, no orientation (its markers carry
//! the world axes). Gravity is a force element in spatial scenes (`force::spatial`).

use super::InitialState;
use crate::error::{check_finite_item, positive, Result};
use crate::description::spatial::Point3Desc;

#[derive(Debug, Clone)]
pub struct Point3 {
    pub mass: f64,
    pub inv_sqrt_m: f64,
}

#[derive(Debug, Clone, Default)]
pub struct Point3Data;

impl Point3 {
    pub fn from_desc(d: &Point3Desc, item: &str) -> Result<Point3> {
        let mass = positive(item, "mass", d.mass)?;
        Ok(Point3 { mass, inv_sqrt_m: 1.0 / mass.sqrt() })
    }

    pub fn initial_state(&self, d: &Point3Desc, item: &str) -> Result<InitialState> {
        check_finite_item(item, "position", &d.position)?;
        check_finite_item(item, "velocity", &d.velocity)?;
        Ok(InitialState { q: d.position.to_vec(), qd: d.velocity.to_vec(), names: ["x", "y", "z"].map(String::from).to_vec() })
    }

    pub fn new_data(&self) -> Point3Data {
        Point3Data
    }

    #[inline]
    pub fn mass_and_forces(&self, _bd: &mut Point3Data, _q: &[f64], _qd: &[f64], _gravity: Option<[f64; 2]>, f: &mut [f64]) {
        f[0] = 0.0;
        f[1] = 0.0;
        f[2] = 0.0;
    }

    #[inline]
    pub fn factor(&self, _bd: &mut Point3Data) -> bool {
        true
    }

    #[inline]
    pub fn finv(&self, _bd: &Point3Data, v: &mut [f64]) {
        for x in &mut v[0..3] {
            *x *= self.inv_sqrt_m;
        }
    }

    #[inline]
    pub fn finvt(&self, bd: &Point3Data, v: &mut [f64]) {
        self.finv(bd, v);
    }

    pub fn dense_block(&self, _bd: &Point3Data, put: &mut impl FnMut(usize, usize, f64)) {
        for i in 0..3 {
            put(i, i, self.mass);
        }
    }

    pub fn mass_times(&self, _bd: &Point3Data, x: &[f64], out: &mut [f64]) {
        for i in 0..3 {
            out[i] += self.mass * x[i];
        }
    }

    pub fn kinetic_energy(&self, _bd: &Point3Data, qd: &[f64]) -> f64 {
        0.5 * self.mass * (qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2])
    }

    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        [self.mass * q[0], self.mass * q[1]]
    }
}
