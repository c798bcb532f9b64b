//! The implicit methods' sparse Newton matrices (`sparse_newton`, `integrate/newton.rs`) against
//! the dense ones: the structure (`M`, `K`, `C`, `A`, `db/dqd`) is the same to the bit on every
//! body, joint and force kind at random states, every entry the kernels write lies in the
//! pattern; GENALPHA and RADAU5M runs on the sparse path give the dense path's answers to
//! rounding; the band of a chain or a cable stays narrow whatever its length.

mod common;
use common::*;
use ukflex::integrate::{integrate, GenAlpha, Radau5, GenAlphaOptions, LinearSolver, NewtonMatrices, Options, RadauM, RadauMOptions, SecondOrderSystem, UkSystem};
use ukflex::sparse_newton::{BandLayout, Pattern};
use ukflex::{Data, Model};

/// A steel wire (1 m, d = 2 mm) of `elements` ANCF elements pinned at one end, horizontal at rest.
fn wire_scene(elements: usize) -> String {
    format!(
        r#"{{"gravity": [0.0, -9.81],
          "bodies": [{{"name": "wire", "kind": "cable", "length": 1.0, "elements": {elements},
            "density": 7850.0, "youngs_modulus": 2.1e11,
            "section": {{"shape": "circular", "diameter": 0.002}}}}],
          "joints": [{{"kind": "revolute", "a": {{"body": "ground"}}, "b": {{"body": "wire", "xi": 0.0}}}}]}}"#
    )
}

fn scenes() -> Vec<(&'static str, String)> {
    vec![
        ("paper timoshenko 2", paper_scene("timoshenko", 2, true)),
        ("paper ancf 4", ancf_paper_scene(4, true)),
        ("every kind", every_kind_scene()),
        ("point masses", point_mass_scene()),
        ("ancf kinds", ancf_scene()),
        ("chain 7", chain_scene(7)),
        ("wire 5", wire_scene(5)),
    ]
}

fn bits_equal(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0)
}

#[test]
fn the_sparse_structure_is_the_dense_one_to_the_bit() {
    for (name, json) in scenes() {
        let model = Model::from_json(&json).unwrap();
        let (n, m) = (model.n, model.m);
        let mut rng = Lcg(5);
        for trial in 0..3 {
            let (q, qd) = random_state(&model, &mut rng);
            let t = 0.1 * trial as f64;
            let mut dense = UkSystem::new(&model, Data::new(&model));
            let mut sparse = UkSystem::new(&model, Data::new(&model));
            let (mut mm, mut kk, mut cc, mut aa, mut bv) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n], vec![0.0; m * n], vec![0.0; m * n]);
            assert!(dense.structure(t, &q, &qd, &mut mm, &mut kk, &mut cc, &mut aa, &mut bv).unwrap());
            let mut s = sparse.sparse_structure().unwrap().expect("the UK system has a sparse structure");
            assert!(sparse.structure_sparse(t, &q, &qd, &mut s).unwrap());
            let p = &s.pattern;
            // every entry of the pattern is the dense entry, bit for bit ...
            let mut inside = vec![false; n * n];
            for (e, (i, j)) in p.entries().enumerate() {
                inside[i * n + j] = true;
                for (what, sv, dv) in [("M", s.m[e], mm[i * n + j]), ("K", s.k[e], kk[i * n + j]), ("C", s.c[e], cc[i * n + j])] {
                    assert!(bits_equal(sv, dv), "{name}: {what}[{i}][{j}] sparse {sv:e} dense {dv:e}");
                }
            }
            // ... and every dense entry outside it is zero
            for i in 0..n {
                for j in 0..n {
                    if !inside[i * n + j] {
                        assert!(mm[i * n + j] == 0.0 && kk[i * n + j] == 0.0 && cc[i * n + j] == 0.0, "{name}: ({i}, {j}) outside the pattern is not zero");
                    }
                }
            }
            let mut a_inside = vec![false; m * n];
            for (e, (r, j)) in p.a_entries().enumerate() {
                a_inside[r * n + j] = true;
                assert!(bits_equal(s.a[e], aa[r * n + j]), "{name}: A[{r}][{j}]");
                assert!(bits_equal(s.bv[e], bv[r * n + j]), "{name}: db/dqd[{r}][{j}]");
            }
            for k in 0..m * n {
                if !a_inside[k] {
                    assert!(aa[k] == 0.0 && bv[k] == 0.0, "{name}: A or db/dqd at ({}, {}) outside the pattern", k / n, k % n);
                }
            }
            // the cheap part where an acceleration evaluation leaves it
            dense.acc(t, &q, &qd, &mut vec![0.0; n]).unwrap();
            sparse.acc(t, &q, &qd, &mut vec![0.0; n]).unwrap();
            assert!(dense.stiff_structure(&q, &qd, &mut mm, &mut kk, &mut cc, &mut aa).unwrap());
            assert!(sparse.stiff_structure_sparse(&q, &qd, &mut s).unwrap());
            let p = &s.pattern;
            for (e, (i, j)) in p.entries().enumerate() {
                assert!(bits_equal(s.m[e], mm[i * n + j]) && bits_equal(s.k[e], kk[i * n + j]), "{name}: stiff part ({i}, {j})");
                // the dampers' analytic share of C moved to (q, qd) the same way in both
                assert!(bits_equal(s.c[e], cc[i * n + j]), "{name}: C after the stiff part ({i}, {j})");
            }
            for (e, (r, j)) in p.a_entries().enumerate() {
                assert!(bits_equal(s.a[e], aa[r * n + j]), "{name}: stiff A[{r}][{j}]");
            }
        }
    }
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d = a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    d / max_abs(b).max(f64::MIN_POSITIVE)
}

