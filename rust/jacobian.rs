//! Jacobian of the UK right-hand side `f(t, y) = [qd, qdd(t, q, qd)]`, `y = [q, qd]`:
//! `J = [[0, I], [Jq, Jv]]` with `Jq = d qdd / d q` and `Jv = d qdd / d qd` (n x n each).
//!
//! Finite differences column by column, with two savings over a generic `num_jac`:
//! * the top half `[0, I]` is exact and never differenced;
//! * `M`, `A` and therefore the mass factor and the SVD of `B^T = F^-1 A^T` depend on `q` only:
//!   the velocity columns re-evaluate just `Q` and `b` and reuse the factorization
//!   (`uk::acceleration_same_q`), so they cost a fraction of a full UK call.
//!
//! Step: `h_j = c * max(|x_j|, typ)` with `c = eps^(1/3)` (central, the default: error
//! O(h^2) + O(eps/h), balanced at this `c`) or `c = eps^(1/2)` (forward). `typ` (default 1e-2,
//! SI units) keeps the step away from zero for coordinates that pass through 0; the model
//! terms are smooth on the scale of the body dimensions (0.1 m, 1 rad), so truncation error is
//! negligible at these steps, and the exact arithmetic step `(x + h) - x` is used. Allocation
//! free after `JacobianWorkspace::new`.

use crate::data::Data;
use crate::error::Result;
use crate::model::Model;
use crate::uk;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Differences {
    #[default]
    Central,
    Forward,
    /// Not differences: the structured linearization of `structured_jacobian`.
    Structured,
}

#[derive(Debug, Clone)]
pub struct JacobianWorkspace {
    pub scheme: Differences,
    /// Typical magnitude below which the step stops shrinking with |x_j|.
    pub typ: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    /// `qdd` at the base point.
    pub f0: Vec<f64>,
    fp: Vec<f64>,
    /// Full UK evaluations and factorization-reusing evaluations of the last call.
    pub full_evals: usize,
    pub cheap_evals: usize,
    /// Workspace of the structured Jacobian (made on first use).
    structured: Option<Box<StructuredJacobian>>,
}

/// The default `typ` (`JacobianWorkspace::typ`).
const TYPICAL: f64 = 1e-2;

impl JacobianWorkspace {
    pub fn new(model: &Model) -> Self {
        let n = model.n;
        JacobianWorkspace {
            scheme: Differences::Central,
            typ: TYPICAL,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            f0: vec![0.0; n],
            fp: vec![0.0; n],
            full_evals: 0,
            cheap_evals: 0,
            structured: None,
        }
    }
}

#[inline]
fn step(x: f64, c: f64, typ: f64) -> f64 {
    let h = c * x.abs().max(typ);
    // exactly representable step
    (x + h) - x
}

/// Fill `jq`, `jv` (n x n row-major) with `d qdd / d q` and `d qdd / d qd` at `(t, q, qd)`.
/// On return `ws.f0` holds `qdd(t, q, qd)`; `data` holds the last perturbed evaluation.
pub fn uk_jacobian(model: &Model, data: &mut Data, ws: &mut JacobianWorkspace, t: f64, q: &[f64], qd: &[f64], jq: &mut [f64], jv: &mut [f64]) -> Result<()> {
    let n = model.n;
    let c = match ws.scheme {
        Differences::Central => f64::EPSILON.cbrt(),
        Differences::Forward => f64::EPSILON.sqrt(),
        Differences::Structured => {
            let sj = ws.structured.get_or_insert_with(|| Box::new(StructuredJacobian::new(model)));
            ws.full_evals = 0;
            ws.cheap_evals = 0;
            return sj.evaluate(model, data, t, q, qd, jq, jv);
        }
    };
    ws.full_evals = 0;
    ws.cheap_evals = 0;
    ws.q.copy_from_slice(q);
    ws.qd.copy_from_slice(qd);
    // base point (also leaves the factorization at q in data)
    uk::acceleration(model, data, t, q, qd)?;
    ws.full_evals += 1;
    ws.f0.copy_from_slice(&data.qdd);
    // velocity columns: factorization reused
    for j in 0..n {
        let h = step(qd[j], c, ws.typ);
        ws.qd[j] = qd[j] + h;
        uk::acceleration_same_q(model, data, t, q, &ws.qd)?;
        ws.cheap_evals += 1;
        match ws.scheme {
            Differences::Forward => {
                for i in 0..n {
                    jv[i * n + j] = (data.qdd[i] - ws.f0[i]) / h;
                }
            }
            Differences::Central | Differences::Structured => {
                ws.fp.copy_from_slice(&data.qdd);
                ws.qd[j] = qd[j] - h;
                uk::acceleration_same_q(model, data, t, q, &ws.qd)?;
                ws.cheap_evals += 1;
                for i in 0..n {
                    jv[i * n + j] = (ws.fp[i] - data.qdd[i]) / (2.0 * h);
                }
            }
        }
        ws.qd[j] = qd[j];
    }
    position_columns(model, data, ws, t, q, qd, c, jq)
}

