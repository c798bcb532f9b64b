//! Spatial sensors at a stored state (not the hot path): per body its centre of mass, velocity,
//! rotation matrix and unit quaternion of the rotation `p / |p|` represents (`R = A(p) / |p|^2`),
//! angular velocity in world and body axes (`w' = 2 G pd / |p|^2`); per joint and driver its
//! reaction wrench; the system's linear and angular momentum.
//!
//! Reactions (docs/spatial-design.md, section 5): the wrench `-A_rows^T lambda_rows` that the
//! constraint exerts on the body of its first marker (`a`), force and torque about that
//! marker's point, from the UK multipliers (minimum-norm: in an over-constrained mechanism only
//! the components orthogonal to the self-stress states are unique). A first marker on the
//! ground: the wrench the ground receives (minus the one on the second body). Components in
//! world axes and in the first marker's axes.

use crate::body::{BodyKind, Rigid3};
use crate::constraint::ConstraintKind;
use crate::data::Data;
use crate::error::Result;
use crate::force::ForceKind;
use crate::model::Model;
use crate::force::spatial::{gravity_energy, SpatialForce};
use crate::linalg::rot3::{cross, dot, mat_t_vec, mat_vec, rot_a, rot_g, scale, sub};
use crate::uk;

/// Columns of one body's row (see [`body_outputs`]).
pub const BODY_COLUMNS: [&str; 22] = [
    "x", "y", "z", "vx", "vy", "vz", "e0", "e1", "e2", "e3", "wx", "wy", "wz", "wx_body", "wy_body", "wz_body", "R00", "R01", "R02", "R10", "R11", "R12",
];
/// Number of numbers per body: the columns above and `R20, R21, R22`.
pub const BODY_WIDTH: usize = 25;
/// Columns of one constraint's reaction row: the wrench in world axes, in the first marker's
/// axes, and the power of the item's constraint forces on the whole system (`-lambda^T A qd`:
/// zero for a joint on the velocity manifold, the input power of a driver).
pub const REACTION_COLUMNS: [&str; REACTION_WIDTH] =
    ["fx", "fy", "fz", "tx", "ty", "tz", "fx_joint", "fy_joint", "fz_joint", "tx_joint", "ty_joint", "tz_joint", "power"];
/// Number of numbers per constraint (`REACTION_COLUMNS`).
pub const REACTION_WIDTH: usize = 13;

/// Per body (`BODY_WIDTH` numbers): centre of mass, its velocity, unit quaternion, angular
/// velocity in world and body axes, rotation matrix (rows). Point masses: identity rotation,
/// zero angular velocity.
pub fn body_outputs(model: &Model, q: &[f64], qd: &[f64], out: &mut [f64]) {
    for (i, b) in model.bodies.iter().enumerate() {
        let o = b.offset;
        let w = &mut out[BODY_WIDTH * i..BODY_WIDTH * (i + 1)];
        w.fill(0.0);
        w[0..3].copy_from_slice(&q[o..o + 3]);
        w[3..6].copy_from_slice(&qd[o..o + 3]);
        match &b.kind {
            BodyKind::Rigid3(_) | BodyKind::Flexible3(_) => {
                let (p, pd) = (&q[o + 3..o + 7], &qd[o + 3..o + 7]);
                let p2 = dot(&[p[0], p[1], p[2]], &[p[0], p[1], p[2]]) + p[3] * p[3];
                let n = p2.sqrt();
                for l in 0..4 {
                    w[6 + l] = p[l] / n;
                }
                let r = rot_a(p).map(|row| row.map(|x| x / p2));
                let wb = Rigid3::omega_body(p, pd);
                let ww = mat_vec(&r, &wb);
                w[10..13].copy_from_slice(&ww);
                w[13..16].copy_from_slice(&wb);
                for a in 0..3 {
                    for c in 0..3 {
                        w[16 + 3 * a + c] = r[a][c];
                    }
                }
            }
            _ => {
                w[6] = 1.0;
                w[16] = 1.0;
                w[20] = 1.0;
                w[24] = 1.0;
            }
        }
    }
}

