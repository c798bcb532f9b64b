//! The ANCF cable kind (rust/body/ancf_cable.rs) at the element level: elastic forces are the
//! gradient of the strain energy, the analytic tangent stiffness and damping matrix match
//! central differences, rigid motions are strain free and the linear stiffness has no spurious
//! zero-energy modes, the constant factor reproduces the mass matrix, gravity and the first
//! moment of mass are consistent.

mod common;
use common::*;
use nalgebra::DMatrix;
use ukflex::body::ancf_cable::{AncfCable, AncfCableData, HB};
use ukflex::body::BodyKind;
use ukflex::linalg::Banded;
use ukflex::Model;

/// A cable alone (no joints): `damping` beta [s], `elements` N.
fn cable_scene(elements: usize, damping: f64, gravity: bool) -> String {
    format!(
        r#"{{"gravity": {g}, "bodies": [{{"name": "c", "kind": "cable", "length": 0.5, "elements": {elements},
        "density": 7800, "youngs_modulus": 2e11, "section": {{"shape": "circular", "diameter": 0.01}},
        "damping": {damping}, "position": [0.2, -0.1], "angle": 0.7}}]}}"#,
        g = if gravity { "[0.3, -9.81]" } else { "null" }
    )
}

fn cable(model: &Model) -> &AncfCable {
    match &model.bodies[0].kind {
        BodyKind::Cable(c) => c,
        _ => panic!("not a cable"),
    }
}

/// A deformed state: the straight guess moved by `amp` (positions) and `10 amp` (slopes).
fn deformed(model: &Model, rng: &mut Lcg, amp: f64) -> Vec<f64> {
    model.q0.iter().enumerate().map(|(i, q)| q + if i % 4 >= 2 { 10.0 * amp } else { amp } * rng.next()).collect()
}

fn forces(c: &AncfCable, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let mut f = vec![0.0; q.len()];
    c.mass_and_forces(&mut AncfCableData, q, qd, None, &mut f);
    f
}

fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

#[test]
fn elastic_force_is_minus_the_gradient_of_the_strain_energy() {
    let (model, _) = build(&cable_scene(4, 0.0, false));
    let c = cable(&model);
    let mut rng = Lcg(3);
    for _ in 0..3 {
        let q = deformed(&model, &mut rng, 0.01);
        let zero = vec![0.0; q.len()];
        let f = forces(c, &q, &zero);
        let h = 1e-7;
        let grad: Vec<f64> = (0..q.len())
            .map(|i| {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[i] += h;
                qm[i] -= h;
                -(c.strain_energy(&qp) - c.strain_energy(&qm)) / (2.0 * h)
            })
            .collect();
        let err = rel_err(&f, &grad);
        assert!(err < 1e-6, "force vs -dU/dq: {err:e}");
    }
}

#[test]
fn tangent_stiffness_and_damping_matrix_match_central_differences() {
    let (model, _) = build(&cable_scene(3, 2e-3, false));
    let c = cable(&model);
    let n = model.n;
    let mut rng = Lcg(5);
    for amp in [0.0, 1e-3, 0.02] {
        let q = deformed(&model, &mut rng, amp);
        let zero = vec![0.0; n];
        let mut kt = Banded::zeros(n, HB);
        c.add_tangent_stiffness(&q, &mut kt);
        let mut cd = Banded::zeros(n, HB);
        c.add_damping_matrix(&q, &mut cd);
        let (kt, cd) = (kt.to_dense(), cd.to_dense());
        // -dQ/dq at qd = 0 (damping forces vanish there), -dQ/dqd
        let (mut k_fd, mut c_fd) = (vec![0.0; n * n], vec![0.0; n * n]);
        for j in 0..n {
            let h = 1e-6 * (1.0 + q[j].abs());
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[j] += h;
            qm[j] -= h;
            let (fp, fm) = (forces(c, &qp, &zero), forces(c, &qm, &zero));
            let mut vp = zero.clone();
            vp[j] = 1.0;
            let mut vm = zero.clone();
            vm[j] = -1.0;
            // damping forces are linear in qd: exact difference with unit steps
            let (gp, gm) = (forces(c, &q, &vp), forces(c, &q, &vm));
            for i in 0..n {
                k_fd[i * n + j] = -(fp[i] - fm[i]) / (2.0 * h);
                c_fd[i * n + j] = -(gp[i] - gm[i]) / 2.0;
            }
        }
        let ek = rel_err(&kt, &k_fd);
        let ec = rel_err(&cd, &c_fd);
        assert!(ek <= 1e-6, "amp {amp}: tangent stiffness vs differences {ek:e}");
        assert!(ec <= 1e-9, "amp {amp}: damping matrix vs differences {ec:e}");
        let asym = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max((kt[i * n + j] - kt[j * n + i]).abs()));
        assert!(asym <= 1e-12 * kt.iter().fold(0.0f64, |m, x| m.max(x.abs())), "K_t not symmetric: {asym:e}");
    }
}

