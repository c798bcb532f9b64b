//! Rigid body: coordinates (x, y, theta) of a reference point and the body angle; the centre
//! of mass sits at `com` in the body frame.

use crate::description::RigidDesc;
use crate::error::{Error, Result};

#[derive(Debug, Clone)]
pub struct Rigid {
    pub mass: f64,
    /// Moment of inertia about the centre of mass.
    pub inertia: f64,
    /// Centre of mass in the body frame.
    pub com: [f64; 2],
    /// Moment of inertia about the reference point: `I_c + m |com|^2`.
    pub j_ref: f64,
}

impl Rigid {
    pub fn new(d: &RigidDesc) -> Result<Rigid> {
        let item = format!("rigid body '{}'", d.name);
        if !d.mass.is_finite() || d.mass <= 0.0 {
            return Err(Error::invalid(item, format!("mass must be positive and finite, got {}", d.mass)));
        }
        if !d.inertia.is_finite() || d.inertia < 0.0 {
            return Err(Error::invalid(item, format!("inertia must be >= 0 and finite, got {}", d.inertia)));
        }
        if !d.com.iter().all(|v| v.is_finite()) {
            return Err(Error::invalid(item, "com must be finite"));
        }
        let j_ref = d.inertia + d.mass * (d.com[0] * d.com[0] + d.com[1] * d.com[1]);
        if !(j_ref > 0.0) {
            // A point mass at its own reference point has no rotational inertia: its angle is
            // not determined by the dynamics and the mass matrix is singular.
            return Err(Error::SingularMass { item: format!("{item}: zero rotational inertia about its reference point") });
        }
        Ok(Rigid { mass: d.mass, inertia: d.inertia, com: d.com, j_ref })
    }
}
