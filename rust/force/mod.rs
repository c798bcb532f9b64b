//! Applied forces other than gravity (which is a body-level term in `dynamics.rs`).
//! Each adds its generalized force `J^T F` to `Q` (paper eqs. 34-37). The constant loads and
//! the spring-damper are here; each further kind has its file (docs/loads.md): loads that are
//! functions of time and state (`load.rs`, their values in `value.rs`), motors (`motor.rs`),
//! rotational spring-dampers (`rotational_spring.rs`), bushings (`bushing.rs`), revolute joints
//! with clearance (`clearance.rs`), joint friction (`friction.rs`: not added by `add_to`, it
//! reads the joint's multipliers: `uk::friction`).

pub mod bushing;
pub mod clearance;
pub mod friction;
pub mod friction3;
pub mod load;
pub mod motor;
pub mod motor3;
pub mod rotational_spring;
pub mod value;
pub mod value3;
pub mod value_beam;
pub mod value_joint;
pub mod value_strain;

pub mod spatial;
pub mod spatial_load;
use crate::body::{Body, Marker};
use crate::constraint::{BuildContext, Constraint};
use crate::description::ForceDesc;
use crate::error::{check_finite_item, non_negative, Result};

#[derive(Debug, Clone)]
pub enum ForceKind {
    /// Constant world-frame force at a marker: `Q += r_q^T F`.
    PointForce { point: Marker, force: [f64; 2] },
    /// Constant torque on a marker frame: `Q += phi_q^T tau`.
    Torque { frame: Marker, torque: f64 },
    /// Linear spring-damper between two markers:
    /// `Q -= (k (l - l0) + c l_dot) (r_a - r_b)_q^T e`, `e = (r_a - r_b) / l`.
    SpringDamper { a: Marker, b: Marker, stiffness: f64, damping: f64, rest_length: f64 },
    /// Spatial force elements, gravity included (`force/spatial.rs`).
    Spatial(spatial::SpatialForce),
    /// A spatial force or torque that is a function of time and state (`spatial_load.rs`).
    SpatialLoad(Box<spatial_load::SpatialLoad>),
    /// A force or torque that is a function of time and state (`load.rs`).
    Load(Box<load::Load>),
    Motor(Box<motor::Motor>),
    /// A motor on a spatial joint (`motor3.rs`).
    Motor3(Box<motor3::Motor3>),
    RotationalSpringDamper(Box<rotational_spring::RotationalSpringDamper>),
    Bushing(Box<bushing::Bushing>),
    RevoluteClearance(Box<clearance::Clearance>),
    /// Coulomb and viscous friction in a joint, a function of its reaction (`friction.rs`).
    JointFriction(Box<friction::JointFriction>),
}

#[derive(Debug, Clone)]
pub struct Force {
    pub name: String,
    pub kind: ForceKind,
}

impl Force {
    /// Write the defaults this force resolved into its description (a spring-damper's rest
    /// length taken at the initial guess).
    pub fn fill_defaults(&self, d: &mut ForceDesc) {
        match (&self.kind, d) {
            (ForceKind::SpringDamper { rest_length: r, .. }, ForceDesc::SpringDamper { rest_length, .. }) => *rest_length = Some(*r),
            (ForceKind::RotationalSpringDamper(r), ForceDesc::RotationalSpringDamper { rest_angle, .. }) => *rest_angle = Some(r.rest_angle),
            (ForceKind::JointFriction(f), ForceDesc::JointFriction { v_eps, .. }) => *v_eps = Some(f.v_eps),
            _ => {}
        }
    }

