//! Spatial joints and drivers (docs/spatial-design.md, section 4), one file per kind, each
//! stated for two markers `i` (`a`, first) and `j` (`b`) that hold when the marker frames
//! coincide, from the row primitives of `prim.rs`. The model appends one normalization row per
//! rigid3 body after the joint and driver rows (`normalization.rs`). `ConstraintKind::Spatial`
//! carries them through the planar machinery (the Jacobian layout, the UK kernels, the
//! integrators), which is dimension-agnostic on the bodies' slices of `q`.

pub mod cylindrical;
pub mod distance;
pub mod driver;
pub mod fixed;
pub mod normalization;
pub mod planar;
pub mod point_on_line;
pub mod point_on_plane;
pub mod prim;
pub mod prismatic;
pub mod revolute;
pub mod spherical;
pub mod universal;

use crate::body::marker3::{Frame3, Marker3, Marker3State, ALL_AXES};
use crate::body::{Body, Marker};
use crate::constraint::ConstraintOut;
use crate::error::{Error, Result};

pub use driver::{RotationDriver, TranslationDriver};
pub use normalization::Normalization;

/// The two markers of a joint (`i` first).
#[derive(Debug, Clone)]
pub struct Pair {
    pub i: Marker3,
    pub j: Marker3,
}

impl Pair {
    /// Two markers on different bodies, at least one of them not the ground.
    pub fn new(item: &str, i: Marker3, j: Marker3) -> Result<Pair> {
        if i.body.is_none() && j.body.is_none() {
            return Err(Error::invalid(item, "both markers are on the ground (the joint would constrain nothing)"));
        }
        if i.body == j.body {
            return Err(Error::invalid(item, "both markers are on the same body"));
        }
        Ok(Pair { i, j })
    }

    /// Both markers turn with their bodies (or sit on the ground).
    pub fn oriented(self, item: &str, kind: &str) -> Result<Pair> {
        self.i.check_oriented(item, kind)?;
        self.j.check_oriented(item, kind)?;
        Ok(self)
    }

    #[inline]
    pub fn states(&self, bodies: &[Body], q: &[f64], qd: &[f64]) -> (Marker3State, Marker3State) {
        self.states_axes(bodies, &[], q, qd, [ALL_AXES; 2])
    }

    /// `states_axes` written into `st` (`Marker3::state_into`).
    #[inline]
    pub fn states_into(&self, st: &mut [Marker3State; 2], bodies: &[Body], frames: &[Frame3], q: &[f64], qd: &[f64], axes: [u8; 2]) {
        self.i.state_into(&mut st[0], bodies, frames, q, qd, axes[0]);
        self.j.state_into(&mut st[1], bodies, frames, q, qd, axes[1]);
    }

    /// The states with only the axes a kind reads (`AXES`: bit `k` of `axes[0]` for axis `k`
    /// of `i`, of `axes[1]` for `j`), the bodies' rotations from `frames` (`Marker3::state_in`).
    #[inline]
    pub fn states_axes(&self, bodies: &[Body], frames: &[Frame3], q: &[f64], qd: &[f64], axes: [u8; 2]) -> (Marker3State, Marker3State) {
        (self.i.state_in(bodies, frames, q, qd, axes[0]), self.j.state_in(bodies, frames, q, qd, axes[1]))
    }
}

/// `f(si, sj, out)` with the pair's marker states (the axes in `axes`), written into the
/// model's buffer with the bodies' cached rotations (`ConstraintOut::marker3`: no state zeroed
/// or moved per call; by value without one).
#[inline(always)]
fn with_states(pair: &Pair, axes: [u8; 2], bodies: &[Body], q: &[f64], qd: &[f64], out: &mut ConstraintOut, f: impl FnOnce(&Marker3State, &Marker3State, &mut ConstraintOut)) {
    match out.marker3.take() {
        Some(w) => {
            pair.states_into(&mut w.states, bodies, &w.frames, q, qd, axes);
            f(&w.states[0], &w.states[1], out);
            out.marker3 = Some(w);
        }
        None => {
            let (si, sj) = pair.states_axes(bodies, &[], q, qd, axes);
            f(&si, &sj, out);
        }
    }
}

