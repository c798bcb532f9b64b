//! The joint quantities a planar load's value may read (docs/loads.md, "Load values"):
//! `angle(J)`, the relative angle `phi_a - phi_b` of a revolute joint's two marker frames (as
//! a motor's `angle`), `s(J)`, the slide of a prismatic joint's point `a` along `b`'s axis,
//! `(r_a - r_b) . e_b` with `e_b = (cos phi_b, sin phi_b)`, and their rates `d:angle(J)`,
//! `d:s(J)` (the time derivatives: `omega_a - omega_b`, `e_b . (v_a - v_b) + omega_b (r_a -
//! r_b) . n_b`, `n_b = (-sin phi_b, cos phi_b)`; the second term vanishes while the joint holds).
//! The joint's markers are the ones the joint resolved (`BuildContext::joints`), so a quantity
//! reads exactly what the joint constrains. Each is read into the expression as a variable
//! (`value.rs`, `Input::Joint`), with its position gradient in the stiffness; a rate's change
//! with the positions is left out (as for `d:x(BODY, XI)`).

use crate::body::{Body, Marker};
use crate::constraint::{BuildContext, ConstraintKind};
use crate::error::{Error, Result};

/// What the joint quantities look like, for messages.
pub const HELP: &str = ", angle(JOINT) (a revolute joint), s(JOINT) (a prismatic joint) or their rates d:angle(...)";

/// The names: `angle` of a revolute, `s` of a prismatic.
const NAMES: [&str; 2] = ["angle", "s"];

/// One joint quantity a value reads.
#[derive(Debug, Clone)]
pub struct JointQuantity {
    /// 0: angle (revolute), 1: slide (prismatic).
    what: usize,
    pub rate: bool,
    a: Marker,
    b: Marker,
}

/// A joint quantity parsed from the start of `s`: `(what, rate, joint name, length of the
/// text)`; `None` when `s` does not start with one.
pub fn parse(s: &str) -> Option<(usize, bool, &str, usize)> {
    let (rate, rest) = match s.strip_prefix("d:") {
        Some(r) => (true, r),
        None => (false, s),
    };
    let what = NAMES.iter().position(|n| rest.strip_prefix(n).is_some_and(|r| r.trim_start().starts_with('(')))?;
    let inner = rest[NAMES[what].len()..].trim_start().strip_prefix('(')?;
    let close = inner.find(')')?;
    let name = inner[..close].trim();
    if name.is_empty() || !name.chars().all(|c| c.is_alphanumeric() || "_.:-#".contains(c)) {
        return None;
    }
    Some((what, rate, name, (s.len() - inner.len()) + close + 1))
}

impl JointQuantity {
    /// Resolve `what(joint)` from the joints built so far; `err` builds the expression's error
    /// at the quantity.
    pub fn new(ctx: &BuildContext, what: usize, rate: bool, joint: &str, err: &dyn Fn(String) -> Error) -> Result<JointQuantity> {
        let name = NAMES[what];
        let Some(c) = ctx.joints.iter().find(|c| c.name == joint) else {
            let known: Vec<&str> = ctx.joints.iter().map(|c| c.name.as_str()).collect();
            let known = if known.is_empty() { "none".to_string() } else { known.join(", ") };
            return Err(err(format!("{name}({joint}): unknown joint '{joint}'; the joints are: {known}")));
        };
        let (a, b) = match (&c.kind, what) {
            (ConstraintKind::Revolute(r), 0) => (r.a.clone(), r.b.clone()),
            (ConstraintKind::Prismatic(p), 1) => (p.a.clone(), p.b.clone()),
            (k, _) => {
                return Err(err(format!(
                    "{name}({joint}): joint '{joint}' is a {} joint; angle(JOINT) reads a revolute joint, s(JOINT) a prismatic joint",
                    kind_name(k)
                )))
            }
        };
        if what == 0 && !(a.has_orientation() && b.has_orientation()) {
            return Err(err(format!("angle({joint}): a marker of the revolute joint '{joint}' is on a point mass, which has no orientation")));
        }
        Ok(JointQuantity { what, rate, a, b })
    }

