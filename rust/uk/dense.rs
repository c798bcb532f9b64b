//! The dense path of the UK correction: `B^T = F^-1 A^T` (n x m, `data.bt`) and its
//! pseudoinverse with the rank decision -- the certified full-rank QR, the one-sided Jacobi
//! SVD of `R` (`linalg::small_svd`) or faer's bidiagonal SVD (`SvdBackend`) -- and the
//! correction `y += U S^+ V^T r` with it. The path of small mechanisms, and the fallback of the
//! sparse path when its full-rank certificate fails (redundant or nearly dependent rows).

use faer::dyn_stack::MemStack;
use faer::linalg::svd::svd;
use faer::Par;

use super::settings::{Factored, RankInfo, SvdBackend};
use crate::data::Data;
use crate::dynamics::{apply_finv_sparse, apply_finvt};
use crate::error::{Error, Result};
use crate::linalg::small_svd::{RankRule, MAX_SWEEPS};
use crate::model::Model;

/// The dense path of `factor_constraints`: `B^T` (n x m) and its certified QR / SVD.
pub(super) fn factor_dense(model: &Model, data: &mut Data) -> Result<()> {
    let (n, m) = (model.n, model.m);
    // B^T = F^-1 A^T, column by column
    for i in 0..m {
        let col = data.bt.col_as_slice_mut(i);
        col.copy_from_slice(&data.jac.read(&data.ajac)[i * n..(i + 1) * n]);
        apply_finv_sparse(model, &data.bodies, col);
    }
    let rcond = data.tolerance.rcond_at(n, m, data.spatial_drift);
    let atol = data.tolerance.atol;
    // rows found redundant at the last nearly consistent state, far off the manifold: their
    // singular values may pass the capped tolerance (and a full-rank certificate) but are the
    // drift's, so the rank-revealing path decides with the drift's tolerance for them
    let redundant = redundant_rule(data);
    let backend = if data.qrj.is_some() { data.svd_backend } else { SvdBackend::Faer };
    match backend {
        SvdBackend::Auto | SvdBackend::QrJacobi | SvdBackend::Cod => {
            let qrj = data.qrj.as_mut().expect("checked");
            let bt = &data.bt;
            qrj.qr_cols(|j| bt.col_as_slice(j));
            let auto = backend != SvdBackend::QrJacobi;
            if auto && data.redundant == 0 {
                let (upper, lower) = qrj.full_rank_bounds();
                let tol_bound = atol.max(rcond * upper);
                if upper.is_finite() && lower > tol_bound && lower > 0.0 {
                    data.factored_with = Factored::FullRankQr;
                    data.rank_info = RankInfo { rank: m, sigma_max: upper, sigma_min_kept: lower, sigma_max_dropped: 0.0, tolerance: tol_bound, exact: false };
                    record_redundancy(data, n, m);
                    return Ok(());
                }
            }
            if auto && m > AUTO_JACOBI_MAX_ROWS {
                // rank-deficient: with `Cod`, the certified complete orthogonal decomposition of
                // R, the SVD only when its bounds cannot decide the rank
                let (red, rcond_red) = redundant.unwrap_or((0, rcond));
                let rule = RankRule { rcond, atol, redundant: red, rcond_redundant: rcond_red };
                // one redundant row (as at the last consistent state, or none known yet): the
                // SVD's truncation by deflation, certified, without the SVD
                if backend == SvdBackend::Auto && data.redundant <= 1 {
                    if let Some(c) = qrj.deflate_factor(&rule) {
                        data.factored_with = Factored::Deflated;
                        data.rank_info = RankInfo { rank: c.rank, sigma_max: c.sigma_max, sigma_min_kept: c.sigma_min_kept, sigma_max_dropped: c.sigma_max_dropped, tolerance: c.tolerance, exact: false };
                        record_redundancy(data, n, m);
                        return Ok(());
                    }
                }
                if let Some(c) = if backend == SvdBackend::Cod { qrj.cod_factor(&rule) } else { None } {
                    data.factored_with = Factored::Cod;
                    data.rank_info = RankInfo { rank: c.rank, sigma_max: c.sigma_max, sigma_min_kept: c.sigma_min_kept, sigma_max_dropped: c.sigma_max_dropped, tolerance: c.tolerance, exact: false };
                    record_redundancy(data, n, m);
                    return Ok(());
                }
                faer_svd(data)?;
            } else if jacobi_of_r(model, data).is_err() {
                if backend == SvdBackend::QrJacobi {
                    return Err(Error::Solver(format!("Jacobi SVD of A F^-T did not converge in {} sweeps", MAX_SWEEPS)));
                }
                // The one-sided Jacobi sweeps can stall on a rank-deficient B (redundant
                // constraint rows: columns of rounding-level norm keep being rotated); faer's
                // bidiagonal SVD of the same B^T (still in `data.bt`) is the robust fallback.
                faer_svd(data)?;
            }
        }
        SvdBackend::Faer => faer_svd(data)?,
    }
    data.rank_info = rank_from_singular_values(data, n, m, rcond, atol, redundant)?;
    record_redundancy(data, n, m);
    Ok(())
}

