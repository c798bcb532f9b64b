//! Adaptive RADAU5M when overdamped modes make an explicit step short: stiff dampers (MBS
//! benchmark A05: spring-dampers with `C = 4e4` N s/m) turn a mode of frequency `omega` and
//! damping ratio `zeta > 1` into a fast decay `omega (zeta + sqrt(zeta^2 - 1))` that bounds
//! DOPRI5's step to `DOPRI5_REAL_STABILITY` over it, and a slow one `omega (zeta - sqrt(zeta^2 -
//! 1))`, the motion left to resolve. The undamped frequencies miss both. When the step that the
//! motion needs (the fixed-step rule on the modes' slow rates) exceeds `RADAU_COST_RATIO`
//! explicit steps, Radau IIA with its own error control is cheaper: the fast decays die out
//! within a step (L-stable) and its error estimate sees them die. Small systems only (every
//! mode known).

use crate::data::Data;
use crate::dynamics;
use crate::error::Result;
use crate::model::Model;

use super::spectrum::{damping_ratios, lowest_elastic_of, lowest_per_body_of, Shares, Spectrum};
use super::{resolving_step, AutoChoice, OverdampedMode, Verdict, DOPRI5_REAL_STABILITY, RADAU_COST_RATIO};

/// Whether the mode at `omega_c` (the lowest elastic one, which the fixed-step rule would
/// resolve) is overdamped: it does not oscillate, and the motion left to resolve is its slow
/// decay. A05 at rtol 1e-3: the fixed step resolved its 171.6 rad/s (zeta > 1) in 403 steps, 25
/// ms CPU; adaptive RADAU5M takes ~100 (docs/spatial.md).
pub fn decides(model: &Model, data: &mut Data, t0: f64, q: &[f64], qd: &[f64], sp: &Spectrum, omega_c: f64) -> Result<bool> {
    let Some(kc) = (0..sp.len()).find(|&k| sp.omega[k] == omega_c) else {
        return Ok(false);
    };
    dynamics::mass_and_forces(model, data, t0, q, qd);
    let mass = dynamics::dense_mass(model, data);
    let zeta = damping_ratios(model, data, t0, q, qd, sp, &mass, &|k| k == kc)?;
    Ok(zeta[kc] > 1.0)
}

/// `Some` adaptive RADAU5M choice when overdamped modes make the scene stiff.
pub fn choice(model: &Model, data: &mut Data, t0: f64, q: &[f64], qd: &[f64], sp: &Spectrum, shares: &mut Shares, phase: f64, span: f64) -> Result<Option<AutoChoice>> {
    dynamics::mass_and_forces(model, data, t0, q, qd);
    let mass = dynamics::dense_mass(model, data);
    let zeta = damping_ratios(model, data, t0, q, qd, sp, &mass, &|_| true)?;
    if !zeta.iter().any(|&z| z > 1.0) {
        return Ok(None);
    }
    // (fast, slow) decay rates of the overdamped modes; omega for the others
    let roots: Vec<(f64, f64)> = (0..sp.len())
        .map(|k| {
            let w = sp.omega[k].abs();
            if zeta[k] > 1.0 {
                let r = (zeta[k] * zeta[k] - 1.0).max(0.0).sqrt();
                (w * (zeta[k] + r), w * (zeta[k] - r))
            } else {
                (w, w)
            }
        })
        .collect();
    let slow: Vec<f64> = (0..sp.len()).map(|k| if sp.omega[k] > 0.0 { roots[k].1 } else { sp.omega[k] }).collect();
    let per_body = lowest_per_body_of(model, data, q, sp, &slow, shares);
    let Some(omega_m) = lowest_elastic_of(&slow, shares, &per_body) else {
        return Ok(None);
    };
    let h = resolving_step(omega_m, phase, span);
    // the fastest overdamped decay (the first of equal ones)
    let mut kmax = 0;
    let mut fmax = 0.0;
    for k in 0..sp.len() {
        let f = if zeta[k] > 1.0 { roots[k].0 } else { 0.0 };
        if f > fmax {
            fmax = f;
            kmax = k;
        }
    }
    let h_explicit = DOPRI5_REAL_STABILITY / fmax;
    if h <= RADAU_COST_RATIO * h_explicit {
        return Ok(None);
    }
    Ok(Some(AutoChoice {
        verdict: Verdict::Overdamped,
        method: "RADAU5M",
        omega_elastic: Some(omega_m),
        omega_max: fmax,
        step: Some(h),
        newton_rtol: None,
        phase,
        floor: None,
        floor_modes: Vec::new(),
        overdamped: Some(OverdampedMode { omega: sp.omega[kmax], zeta: zeta[kmax], fast: roots[kmax].0, h_explicit }),
    }))
}
