//! Shared scenes and helpers for the cargo integration tests.
#![allow(dead_code)]

use ukflex::{Data, Model};

pub const L: f64 = 0.1524;
pub const LB: f64 = 0.3048;
pub const D: f64 = 0.00635;
pub const RHO: f64 = 7834.56;
pub const E: f64 = 2.06843e11;
pub const NU: f64 = 0.285;
pub const OMEGA: f64 = 124.8;

/// The paper's slider-crank (crank frame at the ground pivot, coupler frame at node 1).
pub fn paper_scene(theory: &str, elements: usize, gravity: bool) -> String {
    let a = std::f64::consts::PI * D * D / 4.0;
    let mc = RHO * a * L;
    let g = if gravity { "[0.0, -9.81]" } else { "null" };
    format!(
        r#"{{"gravity": {g},
        "bodies": [
          {{"name": "crank", "kind": "rigid", "mass": {mc}, "inertia": {ic}, "com": [{half}, 0.0], "angular_velocity": {OMEGA}}},
          {{"name": "coupler", "kind": "beam", "length": {LB}, "elements": {elements}, "theory": "{theory}",
            "density": {RHO}, "youngs_modulus": {E}, "poisson_ratio": {NU}, "shear_factor": 0.8,
            "section": {{"shape": "circular", "diameter": {D}}}, "frame": "pinned-pinned",
            "position": [{L}, 0.0], "velocity": [0.0, {vy}], "angular_velocity": {w2}}}],
        "joints": [
          {{"kind": "revolute", "a": {{"body": "ground"}}, "b": {{"body": "crank", "point": [0.0, 0.0]}}}},
          {{"kind": "revolute", "a": {{"body": "crank", "point": [{L}, 0.0]}}, "b": {{"body": "coupler", "xi": 0.0}}}},
          {{"kind": "point_on_line", "point": {{"body": "coupler", "xi": 1.0}}, "line": {{"body": "ground"}}}}],
        "drivers": [{{"kind": "angle", "a": {{"body": "crank"}}, "motion": {{"kind": "constant_speed", "speed": {OMEGA}}}}}]
        }}"#,
        ic = mc * L * L / 12.0,
        half = L / 2.0,
        vy = L * OMEGA,
        w2 = -L * OMEGA / LB
    )
}

/// The paper's slider-crank with the coupler as an ANCF cable of `elements` elements.
pub fn ancf_paper_scene(elements: usize, gravity: bool) -> String {
    let mut v: serde_json::Value = serde_json::from_str(&paper_scene("euler-bernoulli", elements, gravity)).expect("paper scene");
    for b in v["bodies"].as_array_mut().expect("bodies") {
        if b["kind"] == "beam" {
            let o = b.as_object_mut().expect("body");
            o.insert("kind".into(), "cable".into());
            for k in ["theory", "strain", "frame", "rotary_inertia", "poisson_ratio", "shear_modulus", "shear_factor"] {
                o.remove(k);
            }
        }
    }
    v.to_string()
}

