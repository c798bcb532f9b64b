//! The fixed step balanced against the error floor (issue 26, round i26-bal).
//!
//! Where the start sets the run's modes off and nothing else does (at rest with the mechanism
//! held, constant loads, no driver: [`floor::Excitation::at_rest`], [`SceneTraits::driven`]),
//! the history error of a fixed step `h` is the floor (the fast modes it damps) plus its own
//! error on the modes it resolves, both from the start's amplitudes `a_k` and the method's
//! `R(z)^j` ([`floor::Excitation`]). The rtol step resolves the lowest elastic mode to
//! `20 rtol` of its amplitude: far below a floor the run has anyway when the start rings the fast
//! modes hard (the pinned beam under sudden gravity). The step then grows while that sum stays
//! within [`BALANCE_SLACK`] of the rtol step's: the same history error at fewer steps.

use super::floor::Excitation;
use super::{MIN_STEPS, RADAU_MAX_STEP_OMEGA};
use crate::model::Model;

/// How much the history error (floor plus the resolved modes' error) may grow with the step.
pub const BALANCE_SLACK: f64 = 0.25;
/// The step's growth per trial, and the most it may grow.
const GROWTH: f64 = 1.189_207_115_002_721; // 2^(1/4)
const MAX_GROWTH: f64 = 4.0;

/// The longest step from `h` up (by [`GROWTH`], at most `MAX_GROWTH h`, the step caps of
/// [`super::resolving_step`]) whose floor plus resolved error stays within `1 + BALANCE_SLACK`
/// of `h`'s; `h` itself when the start sets nothing off.
pub fn balanced_step(model: &Model, ex: &Excitation, omega_c: f64, h: f64, span: f64) -> f64 {
    let (floor, resolved) = ex.history(model, h, span);
    if !(floor > 0.0) {
        return h;
    }
    let base = floor + resolved;
    let error = |h: f64| {
        let (f, r) = ex.history(model, h, span);
        f + r
    };

    let cap = (RADAU_MAX_STEP_OMEGA / omega_c).min(span / MIN_STEPS).min(MAX_GROWTH * h);
    let mut best = h;
    let mut next = h * GROWTH;
    while best < cap {
        let trial = next.min(cap);
        if error(trial) > (1.0 + BALANCE_SLACK) * base {
            break;
        }
        best = trial;
        next *= GROWTH;
    }
    best
}