    /// Build a force element; `item` names it in errors; `joints`: the joints so far (joint
    /// friction names one).
    pub fn from_desc(ctx: &BuildContext, joints: &[Constraint], item: &str, name: String, d: &ForceDesc) -> Result<Force> {
        let kind = match d {
            ForceDesc::PointForce { point, force, .. } => {
                check_finite_item(item, "force", force)?;
                ForceKind::PointForce { point: ctx.marker(item, point)?, force: *force }
            }
            ForceDesc::Torque { frame, torque, .. } => {
                check_finite_item(item, "torque", &[*torque])?;
                ForceKind::Torque { frame: ctx.oriented_marker(item, frame)?, torque: *torque }
            }
            ForceDesc::SpringDamper { a, b, stiffness, damping, rest_length, .. } => {
                let (a, b) = (ctx.marker(item, a)?, ctx.marker(item, b)?);
                let rest_length = match rest_length {
                    Some(l) => *l,
                    None => {
                        let (sa, sb) = (ctx.state0(&a), ctx.state0(&b));
                        (sa.r[0] - sb.r[0]).hypot(sa.r[1] - sb.r[1])
                    }
                };
                ForceKind::SpringDamper {
                    a,
                    b,
                    stiffness: non_negative(item, "stiffness", *stiffness)?,
                    damping: non_negative(item, "damping", *damping)?,
                    rest_length: non_negative(item, "rest_length", rest_length)?,
                }
            }
            ForceDesc::PointLoad { point, fx, fy, .. } => ForceKind::Load(Box::new(load::Load::force(ctx, item, point, fx, fy)?)),
            ForceDesc::TorqueLoad { frame, torque, .. } => ForceKind::Load(Box::new(load::Load::torque(ctx, item, frame, torque)?)),
            ForceDesc::Motor { a, b, torque, rotor_inertia, .. } => ForceKind::Motor(Box::new(motor::Motor::from_desc(ctx, item, a, b.as_ref(), torque, *rotor_inertia)?)),
            ForceDesc::RotationalSpringDamper { a, b, stiffness, damping, rest_angle, .. } => {
                ForceKind::RotationalSpringDamper(Box::new(rotational_spring::RotationalSpringDamper::from_desc(ctx, item, a, b.as_ref(), *stiffness, *damping, *rest_angle)?))
            }
            ForceDesc::Bushing { a, b, stiffness, damping, .. } => ForceKind::Bushing(Box::new(bushing::Bushing::from_desc(ctx, item, a, b, *stiffness, *damping)?)),
            ForceDesc::RevoluteClearance { journal, bearing, clearance, journal_radius, stiffness, exponent, restitution, impact_velocity, law, friction, friction_velocities, .. } => {
                let p = clearance::ClearanceParams {
                    clearance: *clearance,
                    journal_radius: *journal_radius,
                    stiffness: *stiffness,
                    exponent: *exponent,
                    restitution: *restitution,
                    impact_velocity: *impact_velocity,
                    law: *law,
                    friction: *friction,
                    friction_velocities: *friction_velocities,
                };
                ForceKind::RevoluteClearance(Box::new(clearance::Clearance::from_desc(ctx, item, journal, bearing, p)?))
            }
            ForceDesc::JointFriction { joint, mu, radius, length, damping, v_eps, .. } => {
                ForceKind::JointFriction(Box::new(friction::JointFriction::from_desc(item, joints, joint, *mu, *radius, *length, *damping, *v_eps)?))
            }
        };
        Ok(Force { name, kind })
    }

    /// The markers this force acts through (its generalized force depends on their states only).
    pub fn markers(&self) -> [Option<&Marker>; 2] {
        match &self.kind {
            ForceKind::PointForce { point, .. } => [Some(point), None],
            ForceKind::Torque { frame, .. } => [Some(frame), None],
            ForceKind::SpringDamper { a, b, .. } => [Some(a), Some(b)],
            ForceKind::Spatial(f) => f.markers(),
            ForceKind::Load(l) => [Some(l.marker()), None],
            ForceKind::SpatialLoad(l) => [Some(l.marker()), None],
            ForceKind::Motor(m) => [Some(&m.a), Some(&m.b)],
            ForceKind::Motor3(m) => [Some(&m.pair.i.base), Some(&m.pair.j.base)],
            ForceKind::RotationalSpringDamper(r) => [Some(&r.a), Some(&r.b)],
            ForceKind::Bushing(b) => [Some(&b.a), Some(&b.b)],
            ForceKind::RevoluteClearance(c) => [Some(&c.journal), Some(&c.bearing)],
            ForceKind::JointFriction(f) => [Some(&f.a), Some(&f.b)],
        }
    }

    /// The coordinates this force's values read besides its markers' (a load of another
    /// body's angle; the points of `x(BODY, XI)` quantities are in `read_points`): they couple
    /// in the sparse Newton matrices' pattern.
    pub fn read_coords(&self) -> Vec<usize> {
        self.values().into_iter().flat_map(|v| v.coords()).collect()
    }

    /// The markers of the point quantities this force's values read.
    pub fn read_points(&self) -> Vec<&Marker> {
        self.values().into_iter().flat_map(|v| v.points()).collect()
    }