/// A scene that uses every joint, driver and force kind on rigid bodies and beams, and motions
/// of every kind but the spline (an expression among them; not consistent: for term-by-term
/// checks at random states).
pub fn every_kind_scene() -> String {
    r#"{"gravity": [0.3, -9.81],
      "bodies": [
        {"name": "crank", "kind": "rigid", "mass": 0.3, "inertia": 0.002, "com": [0.05, 0.01]},
        {"name": "coupler", "kind": "beam", "length": 0.4, "elements": 2, "theory": "timoshenko",
         "density": 7800, "youngs_modulus": 2e11, "poisson_ratio": 0.3, "shear_factor": 0.85,
         "section": {"shape": "rectangular", "width": 0.01, "height": 0.02}, "frame": "pinned-pinned", "damping": 1e-4},
        {"name": "slider", "kind": "rigid", "mass": 0.5, "inertia": 0.001},
        {"name": "arm", "kind": "rigid", "mass": 0.2, "inertia": 0.0005, "com": [0.1, 0.0]},
        {"name": "link", "kind": "beam", "length": 0.5, "elements": 3, "theory": "euler-bernoulli",
         "density": 2700, "youngs_modulus": 7e10, "section": {"shape": "custom", "area": 1e-4, "second_moment": 2e-9},
         "frame": "clamped", "rotary_inertia": true}],
      "joints": [
        {"kind": "revolute", "a": {"body": "ground", "point": [0.0, 0.0]}, "b": {"body": "crank", "point": [0.0, 0.0]}},
        {"kind": "revolute", "a": {"body": "crank", "point": [0.1, 0.0]}, "b": {"body": "coupler", "xi": 0.0}},
        {"kind": "point_on_line", "point": {"body": "coupler", "xi": 1.0}, "line": {"body": "ground", "point": [0.0, 0.02], "angle": 0.3}},
        {"kind": "prismatic", "a": {"body": "slider", "point": [0.0, 0.0]}, "b": {"body": "ground", "point": [0.0, -0.1], "angle": 0.1}},
        {"kind": "weld", "a": {"body": "arm", "point": [0.0, 0.0], "angle": 0.2}, "b": {"body": "coupler", "xi": 0.5}},
        {"kind": "point_on_line", "point": {"body": "link", "xi": 1.0}, "line": {"body": "arm", "point": [0.2, 0.0], "angle": 0.5}},
        {"kind": "revolute", "a": {"body": "ground", "point": [0.3, 0.3]}, "b": {"body": "link", "xi": 0.0}},
        {"kind": "prismatic", "a": {"body": "arm", "point": [0.1, 0.0]}, "b": {"body": "link", "xi": 0.4, "angle": 0.1}}],
      "drivers": [
        {"kind": "angle", "a": {"body": "crank"}, "motion": {"kind": "harmonic", "offset": 0.1, "amplitude": 0.5, "frequency": 7.0, "phase": 0.2}},
        {"kind": "coordinate", "point": {"body": "slider", "point": [0.01, 0.0]}, "axis": "x", "motion": {"kind": "polynomial", "coefficients": [0.1, 0.2, -0.3, 0.4]}},
        {"kind": "angle", "a": {"body": "link", "xi": 0.6}, "b": {"body": "arm", "angle": 0.1}, "motion": {"kind": "constant_speed", "initial": 0.2, "speed": 3.0}},
        {"kind": "coordinate", "point": {"body": "coupler", "xi": 0.25}, "axis": "y", "motion": {"kind": "expression", "expression": "0.01*sin(30*t) + 0.002*t^2/(1 + t)"}}],
      "forces": [
        {"kind": "point_force", "point": {"body": "coupler", "xi": 0.3}, "force": [1.0, -2.0]},
        {"kind": "torque", "frame": {"body": "link", "xi": 0.7}, "torque": 0.4},
        {"kind": "torque", "frame": {"body": "crank"}, "torque": -0.1},
        {"kind": "spring_damper", "a": {"body": "arm", "point": [0.15, 0.02]}, "b": {"body": "slider", "point": [0.0, 0.01]}, "stiffness": 300.0, "damping": 2.0, "rest_length": 0.05}]
    }"#
    .to_string()
}

