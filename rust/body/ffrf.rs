//! The floating-frame (FFRF) core shared by the FFRF beam (`ffrf_beam.rs`) and the general
//! flexible body (`flexible.rs`): a frame `(x, y, theta)` plus `n_f` elastic coordinates `q_f`,
//! the displacement field `u_f(P) = S(P) q_f` of a point with undeformed body-frame position
//! `u0`. A kind only builds its invariants (`Ffrf`: the beam by Gauss quadrature of its
//! elements, the modal body from its description) and adds the elastic forces beyond the
//! linear `-K_ff q_f`; everything else is here, written once:
//!
//! * mass blocks and generalized forces (paper eqs. 20-40), with `Sigma = s_t + S_bar q_f`,
//!   `w = s_u0 + M_ff^tr q_f`, `J` = +90 deg turn:
//!   - `m_RR = m I`, `m_Rtheta = A J Sigma`, `m_Rf = A S_bar`                    (eqs. 21-25)
//!   - `m_thetatheta = j0 + q_f . (s_u0 + w)`                                      (eqs. 26-30)
//!   - `m_thetaf = s_ju0 + q_f^T S_tilde = s_ju0 - S_tilde q_f`                    (eq. 31)
//!   - `Q_v,R = thd^2 A Sigma - 2 thd A J S_bar qd_f`, `Q_v,theta = -2 thd qd_f . w`
//!   - `Q_v,f = thd^2 w + 2 thd S_tilde qd_f`                                      (eq. 40)
//!   - `Q_el = -K_ff q_f` (+ the kind's own terms)                                 (eq. 38)
//!   - gravity: `Q_R = m g`, `Q_theta = g . A J Sigma`, `Q_f = S_bar^T A^T g`     (eq. 37)
//! * the block factor `M_b = F_b F_b^T` with the constant Cholesky factor of `M_ff`, its
//!   solves, `M_b x`, the dense block and the kinetic energy from the blocks;
//! * the initial state, the first moment of mass, and the kinematics of a marker at a point of
//!   the body (`PointShape`: an axis point of a beam, an interface point of a modal body).

use super::frame::{add_frame_gravity, add_frame_point_jacobian, frame_mass_block, frame_mass_moment, frame_point_state, frame_sin_cos};
use super::{finite_vec2, InitialState, MarkerState};
use crate::error::{check_finite_item, Error, Result};
use crate::linalg::{cholesky3, dot4 as dot, solve_lower3, solve_upper3, Banded, BandedCholesky};

/// The constant inertia invariants and elastic stiffness of a floating-frame body (body
/// frame). The banded matrices share one half-bandwidth.
#[derive(Debug, Clone)]
pub struct Ffrf {
    /// Number of elastic coordinates.
    pub n_f: usize,
    pub mass: f64,
    /// `int rho u0 dV`: the first moment of the undeformed body.
    pub s_t: [f64; 2],
    /// `int rho |u0|^2 dV` (+ rotary parts): `m_thetatheta` at `q_f = 0`.
    pub j0: f64,
    /// `S_bar = int rho S dV`, rows (x, y) (eq. 23).
    pub s_bar: [Vec<f64>; 2],
    /// `int rho S^T u0 dV` (enters `m_thetatheta`, eq. 29).
    pub s_u0: Vec<f64>,
    /// `int rho S^T J u0 dV` (+ rotary parts): `m_thetaf` at `q_f = 0` (eq. 31).
    pub s_ju0: Vec<f64>,
    /// `S_tilde = int rho S^T I~ S dV` (antisymmetric, eq. 32).
    pub s_tilde: Banded,
    /// `int rho S^T S dV`: the translational part of `M_ff` (enters `m_thetatheta` and the
    /// quadratic velocity forces).
    pub m_ff_tr: Banded,
    /// `M_ff` (with rotary inertia).
    pub m_ff: Banded,
    pub k_ff: Banded,
    /// Cholesky factor of `M_ff` (constant: the elastic block of the body factor).
    pub l_ff: BandedCholesky,
}

