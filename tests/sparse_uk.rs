//! The sparse UK path (band Cholesky of `A M^-1 A^T` with a full-rank certificate) against the
//! dense certified QR / SVD path: same `qdd` and multipliers on random consistent states of
//! chains, within a small multiple of `cond(B) eps`; a chain with a redundant joint falls back
//! to the dense rank-revealing path and reports the rank; every body and joint kind.

mod common;
use common::*;
use ukflex::uk::Factored;
use ukflex::{uk, Data, Model, UkSolver};

/// A consistent state of `chain_scene(k)`: random link angles and rates, the reference points
/// and their velocities from the joints (link i's origin at link i-1's far end, 0.2 m).
fn chain_state(model: &Model, rng: &mut Lcg) -> (Vec<f64>, Vec<f64>) {
    let len = 0.2;
    let k = model.bodies.len();
    let (mut q, mut qd) = (vec![0.0; 3 * k], vec![0.0; 3 * k]);
    let (mut x, mut y, mut vx, mut vy) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..k {
        let th = -1.5 + 0.8 * rng.next();
        let w = 2.0 * rng.next();
        q[3 * i..3 * i + 3].copy_from_slice(&[x, y, th]);
        qd[3 * i..3 * i + 3].copy_from_slice(&[vx, vy, w]);
        x += len * th.cos();
        y += len * th.sin();
        vx -= len * th.sin() * w;
        vy += len * th.cos() * w;
    }
    (q, qd)
}

fn data(model: &Model, solver: UkSolver) -> Data {
    Data::build(model, solver, u64::MAX).expect("workspace")
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d = a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    d / max_abs(b).max(f64::MIN_POSITIVE)
}

/// `cond(B)` from the dense path's exact singular values.
fn cond_b(model: &Model, dense: &mut Data) -> (f64, usize) {
    let info = uk::exact_rank_info(model, dense).unwrap();
    (info.sigma_max / info.sigma_min_kept, info.rank)
}

#[test]
fn sparse_matches_dense_on_random_consistent_chain_states() {
    let mut rng = Lcg(7);
    for k in [4usize, 16, 64, 200] {
        let model = Model::from_json(&chain_scene(k)).unwrap();
        let (mut sp, mut de) = (data(&model, UkSolver::Sparse), data(&model, UkSolver::Dense));
        assert!(sp.sparse.as_ref().unwrap().hb <= 3, "chain band after RCM: {}", sp.sparse.as_ref().unwrap().hb);
        let mut worst = 0.0f64;
        for _ in 0..5 {
            let (q, qd) = chain_state(&model, &mut rng);
            uk::acceleration(&model, &mut sp, 0.0, &q, &qd).unwrap();
            uk::acceleration(&model, &mut de, 0.0, &q, &qd).unwrap();
            assert_eq!(sp.factored_with, Factored::SparseGram, "K={k}: the certificate must pass on a chain");
            assert_eq!(sp.rank_info.rank, model.m);
            let (cond, rank) = cond_b(&model, &mut de);
            assert_eq!(rank, model.m);
            // the certified lower bound is a lower bound of the exact sigma_min
            let exact = uk::exact_rank_info(&model, &mut de).unwrap();
            assert!(sp.rank_info.sigma_min_kept <= exact.sigma_min_kept * (1.0 + 1e-12));
            assert!(sp.rank_info.sigma_max >= exact.sigma_max * (1.0 - 1e-12));
            let dq = rel_diff(&sp.qdd, &de.qdd);
            let dl = rel_diff(&sp.lambda, &de.lambda);
            let bound = 20.0 * cond * f64::EPSILON;
            println!("K={k:4}  cond(B)={cond:9.3e}  |dqdd|/|qdd|={dq:9.2e}  |dlambda|/|lambda|={dl:9.2e}  bound 20 cond eps={bound:9.2e}");
            assert!(dq <= bound, "K={k}: qdd differs by {dq:e} > {bound:e}");
            assert!(dl <= bound, "K={k}: lambda differs by {dl:e} > {bound:e}");
            worst = worst.max(dq / (cond * f64::EPSILON));
        }
        println!("K={k}: worst |dqdd| / (cond eps) = {worst:.2}");
    }
}

