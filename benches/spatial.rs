//! Criterion benches of the spatial UK kernel per call (`uk::acceleration`) on the spatial
//! scenes of docs/spatial.md: the slider-crank, the heavy top, Bricard's mechanism (A04,
//! redundant: the rank-revealing fallback) and the flyball governor (A05), each at its
//! corrected initial state (t = 0.1), and the slider-crank's stages separately. The scene
//! descriptions are `benches/data/spatial/*.json`, written from the NumPy reference's scenes by
//! `benches/spatial_kernel.py --export`. Run: `cargo bench --bench spatial`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use ukflex::correct::{correct, CorrectOptions};
use ukflex::{dynamics, uk, Data, Model};

const SCENES: [(&str, &str); 4] = [
    ("slider_crank", include_str!("data/spatial/slider_crank.json")),
    ("heavy_top", include_str!("data/spatial/heavy_top.json")),
    ("bricard", include_str!("data/spatial/bricard.json")),
    ("flyball", include_str!("data/spatial/flyball.json")),
];

/// The model, its workspace and the initial state corrected as `ukflex.System` does.
fn scene(json: &str) -> (Model, Data, Vec<f64>, Vec<f64>) {
    let model = Model::from_json(json).expect("scene builds");
    let mut data = Data::new(&model);
    let opts = CorrectOptions { hold: vec![false; model.n], rigid: false, position_tol: 1e-12, velocity_tol: 1e-10, max_iterations: 50 };
    let c = correct(&model, &mut data, 0.0, &model.q0, &model.qd0, &opts).expect("initial state corrects");
    (model, data, c.q, c.qd)
}

fn config() -> Criterion {
    Criterion::default()
        .sample_size(40)
        .warm_up_time(Duration::from_millis(400))
        .measurement_time(Duration::from_millis(1500))
        .noise_threshold(0.05)
}

fn acceleration(c: &mut Criterion) {
    let mut g = c.benchmark_group("spatial");
    for (name, json) in SCENES {
        let (model, mut data, q, qd) = scene(json);
        g.bench_function(name, |b| b.iter(|| uk::acceleration(&model, &mut data, black_box(0.1), black_box(&q), black_box(&qd)).unwrap()));
    }
    let (model, _, q, qd) = scene(SCENES[0].1);
    let mut sparse = Data::build(&model, ukflex::UkSolver::Sparse, u64::MAX).unwrap();
    g.bench_function("slider_crank_sparse", |b| b.iter(|| uk::acceleration(&model, &mut sparse, black_box(0.1), black_box(&q), black_box(&qd)).unwrap()));
    g.finish();
}

fn stages(c: &mut Criterion) {
    let mut g = c.benchmark_group("spatial_slider_crank_stages");
    let (model, mut data, q, qd) = scene(SCENES[0].1);
    uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
    g.bench_function("mass_and_forces", |b| b.iter(|| dynamics::mass_and_forces(&model, &mut data, black_box(0.1), black_box(&q), black_box(&qd))));
    g.bench_function("constraints", |b| b.iter(|| dynamics::constraints(&model, &mut data, black_box(0.1), black_box(&q), black_box(&qd), false)));
    g.bench_function("factor_constraints", |b| b.iter(|| uk::factor_constraints(&model, &mut data).unwrap()));
    g.bench_function("correct", |b| b.iter(|| uk::correct(&model, &mut data)));
    g.finish();
}

criterion_group! { name = benches; config = config(); targets = acceleration, stages }
criterion_main!(benches);
