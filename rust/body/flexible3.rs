//! Spatial floating-frame modal body ("flexible3", docs/spatial-flexible.md): coordinates
//! `[r (3), p (4), q_f (n)]`, `r` the origin of the floating frame, `p` its Euler parameters (the
//! orientation coordinates of the spatial rigid body, `rigid3.rs`, with the same normalization
//! row and the same regularization), `q_f` the modal coordinates. A material point sits at
//! `r + R u`, `u = u0 + S q_f = sum_a xi_a S_a` with `xi = [1, q_f]`, `S_0 = u0`.
//!
//! Inertia invariants (Shabana, "Dynamics of Multibody Systems", ch. 5, in the compact form of
//! the extended shapes): `F_a = int rho S_a dV` and `P_ab = int rho S_a S_b^T dV`. Per call,
//! `C_b = sum_a xi_a P_ab = int rho u S_b^T`, `W = sum_b xi_b C_b = int rho u u^T`, and
//!
//! * `S_t = sum_a xi_a F_a` (first moment), `I_tt = tr(W) I - W` (inertia about the frame origin),
//!   `I_tf[:, j] = ax(C_j) = int rho u x S_j` (`ax(C)_a = eps_abc C_bc`), `M_ff = tr P_jk`;
//! * the mass matrix in the velocity coordinates `v = [R^T rd, w', qd_f]` (`w' = 2 G pd`):
//!   `Mv = [[m I, -~S_t, S_bar], [., I_tt, I_tf], [., ., M_ff]]`;
//! * the quadratic velocity forces (d'Alembert on `a = R (R^T rdd + w'd x u + S qdd_f
//!   + w' x (w' x u) + 2 w' x S qd_f)`), with `D = sum_j qd_j C_j^T = int rho (S qd_f) u^T`:
//!   `Q_r = -w' x (w' x S_t) - 2 w' x (S_bar qd_f)`, `Q_w = -w' x I_tt w' - 2 (tr(D) w' - D w')`,
//!   `Q_f,j = |w'|^2 tr C_j - w'^T C_j w' - 2 sum_k qd_k w' . ax(P_kj)`; elastic
//!   `-K_ff q_f - D_ff qd_f`; gravity `Q_r = m R^T g`, `Q_w = S_t x R^T g`, `Q_f = S_bar^T R^T g`.
//!
//! In the coordinates `q`, `v = T qd` with `T = diag(R^T, 2 G, I)` (and `vd = T qdd + Td qd` with
//! `Td qd = [-w' x R^T rd, 0, 0]`, which `Q_r` above already contains: it is written for the
//! body-frame translational velocity), so `M = T^T Mv T + 4 k p p^T` (the regularization of
//! `rigid3.rs`, `k = tr(I_tt(0)) / 3`) and `Q = T^T (Q_v + Q_el + Q_g) - 4 k (pd . pd) p`.
//! The factor is `F = T^T diag(L, sqrt k)` with `Mv = L L^T` (a Cholesky of `6 + n` per call)
//! in the layout `z = [r (3), w (3), normalization (1), f (n)]`: the normalization row maps to
//! the unit coordinate 6, as for `rigid3`. `R = A(p) / |p|^2` (a rotation off `|p| = 1`).

use super::InitialState;
use crate::description::spatial::Flexible3Desc;
use crate::error::{check_finite_item, positive, Error, Result};
use crate::linalg::dense::cholesky;
use crate::linalg::rot3::{cross, dot, mat_t_vec, mat_vec, rot_a, rot_e, rot_g, M3, V3};
use super::flexible3_stiffening::GeometricStiffness;
use super::flexible3_strain::QuadraticStrain;

pub use super::rigid3::NORMALIZATION_COORD;

/// Largest number of modes of one flexible3 body (its blocks are dense).
pub const MAX_MODES: usize = 200;

/// An interface node: undeformed point (frame axes), nodal displacement and rotation per mode.
#[derive(Debug, Clone)]
pub struct Interface3 {
    pub point: V3,
    pub phi: Vec<V3>,
    pub psi: Vec<V3>,
}

