//! The spatial UK kernel per call in batches (no criterion): `uk::acceleration` on the spatial
//! slider-crank (and the heavy top, A05) at the corrected initial state (t = 0.1), `BATCHES`
//! batches of `CALLS` calls each, reporting the lowest batch (what the load did not reach) and
//! the median batch per call. Run: `cargo bench --bench spatial_batches` (about 5 s).
//! With an argument `one`, only the slider-crank; `perf`, only it for ten times as long (a
//! `perf record` target); `stages`, its stages one by one (lowest batch each); `a05`, only the
//! flyball governor (A05), with as many batches as the slider-crank.

use std::hint::black_box;
use std::time::Instant;

use ukflex::correct::{correct, CorrectOptions};
use ukflex::{dynamics, uk, Data, Model};

const CALLS: usize = 500;
const BATCHES: usize = 400;

fn run(name: &str, json: &str, batches: usize) {
    let model = Model::from_json(json).expect("scene builds");
    let mut data = Data::new(&model);
    let opts = CorrectOptions { hold: vec![false; model.n], rigid: false, position_tol: 1e-12, velocity_tol: 1e-10, max_iterations: 50 };
    let c = correct(&model, &mut data, 0.0, &model.q0, &model.qd0, &opts).expect("initial state corrects");
    let (q, qd) = (c.q, c.qd);
    let mut per_call = Vec::with_capacity(batches);
    for _ in 0..batches {
        let t0 = Instant::now();
        for _ in 0..CALLS {
            uk::acceleration(&model, &mut data, black_box(0.1), black_box(&q), black_box(&qd)).unwrap();
        }
        per_call.push(t0.elapsed().as_secs_f64() / CALLS as f64 * 1e9);
    }
    per_call.sort_by(|a, b| a.partial_cmp(b).unwrap());
    println!("{name:14} n {:3} m {:3} path {:?}: lowest batch {:8.1} ns, median {:8.1} ns", model.n, model.m, data.factored_with, per_call[0], per_call[batches / 2]);
}

/// Lowest batch per call of `f` (ns).
fn lowest(mut f: impl FnMut()) -> f64 {
    (0..BATCHES / 4)
        .map(|_| {
            let t0 = Instant::now();
            for _ in 0..CALLS {
                f();
            }
            t0.elapsed().as_secs_f64() / CALLS as f64 * 1e9
        })
        .fold(f64::INFINITY, f64::min)
}

/// The slider-crank's stages one by one (each on the state the full call left).
fn stages(json: &str) {
    let model = Model::from_json(json).expect("scene builds");
    let mut data = Data::new(&model);
    let opts = CorrectOptions { hold: vec![false; model.n], rigid: false, position_tol: 1e-12, velocity_tol: 1e-10, max_iterations: 50 };
    let c = correct(&model, &mut data, 0.0, &model.q0, &model.qd0, &opts).expect("initial state corrects");
    let (q, qd) = (c.q, c.qd);
    uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
    let d = &mut data;
    let mf = lowest(|| {
        dynamics::mass_and_forces(&model, d, black_box(0.1), black_box(&q), black_box(&qd));
        dynamics::factor_mass(&model, d).unwrap();
    });
    let cons = lowest(|| dynamics::constraints(&model, d, black_box(0.1), black_box(&q), black_box(&qd), false));
    let free = lowest(|| uk::free_acceleration(&model, d));
    let fac = lowest(|| uk::factor_constraints(&model, d).unwrap());
    let cor = lowest(|| uk::correct(&model, d));
    println!("stages: mass+factor {mf:.1}, constraints {cons:.1}, free {free:.1}, factor_constraints {fac:.1}, correct {cor:.1} ns");
}

fn main() {
    if std::env::args().any(|a| a == "stages") {
        stages(include_str!("data/spatial/slider_crank.json"));
        return;
    }
    if std::env::args().any(|a| a == "a05") {
        run("flyball", include_str!("data/spatial/flyball.json"), BATCHES);
        return;
    }
    let perf = std::env::args().any(|a| a == "perf");
    let one = perf || std::env::args().any(|a| a == "one");
    run("slider_crank", include_str!("data/spatial/slider_crank.json"), if perf { 10 * BATCHES } else { BATCHES });
    if !one {
        run("heavy_top", include_str!("data/spatial/heavy_top.json"), BATCHES);
        run("flyball", include_str!("data/spatial/flyball.json"), BATCHES / 4);
    }
}
