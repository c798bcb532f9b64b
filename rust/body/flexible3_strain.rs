//! The quadratic (Green-Lagrange) strain of the spatial modal body (docs/spatial-flexible.md,
//! "Quadratic strain"): a St-Venant-Kirchhoff solid's strain energy with `u = Phi q_f`,
//! `E = eps(u) + E_nl(u)`, `E_nl = 1/2 sum_ij q_i q_j B_ij`, `B_ij = sym(grad phi_i^T grad phi_j)`:
//! `V = 1/2 q^T K q + V3 + V4` with
//!
//! * `V3 = int sigma(u) : E_nl(u) dV = 1/2 sum_k q_k q^T G_k q = 1/2 T_kij q_k q_i q_j`,
//!   `G_k = G(sigma(phi_k))` the modal geometric stiffness of mode `k`'s linear stress.
//!   `T_kij` is symmetric in `(i, j)` only, so the force and the tangent keep both index roles:
//!   `dV3/dq_m = 1/2 q^T G_m q + (Gbar q)_m`, `Gbar = sum_k q_k G_k`;
//!   `d2V3/dq_m dq_l = (G_m q)_l + (G_l q)_m + Gbar_ml`;
//! * `V4 = 1/2 int E_nl : C : E_nl dV = 1/8 H_ijkl q_i q_j q_k q_l`, `H_ijkl = int B_ij : C :
//!   B_kl` (symmetric in `(i, j)`, in `(k, l)` and under `(ij) <-> (kl)`): with `S_ij = H_ijkl
//!   q_k q_l` and `P_ml = H_mjlk q_j q_k`, `dV4/dq_m = 1/2 (S q)_m`, `d2V4/dq_m dq_l = 1/2 S_ml
//!   + P_ml`. Without it the cubic energy alone softens a bending body whose ends may slide
//!   (`-EA/8 int w'^4` for a beam: docs).
//!
//! Data from `ukflex.fe3.from_mesh(..., quadratic_strain=True)`. Allocation free.

use crate::error::{Error, Result};

#[derive(Debug, Clone)]
pub struct QuadraticStrain {
    n: usize,
    /// `G_k` at `k n^2 + i n + j`.
    g: Vec<f64>,
    /// `H_ijkl` at `(i n + j) n^2 + k n + l`.
    h: Vec<f64>,
}

impl QuadraticStrain {
    pub fn from_desc(item: &str, rows: &[Vec<Vec<f64>>], quartic: Option<&Vec<Vec<f64>>>, n: usize) -> Result<QuadraticStrain> {
        if rows.len() != n {
            return Err(Error::invalid(
                item,
                format!("quadratic_strain must hold one n x n matrix per mode (n = {n}), got {}; build it with ukflex.fe3.from_mesh(..., quadratic_strain=True)", rows.len()),
            ));
        }
        let mut g = Vec::with_capacity(n * n * n);
        for (k, m) in rows.iter().enumerate() {
            let what = format!("quadratic_strain[{k}]");
            let (flat, big) = super::flexible::square(item, &what, m, n)?;
            super::flexible::check_symmetry(item, &what, &flat, n, big, 1.0)?;
            g.extend_from_slice(&flat);
        }
        let quartic = quartic.ok_or_else(|| Error::invalid(item, "quadratic_strain needs quadratic_strain_quartic (n^2 x n^2, H_ijkl = int B_ij : C : B_kl); build both with ukflex.fe3.from_mesh(..., quadratic_strain=True)"))?;
        let (h, big) = super::flexible::square(item, "quadratic_strain_quartic", quartic, n * n)?;
        super::flexible::check_symmetry(item, "quadratic_strain_quartic", &h, n * n, big, 1.0)?;
        Ok(QuadraticStrain { n, g, h })
    }

    /// `S_ij = H_ijkl q_k q_l` (`which = 0`) or `P_ij = H_ikjl q_k q_l` (`which = 1`).
    #[inline]
    fn quartic_matrix(&self, which: u8, i: usize, j: usize, qf: &[f64]) -> f64 {
        let n = self.n;
        let mut s = 0.0;
        for k in 0..n {
            let row = if which == 0 { (i * n + j) * n * n + k * n } else { (i * n + k) * n * n + j * n };
            s += qf[k] * self.h[row..row + n].iter().zip(qf).map(|(a, b)| a * b).sum::<f64>();
        }
        s
    }

    #[inline]
    fn gk(&self, k: usize) -> &[f64] {
        &self.g[k * self.n * self.n..(k + 1) * self.n * self.n]
    }

    /// `(G_k q)_i`.
    #[inline]
    fn gq(&self, k: usize, i: usize, qf: &[f64]) -> f64 {
        let n = self.n;
        self.gk(k)[i * n..(i + 1) * n].iter().zip(qf).map(|(a, b)| a * b).sum()
    }

    /// `q^T G_k q`.
    #[inline]
    fn qgq(&self, k: usize, qf: &[f64]) -> f64 {
        (0..self.n).map(|i| qf[i] * self.gq(k, i, qf)).sum()
    }

    /// `V3 + V4 = 1/2 sum_k q_k q^T G_k q + 1/8 q^T S q`.
    pub fn energy(&self, qf: &[f64]) -> f64 {
        let n = self.n;
        let v3: f64 = (0..n).map(|k| qf[k] * self.qgq(k, qf)).sum();
        let v4: f64 = (0..n).map(|i| qf[i] * (0..n).map(|j| self.quartic_matrix(0, i, j, qf) * qf[j]).sum::<f64>()).sum();
        0.5 * v3 + 0.125 * v4
    }

    /// `f_f -= d(V3 + V4)/dq_f`.
    #[inline]
    pub fn add_forces(&self, qf: &[f64], ff: &mut [f64]) {
        let n = self.n;
        for m in 0..n {
            let gbar_q: f64 = (0..n).map(|k| qf[k] * self.gq(k, m, qf)).sum();
            let sq: f64 = (0..n).map(|j| self.quartic_matrix(0, m, j, qf) * qf[j]).sum();
            ff[m] -= 0.5 * self.qgq(m, qf) + gbar_q + 0.5 * sq;
        }
    }

    /// `d2(V3 + V4)/dq_f^2` into `k(i, j, v)` (modal indices).
    pub fn tangent(&self, qf: &[f64], k: &mut impl FnMut(usize, usize, f64)) {
        let n = self.n;
        for m in 0..n {
            for l in 0..n {
                let gbar: f64 = (0..n).map(|c| qf[c] * self.gk(c)[m * n + l]).sum();
                let v4 = 0.5 * self.quartic_matrix(0, m, l, qf) + self.quartic_matrix(1, m, l, qf);
                k(m, l, self.gq(m, l, qf) + self.gq(l, m, qf) + gbar + v4);
            }
        }
    }
}