/// Final state and stats of a run of `method` with the linear solver `ls`.
fn run(model: &Model, method: &str, step: Option<f64>, t_end: f64, ls: LinearSolver, ulp: bool) -> (Vec<f64>, ukflex::integrate::Stats) {
    let opts = Options { rtol: 1e-6, atol: vec![1e-9], linear_solver: ls, ..Default::default() };
    let mut sys = UkSystem::new(model, Data::new(model));
    let mut y0: Vec<f64> = model.q0.iter().chain(&model.qd0).copied().collect();
    if ulp {
        // one unit in the last place up on every nonzero entry: the run's sensitivity to rounding
        for v in y0.iter_mut().filter(|v| **v != 0.0) {
            *v = f64::from_bits(v.to_bits() + 1);
        }
    }
    let sol = match method {
        "RADAU5" => {
            // the structured Jacobian: its iteration matrices are saddle points
            sys.jws.scheme = ukflex::jacobian::Differences::Structured;
            let mut st = Radau5::new(model.n, opts).unwrap();
            integrate(&mut st, &mut sys, 0.0, &y0, t_end, None).unwrap()
        }
        "GENALPHA" => {
            let go = GenAlphaOptions { step, projection: Some(ukflex::integrate::default_projection(&vec![1e-9; 2 * model.n])), ..Default::default() };
            let mut st = GenAlpha::new(model.n, model.m, opts, go).unwrap();
            integrate(&mut st, &mut sys, 0.0, &y0, t_end, None).unwrap()
        }
        _ => {
            let ro = RadauMOptions { step, projection: Some(ukflex::integrate::default_projection(&vec![1e-9; 2 * model.n])) };
            let mut st = RadauM::new(model.n, model.m, opts, ro).unwrap();
            integrate(&mut st, &mut sys, 0.0, &y0, t_end, None).unwrap()
        }
    };
    assert_eq!(sol.status, 0, "{method} {ls:?}: {}", sol.message);
    (sol.y[sol.y.len() - sol.dim..].to_vec(), sol.stats)
}

