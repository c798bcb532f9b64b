//! The error floor of RADAU5M at a fixed step `h`: the free vibrations of the modes above
//! `omega_c` that the initial state sets off, which the step damps (or resolves badly) while
//! the physical motion keeps them; tightening rtol does not lower it (docs/integrators.md,
//! "Does auto honour rtol?").
//!
//! A mode `k` (mass-normalized `phi_k`, `omega_k`) starts off its quasi-static path by the
//! modal acceleration that sets it off over `omega_k^2` and oscillates about it with that
//! amplitude `a_k = |phi_k^T M (qdd(t0) - qdd_r)| / omega_k^2`, `qdd_r` the acceleration the
//! mechanism would have with no body deforming ([`rigidified_acceleration`]). Initial elastic
//! *velocities* are not counted. After `j` steps the method has `R(z)^j` of it where the
//! motion has `exp(z j)`, `z = h lambda_k`, `lambda_k = omega_k (-zeta_k + sqrt(zeta_k^2 - 1))`
//! with the mode's damping ratio: the error `a_k max_j |R^j - e^{z j}|` over the run, read at
//! the bodies' points ([`mode_displacements`]), summed over the modes.

use faer::Mat;

use crate::data::Data;
use crate::dynamics;
use crate::error::{Error, Result};
use crate::linalg::dense::pinv_solve;
use crate::model::Model;
use crate::uk;

use super::chains;
use super::spectrum::{damping_ratios, Spectrum};
use super::{SceneTraits, FLOOR_POINTS};

/// A floor at most this share of the model's length scale is the round-off of a start that sets
/// nothing off (1.7e-15 m on the right-angle cantilever, whose load starts from zero).
const ROUND_OFF_FLOOR: f64 = 1e-12;

#[derive(Clone, Copy)]
struct C(f64, f64);

impl C {
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn scale(self, s: f64) -> C {
        C(self.0 * s, self.1 * s)
    }
    fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        C((self.0 * o.0 + self.1 * o.1) / d, (self.1 * o.0 - self.0 * o.1) / d)
    }
}

/// Stability function of Radau IIA (3 stages, order 5): `R(z)`, `z = h lambda`.
fn radau_stability(z: C) -> C {
    let z2 = z.mul(z);
    let z3 = z2.mul(z);
    let num = C(1.0, 0.0).add(z.scale(2.0 / 5.0)).add(z2.scale(1.0 / 20.0));
    let den = C(1.0, 0.0).add(z.scale(-3.0 / 5.0)).add(z2.scale(3.0 / 20.0)).add(z3.scale(-1.0 / 60.0));
    num.div(den)
}

/// The steps at which the error is read: the first 32 and 64 more spread geometrically up to
/// the last (the curve is smooth in `j` where its phase error per step is small, and near its
/// bound where it is not).
fn sample_steps(steps: f64) -> Vec<f64> {
    let first = steps.min(32.0);
    let mut j: Vec<f64> = (1..=first as usize).map(|i| i as f64).collect();
    let (a, b) = (first.log10(), steps.log10());
    for i in 0..64 {
        let x = if i == 0 { first } else if i == 63 { steps } else { 10f64.powf(a + (b - a) * i as f64 / 63.0) };
        j.push(x.round_ties_even());
    }
    j
}