/// `jq = d qdd / d q` at `(t, q, qd)` by central differences alone (the velocity columns left
/// out): the linearization of the modal analysis (`method="auto"`, `System.frequencies`).
/// Allocates its workspace (once per analysis, not per step).
pub fn position_jacobian(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], jq: &mut [f64]) -> Result<()> {
    let mut ws = JacobianWorkspace::new(model);
    ws.q.copy_from_slice(q);
    uk::acceleration(model, data, t, q, qd)?;
    ws.f0.copy_from_slice(&data.qdd);
    position_columns(model, data, &mut ws, t, q, qd, f64::EPSILON.cbrt(), jq)
}

/// `d qdd / d q` times each of the `k` unit directions in `dirs` (n x k, column-major) into
/// `out` (n x k, column-major), by central differences along each direction (two UK evaluations
/// per direction instead of two per coordinate): on a constrained system's null space, `k` is
/// its degrees of freedom (A05: 8 evaluations instead of 68). The step is the columns' rule
/// (`c = eps^(1/3)` times the magnitude) on the direction's mean magnitude
/// `sum_j |d_j| max(|q_j|, typ) / sum_j |d_j|` (a coordinate axis: that column's step).
pub fn position_directional(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], dirs: &[f64], k: usize, out: &mut [f64]) -> Result<()> {
    let n = model.n;
    let (c, typ) = (f64::EPSILON.cbrt(), TYPICAL);
    let (mut qs, mut fp) = (q.to_vec(), vec![0.0; n]);
    for (d, col) in dirs.chunks_exact(n).take(k).zip(out.chunks_exact_mut(n)) {
        let w: f64 = d.iter().map(|x| x.abs()).sum();
        let mag = d.iter().zip(q).map(|(x, qj)| x.abs() * qj.abs().max(typ)).sum::<f64>() / w.max(f64::MIN_POSITIVE);
        let h = c * mag;
        for sign in [1.0, -1.0] {
            for ((x, qj), dj) in qs.iter_mut().zip(q).zip(d) {
                *x = qj + sign * h * dj;
            }
            uk::acceleration(model, data, t, &qs, qd)?;
            if sign > 0.0 {
                fp.copy_from_slice(&data.qdd);
            }
        }
        for ((o, p), m) in col.iter_mut().zip(&fp).zip(&data.qdd) {
            *o = (p - m) / (2.0 * h);
        }
    }
    Ok(())
}

/// The position columns of [`uk_jacobian`] (full UK evaluations), `ws.q = q` and `ws.f0` the
/// base point's `qdd` on entry.
fn position_columns(model: &Model, data: &mut Data, ws: &mut JacobianWorkspace, t: f64, q: &[f64], qd: &[f64], c: f64, jq: &mut [f64]) -> Result<()> {
    let n = model.n;
    for j in 0..n {
        let h = step(q[j], c, ws.typ);
        ws.q[j] = q[j] + h;
        uk::acceleration(model, data, t, &ws.q, qd)?;
        ws.full_evals += 1;
        match ws.scheme {
            Differences::Forward => {
                for i in 0..n {
                    jq[i * n + j] = (data.qdd[i] - ws.f0[i]) / h;
                }
            }
            Differences::Central | Differences::Structured => {
                ws.fp.copy_from_slice(&data.qdd);
                ws.q[j] = q[j] - h;
                uk::acceleration(model, data, t, &ws.q, qd)?;
                ws.full_evals += 1;
                for i in 0..n {
                    jq[i * n + j] = (ws.fp[i] - data.qdd[i]) / (2.0 * h);
                }
            }
        }
        ws.q[j] = q[j];
    }
    Ok(())
}

/// The full Jacobian of `f(t, y) = [qd, qdd]`: `[[0, I], [Jq, Jv]]` (2n x 2n, row-major) from
/// the two n x n blocks.
pub fn assemble_first_order(n: usize, jq: &[f64], jv: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for i in 0..n {
        out[i * 2 * n + n + i] = 1.0;
        out[(n + i) * 2 * n..(n + i) * 2 * n + n].copy_from_slice(&jq[i * n..(i + 1) * n]);
        out[(n + i) * 2 * n + n..(n + i + 1) * 2 * n].copy_from_slice(&jv[i * n..(i + 1) * n]);
    }
}

