//! The small dense algebra of the UK pseudoinverse, measured on the actual `B^T = F^-1 A^T`
//! (n x m) of the paper scene (N = 1, 16, 64: m = 6) and of a 16-link chain (48 x 32):
//! faer's SVD through its scratch API (allocation free), faer's high-level `thin_svd`
//! (allocates), nalgebra's SVD (allocates), and the QR + one-sided Jacobi kernel of
//! `small_svd`, and the QR with the certified full-rank test that `SvdBackend::Auto` uses in
//! place of an SVD when no singular value can be near the tolerance. Also the whole UK acceleration with each in-tree backend.
//! Run: `cargo bench --bench svd`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::svd::{svd, svd_scratch, ComputeSvdVectors};
use faer::{diag::Diag, Mat, Par};
use ukflex::linalg::small_svd::QrJacobi;
use ukflex::{uk, SvdBackend};

mod scenes;
use scenes::*;

fn config() -> Criterion {
    Criterion::default()
        .sample_size(30)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_millis(1000))
}

fn cases() -> Vec<(String, String)> {
    vec![
        ("paper_N1".into(), paper_scene("timoshenko", 1, true)),
        ("paper_N16".into(), paper_scene("timoshenko", 16, true)),
        ("paper_N64".into(), paper_scene("timoshenko", 64, true)),
        ("chain_K16".into(), chain_scene(16)),
    ]
}

fn svd_alternatives(c: &mut Criterion) {
    let mut g = c.benchmark_group("svd");
    for (name, json) in cases() {
        let (model, mut data) = build(&json);
        let (q, qd) = bench_state(&model);
        uk::acceleration(&model, &mut data, 0.01, &q, &qd).unwrap();
        let bt: Mat<f64> = data.bt.clone();
        let (n, m) = (bt.nrows(), bt.ncols());
        let k = n.min(m);

        let mut s = Diag::<f64>::zeros(k);
        let mut u = Mat::<f64>::zeros(n, k);
        let mut v = Mat::<f64>::zeros(m, k);
        let mut mem = MemBuffer::new(svd_scratch::<f64>(n, m, ComputeSvdVectors::Thin, ComputeSvdVectors::Thin, Par::Seq, Default::default()));
        g.bench_function(format!("{name}/faer_scratch"), |b| {
            b.iter(|| {
                svd(black_box(bt.as_ref()), s.as_mut(), Some(u.as_mut()), Some(v.as_mut()), Par::Seq, MemStack::new(&mut mem), Default::default()).unwrap()
            })
        });
        g.bench_function(format!("{name}/faer_thin_svd"), |b| b.iter(|| black_box(&bt).thin_svd().unwrap()));
        let na = nalgebra::DMatrix::<f64>::from_fn(n, m, |i, j| bt[(i, j)]);
        g.bench_function(format!("{name}/nalgebra_svd"), |b| b.iter(|| nalgebra::SVD::new(black_box(na.clone()), true, true)));
        let mut qrj = QrJacobi::new(n, m);
        g.bench_function(format!("{name}/qr_jacobi"), |b| b.iter(|| assert!(qrj.factor_cols(|j| black_box(&bt).col_as_slice(j)))));
        g.bench_function(format!("{name}/qr_certified_full_rank"), |b| {
            b.iter(|| {
                qrj.qr_cols(|j| black_box(&bt).col_as_slice(j));
                qrj.full_rank_bounds()
            })
        });
        qrj.factor_cols(|j| bt.col_as_slice(j));
        println!("{name}: n = {n}, m = {m}, Jacobi sweeps = {}", qrj.sweeps);
    }
    g.finish();
}

fn uk_backends(c: &mut Criterion) {
    let mut g = c.benchmark_group("uk_backend");
    for (name, json) in cases() {
        let (model, mut data) = build(&json);
        let (q, qd) = bench_state(&model);
        for (bname, backend) in [("faer", SvdBackend::Faer), ("qr_jacobi", SvdBackend::QrJacobi), ("auto_certified_qr", SvdBackend::Auto)] {
            data.svd_backend = backend;
            g.bench_function(format!("{name}/{bname}"), |b| {
                b.iter(|| uk::acceleration(&model, &mut data, black_box(0.01), black_box(&q), black_box(&qd)).unwrap())
            });
        }
    }
    g.finish();
}

criterion_group! { name = benches; config = config(); targets = svd_alternatives, uk_backends }
criterion_main!(benches);
