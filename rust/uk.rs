//! The Udwadia-Kalaba acceleration (paper eqs. 70-74) with any factor `M = F F^T`:
//!
//! `qdd = a + F^-T B^+ (b - A a)`, `a = M^-1 Q`, `B = A F^-T`.
//!
//! With `F` the symmetric root this is the paper's eq. 70; every factor gives the same
//! Gauss-principle minimizer, and the block Cholesky factor of `dynamics::factor_mass` is the
//! cheap one. `B^+` comes from a thin faer SVD of `B^T = F^-1 A^T` (n x m) with an explicit rank
//! tolerance. Multipliers (sign of eq. 42: `M qdd + A^T lambda = Q`):
//! `lambda = (A M^-1 A^T)^+ (A a - b) = (B B^T)^+ (A a - b)`.

use faer::dyn_stack::MemStack;
use faer::linalg::svd::svd;
use faer::Par;

use crate::data::{Data, Factored, RankInfo, Stabilization, SvdBackend};
use crate::dynamics;
use crate::dynamics::{apply_finv, apply_finv_sparse, apply_finvt, constraints, factor_mass, mass_and_forces};
use crate::error::{Error, Result};
use crate::model::Model;

/// Evaluate every model term at `(t, q, qd)`: mass blocks and factor, `Q`, `A`, `Phi_t`,
/// `gamma` (and `Phi` when `with_phi`).
pub fn evaluate(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], with_phi: bool) -> Result<()> {
    mass_and_forces(model, data, q, qd);
    factor_mass(model, data)?;
    constraints(model, data, t, q, qd, with_phi);
    Ok(())
}

/// UK acceleration into `data.qdd` and multipliers into `data.lambda`, from the terms already
/// in `data` (see `evaluate`). The three stages below can also be called separately: the
/// factorization of `B^T` depends on `q` only (through `M` and `A`), so a caller that changes
/// only `Q` and `b` (velocity columns of a Jacobian) may reuse it.
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
    if let Some(sp) = data.sparse.as_mut() {
        if let Some(info) = sp.factor(model, &data.bodies, &data.ajac, &data.tolerance) {
            data.factored_with = Factored::SparseGram;
            data.rank_info = info;
            return Ok(());
        }
        // no full-rank certificate: the dense rank-revealing path decides (and reports) the rank
        data.ensure_dense(model)?;
    }
    factor_dense(model, data)
}

/// The dense path of `factor_constraints`: `B^T` (n x m) and its certified QR / SVD.
fn factor_dense(model: &Model, data: &mut Data) -> Result<()> {
    let (n, m) = (model.n, model.m);
    // B^T = F^-1 A^T, column by column
    for i in 0..m {
        let col = data.bt.col_as_slice_mut(i);
        col.copy_from_slice(&data.jac[i * n..(i + 1) * n]);
        apply_finv_sparse(model, &data.bodies, col);
    }
    let rcond = data.tolerance.rcond.unwrap_or((n.max(m) as f64) * f64::EPSILON);
    let atol = data.tolerance.atol;
    let backend = if data.qrj.is_some() { data.svd_backend } else { SvdBackend::Faer };
    match backend {
        SvdBackend::Auto | SvdBackend::QrJacobi => {
            let qrj = data.qrj.as_mut().expect("checked");
            let bt = &data.bt;
            qrj.qr_cols(|j| bt.col_as_slice(j));
            if backend == SvdBackend::Auto {
                let (upper, lower) = qrj.full_rank_bounds();
                let tol_bound = atol.max(rcond * upper);
                if upper.is_finite() && lower > tol_bound && lower > 0.0 {
                    data.factored_with = Factored::FullRankQr;
                    data.rank_info = RankInfo { rank: m, sigma_max: upper, sigma_min_kept: lower, sigma_max_dropped: 0.0, tolerance: tol_bound, exact: false };
                    return Ok(());
                }
            }
            if backend == SvdBackend::Auto && m > AUTO_JACOBI_MAX_ROWS {
                faer_svd(data)?;
            } else if jacobi_of_r(model, data).is_err() {
                if backend == SvdBackend::QrJacobi {
                    return Err(Error::Solver(format!("Jacobi SVD of A F^-T did not converge in {} sweeps", crate::linalg::small_svd::MAX_SWEEPS)));
                }
                // The one-sided Jacobi sweeps can stall on a rank-deficient B (redundant
                // constraint rows: columns of rounding-level norm keep being rotated); faer's
                // bidiagonal SVD of the same B^T (still in `data.bt`) is the robust fallback.
                faer_svd(data)?;
            }
        }
        SvdBackend::Faer => faer_svd(data)?,
    }
    data.rank_info = rank_from_singular_values(data, n, m, rcond, atol)?;
    Ok(())
}