/// Workspace of a floating-frame body: per-call mass blocks and the factor
/// `F_b = [[L_s, X], [0, L_ff]]`.
///
/// `X = M_rf L_ff^-T` (3 x n_f). Its first two rows are the rotation of constants:
/// `M_Rf = A S_bar`, so `X_0 = c a - s b`, `X_1 = s a + c b` with `a = L_ff^-1 S_bar_x^T`,
/// `b = L_ff^-1 S_bar_y^T` fixed at model build (here, once per workspace). Only
/// `X_2 = L_ff^-1 m_thetaf^T` needs a banded solve per call, and the 3x3 Schur complement
/// `m_rr - X X^T` needs only `X_2 . (a, b, X_2)` besides the constant products `a.a`, `a.b`,
/// `b.b`.
#[derive(Debug, Clone)]
pub struct FfrfData {
    /// Reference block `[[m_RR, m_Rtheta], [., m_thetatheta]]` (symmetric 3x3).
    pub m_rr: [[f64; 3]; 3],
    /// `(cos theta, sin theta)` of the last `mass_and_forces`.
    pub cs: [f64; 2],
    /// `m_thetaf = s_ju0 - S_tilde q_f` (n_f).
    pub m_thf: Vec<f64>,
    /// Constants `a = L_ff^-1 S_bar_x^T`, `b = L_ff^-1 S_bar_y^T` (n_f each) and
    /// `[a.a, a.b, b.b]`.
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub ab: [f64; 3],
    /// `X_2 = L_ff^-1 m_thetaf^T` (n_f).
    pub x2: Vec<f64>,
    /// Lower Cholesky factor of the Schur complement `m_rr - X X^T`.
    pub ls: [[f64; 3]; 3],
    /// Scratch of length n_f: `w = s_u0 + M_ff^tr q_f`.
    pub w: Vec<f64>,
}

/// Sparse shape of a point of a floating-frame body: `(q_f index, S_u, S_v, N_psi)` for each
/// nonzero column (`S_u`, `S_v`: displacement rows; `N_psi`: section rotation).
#[derive(Debug, Clone, Default)]
pub struct PointShape {
    pub x: f64,
    /// Undeformed body-frame `y` (0 on a beam axis; interface points of flexible bodies).
    pub y: f64,
    pub entries: Vec<(usize, f64, f64, f64)>,
}

impl Ffrf {
    /// Initial guess: the frame state from the description, the elastic coordinates and their
    /// rates (default zero), and the coordinate names `x, y, theta, qf0, ...`.
    pub fn initial_state(&self, item: &str, position: [f64; 2], velocity: [f64; 2], angle: f64, angular_velocity: f64, elastic: &Option<Vec<f64>>, elastic_rates: &Option<Vec<f64>>) -> Result<InitialState> {
        let p = finite_vec2(item, "position", position)?;
        let v = finite_vec2(item, "velocity", velocity)?;
        let mut q = vec![p[0], p[1], angle];
        let mut qd = vec![v[0], v[1], angular_velocity];
        for (what, given, out) in [("elastic", elastic, &mut q), ("elastic_rates", elastic_rates, &mut qd)] {
            match given {
                Some(v) if v.len() != self.n_f => {
                    return Err(Error::invalid(item, format!("{what} must have length {}, got {}", self.n_f, v.len())))
                }
                Some(v) => {
                    check_finite_item(item, what, v)?;
                    out.extend_from_slice(v);
                }
                None => out.resize(out.len() + self.n_f, 0.0),
            }
        }
        let mut names: Vec<String> = ["x", "y", "theta"].map(String::from).to_vec();
        names.extend((0..self.n_f).map(|i| format!("qf{i}")));
        Ok(InitialState { q, qd, names })
    }

