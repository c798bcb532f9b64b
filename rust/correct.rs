//! Moving a state onto the constraint manifold (between steps and at build; allocates, not
//! the acceleration hot path):
//!
//! * `project`: Newton steps `dq = -M^-1 A^T (A M^-1 A^T)^+ Phi` until `max |Phi| <= tol`, then
//!   `dqd = -M^-1 A^T (A M^-1 A^T)^+ (A qd + Phi_t)`: the closest consistent state in the
//!   kinetic-energy norm (Gauss's principle applied to the correction). Each step is the UK
//!   kernel with `Q = 0` and `b = -residual`.
//! * `correct`: the same, with some coordinates held at their values (the initial-state
//!   correction: by default every body's deformation, so an undeformed guess stays undeformed:
//!   the elastic coordinates of FFRF and modal bodies, and an ANCF cable moves only rigidly),
//!   damped Newton steps, and a report of what changed.

use faer::Mat;

use crate::dynamics::{constraints, mass_and_forces};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::linalg::dense::{cholesky, pinv_solve, solve_lower, solve_upper};
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
    for _ in 0..=tol.max_iter {
        for (v, p) in ws.rhs.iter_mut().zip(&data.phi) {
            *v = -p;
        }
        crate::uk::min_norm_correction(model, data, &ws.rhs);
        let largest = data.qdd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        out.last_correction = largest;
        // converged: the next correction is within the tolerance. The first one is applied
        // however small: near a singular configuration `Phi` hardly sees an error across the
        // constraints, and a correction within the tolerance left alone there was later
        // amplified into an error of 1e-3..1 (the N four-bar at rtol 1e-8..1e-12)
        let small = !(largest > newton_floor(tol.position_tol, q, data));
        if small && out.iterations > 0 {
            out.converged = true;
            break;
        }
        if out.iterations == tol.max_iter {
            break;
        }
        for i in 0..n {
            q[i] += data.qdd[i];
        }
        out.changed = true;
        out.iterations += 1;
        // Phi, A, Phi_t at the corrected positions (the velocity residual needs the turned A)
        constraints(model, data, t, q, qd, true);
    }
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
    for _ in 0..=p.max_iter {
        constraints(model, data, t, q, &ws.zeros, true);
        for i in 0..model.m {
            data.gamma[i] = -data.phi[i];
        }
        min_mass_norm_step(model, data, q, &ws.zeros)?;
        let largest = data.qdd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        out.last_correction = largest;
        if !(largest > newton_floor(p.position_tol, q, data)) && out.iterations > 0 {
            out.converged = true;
            break;
        }
        if out.iterations == p.max_iter {
            break;
        }
        for i in 0..n {
            q[i] += data.qdd[i];
        }
        out.changed = true;
        out.iterations += 1;
    }
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

/// The minimum mass-norm `dx` with `A dx = gamma` (`gamma` already in `data.gamma`) into
/// `data.qdd`: the UK solve at `q` with zero forces.
fn min_mass_norm_step(model: &Model, data: &mut Data, q: &[f64], zeros: &[f64]) -> Result<()> {
    mass_and_forces(model, data, q, zeros);
    crate::dynamics::factor_mass(model, data)?;
    data.force.fill(0.0);
    solve(model, data)
}

/// Settings of `correct`.
#[derive(Debug, Clone)]
pub struct CorrectOptions {
    /// `hold[i]`: coordinate `i` keeps its value (length n).
    pub hold: Vec<bool>,
    /// Every body moves rigidly (its deformation held, `Body::rigid_motions`): what holding the
    /// elastic coordinates means for every kind, an ANCF cable's nodal field included.
    pub rigid: bool,
    /// Newton stops when `max |Phi| <= position_tol` (absolute, m and rad).
    pub position_tol: f64,
    /// Accepted `max |A qd + Phi_t| <= velocity_tol * max(1, max |qd|)`.
    pub velocity_tol: f64,
    pub max_iterations: usize,
}

