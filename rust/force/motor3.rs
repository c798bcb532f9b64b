//! A motor on a spatial joint (docs/loads.md, "Motors in 3D"): a torque `tau` about the axis of a
//! `revolute` or `cylindrical` joint, `+tau` on the body of its marker `a`, `-tau` on `b`'s; or
//! a force `F` along the slide axis of a `prismatic` joint (a linear motor). Its value is a
//! [`Value`] that may read, besides `t`, the coordinates and the point quantities, the joint's
//! own relative quantities:
//!
//! * rotation (`LOCAL_ROTATION`): `angle`, the angle of `x_a` from `x_b` about the axis `z_b`,
//!   `theta = atan2(x_a . y_b, x_a . x_b)`, counted over turns from call to call as the spatial
//!   rotational spring's (`Data::turns`; the first reading within half a turn of 0), and its
//!   rate `w = d theta / dt = (c sd - s cd) / (s^2 + c^2)` (`s = x_a . y_b`, `c = x_a . x_b`),
//!   which on the joint's manifold is `(omega_a - omega_b) . z_b`;
//! * slide (`LOCAL_SLIDE`): `s = z_b . (P_a - P_b)` and its rate `v`.
//!
//! The generalized force is the virtual work of the value on that quantity, `Q = tau J_theta^T`
//! (`J_theta = (c J_s - s J_c) / (s^2 + c^2)`, the same as the rotational spring-damper's) or
//! `Q = F J_s^T`, so its power is exactly `tau w` (`F v`); on the joint's manifold `Q` is the
//! torque `tau z_b` on `a`'s body and `-tau z_b` on `b`'s (the force `F z_b` on `a`'s point and
//! `-F z_b` on `b`'s).
//!
//! The rotor inertia `J_r` turns with `a`'s body (`b`'s when `a` is on the ground, the stator; a
//! rigid3 body): `J_r z z^T` (`z` the marker's axis in body axes) is added to that body's
//! inertia tensor at build (`Rigid3::add_inertia`),
//! so the rotor's spin energy `J_r (omega_a . z)^2 / 2` is in the body's kinetic energy, exactly,
//! whatever the stator does. The rotor's inertia across its axis is not added: it is part of
//! the body's tensor as the user gives it.

use super::value::{Env, Scope, Value};
use super::value3::Spatial;
use super::value3::rate_kin;
use crate::body::marker3::{add_jacobian, Kin3, Marker3State};
use crate::body::{Body, BodyKind};
use crate::constraint::rows::wrap_angle;
use crate::constraint::spatial::{prim, Pair, SpatialConstraint};
use crate::constraint::{Constraint, ConstraintKind};
use crate::description::spatial::Motor3Desc;
use crate::error::{non_negative, Error, Result};
use crate::linalg::rot3::{col, dot, scale, V3};

/// The names a rotary motor's value reads besides `t`, the coordinates and the points.
pub const LOCAL_ROTATION: [&str; 2] = ["angle", "w"];
/// The names a linear motor's value reads.
pub const LOCAL_SLIDE: [&str; 2] = ["s", "v"];

/// What the motor drives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Drive {
    /// A torque about the axis (revolute, cylindrical).
    Rotation,
    /// A force along the axis (prismatic).
    Slide,
}

#[derive(Debug, Clone)]
pub struct Motor3 {
    /// The joint's index among the constraints and its markers (`a`, `b`).
    pub joint: usize,
    pub pair: Pair,
    pub drive: Drive,
    pub value: Value,
    pub rotor_inertia: f64,
}

/// The joint quantity a motor drives with its value and rate: read, the marker states, and
/// for a rotation `(s, c, s^2 + c^2)`.
struct Reading {
    x: f64,
    xd: f64,
    sa: Marker3State,
    sb: Marker3State,
    scr: [f64; 3],
}

