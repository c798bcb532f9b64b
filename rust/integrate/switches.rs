//! The times at which a model's loads have kinks or jumps: a fixed step that straddles one
//! integrates a load that is not smooth inside it, and the collocation loses its order there.
//! On Simo and Vu-Quoc's right-angle cantilever (a triangular pulse `0 -> 50 -> 0` over 2 s, an
//! expression with `abs`), RADAU5M at a fixed 0.0826 s step was 1.0e-3 m off a tight run, at
//! 0.1 s (which lands on the kinks) 1.8e-5 m (`benches/beam3_floor.py --steps`): the fixed-step
//! RADAU5M ends a step at each (`RadauM::with_stops`).

use crate::model::Model;

/// Samples of each load's expression over the run: kinks closer together than the run's
/// `1 / SWITCH_SAMPLES` may be missed.
pub const SWITCH_SAMPLES: usize = 4096;

/// The kinks and jumps in `(t0, t_end)` of the loads that are expressions of `t` alone (an
/// `abs` or `sign` whose argument changes sign), sorted, each once. Drivers' motions and loads
/// of the state are not read.
pub fn load_switches(model: &Model, t0: f64, t_end: f64) -> Vec<f64> {
    let mut out: Vec<f64> = model.forces.iter().flat_map(|f| f.values()).flat_map(|v| v.time_switches(t0, t_end, SWITCH_SAMPLES)).collect();
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * (t_end - t0));
    out
}