#[derive(Debug, Clone)]
pub struct Flexible3 {
    pub mass: f64,
    pub n: usize,
    /// `F_a`, `a = 0..=n`.
    pub first: Vec<V3>,
    /// `P_ab` at `a (n + 1) + b`.
    pub second: Vec<M3>,
    /// `M_ff` (n x n, row-major), the trace of `P_jk`.
    pub m_ff: Vec<f64>,
    pub k_ff: Vec<f64>,
    pub d_ff: Option<Vec<f64>>,
    /// Regularization weight of the Euler parameters and `1/sqrt(k)`.
    pub k: f64,
    pub inv_sqrt_k: f64,
    pub interfaces: Vec<Interface3>,
    /// A length of the body (`sqrt(tr P_00 / m)`), the scale of the interface-point match.
    pub size: f64,
    /// Stress stiffening (`flexible3_stiffening.rs`), when the data carry it.
    pub stiffening: Option<GeometricStiffness>,
    /// The quadratic strain's cubic energy (`flexible3_strain.rs`), when the data carry it.
    pub strain: Option<QuadraticStrain>,
}

/// Workspace: the state of the last `mass_and_forces`, the velocity-space mass matrix and its
/// Cholesky factor (`(6 + n)^2`, row-major), and `C_b` (n + 1).
#[derive(Debug, Clone)]
pub struct Flexible3Data {
    pub p: [f64; 4],
    pub p2: f64,
    /// `R = A(p) / |p|^2`.
    pub r: M3,
    pub mv: Vec<f64>,
    pub l: Vec<f64>,
    pub c: Vec<M3>,
}

/// `ax(C)`: the vector of `int rho u x S` from `C = int rho u S^T`.
#[inline]
fn axial(c: &M3) -> V3 {
    [c[1][2] - c[2][1], c[2][0] - c[0][2], c[0][1] - c[1][0]]
}

/// Index of the factor's layout `z` (skipping the normalization coordinate 6).
#[inline]
fn zi(i: usize) -> usize {
    if i < 6 {
        i
    } else {
        i + 1
    }
}