impl Motor3 {
    /// Build from the description: `joint` among `constraints` (unknown: named), a revolute,
    /// cylindrical or prismatic joint (another kind has no axis to drive: named).
    pub fn from_desc(item: &str, coordinate_names: &[String], spatial: Spatial, constraints: &[Constraint], d: &Motor3Desc) -> Result<Motor3> {
        let Some(ji) = constraints.iter().position(|c| c.name == d.joint) else {
            let valid = constraints.iter().filter(|c| !c.name.ends_with(".normalization")).map(|c| c.name.clone()).collect();
            return Err(Error::UnknownName { what: format!("joint (of {item})"), name: d.joint.clone(), valid });
        };
        let (pair, drive) = match &constraints[ji].kind {
            ConstraintKind::Spatial(SpatialConstraint::Revolute(r)) => (&r.pair, Drive::Rotation),
            ConstraintKind::Spatial(SpatialConstraint::Cylindrical(c)) => (&c.pair, Drive::Rotation),
            ConstraintKind::Spatial(SpatialConstraint::Prismatic(p)) => (&p.pair, Drive::Slide),
            _ => {
                return Err(Error::invalid(item, format!("a motor drives a revolute or cylindrical joint (a torque about its axis) or a prismatic joint (a force along it); '{}' has no such axis", d.joint)));
            }
        };
        let rotor_inertia = non_negative(item, "rotor_inertia", d.rotor_inertia)?;
        if drive == Drive::Slide && rotor_inertia > 0.0 {
            return Err(Error::invalid(item, "rotor_inertia is a rotary motor's: a linear motor's moving part is its body's mass"));
        }
        let local: &[&'static str] = if drive == Drive::Rotation { &LOCAL_ROTATION } else { &LOCAL_SLIDE };
        let scope = Scope { coordinate_names, local, ctx: None, spatial: Some(spatial) };
        let what = if drive == Drive::Rotation { "torque" } else { "force (the value of torque on a prismatic joint)" };
        let value = Value::new(item, what, &scope, &d.torque)?;
        Ok(Motor3 { joint: ji, pair: pair.clone(), drive, value, rotor_inertia })
    }

    /// The rotor's inertia `J_r z z^T` added to the rotor's body: `a`'s, or `b`'s when `a` is
    /// on the ground (the stator); a rigid3 body (a flexible3 body refused by name).
    pub fn add_rotor_inertia(&self, item: &str, bodies: &mut [Body]) -> Result<()> {
        if self.rotor_inertia == 0.0 {
            return Ok(());
        }
        let m = if self.pair.i.body.is_some() { &self.pair.i } else { &self.pair.j };
        let refuse = || Error::invalid(item, "a rotor inertia needs the rotor on a rigid3 body (the marker a's body, or b's when a is on the ground; on a flexible body add the rotor as a rigid3 body joined to it)");
        let Some(b) = m.body.filter(|_| m.iface.is_none()) else { return Err(refuse()) };
        let BodyKind::Rigid3(r) = &mut bodies[b].kind else { return Err(refuse()) };
        let z = col(&m.c, 2);
        let extra = std::array::from_fn(|a| std::array::from_fn(|c| self.rotor_inertia * z[a] * z[c]));
        r.add_inertia(item, &extra)
    }

    /// The driven quantity at `(q, qd)`: a rotation counted from `turn` (the previous reading,
    /// NaN: none) when `count`, which updates it; a slide as it is.
    #[inline]
    fn read(&self, bodies: &[Body], q: &[f64], qd: &[f64], turn: &mut f64, count: bool) -> Reading {
        match self.drive {
            Drive::Rotation => {
                let (sa, sb) = self.pair.states_axes(bodies, &[], q, qd, [0b001, 0b011]);
                let (s, sd, _) = prim::dot_terms(&sa.axes[0], &sb.axes[1]);
                let (c, cd, _) = prim::dot_terms(&sa.axes[0], &sb.axes[0]);
                let r2 = s * s + c * c;
                let mut th = s.atan2(c);
                if turn.is_finite() {
                    th = *turn + wrap_angle(th - *turn);
                }
                if count {
                    *turn = th;
                }
                let thd = if r2 > 0.0 { (c * sd - s * cd) / r2 } else { 0.0 };
                Reading { x: th, xd: thd, sa, sb, scr: [s, c, r2] }
            }
            Drive::Slide => {
                let (sa, sb) = self.pair.states_axes(bodies, &[], q, qd, [0, 0b100]);
                let (x, xd, _) = prim::dot2_terms(&sb.axes[2], &sb, &sa);
                Reading { x, xd, sa, sb, scr: [0.0; 3] }
            }
        }
    }

    /// `row += wt J` of the driven quantity (`J_theta` or `J_s`).
    #[inline]
    fn add_jacobian(&self, bodies: &[Body], r: &Reading, wt: f64, row: &mut [f64]) {
        match self.drive {
            Drive::Rotation => {
                let [s, c, r2] = r.scr;
                if r2 > 0.0 {
                    prim::dot_jacobian(bodies, &r.sa, &r.sa.axes[0], &r.sb, &r.sb.axes[1], wt * c / r2, row, None);
                    prim::dot_jacobian(bodies, &r.sa, &r.sa.axes[0], &r.sb, &r.sb.axes[0], -wt * s / r2, row, None);
                }
            }
            Drive::Slide => prim::dot2_jacobian(bodies, &r.sb.axes[2], &r.sb, &r.sa, wt, row, None),
        }
    }

    /// `row += wt d xd / dq`, the change of the driven quantity's rate with the positions at
    /// fixed `qd` (zero for a planar motor's `w = omega_a - omega_b`, not in 3D): with
    /// `x = u . v` of marker vectors, `d xd / dq = vd^T J_u + ud^T J_v + v^T d ud/dq +
    /// u^T d vd/dq` (`value3::rate_kin`); the angle's quotient rule on top.
    fn add_rate_jacobian(&self, bodies: &[Body], qd: &[f64], r: &Reading, wt: f64, row: &mut [f64]) {
        let (a, b) = (&self.pair.i, &self.pair.j);
        // `wt d(u . v)dot / dq`, `u` the vector `cu` (body axes) of `a`'s state `ku`, `v` of `b`
        let dot_rate = |su: &Marker3State, mu: &crate::body::marker3::Marker3, ku: &Kin3, cu: &V3, sv: &Marker3State, mv: &crate::body::marker3::Marker3, kv: &Kin3, cv: &V3, wt: f64, row: &mut [f64]| {
            add_jacobian(bodies, su, ku, &scale(wt, &kv.vd), row, None);
            add_jacobian(bodies, sv, kv, &scale(wt, &ku.vd), row, None);
            add_jacobian(bodies, su, &rate_kin(mu, bodies, qd, cu), &scale(wt, &kv.v), row, None);
            add_jacobian(bodies, sv, &rate_kin(mv, bodies, qd, cv), &scale(wt, &ku.v), row, None);
        };
        match self.drive {
            Drive::Rotation => {
                let [s, c, r2] = r.scr;
                if !(r2 > 0.0) {
                    return;
                }
                let (sd, cd) = (dot(&r.sa.axes[0].vd, &r.sb.axes[1].v) + dot(&r.sa.axes[0].v, &r.sb.axes[1].vd), dot(&r.sa.axes[0].vd, &r.sb.axes[0].v) + dot(&r.sa.axes[0].v, &r.sb.axes[0].vd));
                let w = r.xd;
                // w = (c sd - s cd) / r2
                prim::dot_jacobian(bodies, &r.sa, &r.sa.axes[0], &r.sb, &r.sb.axes[0], wt * (sd - 2.0 * w * c) / r2, row, None);
                prim::dot_jacobian(bodies, &r.sa, &r.sa.axes[0], &r.sb, &r.sb.axes[1], wt * (-cd - 2.0 * w * s) / r2, row, None);
                let (xa, xb, yb) = (col(&a.c, 0), col(&b.c, 0), col(&b.c, 1));
                dot_rate(&r.sa, a, &r.sa.axes[0], &xa, &r.sb, b, &r.sb.axes[1], &yb, wt * c / r2, row);
                dot_rate(&r.sa, a, &r.sa.axes[0], &xa, &r.sb, b, &r.sb.axes[0], &xb, -wt * s / r2, row);
            }
            Drive::Slide => {
                // x = z_b . (P_a - P_b): the axis with each point
                let zb = col(&b.c, 2);
                dot_rate(&r.sb, b, &r.sb.axes[2], &zb, &r.sa, a, &r.sa.point, &a.s, wt, row);
                dot_rate(&r.sb, b, &r.sb.axes[2], &zb, &r.sb, b, &r.sb.point, &b.s, -wt, row);
            }
        }
    }

    /// `Q += tau J^T` (module docs); `turn`: the counted angle (`Data::turns`), updated.
    #[inline]
    pub fn add_to(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], scratch: &mut [f64], turn: &mut f64, qv: &mut [f64]) {
        let r = self.read(bodies, q, qd, turn, true);
        let tau = self.value.eval(&Env { bodies, t, q, qd, local: [r.x, r.xd] }, scratch);
        self.add_jacobian(bodies, &r, tau, qv);
    }

