//! The loop of joint friction closed in each acceleration call (docs/loads.md, "Joint
//! friction"). A friction force `F_i = -k_i s_i N_i(lambda) - c_i v_i` (`force::friction`)
//! depends on its joint's multipliers, which depend on every friction force. At fixed
//! `(t, q, qd)` the UK solution is affine in a generalized force: with `g_i` the friction's
//! generalized direction,
//!
//! `qdd = qdd_0 + sum_j F_j u_j`, `lambda = lambda_0 + sum_j F_j l_j`,
//!
//! `(qdd_0, lambda_0)` the solution without friction and `(u_j, l_j)` the response to the
//! unit force `g_j` (the same factorization of `B^T`, `b = 0`: one correction each). So the
//! coupled problem is `n_f` equations in the `n_f` friction forces,
//! `R_i(F) = F_i + k_i s_i N_i(lambda_0 + sum_j F_j l_j) + c_i v_i = 0`, solved by Newton's
//! method (`N_i` is piecewise smooth: the Newton steps are exact on each piece) to
//! `|R_i| <= CLOSURE_RTOL (|F_i| + k_i |s_i| N_i(lambda_0) + c_i |v_i|)`, at most
//! `CLOSURE_MAX_ITER` iterations, else an error. It is solvable with one solution when the
//! friction cannot raise its own normal force faster than it grows, `k_i |s_i| |l_ii| < 1`
//! (a single element); a singular Newton matrix is reported (Painleve's paradox of rigid
//! bodies with Coulomb friction).
//!
//! Cost: `n_f` extra corrections (two block-triangular solves and one pass over the
//! factorization each) and an `n_f x n_f` Newton loop, nothing allocated; scenes without
//! friction pay one `Option` check.

use super::{correct, settings::Factored};
use crate::data::Data;
use crate::dynamics::{apply_finv, apply_finvt};
use crate::error::{Error, Result};
use crate::force::friction::FrictionWork;
use crate::model::Model;

/// Relative tolerance of the closure's residual (the friction forces to rounding).
pub const CLOSURE_RTOL: f64 = 1e-12;
/// Newton iterations before the closure reports failure.
pub const CLOSURE_MAX_ITER: usize = 50;

/// After a UK solve of the terms without friction (`uk::solve`; called by the acceleration
/// functions, never by the projections' minimum-norm steps) (`data.qdd`, `data.lambda`, the factorization
/// of `B^T`): close the friction loop, leaving the solution with friction in `data.qdd`,
/// `data.lambda`, the friction forces added to `data.force` and in `FrictionWork::f`.
/// `reuse`: the responses `(u_j, l_j)` of the last closure are still valid (same `q`, same
/// factorization: the velocity columns of a finite-difference Jacobian). Nothing without
/// friction elements. Out of line (`cold`): the scenes without friction keep their hot path.
#[cold]
#[inline(never)]
pub fn close(model: &Model, data: &mut Data, reuse: bool) -> Result<()> {
    let Some(mut w) = data.friction.take() else { return Ok(()) };
    let t = data.t_forces;
    let out = close_with(model, data, &mut w, t, reuse);
    data.friction = Some(w);
    out
}

fn close_with(model: &Model, data: &mut Data, w: &mut FrictionWork, t: f64, reuse: bool) -> Result<()> {
    let (n, m, k) = (model.n, model.m, w.items.len());
    w.qdd0.copy_from_slice(&data.qdd);
    w.lam0.copy_from_slice(&data.lambda);
    if !reuse {
        responses(model, data, w);
    }
    solve_forces(model, w, t)?;
    data.qdd.copy_from_slice(&w.qdd0);
    data.lambda.copy_from_slice(&w.lam0);
    for i in 0..k {
        let f = w.f[i];
        for (x, u) in data.qdd.iter_mut().zip(&w.dqdd[i * n..(i + 1) * n]) {
            *x += f * u;
        }
        for (x, l) in data.lambda.iter_mut().zip(&w.dlam[i * m..(i + 1) * m]) {
            *x += f * l;
        }
    }
    w.add_closed_forces(&mut data.force);
    Ok(())
}