    /// Its value (or rate) at `q`, `qd`.
    #[inline]
    pub fn value(&self, bodies: &[Body], q: &[f64], qd: &[f64]) -> f64 {
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        match (self.what, self.rate) {
            (0, false) => sa.phi - sb.phi,
            (0, true) => sa.omega - sb.omega,
            (_, rate) => {
                let (s, c) = sb.phi.sin_cos();
                let d = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
                if rate {
                    c * (sa.v[0] - sb.v[0]) + s * (sa.v[1] - sb.v[1]) + sb.omega * (-s * d[0] + c * d[1])
                } else {
                    c * d[0] + s * d[1]
                }
            }
        }
    }

    /// `row += w d(value)/dq`; nothing for a rate (its change with the positions is left out).
    pub fn add_gradient(&self, bodies: &[Body], q: &[f64], qd: &[f64], w: f64, row: &mut [f64]) {
        if self.rate {
            return;
        }
        let (sa, sb) = (self.a.state(bodies, q, qd), self.b.state(bodies, q, qd));
        if self.what == 0 {
            self.a.add_angle_jacobian(bodies, &sa, w, row);
            self.b.add_angle_jacobian(bodies, &sb, -w, row);
            return;
        }
        // s = d . e_b: ds = e_b . (dr_a - dr_b) + (d . n_b) dphi_b
        let (s, c) = sb.phi.sin_cos();
        let d = [sa.r[0] - sb.r[0], sa.r[1] - sb.r[1]];
        self.a.add_point_jacobian(bodies, &sa, [w * c, w * s], row);
        self.b.add_point_jacobian(bodies, &sb, [-w * c, -w * s], row);
        self.b.add_angle_jacobian(bodies, &sb, w * (-s * d[0] + c * d[1]), row);
    }

    /// The two markers (their coordinates are what it reads).
    pub fn markers(&self) -> [&Marker; 2] {
        [&self.a, &self.b]
    }
}

/// The description's name of a joint kind, for messages.
fn kind_name(k: &ConstraintKind) -> &'static str {
    match k {
        ConstraintKind::Revolute(_) => "revolute",
        ConstraintKind::Prismatic(_) => "prismatic",
        ConstraintKind::PointOnLine(_) => "point_on_line",
        ConstraintKind::Weld(_) => "weld",
        ConstraintKind::Distance(_) => "distance",
        _ => "spatial",
    }
}

#[cfg(test)]
mod tests {
    use crate::force::tests::stiffness_against_differences;