    /// `add(i, j, K_ij)` of `K = -J^T dtau/dq`, `dtau/dq` the value's gradient through the
    /// coordinates and points it reads and through the driven quantity and its rate
    /// (`dtau/dangle J + dtau/dw dw/dq`); the
    /// change of `J` with `q` (`tau dJ^T/dq`) is left out, as the loads' (`Force::add_stiffness`).
    /// `turn`: the last counted angle (read, not updated). `p`, `r`: n-long scratch rows.
    #[allow(clippy::too_many_arguments)]
    pub fn add_stiffness(&self, bodies: &[Body], t: f64, q: &[f64], qd: &[f64], turn: f64, scratch: &mut [f64], p: &mut [f64], r: &mut [f64], add: &mut dyn FnMut(usize, usize, f64)) {
        let rd = self.read(bodies, q, qd, &mut turn.clone(), false);
        r.fill(0.0);
        let [d_x, d_xd] = self.value.add_position_gradient(&Env { bodies, t, q, qd, local: [rd.x, rd.xd] }, scratch, r);
        self.add_jacobian(bodies, &rd, d_x, r);
        if d_xd != 0.0 {
            self.add_rate_jacobian(bodies, qd, &rd, d_xd, r);
        }
        p.fill(0.0);
        self.add_jacobian(bodies, &rd, 1.0, p);
        super::outer(p, r, -1.0, add);
    }

