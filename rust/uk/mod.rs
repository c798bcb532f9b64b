//! The Udwadia-Kalaba acceleration (paper eqs. 70-74) with any factor `M = F F^T`:
//!
//! `qdd = a + F^-T B^+ (b - A a)`, `a = M^-1 Q`, `B = A F^-T`.
//!
//! With `F` the symmetric root this is the paper's eq. 70; every factor gives the same
//! Gauss-principle minimizer, and the block Cholesky factor of `dynamics::factor_mass` is the
//! cheap one. `B^+` comes from a factorization of `B^T = F^-1 A^T` (n x m) with an explicit rank
//! tolerance. Multipliers (sign of eq. 42: `M qdd + A^T lambda = Q`):
//! `lambda = (A M^-1 A^T)^+ (A a - b) = (B B^T)^+ (A a - b)`.
//!
//! Three paths factor `B^T`: `dense` (the pseudoinverse with an explicit rank decision),
//! `sparse` (a band Cholesky of `B B^T` with a certificate of full rank, for long chains) and
//! `gram` (small spatial models: the envelope Cholesky of `B B^T` with the normalization rows
//! eliminated and the same certificate; `dense` when it fails); `settings` holds the types that choose between them and report the rank. This file is the
//! algorithm: evaluate the terms, the free acceleration, factor, correct.

pub mod dense;
pub mod friction;
pub mod gram;
mod seg;
pub mod settings;
pub mod sparse;

pub use dense::{exact_rank_info, singular_values, AUTO_JACOBI_MAX_ROWS, EXACT_RANK_MAX_ROWS};
pub use settings::{Factored, RankInfo, RankTolerance, Stabilization, SvdBackend, UkSolver};

use crate::data::Data;
use crate::dynamics;
use crate::dynamics::{apply_finv, apply_finvt, constraints, factor_mass, mass_and_forces};
use crate::error::Result;
use crate::model::Model;
use dense::{correct_residual, factor_dense};

/// Evaluate every model term at `(t, q, qd)`: mass blocks and factor, `Q`, `A`, `Phi_t`,
/// `gamma` (and `Phi` when `with_phi`).
pub fn evaluate(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], with_phi: bool) -> Result<()> {
    mass_and_forces(model, data, t, q, qd);
    factor_mass(model, data)?;
    constraints(model, data, t, q, qd, with_phi);
    Ok(())
}

/// UK acceleration into `data.qdd` and multipliers into `data.lambda`, from the terms already
/// in `data` (see `evaluate`), joint friction left out (`solve_closed` adds it). The three
/// stages below can also be called separately: the factorization of `B^T` depends on `q`
/// only (through `M` and `A`), so a caller that changes only `Q` and `b` (velocity columns of
/// a Jacobian) may reuse it.
pub fn solve(model: &Model, data: &mut Data) -> Result<()> {
    free_acceleration(model, data);
    if model.m == 0 {
        data.qdd.copy_from_slice(&data.qdd_free);
        data.rank_info = RankInfo { exact: true, ..Default::default() };
        return Ok(());
    }
    factor_constraints(model, data)?;
    correct(model, data);
    Ok(())
}

/// `solve`, then the joint friction closed with the multipliers (`friction::close`; nothing
/// without friction elements). The acceleration calls use this; `solve` alone is the linear
/// UK solve of the terms in `data` (the projections' minimum-norm steps, with `Q = 0`, must
/// not see friction).
#[inline]
fn solve_closed(model: &Model, data: &mut Data) -> Result<()> {
    solve(model, data)?;
    if data.friction.is_some() && model.m > 0 {
        friction::close(model, data, false)?;
    }
    Ok(())
}

/// `y = F^-1 Q`, `a = F^-T y` (the unconstrained acceleration `qdd_free`).
pub fn free_acceleration(model: &Model, data: &mut Data) {
    data.y.copy_from_slice(&data.force);
    apply_finv(model, &data.bodies, &mut data.y);
    data.qdd_free.copy_from_slice(&data.y);
    apply_finvt(model, &data.bodies, &mut data.qdd_free);
}

