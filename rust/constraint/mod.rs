//! Joints and drivers: `Phi(q, t) = 0`, its Jacobian `A = Phi_q`, `Phi_t`, and
//! `gamma = -(A qd)_q qd - 2 Phi_qt qd - Phi_tt` (paper eq. 43). Every joint works on markers,
//! so it works the same on every body kind.
//!
//! One file per kind states its rows (`ROWS`: one name suffix per row), how it is built from
//! its description (`from_desc`) and its equations (`eval`); `rows.rs` holds the row
//! equations several kinds share. Adding a joint kind = a `JointDesc` variant, one file here,
//! one arm in `ConstraintKind` and in the three `match`es below.

pub mod distance;
pub mod driver;
pub mod jac;
pub mod motion;
pub mod point_on_line;
pub mod prismatic;
pub mod revolute;
pub mod rows;
pub mod spatial;
pub mod weld;

use std::collections::HashMap;

pub use distance::Distance;
pub use driver::{AngleDriver, CoordinateDriver};
pub use motion::Motion;
pub use point_on_line::PointOnLine;
pub use prismatic::Prismatic;
pub use revolute::Revolute;
pub use weld::Weld;

use crate::body::{Body, Marker, MarkerState};
use crate::description::{DriverDesc, JointDesc, MarkerDesc};
use crate::error::{check_finite_item, Error, Result};

#[derive(Debug, Clone)]
pub enum ConstraintKind {
    Revolute(Revolute),
    PointOnLine(PointOnLine),
    Prismatic(Prismatic),
    Weld(Weld),
    Distance(Distance),
    AngleDriver(AngleDriver),
    CoordinateDriver(CoordinateDriver),
    /// Spatial joints, drivers and normalization rows (`spatial/`).
    Spatial(spatial::SpatialConstraint),
}

#[derive(Debug, Clone)]
pub struct Constraint {
    pub name: String,
    /// First row in `Phi`.
    pub row: usize,
    pub kind: ConstraintKind,
}

/// What a joint or driver exerts on the body of its first marker (`a`, `point`), at that
/// marker, from its multipliers (`M qdd + A^T lambda = Q`: the constraint force on the
/// coordinates is `-A^T lambda`): a force in the world frame, a torque, and the angle of the
/// joint frame in which `force` is also reported (`rust/sensors/mod.rs`). The second marker's body
/// receives the opposite force at the same point.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Reaction {
    pub force: [f64; 2],
    pub torque: f64,
    pub frame: f64,
}

/// Output of one constraint evaluation. Slices are the constraint's own rows.
pub struct ConstraintOut<'a> {
    /// `Phi` rows (written only when `Some`).
    pub phi: Option<&'a mut [f64]>,
    /// Jacobian rows in the constraint's compressed layout (`jac::SegJac`): each row is the
    /// coordinates of its bodies one after the other (`layout`: `(body, start)`), `width` long
    /// (the `n` passed to `eval`), row-major, already zeroed by the caller.
    pub jac: &'a mut [f64],
    pub layout: &'a [(usize, usize)],
    /// `Phi_t` rows.
    pub phi_t: &'a mut [f64],
    /// `gamma` rows.
    pub gamma: &'a mut [f64],
    /// Evaluation buffer of a driver's motion (`Data::motion_scratch`, `scratch_len()` long).
    pub scratch: &'a mut [f64],
    /// Spatial models: the bodies' rotations at `(q, qd)` and the buffer of a joint's two
    /// marker states (`Data::marker3`); `None` for planar models.
    pub marker3: Option<&'a mut crate::body::marker3::Marker3Work>,
}

/// What a constraint needs from the model while it is built: the bodies, their names and the
/// initial guess (for offsets such as a weld's `phi0`).
pub struct BuildContext<'a> {
    pub bodies: &'a [Body],
    pub index: &'a HashMap<String, usize>,
    pub q0: &'a [f64],
    /// `body.coordinate` names, in `q`'s order (what loads' expressions may read).
    pub coordinate_names: &'a [String],
    /// The joints built so far, with their resolved markers (what `angle(J)`, `s(J)` in a
    /// load's expression read: `force::value_joint`; forces are built after the joints).
    pub joints: &'a [Constraint],
}

