//! ukflex: planar flexible multibody dynamics (floating frame of reference) with the
//! Udwadia-Kalaba formulation.
//!
//! Data flows one way: description (`description`) -> model (`model`, `body`, `constraint`,
//! `force`) -> workspace (`data`) -> kernels (`dynamics`, `uk`) -> results. `bindings` (feature
//! `python`) is the only module that knows Python.

pub mod body;
pub mod constraint;
pub mod data;
pub mod description;
pub mod dynamics;
pub mod error;
pub mod force;
pub mod integrate;
pub mod jacobian;
pub mod linalg;
pub mod model;
pub mod small_svd;
pub mod uk;

#[cfg(feature = "python")]
mod bindings;

pub use data::{Data, RankInfo, RankTolerance, SvdBackend};
pub use error::{Error, Result};
pub use model::Model;
