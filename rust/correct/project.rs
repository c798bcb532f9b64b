//! The projection onto the constraint manifold after integration steps (and `System.project`):
//! chord Newton through the factorization of the last acceleration call
//! (`project_with_factorization`), or from scratch without allocation (`project_in_place`),
//! or the reporting projection `project`.

use super::{mass_norm, max_abs, velocity_residual};
use crate::data::Data;
use crate::dynamics::{constraints, mass_and_forces};
use crate::error::Result;
use crate::model::Model;
use crate::uk::{evaluate, solve};

/// Outcome of a projection onto the constraint manifold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Newton iterations used for the positions.
    pub iterations: usize,
    /// max |Phi| after the position correction.
    pub position_residual: f64,
    /// max |A qd + Phi_t| after the velocity correction.
    pub velocity_residual: f64,
    /// Mass-norm of the position and velocity corrections, `sqrt(dq^T M dq)`.
    pub position_correction: f64,
    pub velocity_correction: f64,
}

/// Project `(q, qd)` onto `Phi(q, t) = 0` and `A qd + Phi_t = 0` along the mass metric.
pub fn project(model: &Model, data: &mut Data, t: f64, q: &mut [f64], qd: &mut [f64], tol: f64, max_iter: usize) -> Result<Projection> {
    let n = model.n;
    let zeros = vec![0.0; n];
    let mut dq_total = vec![0.0; n];
    let mut iterations = 0;
    let mut pos_res;
    loop {
        evaluate(model, data, t, q, &zeros, true)?;
        pos_res = max_abs(&data.phi);
        if pos_res <= tol || iterations >= max_iter {
            break;
        }
        data.force.fill(0.0);
        for i in 0..model.m {
            data.gamma[i] = -data.phi[i];
        }
        solve(model, data)?;
        for i in 0..n {
            q[i] += data.qdd[i];
            dq_total[i] += data.qdd[i];
        }
        iterations += 1;
    }
    let position_correction = mass_norm(model, data, &dq_total);
    // velocities at the corrected positions
    evaluate(model, data, t, q, qd, false)?;
    data.force.fill(0.0);
    let mut vres = vec![0.0; model.m];
    velocity_residual(model, data, qd, &mut vres);
    for i in 0..model.m {
        data.gamma[i] = -vres[i];
    }
    solve(model, data)?;
    let dqd = data.qdd.clone();
    for i in 0..n {
        qd[i] += dqd[i];
    }
    let velocity_correction = mass_norm(model, data, &dqd);
    velocity_residual(model, data, qd, &mut vres);
    Ok(Projection { iterations, position_residual: pos_res, velocity_residual: max_abs(&vres), position_correction, velocity_correction })
}

/// Buffers of the projections after integration steps, sized once per model.
#[derive(Debug, Clone)]
pub struct ProjectWorkspace {
    zeros: Vec<f64>,
    vres: Vec<f64>,
    /// A velocity scratch (n) for callers that perturb velocities.
    pub v: Vec<f64>,
    lambda: Vec<f64>,
    rhs: Vec<f64>,
}

impl ProjectWorkspace {
    pub fn new(model: &Model) -> Self {
        let (n, m) = (model.n, model.m);
        ProjectWorkspace { zeros: vec![0.0; n], vres: vec![0.0; m], v: vec![0.0; n], lambda: vec![0.0; m], rhs: vec![0.0; m] }
    }
}

/// How the projection after an integration step works.
///
/// The positions are corrected by (chord) Newton steps `dq = -F^-T B^+ Phi`, the minimum
/// mass-norm steps onto `Phi = 0`, until a step's largest entry is at most `position_tol` (m,
/// rad) or after `max_iter` steps; the velocities by one minimum mass-norm step onto
/// `A qd + Phi_t = 0` at the corrected positions (the equation is linear: one step is exact),
/// applied when its largest entry exceeds `velocity_tol`.
///
/// The test is on the size of the correction, not of the residual: near a configuration where
/// `A` loses rank, `Phi` and `A qd + Phi_t` hardly see an error in the directions that open up
/// (`Phi ~ sigma_min x error`), while the correction `B^+ Phi` measures it in full. A test on
/// the residuals leaves such errors alone, and the velocity projection then makes them
/// consistent with a neighbouring branch of the configuration space (docs/integrators.md,
/// singular configurations).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionTolerance {
    /// Newton on the positions stops once a correction's largest entry is at most this (the
    /// correction is then not applied).
    pub position_tol: f64,
    /// The velocity correction is applied when its largest entry exceeds this.
    pub velocity_tol: f64,
    /// Newton steps on the positions at most.
    pub max_iter: usize,
}