    /// The workspace: the constants `a`, `b` of the factor and the per-call buffers.
    pub fn new_data(&self) -> FfrfData {
        let (mut a, mut b) = (self.s_bar[0].clone(), self.s_bar[1].clone());
        self.l_ff.solve_lower(&mut a);
        self.l_ff.solve_lower(&mut b);
        let nf = a.len();
        FfrfData {
            m_rr: [[0.0; 3]; 3],
            cs: [1.0, 0.0],
            m_thf: vec![0.0; nf],
            ab: [dot(&a, &a), dot(&a, &b), dot(&b, &b)],
            a,
            b,
            x2: vec![0.0; nf],
            ls: [[0.0; 3]; 3],
            w: vec![0.0; nf],
        }
    }

    /// `Sigma = s_t + S_bar q_f` (first moment in the body frame).
    #[inline]
    pub fn first_moment(&self, qf: &[f64]) -> [f64; 2] {
        [self.s_t[0] + dot(&self.s_bar[0], qf), self.s_t[1] + dot(&self.s_bar[1], qf)]
    }

    /// The banded products of `mass_and_forces` in one pass over the rows (the constant
    /// matrices share one band layout): `w = s_u0 + M_ff^tr q_f`, `m_thf = s_ju0 - S_tilde q_f`,
    /// `ff = thd^2 w + 2 thd S_tilde qd_f - K_ff q_f`.
    #[inline]
    fn banded_terms(&self, qf: &[f64], qfd: &[f64], thd: f64, w: &mut [f64], m_thf: &mut [f64], ff: &mut [f64]) {
        let (n, hb) = (self.n_f, self.k_ff.hb);
        let width = 2 * hb + 1;
        let (mt, st, kf) = (&self.m_ff_tr.data, &self.s_tilde.data, &self.k_ff.data);
        assert!(self.m_ff_tr.hb == hb && self.s_tilde.hb == hb && mt.len() >= n * width && st.len() >= n * width && kf.len() >= n * width);
        assert!(qf.len() >= n && qfd.len() >= n && w.len() >= n && m_thf.len() >= n && ff.len() >= n);
        for i in 0..n {
            let lo = i.saturating_sub(hb);
            let hi = (i + hb + 1).min(n);
            let base = i * width + hb - i;
            let (mut a_w, mut a_s, mut a_sd, mut a_k) = (0.0, 0.0, 0.0, 0.0);
            for j in lo..hi {
                // SAFETY: lo <= j < hi <= n (vector lengths checked above); base + j =
                // i width + hb + (j - i) with |j - i| <= hb lies in row i of each band
                unsafe {
                    let idx = base.wrapping_add(j);
                    let (x, xd) = (*qf.get_unchecked(j), *qfd.get_unchecked(j));
                    a_w += mt.get_unchecked(idx) * x;
                    let sv = *st.get_unchecked(idx);
                    a_s += sv * x;
                    a_sd += sv * xd;
                    a_k += kf.get_unchecked(idx) * x;
                }
            }
            let wi = self.s_u0[i] + a_w;
            w[i] = wi;
            m_thf[i] = self.s_ju0[i] - a_s;
            ff[i] = thd * thd * wi + 2.0 * thd * a_sd - a_k;
        }
    }

