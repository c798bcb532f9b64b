//! Spatial rigid body (docs/spatial-design.md, sections 1 and 3): coordinates `[r (3), p (4)]`,
//! `r` the centre of mass (world), `p` the Euler parameters of the body frame; a centre-of-mass
//! offset is absorbed into the markers when the model is built (`marker3.rs`).
//!
//! Mass block `diag(m I, 4 G^T J G)` is singular (`G p = 0`); the block the UK solve factors is
//! the one regularized by the body's normalization row (`alpha = k`, exact on the constraint
//! manifold): `M_pp,reg = 4 G^T J G + 4 k p p^T = 4 N^T diag(J, k) N`, `N = [G; p^T]`,
//! `N N^T = |p|^2 I`, with the explicit factor
//! `F_pp^-T = N^T diag(L_J^-T, 1/sqrt k) / (2 |p|^2)` (`J = L_J L_J^T`, `k = trace J / 3`):
//! no factorization per call. Velocity term `8 Gd^T J Gd p` plus the right-hand-side shift
//! `-4 k (pd.pd) p` of the regularization (no effect on the accelerations; it makes the
//! multipliers those of the true mass matrix).
//! Gravity is a force element in spatial scenes (`force::spatial`), so `gravity` is unused here.

use super::InitialState;
use crate::error::{check_finite_item, positive, Error, Result};
use crate::description::spatial::{OrientationDesc, Rigid3Desc};
use crate::linalg::rot3::{cross, dot, mat_vec, p_from_matrix, rot_a, rot_e, rot_g, M3, V3};

/// The body coordinate onto which `F^-1` maps the normalization row: `F^-1 [0, 2 p]^T =
/// e_6 / sqrt k` (`finv`: `G p = 0`, `p . 2 p / (2 |p|^2) = 1`), the unit row of
/// docs/spatial-design.md, section 3.
pub const NORMALIZATION_COORD: usize = 6;

#[derive(Debug, Clone)]
pub struct Rigid3 {
    pub mass: f64,
    /// Inertia about the centre of mass, body axes (symmetrized).
    pub inertia: M3,
    /// Centre of mass in the user's body frame (markers are stored relative to it).
    pub com: V3,
    pub inv_sqrt_m: f64,
    /// `L_J^-1` (lower triangular).
    pub l_inv: M3,
    /// Regularization weight `k = trace(J) / 3` and `1/sqrt(k)`.
    pub k: f64,
    pub inv_sqrt_k: f64,
}

/// Workspace: the Euler parameters of the last `mass_and_forces` and `|p|^2`.
#[derive(Debug, Clone, Default)]
pub struct Rigid3Data {
    pub p: [f64; 4],
    pub p2: f64,
}

/// Bring Euler parameters `p` (4) back to unit length together with their rates `pd`:
/// `p <- p / |p|`, `pd <- pd / |p|`. Orientation (`R(p) / |p|^2`) and angular velocity
/// (`2 G(p) pd / |p|^2`) are invariant under `(p, pd) -> (c p, c pd)`, so this moves no
/// physical quantity; an integration step's error along that scale (a Runge-Kutta step
/// shrinks a turning `p` and `pd` alike: `|R(i y)| < 1`) is removed here instead of being read
/// as a loss of speed. The projection's normalization row alone would take `p` back to the
/// unit sphere with `pd` left as it was, which turned the step's error along the scale into a
/// loss of angular velocity: the heavy top lost energy at 0.03 rtol per step (docs/spatial.md,
/// "The heavy top at the default rtol"). Returns whether anything changed.
pub fn normalize_euler_parameters(p: &mut [f64], pd: &mut [f64]) -> bool {
    let p2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
    if !(p2 > 1e-200 && p2.is_finite()) || p2 == 1.0 {
        return false;
    }
    let s = 1.0 / p2.sqrt();
    for k in 0..4 {
        p[k] *= s;
        pd[k] *= s;
    }
    true
}