/// What a projection after a step did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ProjectOutcome {
    /// Whether `(q, qd)` changed.
    pub changed: bool,
    /// Newton steps applied to the positions.
    pub iterations: usize,
    /// Euclidean norm of `Phi` at the returned positions.
    pub phi_norm: f64,
    /// Largest entry of the last position correction (the Newton test).
    pub last_correction: f64,
    /// Whether Newton reached `position_tol` (or the rounding floor of the positions,
    /// `ROUNDING_FLOOR x eps x max |q| / kappa`, when that is larger) within `max_iter` steps.
    pub converged: bool,
}

/// A correction below this many rounding units of the largest position is converged (a
/// tolerance below it cannot be reached).
const ROUNDING_FLOOR: f64 = 16.0;

/// `tol`, or the rounding floor of a Newton correction at `q` when larger: rounding units of the
/// largest position, amplified by the conditioning of the factorization in `data` (near a
/// singular configuration the corrections carry the rounding of `Phi` times `1 / kappa`).
fn newton_floor(tol: f64, q: &[f64], data: &Data) -> f64 {
    let r = &data.rank_info;
    let kappa = if r.sigma_max > 0.0 && r.sigma_min_kept > 0.0 { (r.sigma_min_kept / r.sigma_max).min(1.0) } else { 1.0 };
    tol.max(ROUNDING_FLOOR * f64::EPSILON * q.iter().fold(0.0f64, |m, x| m.max(x.abs())) / kappa)
}

/// A Newton that stopped correcting while `||Phi||` stays above this has stalled (with
/// redundant rows the minimum-norm steps cannot remove a residual outside the range of `A`:
/// the state is too far from the constraints), not converged.
fn stalled_residual(tol: f64, q: &[f64]) -> f64 {
    1e3 * tol.max(ROUNDING_FLOOR * f64::EPSILON * q.iter().fold(1.0f64, |m, x| m.max(x.abs())))
}

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Newton on the positions: `correction(data, q, first)` leaves the next correction in
/// `data.qdd`, which is applied until one is within `tol` (or the rounding floor,
/// `newton_floor`) or after `max_iter` steps. The first correction is applied however small:
/// near a singular configuration `Phi` hardly sees an error across the constraints, and a
/// correction within the tolerance left alone there was later amplified into an error of
/// 1e-3..1 (the N four-bar at rtol 1e-8..1e-12). Records steps and convergence in `out`.
fn newton_positions(data: &mut Data, q: &mut [f64], tol: f64, max_iter: usize, out: &mut ProjectOutcome, mut correction: impl FnMut(&mut Data, &[f64], bool) -> Result<()>) -> Result<()> {
    for _ in 0..=max_iter {
        correction(data, q, out.iterations == 0)?;
        let largest = data.qdd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        out.last_correction = largest;
        if !(largest > newton_floor(tol, q, data)) && out.iterations > 0 {
            out.converged = true;
            break;
        }
        if out.iterations == max_iter {
            break;
        }
        for (qi, dq) in q.iter_mut().zip(&data.qdd) {
            *qi += dq;
        }
        out.changed = true;
        out.iterations += 1;
    }
    Ok(())
}