impl BuildContext<'_> {
    /// Resolve a marker on the ground or on a body.
    pub fn marker(&self, item: &str, md: &MarkerDesc) -> Result<Marker> {
        check_finite_item(item, "marker angle", &[md.angle])?;
        if md.body == "ground" {
            if md.xi.is_some() {
                return Err(Error::invalid(item, "a marker on the ground is given by a point, not by xi"));
            }
            let p = md.point.unwrap_or([0.0, 0.0]);
            check_finite_item(item, "marker point", &p)?;
            return Ok(Marker::ground(p, md.angle));
        }
        let Some(&bi) = self.index.get(&md.body) else {
            let mut known: Vec<&str> = vec!["ground"];
            known.extend(self.bodies.iter().map(|b| b.name.as_str()));
            return Err(Error::UnknownBody { item: item.to_string(), body: md.body.clone(), known: known.join(", ") });
        };
        self.bodies[bi].marker(bi, md, item)
    }

    /// A marker whose frame turns with its body (refuses point masses).
    pub fn oriented_marker(&self, item: &str, md: &MarkerDesc) -> Result<Marker> {
        let m = self.marker(item, md)?;
        if !m.has_orientation() {
            return Err(Error::invalid(item, format!("point mass '{}' has no orientation: this needs a rigid body or a beam", md.body)));
        }
        Ok(m)
    }

    /// Two markers on different bodies.
    pub fn marker_pair(&self, item: &str, a: &MarkerDesc, b: &MarkerDesc) -> Result<(Marker, Marker)> {
        if a.body == b.body {
            return Err(Error::invalid(item, format!("both markers are on the same body '{}'", a.body)));
        }
        Ok((self.marker(item, a)?, self.marker(item, b)?))
    }

    /// Two markers on different bodies, both with an orientation.
    pub fn oriented_pair(&self, item: &str, a: &MarkerDesc, b: &MarkerDesc) -> Result<(Marker, Marker)> {
        self.marker_pair(item, a, b)?;
        Ok((self.oriented_marker(item, a)?, self.oriented_marker(item, b)?))
    }

    /// Marker kinematics at the initial guess, zero velocities.
    pub fn state0(&self, m: &Marker) -> MarkerState {
        m.state(self.bodies, self.q0, &vec![0.0; self.q0.len()])
    }
}

impl Constraint {
    /// Write the defaults this joint resolved into its description, so that the description
    /// states them (a distance joint's length taken at the initial guess).
    pub fn fill_defaults(&self, d: &mut JointDesc) {
        if let (ConstraintKind::Distance(dist), JointDesc::Distance { length, .. }) = (&self.kind, d) {
            *length = Some(dist.length);
        }
    }

    /// Build a joint; `item` names it in errors.
    pub fn from_joint(ctx: &BuildContext, item: &str, name: String, d: &JointDesc) -> Result<Constraint> {
        let kind = match d {
            JointDesc::Revolute { a, b, .. } => ConstraintKind::Revolute(Revolute::from_desc(ctx, item, a, b)?),
            JointDesc::PointOnLine { point, line, .. } => ConstraintKind::PointOnLine(PointOnLine::from_desc(ctx, item, point, line)?),
            JointDesc::Prismatic { a, b, .. } => ConstraintKind::Prismatic(Prismatic::from_desc(ctx, item, a, b)?),
            JointDesc::Weld { a, b, .. } => ConstraintKind::Weld(Weld::from_desc(ctx, item, a, b)?),
            JointDesc::Distance { a, b, length, .. } => ConstraintKind::Distance(Distance::from_desc(ctx, item, a, b, *length)?),
        };
        Ok(Constraint { name, row: 0, kind })
    }

    /// Build a driver.
    pub fn from_driver(ctx: &BuildContext, item: &str, name: String, d: &DriverDesc) -> Result<Constraint> {
        let kind = match d {
            DriverDesc::Angle { a, b, motion, .. } => ConstraintKind::AngleDriver(AngleDriver::from_desc(ctx, item, a, b.as_ref(), motion)?),
            DriverDesc::Coordinate { point, axis, motion, .. } => {
                ConstraintKind::CoordinateDriver(CoordinateDriver::from_desc(ctx, item, point, *axis, motion)?)
            }
        };
        Ok(Constraint { name, row: 0, kind })
    }

    /// The bodies this constraint's rows can touch (the bodies of its markers; `None` for the
    /// ground or an unused slot). Every Jacobian entry of its rows lies in these bodies'
    /// coordinates: the sparsity pattern of `A` (`sparse_uk`, `dynamics::constraints`).
    pub fn bodies(&self) -> [Option<usize>; 2] {
        match &self.kind {
            ConstraintKind::Revolute(c) => [c.a.body, c.b.body],
            ConstraintKind::PointOnLine(c) => [c.point.body, c.line.body],
            ConstraintKind::Prismatic(c) => [c.a.body, c.b.body],
            ConstraintKind::Weld(c) => [c.a.body, c.b.body],
            ConstraintKind::Distance(c) => [c.a.body, c.b.body],
            ConstraintKind::AngleDriver(c) => [c.a.body, c.b.body],
            ConstraintKind::CoordinateDriver(c) => [c.point.body, None],
            ConstraintKind::Spatial(c) => c.bodies(),
        }
    }

