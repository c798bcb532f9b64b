//! Model kernels: per-body mass blocks `M(q)` (paper eqs. 20-33), generalized forces
//! `Q = Q_e + Q_v + Q_el` (eqs. 34-40), the block-diagonal mass factor `M = F F^T`, and the
//! constraint terms `Phi`, `A`, `Phi_t`, `gamma` (eq. 43). All write into `Data`.

use crate::body::{Body, BodyKind};
use crate::constraint::ConstraintOut;
use crate::data::{BodyData, Data};
use crate::error::{Error, Result};
use crate::linalg::{cholesky3, solve_lower3, solve_upper3};
use crate::model::Model;

/// Per-body mass blocks and generalized forces at `(t, q, qd)`.
///
/// Beam, with `Sigma = s_t + S_bar q_f` (first moment in the body frame), `J` = +90 deg turn:
/// * `m_RR = m I`, `m_Rtheta = A J Sigma`, `m_Rf = A S_bar`                    (eqs. 21-25)
/// * `m_thetatheta = j0 + 2 i_rf . q_f + q_f^T M_ff^tr q_f`                      (eqs. 26-30)
/// * `m_thetaf = i_thf + q_f^T S_tilde`                                          (eq. 31)
/// * `Q_v,R = thd^2 A Sigma - 2 thd A J S_bar qd_f`
/// * `Q_v,theta = -2 thd qd_f . (i_rf + M_ff^tr q_f)`
/// * `Q_v,f = thd^2 (i_rf + M_ff^tr q_f) + 2 thd S_tilde qd_f`                   (eq. 40)
/// * `Q_el = -K_ff (q_f + beta qd_f)`                                           (eq. 38)
/// * gravity: `Q_R = m g`, `Q_theta = g . A J Sigma`, `Q_f = S_bar^T A^T g`     (eq. 37)
pub fn mass_and_forces(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) {
    let gravity = model.gravity;
    for (body, bd) in model.bodies.iter().zip(data.bodies.iter_mut()) {
        let o = body.offset;
        let (th, thd) = (q[o + 2], qd[o + 2]);
        let (s, c) = th.sin_cos();
        let qv = &mut data.force[o..o + body.n_coords];
        match &body.kind {
            BodyKind::Rigid(r) => {
                let sig = [r.mass * r.com[0], r.mass * r.com[1]];
                let asig = [c * sig[0] - s * sig[1], s * sig[0] + c * sig[1]];
                let ajsig = [-asig[1], asig[0]];
                bd.m_rr = [[r.mass, 0.0, ajsig[0]], [0.0, r.mass, ajsig[1]], [ajsig[0], ajsig[1], r.j_ref]];
                bd.cs = [c, s];
                qv[0] = thd * thd * asig[0];
                qv[1] = thd * thd * asig[1];
                qv[2] = 0.0;
                if let Some(g) = gravity {
                    qv[0] += r.mass * g[0];
                    qv[1] += r.mass * g[1];
                    qv[2] += g[0] * ajsig[0] + g[1] * ajsig[1];
                }
            }
            BodyKind::Beam(b) => {
                let nf = b.n_f;
                let qf = &q[o + 3..o + 3 + nf];
                let qfd = &qd[o + 3..o + 3 + nf];
                let mut sig = b.s_t;
                let mut sigd = [0.0; 2]; // S_bar qd_f
                for j in 0..nf {
                    sig[0] += b.s_bar[0][j] * qf[j];
                    sig[1] += b.s_bar[1][j] * qf[j];
                    sigd[0] += b.s_bar[0][j] * qfd[j];
                    sigd[1] += b.s_bar[1][j] * qfd[j];
                }
                let asig = [c * sig[0] - s * sig[1], s * sig[0] + c * sig[1]];
                let ajsig = [-asig[1], asig[0]];
                let asigd = [c * sigd[0] - s * sigd[1], s * sigd[0] + c * sigd[1]];
                // w = i_rf + M_ff^tr q_f
                bd.w.copy_from_slice(&b.i_rf);
                b.m_ff_tr.mul_add(1.0, qf, &mut bd.w);
                let mut m_thth = b.j0;
                let mut qd_w = 0.0;
                for j in 0..nf {
                    m_thth += qf[j] * (b.i_rf[j] + bd.w[j]);
                    qd_w += qfd[j] * bd.w[j];
                }
                bd.m_rr = [[b.mass, 0.0, ajsig[0]], [0.0, b.mass, ajsig[1]], [ajsig[0], ajsig[1], m_thth]];
                bd.cs = [c, s];
                // m_thetaf = i_thf + S_tilde^T q_f = i_thf - S_tilde q_f  (M_Rf = A S_bar is not
                // formed: the factor uses the rotated constants, `dense_mass` rebuilds it)
                bd.m_thf.copy_from_slice(&b.i_thf);
                b.s_tilde.mul_add(-1.0, qf, &mut bd.m_thf);

                qv[0] = thd * thd * asig[0] + 2.0 * thd * asigd[1];
                qv[1] = thd * thd * asig[1] - 2.0 * thd * asigd[0];
                qv[2] = -2.0 * thd * qd_w;
                let qvf = &mut qv[3..];
                for j in 0..nf {
                    qvf[j] = thd * thd * bd.w[j];
                }
                b.s_tilde.mul_add(2.0 * thd, qfd, qvf);
                b.k_ff.mul_add(-1.0, qf, qvf);
                if b.damping > 0.0 {
                    b.k_ff.mul_add(-b.damping, qfd, qvf);
                }
                if let Some(g) = gravity {
                    qv[0] += b.mass * g[0];
                    qv[1] += b.mass * g[1];
                    qv[2] += g[0] * ajsig[0] + g[1] * ajsig[1];
                    let atg = [c * g[0] + s * g[1], -s * g[0] + c * g[1]];
                    for j in 0..nf {
                        qv[3 + j] += b.s_bar[0][j] * atg[0] + b.s_bar[1][j] * atg[1];
                    }
                }
            }
        }
    }
    for f in &model.forces {
        f.add_to(&model.bodies, q, qd, &mut data.force);
    }
}