/// `(u_j, l_j)`: the UK response to the generalized force `g_j` with `b = 0`, from the
/// factorization in `data` (overwrites `y`, `qdd_free`, `residual`; `gamma` is kept).
fn responses(model: &Model, data: &mut Data, w: &mut FrictionWork) {
    let (n, m) = (model.n, model.m);
    w.gamma.copy_from_slice(&data.gamma);
    data.gamma.fill(0.0);
    for i in 0..w.items.len() {
        data.y.copy_from_slice(&w.g[i * n..(i + 1) * n]);
        apply_finv(model, &data.bodies, &mut data.y);
        data.qdd_free.copy_from_slice(&data.y);
        apply_finvt(model, &data.bodies, &mut data.qdd_free);
        if m == 0 || data.factored_with == Factored::None {
            data.qdd.copy_from_slice(&data.qdd_free);
            data.lambda.fill(0.0);
        } else {
            correct(model, data);
        }
        w.dqdd[i * n..(i + 1) * n].copy_from_slice(&data.qdd);
        w.dlam[i * m..(i + 1) * m].copy_from_slice(&data.lambda);
    }
    data.gamma.copy_from_slice(&w.gamma);
}

/// Newton's method on `R(F) = 0` (module doc), starting from the friction of the reactions
/// without friction (a single pass); the multipliers of an iterate are formed in `w.gamma`.
fn solve_forces(model: &Model, w: &mut FrictionWork, t: f64) -> Result<()> {
    let (m, k) = (model.m, w.items.len());
    let forces = &model.forces;
    for i in 0..k {
        w.f[i] = w.force_at(forces, i, &w.lam0).0;
    }
    for iter in 0..=CLOSURE_MAX_ITER {
        // lambda(F) into w.gamma (a scratch of length m here)
        w.gamma.copy_from_slice(&w.lam0);
        for j in 0..k {
            let f = w.f[j];
            for (x, l) in w.gamma.iter_mut().zip(&w.dlam[j * m..(j + 1) * m]) {
                *x += f * l;
            }
        }
        let mut converged = true;
        for i in 0..k {
            let (phi, slope, grad) = w.force_at(forces, i, &w.gamma);
            let scale = w.f[i].abs() + w.force_at(forces, i, &w.lam0).0.abs() + phi.abs();
            w.res[i] = w.f[i] - phi;
            converged &= w.res[i].abs() <= CLOSURE_RTOL * scale;
            // dR_i/dF_j = delta_ij - slope grad . l_j[rows of i]
            let (r0, rows) = (w.items[i].1, w.rows[i]);
            for j in 0..k {
                let l = &w.dlam[j * m + r0..j * m + r0 + rows];
                let d: f64 = grad.iter().zip(l).map(|(a, b)| a * b).sum();
                w.jac[i * k + j] = if i == j { 1.0 } else { 0.0 } - slope * d;
            }
        }
        w.iterations = iter;
        if converged {
            return Ok(());
        }
        if iter == CLOSURE_MAX_ITER {
            break;
        }
        if !gauss_solve(&mut w.jac, &mut w.res, k) {
            return Err(Error::Solver(format!(
                "joint friction at t = {t}: the friction forces raise their own normal forces as fast as they grow (singular closure; Painleve's paradox of Coulomb friction): lower mu or the pin radius"
            )));
        }
        for i in 0..k {
            w.f[i] -= w.res[i];
        }
    }
    Err(Error::Solver(format!("joint friction at t = {t}: the closure of the friction forces with the reactions did not converge in {CLOSURE_MAX_ITER} Newton iterations")))
}

/// `x <- J^-1 x` by Gaussian elimination with partial pivoting (`J` k x k row-major,
/// overwritten); false when a pivot vanishes.
fn gauss_solve(a: &mut [f64], x: &mut [f64], k: usize) -> bool {
    for c in 0..k {
        let p = (c..k).max_by(|&i, &j| a[i * k + c].abs().total_cmp(&a[j * k + c].abs())).expect("non-empty");
        if !(a[p * k + c].abs() > 1e-12) {
            return false;
        }
        if p != c {
            for j in 0..k {
                a.swap(p * k + j, c * k + j);
            }
            x.swap(p, c);
        }
        for r in c + 1..k {
            let f = a[r * k + c] / a[c * k + c];
            for j in c..k {
                a[r * k + j] -= f * a[c * k + j];
            }
            x[r] -= f * x[c];
        }
    }
    for c in (0..k).rev() {
        let s: f64 = (c + 1..k).map(|j| a[c * k + j] * x[j]).sum();
        x[c] = (x[c] - s) / a[c * k + c];
    }
    true
}

#[cfg(test)]
mod tests {
    use crate::data::{Data, UkSolver};
    use crate::model::Model;
    use crate::uk;