/// `B^T = F^-1 A^T` and its thin SVD with the rank decision (into `data.rank_info`).
/// Needs `m > 0` and the mass factor of `dynamics::factor_mass`.
pub fn factor_constraints(model: &Model, data: &mut Data) -> Result<()> {
    // rows found redundant before, far off the manifold: the rank-revealing path decides
    let sparse = if dense::redundant_rule(data).is_none() { data.sparse.as_mut() } else { None };
    if let Some(sp) = sparse {
        let tol = data.tolerance.resolved(model.n, model.m, data.spatial_drift);
        if let Some(info) = sp.factor(model, &data.bodies, &data.ajac, &tol) {
            data.factored_with = Factored::SparseGram;
            data.rank_info = info;
            dense::record_redundancy(data, model.n, model.m);
            return Ok(());
        }
    }
    if data.gram.is_some() && factor_gram(model, data) {
        return Ok(());
    }
    // no full-rank certificate: the dense rank-revealing path decides (and reports) the rank
    data.ensure_dense(model)?;
    factor_dense(model, data)
}

/// The spatial Gram path (`gram`), where the model has one (`Data::gram`), no rows were found
/// redundant and the backend is the certified one (`Auto`, `Cod`), unless it was refused within
/// the last `gram::GRAM_RETRY` factorizations: `true` when it certified full rank (the
/// factorization is then in `data.gram`). Out of line: the planar path keeps
/// its code.
#[inline(never)]
fn factor_gram(model: &Model, data: &mut Data) -> bool {
    if data.redundant != 0 || !matches!(data.svd_backend, SvdBackend::Auto | SvdBackend::Cod) {
        return false;
    }
    let Some(g) = data.gram.as_mut() else { return false };
    if g.skip > 0 {
        g.skip -= 1;
        return false;
    }
    let rcond = data.tolerance.rcond_at(model.n, model.m, data.spatial_drift);
    match g.factor(model, &data.bodies, &data.ajac, rcond, data.tolerance.atol) {
        Some(info) => {
            data.factored_with = Factored::Gram;
            data.rank_info = info;
            dense::record_redundancy(data, model.n, model.m);
            true
        }
        None => {
            g.skip = gram::GRAM_RETRY;
            false
        }
    }
}

/// The constraint correction with the current factorization: `r = b - A a`,
/// `y += U S^+ V^T r`, `lambda = -V S^+ S^+ V^T r`, `qdd = F^-T y`.
pub fn correct(model: &Model, data: &mut Data) {
    if data.factored_with == Factored::SparseGram {
        let sp = data.sparse.as_mut().expect("factored sparse");
        sp.correct(&data.gamma, &mut data.residual, &mut data.y, &mut data.lambda);
        data.qdd.copy_from_slice(&data.y);
        apply_finvt(model, &data.bodies, &mut data.qdd);
        return;
    }
    if data.factored_with == Factored::Gram {
        correct_gram(model, data);
        return;
    }
    for i in 0..model.m {
        data.residual[i] = data.gamma[i] - data.ajac.row_dot(i, &data.qdd_free);
    }
    correct_residual(model, data);
}

/// `correct` on the Gram path's factorization (out of line: the planar path keeps its code).
#[inline(never)]
fn correct_gram(model: &Model, data: &mut Data) {
    let g = data.gram.as_mut().expect("factored by the Gram path");
    g.correct(&data.gamma, &mut data.residual, &mut data.y, &mut data.lambda);
    data.qdd.copy_from_slice(&data.y);
    apply_finvt(model, &data.bodies, &mut data.qdd);
}

