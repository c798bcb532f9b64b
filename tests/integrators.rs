//! Native integrators and the hot path: no allocation per call or per step (counting global
//! allocator, per thread), DOPRI5 and RADAU5 against exact solutions and against each other on
//! the paper's slider-crank, and the finite-difference Jacobian against directional
//! differences.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use common::*;
use ukflex::integrate::{integrate, Dopri5, GenAlpha, GenAlphaOptions, LinearSolver, Options, Radau5, RadauM, RadauMOptions, SecondOrderSystem, Stepper, UkSystem};
use ukflex::jacobian::Differences;
use ukflex::jacobian::{uk_jacobian, JacobianWorkspace};
use ukflex::{uk, Data, Model};

// ---------------------------------------------------------------- counting allocator
struct Counting;

thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        System.realloc(ptr, layout, new_size)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        System.alloc_zeroed(layout)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by this thread while running `f`.
fn allocations(f: impl FnOnce()) -> usize {
    let before = ALLOCS.with(|c| c.get());
    f();
    ALLOCS.with(|c| c.get()) - before
}

fn chain_scene(k: usize) -> String {
    let mut bodies = Vec::new();
    let mut joints = vec![r#"{"kind": "revolute", "a": {"body": "ground"}, "b": {"body": "l0", "point": [0.0, 0.0]}}"#.to_string()];
    for i in 0..k {
        bodies.push(format!(r#"{{"name": "l{i}", "kind": "rigid", "mass": 1.0, "inertia": 0.003, "com": [0.1, 0.0], "position": [{}, 0.0]}}"#, 0.2 * i as f64));
        if i > 0 {
            joints.push(format!(r#"{{"kind": "revolute", "a": {{"body": "l{}", "point": [0.2, 0.0]}}, "b": {{"body": "l{i}", "point": [0.0, 0.0]}}}}"#, i - 1));
        }
    }
    format!(r#"{{"gravity": [0.0, -9.81], "bodies": [{}], "joints": [{}]}}"#, bodies.join(","), joints.join(","))
}

/// Midpoint transverse deflection of the coupler over its length, v(0.5)/Lb.
fn midpoint_deflection(model: &Model, q: &[f64]) -> f64 {
    let bi = model.body_index("coupler").unwrap();
    let body = &model.bodies[bi];
    let ukflex::body::BodyKind::Beam(beam) = &body.kind else { panic!("coupler is a beam") };
    let ps = beam.point_shape(0.5);
    let qf = &q[body.offset + 3..body.offset + body.n_coords];
    ps.entries.iter().map(|&(i, _, sv, _)| sv * qf[i]).sum::<f64>() / beam.length
}

// ---------------------------------------------------------------- allocation freedom
#[test]
fn uk_acceleration_and_jacobian_do_not_allocate() {
    // chain_scene(40) takes the sparse UK path (auto): its per-call loops touch the segment form
    // of A only; its dense A is allocated once, by the first uk_jacobian (warm-up below)
    for json in [paper_scene("timoshenko", 1, true), paper_scene("euler-bernoulli", 8, false), every_kind_scene(), chain_scene(6), chain_scene(40)] {
        let (model, mut data) = build(&json);
        let mut rng = Lcg(17);
        let (q, qd) = random_state(&model, &mut rng);
        uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
        let n = allocations(|| {
            for k in 0..50 {
                uk::acceleration(&model, &mut data, 0.1 + 1e-3 * k as f64, &q, &qd).unwrap();
            }
        });
        assert_eq!(n, 0, "uk::acceleration allocated {n} times in 50 calls");
        // every pseudoinverse backend
        for backend in [ukflex::SvdBackend::QrJacobi, ukflex::SvdBackend::Faer, ukflex::SvdBackend::Auto] {
            data.svd_backend = backend;
            uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
            let n = allocations(|| uk::acceleration(&model, &mut data, 0.2, &q, &qd).unwrap());
            assert_eq!(n, 0, "{backend:?} allocated");
        }
        let mut ws = JacobianWorkspace::new(&model);
        let (mut jq, mut jv) = (vec![0.0; model.n * model.n], vec![0.0; model.n * model.n]);
        uk_jacobian(&model, &mut data, &mut ws, 0.1, &q, &qd, &mut jq, &mut jv).unwrap();
        let n = allocations(|| uk_jacobian(&model, &mut data, &mut ws, 0.1, &q, &qd, &mut jq, &mut jv).unwrap());
        assert_eq!(n, 0, "uk_jacobian allocated {n} times");
    }
}

fn steps_allocate<St: Stepper>(stepper: &mut St, model: &Model, steps: usize) -> usize {
    steps_allocate_with(stepper, model, steps, |_| {})
}

fn steps_allocate_with<St: Stepper>(stepper: &mut St, model: &Model, steps: usize, setup: impl FnOnce(&mut UkSystem)) -> usize {
    let data = Data::new(model);
    let mut sys = UkSystem::new(model, data);
    setup(&mut sys);
    let y0: Vec<f64> = model.q0.iter().chain(&model.qd0).copied().collect();
    stepper.init(&mut sys, 0.0, &y0, 1.0).unwrap();
    stepper.step(&mut sys, 1.0).unwrap();
    let mut out = vec![0.0; y0.len()];
    let n = allocations(|| {
        for _ in 0..steps {
            stepper.step(&mut sys, 1.0).unwrap();
            let tm = 0.5 * (stepper.t() + stepper.t_old());
            stepper.dense(tm, &mut out);
        }
    });
    assert!(stepper.stats().naccept > steps, "steps were taken");
    n
}

#[test]
fn native_steps_do_not_allocate() {
    let model = Model::from_json(&paper_scene("timoshenko", 2, true)).unwrap();
    let opts = Options { rtol: 1e-6, atol: vec![1e-9], ..Default::default() };
    let projection = Some(ukflex::integrate::default_projection(&vec![1e-9; 2 * model.n]));
    let mut dp = Dopri5::new(2 * model.n, opts.clone()).unwrap();
    let n = steps_allocate(&mut dp, &model, 300);
    assert_eq!(n, 0, "DOPRI5 allocated {n} times in 300 steps");
    // with its projection and filtered error estimate (the default on constrained systems)
    let mut dp = Dopri5::new(2 * model.n, opts.clone()).unwrap();
    dp.projection = projection;
    let n = steps_allocate(&mut dp, &model, 300);
    assert_eq!(n, 0, "DOPRI5 (projection) allocated {n} times in 300 steps");
    let mut rd = Radau5::new(model.n, opts.clone()).unwrap();
    let n = steps_allocate(&mut rd, &model, 100);
    let st = rd.stats();
    assert!(st.njev >= 1 && st.nlu >= 2, "{st:?}");
    assert_eq!(n, 0, "RADAU5 allocated {n} times in 100 steps (stats {st:?})");
    // the structured Jacobian (its workspace is made at the first Jacobian, before counting)
    let mut rd = Radau5::new(model.n, opts.clone()).unwrap();
    let n = steps_allocate_with(&mut rd, &model, 100, |sys| sys.jws.scheme = Differences::Structured);
    assert_eq!(n, 0, "RADAU5 (structured Jacobian) allocated {n} times in 100 steps");
    // generalized-alpha, fixed and controlled steps, with its projection
    for step in [Some(2e-4), None] {
        let go = GenAlphaOptions { step, projection, ..Default::default() };
        let mut ga = GenAlpha::new(model.n, model.m, opts.clone(), go).unwrap();
        let n = steps_allocate(&mut ga, &model, 200);
        let st = ga.stats();
        assert!(st.nlu >= 1 && st.njev >= 1, "{st:?}");
        assert_eq!(n, 0, "GENALPHA (step {step:?}) allocated {n} times in 200 steps (stats {st:?})");
    }
    // Radau IIA on the second-order equations, fixed and controlled steps, with its projection
    for step in [Some(2e-4), None] {
        let ro = RadauMOptions { step, projection };
        let mut rm = RadauM::new(model.n, model.m, opts.clone(), ro).unwrap();
        let n = steps_allocate(&mut rm, &model, 100);
        let st = rm.stats();
        assert!(st.nlu >= 2 && st.njev >= 1, "{st:?}");
        assert_eq!(n, 0, "RADAU5M (step {step:?}) allocated {n} times in 100 steps (stats {st:?})");
    }
    // the sparse Newton matrices (band LU, coloured velocity differences): the paper scene, an
    // ANCF coupler and a chain, both implicit methods
    for json in [paper_scene("timoshenko", 2, true), ancf_paper_scene(4, true), chain_scene(12)] {
        let model = Model::from_json(&json).unwrap();
        let opts = Options { linear_solver: LinearSolver::Sparse, ..opts.clone() };
        for step in [Some(2e-4), None] {
            let go = GenAlphaOptions { step, projection, ..Default::default() };
            let mut ga = GenAlpha::new(model.n, model.m, opts.clone(), go).unwrap();
            let n = steps_allocate(&mut ga, &model, 100);
            let st = ga.stats();
            assert!(st.nlu >= 1 && st.njev >= 1, "{st:?}");
            assert_eq!(n, 0, "sparse GENALPHA (step {step:?}) allocated {n} times in 100 steps (stats {st:?})");
            let ro = RadauMOptions { step, projection };
            let mut rm = RadauM::new(model.n, model.m, opts.clone(), ro).unwrap();
            let n = steps_allocate(&mut rm, &model, 100);
            let st = rm.stats();
            assert!(st.nlu >= 2 && st.njev >= 1, "{st:?}");
            assert_eq!(n, 0, "sparse RADAU5M (step {step:?}) allocated {n} times in 100 steps (stats {st:?})");
        }
        // RADAU5 with the structured Jacobian solves its iteration matrices as sparse saddle points
        let mut rd = Radau5::new(model.n, opts.clone()).unwrap();
        let n = steps_allocate_with(&mut rd, &model, 100, |sys| sys.jws.scheme = Differences::Structured);
        let st = rd.stats();
        assert!(st.njev >= 1 && st.nlu >= 2, "{st:?}");
        assert_eq!(n, 0, "sparse RADAU5 allocated {n} times in 100 steps (stats {st:?})");
    }
}

// ---------------------------------------------------------------- accuracy on exact solutions
/// Damped linear oscillators `qdd_i = -w_i^2 q_i - 2 z_i w_i qd_i` (independent modes, one of
/// them stiff): exact solution known.
struct Oscillators {
    w: Vec<f64>,
    z: Vec<f64>,
}

impl SecondOrderSystem for Oscillators {
    fn n(&self) -> usize {
        self.w.len()
    }
    fn acc(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> ukflex::Result<()> {
        for i in 0..self.w.len() {
            qdd[i] = -self.w[i] * self.w[i] * q[i] - 2.0 * self.z[i] * self.w[i] * qd[i];
        }
        Ok(())
    }
    fn jac(&mut self, _t: f64, _q: &[f64], _qd: &[f64], jq: &mut [f64], jv: &mut [f64]) -> ukflex::Result<()> {
        let n = self.w.len();
        jq.fill(0.0);
        jv.fill(0.0);
        for i in 0..n {
            jq[i * n + i] = -self.w[i] * self.w[i];
            jv[i * n + i] = -2.0 * self.z[i] * self.w[i];
        }
        Ok(())
    }
}

fn oscillator_exact(w: f64, z: f64, t: f64) -> (f64, f64) {
    // q(0) = 1, qd(0) = 0, underdamped
    let wd = w * (1.0 - z * z).sqrt();
    let e = (-z * w * t).exp();
    let (s, c) = (wd * t).sin_cos();
    let q = e * (c + z * w / wd * s);
    let qd = e * (-(w * w) / wd * s);
    (q, qd)
}

#[test]
fn integrators_match_exact_oscillators_and_radau_handles_stiffness() {
    let (w, z) = (vec![3.0, 40.0], vec![0.05, 0.1]);
    let y0 = [1.0, 1.0, 0.0, 0.0];
    let te: Vec<f64> = (0..=20).map(|k| 0.1 * k as f64).collect();
    for rtol in [1e-6, 1e-9] {
        let opts = Options { rtol, atol: vec![rtol * 1e-3], ..Default::default() };
        let mut sys = Oscillators { w: w.clone(), z: z.clone() };
        let sol_dp = integrate(&mut Dopri5::new(4, opts.clone()).unwrap(), &mut sys, 0.0, &y0, 2.0, Some(&te)).unwrap();
        let sol_rd = integrate(&mut Radau5::new(2, opts).unwrap(), &mut sys, 0.0, &y0, 2.0, Some(&te)).unwrap();
        for (name, sol) in [("DOPRI5", &sol_dp), ("RADAU5", &sol_rd)] {
            assert_eq!(sol.status, 0, "{name}: {}", sol.message);
            assert_eq!(sol.t.len(), te.len());
            let mut err = 0.0f64;
            for (k, &t) in sol.t.iter().enumerate() {
                for i in 0..2 {
                    let (q, _) = oscillator_exact(w[i], z[i], t);
                    err = err.max((sol.y[k * 4 + i] - q).abs());
                }
            }
            // global error within a modest multiple of rtol (dense output included)
            assert!(err < 50.0 * rtol, "{name} rtol {rtol:e}: max error {err:e}");
        }
    }
    // stiff: w = 1e5 (heavily damped) next to a slow mode; RADAU5 needs far fewer steps
    let mut sys = Oscillators { w: vec![2.0, 1e5], z: vec![0.0, 0.7] };
    let opts = Options { rtol: 1e-6, atol: vec![1e-9], ..Default::default() };
    let rd = integrate(&mut Radau5::new(2, opts.clone()).unwrap(), &mut sys, 0.0, &y0, 1.0, None).unwrap();
    let dp = integrate(&mut Dopri5::new(4, opts).unwrap(), &mut sys, 0.0, &y0, 1.0, None).unwrap();
    assert_eq!(rd.status, 0, "{}", rd.message);
    assert_eq!(dp.status, 0, "{}", dp.message);
    let last = rd.t.len() - 1;
    let (q_slow, _) = oscillator_exact(2.0, 1e-300, 1.0);
    assert!((rd.y[last * 4] - q_slow).abs() < 1e-4, "RADAU5 slow mode {} vs {q_slow}", rd.y[last * 4]);
    assert!(rd.stats.naccept * 20 < dp.stats.naccept, "RADAU5 {:?} vs DOPRI5 {:?}", rd.stats, dp.stats);
}

// ---------------------------------------------------------------- the paper's slider-crank
#[test]
fn dopri5_and_radau5_agree_on_the_paper_scene() {
    let model = Model::from_json(&paper_scene("timoshenko", 1, true)).unwrap();
    let y0: Vec<f64> = model.q0.iter().chain(&model.qd0).copied().collect();
    let te: Vec<f64> = (0..=100).map(|k| 1e-3 * k as f64).collect();
    let run = |method: &str, rtol: f64| {
        let data = Data::new(&model);
        let mut sys = UkSystem::new(&model, data);
        let opts = Options { rtol, atol: vec![rtol * 1e-3], ..Default::default() };
        let sol = match method {
            "dopri5" => integrate(&mut Dopri5::new(2 * model.n, opts).unwrap(), &mut sys, 0.0, &y0, 0.1, Some(&te)).unwrap(),
            _ => integrate(&mut Radau5::new(model.n, opts).unwrap(), &mut sys, 0.0, &y0, 0.1, Some(&te)).unwrap(),
        };
        assert_eq!(sol.status, 0, "{method}: {}", sol.message);
        let v: Vec<f64> = (0..sol.t.len()).map(|k| midpoint_deflection(&model, &sol.y[k * sol.dim..k * sol.dim + model.n])).collect();
        (v, sol.stats)
    };
    let (v_ref, _) = run("dopri5", 1e-11);
    let vmax = v_ref.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(vmax > 1e-6 && vmax < 1e-2, "midpoint deflection / Lb peaks at {vmax:e}");
    let (v_rd_tight, _) = run("radau5", 1e-10);
    let d_tight = v_ref.iter().zip(&v_rd_tight).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(d_tight < 1e-9, "tight DOPRI5 vs tight RADAU5: {d_tight:e}");
    for method in ["dopri5", "radau5"] {
        let (v, stats) = run(method, 1e-6);
        let err = v_ref.iter().zip(&v).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        println!("{method} rtol 1e-6: max |v(0.5)/Lb - ref| = {err:.3e}, stats {stats:?}");
        assert!(err < 1e-6, "{method}: error {err:e} against the tight reference");
    }
}

// ---------------------------------------------------------------- Jacobian
#[test]
fn jacobian_matches_directional_differences() {
    for json in [paper_scene("timoshenko", 2, true), every_kind_scene()] {
        let (model, mut data) = build(&json);
        let n = model.n;
        let mut rng = Lcg(29);
        let (q, qd) = random_state(&model, &mut rng);
        let mut ws = JacobianWorkspace::new(&model);
        let (mut jq, mut jv) = (vec![0.0; n * n], vec![0.0; n * n]);
        uk_jacobian(&model, &mut data, &mut ws, 0.2, &q, &qd, &mut jq, &mut jv).unwrap();
        // direction scaled like the state
        let dq: Vec<f64> = q.iter().map(|x| (1e-2f64).max(x.abs()) * rng.next()).collect();
        let dv: Vec<f64> = qd.iter().map(|x| (1e-2f64).max(x.abs()) * rng.next()).collect();
        let mut acc = |s: f64| {
            let qs: Vec<f64> = q.iter().zip(&dq).map(|(a, b)| a + s * b).collect();
            let vs: Vec<f64> = qd.iter().zip(&dv).map(|(a, b)| a + s * b).collect();
            uk::acceleration(&model, &mut data, 0.2, &qs, &vs).unwrap();
            data.qdd.clone()
        };
        // Richardson-extrapolated central difference along (dq, dv)
        let (h1, h2) = (1e-4, 5e-5);
        let d1: Vec<f64> = acc(h1).iter().zip(acc(-h1)).map(|(a, b)| (a - b) / (2.0 * h1)).collect();
        let d2: Vec<f64> = acc(h2).iter().zip(acc(-h2)).map(|(a, b)| (a - b) / (2.0 * h2)).collect();
        let fd: Vec<f64> = d1.iter().zip(&d2).map(|(a, b)| (4.0 * b - a) / 3.0).collect();
        let scale = max_abs(&fd).max(1.0);
        for i in 0..n {
            let jd: f64 = (0..n).map(|j| jq[i * n + j] * dq[j] + jv[i * n + j] * dv[j]).sum();
            assert!((jd - fd[i]).abs() < 1e-6 * scale, "row {i}: J d = {jd:e}, differences {:e}", fd[i]);
        }
    }
}

// ---------------------------------------------------------------- pseudoinverse backends
#[test]
fn pseudoinverse_backends_agree_including_redundant_rows() {
    // a chain with one joint declared twice: m = 2K + 2 dependent rows; small and large m
    let redundant = |k: usize| {
        chain_scene(k).replace(
            r#""joints": ["#,
            r#""joints": [{"kind": "revolute", "a": {"body": "ground"}, "b": {"body": "l0", "point": [0.0, 0.0]}},"#,
        )
    };
    let cases = [
        (paper_scene("timoshenko", 4, true), false),
        (every_kind_scene(), false),
        (redundant(3), true),
        (redundant(10), true), // m = 22 > AUTO_JACOBI_MAX_ROWS: Auto falls back to faer
    ];
    for (json, is_redundant) in cases {
        let (model, mut data) = build(&json);
        data.ensure_dense_jac().unwrap(); // the forces below read the dense copy of A
        let mut rng = Lcg(41);
        let (q, qd) = random_state(&model, &mut rng);
        let mut results = Vec::new();
        for backend in [ukflex::SvdBackend::Faer, ukflex::SvdBackend::QrJacobi, ukflex::SvdBackend::Auto] {
            data.svd_backend = backend;
            uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
            let info = uk::exact_rank_info(&model, &mut data).unwrap();
            assert!(info.exact);
            results.push((backend, data.qdd.clone(), data.lambda.clone(), info));
        }
        let (_, qdd0, lam0, info0) = &results[0];
        let expected_rank = if is_redundant { model.m - 2 } else { model.m };
        for (backend, qdd, lam, info) in &results {
            assert_eq!(info.rank, expected_rank, "{backend:?}");
            assert!((info.sigma_min_kept - info0.sigma_min_kept).abs() <= 1e-10 * info0.sigma_max, "{backend:?}: {info:?} vs {info0:?}");
            let e = qdd.iter().zip(qdd0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / max_abs(qdd0);
            assert!(e < 1e-10, "{backend:?}: qdd differs by {e:e}");
            // multipliers of dependent rows are not unique: compare A^T lambda (the forces)
            let n = model.n;
            let a = data.dense_jac().to_vec();
            let force = |l: &[f64]| -> Vec<f64> { (0..n).map(|j| (0..model.m).map(|i| a[i * n + j] * l[i]).sum()).collect() };
            let (f, f0) = (force(lam), force(lam0));
            let e = f.iter().zip(&f0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / max_abs(&f0);
            assert!(e < 1e-9, "{backend:?}: constraint forces differ by {e:e}");
            if !is_redundant {
                let e = lam.iter().zip(lam0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / max_abs(lam0);
                assert!(e < 1e-9, "{backend:?}: lambda differs by {e:e}");
            }
        }
    }
}

#[test]
fn jacobi_svd_converges_with_exactly_duplicated_rows() {
    // crank-coupler revolute declared twice: rows identical at every state, B^T has two equal
    // columns and R a rounding-level column that Jacobi must not keep rotating
    let single = paper_scene("timoshenko", 1, true);
    let dup_joint = r#"{"kind": "revolute", "a": {"body": "crank", "point": [0.1524, 0.0]}, "b": {"body": "coupler", "xi": 0.0}}"#;
    let doubled = single.replace(r#""joints": ["#, &format!(r#""joints": [{dup_joint},"#));
    let (model, mut data) = build(&doubled);
    let (model1, mut data1) = build(&single);
    assert_eq!(model.m, 8);
    data.svd_backend = ukflex::SvdBackend::QrJacobi;
    let mut rng = Lcg(77);
    for k in 0..300 {
        let (q, qd) = if k == 0 { (model.q0.clone(), model.qd0.clone()) } else { random_state(&model, &mut rng) };
        uk::acceleration(&model, &mut data, 0.05, &q, &qd).unwrap_or_else(|e| panic!("state {k}: {e}"));
        assert_eq!(data.rank_info.rank, 6, "state {k}");
        uk::acceleration(&model1, &mut data1, 0.05, &q, &qd).unwrap();
        let e = data.qdd.iter().zip(&data1.qdd).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / max_abs(&data1.qdd);
        assert!(e < 1e-9, "state {k}: duplicated vs single declaration differ by {e:e}");
    }
}

// ---------------------------------------------------------------- vector registers
/// A run starts on clean vector registers whatever ran before it: faer's eigensolver at order
/// 40 leaves the upper halves of the vector registers in use on this project's machine, which
/// made every SSE kernel of the run that followed auto's analysis 2x slower (round i26-simd).
/// Without `simd_state::clean_upper` at `integrate_observed`'s entry the state stays in use
/// through the run (the kernels' SSE code never clears it). Where the CPU cannot tell, or faer
/// left it clean, there is nothing to show and the test says so.
#[test]
fn a_run_clears_the_upper_halves_of_the_vector_registers() {
    use faer::{Mat, Side};
    use ukflex::linalg::simd_state::upper_in_use;
    let k = 40;
    let c = Mat::<f64>::from_fn(k, k, |i, j| if i == j { 1.0 + i as f64 } else { 0.01 / (1.0 + (i + j) as f64) });
    let _ = c.self_adjoint_eigen(Side::Lower).unwrap();
    let dirty = upper_in_use();
    let model = Model::from_json(&paper_scene("euler-bernoulli", 1, true)).unwrap();
    let y0: Vec<f64> = model.q0.iter().chain(&model.qd0).copied().collect();
    let mut sys = UkSystem::new(&model, Data::new(&model));
    let sol = integrate(&mut Dopri5::new(2 * model.n, Options::default()).unwrap(), &mut sys, 0.0, &y0, 1e-3, None).unwrap();
    assert_eq!(sol.status, 0, "{}", sol.message);
    if dirty != Some(true) {
        println!("faer's eigensolver left the upper state {dirty:?}: nothing to show here");
    }
    assert_ne!(upper_in_use(), Some(true), "the run ended with the upper halves in use (before it: {dirty:?})");
}
