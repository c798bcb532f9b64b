//! Sensors evaluated at a stored state (after a run, not in the integration loop): joint
//! reactions from the multipliers, energies per body and per force element, the power of the
//! constraint forces (the drivers' power) and the dissipated power. `bindings` loops these over
//! the output times so that no Python runs per state; `python/ukflex/sensors.py` names them.

pub mod spatial;
use crate::data::Data;
use crate::dynamics;
use crate::error::Result;
use crate::model::Model;
use crate::uk;

/// Columns of one constraint's reaction row (see [`reactions_into`]).
pub const REACTION_COLUMNS: [&str; 6] = ["fx", "fy", "torque", "fx_local", "fy_local", "power"];

/// Columns of one body's energy row (see [`energies_into`]).
pub const ENERGY_COLUMNS: [&str; 3] = ["kinetic", "strain", "gravity"];

/// For each constraint item (joint or driver, in `model.constraints` order), 6 numbers into
/// `out` (length `6 * model.constraints.len()`): the force (world frame) and torque it exerts on
/// its first marker's body (`Constraint::reaction`), the force in the joint frame, and the power
/// of its constraint forces on the whole system, `-lambda^T A qd = lambda^T Phi_t` (on the
/// velocity manifold; zero for scleronomic joints, the input power for drivers). Solves the UK
/// acceleration at `(t, q, qd)` for the multipliers.
pub fn reactions_into(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) -> Result<()> {
    uk::acceleration(model, data, t, q, qd)?;
    for (k, c) in model.constraints.iter().enumerate() {
        let rows = c.row..c.row + c.rows();
        let lam = &data.lambda[rows.clone()];
        let r = c.reaction(&model.bodies, q, qd, lam);
        // -lambda^T A qd (exact at any state, also off the velocity manifold)
        let mut power = 0.0;
        for row in rows {
            power -= data.lambda[row] * data.ajac.row_dot(row, qd);
        }
        let (s, co) = r.frame.sin_cos();
        let o = &mut out[6 * k..6 * k + 6];
        o[0] = r.force[0];
        o[1] = r.force[1];
        o[2] = r.torque;
        o[3] = co * r.force[0] + s * r.force[1];
        o[4] = -s * r.force[0] + co * r.force[1];
        o[5] = power;
    }
    Ok(())
}

/// Energies at `(q, qd)`: per body `[kinetic, strain, gravity]` into `bodies`
/// (`3 * model.bodies.len()`), per force element its potential into `forces`
/// (`model.forces.len()`: a spring's `k (l - l0)^2 / 2`, a constant load's `-F . r`,
/// `-tau phi`).
pub fn energies_into(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], bodies: &mut [f64], forces: &mut [f64]) {
    dynamics::mass_and_forces(model, data, t, q, qd);
    for (i, (b, bd)) in model.bodies.iter().zip(&data.bodies).enumerate() {
        bodies[3 * i] = b.kinetic_energy(bd, qd);
        bodies[3 * i + 1] = b.strain_energy(q);
        bodies[3 * i + 2] = model.gravity.map_or(0.0, |g| b.gravity_energy(q, g));
    }
    for (f, o) in model.forces.iter().zip(forces.iter_mut()) {
        *o = f.potential(&model.bodies, q);
    }
}

/// The potentials `-tau phi` of the torques over a run of `nt` states (`fp`: `nt` rows of
/// `model.forces.len()`, as `energies_into` wrote them), with each frame angle `phi` unwrapped
/// from state to state: a marker angle read off a direction (an ANCF slope) jumps by `2 pi`
/// where it passes `+-pi`, and the work of a torque over several turns is not periodic.
pub fn unwrap_torque_potentials(model: &Model, fp: &mut [f64], nt: usize) {
    let nf = model.forces.len();
    for (i, f) in model.forces.iter().enumerate() {
        let crate::force::ForceKind::Torque { torque, .. } = f.kind else { continue };
        if torque == 0.0 {
            continue;
        }
        let mut prev: Option<f64> = None;
        for k in 0..nt {
            let phi = -fp[k * nf + i] / torque;
            let phi = prev.map_or(phi, |p| p + crate::constraint::rows::wrap_angle(phi - p));
            fp[k * nf + i] = -torque * phi;
            prev = Some(phi);
        }
    }
}