/// Linear momentum and angular momentum about the world origin (6 numbers).
pub fn momentum(model: &Model, q: &[f64], qd: &[f64]) -> [f64; 6] {
    let mut out = [0.0; 6];
    for b in &model.bodies {
        let o = b.offset;
        let r = [q[o], q[o + 1], q[o + 2]];
        let rd = [qd[o], qd[o + 1], qd[o + 2]];
        let (m, spin) = match &b.kind {
            BodyKind::Rigid3(k) => {
                let (p, pd) = (&q[o + 3..o + 7], &qd[o + 3..o + 7]);
                let p2: f64 = p.iter().map(|x| x * x).sum();
                let wb = Rigid3::omega_body(p, pd);
                let r_mat = rot_a(p).map(|row| row.map(|x| x / p2));
                (k.mass, mat_vec(&r_mat, &mat_vec(&k.inertia, &wb)))
            }
            BodyKind::Point3(k) => (k.mass, [0.0; 3]),
            BodyKind::Flexible3(k) => {
                let (lin, ang) = k.momentum(&q[o..o + b.n_coords], &qd[o..o + b.n_coords]);
                for c in 0..3 {
                    out[c] += lin[c];
                    out[3 + c] += ang[c];
                }
                continue;
            }
            _ => continue,
        };
        let l = cross(&r, &rd);
        for c in 0..3 {
            out[c] += m * rd[c];
            out[3 + c] += m * l[c] + spin[c];
        }
    }
    out
}

/// For each constraint (model order) `REACTION_COLUMNS` numbers into `out`; normalization rows
/// and planar kinds: zero wrenches. Solves the UK acceleration at `(t, q, qd)` for the multipliers.
pub fn reactions(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) -> Result<()> {
    uk::acceleration(model, data, t, q, qd)?;
    let zeros = vec![0.0; model.n];
    for (k, c) in model.constraints.iter().enumerate() {
        let o = &mut out[REACTION_WIDTH * k..REACTION_WIDTH * (k + 1)];
        o.fill(0.0);
        // -lambda^T A qd, as the planar sensors (`sensors::reactions_into`)
        o[12] = -(c.row..c.row + c.rows()).map(|r| data.lambda[r] * data.ajac.row_dot(r, qd)).sum::<f64>();
        let ConstraintKind::Spatial(sc) = &c.kind else { continue };
        let Some(pair) = sc.pair() else { continue };
        let (target, sign) = match pair.i.body {
            Some(b) => (b, 1.0),
            None => (pair.j.body.expect("a joint has a body"), -1.0),
        };
        let body = &model.bodies[target];
        let nb = body.n_coords;
        // generalized constraint force on the target body: -sum lam_r A_r
        // the reference coordinates `[r, p]` (a flexible3 body's modal coordinates carry no
        // part of the wrench on its frame)
        let mut qc = [0.0; 7];
        for r in c.row..c.row + c.rows() {
            for sg in data.ajac.row_segs(r) {
                if sg.body == target {
                    for l in 0..nb.min(7) {
                        qc[l] -= data.lambda[r] * data.ajac.vals[sg.val + l];
                    }
                }
            }
        }
        let f = [qc[0], qc[1], qc[2]];
        let si = pair.i.state(&model.bodies, q, &zeros);
        let x = si.point.v;
        let ob = body.offset;
        let rc = [q[ob], q[ob + 1], q[ob + 2]];
        let n_c = if matches!(body.kind, BodyKind::Rigid3(_) | BodyKind::Flexible3(_)) {
            let p = &q[ob + 3..ob + 7];
            let p2: f64 = p.iter().map(|v| v * v).sum();
            let g = rot_g(p);
            let mut nbody = [0.0; 3];
            for a in 0..3 {
                nbody[a] = (g[a][0] * qc[3] + g[a][1] * qc[4] + g[a][2] * qc[5] + g[a][3] * qc[6]) / (2.0 * p2);
            }
            scale(1.0 / p2, &mat_vec(&rot_a(p), &nbody))
        } else {
            [0.0; 3]
        };
        let torque = sub(&n_c, &cross(&sub(&x, &rc), &f));
        let (f, torque) = (scale(sign, &f), scale(sign, &torque));
        // joint axes: the first marker's world axes (columns)
        let axes = [si.axes[0].v, si.axes[1].v, si.axes[2].v];
        let cm = [[axes[0][0], axes[1][0], axes[2][0]], [axes[0][1], axes[1][1], axes[2][1]], [axes[0][2], axes[1][2], axes[2][2]]];
        let fj = mat_t_vec(&cm, &f);
        let tj = mat_t_vec(&cm, &torque);
        o[0..3].copy_from_slice(&f);
        o[3..6].copy_from_slice(&torque);
        o[6..9].copy_from_slice(&fj);
        o[9..12].copy_from_slice(&tj);
    }
    Ok(())
}

