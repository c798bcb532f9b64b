//! Spatial (3D) rigid multibody systems (issue 30; docs/spatial.md, docs/spatial-design.md).
//!
//! A scene with `"dim": 3` is built here (`build`) into the same `Model` the planar scenes
//! use: its bodies are `BodyKind::Rigid3` (`body/rigid3.rs`, Euler parameters with the
//! regularized explicit factor) and `BodyKind::Point3` (`body/point3.rs`), its constraints
//! `ConstraintKind::Spatial` (`constraint/spatial/`, one file per joint kind, plus one
//! normalization row per rigid3 body), its forces `ForceKind::Spatial` (`force.rs`). The
//! kernels (`dynamics`, `uk`, `correct`, `integrate`) run them unchanged.
//!
//! `rot`: Euler-parameter algebra; `desc`: the description; `outputs`: the spatial sensors
//! (positions, orientations, angular velocities, 3D joint reactions, momenta).

pub mod build;
pub mod desc;
pub mod force;
pub mod outputs;
pub mod rot;

use crate::body::BodyKind;
use crate::model::Model;

/// A model built from a `"dim": 3` description (its bodies are spatial kinds).
pub fn is_spatial(model: &Model) -> bool {
    model.bodies.iter().any(|b| matches!(b.kind, BodyKind::Rigid3(_) | BodyKind::Point3(_)))
}