/// Power dissipated by the damping forces at `(q, qd)` (>= 0): `-qd . Q_odd` with
/// `Q_odd = (Q(q, qd) - Q(q, -qd)) / 2`, the part of the generalized forces odd in `qd`. The
/// inertial velocity terms are quadratic in `qd` and the elastic, gravity and constant loads do
/// not depend on it, so `Q_odd` is exactly the damping (spring-dampers, beam strain-rate
/// damping) for every body kind. `v` and `f` are n-long scratch vectors.
///
/// The loads that are functions of time and state (and motors) are not damping: their odd part
/// is taken out here and their whole power is [`load_power`] (external work). A contact (a
/// revolute joint with clearance) dissipates `-qd . (Q_c(q, qd) - Q_c(q, 0))`, which is not odd
/// in `qd`: its odd part is replaced by that. `g` is a third n-long scratch.
///
/// Joint friction (`force::friction`, not in `Q`: it reads the multipliers) adds `-sum F_i v_i`,
/// its forces closed with the reactions by a UK solve at the state.
pub fn dissipation_power(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], v: &mut [f64], f: &mut [f64], g: &mut [f64]) -> Result<f64> {
    let friction = match data.friction.is_some() {
        true => {
            uk::acceleration(model, data, t, q, qd)?;
            -data.friction.as_ref().map_or(0.0, |w| w.power())
        }
        false => 0.0,
    };
    dynamics::mass_and_forces(model, data, t, q, qd);
    f.copy_from_slice(&data.force);
    for (vi, x) in v.iter_mut().zip(qd) {
        *vi = -x;
    }
    dynamics::mass_and_forces(model, data, t, q, v);
    let p = -qd.iter().zip(f.iter().zip(&data.force)).map(|(x, (a, b))| x * 0.5 * (a - b)).sum::<f64>();
    let plus = load_power(model, data, t, q, qd, qd, g);
    let minus = load_power(model, data, t, q, v, qd, g);
    let mut p = p + 0.5 * (plus - minus);
    if model.forces.iter().any(is_contact) {
        // a contact's dissipation is not odd in qd (its friction grows with the normal force's
        // damping part): take its odd part out and count `-qd . (Q_c(q, qd) - Q_c(q, 0))`
        let plus = forces_power(model, data, t, q, qd, qd, g, is_contact);
        let minus = forces_power(model, data, t, q, v, qd, g, is_contact);
        f.fill(0.0);
        let rest = forces_power(model, data, t, q, f, qd, g, is_contact);
        p += 0.5 * (plus - minus) - (plus - rest);
    }
    Ok(p + friction)
}

/// Whether a force is a contact (a revolute joint with clearance), whose dissipated power
/// [`dissipation_power`] counts apart.
pub fn is_contact(f: &crate::force::Force) -> bool {
    matches!(f.kind, crate::force::ForceKind::RevoluteClearance(_))
}

/// Columns of one clearance joint's row (see [`clearance_into`]).
pub const CLEARANCE_COLUMNS: [&str; 5] = ["eccentricity", "penetration", "normal_force", "tangential_force", "force"];

/// For each revolute joint with clearance (in `model.forces` order), 5 numbers into `out`: the
/// eccentricity, the penetration (negative in free flight), the normal and tangential contact
/// forces and the contact force's magnitude.
pub fn clearance_into(model: &Model, q: &[f64], qd: &[f64], out: &mut [f64]) {
    let contacts = model.forces.iter().filter_map(|f| match &f.kind {
        crate::force::ForceKind::RevoluteClearance(c) => Some(c),
        _ => None,
    });
    for (c, o) in contacts.zip(out.chunks_exact_mut(CLEARANCE_COLUMNS.len())) {
        let k = c.contact(&c.journal.state(&model.bodies, q, qd), &c.bearing.state(&model.bodies, q, qd));
        o.copy_from_slice(&[k.eccentricity, k.penetration, k.normal_force, k.tangential_force, k.normal_force.hypot(k.tangential_force)]);
    }
}

/// Whether a force's work is counted as external work by its power (a load that is a
/// function of time or state, a motor) rather than by a potential.
pub fn works_by_power(f: &crate::force::Force) -> bool {
    use crate::force::ForceKind;
    match &f.kind {
        ForceKind::Motor(_) | ForceKind::Motor3(_) => true,
        ForceKind::Load(l) => !l.is_constant(),
        ForceKind::SpatialLoad(l) => !l.has_potential(),
        _ => false,
    }
}

/// `w . Q_L(t, q, qd)`: the power (for `w = qd`) of the loads that work by power
/// ([`works_by_power`]). `g` is an n-long scratch.
pub fn load_power(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], w: &[f64], g: &mut [f64]) -> f64 {
    forces_power(model, data, t, q, qd, w, g, works_by_power)
}

/// `w . Q_F(t, q, qd)` of the forces `pick` selects. `g` is an n-long scratch.
#[allow(clippy::too_many_arguments)]
fn forces_power(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], w: &[f64], g: &mut [f64], pick: fn(&crate::force::Force) -> bool) -> f64 {
    g.fill(0.0);
    // a spatial motor reads its angle counted at the last `mass_and_forces` (not updated here)
    for (f, turn) in model.forces.iter().zip(&data.turns).filter(|(f, _)| pick(f)) {
        f.add_to(&model.bodies, t, q, qd, &mut data.load_scratch, &mut turn.clone(), g);
    }
    w.iter().zip(g.iter()).map(|(a, b)| a * b).sum()
}
