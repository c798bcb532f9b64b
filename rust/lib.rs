//! ukflex: planar flexible multibody dynamics (floating frame of reference) with the
//! Udwadia-Kalaba formulation.
//!
//! Data flows one way: description (`description`) -> model (`model`, `body`, `constraint`,
//! `force`, the expression language `expr`) -> workspace (`data`) -> kernels (`dynamics`, `uk`, `jacobian`) -> drivers
//! (`integrate`, `correct`) -> results. `bindings` (feature `python`) is the only module that
//! knows Python. Each body kind owns its code in `body/` (the floating-frame kinds share
//! `body/ffrf.rs`), each joint kind in `constraint/`; the numerics (dense, banded, LU, SVD,
//! orderings) live in `linalg/`, the UK solves and their settings in `uk/`. See
//! `docs/architecture.md`.

// Numeric kernels index like the papers they follow; `!(x > 0.0)` is the deliberate NaN-rejecting
// form of a positivity check; kernels take the state slices and the outputs they write.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord, clippy::too_many_arguments)]

pub mod body;
pub mod constraint;
pub mod correct;
pub mod data;
pub mod description;
pub mod dynamics;
pub mod error;
pub mod expr;
pub mod force;
pub mod integrate;
pub mod jacobian;
pub mod linalg;
pub mod model;
pub mod sensors;
pub mod sparse_newton;
pub mod uk;

#[cfg(feature = "python")]
mod bindings;

pub use data::Data;
pub use error::{Error, Result};
/// The band LU's old path (`crate::band_lu`), still used by the implicit methods.
pub use linalg::band_lu;
pub use model::Model;
pub use uk::{RankInfo, RankTolerance, SvdBackend, UkSolver};
