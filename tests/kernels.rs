//! Kernel checks at random states: M symmetric positive definite, the quadratic-velocity
//! vector against its definition (eq. 40) by central differences, A against differences of
//! Phi, gamma against second differences of Phi along (qd, 1), and the UK acceleration against
//! the augmented saddle-point system (eq. 42).

mod common;
use common::*;
use nalgebra::{DMatrix, DVector};
use ukflex::{dynamics, uk, Data, Model};

fn scenes() -> Vec<(String, String)> {
    vec![
        ("paper timoshenko N=1".into(), paper_scene("timoshenko", 1, true)),
        ("paper euler-bernoulli N=3".into(), paper_scene("euler-bernoulli", 3, false)),
        ("paper timoshenko N=8".into(), paper_scene("timoshenko", 8, true)),
        ("every kind".into(), every_kind_scene()),
        ("point masses and distances".into(), point_mass_scene()),
        ("ANCF cables with every kind".into(), ancf_scene()),
    ]
}

fn mass(model: &Model, data: &mut Data, q: &[f64]) -> DMatrix<f64> {
    let zeros = vec![0.0; model.n];
    dynamics::mass_and_forces(model, data, 0.0, q, &zeros);
    DMatrix::from_row_slice(model.n, model.n, &dynamics::dense_mass(model, data))
}

fn forces(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) -> DVector<f64> {
    dynamics::mass_and_forces(model, data, 0.0, q, qd);
    DVector::from_column_slice(&data.force)
}

fn axpy(q: &[f64], h: f64, d: &[f64]) -> Vec<f64> {
    q.iter().zip(d).map(|(a, b)| a + h * b).collect()
}

#[test]
fn mass_matrix_is_symmetric_positive_definite() {
    for (name, json) in scenes() {
        let (model, mut data) = build(&json);
        let mut rng = Lcg(7);
        for _ in 0..5 {
            let (q, _) = random_state(&model, &mut rng);
            let m = mass(&model, &mut data, &q);
            let asym = (&m - m.transpose()).abs().max();
            assert!(asym <= 1e-14 * m.abs().max(), "{name}: asymmetry {asym:e}");
            let eig = m.clone().symmetric_eigen();
            assert!(eig.eigenvalues.min() > 0.0, "{name}: eigenvalue {:e}", eig.eigenvalues.min());
        }
    }
}

/// The block product `M x` (Newton residuals of the implicit methods) equals the dense mass
/// matrix times `x` for every body kind.
#[test]
fn mass_times_equals_the_dense_mass_product() {
    for (name, json) in scenes() {
        let (model, mut data) = build(&json);
        let mut rng = Lcg(11);
        for _ in 0..3 {
            let (q, x) = random_state(&model, &mut rng);
            let m = mass(&model, &mut data, &q);
            let want = &m * DVector::from_column_slice(&x);
            let mut got = vec![f64::NAN; model.n];
            dynamics::mass_times(&model, &data, &x, &mut got);
            let err = (DVector::from_column_slice(&got) - &want).abs().max();
            assert!(err <= 1e-13 * want.abs().max().max(1e-300), "{name}: |M x - dense| = {err:e}");
        }
    }
}

/// `Q_v = -Mdot qd + 1/2 d/dq (qd^T M qd)`: the velocity-quadratic part of Q is
/// `Q(q, qd) - Q(q, 0)` when no damping acts (damping is linear in qd; removed by symmetry).
#[test]
fn quadratic_velocity_vector_matches_eq_40() {
    for (name, json) in scenes() {
        let (model, mut data) = build(&json);
        let mut rng = Lcg(11);
        for _ in 0..4 {
            let (q, qd) = random_state(&model, &mut rng);
            let n = model.n;
            // quadratic part: (Q(qd) + Q(-qd))/2 - Q(0) removes terms linear in qd (damping)
            let neg: Vec<f64> = qd.iter().map(|v| -v).collect();
            let zero = vec![0.0; n];
            let qv_core = (forces(&model, &mut data, &q, &qd) + forces(&model, &mut data, &q, &neg)) * 0.5 - forces(&model, &mut data, &q, &zero);
            let h = 1e-6;
            let qdv = DVector::from_column_slice(&qd);
            // Mdot qd = d/ds M(q + s qd) qd
            let mdot = (mass(&model, &mut data, &axpy(&q, h, &qd)) - mass(&model, &mut data, &axpy(&q, -h, &qd))) / (2.0 * h);
            let mut qv_fd = -(mdot * &qdv);
            for i in 0..n {
                let mut e = vec![0.0; n];
                e[i] = 1.0;
                let tp = (mass(&model, &mut data, &axpy(&q, h, &e)) * &qdv).dot(&qdv);
                let tm = (mass(&model, &mut data, &axpy(&q, -h, &e)) * &qdv).dot(&qdv);
                qv_fd[i] += 0.5 * (tp - tm) / (2.0 * h);
            }
            let scale = qv_fd.abs().max().max(1e-3);
            let err = (&qv_core - &qv_fd).abs().max() / scale;
            assert!(err < 1e-6, "{name}: Qv mismatch {err:e}\ncore {qv_core}\nfd {qv_fd}");
        }
    }
}