/// The coordinate each driver holds (rotation: the angle, continuous near its motion;
/// translation: `z_a . d`), model constraint order, NaN for other constraints.
pub fn driver_values(model: &Model, t: f64, q: &[f64], scratch: &mut [f64]) -> Vec<f64> {
    use crate::constraint::spatial::SpatialConstraint as S;
    let zeros = vec![0.0; model.n];
    model
        .constraints
        .iter()
        .map(|c| match &c.kind {
            ConstraintKind::Spatial(S::Rotation(d)) => d.angle(&model.bodies, t, q, scratch),
            ConstraintKind::Spatial(S::Translation(d)) => {
                let (si, sj) = d.pair.states(&model.bodies, q, &zeros);
                dot(&si.axes[2].v, &sub(&sj.point.v, &si.point.v))
            }
            _ => f64::NAN,
        })
        .collect()
}


/// The power `qd . Q_f` of each force element (model order) at `(q, qd)` into `out`
/// (`model.forces.len()`): a load's work rate (a torque or a body-frame force has no potential
/// in general, so its work is the integral of this), a spring-damper's `-(k x + c xd) xd`.
/// `turns`: the workspace's counted spring angles at this state (`Data::turns`, read only);
/// `scratch`: n numbers (the loads' and motors' values evaluate in a scratch of their own).
pub fn force_powers(model: &Model, turns: &[f64], t: f64, q: &[f64], qd: &[f64], scratch: &mut [f64], out: &mut [f64]) {
    let mut values = vec![0.0; model.forces.iter().map(|f| f.scratch_len()).max().unwrap_or(0)];
    for ((f, o), turn) in model.forces.iter().zip(out.iter_mut()).zip(turns) {
        scratch.fill(0.0);
        f.add_to(&model.bodies, t, q, qd, &mut values, &mut turn.clone(), scratch);
        *o = dot_n(scratch, qd);
    }
}

/// Replace the rotational springs' potentials in `potentials` (one per force element, as
/// `sensors::energies_into` wrote them: read within half a turn) by their counted ones.
pub fn count_turns(model: &Model, turns: &[f64], potentials: &mut [f64]) {
    for ((f, p), turn) in model.forces.iter().zip(potentials.iter_mut()).zip(turns) {
        if let ForceKind::Spatial(sf) = &f.kind {
            if let Some(v) = sf.counted_potential(*turn) {
                *p = v;
            }
        }
    }
}

/// Each body's gravity potential `-m g . r` (the scene's `gravity` element; 0 without one) into
/// `out` (`model.bodies.len()`).
pub fn gravity_energies(model: &Model, q: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for f in &model.forces {
        if let ForceKind::Spatial(SpatialForce::Gravity { g }) = &f.kind {
            for (b, o) in model.bodies.iter().zip(out.iter_mut()) {
                *o += gravity_energy(g, b, q);
            }
        }
    }
}

fn dot_n(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