/// Factor each body block `M_b = F_b F_b^T`. For a beam, in the order `[r; f]`,
/// `F_b = [[L_s, X], [0, L_ff]]` with the constant `L_ff L_ff^T = M_ff`, `X = M_rf L_ff^-T`
/// and `L_s L_s^T = m_rr - X X^T`. The translational rows of `X` are rotated constants (see
/// `BodyData`), so a call costs one banded solve (`X_2`), three dot products and a 3x3
/// Cholesky per beam.
pub fn factor_mass(model: &Model, data: &mut Data) -> Result<()> {
    for (body, bd) in model.bodies.iter().zip(data.bodies.iter_mut()) {
        let mut ls = bd.m_rr;
        if let BodyKind::Beam(b) = &body.kind {
            bd.x2.copy_from_slice(&bd.m_thf);
            b.l_ff.solve_lower(&mut bd.x2);
            let (mut ax, mut bx, mut xx) = (0.0, 0.0, 0.0);
            for ((x, a), bb) in bd.x2.iter().zip(&bd.a).zip(&bd.b) {
                ax += a * x;
                bx += bb * x;
                xx += x * x;
            }
            let [c, s] = bd.cs;
            let [aa, ab, bb] = bd.ab;
            ls[0][0] -= c * c * aa - 2.0 * c * s * ab + s * s * bb;
            ls[1][0] -= s * c * (aa - bb) + (c * c - s * s) * ab;
            ls[1][1] -= s * s * aa + 2.0 * s * c * ab + c * c * bb;
            ls[2][0] -= c * ax - s * bx;
            ls[2][1] -= s * ax + c * bx;
            ls[2][2] -= xx;
        }
        if !cholesky3(&mut ls) {
            return Err(Error::SingularMass { item: format!("body '{}'", body.name) });
        }
        bd.ls = ls;
    }
    Ok(())
}

/// `v <- F^-1 v` on one body's segment: `v_f <- L_ff^-1 v_f`, `v_r <- L_s^-1 (v_r - X v_f)`.
#[inline]
fn body_finv(body: &Body, bd: &BodyData, v: &mut [f64]) {
    let (vr, vf) = v.split_at_mut(3);
    if let BodyKind::Beam(b) = &body.kind {
        b.l_ff.solve_lower(vf);
        let (mut pa, mut pb, mut px) = (0.0, 0.0, 0.0);
        for (((f, a), bb), x) in vf.iter().zip(&bd.a).zip(&bd.b).zip(&bd.x2) {
            pa += a * f;
            pb += bb * f;
            px += x * f;
        }
        let [c, s] = bd.cs;
        vr[0] -= c * pa - s * pb;
        vr[1] -= s * pa + c * pb;
        vr[2] -= px;
    }
    solve_lower3(&bd.ls, vr);
}

/// `v <- F^-T v` on one body's segment: `v_r <- L_s^-T v_r`, `v_f <- L_ff^-T (v_f - X^T v_r)`.
#[inline]
fn body_finvt(body: &Body, bd: &BodyData, v: &mut [f64]) {
    let (vr, vf) = v.split_at_mut(3);
    solve_upper3(&bd.ls, vr);
    if let BodyKind::Beam(b) = &body.kind {
        let [c, s] = bd.cs;
        // X^T v_r = (c v0 + s v1) a + (-s v0 + c v1) b + v2 X_2
        let (ka, kb, kx) = (c * vr[0] + s * vr[1], -s * vr[0] + c * vr[1], vr[2]);
        for (((f, a), bb), x) in vf.iter_mut().zip(&bd.a).zip(&bd.b).zip(&bd.x2) {
            *f -= ka * a + kb * bb + kx * x;
        }
        b.l_ff.solve_upper(vf);
    }
}