#[test]
fn sparse_and_dense_newton_runs_give_the_same_answer_to_rounding() {
    for (name, json, t_end) in [
        ("paper timoshenko 2", paper_scene("timoshenko", 2, true), 4e-3),
        ("paper ancf 4", ancf_paper_scene(4, true), 4e-3),
        ("chain 7", chain_scene(7), 0.05),
        ("wire 6", wire_scene(6), 2e-3),
    ] {
        let model = Model::from_json(&json).unwrap();
        for (method, step) in [("GENALPHA", Some(1e-4)), ("GENALPHA", None), ("RADAU5M", Some(2e-4)), ("RADAU5M", None), ("RADAU5", None)] {
            let (yd, sd) = run(&model, method, step, t_end, LinearSolver::Dense, false);
            let (ys, ss) = run(&model, method, step, t_end, LinearSolver::Sparse, false);
            let (yu, _) = run(&model, method, step, t_end, LinearSolver::Dense, true);
            let d = rel_diff(&ys, &yd);
            let du = rel_diff(&yu, &yd);
            println!("{name:20} {method:8} step {step:?}: steps {} / {}, Newton {} / {}, relative difference {d:.1e} (dense, 1 ulp: {du:.1e})", sd.naccept, ss.naccept, sd.newton, ss.newton);
            if method != "RADAU5" && step.is_some() {
                // the same matrices, factored differently: at a fixed step, the same steps
                assert_eq!((sd.naccept, sd.nreject), (ss.naccept, ss.nreject), "{name} {method} {step:?}: the same steps");
            } else if method != "RADAU5" {
                // error-controlled: the rounding of another factorization may move an error
                // estimate across 1 (on CI's machine, whose SIMD rounds the dense LU differently,
                // the ANCF coupler's 6,188 RADAU5M steps had 397 rejections dense and 393
                // sparse); from there on the two step sequences are two draws of the same
                // controller, whose counts differ like sqrt(rejections), not more
                let (a, r) = (sd.naccept as f64, sd.nreject as f64);
                let moved = (a - ss.naccept as f64).abs() + (r - ss.nreject as f64).abs();
                assert!(moved <= 2.0 + 3.0 * (r + 1.0).sqrt(), "{name} {method} {step:?}: steps {} + {} rejected dense, {} + {} sparse", sd.naccept, sd.nreject, ss.naccept, ss.nreject);
            }
            // rounding: within what one ulp of the initial state changes (stiff runs amplify it)
            assert!(d <= (5.0 * du).max(1e-11), "{name} {method} {step:?}: sparse and dense differ by {d:e} (1 ulp: {du:e})");
        }
    }
}

#[test]
fn auto_takes_the_sparse_newton_matrices_where_they_were_measured_to_pay() {
    // (scene, sparse for RADAU5M, sparse for GENALPHA): the measured crossovers (n + m = 50
    // and 100, benches/crossover.py) and the band condition (the paper's FFRF coupler of 16
    // elements is one dense body: its band is the whole matrix)
    for (json, radau, galpha) in [
        (paper_scene("timoshenko", 1, true), false, false),
        (paper_scene("euler-bernoulli", 16, true), false, false),
        (wire_scene(4), false, false),
        (wire_scene(12), true, false),
        (wire_scene(24), true, true),
        (wire_scene(64), true, true),
        (chain_scene(64), true, true),
    ] {
        let model = Model::from_json(&json).unwrap();
        let mut sys = UkSystem::new(&model, Data::new(&model));
        let nw = NewtonMatrices::for_system(&mut sys, LinearSolver::Auto, true, false, "RADAU5M").unwrap();
        assert_eq!(nw.is_sparse(), radau, "RADAU5M: n = {}, m = {}", model.n, model.m);
        let nw = NewtonMatrices::for_system(&mut sys, LinearSolver::Auto, false, true, "GENALPHA").unwrap();
        assert_eq!(nw.is_sparse(), galpha, "GENALPHA: n = {}, m = {}", model.n, model.m);
    }
}

#[test]
fn the_band_of_a_cable_or_a_chain_does_not_grow_with_its_length() {
    for (make, name) in [(wire_scene as fn(usize) -> String, "wire"), (chain_scene as fn(usize) -> String, "chain")] {
        let hbs: Vec<usize> = [16, 64, 256]
            .iter()
            .map(|&k| {
                let model = Model::from_json(&make(k)).unwrap();
                let data = Data::new(&model);
                let p = Pattern::new(&model, &data.ajac, false, u64::MAX).unwrap();
                BandLayout::new(&p).hb
            })
            .collect();
        println!("{name}: half-bandwidth {hbs:?}");
        assert!(hbs.windows(2).all(|w| w[0] == w[1]), "{name}: {hbs:?}");
    }
}

#[test]
fn the_sparse_path_refuses_a_pattern_above_the_memory_limit() {
    let model = Model::from_json(&wire_scene(64)).unwrap();
    let data = Data::new(&model);
    let err = Pattern::new(&model, &data.ajac, false, 4096).unwrap_err();
    assert!(matches!(err, ukflex::Error::Memory { .. }), "{err}");
    assert!(Pattern::new(&model, &data.ajac, false, 1 << 30).is_ok());
}