/// Deterministic pseudo-random numbers in [-1, 1).
pub struct Lcg(pub u64);
impl Lcg {
    #[allow(clippy::should_implement_trait)] // an infinite generator, not an Iterator
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// A random state: reference coordinates O(1) (angles in [-pi, pi]), elastic coordinates
/// small (so the beams stay in their linear range), rates O(10).
pub fn random_state(model: &Model, rng: &mut Lcg) -> (Vec<f64>, Vec<f64>) {
    let (mut q, mut qd) = (vec![0.0; model.n], vec![0.0; model.n]);
    for b in &model.bodies {
        let o = b.offset;
        if let ukflex::body::BodyKind::Cable(_) = b.kind {
            // nodal positions and slopes: the straight initial guess, moved and deformed a
            // little (slopes stay near their direction: marker angles are measured from it)
            for j in 0..b.n_coords {
                let i = o + j;
                let slope = j % 4 >= 2;
                q[i] = model.q0[i] + if slope { 0.05 } else { 0.02 } * rng.next();
                qd[i] = if slope { 5.0 } else { 2.0 } * rng.next();
            }
            continue;
        }
        let elastic = b.elastic_range();
        for j in 0..b.n_coords {
            let i = o + j;
            if elastic.contains(&i) {
                q[i] = 1e-3 * rng.next();
                qd[i] = 0.5 * rng.next();
            } else if j == 2 {
                // the frame angle of a rigid body or a beam
                q[i] = std::f64::consts::PI * rng.next();
                qd[i] = 20.0 * rng.next();
            } else {
                q[i] = 0.3 * rng.next();
                qd[i] = 2.0 * rng.next();
            }
        }
    }
    (q, qd)
}

/// Point masses and distance constraints with every other kind: a particle on a massless rod
/// to the ground, a second one on a rod to a beam point, pinned to a rigid arm and on a line.
pub fn point_mass_scene() -> String {
    r#"{
      "gravity": [0.3, -9.81],
      "bodies": [
        {"name": "bob", "kind": "point_mass", "mass": 0.7, "position": [0.4, -0.3]},
        {"name": "arm", "kind": "rigid", "mass": 0.3, "inertia": 0.002, "com": [0.1, 0.01]},
        {"name": "beam", "kind": "beam", "length": 0.4, "elements": 2, "theory": "euler-bernoulli",
         "density": 7800.0, "youngs_modulus": 2e11, "section": {"shape": "circular", "diameter": 0.01},
         "frame": "pinned-pinned", "position": [0.2, 0.1]},
        {"name": "bead", "kind": "point_mass", "mass": 0.2, "position": [0.5, 0.2]}],
      "joints": [
        {"kind": "distance", "a": {"body": "ground", "point": [0.0, 0.0]}, "b": {"body": "bob"}, "length": 0.5},
        {"kind": "distance", "a": {"body": "beam", "xi": 0.7}, "b": {"body": "bead"}},
        {"kind": "revolute", "a": {"body": "arm", "point": [0.2, 0.0]}, "b": {"body": "bob"}},
        {"kind": "point_on_line", "point": {"body": "bead"}, "line": {"body": "arm", "point": [0.0, 0.05], "angle": 0.3}},
        {"kind": "point_on_line", "point": {"body": "beam", "xi": 1.0}, "line": {"body": "bob", "angle": 0.2}},
        {"kind": "distance", "a": {"body": "beam", "xi": 0.0}, "b": {"body": "arm", "point": [0.05, 0.02]}, "length": 0.3}],
      "drivers": [
        {"kind": "coordinate", "point": {"body": "bead"}, "axis": "y", "motion": {"kind": "harmonic", "amplitude": 0.01, "frequency": 5.0}}],
      "forces": [
        {"kind": "point_force", "point": {"body": "bob"}, "force": [1.0, 0.5]},
        {"kind": "spring_damper", "a": {"body": "bead"}, "b": {"body": "ground", "point": [1.0, 0.0]}, "stiffness": 50.0, "damping": 0.5}]
    }"#
    .to_string()
}