/// `v <- F^-1 v` for the whole (block-diagonal) factor.
pub fn apply_finv(model: &Model, bodies: &[BodyData], v: &mut [f64]) {
    for (body, bd) in model.bodies.iter().zip(bodies) {
        body_finv(body, bd, &mut v[body.offset..body.offset + body.n_coords]);
    }
}

/// `v <- F^-T v`.
pub fn apply_finvt(model: &Model, bodies: &[BodyData], v: &mut [f64]) {
    for (body, bd) in model.bodies.iter().zip(bodies) {
        body_finvt(body, bd, &mut v[body.offset..body.offset + body.n_coords]);
    }
}

/// `F^-1` applied only to the bodies whose segment of `v` is not all zero (constraint rows
/// touch one or two bodies).
pub fn apply_finv_sparse(model: &Model, bodies: &[BodyData], v: &mut [f64]) {
    for (body, bd) in model.bodies.iter().zip(bodies) {
        let seg = &mut v[body.offset..body.offset + body.n_coords];
        if seg.iter().any(|x| *x != 0.0) {
            body_finv(body, bd, seg);
        }
    }
}

/// Constraint terms: `A`, `Phi_t`, `gamma`, and `Phi` when `with_phi`.
pub fn constraints(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], with_phi: bool) {
    let n = model.n;
    data.jac.fill(0.0);
    for c in &model.constraints {
        let rows = c.kind.rows();
        let r0 = c.row;
        let out = ConstraintOut {
            phi: if with_phi { Some(&mut data.phi[r0..r0 + rows]) } else { None },
            jac: &mut data.jac[r0 * n..(r0 + rows) * n],
            phi_t: &mut data.phi_t[r0..r0 + rows],
            gamma: &mut data.gamma[r0..r0 + rows],
        };
        c.eval(&model.bodies, t, q, qd, n, out);
    }
}

/// Dense mass matrix (n x n, row-major) from the body blocks (inspection, not the hot path).
pub fn dense_mass(model: &Model, data: &Data) -> Vec<f64> {
    let n = model.n;
    let mut m = vec![0.0; n * n];
    for (body, bd) in model.bodies.iter().zip(&data.bodies) {
        let o = body.offset;
        for i in 0..3 {
            for j in 0..3 {
                m[(o + i) * n + o + j] = bd.m_rr[i][j];
            }
        }
        if let BodyKind::Beam(b) = &body.kind {
            let nf = b.n_f;
            let [c, s] = bd.cs;
            for i in 0..3 {
                for j in 0..nf {
                    // M_Rf = A S_bar, m_thetaf
                    let v = match i {
                        0 => c * b.s_bar[0][j] - s * b.s_bar[1][j],
                        1 => s * b.s_bar[0][j] + c * b.s_bar[1][j],
                        _ => bd.m_thf[j],
                    };
                    m[(o + i) * n + o + 3 + j] = v;
                    m[(o + 3 + j) * n + o + i] = v;
                }
            }
            for i in 0..nf {
                for j in 0..nf {
                    m[(o + 3 + i) * n + o + 3 + j] = b.m_ff.get(i, j);
                }
            }
        }
    }
    m
}

/// Potential energy: gravity, elastic strain and force elements.
pub fn potential_energy(model: &Model, q: &[f64]) -> f64 {
    let mut v = 0.0;
    for body in &model.bodies {
        let o = body.offset;
        let (s, c) = q[o + 2].sin_cos();
        let (mass, sig) = match &body.kind {
            BodyKind::Rigid(r) => (r.mass, [r.mass * r.com[0], r.mass * r.com[1]]),
            BodyKind::Beam(b) => {
                let qf = &q[o + 3..o + 3 + b.n_f];
                v += 0.5 * b.k_ff.bilinear(qf, qf);
                let mut sig = b.s_t;
                for j in 0..b.n_f {
                    sig[0] += b.s_bar[0][j] * qf[j];
                    sig[1] += b.s_bar[1][j] * qf[j];
                }
                (b.mass, sig)
            }
        };
        if let Some(g) = model.gravity {
            // -g . int rho r dV = -g . (m R + A Sigma)
            let asig = [c * sig[0] - s * sig[1], s * sig[0] + c * sig[1]];
            v -= g[0] * (mass * q[o] + asig[0]) + g[1] * (mass * q[o + 1] + asig[1]);
        }
    }
    for f in &model.forces {
        v += f.potential(&model.bodies, q);
    }
    v
}