#[test]
fn jacobian_matches_differences_of_phi_and_gamma_second_differences() {
    for (name, json) in scenes() {
        let (model, mut data) = build(&json);
        data.ensure_dense_jac().unwrap(); // the dense m x n copy of A (the sparse path keeps none)
        let (n, m) = (model.n, model.m);
        let mut rng = Lcg(3);
        for _ in 0..4 {
            let (q, qd) = random_state(&model, &mut rng);
            let t = 0.37;
            let phi_at = |data: &mut Data, t: f64, q: &[f64]| -> Vec<f64> {
                dynamics::constraints(&model, data, t, q, &vec![0.0; n], true);
                data.phi.clone()
            };
            dynamics::constraints(&model, &mut data, t, &q, &qd, true);
            let (a, gamma, phi_t) = (data.dense_jac().to_vec(), data.gamma.clone(), data.phi_t.clone());
            let h = 1e-6;
            for j in 0..n {
                let mut e = vec![0.0; n];
                e[j] = 1.0;
                let (pp, pm) = (phi_at(&mut data, t, &axpy(&q, h, &e)), phi_at(&mut data, t, &axpy(&q, -h, &e)));
                for i in 0..m {
                    let fd = (pp[i] - pm[i]) / (2.0 * h);
                    assert!((a[i * n + j] - fd).abs() < 1e-7 * (1.0 + fd.abs()), "{name}: A[{i},{j}] = {} vs fd {fd}", a[i * n + j]);
                }
            }
            let (pp, pm) = (phi_at(&mut data, t + h, &q), phi_at(&mut data, t - h, &q));
            for i in 0..m {
                let fd = (pp[i] - pm[i]) / (2.0 * h);
                assert!((phi_t[i] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "{name}: Phi_t[{i}] {} vs {fd}", phi_t[i]);
            }
            // d^2/ds^2 Phi(q + s qd, t + s) = -gamma
            let hs = 1e-4;
            let (p0, pp, pm) = (phi_at(&mut data, t, &q), phi_at(&mut data, t + hs, &axpy(&q, hs, &qd)), phi_at(&mut data, t - hs, &axpy(&q, -hs, &qd)));
            for i in 0..m {
                let fd = -(pp[i] - 2.0 * p0[i] + pm[i]) / (hs * hs);
                assert!((gamma[i] - fd).abs() < 1e-4 * (1.0 + fd.abs()), "{name}: gamma[{i}] = {} vs second difference {fd}", gamma[i]);
            }
        }
    }
}

#[test]
fn uk_satisfies_constraints_and_equals_augmented_solution() {
    for (name, json) in scenes() {
        let (model, mut data) = build(&json);
        data.ensure_dense_jac().unwrap(); // the dense m x n copy of A (the sparse path keeps none)
        let (n, m) = (model.n, model.m);
        let mut rng = Lcg(5);
        for _ in 0..5 {
            let (q, qd) = random_state(&model, &mut rng);
            let t = 0.11;
            uk::acceleration(&model, &mut data, t, &q, &qd).unwrap();
            assert_eq!(data.rank_info.rank, m, "{name}: constraints should be independent here");
            let qdd = DVector::from_column_slice(&data.qdd);
            let lam = DVector::from_column_slice(&data.lambda);
            let a = DMatrix::from_row_slice(m, n, data.dense_jac());
            let b = DVector::from_column_slice(&data.gamma);
            let qf = DVector::from_column_slice(&data.force);
            let mm = mass(&model, &mut data, &q);
            // A qdd = b
            // backward-error scale: |A| |qdd| (the elastic accelerations at random states are
            // O(1e6) while b is O(1e2), so |b| alone would not measure the achievable precision)
            let scale = b.abs().max().max(a.abs().max() * qdd.abs().max());
            let res = (&a * &qdd - &b).abs().max() / scale;
            assert!(res < 1e-12, "{name}: |A qdd - b| / (|A| |qdd|) = {res:e}");
            // augmented system [[M, A^T], [A, 0]] [qdd; lambda] = [Q; b]   (eq. 42)
            let mut k = DMatrix::zeros(n + m, n + m);
            k.view_mut((0, 0), (n, n)).copy_from(&mm);
            k.view_mut((0, n), (n, m)).copy_from(&a.transpose());
            k.view_mut((n, 0), (m, n)).copy_from(&a);
            let mut rhs = DVector::zeros(n + m);
            rhs.rows_mut(0, n).copy_from(&qf);
            rhs.rows_mut(n, m).copy_from(&b);
            let sol = k.lu().solve(&rhs).expect("augmented system solvable");
            let e_qdd = (&qdd - sol.rows(0, n)).abs().max() / qdd.abs().max();
            let e_lam = (&lam - sol.rows(n, m)).abs().max() / lam.abs().max();
            assert!(e_qdd < 1e-8, "{name}: qdd vs augmented {e_qdd:e}");
            assert!(e_lam < 1e-8, "{name}: lambda vs augmented {e_lam:e}");
        }
    }
}

#[test]
fn redundant_constraint_is_detected_by_rank_and_still_satisfied() {
    // the paper scene with its crank pivot declared twice: consistent but dependent rows
    let json = paper_scene("timoshenko", 2, true).replace(
        r#""joints": ["#,
        r#""joints": [{"kind": "revolute", "a": {"body": "ground"}, "b": {"body": "crank", "point": [0.0, 0.0]}},"#,
    );
    let (model, mut data) = build(&json);
    let (q, qd) = (model.q0.clone(), model.qd0.clone());
    uk::acceleration(&model, &mut data, 0.0, &q, &qd).unwrap();
    assert_eq!(model.m, 8);
    assert_eq!(data.rank_info.rank, 6);
    let (single, mut d1) = build(&paper_scene("timoshenko", 2, true));
    uk::acceleration(&single, &mut d1, 0.0, &q, &qd).unwrap();
    let err = data.qdd.iter().zip(&d1.qdd).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / max_abs(&d1.qdd);
    assert!(err < 1e-9, "redundant vs single declaration: {err:e}");
}

#[test]
fn projection_restores_consistency_and_leaves_consistent_states_alone() {
    let (model, mut data) = build(&paper_scene("timoshenko", 4, true));
    let (mut q, mut qd) = (model.q0.clone(), model.qd0.clone());
    let (q_ref, qd_ref) = (q.clone(), qd.clone());
    let rep = ukflex::correct::project(&model, &mut data, 0.0, &mut q, &mut qd, 1e-13, 10).unwrap();
    assert_eq!(rep.iterations, 0);
    assert!(max_abs(&q.iter().zip(&q_ref).map(|(a, b)| a - b).collect::<Vec<_>>()) < 1e-15);
    assert!(max_abs(&qd.iter().zip(&qd_ref).map(|(a, b)| a - b).collect::<Vec<_>>()) < 1e-9);
    let mut rng = Lcg(9);
    for i in 0..model.n {
        q[i] += 1e-3 * rng.next() * if i < 6 { 1.0 } else { 1e-3 };
        qd[i] += 0.1 * rng.next();
    }
    let rep = ukflex::correct::project(&model, &mut data, 0.2, &mut q, &mut qd, 1e-13, 20).unwrap();
    assert!(rep.position_residual <= 1e-13, "{rep:?}");
    assert!(rep.velocity_residual <= 1e-9, "{rep:?}");
    assert!(rep.iterations >= 2 && rep.iterations <= 6, "Newton should converge quadratically: {rep:?}");
}

#[test]
fn baumgarte_modifies_the_acceleration_right_hand_side() {
    let (model, mut data) = build(&paper_scene("euler-bernoulli", 2, true));
    data.ensure_dense_jac().unwrap(); // the dense m x n copy of A (the sparse path keeps none)
    let n = model.n;
    let mut rng = Lcg(21);
    let (q, qd) = random_state(&model, &mut rng);
    let (alpha, beta) = (5.0, 7.0);
    data.stabilization = ukflex::data::Stabilization::Baumgarte { alpha, beta };
    uk::acceleration(&model, &mut data, 0.3, &q, &qd).unwrap();
    let qdd = data.qdd.clone();
    dynamics::constraints(&model, &mut data, 0.3, &q, &qd, true);
    let a = data.dense_jac().to_vec();
    for i in 0..model.m {
        let row = &a[i * n..(i + 1) * n];
        let vel: f64 = row.iter().zip(&qd).map(|(a, b)| a * b).sum::<f64>() + data.phi_t[i];
        let want = data.gamma[i] - 2.0 * alpha * vel - beta * beta * data.phi[i];
        let got: f64 = row.iter().zip(&qdd).map(|(a, b)| a * b).sum();
        let scale = max_abs(row) * max_abs(&qdd) + want.abs();
        assert!((got - want).abs() < 1e-12 * scale, "row {i}: {got} vs {want}");
    }
}