    /// The driven quantity and its rate at `(q, qd)` read from the counted angle `turn`
    /// (inspection: the sensors).
    pub fn reading(&self, bodies: &[Body], q: &[f64], qd: &[f64], turn: f64) -> [f64; 2] {
        let r = self.read(bodies, q, qd, &mut turn.clone(), false);
        [r.x, r.xd]
    }
}

#[cfg(test)]
mod tests {
    use crate::data::Data;
    use crate::dynamics;
    use crate::force::ForceKind;
    use crate::model::Model;

    /// `K` of the force elements (`add_force_stiffness`) at a state off the scene's start against
    /// central differences of `d(q) = Q_F(q) - F(q*) J(q)` (`Q_F = F J` the elements' generalized
    /// force; for a motor the frozen part subtracted, so that the left-out `F dJ/dq` is not
    /// compared; a load at a point mass has a constant `J`): `-dd/dq = -J (dF/dq)^T`, to 1e-6.
    fn check(text: &str) -> Vec<f64> {
        let model = Model::from_json(text).unwrap();
        let mut data = Data::new(&model);
        let n = model.n;
        let q: Vec<f64> = model.q0.iter().enumerate().map(|(i, x)| x + 0.013 * (i as f64 + 1.0)).collect();
        let qd: Vec<f64> = (0..n).map(|i| 0.4 - 0.1 * i as f64).collect();
        let t = 0.7;
        dynamics::mass_and_forces(&model, &mut data, t, &q, &qd);
        let mut k = vec![0.0; n * n];
        dynamics::add_force_stiffness(&model, &mut data, &q, &qd, &mut |i, j, v| k[i * n + j] += v);
        let turns = data.turns.clone();
        let mut scratch = vec![0.0; 64];
        let frozen: Vec<f64> = model.forces.iter().zip(&turns).map(|(f, &turn)| match &f.kind {
            ForceKind::Motor3(m) => {
                let r = m.read(&model.bodies, &q, &qd, &mut turn.clone(), false);
                m.value.eval(&super::Env { bodies: &model.bodies, t, q: &q, qd: &qd, local: [r.x, r.xd] }, &mut scratch)
            }
            _ => 0.0,
        }).collect();
        let forces = |x: &[f64], scratch: &mut [f64]| {
            let mut out = vec![0.0; n];
            for ((f, &turn), &tau) in model.forces.iter().zip(&turns).zip(&frozen) {
                f.add_to(&model.bodies, t, x, &qd, scratch, &mut turn.clone(), &mut out);
                if let ForceKind::Motor3(m) = &f.kind {
                    let r = m.read(&model.bodies, x, &qd, &mut turn.clone(), false);
                    m.add_jacobian(&model.bodies, &r, -tau, &mut out);
                }
            }
            out
        };
        let (mut x, h) = (q.clone(), 1e-6);
        for j in 0..n {
            x[j] = q[j] + h;
            let fp = forces(&x, &mut scratch);
            x[j] = q[j] - h;
            let fm = forces(&x, &mut scratch);
            x[j] = q[j];
            for i in 0..n {
                let fd = -(fp[i] - fm[i]) / (2.0 * h);
                assert!((k[i * n + j] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "K[{i}][{j}] = {} vs {fd}", k[i * n + j]);
            }
        }
        k
    }

    const BODIES: &str = r#""bodies": [
        {"kind": "point3", "name": "m", "mass": 1.0, "position": [1.0, 0.5, 0.2]},
        {"kind": "rigid3", "name": "a", "mass": 2.0, "inertia": [[0.1, 0, 0], [0, 0.2, 0], [0, 0, 0.3]],
         "position": [0.1, -0.3, 0.4], "orientation": [0.3, 0.8, 0.2, -0.4]},
        {"kind": "rigid3", "name": "b", "mass": 1.0, "inertia": [0.2, 0.2, 0.3], "position": [0.3, 0.1, 0.2]}]"#;