/// What `correct` did. `q`, `qd` are the corrected state (as far as it got).
#[derive(Debug, Clone)]
pub struct Correction {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub iterations: usize,
    pub position_residual_before: f64,
    pub position_residual_after: f64,
    pub velocity_residual_before: f64,
    pub velocity_residual_after: f64,
    /// `Phi` at the end of the position correction (m).
    pub phi: Vec<f64>,
    /// `A qd + Phi_t` at the end (m; zeros when the positions failed).
    pub velocity: Vec<f64>,
    pub positions_ok: bool,
    pub velocities_ok: bool,
}

/// Minimum-norm solution of `A[:, free] dx = r` in the metric `M[free, free]` (the UK/Gauss
/// projection restricted to the free coordinates): `dx_free = F^-T (A_f F^-T)^+ r` with
/// `M_ff = F F^T`. Needs the mass blocks and `A` at the current `q` in `data`.
///
/// When no coordinate is held and the workspace has the sparse UK path, this is the UK solve
/// itself with `Q = 0`, `b = r` (O(n), the sparse path's rank certificate or its dense
/// fallback); otherwise the dense SVD of `A_f F^-T` below (O(n m^2)): a body whose coordinates
/// are all free is factored by its own `M_b = F_b F_b^T` (banded for an ANCF cable: O(n_b)),
/// a body with held coordinates by the dense Cholesky of its free block.
fn metric_step(model: &Model, data: &mut Data, free: &[bool], r: &[f64]) -> Result<Vec<f64>> {
    let (n, m) = (model.n, model.m);
    if m > 0 && data.sparse.is_some() && free.iter().all(|f| *f) {
        crate::dynamics::factor_mass(model, data)?;
        data.force.fill(0.0);
        data.gamma.copy_from_slice(r);
        solve(model, data)?;
        return Ok(data.qdd.clone());
    }
    let mut dx = vec![0.0; n];
    let idx: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
    let k = idx.len();
    if k == 0 || m == 0 {
        return Ok(dx);
    }
    // M restricted to the free coordinates (block diagonal by body): only the free entries of
    // each body block are visited, so holding the elastic coordinates of a long beam costs a
    // 3 x 3 block, not its whole mass matrix.
    let mut pos = vec![usize::MAX; n];
    for (p, &i) in idx.iter().enumerate() {
        pos[i] = p;
    }
    let hint = "the initial-state correction with held coordinates solves densely in the free coordinates and the constraint rows; hold fewer coordinates (hold=None) or raise memory_limit";
    Error::check_memory("the initial-state correction (free coordinates x constraint rows)", 8 * (k as u64 + m as u64) * m as u64 * 3, data.memory_limit, hint)?;
    // per body with free coordinates: (first compact index, size, whole body: its own factor)
    let mut blocks: Vec<(usize, usize, usize, bool)> = Vec::new();
    let mut mf = vec![0.0; 0];
    let mut offsets = Vec::new();
    for (b, body) in model.bodies.iter().enumerate() {
        let local: Vec<usize> = (body.offset..body.offset + body.n_coords).filter(|&i| free[i]).collect();
        let kb = local.len();
        if kb == 0 {
            continue;
        }
        let first = pos[local[0]];
        if kb == body.n_coords {
            body.factor(&mut data.bodies[b])?;
            blocks.push((first, kb, b, true));
            offsets.push(0);
            continue;
        }
        let bd = &data.bodies[b];
        Error::check_memory("the initial-state correction (a body's free mass block)", 8 * (kb * kb) as u64, data.memory_limit, hint)?;
        let mut blk = vec![0.0; kb * kb];
        body.dense_block(bd, &mut |i, j, v| {
            let (gi, gj) = (body.offset + i, body.offset + j);
            if free[gi] && free[gj] {
                blk[(pos[gi] - first) * kb + pos[gj] - first] = v;
            }
        });
        if cholesky(&mut blk, kb, 0.0).is_err() {
            return Err(Error::SingularMass { item: format!("body '{}': mass block of the corrected coordinates", body.name) });
        }
        blocks.push((first, kb, b, false));
        offsets.push(mf.len());
        mf.extend_from_slice(&blk);
    }
    // B^T = F^-1 A_f^T (k x m)
    let mut bt = Mat::<f64>::zeros(k, m);
    let mut col = vec![0.0; k];
    for i in 0..m {
        // row i of A on the free coordinates, from the segment form (O(nnz) per row)
        col.fill(0.0);
        for sg in data.ajac.row_segs(i) {
            for (j, &a) in data.ajac.vals[sg.val..sg.val + sg.len].iter().enumerate() {
                let p = pos[sg.col + j];
                if p != usize::MAX {
                    col[p] = a;
                }
            }
        }
        for (&(first, kb, b, whole), &off) in blocks.iter().zip(&offsets) {
            if whole {
                model.bodies[b].finv(&data.bodies[b], &mut col[first..first + kb]);
            } else {
                solve_lower(&mf[off..off + kb * kb], kb, &mut col[first..first + kb]);
            }
        }
        for p in 0..k {
            bt[(p, i)] = col[p];
        }
    }
    let mut y = pseudo_solve(&bt, r)?;
    for (&(first, kb, b, whole), &off) in blocks.iter().zip(&offsets) {
        if whole {
            model.bodies[b].finvt(&data.bodies[b], &mut y[first..first + kb]);
        } else {
            solve_upper(&mf[off..off + kb * kb], kb, &mut y[first..first + kb]);
        }
    }
    for (p, &g) in idx.iter().enumerate() {
        dx[g] = y[p];
    }
    Ok(dx)
}

