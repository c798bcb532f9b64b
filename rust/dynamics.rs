//! Model kernels: loops over the per-body stages (each body kind owns its physics in
//! `body/`), the force elements and the constraints. All write into `Data`.
//!
//! * `mass_and_forces`: per-body mass blocks `M_b(q)` and generalized forces
//!   `Q = Q_e + Q_v + Q_el` (paper eqs. 20-40), then the force elements;
//! * `factor_mass`: the block-diagonal factor `M = F F^T`; `apply_finv`/`apply_finvt`;
//! * `constraints`: `Phi`, `A`, `Phi_t`, `gamma` (eq. 43);
//! * inspection (not the hot path): `dense_mass`, energies.

use crate::constraint::ConstraintOut;
use crate::data::Data;
use crate::body::BodyData;
use crate::error::Result;
use crate::model::Model;

/// Per-body mass blocks and generalized forces at `(t, q, qd)` (`t`: the loads that are
/// functions of time; the mass blocks and body forces do not depend on it).
pub fn mass_and_forces(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) {
    data.t_forces = t;
    for (body, bd) in model.bodies.iter().zip(data.bodies.iter_mut()) {
        body.mass_and_forces(bd, q, qd, model.gravity, &mut data.force);
    }
    for (f, turn) in model.forces.iter().zip(data.turns.iter_mut()) {
        f.add_to(&model.bodies, t, q, qd, &mut data.load_scratch, turn, &mut data.force);
    }
    if data.friction.is_some() {
        prepare_friction(model, data, q, qd);
    }
}

/// Joint friction reads the multipliers: its slip rates here, its forces in `uk::acceleration`. Out of
/// line: the scenes without friction keep their hot path as it was.
#[cold]
#[inline(never)]
fn prepare_friction(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) {
    if let Some(w) = data.friction.as_mut() {
        w.prepare(&model.forces, &model.bodies, q, qd);
    }
}

/// `data.force += ` the joint friction forces at the multipliers in `data.lambda` (those of
/// the last UK solve) and the state of the last `mass_and_forces`: the velocity Jacobian `C` of
/// the implicit methods' Newton matrices sees the friction's dependence on the rates at fixed
/// reactions (`velocity_jacobians_into`, `sparse_newton::fill_velocity_terms`).
pub fn add_friction_at_last_multipliers(model: &Model, data: &mut Data) {
    if let Some(w) = &data.friction {
        w.add_forces(&model.forces, &data.lambda, &mut data.force);
    }
}

/// Factor each body block `M_b = F_b F_b^T` (after `mass_and_forces`).
pub fn factor_mass(model: &Model, data: &mut Data) -> Result<()> {
    for (body, bd) in model.bodies.iter().zip(data.bodies.iter_mut()) {
        body.factor(bd)?;
    }
    Ok(())
}

/// `v <- F^-1 v` for the whole (block-diagonal) factor.
pub fn apply_finv(model: &Model, bodies: &[BodyData], v: &mut [f64]) {
    for (body, bd) in model.bodies.iter().zip(bodies) {
        body.finv(bd, &mut v[body.offset..body.offset + body.n_coords]);
    }
}

/// `v <- F^-T v`.
pub fn apply_finvt(model: &Model, bodies: &[BodyData], v: &mut [f64]) {
    for (body, bd) in model.bodies.iter().zip(bodies) {
        body.finvt(bd, &mut v[body.offset..body.offset + body.n_coords]);
    }
}

/// `F^-1` applied only to the bodies whose segment of `v` is not all zero (constraint rows
/// touch one or two bodies).
pub fn apply_finv_sparse(model: &Model, bodies: &[BodyData], v: &mut [f64]) {
    for (body, bd) in model.bodies.iter().zip(bodies) {
        let seg = &mut v[body.offset..body.offset + body.n_coords];
        if seg.iter().any(|x| *x != 0.0) {
            body.finv(bd, seg);
        }
    }
}

/// Constraint terms: `A` (in segment form, `data.ajac`; the dense `data.jac`, when allocated,
/// is scattered from it when read), `Phi_t`, `gamma`, and `Phi` when `with_phi`. O(nnz(A)): no
/// pass over `m x n`.
pub fn constraints(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], with_phi: bool) {
    // spatial rows compute their value anyway: keep it, it sets the rank tolerance (uk::dense)
    let with_phi = with_phi || data.spatial_drift.is_some();
    if let Some(w) = data.marker3.as_deref_mut() {
        crate::body::marker3::Frame3::fill(&model.bodies, q, qd, &mut w.frames);
    }
    // the kernels add into zeroed rows: one fill for all (not one call per constraint)
    data.ajac.vals.fill(0.0);
    for (k, c) in model.constraints.iter().enumerate() {
        let rows = c.rows();
        let r0 = c.row;
        let (vals, layout, width) = data.ajac.constraint_block(k, r0, rows);
        let out = ConstraintOut {
            phi: if with_phi { Some(&mut data.phi[r0..r0 + rows]) } else { None },
            jac: vals,
            layout,
            phi_t: &mut data.phi_t[r0..r0 + rows],
            gamma: &mut data.gamma[r0..r0 + rows],
            scratch: &mut data.motion_scratch,
            marker3: data.marker3.as_deref_mut(),
        };
        c.eval(&model.bodies, t, q, qd, width, out);
    }
    if let Some(d) = data.spatial_drift.as_mut() {
        *d = data.phi.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
    }
    data.jac.invalidate();
}

/// Dense mass matrix (n x n, row-major) from the body blocks of the last `mass_and_forces`
/// (inspection and the initial-state correction, not the hot path).
pub fn dense_mass(model: &Model, data: &Data) -> Vec<f64> {
    let mut m = vec![0.0; model.n * model.n];
    dense_mass_into(model, data, &mut m);
    m
}