    /// The values of this force (the loads' components, a motor's torque).
    pub fn values(&self) -> Vec<&value::Value> {
        match &self.kind {
            ForceKind::Load(l) => match l.as_ref() {
                load::Load::Force { f, .. } => f.iter().collect(),
                load::Load::Torque { tau, .. } => vec![tau],
            },
            ForceKind::Motor(m) => vec![&m.torque],
            ForceKind::Motor3(m) => vec![&m.value],
            ForceKind::SpatialLoad(l) => l.values().iter().collect(),
            _ => Vec::new(),
        }
    }

    /// The values of this force (the loads' components, a motor's torque), mutable: where
    /// callables are attached.
    pub fn values_mut(&mut self) -> Vec<&mut value::Value> {
        match &mut self.kind {
            ForceKind::Load(l) => match l.as_mut() {
                load::Load::Force { f, .. } => f.iter_mut().collect(),
                load::Load::Torque { tau, .. } => vec![tau],
            },
            ForceKind::Motor(m) => vec![&mut m.torque],
            ForceKind::Motor3(m) => vec![&mut m.value],
            ForceKind::SpatialLoad(l) => l.values_mut().iter_mut().collect(),
            _ => Vec::new(),
        }
    }

    /// Whether [`Force::add_stiffness`] adds anything: a load or motor whose value is an
    /// expression or a table, a spring (translational, rotational, bushing) with stiffness or
    /// damping, a revolute joint with clearance.
    pub fn has_stiffness(&self) -> bool {
        match &self.kind {
            ForceKind::SpringDamper { stiffness, damping, .. } => *stiffness > 0.0 || *damping > 0.0,
            ForceKind::RotationalSpringDamper(r) => r.stiffness > 0.0,
            ForceKind::Bushing(b) => b.stiffness.iter().any(|k| *k > 0.0),
            ForceKind::Spatial(f) => f.has_stiffness(),
            ForceKind::RevoluteClearance(_) => true,
            ForceKind::SpatialLoad(l) => l.has_stiffness(),
            _ => self.values().iter().any(|v| v.has_gradient()),
        }
    }