impl Flexible3 {
    pub fn from_desc(d: &Flexible3Desc, item: &str) -> Result<Flexible3> {
        let mass = positive(item, "mass", d.mass)?;
        let n = d.k_ff.len();
        if n > MAX_MODES {
            return Err(Error::invalid(item, format!("at most {MAX_MODES} modes, got {n} (k_ff is {n} x {n})")));
        }
        let n1 = n + 1;
        if d.first_moment.len() != n1 {
            return Err(Error::invalid(item, format!("first_moment must hold n + 1 = {n1} vectors (n = {n}, the size of k_ff), got {}", d.first_moment.len())));
        }
        if d.second_moment.len() != n1 * n1 {
            return Err(Error::invalid(item, format!("second_moment must hold (n + 1)^2 = {} 3x3 matrices (n = {n}), got {}", n1 * n1, d.second_moment.len())));
        }
        check_finite_item(item, "first_moment", &d.first_moment.concat())?;
        let flat: Vec<f64> = d.second_moment.iter().flat_map(|m| m.iter().flatten().copied()).collect();
        check_finite_item(item, "second_moment", &flat)?;
        let big = flat.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for a in 0..n1 {
            for b in 0..n1 {
                for i in 0..3 {
                    for j in 0..3 {
                        let (x, y) = (d.second_moment[a * n1 + b][i][j], d.second_moment[b * n1 + a][j][i]);
                        if (x - y).abs() > 1e-9 * big {
                            return Err(Error::invalid(item, format!("second_moment: P_ab must equal P_ba^T (int rho S_a S_b^T dV), entry ({a}, {b})[{i}][{j}] = {x} but ({b}, {a})[{j}][{i}] = {y}")));
                        }
                    }
                }
            }
        }
        let (k_ff, _) = super::flexible::square(item, "k_ff", &d.k_ff, n)?;
        let d_ff = d.d_ff.as_ref().map(|rows| super::flexible::square(item, "d_ff", rows, n).map(|x| x.0)).transpose()?;
        let mut m_ff = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let p = &d.second_moment[(i + 1) * n1 + j + 1];
                m_ff[i * n + j] = p[0][0] + p[1][1] + p[2][2];
            }
        }
        let p00 = &d.second_moment[0];
        let tr0 = p00[0][0] + p00[1][1] + p00[2][2];
        // k = tr(I_tt(0)) / 3 = 2 tr(P_00) / 3
        let k = 2.0 * tr0 / 3.0;
        let size = (tr0 / mass).sqrt();
        let mut interfaces = Vec::with_capacity(d.interfaces.len());
        for (i, f) in d.interfaces.iter().enumerate() {
            check_finite_item(item, &format!("interfaces[{i}].point"), &f.point)?;
            let psi = f.psi.clone().unwrap_or_else(|| vec![[0.0; 3]; n]);
            for (what, v) in [("phi", &f.phi), ("psi", &psi)] {
                if v.len() != n {
                    return Err(Error::invalid(item, format!("interfaces[{i}].{what} must hold n = {n} vectors (one per mode), got {}", v.len())));
                }
                check_finite_item(item, &format!("interfaces[{i}].{what}"), &v.concat())?;
            }
            interfaces.push(Interface3 { point: f.point, phi: f.phi.clone(), psi });
        }
        let stiffening = d.geometric_stiffness.as_ref().map(|g| GeometricStiffness::from_desc(item, g, n)).transpose()?;
        let strain = d.quadratic_strain.as_ref().map(|g| QuadraticStrain::from_desc(item, g, d.quadratic_strain_quartic.as_ref(), n)).transpose()?;
        let body = Flexible3 { mass, n, first: d.first_moment.clone(), second: d.second_moment.clone(), m_ff, k_ff, d_ff, k, inv_sqrt_k: 1.0 / k.max(f64::MIN_POSITIVE).sqrt(), interfaces, size, stiffening, strain };
        body.check_definite(item)?;
        Ok(body)
    }

    /// `K_ff`, `D_ff` symmetric, `K_ff` positive definite, `D_ff` semi-definite, and the mass
    /// matrix at `q_f = 0` positive definite (one mass distribution).
    fn check_definite(&self, item: &str) -> Result<()> {
        let n = self.n;
        let kbig = self.k_ff.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        super::flexible::check_symmetry(item, "k_ff", &self.k_ff, n, kbig, 1.0)?;
        let mut kc = self.k_ff.clone();
        if let Err((p, v)) = cholesky(&mut kc, n, 1e-12) {
            return Err(Error::invalid(item, format!("k_ff must be positive definite (pivot {p} = {v:e}): rigid-body modes belong to the floating frame, not to q_f")));
        }
        if let Some(dd) = &self.d_ff {
            let dbig = dd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            super::flexible::check_symmetry(item, "d_ff", dd, n, dbig, 1.0)?;
            let mut dc = dd.clone();
            for i in 0..n {
                dc[i * n + i] += 1e-12 * dbig + f64::MIN_POSITIVE;
            }
            if cholesky(&mut dc, n, 0.0).is_err() {
                return Err(Error::invalid(item, "d_ff must be positive semi-definite"));
            }
        }
        let mut bd = self.new_data();
        let q: Vec<f64> = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0].into_iter().chain(std::iter::repeat(0.0).take(n)).collect();
        let mut f = vec![0.0; 7 + n];
        self.mass_and_forces(&mut bd, &q, &vec![0.0; 7 + n], None, &mut f);
        if !self.factor(&mut bd) {
            return Err(Error::SingularMass {
                item: format!("{item}: the mass matrix at q_f = 0 is not positive definite: mass, first_moment and second_moment do not belong to one mass distribution"),
            });
        }
        Ok(())
    }

    pub fn initial_state(&self, d: &Flexible3Desc, item: &str) -> Result<InitialState> {
        for (what, v) in [("position", &d.position), ("velocity", &d.velocity), ("angular_velocity", &d.angular_velocity)] {
            check_finite_item(item, what, v)?;
        }
        let p = super::rigid3::orientation_p(item, d.orientation.as_ref())?;
        let e = rot_e(&p);
        let w = d.angular_velocity;
        let mut q = vec![d.position[0], d.position[1], d.position[2], p[0], p[1], p[2], p[3]];
        let mut qd = vec![d.velocity[0], d.velocity[1], d.velocity[2]];
        for l in 0..4 {
            qd.push(0.5 * (e[0][l] * w[0] + e[1][l] * w[1] + e[2][l] * w[2]));
        }
        for (what, given, out) in [("elastic", &d.elastic, &mut q), ("elastic_rates", &d.elastic_rates, &mut qd)] {
            match given {
                Some(v) if v.len() != self.n => return Err(Error::invalid(item, format!("{what} must have length {}, got {}", self.n, v.len()))),
                Some(v) => {
                    check_finite_item(item, what, v)?;
                    out.extend_from_slice(v);
                }
                None => out.resize(out.len() + self.n, 0.0),
            }
        }
        let mut names: Vec<String> = ["x", "y", "z", "e0", "e1", "e2", "e3"].map(String::from).to_vec();
        names.extend((0..self.n).map(|i| format!("qf{i}")));
        Ok(InitialState { q, qd, names })
    }

    pub fn new_data(&self) -> Flexible3Data {
        let m = 6 + self.n;
        Flexible3Data { p: [1.0, 0.0, 0.0, 0.0], p2: 1.0, r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], mv: vec![0.0; m * m], l: vec![0.0; m * m], c: vec![[[0.0; 3]; 3]; self.n + 1] }
    }

    /// `S_t = sum_a xi_a F_a`.
    #[inline]
    pub fn first_moment(&self, qf: &[f64]) -> V3 {
        let mut s = self.first[0];
        for (j, x) in qf.iter().enumerate() {
            for c in 0..3 {
                s[c] += x * self.first[j + 1][c];
            }
        }
        s
    }

    /// `R` and `w' = 2 G pd` (body axes) at `p`, `pd`; `|p|^2`.
    #[inline]
    pub fn frame(p: &[f64], pd: &[f64]) -> (M3, V3, f64) {
        let p2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
        let r = rot_a(p).map(|row| row.map(|x| x / p2));
        let g = rot_g(p);
        let mut w = [0.0; 3];
        for i in 0..3 {
            w[i] = 2.0 * (g[i][0] * pd[0] + g[i][1] * pd[1] + g[i][2] * pd[2] + g[i][3] * pd[3]);
        }
        (r, w, p2)
    }

    /// `C_b` into the workspace and `W = int rho u u^T`.
    fn moments(&self, bd: &mut Flexible3Data, qf: &[f64]) -> M3 {
        let n1 = self.n + 1;
        let mut wm = [[0.0; 3]; 3];
        for b in 0..n1 {
            let mut c = self.second[b];
            for (a, x) in qf.iter().enumerate() {
                let p = &self.second[(a + 1) * n1 + b];
                for i in 0..3 {
                    for j in 0..3 {
                        c[i][j] += x * p[i][j];
                    }
                }
            }
            let xb = if b == 0 { 1.0 } else { qf[b - 1] };
            for i in 0..3 {
                for j in 0..3 {
                    wm[i][j] += xb * c[i][j];
                }
            }
            bd.c[b] = c;
        }
        wm
    }

    /// Mass matrix (velocity coordinates, into the workspace) and generalized forces (module
    /// docs). Gravity is the scene's force element (`force::spatial`, `add_gravity`).
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut Flexible3Data, q: &[f64], qd: &[f64], _gravity: Option<[f64; 2]>, f: &mut [f64]) {
        let n = self.n;
        let m = 6 + n;
        let (p, pd) = (&q[3..7], &qd[3..7]);
        let (qf, qfd) = (&q[7..7 + n], &qd[7..7 + n]);
        let (r, w, p2) = Self::frame(p, pd);
        bd.p = [p[0], p[1], p[2], p[3]];
        bd.p2 = p2;
        bd.r = r;
        let wm = self.moments(bd, qf);
        let st = self.first_moment(qf);
        let tr = wm[0][0] + wm[1][1] + wm[2][2];
        let mut itt = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                itt[i][j] = if i == j { tr } else { 0.0 } - wm[i][j];
            }
        }
        // the mass matrix Mv
        let mv = &mut bd.mv;
        mv.fill(0.0);
        let skew = [[0.0, -st[2], st[1]], [st[2], 0.0, -st[0]], [-st[1], st[0], 0.0]];
        for i in 0..3 {
            mv[i * m + i] = self.mass;
            for j in 0..3 {
                mv[i * m + 3 + j] = -skew[i][j];
                mv[(3 + j) * m + i] = -skew[i][j];
                mv[(3 + i) * m + 3 + j] = itt[i][j];
            }
        }
        for j in 0..n {
            let fj = &self.first[j + 1];
            let ax = axial(&bd.c[j + 1]);
            for i in 0..3 {
                mv[i * m + 6 + j] = fj[i];
                mv[(6 + j) * m + i] = fj[i];
                mv[(3 + i) * m + 6 + j] = ax[i];
                mv[(6 + j) * m + 3 + i] = ax[i];
            }
            for k in 0..n {
                mv[(6 + j) * m + 6 + k] = self.m_ff[j * n + k];
            }
        }
        // quadratic velocity forces
        let mut sbd = [0.0; 3];
        let mut dm = [[0.0; 3]; 3];
        for (j, x) in qfd.iter().enumerate() {
            let c = &bd.c[j + 1];
            for i in 0..3 {
                sbd[i] += x * self.first[j + 1][i];
                for l in 0..3 {
                    dm[i][l] += x * c[l][i];
                }
            }
        }
        let wst = cross(&w, &st);
        let wwst = cross(&w, &wst);
        let wsbd = cross(&w, &sbd);
        let qr = [-wwst[0] - 2.0 * wsbd[0], -wwst[1] - 2.0 * wsbd[1], -wwst[2] - 2.0 * wsbd[2]];
        let iw = mat_vec(&itt, &w);
        let wiw = cross(&w, &iw);
        let trd = dm[0][0] + dm[1][1] + dm[2][2];
        let dw = mat_vec(&dm, &w);
        let qw = [0, 1, 2].map(|i| -wiw[i] - 2.0 * (trd * w[i] - dw[i]));
        let ww = dot(&w, &w);
        let n1 = n + 1;
        for j in 0..n {
            let c = &bd.c[j + 1];
            let mut v = ww * (c[0][0] + c[1][1] + c[2][2]) - dot(&w, &mat_vec(c, &w));
            for (k, x) in qfd.iter().enumerate() {
                v -= 2.0 * x * dot(&w, &axial(&self.second[(k + 1) * n1 + j + 1]));
            }
            for k in 0..n {
                v -= self.k_ff[j * n + k] * qf[k];
                if let Some(dd) = &self.d_ff {
                    v -= dd[j * n + k] * qfd[k];
                }
            }
            f[7 + j] = v;
        }
        if let Some(g) = &self.stiffening {
            g.add_forces(&w, &mat_t_vec(&r, &[qd[0], qd[1], qd[2]]), qf, &mut f[7..7 + n]);
        }
        if let Some(s) = &self.strain {
            s.add_forces(qf, &mut f[7..7 + n]);
        }
        let fr = mat_vec(&r, &qr);
        f[0..3].copy_from_slice(&fr);
        self.put_rotational(bd, &qw, pd, &mut f[3..7]);
    }

    /// `f_p = 2 G^T q_w - 4 k (pd . pd) p` (the regularization's shift as in `rigid3.rs`).
    #[inline]
    fn put_rotational(&self, bd: &Flexible3Data, qw: &V3, pd: &[f64], fp: &mut [f64]) {
        let g = rot_g(&bd.p);
        let pdd = pd[0] * pd[0] + pd[1] * pd[1] + pd[2] * pd[2] + pd[3] * pd[3];
        for l in 0..4 {
            fp[l] = 2.0 * (g[0][l] * qw[0] + g[1][l] * qw[1] + g[2][l] * qw[2]) - 4.0 * self.k * pdd * bd.p[l];
        }
    }

    /// Cholesky of `Mv` (after `mass_and_forces`).
    #[inline]
    pub fn factor(&self, bd: &mut Flexible3Data) -> bool {
        if !(bd.p2 > 1e-200 && bd.p2.is_finite()) {
            return false;
        }
        bd.l.copy_from_slice(&bd.mv);
        cholesky(&mut bd.l, 6 + self.n, 1e-14).is_ok()
    }

    /// `v <- F^-1 v = diag(L^-1, 1/sqrt k) T^-T v`, `T^-T = diag(R^T, N / (2 |p|^2), I)`.
    #[inline]
    pub fn finv(&self, bd: &Flexible3Data, v: &mut [f64]) {
        let m = 6 + self.n;
        let vr = mat_t_vec(&bd.r, &[v[0], v[1], v[2]]);
        let g = rot_g(&bd.p);
        let p = &bd.p;
        let vp = [v[3], v[4], v[5], v[6]];
        let s = 0.5 / bd.p2;
        for i in 0..3 {
            v[i] = vr[i];
            v[3 + i] = s * (g[i][0] * vp[0] + g[i][1] * vp[1] + g[i][2] * vp[2] + g[i][3] * vp[3]);
        }
        v[6] = s * (p[0] * vp[0] + p[1] * vp[1] + p[2] * vp[2] + p[3] * vp[3]) * self.inv_sqrt_k;
        let l = &bd.l;
        for i in 0..m {
            let mut acc = v[zi(i)];
            for c in 0..i {
                acc -= l[i * m + c] * v[zi(c)];
            }
            v[zi(i)] = acc / l[i * m + i];
        }
    }

    /// `v <- F^-T v = T^-1 diag(L^-T, 1/sqrt k) v`, `T^-1 = diag(R, N^T / (2 |p|^2), I)`.
    #[inline]
    pub fn finvt(&self, bd: &Flexible3Data, v: &mut [f64]) {
        let m = 6 + self.n;
        let l = &bd.l;
        for i in (0..m).rev() {
            let mut acc = v[zi(i)];
            for c in i + 1..m {
                acc -= l[c * m + i] * v[zi(c)];
            }
            v[zi(i)] = acc / l[i * m + i];
        }
        let vr = mat_vec(&bd.r, &[v[0], v[1], v[2]]);
        v[0..3].copy_from_slice(&vr);
        let g = rot_g(&bd.p);
        let (uw, z4) = ([v[3], v[4], v[5]], v[6] * self.inv_sqrt_k);
        let s = 0.5 / bd.p2;
        for c in 0..4 {
            v[3 + c] = s * (g[0][c] * uw[0] + g[1][c] * uw[1] + g[2][c] * uw[2] + bd.p[c] * z4);
        }
    }

    /// `out += M x` with `M = T^T Mv T + 4 k p p^T`.
    pub fn mass_times(&self, bd: &Flexible3Data, x: &[f64], out: &mut [f64]) {
        let m = 6 + self.n;
        let g = rot_g(&bd.p);
        let xr = mat_t_vec(&bd.r, &[x[0], x[1], x[2]]);
        let mut xw = [0.0; 3];
        for i in 0..3 {
            xw[i] = 2.0 * (g[i][0] * x[3] + g[i][1] * x[4] + g[i][2] * x[5] + g[i][3] * x[6]);
        }
        let y = |j: usize| if j < 3 { xr[j] } else if j < 6 { xw[j - 3] } else { x[j + 1] };
        let (mut zr, mut zw) = ([0.0; 3], [0.0; 3]);
        for i in 0..m {
            let zi_: f64 = (0..m).map(|j| bd.mv[i * m + j] * y(j)).sum();
            if i < 3 {
                zr[i] = zi_;
            } else if i < 6 {
                zw[i - 3] = zi_;
            } else {
                out[i + 1] += zi_;
            }
        }
        let or = mat_vec(&bd.r, &zr);
        let px: f64 = (0..4).map(|c| bd.p[c] * x[3 + c]).sum();
        for c in 0..3 {
            out[c] += or[c];
        }
        for c in 0..4 {
            out[3 + c] += 2.0 * (g[0][c] * zw[0] + g[1][c] * zw[1] + g[2][c] * zw[2]) + 4.0 * self.k * bd.p[c] * px;
        }
    }

    /// The entries of `M` (inspection, correction; allocates).
    pub fn dense_block(&self, bd: &Flexible3Data, put: &mut impl FnMut(usize, usize, f64)) {
        let nb = 7 + self.n;
        let mut x = vec![0.0; nb];
        let mut col = vec![0.0; nb];
        for j in 0..nb {
            x.fill(0.0);
            x[j] = 1.0;
            col.fill(0.0);
            self.mass_times(bd, &x, &mut col);
            for (i, v) in col.iter().enumerate() {
                put(i, j, *v);
            }
        }
    }

    /// `1/2 v^T Mv v`, `v = [R^T rd, 2 G pd, qd_f]` (the true kinetic energy; the
    /// regularization adds nothing on the manifold).
    pub fn kinetic_energy(&self, bd: &Flexible3Data, qd: &[f64]) -> f64 {
        let m = 6 + self.n;
        let (_, w, _) = Self::frame(&bd.p, &qd[3..7]);
        let vr = mat_t_vec(&bd.r, &[qd[0], qd[1], qd[2]]);
        let y = |j: usize| if j < 3 { vr[j] } else if j < 6 { w[j - 3] } else { qd[j + 1] };
        let mut e = 0.0;
        for i in 0..m {
            let yi = y(i);
            for j in 0..m {
                e += yi * bd.mv[i * m + j] * y(j);
            }
        }
        0.5 * e
    }

    /// `1/2 q_f^T K_ff q_f` (+ the quadratic strain's `V3`, `flexible3_strain.rs`).
    pub fn strain_energy(&self, q: &[f64]) -> f64 {
        self.material_energy(q, q) + self.strain.as_ref().map_or(0.0, |s| s.energy(&q[7..7 + self.n]))
    }

    /// `1/2 v_f^T K_ff v_f` (body segments).
    pub fn material_energy(&self, _q: &[f64], v: &[f64]) -> f64 {
        let n = self.n;
        let vf = &v[7..7 + n];
        let mut e = 0.0;
        for i in 0..n {
            for j in 0..n {
                e += vf[i] * self.k_ff[i * n + j] * vf[j];
            }
        }
        0.5 * e
    }

    /// `-dQ/dq_f = K_ff (+ K_g(w', v')) (+ d2V3/dq_f^2)`, `-dQ/dqd_f = D_ff` (body coordinates;
    /// the stress stiffening's dependence on the frame's rates is left to the differences).
    pub fn tangent(&self, q: &[f64], qd: &[f64], k: &mut impl FnMut(usize, usize, f64), c: &mut impl FnMut(usize, usize, f64)) {
        let n = self.n;
        if let Some(s) = &self.strain {
            s.tangent(&q[7..7 + n], &mut |i, j, v| k(7 + i, 7 + j, v));
        }
        if let Some(g) = &self.stiffening {
            let (r, w, _) = Self::frame(&q[3..7], &qd[3..7]);
            g.tangent(&w, &mat_t_vec(&r, &[qd[0], qd[1], qd[2]]), &mut |i, j, v| k(7 + i, 7 + j, v));
        }
        for i in 0..n {
            for j in 0..n {
                k(7 + i, 7 + j, self.k_ff[i * n + j]);
                if let Some(dd) = &self.d_ff {
                    c(7 + i, 7 + j, dd[i * n + j]);
                }
            }
        }
    }

    /// Gravity `g` (world) into the body's segment `f` of `Q` (module docs).
    pub fn add_gravity(&self, q: &[f64], g: &V3, f: &mut [f64]) {
        let n = self.n;
        let p = &q[3..7];
        let (r, _, _) = Self::frame(p, &[0.0; 4]);
        let gb = mat_t_vec(&r, g);
        let st = self.first_moment(&q[7..7 + n]);
        for c in 0..3 {
            f[c] += self.mass * g[c];
        }
        let mut qw = cross(&st, &gb);
        if let Some(s) = &self.stiffening {
            s.add_gravity(&gb, &q[7..7 + n], &mut qw, &mut f[7..7 + n]);
        }
        let gm = rot_g(p);
        for l in 0..4 {
            f[3 + l] += 2.0 * (gm[0][l] * qw[0] + gm[1][l] * qw[1] + gm[2][l] * qw[2]);
        }
        for j in 0..n {
            f[7 + j] += dot(&self.first[j + 1], &gb);
        }
    }

    /// `-g . int rho r_P dV = -g . (m r + R S_t)` (and the prestress's `1/2 q_f^T K_g(R^T g) q_f`).
    pub fn gravity_potential(&self, q: &[f64], g: &V3) -> f64 {
        let (r, _, _) = Self::frame(&q[3..7], &[0.0; 4]);
        let c = mat_vec(&r, &self.first_moment(&q[7..7 + self.n]));
        let prestress = self.stiffening.as_ref().map_or(0.0, |s| s.gravity_potential(&mat_t_vec(&r, g), &q[7..7 + self.n]));
        prestress - (0..3).map(|i| g[i] * (self.mass * q[i] + c[i])).sum::<f64>()
    }

    /// Linear momentum and angular momentum about the world origin (sensors; allocates).
    pub fn momentum(&self, q: &[f64], qd: &[f64]) -> (V3, V3) {
        let n = self.n;
        let mut bd = self.new_data();
        let mut f = vec![0.0; 7 + n];
        self.mass_and_forces(&mut bd, q, qd, None, &mut f);
        let (r, w, _) = Self::frame(&q[3..7], &qd[3..7]);
        let m = 6 + n;
        let vr = mat_t_vec(&r, &[qd[0], qd[1], qd[2]]);
        let y = |j: usize| if j < 3 { vr[j] } else if j < 6 { w[j - 3] } else { qd[j + 1] };
        // Mv v: its r rows are R^T (linear momentum), its w rows the angular momentum about the
        // frame origin in frame axes
        let mut z = [0.0; 6];
        for (i, zi_) in z.iter_mut().enumerate() {
            *zi_ = (0..m).map(|j| bd.mv[i * m + j] * y(j)).sum();
        }
        let lin = mat_vec(&r, &[z[0], z[1], z[2]]);
        let ang0 = mat_vec(&r, &[z[3], z[4], z[5]]);
        let ro = [q[0], q[1], q[2]];
        let rl = cross(&ro, &lin);
        (lin, [ang0[0] + rl[0], ang0[1] + rl[1], ang0[2] + rl[2]])
    }

    /// `m r` (its planar part: the 2D gravity potential is never asked of a spatial body).
    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        [self.mass * q[0], self.mass * q[1]]
    }

    /// The interface node at `point` (frame axes), within `1e-9` of the body's size.
    pub fn interface_at(&self, point: &V3) -> Option<usize> {
        let tol = 1e-9 * self.size.max(f64::MIN_POSITIVE);
        self.interfaces.iter().position(|f| (0..3).all(|c| (f.point[c] - point[c]).abs() <= tol))
    }

    /// Elastic Jacobian columns of a marker quantity: `which = 1` the point (`A Phi`),
    /// `2 + k` the axis `c` (`A (-~c Psi)`): `row_f += Phi^T (A^T w)`, resp.
    /// `Psi^T (c x A^T w)`.
    #[inline]
    pub fn add_marker_jacobian(&self, iface: usize, which: u8, c: &V3, a: &M3, w: &V3, row_f: &mut [f64]) {
        let f = &self.interfaces[iface];
        let aw = mat_t_vec(a, w);
        if which == 1 {
            for (j, ph) in f.phi.iter().enumerate() {
                row_f[j] += dot(ph, &aw);
            }
        } else {
            let cw = cross(c, &aw);
            for (j, ps) in f.psi.iter().enumerate() {
                row_f[j] += dot(ps, &cw);
            }
        }
    }

    /// The interface's deformed point `u0 + Phi q_f` and its rate, and the small rotation
    /// `Psi q_f` and its rate (frame axes).
    #[inline]
    pub fn interface_state(&self, iface: usize, qf: &[f64], qfd: &[f64]) -> [V3; 4] {
        let f = &self.interfaces[iface];
        let (mut s, mut sd, mut th, mut thd) = (f.point, [0.0; 3], [0.0; 3], [0.0; 3]);
        for j in 0..self.n {
            for c in 0..3 {
                s[c] += f.phi[j][c] * qf[j];
                sd[c] += f.phi[j][c] * qfd[j];
                th[c] += f.psi[j][c] * qf[j];
                thd[c] += f.psi[j][c] * qfd[j];
            }
        }
        [s, sd, th, thd]
    }

    /// Inspection entries (`inspect.rs`).
    pub fn info(&self, m: &mut serde_json::Map<String, serde_json::Value>) {
        m.insert("n_modes".into(), self.n.into());
        m.insert("interfaces".into(), self.interfaces.iter().map(|f| f.point.to_vec()).collect::<Vec<_>>().into());
        m.insert("first_moment".into(), self.first[0].to_vec().into());
        m.insert("stress_stiffening".into(), self.stiffening.is_some().into());
        m.insert("quadratic_strain".into(), self.strain.is_some().into());
    }
}