/// ANCF cables with every joint, driver and force kind attached to cable markers (as point, as
/// line, as oriented frame), gravity and strain-rate damping (not consistent: for term-by-term
/// checks at random states).
pub fn ancf_scene() -> String {
    r#"{"gravity": [0.4, -9.81],
      "bodies": [
        {"name": "crank", "kind": "rigid", "mass": 0.3, "inertia": 0.002, "com": [0.05, 0.01]},
        {"name": "cable", "kind": "cable", "length": 0.4, "elements": 3, "density": 7800, "youngs_modulus": 2e11, "section": {"shape": "circular", "diameter": 0.01},
         "damping": 1e-4, "position": [0.1, 0.0], "angle": 0.2, "velocity": [0.1, 0.3], "angular_velocity": 1.5},
        {"name": "slider", "kind": "rigid", "mass": 0.5, "inertia": 0.001, "position": [0.3, 0.1]},
        {"name": "rope", "kind": "cable", "length": 0.3, "elements": 2, "density": 2700, "youngs_modulus": 7e10, "section": {"shape": "rectangular", "width": 0.01, "height": 0.004},
         "position": [0.3, 0.3], "angle": 2.5},
        {"name": "bob", "kind": "point_mass", "mass": 0.2, "position": [0.1, 0.5]}],
      "joints": [
        {"kind": "revolute", "a": {"body": "ground", "point": [0.0, 0.0]}, "b": {"body": "crank", "point": [0.0, 0.0]}},
        {"kind": "revolute", "a": {"body": "crank", "point": [0.1, 0.0]}, "b": {"body": "cable", "xi": 0.0}},
        {"kind": "point_on_line", "point": {"body": "cable", "xi": 1.0}, "line": {"body": "ground", "point": [0.0, 0.02], "angle": 0.3}},
        {"kind": "prismatic", "a": {"body": "slider", "point": [0.0, 0.0]}, "b": {"body": "cable", "xi": 0.5, "angle": 0.1}},
        {"kind": "weld", "a": {"body": "rope", "xi": 0.0, "angle": 0.2}, "b": {"body": "slider", "point": [0.01, 0.0]}},
        {"kind": "point_on_line", "point": {"body": "bob"}, "line": {"body": "rope", "xi": 0.7, "angle": -0.4}},
        {"kind": "distance", "a": {"body": "rope", "xi": 1.0}, "b": {"body": "bob"}, "length": 0.1},
        {"kind": "weld", "a": {"body": "cable", "xi": 0.25}, "b": {"body": "rope", "xi": 0.4}}],
      "drivers": [
        {"kind": "angle", "a": {"body": "cable", "xi": 0.6}, "b": {"body": "crank", "angle": 0.1}, "motion": {"kind": "harmonic", "offset": 0.1, "amplitude": 0.5, "frequency": 7.0}},
        {"kind": "coordinate", "point": {"body": "rope", "xi": 0.5}, "axis": "y", "motion": {"kind": "polynomial", "coefficients": [0.1, 0.2, -0.3]}}],
      "forces": [
        {"kind": "point_force", "point": {"body": "cable", "xi": 0.3}, "force": [1.0, -2.0]},
        {"kind": "torque", "frame": {"body": "rope", "xi": 1.0}, "torque": 0.4},
        {"kind": "spring_damper", "a": {"body": "cable", "xi": 0.8}, "b": {"body": "ground", "point": [0.5, 0.2]}, "stiffness": 300.0, "damping": 2.0}]
    }"#
    .to_string()
}

pub fn build(json: &str) -> (Model, Data) {
    let model = Model::from_json(json).expect("scene builds");
    let data = Data::new(&model);
    (model, data)
}

pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// K rigid links of length 0.2 m hanging in a chain from a ground pivot, laid out
/// horizontally at rest; gravity -Y. n = 3K coordinates, m = 2K constraint rows.
pub fn chain_scene(k: usize) -> String {
    let len = 0.2;
    let mut bodies = Vec::new();
    let mut joints = vec![format!(
        r#"{{"kind": "revolute", "a": {{"body": "ground"}}, "b": {{"body": "link0", "point": [0.0, 0.0]}}}}"#
    )];
    for i in 0..k {
        bodies.push(format!(
            r#"{{"name": "link{i}", "kind": "rigid", "mass": 1.0, "inertia": {inertia}, "com": [{half}, 0.0], "position": [{x}, 0.0]}}"#,
            inertia = len * len / 12.0,
            half = len / 2.0,
            x = i as f64 * len
        ));
        if i > 0 {
            joints.push(format!(
                r#"{{"kind": "revolute", "a": {{"body": "link{p}", "point": [{len}, 0.0]}}, "b": {{"body": "link{i}", "point": [0.0, 0.0]}}}}"#,
                p = i - 1
            ));
        }
    }
    format!(r#"{{"gravity": [0.0, -9.81], "bodies": [{}], "joints": [{}]}}"#, bodies.join(","), joints.join(","))
}