    /// `add(i, j, K_ij)` of this force's analytic position stiffness `K = -dQ/dq`: for the loads
    /// and motors whose value is an expression or a table, `-J^T dF/dq` from the symbolic
    /// gradient; for the springs, their stiffness through the markers' Jacobians (the
    /// spring-damper's also the turning of its line under load). The change of the markers'
    /// Jacobians with `q`, `(dJ^T/dq) F`, is left out, as for the constant loads: it is what
    /// the implicit methods' Newton iteration needs, not an exact Jacobian. `rows` is a `2 n`
    /// scratch, `scratch` the force's evaluation scratch. A revolute joint with clearance adds its
    /// contact stiffness (`clearance.rs`); nothing for the other kinds.
    #[allow(clippy::too_many_arguments)]
    pub fn add_stiffness(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], turn: f64, scratch: &mut [f64], rows: &mut [f64], add: &mut dyn FnMut(usize, usize, f64)) {
        let n = q.len();
        let (p, r) = rows[..2 * n].split_at_mut(n);
        match &self.kind {
            ForceKind::Load(l) => {
                let env = value::Env { bodies, t, q, qd, local: [0.0; 2] };
                match l.as_ref() {
                    load::Load::Force { point, f } => {
                        for (c, v) in f.iter().enumerate().filter(|(_, v)| v.has_gradient()) {
                            r.fill(0.0);
                            v.add_position_gradient(&env, scratch, r);
                            p.fill(0.0);
                            let mut w = [0.0; 2];
                            w[c] = 1.0;
                            point.add_point_jacobian(bodies, &point.state(bodies, q, qd), w, p);
                            outer(p, r, -1.0, add);
                        }
                    }
                    load::Load::Torque { frame, tau } if tau.has_gradient() => {
                        r.fill(0.0);
                        tau.add_position_gradient(&env, scratch, r);
                        p.fill(0.0);
                        frame.add_angle_jacobian(bodies, &frame.state(bodies, q, qd), 1.0, p);
                        outer(p, r, -1.0, add);
                    }
                    load::Load::Torque { .. } => {}
                }
            }
            ForceKind::SpringDamper { a, b, stiffness, damping, rest_length } => {
                let Some(Line { sa, sb, l, e, vrel }) = Line::of(a, b, bodies, q, qd) else { return };
                let nrm = [-e[1], e[0]];
                let f = stiffness * (l - rest_length) + damping * (e[0] * vrel[0] + e[1] * vrel[1]);
                // p = G^T e (dl/dq), r = G^T n, G = (r_a - r_b)_q: K = k p p^T + c (v . n)/l p r^T + f/l r r^T
                p.fill(0.0);
                a.add_point_jacobian(bodies, &sa, e, p);
                b.add_point_jacobian(bodies, &sb, [-e[0], -e[1]], p);
                r.fill(0.0);
                a.add_point_jacobian(bodies, &sa, nrm, r);
                b.add_point_jacobian(bodies, &sb, [-nrm[0], -nrm[1]], r);
                outer(p, p, *stiffness, add);
                outer(p, r, damping * (vrel[0] * nrm[0] + vrel[1] * nrm[1]) / l, add);
                outer(r, r, f / l, add);
            }
            ForceKind::RotationalSpringDamper(rs) => rs.add_stiffness(bodies, q, qd, p, add),
            ForceKind::Bushing(bu) => bu.add_stiffness(bodies, q, qd, p, add),
            ForceKind::Spatial(f) => f.add_stiffness(bodies, q, qd, p, r, add),
            ForceKind::SpatialLoad(l) => l.add_stiffness(&value::Env { bodies, t, q, qd, local: [0.0; 2] }, scratch, p, r, add),
            ForceKind::RevoluteClearance(c) => c.add_stiffness(bodies, q, qd, p, r, add),
            ForceKind::Motor3(m) if m.value.has_gradient() => m.add_stiffness(bodies, t, q, qd, turn, scratch, p, r, add),
            ForceKind::Motor(m) if m.torque.has_gradient() => {
                let (sa, sb, local) = motor::relative(bodies, &m.a, &m.b, q, qd);
                r.fill(0.0);
                let [d_angle, _] = m.torque.add_position_gradient(&value::Env { bodies, t, q, qd, local }, scratch, r);
                m.a.add_angle_jacobian(bodies, &sa, d_angle, r);
                m.b.add_angle_jacobian(bodies, &sb, -d_angle, r);
                p.fill(0.0);
                m.a.add_angle_jacobian(bodies, &sa, 1.0, p);
                m.b.add_angle_jacobian(bodies, &sb, -1.0, p);
                outer(p, r, -1.0, add);
            }
            _ => {}
        }
    }

    /// Whether [`Force::add_damping`] adds anything: a spring-damper (planar or spatial) with
    /// damping.
    pub fn has_damping(&self) -> bool {
        match &self.kind {
            ForceKind::SpringDamper { damping, .. } => *damping > 0.0,
            ForceKind::Spatial(f) => f.has_damping(),
            _ => false,
        }
    }

    /// `add(i, j, C_ij)` of this force's analytic damping `C = -dQ/dqd` through the markers'
    /// Jacobians: a spring-damper's `c p p^T`, `p = G^T e` (`e` its unit direction). The implicit
    /// methods refresh it with `K` at every factorization (`UkSystem::stiff_structure`): a stiff
    /// damper's line turns with the mechanism (A05's governor), and a `C` read once per step (or
    /// per Newton failure, by differences) left Newton contracting slowly (docs/spatial.md).
    /// `rows` is a `2 n` scratch; nothing for the other kinds (their velocity terms come from the
    /// differences of `dynamics::velocity_jacobians_into`).
    pub fn add_damping(&self, bodies: &[Body], q: &[f64], qd: &[f64], rows: &mut [f64], add: &mut dyn FnMut(usize, usize, f64)) {
        let n = q.len();
        let p = &mut rows[..n];
        match &self.kind {
            ForceKind::SpringDamper { a, b, damping, .. } if *damping > 0.0 => {
                let Some(Line { sa, sb, e, .. }) = Line::of(a, b, bodies, q, qd) else { return };
                p.fill(0.0);
                a.add_point_jacobian(bodies, &sa, e, p);
                b.add_point_jacobian(bodies, &sb, [-e[0], -e[1]], p);
                outer(p, p, *damping, add);
            }
            ForceKind::Spatial(f) => f.add_damping(bodies, q, qd, p, add),
            _ => {}
        }
    }

    /// Evaluation scratch this force needs (`Data::load_scratch`).
    pub fn scratch_len(&self) -> usize {
        match &self.kind {
            ForceKind::Load(l) => l.scratch_len(),
            ForceKind::Motor(m) => m.torque.scratch_len(),
            ForceKind::Motor3(m) => m.value.scratch_len(),
            ForceKind::SpatialLoad(l) => l.scratch_len(),
            _ => 0,
        }
    }

    /// Add this force's generalized force to `qvec` (length n).
    #[inline]
    pub fn add_to(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], scratch: &mut [f64], turn: &mut f64, qvec: &mut [f64]) {
        match &self.kind {
            ForceKind::PointForce { point, force } => {
                let s = point.state(bodies, q, qd);
                point.add_point_jacobian(bodies, &s, *force, qvec);
            }
            ForceKind::Torque { frame, torque } => {
                let s = frame.state(bodies, q, qd);
                frame.add_angle_jacobian(bodies, &s, *torque, qvec);
            }
            ForceKind::SpringDamper { a, b, stiffness, damping, rest_length } => {
                // direction undefined at zero length: no force (documented limitation)
                let Some(Line { sa, sb, l, e, vrel }) = Line::of(a, b, bodies, q, qd) else { return };
                let f = stiffness * (l - rest_length) + damping * (e[0] * vrel[0] + e[1] * vrel[1]);
                a.add_point_jacobian(bodies, &sa, [-f * e[0], -f * e[1]], qvec);
                b.add_point_jacobian(bodies, &sb, [f * e[0], f * e[1]], qvec);
            }
            ForceKind::Spatial(f) => f.add_to(bodies, q, qd, turn, qvec),
            ForceKind::Load(l) => l.add_to(bodies, t, q, qd, scratch, qvec),
            ForceKind::SpatialLoad(l) => l.add_to(bodies, t, q, qd, scratch, qvec),
            ForceKind::Motor(m) => m.add_to(bodies, t, q, qd, scratch, qvec),
            ForceKind::Motor3(m) => m.add_to(bodies, t, q, qd, scratch, turn, qvec),
            ForceKind::RotationalSpringDamper(r) => r.add_to(bodies, q, qd, qvec),
            ForceKind::Bushing(b) => b.add_to(bodies, q, qd, qvec),
            ForceKind::RevoluteClearance(c) => c.add_to(bodies, q, qd, qvec),
            // a function of the joint's multipliers: added by the UK kernel (`uk::friction`)
            ForceKind::JointFriction(_) => {}
        }
    }

    /// `1/2 k ldot^2` of a spring-damper for the motion `v` at `q` (its length's first-order
    /// change squared: the spring's share of a mode's stiffness; 0 for the loads).
    pub fn material_energy(&self, bodies: &[Body], q: &[f64], v: &[f64]) -> f64 {
        match &self.kind {
            ForceKind::SpringDamper { a, b, stiffness, .. } => {
                let (sa, sb) = (a.state(bodies, q, v), b.state(bodies, q, v));
                let d = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
                let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
                if l == 0.0 {
                    return 0.0;
                }
                let ldot = (d[0] * (sa.v[0] - sb.v[0]) + d[1] * (sa.v[1] - sb.v[1])) / l;
                0.5 * stiffness * ldot * ldot
            }
            ForceKind::PointForce { .. } | ForceKind::Torque { .. } | ForceKind::Load(_) | ForceKind::SpatialLoad(_) | ForceKind::Motor(_) | ForceKind::Motor3(_) | ForceKind::JointFriction(_) => 0.0,
            ForceKind::Spatial(f) => f.material_energy(bodies, q, v),
            ForceKind::RotationalSpringDamper(r) => r.material_energy(bodies, q, v),
            ForceKind::Bushing(b) => b.material_energy(bodies, q, v),
            ForceKind::RevoluteClearance(c) => c.material_energy(bodies, q, v),
        }
    }

    /// Potential energy stored in this force element (springs only).
    pub fn potential(&self, bodies: &[Body], q: &[f64]) -> f64 {
        match &self.kind {
            ForceKind::SpringDamper { a, b, stiffness, rest_length, .. } => {
                let zeros = vec![0.0; q.len()];
                let (sa, sb) = (a.state(bodies, q, &zeros), b.state(bodies, q, &zeros));
                let l = ((sa.r[0] - sb.r[0]).powi(2) + (sa.r[1] - sb.r[1]).powi(2)).sqrt();
                0.5 * stiffness * (l - rest_length).powi(2)
            }
            // constant forces are not potential-free in general (follower frames); they are
            // world-fixed here, so their potential is -F . r
            ForceKind::PointForce { point, force } => {
                let zeros = vec![0.0; q.len()];
                let s = point.state(bodies, q, &zeros);
                -(force[0] * s.r[0] + force[1] * s.r[1])
            }
            ForceKind::Torque { frame, torque } => {
                let zeros = vec![0.0; q.len()];
                -torque * frame.state(bodies, q, &zeros).phi
            }
            ForceKind::Spatial(f) => f.potential(bodies, q),
            ForceKind::RotationalSpringDamper(r) => r.potential(bodies, q),
            ForceKind::Bushing(b) => b.potential(bodies, q),
            ForceKind::RevoluteClearance(c) => c.potential(bodies, q),
            // a load that is a function has no potential unless it is constant; a motor's work
            // is input, not stored (sensors: `external_work`)
            ForceKind::Load(l) => l.potential(bodies, q).unwrap_or(0.0),
            ForceKind::SpatialLoad(l) => l.potential(bodies, q).unwrap_or(0.0),
            ForceKind::Motor(_) | ForceKind::Motor3(_) | ForceKind::JointFriction(_) => 0.0,
        }
    }
}

