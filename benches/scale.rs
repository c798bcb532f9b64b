//! Scale: the UK acceleration of a chain of K rigid links (n = 3K, m = 2K) with the automatic
//! path for K = 2..1024 (sparse from K = 4 on, see `data::SPARSE_MIN_ROWS`), and the dense
//! and sparse paths forced side by side at K = 4..64 (the crossover). Run:
//! `cargo bench --bench scale` (docs/scale.md).

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use ukflex::{uk, Data, Model, UkSolver};

mod scenes;
use scenes::*;

fn config() -> Criterion {
    Criterion::default()
        .sample_size(30)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_millis(1200))
        .noise_threshold(0.05)
}

fn with_solver(k: usize, solver: UkSolver) -> (Model, Data) {
    let model = Model::from_json(&chain_scene(k)).expect("scene builds");
    let data = Data::build(&model, solver, u64::MAX).expect("workspace");
    (model, data)
}

fn chain_auto(c: &mut Criterion) {
    let mut g = c.benchmark_group("scale_chain_auto");
    for k in [2usize, 4, 8, 16, 32, 64, 128, 256, 512, 1024] {
        let (model, mut data) = with_solver(k, UkSolver::Auto);
        let (q, qd) = bench_state(&model);
        g.bench_with_input(BenchmarkId::from_parameter(k), &k, |b, _| {
            b.iter(|| uk::acceleration(&model, &mut data, black_box(0.0), black_box(&q), black_box(&qd)).unwrap())
        });
    }
    g.finish();
}

fn dense_vs_sparse(c: &mut Criterion) {
    let mut g = c.benchmark_group("scale_dense_vs_sparse");
    for k in [4usize, 8, 16, 32, 64] {
        for (name, solver) in [("dense", UkSolver::Dense), ("sparse", UkSolver::Sparse)] {
            let (model, mut data) = with_solver(k, solver);
            let (q, qd) = bench_state(&model);
            uk::acceleration(&model, &mut data, 0.0, &q, &qd).unwrap();
            assert_eq!(data.uk_path(), name, "K={k}: the {name} path must run");
            g.bench_with_input(BenchmarkId::new(name, k), &k, |b, _| {
                b.iter(|| uk::acceleration(&model, &mut data, black_box(0.0), black_box(&q), black_box(&qd)).unwrap())
            });
        }
    }
    g.finish();
}

criterion_group! { name = benches; config = config(); targets = dense_vs_sparse, chain_auto }
criterion_main!(benches);