/// `(count, relative tolerance)` for the smallest singular values found redundant at the last
/// nearly consistent state, when the state is far enough off the manifold that the capped
/// tolerance may keep them (`RankTolerance::redundant_rcond`); `None` otherwise.
pub(super) fn redundant_rule(data: &Data) -> Option<(usize, f64)> {
    if data.redundant == 0 {
        return None;
    }
    data.tolerance.redundant_rcond(data.spatial_drift).map(|r| (data.redundant, r))
}

/// After a rank decision at a nearly consistent state (`RankTolerance::decides_redundancy`):
/// keep how many singular values it dropped.
pub(super) fn record_redundancy(data: &mut Data, n: usize, m: usize) {
    if data.tolerance.decides_redundancy(data.spatial_drift) {
        data.redundant = n.min(m) - data.rank_info.rank.min(n.min(m));
    }
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
    crate::linalg::simd_state::after_wide(|| {
        svd(
            data.bt.as_ref(),
            data.svd_s.as_mut(),
            Some(data.svd_u.as_mut()),
            Some(data.svd_v.as_mut()),
            Par::Seq,
            stack,
            Default::default(),
        )
    })
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
        return Err(Error::Solver(format!("Jacobi SVD of A F^-T did not converge in {} sweeps", MAX_SWEEPS)));
    }
    let mut s = data.svd_s.column_vector_mut();
    for j in 0..k {
        s[j] = qrj.sigma(j);
        qrj.v_col_into(j, data.svd_v.col_as_slice_mut(j));
    }
    data.factored_with = Factored::Jacobi;
    Ok(())
}

fn rank_from_singular_values(data: &Data, n: usize, m: usize, rcond: f64, atol: f64, redundant: Option<(usize, f64)>) -> Result<RankInfo> {
    let k = n.min(m);
    let s = data.svd_s.column_vector();
    let sigma_max = if k > 0 { s[0] } else { 0.0 };
    if !sigma_max.is_finite() {
        return Err(Error::Solver("SVD of A F^-T: non-finite singular values".into()));
    }
    Ok(rank_decision(k, |j| s[j], rcond, atol, redundant))
}