/// The structured linearization of the UK acceleration, instead of differences of it: the
/// acceleration solves `M qdd + A^T lambda = Q(q, qd)`, `A qdd = b(q, qd)`; with the stiffness
/// `K = -dQ/dq` the bodies and the loads know analytically, `C = -dQ/dqd` and `db/dqd` (exact differences of
/// functions quadratic in `qd`) and `M`, `A` held fixed,
///
/// `[M, A^T; A, 0] [Jq e_j; .] = [-K e_j; 0]`, `[M, A^T; A, 0] [Jv e_j; .] = [-C e_j; db/dqd e_j]`,
///
/// one factorization of the saddle-point matrix and 2n solves: `Jq = -P M^-1 K`,
/// `Jv = -P M^-1 C + M^-1 A^T (A M^-1 A^T)^-1 db/dqd` with the `M`-orthogonal projector `P`
/// onto the constraint null space. Neglected: the variation of `M`, `A` and the multiplier forces
/// with `q`, the position derivatives of `b` and of the inertial velocity terms. Cost: no UK
/// call, `(n + m)^3 / 3 + 2 n (n + m)^2` flops, against the `4 n` UK calls of central
/// differences. Allocation free after the first call.
#[derive(Debug, Clone)]
pub struct StructuredJacobian {
    m_dense: Vec<f64>,
    k: Vec<f64>,
    c: Vec<f64>,
    bv: Vec<f64>,
    saddle: Vec<f64>,
    piv: Vec<usize>,
    rhs: Vec<f64>,
    v: Vec<f64>,
}

impl StructuredJacobian {
    pub fn new(model: &Model) -> Self {
        let (n, m) = (model.n, model.m);
        let nm = n + m;
        StructuredJacobian {
            m_dense: vec![0.0; n * n],
            k: vec![0.0; n * n],
            c: vec![0.0; n * n],
            bv: vec![0.0; m * n],
            saddle: vec![0.0; nm * nm],
            piv: vec![0; nm],
            rhs: vec![0.0; nm],
            v: vec![0.0; n],
        }
    }

    /// `[M, A^T; A, reg I]` from `self.m_dense` and the constraint Jacobian `jac` (m x n).
    fn assemble_saddle(&mut self, jac: &[f64], n: usize, m: usize, reg: f64) {
        let nm = n + m;
        for i in 0..n {
            self.saddle[i * nm..i * nm + n].copy_from_slice(&self.m_dense[i * n..(i + 1) * n]);
            for r in 0..m {
                self.saddle[i * nm + n + r] = jac[r * n + i];
            }
        }
        for r in 0..m {
            self.saddle[(n + r) * nm..(n + r) * nm + n].copy_from_slice(&jac[r * n..(r + 1) * n]);
            for c in 0..m {
                self.saddle[(n + r) * nm + n + c] = if r == c { reg } else { 0.0 };
            }
        }
    }

    /// `jq`, `jv` (n x n row-major) at `(t, q, qd)`.
    pub fn evaluate(&mut self, model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], jq: &mut [f64], jv: &mut [f64]) -> Result<()> {
        use crate::dynamics;
        use crate::linalg::lu::{lu_cm, lu_cm_solve}; // the saddle-point matrix is symmetric: row- and column-major alike
        let (n, m) = (model.n, model.m);
        let nm = n + m;
        dynamics::mass_and_forces(model, data, t, q, qd);
        dynamics::dense_mass_into(model, data, &mut self.m_dense);
        dynamics::stiffness_into(model, data, q, qd, &mut self.k);
        data.ensure_dense_jac()?;
        dynamics::constraints(model, data, t, q, qd, false);
        self.assemble_saddle(data.jac.read(&data.ajac), n, m, 0.0);
        if !lu_cm(&mut self.saddle, &mut self.piv, nm) {
            // redundant constraint rows: the multiplier block, slightly regularized
            let scale = self.m_dense.iter().fold(0.0f64, |s, v| s.max(v.abs())).max(f64::MIN_POSITIVE);
            self.assemble_saddle(data.jac.read(&data.ajac), n, m, -1e-12 * scale);
            if !lu_cm(&mut self.saddle, &mut self.piv, nm) {
                return Err(crate::error::Error::Solver("structured Jacobian: the saddle-point matrix is singular".into()));
            }
        }
        dynamics::velocity_jacobians_into(model, data, t, q, qd, &mut self.v, &mut self.c, &mut self.bv);
        for j in 0..n {
            for i in 0..n {
                self.rhs[i] = -self.k[i * n + j];
            }
            self.rhs[n..].fill(0.0);
            lu_cm_solve(&self.saddle, &self.piv, nm, &mut self.rhs);
            for i in 0..n {
                jq[i * n + j] = self.rhs[i];
            }
            for i in 0..n {
                self.rhs[i] = -self.c[i * n + j];
            }
            for r in 0..m {
                self.rhs[n + r] = self.bv[r * n + j];
            }
            lu_cm_solve(&self.saddle, &self.piv, nm, &mut self.rhs);
            for i in 0..n {
                jv[i * n + j] = self.rhs[i];
            }
        }
        Ok(())
    }
}
