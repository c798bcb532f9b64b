//! Which coordinates RADAU5M's Newton matrices turn with, and by whose rotation
//! (`radau_m/corotate.rs` turns them). Two invariances of a model give `K(G q) = G K(q) G^T`,
//! `M(G q) = G M(q) G^T` for an orthogonal map `G` of the coordinates (a rotation `R` acting
//! on a body's `r` as `R r` and on its Euler parameters as `p -> r (x) p`):
//!
//! * **Beam nodes, each by its own rotation.** A geometrically exact beam element's energy is
//!   invariant under a rotation of both its nodes (issue 31's spin-up beam).
//! * **The whole mechanism, by one rotation about gravity's axis** (A05, the flyball
//!   governor). Rotating every body about a line parallel to gravity leaves the kinetic
//!   energy, gravity's potential and every force element between two bodies (spring-dampers)
//!   unchanged, and every joint between two bodies satisfied as before. What does not turn is
//!   the ground: so the rule holds when the mechanism's only tie to the ground is one revolute
//!   whose axis is parallel to gravity (any axis without gravity), and nothing else acts from
//!   the ground (no driver, no point force or torque, no force element with a ground marker).
//!   The body on that revolute (the hub) turns only about the axis: its rotation since the
//!   matrices were read is the common rotation. One body alone is not invariant (its joints
//!   tie it to the others, who did not turn): a rod's own swing is not a symmetry.
//!
//! Scenes with neither get nothing (RADAU5M's plain iteration, to the bit).

use crate::body::BodyKind;
use crate::constraint::spatial::SpatialConstraint;
use crate::constraint::ConstraintKind;
use crate::force::spatial::SpatialForce;
use crate::force::ForceKind;
use crate::linalg::rot3::{col, cross, norm, V3};
use crate::model::Model;

/// Relative sine between the ground revolute's axis and gravity below which they are parallel.
const AXIS_PARALLEL: f64 = 1e-12;

/// The co-rotated coordinates of a model.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Corotated {
    /// Offsets of the bodies `[r (3), p (4)]` whose rotations since the reference turn the matrices.
    pub sources: Vec<usize>,
    /// The turned blocks: coordinate offset, `true` for `[r, p]` (7) or `false` for a point's
    /// `r` (3), and the index in `sources` of the rotation that turns it.
    pub blocks: Vec<(usize, bool, usize)>,
}

impl Corotated {
    /// The model's co-rotation (module docs): its beam nodes, else the common spin of a
    /// mechanism hung on one revolute about gravity's axis, else nothing.
    pub fn of_model(model: &Model) -> Corotated {
        let mut c = Corotated::default();
        for f in &model.forces {
            if let ForceKind::Spatial(SpatialForce::Beam3 { nodes, .. }) = &f.kind {
                c.sources.extend(nodes.iter().map(|&b| model.bodies[b].offset));
            }
        }
        if !c.sources.is_empty() {
            c.sources.sort_unstable();
            c.sources.dedup();
            c.blocks = (0..c.sources.len()).map(|i| (c.sources[i], true, i)).collect();
            return c;
        }
        let Some(hub) = spin_hub(model) else { return c };
        c.sources.push(model.bodies[hub].offset);
        for b in &model.bodies {
            match b.kind {
                BodyKind::Rigid3(_) => c.blocks.push((b.offset, true, 0)),
                BodyKind::Point3(_) => c.blocks.push((b.offset, false, 0)),
                _ => return Corotated::default(),
            }
        }
        c
    }
}

/// The body on the mechanism's one revolute to the ground when everything may turn about that
/// revolute's axis (module docs), else `None`.
fn spin_hub(model: &Model) -> Option<usize> {
    let mut gravity: Option<V3> = None;
    for f in &model.forces {
        match &f.kind {
            ForceKind::Spatial(SpatialForce::Gravity { g }) => gravity = Some(*g),
            ForceKind::Spatial(SpatialForce::SpringDamper { a, b, .. } | SpatialForce::RotationalSpringDamper { a, b, .. })
                if a.body.is_some() && b.body.is_some() => {}
            _ => return None,
        }
    }
    let mut hub = None;
    for c in &model.constraints {
        let ConstraintKind::Spatial(s) = &c.kind else { return None };
        let Some(pair) = s.pair() else { continue };
        if pair.i.body.is_some() && pair.j.body.is_some() {
            if matches!(s, SpatialConstraint::Rotation(_) | SpatialConstraint::Translation(_)) {
                // a driver between two bodies is invariant too, but a time law is not a
                // symmetry worth the risk here: keep to the free mechanism
                return None;
            }
            continue;
        }
        let SpatialConstraint::Revolute(_) = s else { return None };
        let (ground, body) = if pair.i.body.is_none() { (&pair.i, &pair.j) } else { (&pair.j, &pair.i) };
        if hub.is_some() {
            return None;
        }
        let axis = col(&ground.c, 2);
        if let Some(g) = gravity {
            if norm(&cross(&axis, &g)) > AXIS_PARALLEL * norm(&axis) * norm(&g) {
                return None;
            }
        }
        let b = body.body?;
        if !matches!(model.bodies[b].kind, BodyKind::Rigid3(_)) {
            return None;
        }
        hub = Some(b);
    }
    hub
}