/// `B^+ r` with `B^T = bt` (`linalg::dense::pinv_solve`, the rank cut of `scipy.linalg.pinv`).
fn pseudo_solve(bt: &Mat<f64>, r: &[f64]) -> Result<Vec<f64>> {
    pinv_solve(bt, r).map_err(|e| Error::Solver(format!("SVD in the state correction did not converge: {e:?}")))
}

/// The bodies' rigid motions at `q` that touch no held coordinate (`Body::rigid_motions`):
/// per body its columns (first column index, count, the sizes of the body's full basis), and
/// per coordinate the `(column, value)` entries of the basis `B`.
struct RigidBasis {
    bodies: Vec<(usize, usize)>,
    kept: Vec<Vec<usize>>,
    entries: Vec<Vec<(usize, f64)>>,
    k: usize,
}

impl RigidBasis {
    fn new(model: &Model, q: &[f64], hold: &[bool]) -> RigidBasis {
        let n = model.n;
        let zeros = vec![0.0; n];
        let mut cen = vec![0.0; n];
        let (mut bodies, mut kept, mut entries) = (Vec::new(), Vec::new(), vec![Vec::new(); n]);
        let mut k = 0;
        for body in &model.bodies {
            let mut raw: Vec<(usize, usize, f64)> = Vec::new();
            let cols = body.rigid_motions(q, &zeros, 0, &mut |i, j, x| raw.push((i, j, x)), &mut cen);
            // a column that moves a held coordinate is left out
            let keep: Vec<usize> = (0..cols).filter(|&c| !raw.iter().any(|&(i, j, x)| j == c && x != 0.0 && hold[i])).collect();
            for &(i, j, x) in &raw {
                if let Some(p) = keep.iter().position(|&c| c == j) {
                    entries[i].push((k + p, x));
                }
            }
            bodies.push((k, cols));
            k += keep.len();
            kept.push(keep);
        }
        RigidBasis { bodies, kept, entries, k }
    }

    /// `x` (the kept columns) as each body's full rigid-motion vector.
    fn body_motion(&self, b: usize, x: &[f64]) -> [f64; 3] {
        let mut out = [0.0; 3];
        let (first, _) = self.bodies[b];
        for (p, &c) in self.kept[b].iter().enumerate() {
            out[c] = x[first + p];
        }
        out
    }

    /// `B x` (n).
    fn times(&self, x: &[f64]) -> Vec<f64> {
        self.entries.iter().map(|e| e.iter().map(|&(c, v)| v * x[c]).sum()).collect()
    }
}

