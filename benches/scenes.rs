//! Scenes shared by the benches: the paper's slider-crank (from the cargo tests' builders)
//! and a chain of K rigid links (a K-link pendulum).
#![allow(dead_code)]

#[path = "../tests/common/mod.rs"]
mod common;
#[allow(unused_imports)] // each bench uses its own subset
pub use common::{ancf_paper_scene, chain_scene, paper_scene, Lcg};

use ukflex::{Data, Model};

/// A representative (not exactly consistent) state: the initial guess with a small elastic
/// deformation, a small elastic rate and, for chains, a bent configuration. The cost of a call
/// does not depend on consistency; the SVD's work depends mildly on the matrix.
pub fn bench_state(model: &Model) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Lcg(42);
    let (mut q, mut qd) = (model.q0.clone(), model.qd0.clone());
    for b in &model.bodies {
        let o = b.offset;
        if b.n_coords == 3 && model.constraints.iter().all(|c| !c.is_driver()) {
            q[o + 2] += 0.3 * rng.next();
            qd[o + 2] += rng.next();
        }
        for j in 3..b.n_coords {
            q[o + j] += 1e-5 * rng.next();
            qd[o + j] += 1e-2 * rng.next();
        }
    }
    (q, qd)
}

pub fn build(json: &str) -> (Model, Data) {
    let model = Model::from_json(json).expect("scene builds");
    let data = Data::new(&model);
    (model, data)
}
