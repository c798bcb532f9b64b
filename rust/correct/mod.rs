//! Moving a state onto the constraint manifold (between steps and at build; allocates, not
//! the acceleration hot path), in two responsibilities:
//!
//! * `project` (after integration steps and on request): Newton steps
//!   `dq = -M^-1 A^T (A M^-1 A^T)^+ Phi` onto `Phi = 0`, then
//!   `dqd = -M^-1 A^T (A M^-1 A^T)^+ (A qd + Phi_t)`: the closest consistent state in the
//!   kinetic-energy norm (Gauss's principle applied to the correction). Each step is the UK
//!   kernel with `Q = 0` and `b = -residual`.
//! * `initial` (the initial-state correction): the same, with some coordinates held at their
//!   values (by default every body's deformation, so an undeformed guess stays undeformed: the
//!   elastic coordinates of FFRF and modal bodies, and an ANCF cable moves only rigidly, in
//!   `rigid`), damped Newton steps, and a report of what changed.

mod conditioning;
mod initial;
mod project;
mod rigid;

pub use conditioning::{check_state, CONDITIONING_CHECK_WORK};
pub use initial::{correct, correct_within, CorrectOptions, Correction};
pub use project::{project, project_in_place, project_with_factorization, ProjectOutcome, ProjectWorkspace, Projection, ProjectionTolerance};

use faer::Mat;

use crate::data::Data;
use crate::error::{Error, Result};
use crate::linalg::dense::pinv_solve;
use crate::model::Model;

/// `max |v_i|`.
fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// `sqrt(v^T M v)` from the body blocks in `data` (reporting only).
fn mass_norm(model: &Model, data: &Data, v: &[f64]) -> f64 {
    let e: f64 = model.bodies.iter().zip(&data.bodies).map(|(b, bd)| b.kinetic_energy(bd, v)).sum();
    (2.0 * e).max(0.0).sqrt()
}

/// `A qd + Phi_t` from the terms in `data`.
fn velocity_residual(model: &Model, data: &Data, qd: &[f64], out: &mut [f64]) {
    debug_assert_eq!(out.len(), model.m);
    for (i, o) in out.iter_mut().enumerate() {
        *o = data.ajac.row_dot(i, qd) + data.phi_t[i];
    }
}

/// The Gauss projection in a reduced basis `C` of `k` columns (the free coordinates, or the
/// bodies' rigid motions): `y = F^-T (A C F^-T)^+ r` with `C^T M C = F F^T` block diagonal by
/// body, the pseudoinverse with the rank cut of `scipy.linalg.pinv` (`linalg::dense::pinv_solve`).
/// `row_into(i, col)` adds row `i` of `A C` into the zeroed `col` (k); `finv` and `finvt`
/// apply `F^-1` and `F^-T` in place.
fn reduced_gauss_step(k: usize, r: &[f64], row_into: impl Fn(usize, &mut [f64]), finv: impl Fn(&mut [f64]), finvt: impl Fn(&mut [f64])) -> Result<Vec<f64>> {
    let m = r.len();
    // B^T = F^-1 (A C)^T (k x m)
    let mut bt = Mat::<f64>::zeros(k, m);
    let mut col = vec![0.0; k];
    for i in 0..m {
        col.fill(0.0);
        row_into(i, &mut col);
        finv(&mut col);
        for p in 0..k {
            bt[(p, i)] = col[p];
        }
    }
    let mut y = pinv_solve(&bt, r).map_err(|e| Error::Solver(format!("SVD in the state correction did not converge: {e:?}")))?;
    finvt(&mut y);
    Ok(y)
}