    /// The markers of this constraint's rows (`None`: an unused slot). Each row is a function
    /// of their states only, so its entries lie in their coordinates (`Marker::coords`): the
    /// structural pattern of `A` and `db/dqd` (`sparse_newton`).
    pub fn markers(&self) -> [Option<&Marker>; 2] {
        match &self.kind {
            ConstraintKind::Revolute(c) => [Some(&c.a), Some(&c.b)],
            ConstraintKind::PointOnLine(c) => [Some(&c.point), Some(&c.line)],
            ConstraintKind::Prismatic(c) => [Some(&c.a), Some(&c.b)],
            ConstraintKind::Weld(c) => [Some(&c.a), Some(&c.b)],
            ConstraintKind::Distance(c) => [Some(&c.a), Some(&c.b)],
            ConstraintKind::AngleDriver(c) => [Some(&c.a), Some(&c.b)],
            ConstraintKind::CoordinateDriver(c) => [Some(&c.point), None],
            ConstraintKind::Spatial(c) => c.markers(),
        }
    }

    /// Name suffix of each row (`""` for single-row kinds).
    pub fn row_suffixes(&self) -> &'static [&'static str] {
        match &self.kind {
            ConstraintKind::Revolute(_) => Revolute::ROWS,
            ConstraintKind::PointOnLine(_) => PointOnLine::ROWS,
            ConstraintKind::Prismatic(_) => Prismatic::ROWS,
            ConstraintKind::Weld(_) => Weld::ROWS,
            ConstraintKind::Distance(_) => Distance::ROWS,
            ConstraintKind::AngleDriver(_) => AngleDriver::ROWS,
            ConstraintKind::CoordinateDriver(_) => CoordinateDriver::ROWS,
            ConstraintKind::Spatial(c) => c.row_suffixes(),
        }
    }

    #[inline]
    pub fn rows(&self) -> usize {
        self.row_suffixes().len()
    }

    /// Length of the buffer a driver's motion evaluates in (0 for joints).
    pub fn scratch_len(&self) -> usize {
        match &self.kind {
            ConstraintKind::AngleDriver(c) => c.motion.scratch_len(),
            ConstraintKind::CoordinateDriver(c) => c.motion.scratch_len(),
            ConstraintKind::Spatial(c) => c.scratch_len(),
            _ => 0,
        }
    }

    pub fn is_driver(&self) -> bool {
        match &self.kind {
            ConstraintKind::Spatial(c) => c.is_driver(),
            k => matches!(k, ConstraintKind::AngleDriver(_) | ConstraintKind::CoordinateDriver(_)),
        }
    }

    /// The reaction on the first marker's body from this constraint's multipliers `lam` (its
    /// own rows) at `(q, qd)`.
    pub fn reaction(&self, bodies: &[Body], q: &[f64], qd: &[f64], lam: &[f64]) -> Reaction {
        match &self.kind {
            ConstraintKind::Revolute(c) => c.reaction(bodies, q, qd, lam),
            ConstraintKind::PointOnLine(c) => c.reaction(bodies, q, qd, lam),
            ConstraintKind::Prismatic(c) => c.reaction(bodies, q, qd, lam),
            ConstraintKind::Weld(c) => c.reaction(bodies, q, qd, lam),
            ConstraintKind::Distance(c) => c.reaction(bodies, q, qd, lam),
            ConstraintKind::AngleDriver(c) => c.reaction(bodies, q, qd, lam),
            ConstraintKind::CoordinateDriver(c) => c.reaction(bodies, q, qd, lam),
            // spatial reactions are 3D wrenches: sensors::spatial::reactions
            ConstraintKind::Spatial(_) => Reaction::default(),
        }
    }

    /// Name of the body the reaction acts on (`None`: the ground).
    pub fn first_body(&self) -> Option<usize> {
        match &self.kind {
            ConstraintKind::Revolute(c) => c.a.body,
            ConstraintKind::PointOnLine(c) => c.point.body,
            ConstraintKind::Prismatic(c) => c.a.body,
            ConstraintKind::Weld(c) => c.a.body,
            ConstraintKind::Distance(c) => c.a.body,
            ConstraintKind::AngleDriver(c) => c.a.body,
            ConstraintKind::CoordinateDriver(c) => c.point.body,
            ConstraintKind::Spatial(c) => c.first_body(),
        }
    }

    /// Evaluate this constraint's rows at `(t, q, qd)`; `n` is the width of a Jacobian row in
    /// `out.jac` (the compressed layout).
    #[inline]
    pub fn eval(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], n: usize, mut out: ConstraintOut) {
        let out = &mut out;
        match &self.kind {
            ConstraintKind::Revolute(c) => c.eval(bodies, q, qd, n, out),
            ConstraintKind::PointOnLine(c) => c.eval(bodies, q, qd, n, out),
            ConstraintKind::Prismatic(c) => c.eval(bodies, q, qd, n, out),
            ConstraintKind::Weld(c) => c.eval(bodies, q, qd, n, out),
            ConstraintKind::Distance(c) => c.eval(bodies, q, qd, n, out),
            ConstraintKind::AngleDriver(c) => c.eval(bodies, t, q, qd, n, out),
            ConstraintKind::CoordinateDriver(c) => c.eval(bodies, t, q, qd, n, out),
            ConstraintKind::Spatial(c) => c.eval(bodies, t, q, qd, n, out),
        }
    }
}
