//! The mass conditioning of a corrected initial state (`check_state`, with the resolution rule
//! of `model::scale`): the rank of `A M^-1/2` must be the rank of `A`.

use crate::data::Data;
use crate::dynamics;
use crate::error::{fmt_g, Error, Result};
use crate::model::scale::{check_resolution, is_rotation};
use crate::model::Model;
use crate::uk;

/// Largest problem (`m n min(m, n)`) for which a rank-deficient start is cross-checked against
/// the unweighted Jacobian (a dense SVD: ~1 s at this size).
pub const CONDITIONING_CHECK_WORK: f64 = 2e9;

/// Refuse masses so disparate that the UK solve cannot tell independent constraints from
/// redundant ones: the rank of `A M^-1/2` at the state must equal the rank of `A` (columns
/// equilibrated, so units do not matter). Only a rank-deficient solve needs the check; it runs
/// the UK solve at the state (which leaves the workspace at that state).
pub fn check_conditioning(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) -> Result<()> {
    let (m, n) = (model.m, model.n);
    if m == 0 {
        return Ok(());
    }
    uk::acceleration(model, data, t, q, qd)?;
    let rank = data.rank_info.rank;
    if rank >= m || (m * n * m.min(n)) as f64 > CONDITIONING_CHECK_WORK {
        return Ok(());
    }
    let mut a = vec![0.0; m * n];
    data.ajac.scatter(&mut a); // row-major m x n
    let dead: Vec<&str> = (0..m)
        .filter(|&i| a[i * n..(i + 1) * n].iter().all(|&v| v == 0.0))
        .map(|i| model.constraint_row_names[i].as_str())
        .collect();
    if !dead.is_empty() {
        return Err(Error::Description(format!(
            "constraint row(s) {} are degenerate at the start: their gradient vanishes (e.g. a distance between \
             coincident points, whose direction is undefined); use a revolute joint for coincident points, or check \
             the lengths and their units",
            dead.join(", ")
        )));
    }
    let mut norms = vec![0.0; n];
    for i in 0..m {
        for j in 0..n {
            norms[j] += a[i * n + j] * a[i * n + j];
        }
    }
    let scaled = faer::Mat::<f64>::from_fn(m, n, |i, j| {
        let s = norms[j].sqrt();
        a[i * n + j] / if s == 0.0 { 1.0 } else { s }
    });
    let svd = crate::linalg::simd_state::after_wide(|| scaled.thin_svd()).map_err(|_| Error::Solver("the singular values of A did not converge".into()))?;
    let sv: Vec<f64> = (0..m.min(n)).map(|k| svd.S().column_vector()[k]).collect();
    let top = sv.iter().cloned().fold(0.0_f64, f64::max);
    let tol = (m.max(n) as f64) * f64::EPSILON * top;
    let rank_a = if top > 0.0 { sv.iter().filter(|&&s| s > tol).count() } else { 0 };
    if rank_a <= rank {
        return Ok(()); // the redundancy is the constraints' own
    }
    dynamics::mass_and_forces(model, data, t, q, qd);
    let mass = dynamics::dense_mass(model, data);
    let scale = model.length_scale;
    let names = &model.coordinate_names;
    let d: Vec<f64> = (0..n).map(|i| mass[i * n + i] / if is_rotation(&names[i]) { scale * scale } else { 1.0 }).collect();
    let (mut lo, mut hi) = (0, 0);
    for i in 0..n {
        if d[i] < d[lo] {
            lo = i;
        }
        if d[i] > d[hi] {
            hi = i;
        }
    }
    let describe = |i: usize| {
        let per = if is_rotation(&names[i]) { format!(", inertia / {} m^2", fmt_g(scale, 3)) } else { String::new() };
        format!("{} kg ({}{per})", fmt_g(d[i], 3), names[i])
    };
    Err(Error::Description(format!(
        "the masses span too many orders of magnitude for double precision: the {m} constraints are independent (rank \
         {rank_a} of A at the start) but the mass-weighted UK solve resolves only rank {rank}; the mass matrix ranges \
         from {} to {}; check tiny bodies (lengths, masses, inertias) and their units",
        describe(lo),
        describe(hi)
    )))
}

/// The checks of a corrected initial state (`check_resolution`, `check_conditioning`).
pub fn check_state(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) -> Result<()> {
    check_resolution(model, q)?;
    check_conditioning(model, data, t, q, qd)
}

