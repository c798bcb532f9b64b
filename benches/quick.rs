//! A quick, noise-robust timing table (not criterion): for each case, 101 batches of calls,
//! reporting the minimum and the median time per call over the batches. On a shared machine
//! the minimum is the better estimate of the cost of the code; the median is what criterion
//! would report. Run: `cargo bench --bench quick` (about 20 s).

use std::hint::black_box;
use std::time::Instant;

use ukflex::{dynamics, uk};

mod scenes;
use scenes::*;

fn time(mut f: impl FnMut()) -> (f64, f64) {
    // calibrate a batch to ~200 us
    let mut reps = 1usize;
    loop {
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        if t.elapsed().as_secs_f64() > 2e-4 || reps > 1 << 24 {
            break;
        }
        reps *= 2;
    }
    let mut v: Vec<f64> = (0..101)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..reps {
                f();
            }
            t.elapsed().as_secs_f64() / reps as f64
        })
        .collect();
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    (v[0], v[50])
}

fn row(name: &str, (min, med): (f64, f64)) {
    println!("{name:<40} min {:>10.1} ns   median {:>10.1} ns", min * 1e9, med * 1e9);
}

fn main() {
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-')).unwrap_or_default();
    let want = |name: &str| name.contains(&filter);
    for theory in ["timoshenko", "euler-bernoulli"] {
        let name = format!("paper N=1 {theory}");
        if !want(&name) {
            continue;
        }
        let (model, mut data) = build(&paper_scene(theory, 1, true));
        let (q, qd) = bench_state(&model);
        row(&name, time(|| uk::acceleration(&model, &mut data, black_box(0.01), black_box(&q), black_box(&qd)).unwrap()));
    }
    let mut fit = Vec::new();
    for n_el in [1usize, 2, 4, 8, 16, 32, 64] {
        let name = format!("elements N={n_el}");
        if !want(&name) {
            continue;
        }
        let (model, mut data) = build(&paper_scene("timoshenko", n_el, true));
        let (q, qd) = bench_state(&model);
        let r = time(|| uk::acceleration(&model, &mut data, black_box(0.01), black_box(&q), black_box(&qd)).unwrap());
        row(&format!("{name} (n={})", model.n), r);
        fit.push((n_el as f64, r.0));
    }
    if fit.len() > 2 {
        // least-squares slope of log(time) vs log(N) over N >= 4 (and over all)
        let slope = |pts: &[(f64, f64)]| {
            let k = pts.len() as f64;
            let (sx, sy) = pts.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x.ln(), b + y.ln()));
            let (mx, my) = (sx / k, sy / k);
            let num: f64 = pts.iter().map(|(x, y)| (x.ln() - mx) * (y.ln() - my)).sum();
            let den: f64 = pts.iter().map(|(x, _)| (x.ln() - mx).powi(2)).sum();
            num / den
        };
        let tail: Vec<_> = fit.iter().copied().filter(|(x, _)| *x >= 8.0).collect();
        println!("growth exponent (min times): N=1..64 {:.2}, N=8..64 {:.2}", slope(&fit), slope(&tail));
    }
    for n_el in [1usize, 2, 4, 8, 16, 32, 64] {
        let name = format!("coupler N={n_el}");
        if !want(&name) {
            continue;
        }
        let mut per = Vec::new();
        let nonlinear = paper_scene("euler-bernoulli", n_el, true); // the core's default strain
        let linear = nonlinear.replace(r#""kind": "beam","#, r#""kind": "beam", "strain": "linear","#);
        for (kind, json) in [("ffrf-eb linear", linear), ("ffrf-eb nonlinear", nonlinear), ("ancf", ancf_paper_scene(n_el, true))] {
            let (model, mut data) = build(&json);
            let (q, qd) = bench_state(&model);
            let r = time(|| uk::acceleration(&model, &mut data, black_box(0.01), black_box(&q), black_box(&qd)).unwrap());
            row(&format!("{name} {kind} (n={})", model.n), r);
            per.push(r.0);
        }
        println!("{:<40} (min) nonlinear / linear {:.2}, ancf / nonlinear {:.2}", "", per[1] / per[0], per[2] / per[1]);
    }
    let mut fit = Vec::new();
    for k in [2usize, 4, 8, 16, 32, 64] {
        let name = format!("chain K={k}");
        if !want(&name) {
            continue;
        }
        let (model, mut data) = build(&chain_scene(k));
        let (q, qd) = bench_state(&model);
        let r = time(|| uk::acceleration(&model, &mut data, black_box(0.0), black_box(&q), black_box(&qd)).unwrap());
        row(&format!("{name} (n={}, m={})", model.n, model.m), r);
        fit.push((k as f64, r.0));
    }
    if fit.len() > 2 {
        let k = fit.len() as f64;
        let (sx, sy) = fit.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x.ln(), b + y.ln()));
        let (mx, my) = (sx / k, sy / k);
        let num: f64 = fit.iter().map(|(x, y)| (x.ln() - mx) * (y.ln() - my)).sum();
        let den: f64 = fit.iter().map(|(x, _)| (x.ln() - mx).powi(2)).sum();
        println!("chain growth exponent (min times): {:.2}", num / den);
    }
    for (n_el, kind, json) in [(1usize, "", paper_scene("timoshenko", 1, true)), (64, "", paper_scene("timoshenko", 64, true)), (64, " ancf", ancf_paper_scene(64, true))] {
        let name = format!("stages N={n_el}{kind}");
        if !want(&name) {
            continue;
        }
        let (model, mut data) = build(&json);
        let (q, qd) = bench_state(&model);
        let t = 0.01;
        uk::acceleration(&model, &mut data, t, &q, &qd).unwrap();
        row(&format!("{name} 1 assembly M, Q"), time(|| dynamics::mass_and_forces(&model, &mut data, 0.0, black_box(&q), black_box(&qd))));
        row(&format!("{name} 2 assembly A, b"), time(|| dynamics::constraints(&model, &mut data, black_box(t), black_box(&q), black_box(&qd), false)));
        row(&format!("{name} 3 factor M"), time(|| dynamics::factor_mass(&model, &mut data).unwrap()));
        row(&format!("{name} 4 free acceleration"), time(|| uk::free_acceleration(&model, &mut data)));
        row(&format!("{name} 5 B^T, QR/SVD, rank"), time(|| uk::factor_constraints(&model, &mut data).unwrap()));
        row(&format!("{name} 6 correction, multipliers"), time(|| uk::correct(&model, &mut data)));
    }
}
