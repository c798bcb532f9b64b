//! The initial-state correction: `(q, qd)` onto the constraints with some coordinates held
//! (by default every body's deformation), damped Newton on the positions in the mass metric of
//! the free coordinates (`metric_step`) or of the bodies' rigid motions (`rigid.rs`), then one
//! velocity projection, and a report of what changed.

use super::rigid::{rigid_step, RigidBasis};
use super::{max_abs, reduced_gauss_step, velocity_residual};
use crate::data::Data;
use crate::dynamics::{constraints, mass_and_forces};
use crate::error::{Error, Result};
use crate::linalg::dense::{cholesky, solve_lower, solve_upper};
use crate::model::Model;
use crate::uk::solve;

/// Settings of `correct`.
#[derive(Debug, Clone)]
pub struct CorrectOptions {
    /// `hold[i]`: coordinate `i` keeps its value (length n).
    pub hold: Vec<bool>,
    /// Every body moves rigidly (its deformation held, `Body::rigid_motions`): what holding the
    /// elastic coordinates means for every kind, an ANCF cable's nodal field included.
    pub rigid: bool,
    /// Newton stops when `max |Phi| <= position_tol` (absolute, m and rad).
    pub position_tol: f64,
    /// Accepted `max |A qd + Phi_t| <= velocity_tol * max(1, max |qd|)`.
    pub velocity_tol: f64,
    pub max_iterations: usize,
}

/// What `correct` did. `q`, `qd` are the corrected state (as far as it got).
#[derive(Debug, Clone)]
pub struct Correction {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub iterations: usize,
    pub position_residual_before: f64,
    pub position_residual_after: f64,
    pub velocity_residual_before: f64,
    pub velocity_residual_after: f64,
    /// `Phi` at the end of the position correction (m).
    pub phi: Vec<f64>,
    /// `A qd + Phi_t` at the end (m; zeros when the positions failed).
    pub velocity: Vec<f64>,
    pub positions_ok: bool,
    pub velocities_ok: bool,
}

