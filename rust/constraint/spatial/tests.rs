//! Finite-difference checks of every spatial joint kind and both drivers: `A` against central
//! differences of `Phi` in `q`, `Phi_t` against differences in `t`, and `gamma` against the
//! derivative of `A qd + Phi_t` along `(qd, 1)` (`gamma = -(A qd)_q qd - 2 Phi_qt qd - Phi_tt`),
//! at random non-unit Euler parameters, body-body, ground-body and body-point-mass.

use crate::data::Data;
use crate::dynamics;
use crate::model::Model;

fn scene(joint: &str, a: &str, b: &str, extra: &str) -> String {
    format!(
        r#"{{"dim": 3, "gravity": [0, 0, -9.81],
        "bodies": [
          {{"kind": "rigid3", "name": "b1", "mass": 1.3, "inertia": [[0.1, 0.01, 0], [0.01, 0.2, 0.02], [0, 0.02, 0.15]],
            "com": [0.05, -0.02, 0.1], "position": [0.1, 0.2, 0.3], "orientation": [0.9, 0.1, -0.3, 0.2]}},
          {{"kind": "rigid3", "name": "b2", "mass": 0.7, "inertia": [[0.05, 0, 0], [0, 0.06, 0], [0, 0, 0.07]],
            "position": [0.4, -0.1, 0.2], "orientation": [0.3, 0.8, 0.2, -0.4]}},
          {{"kind": "point3", "name": "pm", "mass": 0.5, "position": [0.3, 0.3, -0.2]}}
        ],
        "joints": [{{"kind": "{joint}", "name": "j", "a": {a}, "b": {b}{extra}}}]}}"#
    )
}

const MA: &str = r#"{"body": "b1", "point": [0.2, -0.1, 0.3], "z": [0.3, 1.0, -0.2], "x": [1, 0, 0]}"#;
const MB: &str = r#"{"body": "b2", "point": [-0.1, 0.25, 0.05], "z": [-0.5, 0.2, 1.0]}"#;
const MG: &str = r#"{"body": "ground", "point": [0.3, -0.2, 0.1], "z": [0.2, 0.1, 1.0], "x": [0, 1, 0]}"#;
const MP: &str = r#"{"body": "pm"}"#;

/// A deterministic pseudo-random perturbation in [-1, 1].
fn rnd(k: usize) -> f64 {
    let x = ((k as f64 + 1.0) * 12.9898).sin() * 43758.5453;
    2.0 * (x - x.floor()) - 1.0
}

fn check(text: &str, what: &str) {
    let model = Model::from_json(text).unwrap_or_else(|e| panic!("{what}: {e}"));
    let mut data = Data::new(&model);
    data.ensure_dense_jac().unwrap();
    let (n, m) = (model.n, model.m);
    let mut q = model.q0.clone();
    for (k, x) in q.iter_mut().enumerate() {
        *x += 0.1 * rnd(k); // non-unit p on purpose
    }
    let qd: Vec<f64> = (0..n).map(|k| rnd(100 + k)).collect();
    let t = 0.37;
    let eval = |data: &mut Data, t: f64, q: &[f64], qd: &[f64]| {
        dynamics::constraints(&model, data, t, q, qd, true);
        (data.phi.clone(), data.dense_jac().to_vec(), data.phi_t.clone(), data.gamma.clone())
    };
    let (_phi, a, phi_t, gamma) = eval(&mut data, t, &q, &qd);
    let h = 1e-6;
    let scale = a.iter().fold(1.0f64, |s, x| s.max(x.abs()));
    for j in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        let (pp, ..) = eval(&mut data, t, &qp, &qd);
        let (pm, ..) = eval(&mut data, t, &qm, &qd);
        for i in 0..m {
            let fd = (pp[i] - pm[i]) / (2.0 * h);
            assert!((fd - a[i * n + j]).abs() < 1e-7 * scale, "{what}: A[{i}][{j}] = {} vs {fd}", a[i * n + j]);
        }
    }
    let (pp, ..) = eval(&mut data, t + h, &q, &qd);
    let (pm, ..) = eval(&mut data, t - h, &q, &qd);
    for i in 0..m {
        let fd = (pp[i] - pm[i]) / (2.0 * h);
        assert!((fd - phi_t[i]).abs() < 1e-7 * scale.max(phi_t[i].abs()), "{what}: Phi_t[{i}] = {} vs {fd}", phi_t[i]);
    }
    // v(s) = A(q + s qd) qd + Phi_t(t + s): dv/ds = (A qd)_q qd + 2 Phi_qt qd + Phi_tt = -gamma
    let vel = |data: &mut Data, s: f64| {
        let qs: Vec<f64> = q.iter().zip(&qd).map(|(x, v)| x + s * v).collect();
        let (_, a, pt, _) = eval(data, t + s, &qs, &qd);
        (0..m).map(|i| (0..n).map(|j| a[i * n + j] * qd[j]).sum::<f64>() + pt[i]).collect::<Vec<f64>>()
    };
    let (vp, vm) = (vel(&mut data, h), vel(&mut data, -h));
    for i in 0..m {
        let fd = -(vp[i] - vm[i]) / (2.0 * h);
        assert!((fd - gamma[i]).abs() < 1e-6 * (1.0 + gamma[i].abs()), "{what}: gamma[{i}] = {} vs {fd}", gamma[i]);
    }
}