/// Above this many constraint rows `exact_rank_info` keeps the sparse path's certified bounds
/// instead of running the dense SVD (at m = 256, n ~ 400 that SVD takes ~10 ms; at m = 2048 it
/// takes seconds and 100 MB).
pub const EXACT_RANK_MAX_ROWS: usize = 256;

/// Above this many constraint rows the `Auto` fallback (no full-rank certificate) uses faer's
/// bidiagonal SVD instead of Jacobi: measured crossover between m = 6 (Jacobi 1.6x faster) and
/// m = 32 (faer 3x faster), see docs/performance.md.
pub const AUTO_JACOBI_MAX_ROWS: usize = 12;

fn faer_svd(data: &mut Data) -> Result<()> {
    let stack = MemStack::new(&mut data.mem);
    svd(
        data.bt.as_ref(),
        data.svd_s.as_mut(),
        Some(data.svd_u.as_mut()),
        Some(data.svd_v.as_mut()),
        Par::Seq,
        stack,
        Default::default(),
    )
    .map_err(|e| Error::Solver(format!("SVD of A F^-T did not converge: {e:?}")))?;
    data.factored_with = Factored::Faer;
    Ok(())
}

/// Jacobi SVD of the R in `data.qrj` (after `qr_cols`); sorted values and right vectors are
/// copied to `svd_s`, `svd_v`.
fn jacobi_of_r(model: &Model, data: &mut Data) -> Result<()> {
    let k = model.n.min(model.m);
    let qrj = data.qrj.as_mut().expect("QR workspace");
    if !qrj.svd_of_r() {
        return Err(Error::Solver(format!("Jacobi SVD of A F^-T did not converge in {} sweeps", crate::linalg::small_svd::MAX_SWEEPS)));
    }
    let mut s = data.svd_s.column_vector_mut();
    for j in 0..k {
        s[j] = qrj.sigma(j);
        data.svd_v.col_as_slice_mut(j).copy_from_slice(qrj.v_col(j));
    }
    data.factored_with = Factored::Jacobi;
    Ok(())
}

fn rank_from_singular_values(data: &Data, n: usize, m: usize, rcond: f64, atol: f64) -> Result<RankInfo> {
    let k = n.min(m);
    let s = data.svd_s.column_vector();
    let sigma_max = if k > 0 { s[0] } else { 0.0 };
    if !sigma_max.is_finite() {
        return Err(Error::Solver("SVD of A F^-T: non-finite singular values".into()));
    }
    let tol = atol.max(rcond * sigma_max);
    let mut info = RankInfo { sigma_max, tolerance: tol, exact: true, ..Default::default() };
    for j in 0..k {
        let sj = s[j];
        if sj > tol && sj > 0.0 {
            info.rank += 1;
            info.sigma_min_kept = sj;
        } else if sj > info.sigma_max_dropped {
            info.sigma_max_dropped = sj;
        }
    }
    Ok(info)
}

/// Exact rank information of the current factorization: after the certified full-rank path
/// this runs the Jacobi SVD of the stored R (the singular values of `B`) -- O(m^3), not part of
/// the acceleration hot path -- and stores the exact `RankInfo` in `data.rank_info`. The
/// current correction stays valid (it needs only the QR part).
///
/// After the sparse path (certified full rank, `exact == false`) the exact values need the
/// dense SVD, O(n m^2) time and O(n m) memory: done here only for `m <= EXACT_RANK_MAX_ROWS`;
/// above, the certified report stays (rank = m exactly, `sigma_max` the upper bound
/// `sqrt(trace(A M^-1 A^T))`, `sigma_min_kept` the lower bound
/// `sqrt(1/(2 trace((A M^-1 A^T)^-1)) - delta)`, `exact == false`).
pub fn exact_rank_info(model: &Model, data: &mut Data) -> Result<RankInfo> {
    if data.factored_with == Factored::SparseGram && !data.rank_info.exact {
        if model.m > EXACT_RANK_MAX_ROWS {
            return Ok(data.rank_info);
        }
        // the singular values need the dense path (O(n m^2), on demand): factor the same `A`
        // (the segment form is current) densely; the correction stays valid (same `q`)
        data.ensure_dense(model)?;
        factor_dense(model, data)?;
    }
    if data.factored_with == Factored::FullRankQr && !data.rank_info.exact {
        let (n, m) = (model.n, model.m);
        let qrj = data.qrj.as_mut().expect("QR workspace");
        // keep R^-1 (in the Jacobi buffers) intact for the correction: work on a copy
        let mut tmp = qrj.clone();
        if !tmp.svd_of_r() {
            return Err(Error::Solver("Jacobi SVD of A F^-T did not converge".into()));
        }
        let rcond = data.tolerance.rcond.unwrap_or((n.max(m) as f64) * f64::EPSILON);
        let sigma_max = tmp.sigma(0);
        let tol = data.tolerance.atol.max(rcond * sigma_max);
        let mut info = RankInfo { sigma_max, tolerance: tol, exact: true, ..Default::default() };
        for j in 0..n.min(m) {
            let sj = tmp.sigma(j);
            if sj > tol && sj > 0.0 {
                info.rank += 1;
                info.sigma_min_kept = sj;
            } else if sj > info.sigma_max_dropped {
                info.sigma_max_dropped = sj;
            }
        }
        data.rank_info = info;
    }
    Ok(data.rank_info)
}