/// The rank decision on the `k` singular values `sigma(0) >= sigma(1) >= ...`: those above
/// `max(atol, rcond sigma_max)` (and above zero) are kept; with `redundant = (r, rc)` the `r`
/// smallest are kept only above `max(atol, rc sigma_max)` (`redundant_rule`).
fn rank_decision(k: usize, sigma: impl Fn(usize) -> f64, rcond: f64, atol: f64, redundant: Option<(usize, f64)>) -> RankInfo {
    let sigma_max = if k > 0 { sigma(0) } else { 0.0 };
    let tol = atol.max(rcond * sigma_max);
    let (r, rc) = redundant.unwrap_or((0, rcond));
    let tol_redundant = tol.max(rc * sigma_max);
    let mut info = RankInfo { sigma_max, tolerance: tol, exact: true, ..Default::default() };
    for j in 0..k {
        let sj = sigma(j);
        let tj = if j + r >= k { tol_redundant } else { tol };
        if sj > tj && sj > 0.0 {
            info.rank += 1;
            info.sigma_min_kept = sj;
        } else if sj > info.sigma_max_dropped {
            info.sigma_max_dropped = sj;
        }
    }
    info
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
    if data.factored_with == Factored::Gram && !data.rank_info.exact {
        // the singular values by the dense QR + Jacobi SVD of the same B^T (its correction
        // then serves: same q, same rank)
        data.ensure_dense(model)?;
        factor_dense(model, data)?;
    }
    if data.factored_with == Factored::SparseGram && !data.rank_info.exact {
        if model.m > EXACT_RANK_MAX_ROWS {
            return Ok(data.rank_info);
        }
        // the singular values need the dense path (O(n m^2), on demand): factor the same `A`
        // (the segment form is current) densely; the correction stays valid (same `q`)
        data.ensure_dense(model)?;
        factor_dense(model, data)?;
    }
    if matches!(data.factored_with, Factored::Cod | Factored::Deflated) && !data.rank_info.exact {
        // the bounds of the decomposition: the exact values by the SVD of the same B^T (the
        // correction then uses it: same q, same rank)
        let (n, m) = (model.n, model.m);
        let rcond = data.tolerance.rcond_at(n, m, data.spatial_drift);
        let redundant = redundant_rule(data);
        faer_svd(data)?;
        data.rank_info = rank_from_singular_values(data, n, m, rcond, data.tolerance.atol, redundant)?;
    }
    if data.factored_with == Factored::FullRankQr && !data.rank_info.exact {
        let (n, m) = (model.n, model.m);
        let qrj = data.qrj.as_mut().expect("QR workspace");
        // keep R^-1 (in the Jacobi buffers) intact for the correction: work on a copy
        let mut tmp = qrj.clone();
        if !tmp.svd_of_r() {
            return Err(Error::Solver("Jacobi SVD of A F^-T did not converge".into()));
        }
        let rcond = data.tolerance.rcond_at(n, m, data.spatial_drift);
        data.rank_info = rank_decision(n.min(m), |j| tmp.sigma(j), rcond, data.tolerance.atol, None);
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


/// `correct` for the residual already in `data.residual` (dense paths).
pub(super) fn correct_residual(model: &Model, data: &mut Data) {
    let (n, m) = (model.n, model.m);
    let k = n.min(m);
    let rank = data.rank_info.rank;
    if matches!(data.factored_with, Factored::FullRankQr | Factored::Cod | Factored::Deflated) {
        let qrj = data.qrj.as_mut().expect("factored with QR");
        if data.factored_with == Factored::Cod {
            qrj.cod_solve(&data.residual, &mut data.y, &mut data.lambda);
        } else if data.factored_with == Factored::Deflated {
            qrj.deflate_solve(&data.residual, &mut data.y, &mut data.lambda);
        } else {
            qrj.full_rank_solve(&data.residual, &mut data.y, &mut data.lambda);
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::correct::{correct, CorrectOptions};
    use crate::linalg::small_svd::QrJacobi;
    use crate::uk;

    /// The normalization rows eliminated in the QR (`Model::unit_columns`) give the accelerations,
    /// multipliers and rank of the plain QR of `B^T` on the spatial slider-crank (certified
    /// full-rank path) and on Bricard's mechanism (rank 34 of 35: the Jacobi SVD of the permuted
    /// `R`, and the default path), at a consistent state and off it.
    #[test]
    fn eliminated_normalization_rows_change_nothing() {
        let scenes = [
            (include_str!("../../benches/data/spatial/slider_crank.json"), 20, SvdBackend::Auto),
            (include_str!("../../benches/data/spatial/bricard.json"), 34, SvdBackend::QrJacobi),
            (include_str!("../../benches/data/spatial/bricard.json"), 34, SvdBackend::Auto),
        ];
        for (json, rank, backend) in scenes {
            let model = Model::from_json(json).unwrap();
            let (n, m) = (model.n, model.m);
            assert_eq!(model.unit_columns().len(), model.bodies.len(), "one normalization row per rigid3 body");
            let fresh = || {
                let mut d = Data::new(&model);
                d.ensure_dense(&model).unwrap();
                d.svd_backend = backend;
                d
            };
            let (mut data, mut plain) = (fresh(), fresh());
            plain.qrj = Some(QrJacobi::new(n, m));
            let opts = CorrectOptions { hold: vec![false; n], rigid: false, position_tol: 1e-12, velocity_tol: 1e-10, max_iterations: 50 };
            let c = correct(&model, &mut data, 0.0, &model.q0, &model.qd0, &opts).unwrap();
            for (k, scale) in [(0usize, 0.0), (1, 1e-7)] {
                let q: Vec<f64> = c.q.iter().enumerate().map(|(i, x)| x + scale * ((i * 7 + k) as f64).sin()).collect();
                uk::acceleration(&model, &mut data, 0.0, &q, &c.qd).unwrap();
                uk::acceleration(&model, &mut plain, 0.0, &q, &c.qd).unwrap();
                assert_eq!(data.rank_info.rank, rank);
                assert_eq!(plain.rank_info.rank, rank);
                assert_eq!(data.factored_with, plain.factored_with);
                let amax = plain.qdd.iter().fold(1.0f64, |a, x| a.max(x.abs()));
                let lmax = plain.lambda.iter().fold(1.0f64, |a, x| a.max(x.abs()));
                for i in 0..n {
                    assert!((data.qdd[i] - plain.qdd[i]).abs() < 1e-12 * amax, "qdd[{i}] {} vs {}", data.qdd[i], plain.qdd[i]);
                }
                for i in 0..m {
                    assert!((data.lambda[i] - plain.lambda[i]).abs() < 1e-10 * lmax, "lambda[{i}] {} vs {}", data.lambda[i], plain.lambda[i]);
                }
            }
        }
    }
}