/// `max_j |R(z)^j - exp(z j)|` over the sampled steps, from moduli and phases (real arithmetic).
fn history_error(z: C, j: &[f64]) -> f64 {
    let r = radau_stability(z);
    let lr0 = r.0.hypot(r.1).ln();
    let dphase0 = r.1.atan2(r.0) - z.1;
    j.iter()
        .map(|&j| {
            let (lr, lz, dp) = (lr0 * j, z.0 * j, dphase0 * j);
            ((2.0 * lr).exp() + (2.0 * lz).exp() - 2.0 * (lr + lz).exp() * dp.cos()).max(0.0).sqrt()
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The acceleration at `(t0, q, qd)` of the motion in which no body deforms: the UK acceleration
/// restricted to the bodies' rigid motions (`Body::rigid_motions`: `qdd = B x + cen`; a beam's
/// node bodies as one body, [`chains::chain_motions`]), the constraints met in the least-squares sense (minimum-norm solution of the KKT system, SVD).
/// Leaves `M`, `Q` and `b` of `(t0, q, qd)` in `data`.
fn rigidified_acceleration(model: &Model, data: &mut Data, t0: f64, q: &[f64], qd: &[f64], mass: &[f64]) -> Result<Vec<f64>> {
    let (n, m) = (model.n, model.m);
    let mut entries = Vec::new();
    let mut cen = vec![0.0; n];
    let mut r = 0;
    let chains = chains::beam_chains(model);
    let mut first = vec![None; model.bodies.len()];
    for (c, chain) in chains.iter().enumerate() {
        for &b in chain {
            first[b] = Some((c, b == chain[0]));
        }
    }
    for (k, b) in model.bodies.iter().enumerate() {
        let put = &mut |i, j, x| entries.push((i, j, x));
        r += match first[k] {
            None => b.rigid_motions(q, qd, r, put, &mut cen),
            Some((c, true)) => chains::chain_motions(&model.bodies, &chains[c], q, qd, r, put, &mut cen),
            Some((_, false)) => 0,
        };
    }
    let mut basis = vec![0.0; n * r]; // row-major n x r
    for (i, j, x) in entries {
        basis[i * r + j] = x;
    }
    dynamics::mass_and_forces(model, data, t0, q, qd);
    dynamics::constraints(model, data, t0, q, qd, false);
    let mcen: Vec<f64> = (0..n).map(|i| (0..n).map(|j| mass[i * n + j] * cen[j]).sum()).collect();
    let mb: Vec<f64> = (0..n * r).map(|ij| {
        let (i, c) = (ij / r, ij % r);
        (0..n).map(|j| mass[i * n + j] * basis[j * r + c]).sum()
    }).collect();
    let mut a = vec![0.0; m * n];
    data.ajac.scatter(&mut a);
    let size = r + m;
    let mut kkt = Mat::<f64>::zeros(size, size);
    let mut rhs = vec![0.0; size];
    for c1 in 0..r {
        for c2 in 0..r {
            kkt[(c1, c2)] = (0..n).map(|i| basis[i * r + c1] * mb[i * r + c2]).sum();
        }
        rhs[c1] = (0..n).map(|i| basis[i * r + c1] * (data.force[i] - mcen[i])).sum();
    }
    for row in 0..m {
        let ar = &a[row * n..(row + 1) * n];
        for c in 0..r {
            let x: f64 = (0..n).map(|i| ar[i] * basis[i * r + c]).sum();
            kkt[(r + row, c)] = x;
            kkt[(c, r + row)] = x;
        }
        rhs[r + row] = data.gamma[row] - (0..n).map(|i| ar[i] * cen[i]).sum::<f64>();
    }
    // the KKT matrix is symmetric: its pseudoinverse solve from the transposed form is the same
    let x = pinv_solve(&kkt, &rhs).map_err(|e| Error::Solver(format!("method='auto': the rigidified motion's SVD failed ({e:?})")))?;
    Ok((0..n).map(|i| cen[i] + (0..r).map(|c| basis[i * r + c] * x[c]).sum::<f64>()).collect())
}

/// Largest displacement of a beam point per unit modal coordinate, one per mode in `modes`:
/// central differences of `Body::beam_point` at [`FLOOR_POINTS`] (planar beams), and the
/// geometrically exact beams' node positions ([`chains::node_displacement`]).
fn mode_displacements(model: &Model, q: &[f64], sp: &Spectrum, modes: &[usize]) -> Result<Vec<f64>> {
    let n = model.n;
    let mut out = vec![0.0f64; modes.len()];
    for chain in chains::beam_chains(model) {
        for (o, &k) in modes.iter().enumerate() {
            out[o] = out[o].max(chains::node_displacement(&model.bodies, &chain, sp.mode(k)));
        }
    }
    let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
    for body in model.bodies.iter().filter(|b| b.capabilities().beam) {
        for (o, &k) in modes.iter().enumerate() {
            let s = sp.mode(k);
            let scale = s.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let eps = 1e-7 / if scale > 0.0 { scale } else { 1.0 };
            for i in 0..n {
                plus[i] = q[i] + s[i] * eps;
                minus[i] = q[i] - s[i] * eps;
            }
            for &xi in &FLOOR_POINTS {
                let (p, m) = (body.beam_point(xi, &plus)?, body.beam_point(xi, &minus)?);
                out[o] = f64::max(out[o], (p[0] - m[0]).hypot(p[1] - m[1]) / (2.0 * eps));
            }
        }
    }
    Ok(out)
}

/// The floor [m] (largest displacement error of a beam point) and its three largest
/// contributions `(omega, amplitude of the body point, error)`.
pub fn transient_floor(model: &Model, data: &mut Data, traits: SceneTraits, t0: f64, q: &[f64], qd: &[f64], sp: &Spectrum, omega_c: f64, h: f64, span: f64) -> Result<(f64, Vec<[f64; 3]>)> {
    let n = model.n;
    let fast: Vec<usize> = (0..sp.len()).filter(|&k| sp.omega[k] > omega_c * (1.0 + 1e-9)).collect();
    if fast.is_empty() {
        return Ok((0.0, Vec::new()));
    }
    dynamics::mass_and_forces(model, data, t0, q, qd);
    let mass = dynamics::dense_mass(model, data);
    uk::acceleration(model, data, t0, q, qd)?;
    let qdd = data.qdd.clone();
    let rigid = rigidified_acceleration(model, data, t0, q, qd, &mass)?;
    let excite: Vec<f64> = (0..n).map(|i| qdd[i] - rigid[i]).collect();
    let mexc: Vec<f64> = (0..n).map(|i| (0..n).map(|j| mass[i * n + j] * excite[j]).sum()).collect();
    let zeta = if traits.damped {
        let is_fast = |k: usize| sp.omega[k] > omega_c * (1.0 + 1e-9);
        damping_ratios(model, data, t0, q, qd, sp, &mass, &is_fast)?
    } else {
        vec![0.0; sp.len()]
    };
    let j = sample_steps((span / h).ceil().max(1.0));
    let d = mode_displacements(model, q, sp, &fast)?;
    let mut parts: Vec<(f64, f64, f64)> = Vec::with_capacity(fast.len());
    for (o, &k) in fast.iter().enumerate() {
        let w = sp.omega[k];
        let s = sp.mode(k);
        let amp = (0..n).map(|i| s[i] * mexc[i]).sum::<f64>().abs() / (w * w);
        let zt = zeta[k];
        // the physical motion decays as exp(lambda t): under-damped, the oscillating root; over, the slow one
        let disc = zt * zt - 1.0;
        let lam = if disc >= 0.0 { C(w * (-zt + disc.sqrt()), 0.0) } else { C(-w * zt, w * (-disc).sqrt()) };
        let err = history_error(lam.scale(h), &j);
        parts.push((w, amp * d[o], amp * err * d[o]));
    }
    let total: f64 = parts.iter().map(|p| p.2).sum();
    // what the start sets off is round-off (a load or a drive starting from rest): no floor
    if total <= ROUND_OFF_FLOOR * model.length_scale {
        return Ok((0.0, Vec::new()));
    }
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by(|&a, &b| parts[b].2.total_cmp(&parts[a].2));
    let top = order.into_iter().take(3).filter(|&k| parts[k].2 > 0.0).map(|k| [parts[k].0, parts[k].1, parts[k].2]).collect();
    Ok((total, top))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::choice::RADAU_DECAY;

    #[test]
    fn the_decay_constant_is_the_stability_function_on_the_imaginary_axis() {
        // 1 - |R(i y)| = RADAU_DECAY y^6 to 10 % for y up to 1 (1.39e-4 at 0.1, 1.31e-4 at 1)
        for y in [0.1, 0.3, 1.0] {
            let r = radau_stability(C(0.0, y));
            let loss = (1.0 - r.0.hypot(r.1)) / y.powi(6);
            assert!((loss / RADAU_DECAY - 1.0).abs() < 0.1, "y = {y}: {loss}");
        }
    }

    #[test]
    fn the_sampled_steps_start_with_every_step_and_end_at_the_last() {
        let j = sample_steps(307.0);
        assert_eq!(&j[..32], &(1..=32).map(|i| i as f64).collect::<Vec<_>>()[..]);
        assert_eq!(*j.last().unwrap(), 307.0);
        assert!(j.windows(2).skip(32).all(|w| w[1] >= w[0]));
        assert_eq!(sample_steps(5.0).iter().fold(0.0f64, |m, &x| m.max(x)), 5.0);
    }

    #[test]
    fn the_history_error_of_a_resolved_a_fast_and_an_unresolved_mode() {
        let j = sample_steps(1000.0);
        // a decay far beyond the step: the motion loses it at once, the method keeps |R| ~ 3/|z|
        // of it for a step (L-stable)
        let e = history_error(C(-1e3, 0.0), &j);
        assert!(e > 2e-3 && e < 4e-3, "{e}");
        // a resolved undamped mode (0.01 rad per step): the method follows it
        assert!(history_error(C(0.0, 0.01), &j) < 1e-9);
        // an undamped mode at 10 rad per step: the method damps it, the motion keeps it (error ~1)
        let e = history_error(C(0.0, 10.0), &j);
        assert!(e > 0.9 && e < 2.0 + 1e-12, "{e}");
    }
}