/// Every singular value of `B = A F^-T` at the terms in `data` (after `evaluate`), in
/// decreasing order: the dense SVD (O(n m^2); diagnostics, not the hot path). `None` above
/// `EXACT_RANK_MAX_ROWS` rows. Leaves the dense factorization in `data`.
pub fn singular_values(model: &Model, data: &mut Data) -> Result<Option<Vec<f64>>> {
    if model.m == 0 || model.m > EXACT_RANK_MAX_ROWS {
        return Ok(None);
    }
    data.ensure_dense(model)?;
    let backend = data.svd_backend;
    data.svd_backend = SvdBackend::Faer;
    let r = factor_dense(model, data);
    data.svd_backend = backend;
    r?;
    let k = model.n.min(model.m);
    let s = data.svd_s.column_vector();
    Ok(Some((0..k).map(|j| s[j]).collect()))
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
    for i in 0..model.m {
        data.residual[i] = data.gamma[i] - data.ajac.row_dot(i, &data.qdd_free);
    }
    correct_residual(model, data);
}

/// `correct` for the residual already in `data.residual` (dense paths).
fn correct_residual(model: &Model, data: &mut Data) {
    let (n, m) = (model.n, model.m);
    let k = n.min(m);
    let rank = data.rank_info.rank;
    if data.factored_with == Factored::FullRankQr {
        let qrj = data.qrj.as_mut().expect("factored with QR");
        qrj.full_rank_solve(&data.residual, &mut data.y, &mut data.lambda);
        data.qdd.copy_from_slice(&data.y);
        apply_finvt(model, &data.bodies, &mut data.qdd);
        return;
    }
    let s = data.svd_s.column_vector();
    // coeff = S^+ V^T r (kept singular values are the leading `rank`)
    for j in 0..k {
        if j < rank {
            let vj = data.svd_v.col_as_slice(j);
            let dot: f64 = vj.iter().zip(&data.residual).map(|(x, y)| x * y).sum();
            data.coeff[j] = dot / s[j];
        } else {
            data.coeff[j] = 0.0;
        }
    }
    data.lambda.fill(0.0);
    for j in 0..rank {
        let lj = -data.coeff[j] / s[j];
        let vj = data.svd_v.col_as_slice(j);
        for (li, vi) in data.lambda.iter_mut().zip(vj) {
            *li += vi * lj;
        }
    }
    match data.factored_with {
        Factored::Jacobi => {
            let qrj = data.qrj.as_mut().expect("factored with QrJacobi");
            qrj.add_u_times(&data.coeff, rank, &mut data.y);
        }
        _ => {
            for j in 0..rank {
                let cj = data.coeff[j];
                let uj = data.svd_u.col_as_slice(j);
                for (yi, ui) in data.y.iter_mut().zip(uj) {
                    *yi += ui * cj;
                }
            }
        }
    }
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
    solve(model, data)
}

/// `acceleration` that also leaves `Phi` in `data.phi` (for a projection that reuses the
/// factorization).
pub fn acceleration_with_phi(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) -> Result<()> {
    evaluate(model, data, t, q, qd, true)?;
    stabilize_rhs(model, data, qd);
    solve(model, data)
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
    if data.factored_with == Factored::SparseGram {
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
    dynamics::mass_and_forces(model, data, q, qd);
    let with_phi = matches!(data.stabilization, Stabilization::Baumgarte { .. });
    constraints(model, data, t, q, qd, with_phi);
    stabilize_rhs(model, data, qd);
    free_acceleration(model, data);
    if model.m == 0 {
        data.qdd.copy_from_slice(&data.qdd_free);
    } else {
        correct(model, data);
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
    solve(model, data)?;
    for i in 0..model.m {
        pos[i] = data.phi[i];
        vel[i] = data.ajac.row_dot(i, qd) + data.phi_t[i];
        acc[i] = data.ajac.row_dot(i, &data.qdd) - data.gamma[i];
    }
    Ok(())
}