/// `qdd = UK(t, q, qd)` into `data.qdd` (and `data.lambda`). Allocation free.
/// With Baumgarte stabilization the right-hand side becomes
/// `b = gamma - 2 alpha (A qd + Phi_t) - beta^2 Phi`.
pub fn acceleration(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) -> Result<()> {
    let with_phi = matches!(data.stabilization, Stabilization::Baumgarte { .. });
    evaluate(model, data, t, q, qd, with_phi)?;
    stabilize_rhs(model, data, qd);
    solve_closed(model, data)
}

/// `acceleration` that also leaves `Phi` in `data.phi` (for a projection that reuses the
/// factorization).
pub fn acceleration_with_phi(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) -> Result<()> {
    evaluate(model, data, t, q, qd, true)?;
    stabilize_rhs(model, data, qd);
    solve_closed(model, data)
}

/// `data.qdd = F^-T B^+ r`: the minimum-mass-norm `dx` with `A dx = r`, from the
/// factorization of `B^T = F^-1 A^T` already in `data` (left by `solve`). Overwrites `y`,
/// `qdd_free`, `gamma`, `residual`, `coeff`, `lambda` and `qdd` of `data`.
pub fn min_norm_correction(model: &Model, data: &mut Data, r: &[f64]) {
    if model.m == 0 {
        data.qdd.fill(0.0);
        return;
    }
    // correct(): y += B^+ (gamma - A qdd_free), qdd = F^-T y; with y = qdd_free = 0, gamma = r
    data.qdd_free.fill(0.0);
    data.y.fill(0.0);
    data.gamma.copy_from_slice(r);
    if matches!(data.factored_with, Factored::SparseGram | Factored::Gram) {
        correct(model, data);
    } else {
        // the residual is r itself (A 0 = 0)
        data.residual.copy_from_slice(r);
        correct_residual(model, data);
    }
}

/// `qdd` at `(t, q, qd)` reusing the mass factor and the SVD of `B^T` already in `data`, which
/// must come from a full `acceleration` at the same `q` (and `t` for rheonomic rows): `M`, `A`
/// and `B` depend on `q` only, so a change of `qd` changes just `Q` and `b`. Used for the
/// velocity columns of the finite-difference Jacobian.
pub fn acceleration_same_q(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) -> Result<()> {
    dynamics::mass_and_forces(model, data, t, q, qd);
    let with_phi = matches!(data.stabilization, Stabilization::Baumgarte { .. });
    constraints(model, data, t, q, qd, with_phi);
    stabilize_rhs(model, data, qd);
    free_acceleration(model, data);
    if model.m == 0 {
        data.qdd.copy_from_slice(&data.qdd_free);
    } else {
        correct(model, data);
        if data.friction.is_some() {
            // the responses to the friction forces depend on q only: those of the full call
            friction::close(model, data, true)?;
        }
    }
    Ok(())
}

/// Baumgarte: `b <- gamma - 2 alpha (A qd + Phi_t) - beta^2 Phi` (needs `Phi`).
fn stabilize_rhs(model: &Model, data: &mut Data, qd: &[f64]) {
    if let Stabilization::Baumgarte { alpha, beta } = data.stabilization {
        for i in 0..model.m {
            let vel = data.ajac.row_dot(i, qd) + data.phi_t[i];
            data.gamma[i] -= 2.0 * alpha * vel + beta * beta * data.phi[i];
        }
    }
}

/// Residuals at `(t, q, qd)` with the UK acceleration: position `Phi`, velocity
/// `A qd + Phi_t`, acceleration `A qdd - b`, written into the three slices (length m).
pub fn residuals(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], pos: &mut [f64], vel: &mut [f64], acc: &mut [f64]) -> Result<()> {
    evaluate(model, data, t, q, qd, true)?;
    solve_closed(model, data)?;
    for i in 0..model.m {
        pos[i] = data.phi[i];
        vel[i] = data.ajac.row_dot(i, qd) + data.phi_t[i];
        acc[i] = data.ajac.row_dot(i, &data.qdd) - data.gamma[i];
    }
    Ok(())
}