/// `out = M x` from the body blocks of the last `mass_and_forces` (allocation free).
pub fn mass_times(model: &Model, data: &Data, x: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (body, bd) in model.bodies.iter().zip(&data.bodies) {
        let r = body.offset..body.offset + body.n_coords;
        body.mass_times(bd, &x[r.clone()], &mut out[r]);
    }
}

/// `dense_mass` into a buffer of length n^2 (overwritten).
pub fn dense_mass_into(model: &Model, data: &Data, m: &mut [f64]) {
    let n = model.n;
    m.fill(0.0);
    for (body, bd) in model.bodies.iter().zip(&data.bodies) {
        let o = body.offset;
        body.dense_block(bd, &mut |i, j, v| m[(o + i) * n + o + j] = v);
    }
}

/// The stiffness part of `tangent_into` alone (n x n, overwritten).
pub fn stiffness_into(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], k: &mut [f64]) {
    let n = model.n;
    k.fill(0.0);
    for (body, bd) in model.bodies.iter().zip(&data.bodies) {
        let o = body.offset;
        body.tangent(bd, q, qd, &mut |i, j, v| k[(o + i) * n + o + j] += v, &mut |_, _, _| {});
    }
    add_force_stiffness(model, data, q, qd, &mut |i, j, v| k[i * n + j] += v);
}

/// The analytic position stiffness of the force elements that have one (`Force::add_stiffness`:
/// loads and motors whose values are expressions or tables), at `q`, `qd` and the time of the
/// last `mass_and_forces`.
pub fn add_force_stiffness(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], add: &mut dyn FnMut(usize, usize, f64)) {
    if data.load_rows.is_empty() {
        return;
    }
    let t = data.t_forces;
    for (f, &turn) in model.forces.iter().zip(&data.turns).filter(|(f, _)| f.has_stiffness()) {
        f.add_stiffness(&model.bodies, t, q, qd, turn, &mut data.load_scratch, &mut data.load_rows, add);
    }
}

/// The analytic damping of the force elements that have one (`Force::add_damping`: the
/// spring-dampers) at `(q, qd)`.
pub fn add_force_damping(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], add: &mut dyn FnMut(usize, usize, f64)) {
    if data.load_rows.is_empty() {
        return;
    }
    for f in model.forces.iter().filter(|f| f.has_damping()) {
        f.add_damping(&model.bodies, q, qd, &mut data.load_rows, add);
    }
}

/// The stiffness `k = -dQ/dq` and damping `c = -dQ/dqd` that the bodies know analytically
/// (elastic tangent stiffness and strain-rate damping; not the inertial velocity terms, the
/// gravity or the force elements), plus the loads' analytic position stiffness
/// (`add_force_stiffness`), n x n row-major, overwritten. For implicit methods' iteration
/// matrices.
pub fn tangent_into(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], k: &mut [f64], c: &mut [f64]) {
    let n = model.n;
    k.fill(0.0);
    c.fill(0.0);
    for (body, bd) in model.bodies.iter().zip(&data.bodies) {
        let o = body.offset;
        body.tangent(bd, q, qd, &mut |i, j, v| k[(o + i) * n + o + j] += v, &mut |i, j, v| c[(o + i) * n + o + j] += v);
    }
    add_force_stiffness(model, data, q, qd, &mut |i, j, v| k[i * n + j] += v);
}

/// Kinetic energy `1/2 qd^T M qd` from the body blocks (calls `mass_and_forces` at `(q, qd)`).
pub fn kinetic_energy(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) -> f64 {
    // the mass blocks alone are read: the loads' time does not matter
    mass_and_forces(model, data, 0.0, q, qd);
    model.bodies.iter().zip(&data.bodies).map(|(b, bd)| b.kinetic_energy(bd, qd)).sum()
}

/// Potential energy: gravity, elastic strain and force elements.
pub fn potential_energy(model: &Model, q: &[f64]) -> f64 {
    let mut v = 0.0;
    for body in &model.bodies {
        v += body.strain_energy(q);
        if let Some(g) = model.gravity {
            v += body.gravity_energy(q, g);
        }
    }
    for f in &model.forces {
        v += f.potential(&model.bodies, q);
    }
    v
}

/// `c = -dQ/dqd` (n x n) and `bv = d gamma/dqd` (m x n) at `(t, q, qd)` by central differences
/// in `qd`: both are quadratic in `qd` (inertial velocity terms, constraint velocity terms) plus
/// linear damping, so the differences are exact up to rounding for any step. `v` is an n-long
/// scratch. Leaves `data` at a perturbed state.
pub fn velocity_jacobians_into(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], v: &mut [f64], c: &mut [f64], bv: &mut [f64]) {
    let (n, rows) = (model.n, model.m);
    v.copy_from_slice(qd);
    for j in 0..n {
        let s = 1e-3 * qd[j].abs().max(1.0);
        v[j] = qd[j] + s;
        mass_and_forces(model, data, t, q, v);
        add_friction_at_last_multipliers(model, data);
        constraints(model, data, t, q, v, false);
        for i in 0..n {
            c[i * n + j] = -data.force[i];
        }
        for r in 0..rows {
            bv[r * n + j] = data.gamma[r];
        }
        v[j] = qd[j] - s;
        mass_and_forces(model, data, t, q, v);
        add_friction_at_last_multipliers(model, data);
        constraints(model, data, t, q, v, false);
        for i in 0..n {
            c[i * n + j] = (c[i * n + j] + data.force[i]) / (2.0 * s);
        }
        for r in 0..rows {
            bv[r * n + j] = (bv[r * n + j] - data.gamma[r]) / (2.0 * s);
        }
        v[j] = qd[j];
    }
}