#[test]
fn every_joint_kind_has_consistent_jacobian_phi_t_and_gamma() {
    let kinds = ["spherical", "revolute", "prismatic", "cylindrical", "universal", "fixed", "planar", "distance", "point_on_line", "point_on_plane"];
    for kind in kinds {
        for (a, b, what) in [(MA, MB, "body-body"), (MG, MB, "ground-body"), (MA, MG, "body-ground")] {
            check(&scene(kind, a, b, ""), &format!("{kind} {what}"));
        }
    }
    for kind in ["spherical", "distance", "point_on_line", "point_on_plane"] {
        check(&scene(kind, MA, MP, ""), &format!("{kind} body-point mass"));
    }
    check(&scene("distance", MA, MB, r#", "length": 0.7"#), "distance with a length");
}

#[test]
fn drivers_have_consistent_jacobian_phi_t_and_gamma() {
    let motions = [
        r#"{"kind": "constant_speed", "initial": 0.3, "speed": 2.0}"#,
        r#"{"kind": "polynomial", "coefficients": [0.1, 0.5, -0.7, 0.3]}"#,
        r#"{"kind": "harmonic", "offset": 0.2, "amplitude": 0.4, "frequency": 3.0, "phase": 0.1}"#,
        r#"{"kind": "expression", "expression": "0.5*sin(2*t) + t^2"}"#,
        r#"{"kind": "spline", "times": [0, 0.5, 1], "values": [0, 0.4, 0.1]}"#,
    ];
    for kind in ["rotation", "translation"] {
        for motion in motions {
            for (a, b) in [(MA, MB), (MG, MB)] {
                let text = scene("spherical", MA, MP, "").replace(
                    r#""joints": ["#,
                    &format!(r#""drivers": [{{"kind": "{kind}", "a": {a}, "b": {b}, "motion": {motion}}}], "joints": ["#),
                );
                check(&text, &format!("{kind} driver, {motion}"));
            }
        }
    }
}

#[test]
fn row_counts_and_zero_residual_when_frames_coincide() {
    let rows = [("spherical", 3), ("revolute", 5), ("prismatic", 5), ("cylindrical", 4), ("universal", 4), ("fixed", 6), ("planar", 3), ("distance", 1), ("point_on_line", 2), ("point_on_plane", 1)];
    for (kind, r) in rows {
        // marker b on b2 placed and oriented where marker a's frame is: b2 at b1's pose
        let text = scene(kind, MA, &MA.replace("b1", "b2"), if kind == "distance" { r#", "length": 1e-4"# } else { "" })
            .replace(r#""position": [0.4, -0.1, 0.2], "orientation": [0.3, 0.8, 0.2, -0.4]"#, r#""com": [0.05, -0.02, 0.1], "position": [0.1, 0.2, 0.3], "orientation": [0.9, 0.1, -0.3, 0.2]"#);
        let model = Model::from_json(&text).unwrap();
        // joint rows + 2 normalization rows
        assert_eq!(model.m, r + 2, "{kind}");
        let mut data = Data::new(&model);
        dynamics::constraints(&model, &mut data, 0.0, &model.q0, &model.qd0, true);
        let tol = if kind == "distance" { 1e-6 } else { 1e-14 };
        for i in 0..model.m {
            assert!(data.phi[i].abs() < tol, "{kind}: Phi[{i}] = {}", data.phi[i]);
        }
    }
}
