//! Stress stiffening of the spatial modal body (docs/spatial-flexible.md, "Stress stiffening"):
//! the modal geometric stiffness `K_c` (n x n) of unit inertia load cases, precomputed from the
//! FE solid (`ukflex.fe3.from_mesh(..., stress_stiffening=True)`), scaled by the load the frame's
//! motion puts on the body: `Q_f -= K_g q_f`, `K_g = sum_c lambda_c K_c`.
//!
//! Cases (`LOAD_CASES`), each a body force per unit mass in frame axes: the six centrifugal
//! `w_k w_l` (`-w x (w x x) = sum_{k<=l} w_k w_l (tr E_kl I - E_kl) x`), the three angular
//! accelerations (`-e_k x x`) and the three specific forces (`e_k`). Applied, from the state:
//! the centrifugal cases with `w'` (body axes), the specific forces with the velocity part of the
//! frame origin's acceleration, `-(w' x v')` (`v' = R^T rd`; exact for a frame carried by a hub
//! at a steady speed: the hub radius term), and gravity (`R^T g`, with its potential, through
//! `add_gravity`). Not applied: the angular-acceleration cases and the rate `vd'` of the frame
//! velocity (they are linear in the accelerations and belong to the mass matrix; zero in a steady
//! spin; the docs give the size of what they leave out).

use crate::error::{Error, Result};
use crate::linalg::rot3::{cross, V3};

/// The unit load cases in the order of the description's `geometric_stiffness`.
pub const LOAD_CASES: [&str; 12] = ["ww_xx", "ww_yy", "ww_zz", "ww_xy", "ww_yz", "ww_zx", "alpha_x", "alpha_y", "alpha_z", "f_x", "f_y", "f_z"];
/// The first specific-force case (`f_x`).
const FORCE_CASE: usize = 9;

#[derive(Debug, Clone)]
pub struct GeometricStiffness {
    n: usize,
    /// `K_c` at `c n^2 + i n + j`.
    k: Vec<f64>,
}

impl GeometricStiffness {
    pub fn from_desc(item: &str, rows: &[Vec<Vec<f64>>], n: usize) -> Result<GeometricStiffness> {
        if rows.len() != LOAD_CASES.len() {
            return Err(Error::invalid(
                item,
                format!("geometric_stiffness must hold one n x n matrix per load case ({}: {}), got {}; build it with ukflex.fe3.from_mesh(..., stress_stiffening=True)", LOAD_CASES.len(), LOAD_CASES.join(", "), rows.len()),
            ));
        }
        let mut k = Vec::with_capacity(rows.len() * n * n);
        for (c, m) in rows.iter().enumerate() {
            let what = format!("geometric_stiffness[{}] ({})", c, LOAD_CASES[c]);
            let (flat, big) = super::flexible::square(item, &what, m, n)?;
            super::flexible::check_symmetry(item, &what, &flat, n, big, 1.0)?;
            k.extend_from_slice(&flat);
        }
        Ok(GeometricStiffness { n, k })
    }

    /// The load factors of the cases applied from the state (zero for the others).
    #[inline]
    fn factors(w: &V3, v: &V3) -> [f64; 12] {
        let a = cross(w, v);
        [w[0] * w[0], w[1] * w[1], w[2] * w[2], w[0] * w[1], w[1] * w[2], w[2] * w[0], 0.0, 0.0, 0.0, -a[0], -a[1], -a[2]]
    }

    /// `f_f -= K_g(w', v') q_f` (`w'` the body-axes angular velocity, `v' = R^T rd`).
    #[inline]
    pub fn add_forces(&self, w: &V3, v: &V3, qf: &[f64], ff: &mut [f64]) {
        self.apply(&Self::factors(w, v), qf, ff);
    }

    /// `out_f -= sum_c lambda_c K_c q_f`.
    #[inline]
    fn apply(&self, lambda: &[f64; 12], qf: &[f64], ff: &mut [f64]) {
        let n = self.n;
        for (c, l) in lambda.iter().enumerate() {
            if *l == 0.0 {
                continue;
            }
            let kc = &self.k[c * n * n..(c + 1) * n * n];
            for i in 0..n {
                let row = &kc[i * n..(i + 1) * n];
                ff[i] -= l * row.iter().zip(qf).map(|(a, b)| a * b).sum::<f64>();
            }
        }
    }

    /// `-dQ_f/dq_f = K_g(w', v')` into `k(i, j, v)` (modal indices).
    pub fn tangent(&self, w: &V3, v: &V3, k: &mut impl FnMut(usize, usize, f64)) {
        let n = self.n;
        let lambda = Self::factors(w, v);
        for i in 0..n {
            for j in 0..n {
                let s: f64 = lambda.iter().enumerate().map(|(c, l)| l * self.k[c * n * n + i * n + j]).sum();
                k(i, j, s);
            }
        }
    }

    /// `s_k = q_f^T K_{f_k} q_f` (the specific-force cases).
    fn force_quadratics(&self, qf: &[f64]) -> V3 {
        let n = self.n;
        let mut s = [0.0; 3];
        for (k, sk) in s.iter_mut().enumerate() {
            let kc = &self.k[(FORCE_CASE + k) * n * n..(FORCE_CASE + k + 1) * n * n];
            for i in 0..n {
                *sk += qf[i] * kc[i * n..(i + 1) * n].iter().zip(qf).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        s
    }

    /// Gravity's prestress, the gradient of `V = 1/2 gb . s(q_f)` (`gb = R^T g`): `Q_f -=
    /// sum_k gb_k K_{f_k} q_f` and the body-axes torque `Q_w += (-s / 2) x gb` (the same
    /// rotation dependence as `-g . R S_t`, whose torque is `S_t x gb`). Allocation free.
    pub fn add_gravity(&self, gb: &V3, qf: &[f64], qw: &mut V3, ff: &mut [f64]) {
        let mut lambda = [0.0; 12];
        lambda[FORCE_CASE..FORCE_CASE + 3].copy_from_slice(gb);
        self.apply(&lambda, qf, ff);
        let s = self.force_quadratics(qf);
        let t = cross(&[-0.5 * s[0], -0.5 * s[1], -0.5 * s[2]], gb);
        for c in 0..3 {
            qw[c] += t[c];
        }
    }

    /// `1/2 gb . s(q_f)`.
    pub fn gravity_potential(&self, gb: &V3, qf: &[f64]) -> f64 {
        let s = self.force_quadratics(qf);
        0.5 * (gb[0] * s[0] + gb[1] * s[1] + gb[2] * s[2])
    }
}