/// The line of a spring-damper: marker states, length, unit vector `e` from `b` to `a`, relative
/// velocity (`None` at zero length, where the direction is undefined).
struct Line {
    sa: crate::body::MarkerState,
    sb: crate::body::MarkerState,
    l: f64,
    e: [f64; 2],
    vrel: [f64; 2],
}

impl Line {
    #[inline]
    fn of(a: &Marker, b: &Marker, bodies: &[Body], q: &[f64], qd: &[f64]) -> Option<Line> {
        let (sa, sb) = (a.state(bodies, q, qd), b.state(bodies, q, qd));
        let d = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
        let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
        if l == 0.0 {
            return None;
        }
        let vrel = [sa.v[0] - sb.v[0], sa.v[1] - sb.v[1]];
        Some(Line { sa, sb, l, e: [d[0] / l, d[1] / l], vrel })
    }
}

/// `add(i, j, s p_i r_j)` over the non-zeros of `p` and `r` (`s = -1`: `K = -dQ/dq` of
/// `Q = p F`, `dF/dq = r`).
fn outer(p: &[f64], r: &[f64], s: f64, add: &mut dyn FnMut(usize, usize, f64)) {
    if s == 0.0 {
        return;
    }
    for (i, &pi) in p.iter().enumerate().filter(|(_, x)| **x != 0.0) {
        for (j, &rj) in r.iter().enumerate().filter(|(_, x)| **x != 0.0) {
            add(i, j, s * pi * rj);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::data::Data;
    use crate::dynamics;
    use crate::model::Model;

    #[test]
    fn analytic_load_stiffness_matches_differences() {
        // point-mass and rigid-frame Jacobians are constant: -dQ/dq is exactly -J^T dF/dq
        let text = r#"{"bodies": [
            {"kind": "point_mass", "name": "m", "mass": 1.0, "position": [1.0, 0.5]},
            {"kind": "rigid", "name": "w", "mass": 2.0, "inertia": 0.1, "angle": 0.3, "position": [0.2, -0.4]}],
          "forces": [
            {"kind": "point_load", "point": {"body": "m"},
             "fx": "-200 * (m.x - 1) - 3 * m.y^2 + sin(t) * w.theta + d:m.x",
             "fy": {"of": "m.x", "x": [0, 0.5, 1.5, 2], "y": [0, 1, -1, 3]}},
            {"kind": "motor", "a": {"body": "w"}, "torque": "-5 * angle^2 + 0.3 * w + y(w, 0) * x(w, 0)"},
            {"kind": "torque_load", "frame": {"body": "w"}, "torque": "m.x * w.theta"}]}"#;
        let model = Model::from_json(text).unwrap();
        let mut data = Data::new(&model);
        let n = model.n;
        let q: Vec<f64> = model.q0.iter().enumerate().map(|(i, x)| x + 0.01 * (i as f64 + 1.0)).collect();
        let qd: Vec<f64> = (0..n).map(|i| 0.3 - 0.1 * i as f64).collect();
        let t = 0.7;
        let mut k = vec![0.0; n * n];
        dynamics::mass_and_forces(&model, &mut data, t, &q, &qd);
        dynamics::stiffness_into(&model, &mut data, &q, &qd, &mut k);
        let mut qv = q.clone();
        let h = 1e-6;
        for j in 0..n {
            qv[j] = q[j] + h;
            dynamics::mass_and_forces(&model, &mut data, t, &qv, &qd);
            let fp = data.force.clone();
            qv[j] = q[j] - h;
            dynamics::mass_and_forces(&model, &mut data, t, &qv, &qd);
            qv[j] = q[j];
            for i in 0..n {
                let fd = -(fp[i] - data.force[i]) / (2.0 * h);
                assert!((k[i * n + j] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "K[{i}][{j}] = {} vs {fd}", k[i * n + j]);
            }
        }
        assert!(k[0] == 200.0 && k[4 * n + 4] != 0.0 && k[4 * n] != 0.0, "{k:?}");
    }

    /// `K` of `stiffness_into` against central differences of the forces.
    /// The scene of `text` at its `q0` moved by `dq (i + 1)` and the velocities `qd0 (1 - 0.4 i)`.
    pub(super) fn moving(text: &str, dq: f64, qd0: f64) -> (Model, Data, Vec<f64>, Vec<f64>) {
        let model = Model::from_json(text).unwrap();
        let data = Data::new(&model);
        let q: Vec<f64> = model.q0.iter().enumerate().map(|(i, x)| x + dq * (i as f64 + 1.0)).collect();
        let qd: Vec<f64> = (0..model.n).map(|i| qd0 * (1.0 - 0.4 * i as f64)).collect();
        (model, data, q, qd)
    }

    pub(super) fn stiffness_against_differences(text: &str, dq: f64, qd0: f64) -> Vec<f64> {
        stiffness_rows_against_differences(text, dq, qd0, |_, _| true)
    }

    /// As `stiffness_against_differences`, on the rows `row(model, i)` selects only.
    pub(super) fn stiffness_rows_against_differences(text: &str, dq: f64, qd0: f64, row: impl Fn(&Model, usize) -> bool + Copy) -> Vec<f64> {
        let (model, mut data, q, qd) = moving(text, dq, qd0);
        let n = model.n;
        let mut k = vec![0.0; n * n];
        dynamics::mass_and_forces(&model, &mut data, 0.0, &q, &qd);
        dynamics::stiffness_into(&model, &mut data, &q, &qd, &mut k);
        let (mut qv, h) = (q.clone(), 1e-6);
        for j in 0..n {
            qv[j] = q[j] + h;
            dynamics::mass_and_forces(&model, &mut data, 0.0, &qv, &qd);
            let fp = data.force.clone();
            qv[j] = q[j] - h;
            dynamics::mass_and_forces(&model, &mut data, 0.0, &qv, &qd);
            qv[j] = q[j];
            for i in (0..n).filter(|&i| row(&model, i)) {
                let fd = -(fp[i] - data.force[i]) / (2.0 * h);
                assert!((k[i * n + j] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "K[{i}][{j}] = {} vs {fd}", k[i * n + j]);
            }
        }
        k
    }

    #[test]
    fn spring_stiffness_matches_differences() {
        // a loaded, moving spring-damper between point masses (its line turns: the f / l and
        // c (v . n) / l terms) and a rotational spring-damper between frames: exact
        let k = stiffness_against_differences(r#"{"bodies": [
            {"kind": "point_mass", "name": "m", "mass": 1.0, "position": [1.0, 0.5]},
            {"kind": "point_mass", "name": "p", "mass": 1.0, "position": [0.2, -0.3]},
            {"kind": "rigid", "name": "w", "mass": 2.0, "inertia": 0.1, "angle": 0.3}],
          "forces": [
            {"kind": "spring_damper", "a": {"body": "m"}, "b": {"body": "p"}, "stiffness": 1e4, "damping": 30.0, "rest_length": 0.5},
            {"kind": "rotational_spring_damper", "a": {"body": "w"}, "stiffness": 70.0, "damping": 2.0}]}"#, 0.02, 0.5);
        assert!(k[0] > 1e3 && k[1] != 0.0 && k[6 * 7 + 6] > 0.0, "{k:?}");
        // a bushing at rest (no load: its K is the exact sum k_i p_i p_i^T), b's frame turned
        let k = stiffness_against_differences(r#"{"bodies": [
            {"kind": "rigid", "name": "u", "mass": 1.0, "inertia": 0.1, "angle": 0.2, "position": [0.3, 0.1]},
            {"kind": "rigid", "name": "w", "mass": 2.0, "inertia": 0.1, "angle": 0.7, "position": [-0.2, 0.4]}],
          "forces": [
            {"kind": "bushing", "a": {"body": "u", "point": [0.1, 0.05]}, "b": {"body": "w", "point": [-0.1, 0.2]},
             "stiffness": [1e5, 3e4, 50.0], "damping": [0.0, 0.0, 0.0]}]}"#, 0.0, 0.0);
        assert!(k[0] > 1e4 && k[2 * 6 + 5] != 0.0, "{k:?}");
        // the spatial spring-damper between point masses: exact, its line turning in 3D
        let k = stiffness_against_differences(r#"{"dim": 3, "bodies": [
            {"kind": "point3", "name": "a", "mass": 1.0, "position": [1.0, 0.5, 0.2]},
            {"kind": "point3", "name": "b", "mass": 2.0, "position": [0.1, -0.3, 0.4]}],
          "forces": [{"kind": "spring_damper", "a": {"body": "a"}, "b": {"body": "b"}, "stiffness": 1e4, "damping": 30.0, "rest_length": 0.5}]}"#, 0.02, 0.5);
        assert!(k[0] > 1e3 && k[1] != 0.0 && k[2] != 0.0, "{k:?}");
    }
    /// `C` of `add_force_damping` against central differences in `qd` of the force elements'
    /// generalized forces alone (the bodies' own velocity terms left out).
    fn damping_against_differences(text: &str, dq: f64, qd0: f64) -> Vec<f64> {
        let (model, mut data, q, qd) = moving(text, dq, qd0);
        let n = model.n;
        let mut c = vec![0.0; n * n];
        dynamics::add_force_damping(&model, &mut data, &q, &qd, &mut |i, j, v| c[i * n + j] += v);
        let forces = |v: &[f64]| {
            let (mut out, mut turn) = (vec![0.0; n], f64::NAN);
            for f in &model.forces {
                f.add_to(&model.bodies, 0.0, &q, v, &mut [], &mut turn, &mut out);
            }
            out
        };
        let (mut v, h) = (qd.clone(), 1e-4);
        for j in 0..n {
            v[j] = qd[j] + h;
            let fp = forces(&v);
            v[j] = qd[j] - h;
            let fm = forces(&v);
            v[j] = qd[j];
            for i in 0..n {
                let fd = -(fp[i] - fm[i]) / (2.0 * h);
                assert!((c[i * n + j] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "C[{i}][{j}] = {} vs {fd}", c[i * n + j]);
            }
        }
        c
    }

    #[test]
    fn spring_damping_matches_differences() {
        // planar: a moving spring-damper between point masses (the damping is linear in qd: exact)
        let c = damping_against_differences(r#"{"bodies": [
            {"kind": "point_mass", "name": "m", "mass": 1.0, "position": [1.0, 0.5]},
            {"kind": "point_mass", "name": "p", "mass": 1.0, "position": [0.2, -0.3]}],
          "forces": [{"kind": "spring_damper", "a": {"body": "m"}, "b": {"body": "p"}, "stiffness": 1e4, "damping": 30.0, "rest_length": 0.5}]}"#, 0.02, 0.5);
        assert!(c[0] > 1.0 && c[1] != 0.0, "{c:?}");
        // spatial: from a point mass to a point off a turned rigid body's centre (Euler parameters)
        let c = damping_against_differences(r#"{"dim": 3, "bodies": [
            {"kind": "point3", "name": "a", "mass": 1.0, "position": [1.0, 0.5, 0.2]},
            {"kind": "rigid3", "name": "b", "mass": 2.0, "inertia": [[0.1, 0, 0], [0, 0.2, 0], [0, 0, 0.3]],
             "position": [0.1, -0.3, 0.4], "orientation": [0.3, 0.8, 0.2, -0.4]}],
          "forces": [{"kind": "spring_damper", "a": {"body": "a"}, "b": {"body": "b", "point": [0.1, 0.2, -0.05]},
                      "stiffness": 1e4, "damping": 4e4, "rest_length": 0.5}]}"#, 0.0, 0.5);
        assert!(c[0] > 1e3 && c[3 * 10 + 6] != 0.0, "{c:?}");
    }
}