/// Minimum-norm solution of `A[:, free] dx = r` in the metric `M[free, free]` (the UK/Gauss
/// projection restricted to the free coordinates): `dx_free = F^-T (A_f F^-T)^+ r` with
/// `M_ff = F F^T`. Needs the mass blocks and `A` at the current `q` in `data`.
///
/// When no coordinate is held and the workspace has the sparse UK path, this is the UK solve
/// itself with `Q = 0`, `b = r` (O(n), the sparse path's rank certificate or its dense
/// fallback); otherwise the dense SVD of `A_f F^-T` below (O(n m^2)): a body whose coordinates
/// are all free is factored by its own `M_b = F_b F_b^T` (banded for an ANCF cable: O(n_b)),
/// a body with held coordinates by the dense Cholesky of its free block.
fn metric_step(model: &Model, data: &mut Data, free: &[bool], r: &[f64]) -> Result<Vec<f64>> {
    let (n, m) = (model.n, model.m);
    if m > 0 && data.sparse.is_some() && free.iter().all(|f| *f) {
        crate::dynamics::factor_mass(model, data)?;
        data.force.fill(0.0);
        data.gamma.copy_from_slice(r);
        solve(model, data)?;
        return Ok(data.qdd.clone());
    }
    let mut dx = vec![0.0; n];
    let idx: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
    let k = idx.len();
    if k == 0 || m == 0 {
        return Ok(dx);
    }
    // M restricted to the free coordinates (block diagonal by body): only the free entries of
    // each body block are visited, so holding the elastic coordinates of a long beam costs a
    // 3 x 3 block, not its whole mass matrix.
    let mut pos = vec![usize::MAX; n];
    for (p, &i) in idx.iter().enumerate() {
        pos[i] = p;
    }
    let hint = "the initial-state correction with held coordinates solves densely in the free coordinates and the constraint rows; hold fewer coordinates (hold=None) or raise memory_limit";
    Error::check_memory("the initial-state correction (free coordinates x constraint rows)", 8 * (k as u64 + m as u64) * m as u64 * 3, data.memory_limit, hint)?;
    // per body with free coordinates: (first compact index, size, whole body: its own factor)
    let mut blocks: Vec<(usize, usize, usize, bool)> = Vec::new();
    let mut mf = vec![0.0; 0];
    let mut offsets = Vec::new();
    for (b, body) in model.bodies.iter().enumerate() {
        let local: Vec<usize> = (body.offset..body.offset + body.n_coords).filter(|&i| free[i]).collect();
        let kb = local.len();
        if kb == 0 {
            continue;
        }
        let first = pos[local[0]];
        if kb == body.n_coords {
            body.factor(&mut data.bodies[b])?;
            blocks.push((first, kb, b, true));
            offsets.push(0);
            continue;
        }
        let bd = &data.bodies[b];
        Error::check_memory("the initial-state correction (a body's free mass block)", 8 * (kb * kb) as u64, data.memory_limit, hint)?;
        let mut blk = vec![0.0; kb * kb];
        body.dense_block(bd, &mut |i, j, v| {
            let (gi, gj) = (body.offset + i, body.offset + j);
            if free[gi] && free[gj] {
                blk[(pos[gi] - first) * kb + pos[gj] - first] = v;
            }
        });
        if cholesky(&mut blk, kb, 0.0).is_err() {
            return Err(Error::SingularMass { item: format!("body '{}': mass block of the corrected coordinates", body.name) });
        }
        blocks.push((first, kb, b, false));
        offsets.push(mf.len());
        mf.extend_from_slice(&blk);
    }
    let data = &*data;
    // F^-1 (transposed: F^-T) of the free blocks: a whole body by its own factor, a partial one
    // by the Cholesky factor of its free block
    let apply = |v: &mut [f64], transposed: bool| {
        for (&(first, kb, b, whole), &off) in blocks.iter().zip(&offsets) {
            let seg = &mut v[first..first + kb];
            if whole {
                let (body, bd) = (&model.bodies[b], &data.bodies[b]);
                if transposed {
                    body.finvt(bd, seg)
                } else {
                    body.finv(bd, seg)
                }
            } else {
                let l = &mf[off..off + kb * kb];
                if transposed {
                    solve_upper(l, kb, seg)
                } else {
                    solve_lower(l, kb, seg)
                }
            }
        }
    };
    let y = reduced_gauss_step(
        k,
        r,
        |i, col| {
            // row i of A on the free coordinates, from the segment form (O(nnz) per row)
            for sg in data.ajac.row_segs(i) {
                for (j, &a) in data.ajac.vals[sg.val..sg.val + sg.len].iter().enumerate() {
                    let p = pos[sg.col + j];
                    if p != usize::MAX {
                        col[p] = a;
                    }
                }
            }
        },
        |col| apply(col, false),
        |y| apply(y, true),
    )?;
    for (p, &g) in idx.iter().enumerate() {
        dx[g] = y[p];
    }
    Ok(dx)
}

/// Correct `(q, qd)` onto the constraints at time `t`, holding the coordinates marked in
/// `opts.hold`: damped Newton on the positions (the step halved while `max |Phi|` grows, stop
/// after 5 iterations without halving the best residual), then one velocity projection.
pub fn correct(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], opts: &CorrectOptions) -> Result<Correction> {
    correct_within(model, data, t, q, qd, opts, f64::INFINITY)
}