    /// Mass blocks at `q` and generalized forces (see the module docs) into `f` (the body's
    /// segment): inertial velocity terms and `-K_ff q_f`, then the kind's own elastic and
    /// damping forces `elastic(q_f, qd_f, Q_f)`, then gravity.
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut FfrfData, q: &[f64], qd: &[f64], gravity: Option<[f64; 2]>, f: &mut [f64], elastic: impl FnOnce(&[f64], &[f64], &mut [f64])) {
        let nf = self.n_f;
        let thd = qd[2];
        let (s, c) = frame_sin_cos(q[2]);
        let (qf, qfd) = (&q[3..3 + nf], &qd[3..3 + nf]);
        let sig = self.first_moment(qf);
        let sigd = [dot(&self.s_bar[0], qfd), dot(&self.s_bar[1], qfd)]; // S_bar qd_f
        let asig = [c * sig[0] - s * sig[1], s * sig[0] + c * sig[1]];
        let asigd = [c * sigd[0] - s * sigd[1], s * sigd[0] + c * sigd[1]];
        // one pass over the bands (M_Rf = A S_bar is not formed: the factor uses the rotated
        // constants, `dense_block` rebuilds it)
        self.banded_terms(qf, qfd, thd, &mut bd.w, &mut bd.m_thf, &mut f[3..3 + nf]);
        let mut m_thth = self.j0;
        let mut qd_w = 0.0;
        for j in 0..nf {
            m_thth += qf[j] * (self.s_u0[j] + bd.w[j]);
            qd_w += qfd[j] * bd.w[j];
        }
        bd.m_rr = frame_mass_block(self.mass, sig, m_thth, c, s);
        bd.cs = [c, s];
        f[0] = thd * thd * asig[0] + 2.0 * thd * asigd[1];
        f[1] = thd * thd * asig[1] - 2.0 * thd * asigd[0];
        f[2] = -2.0 * thd * qd_w;
        elastic(qf, qfd, &mut f[3..3 + nf]);
        if let Some(g) = gravity {
            add_frame_gravity(self.mass, &bd.m_rr, g, f);
            let atg = [c * g[0] + s * g[1], -s * g[0] + c * g[1]];
            for j in 0..nf {
                f[3 + j] += self.s_bar[0][j] * atg[0] + self.s_bar[1][j] * atg[1];
            }
        }
    }

    /// `M_b = F_b F_b^T` in the order `[r; f]`: `F_b = [[L_s, X], [0, L_ff]]` with the constant
    /// `L_ff L_ff^T = M_ff`, `X = M_rf L_ff^-T` and `L_s L_s^T = m_rr - X X^T`. A call costs one
    /// banded solve (`X_2`), three dot products and a 3x3 Cholesky.
    #[inline]
    pub fn factor(&self, bd: &mut FfrfData) -> bool {
        let mut ls = bd.m_rr;
        bd.x2.copy_from_slice(&bd.m_thf);
        self.l_ff.solve_lower(&mut bd.x2);
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
        let ok = cholesky3(&mut ls);
        bd.ls = ls;
        ok
    }

    /// `v <- F^-1 v`: `v_f <- L_ff^-1 v_f`, `v_r <- L_s^-1 (v_r - X v_f)`.
    #[inline]
    pub fn finv(&self, bd: &FfrfData, v: &mut [f64]) {
        let (vr, vf) = v.split_at_mut(3);
        self.l_ff.solve_lower(vf);
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
        solve_lower3(&bd.ls, vr);
    }

    /// `v <- F^-T v`: `v_r <- L_s^-T v_r`, `v_f <- L_ff^-T (v_f - X^T v_r)`.
    #[inline]
    pub fn finvt(&self, bd: &FfrfData, v: &mut [f64]) {
        let (vr, vf) = v.split_at_mut(3);
        solve_upper3(&bd.ls, vr);
        let [c, s] = bd.cs;
        // X^T v_r = (c v0 + s v1) a + (-s v0 + c v1) b + v2 X_2
        let (ka, kb, kx) = (c * vr[0] + s * vr[1], -s * vr[0] + c * vr[1], vr[2]);
        for (((f, a), bb), x) in vf.iter_mut().zip(&bd.a).zip(&bd.b).zip(&bd.x2) {
            *f -= ka * a + kb * bb + kx * x;
        }
        self.l_ff.solve_upper(vf);
    }

    /// `M_Rf = A S_bar` entry `(i, j)`, `i` in 0..3 (row 2: `m_thetaf`).
    #[inline]
    fn m_rf(&self, bd: &FfrfData, i: usize, j: usize) -> f64 {
        let [c, s] = bd.cs;
        match i {
            0 => c * self.s_bar[0][j] - s * self.s_bar[1][j],
            1 => s * self.s_bar[0][j] + c * self.s_bar[1][j],
            _ => bd.m_thf[j],
        }
    }

    /// `out += M_b x` from the blocks (`x`, `out`: the body's segments; allocation free).
    pub fn mass_times(&self, bd: &FfrfData, x: &[f64], out: &mut [f64]) {
        let (xr, xf) = x.split_at(3);
        let (or, of) = out.split_at_mut(3);
        let [c, s] = bd.cs;
        let (s0, s1, t) = (dot(&self.s_bar[0], xf), dot(&self.s_bar[1], xf), dot(&bd.m_thf, xf));
        for i in 0..3 {
            or[i] += bd.m_rr[i][0] * xr[0] + bd.m_rr[i][1] * xr[1] + bd.m_rr[i][2] * xr[2];
        }
        or[0] += c * s0 - s * s1;
        or[1] += s * s0 + c * s1;
        or[2] += t;
        let (ka, kb) = (c * xr[0] + s * xr[1], -s * xr[0] + c * xr[1]);
        for (((o, a), b), m) in of.iter_mut().zip(&self.s_bar[0]).zip(&self.s_bar[1]).zip(&bd.m_thf) {
            *o += ka * a + kb * b + xr[2] * m;
        }
        self.m_ff.mul_add(1.0, xf, of);
    }

    /// Visit the entries of `M_b` (body coordinates).
    pub fn dense_block(&self, bd: &FfrfData, put: &mut impl FnMut(usize, usize, f64)) {
        for i in 0..3 {
            for j in 0..3 {
                put(i, j, bd.m_rr[i][j]);
            }
            for j in 0..self.n_f {
                let v = self.m_rf(bd, i, j);
                put(i, 3 + j, v);
                put(3 + j, i, v);
            }
        }
        self.m_ff.visit(&mut |i, j, v| put(3 + i, 3 + j, v));
    }

    /// `1/2 qd^T M_b qd` from the blocks (no dense matrix).
    pub fn kinetic_energy(&self, bd: &FfrfData, qd: &[f64]) -> f64 {
        let (qr, qf) = qd.split_at(3);
        let mut e = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                e += qr[i] * bd.m_rr[i][j] * qr[j];
            }
            let mut cross = 0.0;
            for (j, v) in qf.iter().enumerate() {
                cross += self.m_rf(bd, i, j) * v;
            }
            e += 2.0 * qr[i] * cross;
        }
        e += self.m_ff.bilinear(qf, qf);
        0.5 * e
    }

    /// `1/2 q_f^T K_ff q_f`: the strain energy of the linear elastic law.
    pub fn linear_strain_energy(&self, qf: &[f64]) -> f64 {
        0.5 * self.k_ff.bilinear(qf, qf)
    }

    /// `int rho r dV = m R + A Sigma`.
    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        frame_mass_moment(self.mass, self.first_moment(&q[3..3 + self.n_f]), q)
    }
}