/// Minimum-norm rigid motions `x` of the bodies with `A B x = r` in the metric `B^T M B` (the
/// Gauss projection restricted to rigid motions); `B^T M B` is block diagonal by body (at most
/// 3 x 3, from `M_b` times the columns: O(n)). Needs the mass blocks and `A` in `data`.
fn rigid_step(model: &Model, data: &Data, basis: &RigidBasis, r: &[f64]) -> Result<Vec<f64>> {
    let (n, m, k) = (model.n, model.m, basis.k);
    let mut x = vec![0.0; k];
    if k == 0 || m == 0 {
        return Ok(x);
    }
    Error::check_memory("the initial-state correction (rigid motions x constraint rows)", 8 * (k as u64 + m as u64) * m as u64 * 3, data.memory_limit,
        "the initial-state correction solves densely in the bodies' rigid motions and the constraint rows; raise memory_limit")?;
    // per body: the Cholesky factor of its block of B^T M B
    let mut factors: Vec<Vec<f64>> = Vec::with_capacity(model.bodies.len());
    for (b, body) in model.bodies.iter().enumerate() {
        let (first, _) = basis.bodies[b];
        let kb = basis.kept[b].len();
        let seg = body.offset..body.offset + body.n_coords;
        let cols: Vec<Vec<f64>> = (0..kb)
            .map(|p| seg.clone().map(|i| basis.entries[i].iter().filter(|e| e.0 == first + p).map(|e| e.1).sum()).collect())
            .collect();
        let mut blk = vec![0.0; kb * kb];
        let mut mv = vec![0.0; body.n_coords];
        for p2 in 0..kb {
            mv.fill(0.0);
            body.mass_times(&data.bodies[b], &cols[p2], &mut mv);
            for p1 in 0..kb {
                blk[p1 * kb + p2] = cols[p1].iter().zip(&mv).map(|(a, b)| a * b).sum();
            }
        }
        if kb > 0 && cholesky(&mut blk, kb, 0.0).is_err() {
            return Err(Error::SingularMass { item: format!("body '{}': mass of its rigid motions", body.name) });
        }
        factors.push(blk);
    }
    // bt = F^-1 (A B)^T (k x m)
    let mut bt = Mat::<f64>::zeros(k, m);
    let mut col = vec![0.0; k];
    for i in 0..m {
        col.fill(0.0);
        for sg in data.ajac.row_segs(i) {
            for (j, &a) in data.ajac.vals[sg.val..sg.val + sg.len].iter().enumerate() {
                for &(c, v) in &basis.entries[sg.col + j] {
                    col[c] += a * v;
                }
            }
        }
        for (b, f) in factors.iter().enumerate() {
            let (first, kb) = (basis.bodies[b].0, basis.kept[b].len());
            solve_lower(f, kb, &mut col[first..first + kb]);
        }
        for p in 0..k {
            bt[(p, i)] = col[p];
        }
    }
    let _ = n;
    let mut y = pseudo_solve(&bt, r)?;
    for (b, f) in factors.iter().enumerate() {
        let (first, kb) = (basis.bodies[b].0, basis.kept[b].len());
        solve_upper(f, kb, &mut y[first..first + kb]);
    }
    x.copy_from_slice(&y);
    Ok(x)
}

/// Correct `(q, qd)` onto the constraints at time `t`, holding the coordinates marked in
/// `opts.hold`: damped Newton on the positions (the step halved while `max |Phi|` grows, stop
/// after 5 iterations without halving the best residual), then one velocity projection.
pub fn correct(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], opts: &CorrectOptions) -> Result<Correction> {
    correct_within(model, data, t, q, qd, opts, f64::INFINITY)
}