/// Eigenvalues of a symmetric 3x3 matrix, ascending (closed form).
pub fn sym_eigenvalues(a: &M3) -> [f64; 3] {
    let p1 = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    let q = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
    if p1 == 0.0 {
        let mut e = [a[0][0], a[1][1], a[2][2]];
        e.sort_by(|x, y| x.partial_cmp(y).unwrap_or(std::cmp::Ordering::Equal));
        return e;
    }
    let p2 = (a[0][0] - q).powi(2) + (a[1][1] - q).powi(2) + (a[2][2] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let mut b = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            b[i][j] = (a[i][j] - if i == j { q } else { 0.0 }) / p;
        }
    }
    let det = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) - b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0])
        + b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
    let r = (det / 2.0).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let e3 = q + 2.0 * p * phi.cos();
    let e1 = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    let e2 = 3.0 * q - e1 - e3;
    let mut e = [e1, e2, e3];
    e.sort_by(|x, y| x.partial_cmp(y).unwrap_or(std::cmp::Ordering::Equal));
    e
}

/// The checks of an inertia tensor about the centre of mass: finite, symmetric, positive
/// definite (not singular), principal moments obeying the triangle inequality. Returns it
/// symmetrized.
pub fn check_inertia(item: &str, j: &[[f64; 3]; 3]) -> Result<M3> {
    for row in j {
        check_finite_item(item, "inertia", row)?;
    }
    let big = j.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    for a in 0..3 {
        for b in 0..a {
            if (j[a][b] - j[b][a]).abs() > 1e-12 * big.max(f64::MIN_POSITIVE) {
                return Err(Error::invalid(item, format!("inertia tensor is not symmetric: [{a}][{b}] = {} but [{b}][{a}] = {}", j[a][b], j[b][a])));
            }
        }
    }
    let mut s = *j;
    for a in 0..3 {
        for b in 0..3 {
            s[a][b] = 0.5 * (j[a][b] + j[b][a]);
        }
    }
    let e = sym_eigenvalues(&s);
    if !(e[0] > 1e-14 * e[2].abs()) || !(e[0] > 0.0) {
        return Err(Error::invalid(item, format!("inertia tensor is singular or not positive definite (principal moments {:?})", e)));
    }
    if e[0] + e[1] < e[2] * (1.0 - 1e-12) {
        return Err(Error::invalid(item, format!(
            "principal moments of inertia {:?} violate the triangle inequality (I1 + I2 >= I3 holds for every real body)",
            e
        )));
    }
    Ok(s)
}