macro_rules! spatial_kinds {
    ($($variant:ident($ty:ty)),* $(,)?) => {
        /// The closed set of spatial constraint kinds.
        #[derive(Debug, Clone)]
        pub enum SpatialConstraint {
            $($variant($ty),)*
            Rotation(RotationDriver),
            Translation(TranslationDriver),
            Normalization(Normalization),
        }

        impl SpatialConstraint {
            pub fn row_suffixes(&self) -> &'static [&'static str] {
                match self {
                    $(SpatialConstraint::$variant(_) => <$ty>::ROWS,)*
                    SpatialConstraint::Rotation(_) | SpatialConstraint::Translation(_) | SpatialConstraint::Normalization(_) => &[""],
                }
            }

            /// The joint's markers (`None` for a normalization row).
            pub fn pair(&self) -> Option<&Pair> {
                match self {
                    $(SpatialConstraint::$variant(c) => Some(&c.pair),)*
                    SpatialConstraint::Rotation(c) => Some(&c.pair),
                    SpatialConstraint::Translation(c) => Some(&c.pair),
                    SpatialConstraint::Normalization(_) => None,
                }
            }

            /// Out of line: the planar constraint loop (`dynamics::constraints`) keeps its code.
            #[inline(never)]
            pub fn eval(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], n: usize, out: &mut ConstraintOut) {
                match self {
                    $(SpatialConstraint::$variant(c) => with_states(&c.pair, <$ty>::AXES, bodies, q, qd, out, |si, sj, out| c.eval(bodies, si, sj, n, out)),)*
                    SpatialConstraint::Rotation(c) => with_states(&c.pair, RotationDriver::AXES, bodies, q, qd, out, |si, sj, out| c.eval(bodies, si, sj, t, n, out)),
                    SpatialConstraint::Translation(c) => with_states(&c.pair, TranslationDriver::AXES, bodies, q, qd, out, |si, sj, out| c.eval(bodies, si, sj, t, n, out)),
                    SpatialConstraint::Normalization(c) => c.eval(bodies, q, qd, n, out),
                }
            }
        }
    };
}

spatial_kinds!(
    Spherical(spherical::Spherical),
    Revolute(revolute::Revolute3),
    Prismatic(prismatic::Prismatic3),
    Cylindrical(cylindrical::Cylindrical),
    Universal(universal::Universal),
    Fixed(fixed::Fixed),
    Planar(planar::Planar),
    Distance(distance::Distance3),
    PointOnLine(point_on_line::PointOnLine3),
    PointOnPlane(point_on_plane::PointOnPlane),
);

impl SpatialConstraint {
    /// The bodies its rows touch.
    pub fn bodies(&self) -> [Option<usize>; 2] {
        match self {
            SpatialConstraint::Normalization(c) => [Some(c.body), None],
            _ => {
                let p = self.pair().expect("a joint has markers");
                [p.i.body, p.j.body]
            }
        }
    }

    /// The markers as the planar machinery sees them (body and structural pattern).
    pub fn markers(&self) -> [Option<&Marker>; 2] {
        match self {
            SpatialConstraint::Normalization(c) => [Some(&c.base), None],
            _ => {
                let p = self.pair().expect("a joint has markers");
                [Some(&p.i.base), Some(&p.j.base)]
            }
        }
    }

    pub fn scratch_len(&self) -> usize {
        match self {
            SpatialConstraint::Rotation(c) => c.motion.scratch_len(),
            SpatialConstraint::Translation(c) => c.motion.scratch_len(),
            _ => 0,
        }
    }

    pub fn is_driver(&self) -> bool {
        matches!(self, SpatialConstraint::Rotation(_) | SpatialConstraint::Translation(_))
    }

    /// The body of the first marker (`None`: the ground).
    pub fn first_body(&self) -> Option<usize> {
        self.bodies()[0]
    }
}

#[cfg(test)]
mod tests;