/// `correct` within a wall-time budget of `max_wall_time` seconds (checked before every Newton
/// iteration and before the velocity projection): past it `Error::Budget` (`max_wall_time`)
/// saying how far the correction got.
pub fn correct_within(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], opts: &CorrectOptions, max_wall_time: f64) -> Result<Correction> {
    let started = std::time::Instant::now();
    let over = |it: usize, res: f64| -> Result<()> {
        if max_wall_time.is_finite() && started.elapsed().as_secs_f64() > max_wall_time {
            return Err(Error::Budget {
                what: "max_wall_time".into(),
                message: format!("the initial-state correction: wall time over max_wall_time = {max_wall_time} s after {it} Newton iteration(s) (max |Phi| = {res:.3e})"),
            });
        }
        Ok(())
    };
    let (n, m) = (model.n, model.m);
    if opts.hold.len() != n {
        return Err(Error::Shape { what: "hold".into(), expected: n, got: opts.hold.len() });
    }
    let free: Vec<bool> = opts.hold.iter().map(|h| !h).collect();
    // bodies that move only rigidly: the cables' nodal fields (the other kinds' deformation is
    // their elastic coordinates, held by the mask)
    let rigid = opts.rigid && model.bodies.iter().any(|b| matches!(b.kind, crate::body::BodyKind::AncfBeam(_)));
    let zeros = vec![0.0; n];
    let mut q = q.to_vec();
    constraints(model, data, t, &q, &zeros, true);
    let mut phi = data.phi.clone();
    let r0 = max_abs(&phi);
    let (mut res, mut best, mut it, mut stall) = (r0, r0, 0usize, 0usize);
    let mut r = vec![0.0; m];
    while res > opts.position_tol && it < opts.max_iterations {
        over(it, res)?;
        it += 1;
        mass_and_forces(model, data, &q, &zeros);
        constraints(model, data, t, &q, &zeros, false);
        for i in 0..m {
            r[i] = -phi[i];
        }
        let (dq, basis, x) = if rigid {
            let basis = RigidBasis::new(model, &q, &opts.hold);
            let x = rigid_step(model, data, &basis, &r)?;
            (Vec::new(), Some(basis), x)
        } else {
            (metric_step(model, data, &free, &r)?, None, Vec::new())
        };
        let mut step = 1.0;
        let mut q_try = q.clone();
        loop {
            match &basis {
                Some(basis) => {
                    q_try.copy_from_slice(&q);
                    let xs: Vec<f64> = x.iter().map(|v| step * v).collect();
                    for (b, body) in model.bodies.iter().enumerate() {
                        body.move_rigidly(&mut q_try, &basis.body_motion(b, &xs));
                    }
                }
                None => {
                    for i in 0..n {
                        q_try[i] = q[i] + step * dq[i];
                    }
                }
            }
            constraints(model, data, t, &q_try, &zeros, true);
            if max_abs(&data.phi) < res || step < 1e-6 {
                break;
            }
            step *= 0.5;
        }
        q.copy_from_slice(&q_try);
        phi.copy_from_slice(&data.phi);
        res = max_abs(&phi);
        if res < 0.5 * best {
            best = res;
            stall = 0;
        } else {
            stall += 1;
            if stall >= 5 {
                break;
            }
        }
        if !res.is_finite() {
            break;
        }
    }
    let positions_ok = res <= opts.position_tol;
    let mut out = Correction {
        q,
        qd: qd.to_vec(),
        iterations: it,
        position_residual_before: r0,
        position_residual_after: res,
        velocity_residual_before: f64::NAN,
        velocity_residual_after: f64::NAN,
        phi,
        velocity: vec![0.0; m],
        positions_ok,
        velocities_ok: false,
    };
    if !positions_ok {
        return Ok(out);
    }
    over(it, res)?;
    mass_and_forces(model, data, &out.q, &zeros);
    constraints(model, data, t, &out.q, &zeros, false);
    let mut vres = vec![0.0; m];
    velocity_residual(model, data, &out.qd, &mut vres);
    out.velocity_residual_before = max_abs(&vres);
    for i in 0..m {
        r[i] = -vres[i];
    }
    let dqd = if rigid {
        let basis = RigidBasis::new(model, &out.q, &opts.hold);
        basis.times(&rigid_step(model, data, &basis, &r)?)
    } else {
        metric_step(model, data, &free, &r)?
    };
    for i in 0..n {
        out.qd[i] += dqd[i];
    }
    velocity_residual(model, data, &out.qd, &mut vres);
    out.velocity_residual_after = max_abs(&vres);
    out.velocity = vres;
    let scale = max_abs(&out.qd).max(1.0);
    out.velocities_ok = out.velocity_residual_after <= opts.velocity_tol * scale;
    Ok(out)
}