/// After `uk::acceleration_with_phi` at `(t, q, qd)` (so `data` holds `Phi`, `A` and the
/// factorization of `B = A F^-T` at `q`): project `q` onto `Phi = 0` and `qd` onto
/// `A qd + Phi_t = 0` as `ProjectionTolerance` says, every correction through the factorization
/// of that call (chord Newton: `B` is not refactored; the corrections are tiny next to the
/// distance over which `B` turns). `data.lambda` is kept; `data.qdd` is not. Leaves `Phi`, `A`
/// and `Phi_t` of the returned positions in `data`.
pub fn project_with_factorization(model: &Model, data: &mut Data, ws: &mut ProjectWorkspace, t: f64, q: &mut [f64], qd: &mut [f64], tol: ProjectionTolerance) -> Result<ProjectOutcome> {
    let n = model.n;
    if model.m == 0 {
        return Ok(ProjectOutcome::default());
    }
    ws.lambda.copy_from_slice(&data.lambda);
    let mut out = ProjectOutcome::default();
    let normalized = normalize_orientations(model, q, qd);
    out.changed = normalized;
    let rhs = &mut ws.rhs;
    newton_positions(data, q, tol.position_tol, tol.max_iter, &mut out, |data, q, first| {
        if !first || normalized {
            // Phi, A, Phi_t at the corrected positions (the velocity residual needs the turned A)
            constraints(model, data, t, q, qd, true);
        }
        for (v, p) in rhs.iter_mut().zip(&data.phi) {
            *v = -p;
        }
        crate::uk::min_norm_correction(model, data, rhs);
        Ok(())
    })?;
    // the velocities: linear in qd, so one step with the factorization at `q` is exact; with the
    // factorization of the step's end (chord) a large correction (a start off the constraints)
    // leaves a residual of its relative change: repeat while the correction exceeds the tolerance.
    // A correction within the tolerance is left alone: at the rounding level it only adds noise
    // (a clamped FFRF cantilever's fast axial mode rang at twice the amplitude with it).
    for _ in 0..=tol.max_iter {
        velocity_residual(model, data, qd, &mut ws.vres);
        for v in ws.vres.iter_mut() {
            *v = -*v;
        }
        crate::uk::min_norm_correction(model, data, &ws.vres);
        if !data.qdd.iter().any(|d| d.abs() > tol.velocity_tol) {
            break;
        }
        for i in 0..n {
            qd[i] += data.qdd[i];
        }
        out.changed = true;
    }
    out.phi_norm = norm2(&data.phi);
    out.converged &= out.phi_norm <= stalled_residual(tol.position_tol, q);
    data.lambda.copy_from_slice(&ws.lambda);
    Ok(out)
}

/// The projection of `project_with_factorization` from scratch (a fresh factorization at every
/// Newton iterate, for callers whose last kernel call was elsewhere): no allocation, no report.
pub fn project_in_place(model: &Model, data: &mut Data, ws: &mut ProjectWorkspace, t: f64, q: &mut [f64], qd: &mut [f64], p: ProjectionTolerance) -> Result<ProjectOutcome> {
    let n = model.n;
    let mut out = ProjectOutcome::default();
    if model.m == 0 {
        out.converged = true;
        return Ok(out);
    }
    out.changed = normalize_orientations(model, q, qd);
    let zeros = &ws.zeros;
    newton_positions(data, q, p.position_tol, p.max_iter, &mut out, |data, q, _| {
        constraints(model, data, t, q, zeros, true);
        for i in 0..model.m {
            data.gamma[i] = -data.phi[i];
        }
        min_mass_norm_step(model, data, q, zeros)
    })?;
    // velocities (A and Phi_t at the current q; A does not depend on qd)
    constraints(model, data, t, q, &ws.zeros, true);
    out.phi_norm = norm2(&data.phi);
    velocity_residual(model, data, qd, &mut ws.vres);
    for i in 0..model.m {
        data.gamma[i] = -ws.vres[i];
    }
    min_mass_norm_step(model, data, q, &ws.zeros)?;
    if data.qdd.iter().any(|d| d.abs() > p.velocity_tol) {
        for i in 0..n {
            qd[i] += data.qdd[i];
        }
        out.changed = true;
    }
    out.converged &= out.phi_norm <= stalled_residual(p.position_tol, q);
    Ok(out)
}

/// Every body's Euler parameters to unit length, their rates alike (`Body::normalize_orientation`),
/// before the projection: the normalization rows are then met and the projection moves only
/// what the joints ask. Returns whether anything changed.
fn normalize_orientations(model: &Model, q: &mut [f64], qd: &mut [f64]) -> bool {
    model.bodies.iter().fold(false, |any, b| b.normalize_orientation(q, qd) | any)
}

/// The minimum mass-norm `dx` with `A dx = gamma` (`gamma` already in `data.gamma`) into
/// `data.qdd`: the UK solve at `q` with zero forces.
fn min_mass_norm_step(model: &Model, data: &mut Data, q: &[f64], zeros: &[f64]) -> Result<()> {
    // the forces are discarded: only the mass blocks are read
    mass_and_forces(model, data, 0.0, q, zeros);
    crate::dynamics::factor_mass(model, data)?;
    data.force.fill(0.0);
    solve(model, data)
}
