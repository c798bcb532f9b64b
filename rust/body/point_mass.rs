//! Point mass (particle): coordinates `(x, y)`, mass block `m I`, no orientation. Markers sit
//! on the particle; their frame angle is the constant marker angle, so joints that need an
//! orientation (weld, prismatic, angle driver, torque) refuse a point-mass marker.

use super::{finite_vec2, InitialState, MarkerState};
use crate::description::{MarkerDesc, PointMassDesc};
use crate::error::{positive, Error, Result};

#[derive(Debug, Clone)]
pub struct PointMass {
    pub mass: f64,
    /// `sqrt(mass)`: the factor `F = sqrt(m) I`.
    pub sqrt_mass: f64,
}

/// A point mass needs no per-call workspace: its mass block is constant.
#[derive(Debug, Clone, Default)]
pub struct PointMassData;

impl PointMass {
    pub fn from_desc(d: &PointMassDesc, item: &str) -> Result<PointMass> {
        let mass = positive(item, "mass", d.mass)?;
        Ok(PointMass { mass, sqrt_mass: mass.sqrt() })
    }

    pub fn initial_state(&self, d: &PointMassDesc, item: &str) -> Result<InitialState> {
        let p = finite_vec2(item, "position", d.position)?;
        let v = finite_vec2(item, "velocity", d.velocity)?;
        Ok(InitialState { q: p.to_vec(), qd: v.to_vec(), names: ["x", "y"].map(String::from).to_vec() })
    }

    pub fn new_data(&self) -> PointMassData {
        PointMassData
    }

    /// No velocity terms; gravity `m g`.
    #[inline]
    pub fn mass_and_forces(&self, _bd: &mut PointMassData, _q: &[f64], _qd: &[f64], gravity: Option<[f64; 2]>, f: &mut [f64]) {
        let g = gravity.unwrap_or([0.0, 0.0]);
        f[0] = self.mass * g[0];
        f[1] = self.mass * g[1];
    }

    #[inline]
    pub fn factor(&self, _bd: &mut PointMassData) -> bool {
        true
    }

    #[inline]
    pub fn finv(&self, _bd: &PointMassData, v: &mut [f64]) {
        v[0] /= self.sqrt_mass;
        v[1] /= self.sqrt_mass;
    }

    #[inline]
    pub fn finvt(&self, bd: &PointMassData, v: &mut [f64]) {
        self.finv(bd, v);
    }

    pub fn dense_block(&self, _bd: &PointMassData, put: &mut impl FnMut(usize, usize, f64)) {
        put(0, 0, self.mass);
        put(1, 1, self.mass);
    }

    /// `out += m x`.
    pub fn mass_times(&self, _bd: &PointMassData, x: &[f64], out: &mut [f64]) {
        out[0] += self.mass * x[0];
        out[1] += self.mass * x[1];
    }

    pub fn kinetic_energy(&self, _bd: &PointMassData, qd: &[f64]) -> f64 {
        0.5 * self.mass * (qd[0] * qd[0] + qd[1] * qd[1])
    }

    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        [self.mass * q[0], self.mass * q[1]]
    }
}

/// A marker on a point mass is the particle itself.
pub fn check_marker(md: &MarkerDesc, body: &str, item: &str) -> Result<()> {
    if md.xi.is_some() {
        return Err(Error::invalid(item, format!("a marker on point mass '{body}' is the particle itself: give no xi")));
    }
    if let Some(p) = md.point {
        if p != [0.0, 0.0] {
            return Err(Error::invalid(item, format!("a marker on point mass '{body}' is the particle itself: point must be [0, 0], got {p:?}")));
        }
    }
    Ok(())
}

#[inline]
pub fn marker_state(angle: f64, q: &[f64], qd: &[f64]) -> MarkerState {
    MarkerState { r: [q[0], q[1]], phi: angle, v: [qd[0], qd[1]], cs: [1.0, 0.0], ..Default::default() }
}

#[inline]
pub fn add_point_jacobian(w: [f64; 2], row: &mut [f64]) {
    row[0] += w[0];
    row[1] += w[1];
}