/// `correct` within a wall-time budget of `max_wall_time` seconds (checked before every Newton
/// iteration and before the velocity projection): past it `Error::Budget` (`max_wall_time`)
/// saying how far the correction got.
pub fn correct_within(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], opts: &CorrectOptions, max_wall_time: f64) -> Result<Correction> {
    let started = std::time::Instant::now();
    let over = |it: usize, res: f64| -> Result<()> {
        if max_wall_time.is_finite() && started.elapsed().as_secs_f64() > max_wall_time {
            return Err(Error::Budget {
                what: "max_wall_time".into(),
                message: format!("the initial-state correction: wall time over max_wall_time = {max_wall_time} s after {it} Newton iteration(s) (max |Phi| = {res:.3e})"),
            });
        }
        Ok(())
    };
    let (n, m) = (model.n, model.m);
    if opts.hold.len() != n {
        return Err(Error::Shape { what: "hold".into(), expected: n, got: opts.hold.len() });
    }
    let free: Vec<bool> = opts.hold.iter().map(|h| !h).collect();
    // bodies that move only rigidly: the cables' nodal fields (the other kinds' deformation is
    // their elastic coordinates, held by the mask)
    let rigid = opts.rigid && model.bodies.iter().any(|b| b.capabilities().nodal_deformation);
    let zeros = vec![0.0; n];
    let mut q = q.to_vec();
    constraints(model, data, t, &q, &zeros, true);
    let mut phi = data.phi.clone();
    let r0 = max_abs(&phi);
    let (mut res, mut best, mut it, mut stall) = (r0, r0, 0usize, 0usize);
    let mut r = vec![0.0; m];
    while res > opts.position_tol && it < opts.max_iterations {
        over(it, res)?;
        it += 1;
        mass_and_forces(model, data, t, &q, &zeros);
        constraints(model, data, t, &q, &zeros, false);
        for i in 0..m {
            r[i] = -phi[i];
        }
        let (dq, basis, x) = if rigid {
            let basis = RigidBasis::new(model, &q, &opts.hold);
            let x = rigid_step(model, data, &basis, &r)?;
            (Vec::new(), Some(basis), x)
        } else {
            (metric_step(model, data, &free, &r)?, None, Vec::new())
        };
        let mut step = 1.0;
        let mut q_try = q.clone();
        loop {
            match &basis {
                Some(basis) => {
                    q_try.copy_from_slice(&q);
                    let xs: Vec<f64> = x.iter().map(|v| step * v).collect();
                    for (b, body) in model.bodies.iter().enumerate() {
                        body.move_rigidly(&mut q_try, &basis.body_motion(b, &xs));
                    }
                }
                None => {
                    for i in 0..n {
                        q_try[i] = q[i] + step * dq[i];
                    }
                }
            }
            constraints(model, data, t, &q_try, &zeros, true);
            if max_abs(&data.phi) < res || step < 1e-6 {
                break;
            }
            step *= 0.5;
        }
        q.copy_from_slice(&q_try);
        phi.copy_from_slice(&data.phi);
        res = max_abs(&phi);
        if res < 0.5 * best {
            best = res;
            stall = 0;
        } else {
            stall += 1;
            if stall >= 5 {
                break;
            }
        }
        if !res.is_finite() {
            break;
        }
    }
    let positions_ok = res <= opts.position_tol;
    let mut out = Correction {
        q,
        qd: qd.to_vec(),
        iterations: it,
        position_residual_before: r0,
        position_residual_after: res,
        velocity_residual_before: f64::NAN,
        velocity_residual_after: f64::NAN,
        phi,
        velocity: vec![0.0; m],
        positions_ok,
        velocities_ok: false,
    };
    if !positions_ok {
        return Ok(out);
    }
    over(it, res)?;
    mass_and_forces(model, data, t, &out.q, &zeros);
    constraints(model, data, t, &out.q, &zeros, false);
    let mut vres = vec![0.0; m];
    velocity_residual(model, data, &out.qd, &mut vres);
    out.velocity_residual_before = max_abs(&vres);
    for i in 0..m {
        r[i] = -vres[i];
    }
    let dqd = if rigid {
        let basis = RigidBasis::new(model, &out.q, &opts.hold);
        basis.times(&rigid_step(model, data, &basis, &r)?)
    } else {
        metric_step(model, data, &free, &r)?
    };
    for i in 0..n {
        out.qd[i] += dqd[i];
    }
    velocity_residual(model, data, &out.qd, &mut vres);
    out.velocity_residual_after = max_abs(&vres);
    out.velocity = vres;
    let scale = max_abs(&out.qd).max(1.0);
    out.velocities_ok = out.velocity_residual_after <= opts.velocity_tol * scale;
    Ok(out)
}