#[test]
fn redundant_joint_falls_back_to_the_dense_rank_revealing_path() {
    // a chain of 40 links with the joint between links 9 and 10 declared twice: 2 redundant rows
    let k = 40;
    let dup = r#"{"kind": "revolute", "a": {"body": "link9", "point": [0.2, 0.0]}, "b": {"body": "link10", "point": [0.0, 0.0]}}"#;
    let json = chain_scene(k).replace(r#""joints": ["#, &format!(r#""joints": [{dup},"#));
    let model = Model::from_json(&json).unwrap();
    assert_eq!(model.m, 2 * k + 2);
    let (mut sp, mut de) = (data(&model, UkSolver::Sparse), data(&model, UkSolver::Dense));
    assert!(!sp.dense_ready, "dense buffers are allocated only on a failed certificate");
    let mut rng = Lcg(3);
    for _ in 0..3 {
        let (q, qd) = chain_state(&model, &mut rng);
        uk::acceleration(&model, &mut sp, 0.0, &q, &qd).unwrap();
        uk::acceleration(&model, &mut de, 0.0, &q, &qd).unwrap();
        assert_ne!(sp.factored_with, Factored::SparseGram, "no certificate with redundant rows");
        let (rs, rd) = (uk::exact_rank_info(&model, &mut sp).unwrap(), uk::exact_rank_info(&model, &mut de).unwrap());
        assert_eq!(rs.rank, model.m - 2);
        assert_eq!(rd.rank, model.m - 2);
        let cond = rd.sigma_max / rd.sigma_min_kept;
        let dq = rel_diff(&sp.qdd, &de.qdd);
        println!("redundant: rank {} of {}, cond(B) on the range {cond:.3e}, |dqdd|/|qdd| = {dq:.2e}", rs.rank, model.m);
        assert!(dq <= 20.0 * cond * f64::EPSILON);
    }
    assert!(sp.dense_ready);
}

#[test]
fn sparse_path_covers_every_body_and_joint_kind() {
    // not consistent states: the UK minimizer is defined anyway; the pattern of every kind's
    // Jacobian rows must lie in the bodies `Constraint::bodies` names
    let mut rng = Lcg(11);
    for json in [every_kind_scene(), ancf_scene(), point_mass_scene(), paper_scene("timoshenko", 8, true)] {
        let model = Model::from_json(&json).unwrap();
        let (mut sp, mut de) = (data(&model, UkSolver::Sparse), data(&model, UkSolver::Dense));
        for _ in 0..3 {
            let (q, qd) = random_state(&model, &mut rng);
            uk::acceleration(&model, &mut sp, 0.1, &q, &qd).unwrap();
            uk::acceleration(&model, &mut de, 0.1, &q, &qd).unwrap();
            let (cond, _) = cond_b(&model, &mut de);
            let dq = rel_diff(&sp.qdd, &de.qdd);
            let bound = 20.0 * cond * f64::EPSILON;
            assert!(dq <= bound, "{}: {dq:e} vs cond {cond:e} ({:?})", &json[..40], sp.factored_with);
        }
    }
}

#[test]
fn auto_picks_dense_for_small_and_sparse_for_long_chains() {
    let small = Model::from_json(&chain_scene(2)).unwrap();
    assert!(Data::new(&small).sparse.is_none());
    let paper = Model::from_json(&paper_scene("timoshenko", 64, true)).unwrap();
    assert!(Data::new(&paper).sparse.is_none());
    let long = Model::from_json(&chain_scene(64)).unwrap();
    let d = Data::new(&long);
    assert!(d.sparse.is_some() && !d.dense_ready);
    assert!(UkSolver::parse("banded").is_err());
}

#[test]
fn memory_limit_refuses_before_allocating() {
    let model = Model::from_json(&chain_scene(300)).unwrap();
    let err = Data::build(&model, UkSolver::Dense, 1 << 20).err().expect("refused");
    assert!(matches!(err, ukflex::Error::Memory { .. }), "{err}");
    assert!(Data::build(&model, UkSolver::Sparse, 16 << 20).is_ok());
}

#[test]
fn sparse_workspace_keeps_no_dense_jacobian_and_reports_the_certificate() {
    // K = 1024: n = 3072, m = 2048; the dense A alone would be 50 MB
    let model = Model::from_json(&chain_scene(1024)).unwrap();
    let mut sp = data(&model, UkSolver::Sparse);
    let mut rng = Lcg(5);
    let (q, qd) = chain_state(&model, &mut rng);
    uk::acceleration(&model, &mut sp, 0.0, &q, &qd).unwrap();
    assert_eq!(sp.factored_with, Factored::SparseGram);
    assert!(!sp.jac.is_on() && !sp.dense_ready, "no m x n buffer on the sparse path");
    assert_eq!(sp.ajac.nnz(), 2 * 1024 * 6 - 2 * 3, "two rigid bodies per row, one at the pivot");
    // the residual A qdd - b of the solve, from the segment form
    let (mut p, mut v, mut a) = (vec![0.0; model.m], vec![0.0; model.m], vec![0.0; model.m]);
    uk::residuals(&model, &mut sp, 0.0, &q, &qd, &mut p, &mut v, &mut a).unwrap();
    let scale = max_abs(&sp.gamma).max(1.0);
    assert!(max_abs(&a) <= 1e-10 * scale, "A qdd - b = {:e}", max_abs(&a));
    assert!(max_abs(&p) <= 1e-12 && max_abs(&v) <= 1e-12, "a consistent state");
    // above EXACT_RANK_MAX_ROWS: the certified report, no dense SVD
    let info = uk::exact_rank_info(&model, &mut sp).unwrap();
    assert!(!info.exact && info.rank == model.m && info.sigma_min_kept > info.tolerance);
    assert!(!sp.dense_ready && !sp.jac.is_on());
    // at or below it: the exact values (the dense SVD on demand), which the bounds enclose
    let small = Model::from_json(&chain_scene(64)).unwrap();
    let mut s2 = data(&small, UkSolver::Sparse);
    let (q, qd) = chain_state(&small, &mut rng);
    uk::acceleration(&small, &mut s2, 0.0, &q, &qd).unwrap();
    let bounds = s2.rank_info;
    let exact = uk::exact_rank_info(&small, &mut s2).unwrap();
    assert!(exact.exact && !bounds.exact && exact.rank == small.m);
    assert!(bounds.sigma_min_kept <= exact.sigma_min_kept && bounds.sigma_max >= exact.sigma_max);
}

#[test]
fn baumgarte_and_state_correction_agree_on_both_paths() {
    let model = Model::from_json(&chain_scene(48)).unwrap();
    let (mut sp, mut de) = (data(&model, UkSolver::Sparse), data(&model, UkSolver::Dense));
    let mut rng = Lcg(9);
    let (mut q, qd) = chain_state(&model, &mut rng);
    // off the manifold: Baumgarte's Phi and A qd terms matter
    for x in q.iter_mut() {
        *x += 1e-3 * (rng.next() - 0.5);
    }
    for d in [&mut sp, &mut de] {
        d.stabilization = ukflex::data::Stabilization::Baumgarte { alpha: 5.0, beta: 7.0 };
    }
    uk::acceleration(&model, &mut sp, 0.0, &q, &qd).unwrap();
    uk::acceleration(&model, &mut de, 0.0, &q, &qd).unwrap();
    assert_eq!(sp.factored_with, Factored::SparseGram);
    let (cond, _) = cond_b(&model, &mut de);
    let dq = rel_diff(&sp.qdd, &de.qdd);
    assert!(dq <= 20.0 * cond * f64::EPSILON, "Baumgarte: {dq:e}");
    // the initial-state correction (nothing held): the sparse UK step vs the dense SVD step
    let opts = ukflex::correct::CorrectOptions { hold: vec![false; model.n], rigid: false, position_tol: 1e-12, velocity_tol: 1e-12, max_iterations: 20 };
    let (cs, cd) = (ukflex::correct::correct(&model, &mut sp, 0.0, &q, &qd, &opts).unwrap(), ukflex::correct::correct(&model, &mut de, 0.0, &q, &qd, &opts).unwrap());
    assert!(cs.positions_ok && cs.velocities_ok && cd.positions_ok && cd.velocities_ok);
    assert!(cs.position_residual_after <= 1e-12 && cs.velocity_residual_after <= 1e-12);
    assert!(rel_diff(&cs.q, &cd.q) <= 1e-9, "corrected q differ by {:e}", rel_diff(&cs.q, &cd.q));
    assert!(rel_diff(&cs.qd, &cd.qd) <= 1e-9, "corrected qd differ by {:e}", rel_diff(&cs.qd, &cd.qd));
    assert!(!sp.dense_ready && !sp.jac.is_on(), "the correction stayed on the sparse path");
}