/// Marker point: body-frame position `(x + u, y + v)`, elastic velocity, rotation `psi`.
#[inline]
pub fn marker_state(ps: &PointShape, angle: f64, q: &[f64], qd: &[f64]) -> MarkerState {
    let (qf, qfd) = (&q[3..], &qd[3..]);
    let (mut pl, mut vl, mut psi, mut psid) = ([ps.x, ps.y], [0.0; 2], 0.0, 0.0);
    for &(i, su, sv, sp) in &ps.entries {
        pl[0] += su * qf[i];
        pl[1] += sv * qf[i];
        vl[0] += su * qfd[i];
        vl[1] += sv * qfd[i];
        psi += sp * qf[i];
        psid += sp * qfd[i];
    }
    frame_point_state(pl, vl, angle + psi, psid, q, qd)
}

#[inline]
pub fn add_point_jacobian(ps: &PointShape, ms: &MarkerState, w: [f64; 2], row: &mut [f64]) {
    add_frame_point_jacobian(ms, w, row);
    let [c, s] = ms.cs;
    // w . A (S_u, S_v)
    let (wa0, wa1) = (w[0] * c + w[1] * s, -w[0] * s + w[1] * c);
    for &(i, su, sv, _) in &ps.entries {
        row[3 + i] += wa0 * su + wa1 * sv;
    }
}

#[inline]
pub fn add_angle_jacobian(ps: &PointShape, w: f64, row: &mut [f64]) {
    row[2] += w;
    for &(i, _, _, sp) in &ps.entries {
        row[3 + i] += w * sp;
    }
}