    /// A rigid slider-crank with friction in the main bearing, the crank pin and the guide
    /// (with a slider length): three coupled friction forces.
    const SCENE: &str = r#"{"gravity": [0, -9.81], "bodies": [
        {"kind": "rigid", "name": "crank", "mass": 1.0, "inertia": 0.01, "com": [0.075, 0.0], "angle": 0.5, "angular_velocity": 20.0},
        {"kind": "rigid", "name": "coupler", "mass": 1.0, "inertia": 0.0075, "com": [0.15, 0.0], "position": [0.1316, 0.0719], "angle": -0.2411},
        {"kind": "rigid", "name": "slider", "mass": 0.5, "inertia": 0.001, "position": [0.4229, 0.0]}],
      "joints": [
        {"kind": "revolute", "name": "main", "a": {"body": "crank", "point": [0, 0]}, "b": {"body": "ground", "point": [0, 0]}},
        {"kind": "revolute", "name": "crankpin", "a": {"body": "crank", "point": [0.15, 0]}, "b": {"body": "coupler", "point": [0, 0]}},
        {"kind": "revolute", "name": "pistonpin", "a": {"body": "coupler", "point": [0.3, 0]}, "b": {"body": "slider", "point": [0, 0]}},
        {"kind": "prismatic", "name": "guide", "a": {"body": "slider"}, "b": {"body": "ground"}}],
      "forces": [
        {"kind": "point_force", "point": {"body": "slider"}, "force": [-300.0, 40.0]},
        {"kind": "joint_friction", "joint": "main", "mu": 0.3, "radius": 0.02},
        {"kind": "joint_friction", "joint": "crankpin", "mu": 0.3, "radius": 0.015, "damping": 0.001},
        {"kind": "joint_friction", "joint": "guide", "mu": 0.4, "length": 0.03}]}"#;

    fn check(solver: UkSolver) {
        let model = Model::from_json(SCENE).unwrap();
        let mut data = Data::build(&model, solver, u64::MAX).unwrap();
        let (q, qd) = (model.q0.clone(), vec![0.1, -0.2, 20.0, 0.3, 1.2, -3.0, -1.1, 0.05, 0.0]);
        uk::acceleration(&model, &mut data, 0.0, &q, &qd).unwrap();
        let w = data.friction.as_ref().unwrap();
        // each friction force is its law at the closed multipliers
        for i in 0..3 {
            let (law, _, _) = w.force_at(&model.forces, i, &data.lambda);
            assert!((w.f[i] - law).abs() <= 1e-12 * law.abs().max(1e-3), "element {i}: {} vs {law}", w.f[i]);
            assert!(w.f[i] != 0.0);
        }
        assert!(w.iterations <= 4, "{} Newton iterations", w.iterations);
        // an independent UK solve with the friction forces as given loads gives the same motion
        let (f, g, n) = (w.f.clone(), w.g.clone(), model.n);
        let mut plain = Data::build(&model, solver, u64::MAX).unwrap();
        let saved = plain.friction.take();
        uk::evaluate(&model, &mut plain, 0.0, &q, &qd, false).unwrap();
        for (i, fi) in f.iter().enumerate() {
            for (x, gi) in plain.force.iter_mut().zip(&g[i * n..(i + 1) * n]) {
                *x += fi * gi;
            }
        }
        uk::solve(&model, &mut plain).unwrap();
        for (a, b) in data.qdd.iter().zip(&plain.qdd) {
            assert!((a - b).abs() <= 1e-10 * (1.0 + b.abs()), "qdd {a} vs {b}");
        }
        for (a, b) in data.lambda.iter().zip(&plain.lambda) {
            assert!((a - b).abs() <= 1e-10 * (1.0 + b.abs()), "lambda {a} vs {b}");
        }
        // a single pass (the friction of the reactions without friction) is measurably different
        plain.friction = saved;
        uk::evaluate(&model, &mut plain, 0.0, &q, &qd, false).unwrap();
        uk::free_acceleration(&model, &mut plain);
        uk::factor_constraints(&model, &mut plain).unwrap();
        uk::correct(&model, &mut plain);
        let single: Vec<f64> = (0..3).map(|i| plain.friction.as_ref().unwrap().force_at(&model.forces, i, &plain.lambda).0).collect();
        assert!(single.iter().zip(&f).any(|(s, c)| (s - c).abs() > 1e-3 * c.abs()), "{single:?} vs {f:?}");
    }

    #[test]
    fn closure_is_the_fixed_point_dense() {
        check(UkSolver::Dense);
    }

    #[test]
    fn closure_is_the_fixed_point_sparse() {
        check(UkSolver::Sparse);
    }
}