#[test]
fn rigid_motions_are_strain_free_and_the_linear_stiffness_has_only_three_zero_modes() {
    for n_el in [1, 2, 5] {
        let (model, _) = build(&cable_scene(n_el, 0.0, false));
        let c = cable(&model);
        let n = model.n;
        // a rotated and translated straight cable: no strain, no force
        let (s, co) = (2.1f64).sin_cos();
        let mut q = vec![0.0; n];
        for j in 0..=n_el {
            let x = j as f64 * c.element_length;
            q[4 * j..4 * j + 4].copy_from_slice(&[1.0 + x * co, -0.5 + x * s, co, s]);
        }
        assert!(c.strain_energy(&q).abs() < 1e-20, "N={n_el}: strain energy of a rigid motion");
        let f = forces(c, &q, &vec![0.0; n]);
        assert!(max_abs(&f) < 1e-6, "N={n_el}: elastic force of a rigid motion {:e}", max_abs(&f));
        let mut kt = Banded::zeros(n, HB);
        c.add_tangent_stiffness(&q, &mut kt);
        let eig = DMatrix::from_row_slice(n, n, &kt.to_dense()).symmetric_eigen();
        let mut ev: Vec<f64> = eig.eigenvalues.iter().copied().collect();
        ev.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let top = ev[n - 1];
        // two translations and the rotation; every other mode (axial, bending, slope stretch)
        // is stiff: the reduced axial rule leaves no hourglass mode
        assert!(ev[..3].iter().all(|v| v.abs() < 1e-10 * top), "N={n_el}: rigid modes {:?}", &ev[..3]);
        assert!(ev[3] > 1e-7 * top, "N={n_el}: a spurious zero-energy mode, eigenvalue {:e} (largest {top:e})", ev[3]);
    }
}

#[test]
fn constant_factor_reproduces_the_mass_matrix_and_gravity_is_consistent() {
    let (model, mut data) = build(&cable_scene(4, 0.0, true));
    let c = cable(&model);
    let n = model.n;
    let zero = vec![0.0; n];
    ukflex::dynamics::mass_and_forces(&model, &mut data, 0.0, &model.q0, &zero);
    let m = ukflex::dynamics::dense_mass(&model, &data);
    // F^-1 M F^-T = I, column by column
    let mut x = DMatrix::from_row_slice(n, n, &m);
    for j in 0..n {
        let mut col: Vec<f64> = x.column(j).iter().copied().collect();
        model.bodies[0].finv(&data.bodies[0], &mut col);
        x.set_column(j, &nalgebra::DVector::from_vec(col));
    }
    let mut y = x.transpose();
    for j in 0..n {
        let mut col: Vec<f64> = y.column(j).iter().copied().collect();
        model.bodies[0].finv(&data.bodies[0], &mut col);
        y.set_column(j, &nalgebra::DVector::from_vec(col));
    }
    let err = (&y - DMatrix::identity(n, n)).abs().max();
    assert!(err < 1e-10, "F^-1 M F^-T - I = {err:e}");
    // finvt is the transpose of finv: <F^-1 a, b> = <a, F^-T b>
    let mut rng = Lcg(8);
    let a: Vec<f64> = (0..n).map(|_| rng.next()).collect();
    let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
    let (mut fa, mut fb) = (a.clone(), b.clone());
    model.bodies[0].finv(&data.bodies[0], &mut fa);
    model.bodies[0].finvt(&data.bodies[0], &mut fb);
    let (l, r): (f64, f64) = (fa.iter().zip(&b).map(|(x, y)| x * y).sum(), a.iter().zip(&fb).map(|(x, y)| x * y).sum());
    assert!((l - r).abs() < 1e-10 * l.abs().max(1.0), "finvt is not the transpose of finv: {l} vs {r}");
    // mass, gravity resultant m g, kinetic energy of a translation 1/2 m v^2
    assert!((c.mass - 7800.0 * std::f64::consts::PI * 1e-4 / 4.0 * 0.5).abs() < 1e-12 * c.mass);
    let g = [0.3, -9.81];
    let fx: f64 = data.force.iter().step_by(2).zip(0..).filter(|(_, i)| i % 2 == 0).map(|(f, _)| f).sum();
    let fy: f64 = data.force.iter().skip(1).step_by(2).zip(0..).filter(|(_, i)| i % 2 == 0).map(|(f, _)| f).sum();
    assert!((fx - c.mass * g[0]).abs() < 1e-12 * c.mass * 9.81 && (fy - c.mass * g[1]).abs() < 1e-12 * c.mass * 9.81, "gravity resultant ({fx}, {fy})");
    let v: Vec<f64> = (0..n).map(|i| if i % 4 == 0 { 2.0 } else if i % 4 == 1 { -1.0 } else { 0.0 }).collect();
    let t = ukflex::dynamics::kinetic_energy(&model, &mut data, &model.q0, &v);
    assert!((t - 0.5 * c.mass * 5.0).abs() < 1e-12 * t, "kinetic energy of a translation {t}");
    // first moment of the straight cable: m times its midpoint
    let r = c.mass_moment(&model.q0);
    let (s, co) = (0.7f64).sin_cos();
    let mid = [0.2 + 0.25 * co, -0.1 + 0.25 * s];
    assert!((r[0] - c.mass * mid[0]).abs() < 1e-13 && (r[1] - c.mass * mid[1]).abs() < 1e-13, "first moment {r:?}");
}