/// Lower Cholesky factor of a symmetric positive definite 3x3 matrix.
fn cholesky3(a: &M3) -> Option<M3> {
    let mut l = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let mut s = a[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            if i == j {
                if !(s > 0.0) {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    Some(l)
}

/// Inverse of a lower triangular 3x3 matrix.
fn lower_inverse(l: &M3) -> M3 {
    let mut x = [[0.0; 3]; 3];
    for c in 0..3 {
        for i in 0..3 {
            let mut s = if i == c { 1.0 } else { 0.0 };
            for k in 0..i {
                s -= l[i][k] * x[k][c];
            }
            x[i][c] = s / l[i][i];
        }
    }
    x
}

/// Unit Euler parameters from a description's orientation (identity when absent): a
/// quaternion is normalized (zero or non-finite: an error), a matrix must be a rotation.
pub fn orientation_p(item: &str, o: Option<&OrientationDesc>) -> Result<[f64; 4]> {
    match o {
        None => Ok([1.0, 0.0, 0.0, 0.0]),
        Some(OrientationDesc::Quaternion(p)) => {
            check_finite_item(item, "orientation", p)?;
            let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]).sqrt();
            if !(n > 1e-12) {
                return Err(Error::invalid(item, "orientation quaternion must be nonzero"));
            }
            Ok(p.map(|x| x / n))
        }
        Some(OrientationDesc::Matrix(r)) => {
            for row in r {
                check_finite_item(item, "orientation", row)?;
            }
            let mut err = 0.0f64;
            for a in 0..3 {
                for b in 0..3 {
                    let s: f64 = (0..3).map(|k| r[k][a] * r[k][b]).sum();
                    err = err.max((s - if a == b { 1.0 } else { 0.0 }).abs());
                }
            }
            let det = dot(&r[0], &cross(&r[1], &r[2]));
            if err > 1e-9 || det < 0.0 {
                return Err(Error::invalid(item, "orientation matrix must be a rotation (orthonormal, determinant +1)"));
            }
            Ok(p_from_matrix(r))
        }
    }
}

impl Rigid3 {
    pub fn from_desc(d: &Rigid3Desc, item: &str) -> Result<Rigid3> {
        let mass = positive(item, "mass", d.mass)?;
        let inertia = check_inertia(item, &d.inertia)?;
        check_finite_item(item, "com", &d.com)?;
        let l = cholesky3(&inertia).ok_or_else(|| Error::invalid(item, "inertia tensor is singular or not positive definite"))?;
        let k = (inertia[0][0] + inertia[1][1] + inertia[2][2]) / 3.0;
        Ok(Rigid3 { mass, inertia, com: d.com, inv_sqrt_m: 1.0 / mass.sqrt(), l_inv: lower_inverse(&l), k, inv_sqrt_k: 1.0 / k.sqrt() })
    }

    /// Add `extra` (body axes, symmetric, positive semi-definite: a motor's rotor `J_r z z^T`,
    /// `force/motor3.rs`) to the inertia tensor and refresh its factor and regularization
    /// weight. The sum need not obey the triangle inequality (a rotor's inertia across its axis
    /// is left to the body's tensor); it stays positive definite.
    pub fn add_inertia(&mut self, item: &str, extra: &M3) -> Result<()> {
        let mut j = self.inertia;
        for a in 0..3 {
            for b in 0..3 {
                j[a][b] += extra[a][b];
            }
        }
        let l = cholesky3(&j).ok_or_else(|| Error::invalid(item, "inertia tensor with the rotor's is not positive definite"))?;
        let k = (j[0][0] + j[1][1] + j[2][2]) / 3.0;
        (self.inertia, self.l_inv, self.k, self.inv_sqrt_k) = (j, lower_inverse(&l), k, 1.0 / k.sqrt());
        Ok(())
    }

    pub fn initial_state(&self, d: &Rigid3Desc, item: &str) -> Result<InitialState> {
        for (what, v) in [("position", &d.position), ("velocity", &d.velocity), ("angular_velocity", &d.angular_velocity)] {
            check_finite_item(item, what, v)?;
        }
        let p = orientation_p(item, d.orientation.as_ref())?;
        let c = mat_vec(&rot_a(&p), &self.com);
        let w = d.angular_velocity;
        let wc = cross(&w, &c);
        let e = rot_e(&p);
        let mut pd = [0.0; 4];
        for l in 0..4 {
            pd[l] = 0.5 * (e[0][l] * w[0] + e[1][l] * w[1] + e[2][l] * w[2]);
        }
        Ok(InitialState {
            q: vec![d.position[0] + c[0], d.position[1] + c[1], d.position[2] + c[2], p[0], p[1], p[2], p[3]],
            qd: vec![d.velocity[0] + wc[0], d.velocity[1] + wc[1], d.velocity[2] + wc[2], pd[0], pd[1], pd[2], pd[3]],
            names: ["x", "y", "z", "e0", "e1", "e2", "e3"].map(String::from).to_vec(),
        })
    }

    pub fn new_data(&self) -> Rigid3Data {
        Rigid3Data::default()
    }

    /// `Q_p = 8 Gd^T J Gd p - 4 k (pd.pd) p` (Lagrange's velocity term and the regularization's
    /// shift); no force on `r`.
    #[inline]
    pub fn mass_and_forces(&self, bd: &mut Rigid3Data, q: &[f64], qd: &[f64], _gravity: Option<[f64; 2]>, f: &mut [f64]) {
        let p = [q[3], q[4], q[5], q[6]];
        bd.p = p;
        bd.p2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
        let gd = rot_g(&qd[3..7]);
        let mut v = [0.0; 3];
        for i in 0..3 {
            v[i] = gd[i][0] * p[0] + gd[i][1] * p[1] + gd[i][2] * p[2] + gd[i][3] * p[3];
        }
        let jv = mat_vec(&self.inertia, &v);
        f[0] = 0.0;
        f[1] = 0.0;
        f[2] = 0.0;
        // the shift -4 k (pd.pd) p of Q_reg: it leaves the accelerations alone (a force along p
        // is the normalization multiplier's) but makes the multipliers those of the true M
        // (A^T lambda = Q - M qdd), so that an over-constrained mechanism reports the
        // minimum-norm reactions of the physical system
        let pdd = qd[3] * qd[3] + qd[4] * qd[4] + qd[5] * qd[5] + qd[6] * qd[6];
        for l in 0..4 {
            f[3 + l] = 8.0 * (gd[0][l] * jv[0] + gd[1][l] * jv[1] + gd[2][l] * jv[2]) - 4.0 * self.k * pdd * p[l];
        }
    }

    /// Nothing to factor (`F` is explicit): only `|p| > 0` is needed.
    #[inline]
    pub fn factor(&self, bd: &mut Rigid3Data) -> bool {
        bd.p2 > 1e-200 && bd.p2.is_finite()
    }

    /// `v <- F^-1 v`: `v_r / sqrt m`; `diag(L_J^-1, 1/sqrt k) N v_p / (2 |p|^2)`.
    #[inline]
    pub fn finv(&self, bd: &Rigid3Data, v: &mut [f64]) {
        for x in &mut v[0..3] {
            *x *= self.inv_sqrt_m;
        }
        let p = &bd.p;
        let g = rot_g(p);
        let vp = [v[3], v[4], v[5], v[6]];
        let mut y = [0.0; 3];
        for i in 0..3 {
            y[i] = g[i][0] * vp[0] + g[i][1] * vp[1] + g[i][2] * vp[2] + g[i][3] * vp[3];
        }
        let y4 = p[0] * vp[0] + p[1] * vp[1] + p[2] * vp[2] + p[3] * vp[3];
        let s = 0.5 / bd.p2;
        let z = mat_vec(&self.l_inv, &y);
        v[3] = s * z[0];
        v[4] = s * z[1];
        v[5] = s * z[2];
        v[6] = s * y4 * self.inv_sqrt_k;
    }

    /// `F^-1` of the body as `(1 / sqrt m, T)`: `(F^-1 v)_r = v_r / sqrt m`, `(F^-1 v)_p = T v_p`
    /// (`T = [L_J^-1 G; p^T / sqrt k] / (2 |p|^2)`, the rows of `finv`), for a caller that maps
    /// many vectors with one factor (`uk::gram`: each constraint row's segment of `B^T`).
    #[inline]
    pub fn finv_matrix(&self, bd: &Rigid3Data) -> (f64, [[f64; 4]; 4]) {
        let p = &bd.p;
        let g = rot_g(p);
        let s = 0.5 / bd.p2;
        let mut t = [[0.0; 4]; 4];
        for i in 0..3 {
            for l in 0..4 {
                t[i][l] = s * (self.l_inv[i][0] * g[0][l] + self.l_inv[i][1] * g[1][l] + self.l_inv[i][2] * g[2][l]);
            }
        }
        for l in 0..4 {
            t[3][l] = s * self.inv_sqrt_k * p[l];
        }
        (self.inv_sqrt_m, t)
    }

    /// `v <- F^-T v`: `v_r / sqrt m`; `N^T diag(L_J^-T, 1/sqrt k) v_p / (2 |p|^2)`.
    #[inline]
    pub fn finvt(&self, bd: &Rigid3Data, v: &mut [f64]) {
        for x in &mut v[0..3] {
            *x *= self.inv_sqrt_m;
        }
        let p = &bd.p;
        let g = rot_g(p);
        // L^-T u: transpose of the lower inverse
        let u = [v[3], v[4], v[5]];
        let mut z = [0.0; 3];
        for j in 0..3 {
            z[j] = self.l_inv[0][j] * u[0] + self.l_inv[1][j] * u[1] + self.l_inv[2][j] * u[2];
        }
        let z4 = v[6] * self.inv_sqrt_k;
        let s = 0.5 / bd.p2;
        for l in 0..4 {
            v[3 + l] = s * (g[0][l] * z[0] + g[1][l] * z[1] + g[2][l] * z[2] + p[l] * z4);
        }
    }

    /// The regularized rotational block `4 G^T J G + 4 k p p^T` at the stored `p`.
    pub fn rotational_block(&self, bd: &Rigid3Data) -> [[f64; 4]; 4] {
        let g = rot_g(&bd.p);
        let mut out = [[0.0; 4]; 4];
        for a in 0..4 {
            let ga = [g[0][a], g[1][a], g[2][a]];
            let jga = mat_vec(&self.inertia, &ga);
            for b in 0..4 {
                let gb = [g[0][b], g[1][b], g[2][b]];
                out[a][b] = 4.0 * dot(&gb, &jga) + 4.0 * self.k * bd.p[a] * bd.p[b];
            }
        }
        out
    }

    /// The factored block `M_reg` (what `F F^T` is), for the dense consumers.
    pub fn dense_block(&self, bd: &Rigid3Data, put: &mut impl FnMut(usize, usize, f64)) {
        for i in 0..3 {
            put(i, i, self.mass);
        }
        let m = self.rotational_block(bd);
        for a in 0..4 {
            for b in 0..4 {
                put(3 + a, 3 + b, m[a][b]);
            }
        }
    }

    /// `out += M_reg x`.
    pub fn mass_times(&self, bd: &Rigid3Data, x: &[f64], out: &mut [f64]) {
        for i in 0..3 {
            out[i] += self.mass * x[i];
        }
        let m = self.rotational_block(bd);
        for a in 0..4 {
            out[3 + a] += m[a][0] * x[3] + m[a][1] * x[4] + m[a][2] * x[5] + m[a][3] * x[6];
        }
    }

    /// Angular velocity in body axes of the rotation `p / |p|` represents: `2 G pd / |p|^2`.
    pub fn omega_body(p: &[f64], pd: &[f64]) -> V3 {
        let g = rot_g(p);
        let p2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
        let mut w = [0.0; 3];
        for i in 0..3 {
            w[i] = 2.0 * (g[i][0] * pd[0] + g[i][1] * pd[1] + g[i][2] * pd[2] + g[i][3] * pd[3]) / p2;
        }
        w
    }

    /// `1/2 m rd.rd + 1/2 w'.J w'` with `w' = 2 G pd / |p|^2`.
    pub fn kinetic_energy(&self, _bd: &Rigid3Data, qd: &[f64]) -> f64 {
        // |p|^2 from the stored state (mass_and_forces ran at the same q)
        let w = Self::omega_body(&_bd.p, &qd[3..7]);
        let rd = [qd[0], qd[1], qd[2]];
        0.5 * self.mass * dot(&rd, &rd) + 0.5 * dot(&w, &mat_vec(&self.inertia, &w))
    }

    /// `m r` (its planar part: the 2D gravity potential is never asked of a spatial body).
    pub fn mass_moment(&self, q: &[f64]) -> [f64; 2] {
        [self.mass * q[0], self.mass * q[1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body() -> (Rigid3, Rigid3Data) {
        let d = Rigid3Desc {
            name: "b".into(),
            mass: 2.0,
            inertia: [[0.3, 0.01, -0.02], [0.01, 0.25, 0.03], [-0.02, 0.03, 0.2]],
            com: [0.0; 3],
            position: [0.0; 3],
            orientation: None,
            velocity: [0.0; 3],
            angular_velocity: [0.0; 3],
        };
        let b = Rigid3::from_desc(&d, "body 'b'").unwrap();
        let mut bd = b.new_data();
        let q = [0.1, 0.2, 0.3, 0.8, -0.3, 0.4, 0.35]; // |p| != 1 on purpose
        let mut f = [0.0; 7];
        b.mass_and_forces(&mut bd, &q, &[0.0; 7], None, &mut f);
        (b, bd)
    }

    #[test]
    fn explicit_factor_is_the_inverse_of_the_regularized_block() {
        let (b, bd) = body();
        assert!(b.factor(&mut bd.clone()));
        // F^-T F^-1 M_reg x = x for unit vectors x
        for c in 0..7 {
            let mut x = [0.0; 7];
            x[c] = 1.0;
            let mut y = [0.0; 7];
            b.mass_times(&bd, &x, &mut y);
            b.finv(&bd, &mut y);
            b.finvt(&bd, &mut y);
            for i in 0..7 {
                assert!((y[i] - x[i]).abs() < 1e-12, "column {c}, entry {i}: {}", y[i]);
            }
        }
    }

    #[test]
    fn velocity_term_follows_from_lagrange() {
        // Q_v = -Md qd + dT/dq with T = 2 pd^T G^T J G pd (the true, singular M)
        let (b, _) = body();
        let q = [0.0, 0.0, 0.0, 0.8, -0.3, 0.4, 0.35];
        let qd = [0.0, 0.0, 0.0, 0.2, 0.5, -0.4, 0.1];
        let t = |p: &[f64], pd: &[f64]| {
            let g = rot_g(p);
            let mut w = [0.0; 3];
            for i in 0..3 {
                w[i] = (0..4).map(|l| g[i][l] * pd[l]).sum();
            }
            2.0 * dot(&w, &mat_vec(&b.inertia, &w))
        };
        let h = 1e-4; // T is a polynomial of degree 4: central differences err by O(h^2)
        let mut f = [0.0; 7];
        b.mass_and_forces(&mut b.new_data(), &q, &qd, None, &mut f);
        for l in 0..4 {
            // dT/dp_l
            let (mut pp, mut pm) = ([q[3], q[4], q[5], q[6]], [q[3], q[4], q[5], q[6]]);
            pp[l] += h;
            pm[l] -= h;
            let dtdp = (t(&pp, &qd[3..7]) - t(&pm, &qd[3..7])) / (2.0 * h);
            // (Md qd)_l = d/dt (dT/dpd_l) at constant pd = sum_k d(dT/dpd_l)/dp_k pd_k
            let dtdpd = |p: &[f64]| {
                let (mut a, mut c) = ([qd[3], qd[4], qd[5], qd[6]], [qd[3], qd[4], qd[5], qd[6]]);
                a[l] += h;
                c[l] -= h;
                (t(p, &a) - t(p, &c)) / (2.0 * h)
            };
            let p0 = [q[3], q[4], q[5], q[6]];
            let mut pf = p0;
            let mut pb = p0;
            for k in 0..4 {
                pf[k] += h * qd[3 + k];
                pb[k] -= h * qd[3 + k];
            }
            let mdqd = (dtdpd(&pf) - dtdpd(&pb)) / (2.0 * h);
            // plus the regularization's shift -4 k (pd.pd) p
            let pdd: f64 = qd[3..7].iter().map(|x| x * x).sum();
            let expect = -mdqd + dtdp - 4.0 * b.k * pdd * q[3 + l];
            assert!((f[3 + l] - expect).abs() < 1e-6 * (1.0 + expect.abs()), "l = {l}: {} vs {expect}", f[3 + l]);
        }
    }

    #[test]
    fn inertia_checks() {
        let ok = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.5]];
        assert!(check_inertia("b", &ok).is_ok());
        let tri = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.5]];
        assert!(format!("{}", check_inertia("b", &tri).unwrap_err()).contains("triangle"));
        let sing = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]];
        assert!(format!("{}", check_inertia("b", &sing).unwrap_err()).contains("singular"));
        let asym = [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(format!("{}", check_inertia("b", &asym).unwrap_err()).contains("symmetric"));
        let nan = [[1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0], [0.0, 0.0, 1.0]];
        assert!(check_inertia("b", &nan).is_err());
        let e = sym_eigenvalues(&[[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 5.0]]);
        assert!((e[0] - 1.0).abs() < 1e-14 && (e[1] - 3.0).abs() < 1e-14 && (e[2] - 5.0).abs() < 1e-14);
    }
}

impl Rigid3 {
    /// Inspection entries (`inspect.rs`).
    pub fn info(&self, m: &mut serde_json::Map<String, serde_json::Value>) {
        m.insert("inertia".into(), self.inertia.iter().map(|row| row.to_vec()).collect::<Vec<_>>().into());
        m.insert("com".into(), self.com.to_vec().into());
    }
}
