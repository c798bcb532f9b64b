//! Criterion benches of the UK acceleration: the paper's scene (N = 1, both beam theories),
//! the same scene with N = 2..64 coupler elements, the Euler-Bernoulli coupler as an FFRF beam
//! (linear and nonlinear strain) and as an ANCF cable at N = 1..64 (`coupler`), a chain of K = 2..64 rigid links, and the
//! stages separately. Run: `cargo bench --bench uk`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use ukflex::{dynamics, uk};

mod scenes;
use scenes::*;

fn config() -> Criterion {
    Criterion::default()
        .sample_size(40)
        .warm_up_time(Duration::from_millis(400))
        .measurement_time(Duration::from_millis(1500))
        .noise_threshold(0.05)
}

fn paper(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper_N1");
    for theory in ["timoshenko", "euler-bernoulli"] {
        let (model, mut data) = build(&paper_scene(theory, 1, true));
        let (q, qd) = bench_state(&model);
        g.bench_function(theory, |b| {
            b.iter(|| uk::acceleration(&model, &mut data, black_box(0.01), black_box(&q), black_box(&qd)).unwrap())
        });
    }
    g.finish();
}

fn elements(c: &mut Criterion) {
    let mut g = c.benchmark_group("elements");
    for n_el in [1usize, 2, 4, 8, 16, 32, 64] {
        let (model, mut data) = build(&paper_scene("timoshenko", n_el, true));
        let (q, qd) = bench_state(&model);
        g.bench_with_input(BenchmarkId::from_parameter(n_el), &n_el, |b, _| {
            b.iter(|| uk::acceleration(&model, &mut data, black_box(0.01), black_box(&q), black_box(&qd)).unwrap())
        });
    }
    g.finish();
}

fn coupler(c: &mut Criterion) {
    let mut g = c.benchmark_group("coupler");
    for n_el in [1usize, 2, 4, 8, 16, 32, 64] {
        let nonlinear = paper_scene("euler-bernoulli", n_el, true); // the core's default strain
        let linear = nonlinear.replace(r#""kind": "beam","#, r#""kind": "beam", "strain": "linear","#);
        for (kind, json) in [("ffrf-eb-linear", linear), ("ffrf-eb-nonlinear", nonlinear), ("ancf", ancf_paper_scene(n_el, true))] {
            let (model, mut data) = build(&json);
            let (q, qd) = bench_state(&model);
            g.bench_with_input(BenchmarkId::new(kind, n_el), &n_el, |b, _| {
                b.iter(|| uk::acceleration(&model, &mut data, black_box(0.01), black_box(&q), black_box(&qd)).unwrap())
            });
        }
    }
    g.finish();
}

fn chain(c: &mut Criterion) {
    let mut g = c.benchmark_group("chain");
    for k in [2usize, 4, 8, 16, 32, 64] {
        let (model, mut data) = build(&chain_scene(k));
        let (q, qd) = bench_state(&model);
        g.bench_with_input(BenchmarkId::from_parameter(k), &k, |b, _| {
            b.iter(|| uk::acceleration(&model, &mut data, black_box(0.0), black_box(&q), black_box(&qd)).unwrap())
        });
    }
    g.finish();
}

fn stages(c: &mut Criterion) {
    let mut g = c.benchmark_group("stages");
    for n_el in [1usize, 64] {
        let (model, mut data) = build(&paper_scene("timoshenko", n_el, true));
        let (q, qd) = bench_state(&model);
        let t = 0.01;
        uk::acceleration(&model, &mut data, t, &q, &qd).unwrap();
        g.bench_function(format!("N{n_el}/1_assembly_M_Q"), |b| {
            b.iter(|| dynamics::mass_and_forces(&model, &mut data, 0.0, black_box(&q), black_box(&qd)))
        });
        g.bench_function(format!("N{n_el}/2_assembly_A_b"), |b| {
            b.iter(|| dynamics::constraints(&model, &mut data, black_box(t), black_box(&q), black_box(&qd), false))
        });
        g.bench_function(format!("N{n_el}/3_factor_M"), |b| b.iter(|| dynamics::factor_mass(&model, &mut data).unwrap()));
        g.bench_function(format!("N{n_el}/4_free_accel"), |b| b.iter(|| uk::free_acceleration(&model, &mut data)));
        g.bench_function(format!("N{n_el}/5_BT_svd_rank"), |b| b.iter(|| uk::factor_constraints(&model, &mut data).unwrap()));
        g.bench_function(format!("N{n_el}/6_correction_multipliers"), |b| b.iter(|| uk::correct(&model, &mut data)));
    }
    g.finish();
}

criterion_group! { name = benches; config = config(); targets = paper, elements, coupler, chain, stages }
criterion_main!(benches);