    /// A revolute hinge and a prismatic slide between turned rigid bodies (markers off their
    /// centres): `K` of loads of `angle`, `s` (and `d:angle` on rigid frames, whose change with
    /// the positions is zero) against central differences of `Q`, to 1e-6; off the joints'
    /// manifold (the state is moved), where `d:s` has its rotation term.
    #[test]
    fn joint_quantity_stiffness_matches_differences() {
        let bodies = r#"[
            {"kind": "rigid", "name": "u", "mass": 1.0, "inertia": 0.1, "angle": 0.2, "position": [0.3, 0.1]},
            {"kind": "rigid", "name": "w", "mass": 2.0, "inertia": 0.1, "angle": 0.7, "position": [-0.2, 0.4]},
            {"kind": "rigid", "name": "z", "mass": 2.0, "inertia": 0.1, "angle": -0.4, "position": [0.5, 0.9]}]"#;
        let joints = r#"[
            {"kind": "revolute", "name": "h", "a": {"body": "u", "point": [0.1, 0.05]}, "b": {"body": "w", "point": [-0.1, 0.2], "angle": 0.3}},
            {"kind": "prismatic", "name": "p", "a": {"body": "z", "point": [0.05, -0.1]}, "b": {"body": "w", "point": [0.2, 0.1], "angle": -0.5}}]"#;
        let forces = r#"[
            {"kind": "torque_load", "frame": {"body": "u"}, "torque": "-50 * angle(h) - 3 * d:angle(h) + angle(h)^2 * d:angle(h)"},
            {"kind": "point_load", "point": {"body": "z"}, "fx": "-80 * s(p) + 7 * s(p)^2 * angle(h)", "fy": "sin(s(p))"},
            {"kind": "motor", "a": {"body": "z"}, "torque": "s(p) * angle"}]"#;
        let text = format!(r#"{{"bodies": {bodies}, "joints": {joints}, "forces": {forces}}}"#);
        let k = stiffness_against_differences(&text, 0.03, 0.5);
        let n = 9;
        assert!(k[2 * n + 2] != 0.0 && k[2 * n + 5] != 0.0 && k[6 * n + 8] != 0.0 && k[6 * n + 5] != 0.0, "{k:?}");
    }

    /// The rates are the time derivatives of the values: `d:angle`, `d:s` against the gradient
    /// times `qd` (off the manifold too), and the values against the markers' states.
    #[test]
    fn joint_rates_are_time_derivatives() {
        let text = r#"{"bodies": [
            {"kind": "rigid", "name": "w", "mass": 2.0, "inertia": 0.1, "angle": 0.7, "position": [-0.2, 0.4]},
            {"kind": "rigid", "name": "z", "mass": 2.0, "inertia": 0.1, "angle": -0.4, "position": [0.5, 0.9]}],
          "joints": [{"kind": "prismatic", "name": "p", "a": {"body": "z", "point": [0.05, -0.1]}, "b": {"body": "w", "point": [0.2, 0.1], "angle": -0.5}},
                     {"kind": "revolute", "name": "h", "a": {"body": "z"}, "b": {"body": "w"}}]}"#;
        let (model, _, q, qd) = crate::force::tests::moving(text, 0.02, 0.7);
        let index: std::collections::HashMap<String, usize> = model.bodies.iter().enumerate().map(|(i, b)| (b.name.clone(), i)).collect();
        let ctx = crate::constraint::BuildContext { bodies: &model.bodies, index: &index, q0: &model.q0, coordinate_names: &model.coordinate_names, joints: &model.constraints };
        let err = |m: String| crate::error::Error::invalid("t", m);
        for (what, joint) in [(0, "h"), (1, "p")] {
            let (v, r) = (super::JointQuantity::new(&ctx, what, false, joint, &err).unwrap(), super::JointQuantity::new(&ctx, what, true, joint, &err).unwrap());
            let mut g = vec![0.0; model.n];
            v.add_gradient(&model.bodies, &q, &qd, 1.0, &mut g);
            let fd: f64 = g.iter().zip(&qd).map(|(a, b)| a * b).sum();
            let rate = r.value(&model.bodies, &q, &qd);
            assert!((rate - fd).abs() < 1e-12 * (1.0 + fd.abs()) && rate.abs() > 0.1, "{joint}: {rate} vs {fd}");
            // the value against a step along qd
            let h = 1e-6;
            let qp: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + h * b).collect();
            let qm: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a - h * b).collect();
            let cd = (v.value(&model.bodies, &qp, &qd) - v.value(&model.bodies, &qm, &qd)) / (2.0 * h);
            assert!((cd - rate).abs() < 1e-7, "{joint}: {cd} vs {rate}");
        }
        // named errors: an unknown joint lists the joints; a kind without the quantity says which
        let msg = |r: crate::error::Result<super::JointQuantity>| format!("{}", r.unwrap_err());
        assert!(msg(super::JointQuantity::new(&ctx, 0, false, "hinge", &err)).contains("unknown joint 'hinge'; the joints are: p, h"));
        assert!(msg(super::JointQuantity::new(&ctx, 0, false, "p", &err)).contains("'p' is a prismatic joint; angle(JOINT) reads a revolute joint"));
        assert!(msg(super::JointQuantity::new(&ctx, 1, false, "h", &err)).contains("'h' is a revolute joint"));
    }

    #[test]
    fn joint_quantities_parse() {
        assert_eq!(super::parse("angle(hinge) + 1"), Some((0, false, "hinge", 12)));
        assert_eq!(super::parse("d:s( slide )"), Some((1, true, "slide", 12)));
        assert_eq!(super::parse("sin(t)"), None);
        assert_eq!(super::parse("angle * 2"), None);
    }
}
