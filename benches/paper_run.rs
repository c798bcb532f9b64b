//! Whole paper run (slider-crank, Timoshenko and Euler-Bernoulli coupler, N = 1, 0..0.1 s) with
//! the native integrators at several tolerances: wall time (min and median of repeated runs),
//! step and evaluation counts, and the max error of the coupler midpoint deflection v(0.5)/Lb
//! (at 101 equally spaced times, dense output) against a tight reference (DOPRI5, rtol 1e-11,
//! cross-checked with RADAU5, rtol 1e-10). Run: `cargo bench --bench paper_run`.

use std::time::Instant;

use ukflex::integrate::{integrate_uk, Method, Options};
use ukflex::{Data, Model};

mod scenes;
use scenes::*;

fn midpoint_deflection(model: &Model, q: &[f64]) -> f64 {
    let bi = model.body_index("coupler").unwrap();
    let body = &model.bodies[bi];
    let ukflex::body::BodyKind::Beam(beam) = &body.kind else { panic!("coupler is a beam") };
    let ps = beam.point_shape(0.5);
    let qf = &q[body.offset + 3..body.offset + body.n_coords];
    ps.entries.iter().map(|&(i, _, sv, _)| sv * qf[i]).sum::<f64>() / beam.length
}

struct Run {
    v: Vec<f64>,
    secs: f64,
    naccept: usize,
    nfev: usize,
    njev: usize,
    nlu: usize,
    jac_evals: usize,
}

fn run(model: &Model, method: Method, rtol: f64, atol: f64, te: &[f64]) -> Run {
    let y0: Vec<f64> = model.q0.iter().chain(&model.qd0).copied().collect();
    let opts = Options { rtol, atol: vec![atol], ..Default::default() };
    let tic = Instant::now();
    let (sol, full, cheap) = integrate_uk(model, Data::new(model), method, opts, 0.0, &y0, 0.1, Some(te), None, ukflex::jacobian::Differences::Central, false).unwrap();
    let secs = tic.elapsed().as_secs_f64();
    assert_eq!(sol.status, 0, "{}", sol.message);
    let v = (0..sol.t.len()).map(|k| midpoint_deflection(model, &sol.y[k * sol.dim..k * sol.dim + model.n])).collect();
    Run { v, secs, naccept: sol.stats.naccept, nfev: sol.stats.nfev, njev: sol.stats.njev, nlu: sol.stats.nlu, jac_evals: full + cheap }
}

fn main() {
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-')).unwrap_or_default();
    let te: Vec<f64> = (0..=100).map(|k| 1e-3 * k as f64).collect();
    // the paper's scene (undamped) for both theories, then with stiffness-proportional beam
    // damping beta = 1e-5 s (N = 1 and 4): the case a stiff method is for
    let damped = |n_el: usize| paper_scene("timoshenko", n_el, true).replace(r#""frame": "pinned-pinned""#, r#""frame": "pinned-pinned", "damping": 1e-5"#);
    let cases = [
        ("timoshenko", paper_scene("timoshenko", 1, true), 1),
        ("euler-bernoulli", paper_scene("euler-bernoulli", 1, true), 1),
        ("timoshenko, beam damping 1e-5 s", damped(1), 1),
        ("timoshenko, beam damping 1e-5 s", damped(4), 4),
    ];
    for (theory, json, n_el) in cases {
        if !theory.contains(&filter) && !filter.is_empty() && !"dopri5 radau5".contains(&filter) {
            continue;
        }
        let model = Model::from_json(&json).unwrap();
        let reference = run(&model, Method::Dopri5, 1e-11, 1e-14, &te);
        let check = run(&model, Method::Radau5, 1e-10, 1e-13, &te);
        let d = reference.v.iter().zip(&check.v).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        let vmax = reference.v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        println!("paper scene, {theory}, N = {n_el}: max |v(0.5)/Lb| = {vmax:.4e}; reference DOPRI5 rtol 1e-11 vs RADAU5 rtol 1e-10 differ by {d:.2e}");
        println!("{:<8} {:>7} {:>9} {:>10} {:>10} {:>8} {:>7} {:>7} {:>7} {:>9} {:>11}", "method", "rtol", "atol", "min [ms]", "med [ms]", "steps", "nfev", "njev", "nlu", "jac evals", "max err");
        for (method, name) in [(Method::Radau5, "RADAU5"), (Method::Dopri5, "DOPRI5")] {
            if !filter.is_empty() && !name.to_lowercase().contains(&filter) && !theory.contains(&filter) {
                continue;
            }
            for rtol in [1e-3, 1e-4, 5e-5, 1e-5, 1e-6] {
                let atol = 1e-3 * rtol;
                let mut times = Vec::new();
                let mut last = None;
                let reps = 7;
                for _ in 0..reps {
                    let r = run(&model, method, rtol, atol, &te);
                    times.push(r.secs);
                    last = Some(r);
                }
                times.sort_by(|a, b| a.partial_cmp(b).unwrap());
                let r = last.unwrap();
                let err = reference.v.iter().zip(&r.v).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
                println!(
                    "{name:<8} {rtol:>7.0e} {atol:>9.0e} {:>10.3} {:>10.3} {:>8} {:>7} {:>7} {:>7} {:>9} {:>11.2e}",
                    times[0] * 1e3,
                    times[reps / 2] * 1e3,
                    r.naccept,
                    r.nfev,
                    r.njev,
                    r.nlu,
                    r.jac_evals,
                    err
                );
            }
        }
    }
}