    #[test]
    fn spatial_point_quantities_stiffness_matches_differences() {
        // a load at a point mass (constant Jacobian) reading the mass's and a turned body's points
        let k = check(&format!(r#"{{"dim": 3, {BODIES}, "forces": [{{"kind": "point_load", "point": {{"body": "m"}},
            "force": ["-30 * z(m) * x(a, [0.1, 0.2, -0.1]) + d:z(m)", "sin(t) * y(a)^2 + 3 * d:x(a, [0.1, 0.2, -0.1]) * d:y(a, [0.1, 0.2, -0.1])", "5 * z(b, [0, 0.3, 0]) - x(m)"]}}]}}"#));
        assert!(k[2] != 0.0 && k[3 + 3] != 0.0 && k[2 * 17 + 12] != 0.0, "{k:?}");
    }

    #[test]
    fn motor_stiffness_matches_differences() {
        // a revolute about a tilted axis between two turned bodies, and a prismatic joint
        let k = check(&format!(r#"{{"dim": 3, {BODIES},
          "joints": [{{"kind": "revolute", "name": "h", "a": {{"body": "a", "z": [1, 2, 2]}}, "b": {{"body": "b", "point": [-0.2, -0.4, 0.2], "z": [0, 1, 1]}}}},
                     {{"kind": "prismatic", "name": "p", "a": {{"body": "b", "z": [1, 0, 1]}}, "b": {{"body": "ground", "point": [0.3, 0.1, 0.2], "z": [1, 0, 1]}}}}],
          "forces": [{{"kind": "motor", "joint": "h", "torque": "-5 * angle^2 + 0.3 * w + z(b) * x(a, [0.1, 0, 0]) + sin(t) * a.x"}},
                     {{"kind": "motor", "joint": "p", "torque": "3 * s^2 - v + 2 * y(m) + s * z(a)"}}]}}"#));
        assert!(k.iter().filter(|x| **x != 0.0).count() > 50, "{k:?}");
    }
}
