//! Thin SVD of a small tall matrix `G` (n x m, m <= n) for the UK pseudoinverse:
//! Householder QR `G = Q R` (R is m x m), then one-sided (Hestenes) Jacobi on `R`:
//! `R V = W`, columns of `W` mutually orthogonal, `sigma_j = |w_j|`, `U_r = W S^-1`, so
//! `G = (Q U_r) S V^T`. `Q U_r` is never formed: the UK kernel needs only `U c` for one vector
//! `c`, which is `Q [U_r c; 0]` (m reflector applications, O(n m)).
//!
//! Why this and not a bidiagonal SVD: for the m x m core (m = 6 for the paper's slider-crank,
//! whatever the number of beam elements) the Jacobi sweeps are short, branch-light loops over
//! contiguous columns, and one-sided Jacobi is at least as accurate as the bidiagonal QR
//! (relative accuracy of the singular values for column-scaled well-conditioned matrices,
//! Demmel & Veselic 1992). The QR step first makes the cost O(n m^2) + O(m^3 sweeps), linear in
//! the number of coordinates n. Everything is allocation free after `QrJacobi::new`.
//!
//! Unit columns (`QrJacobi::with_unit_columns`): when some columns of `G` are known multiples of
//! unit vectors (the spatial rigid body's Euler-parameter normalization rows: `F^-1 A_n^T =
//! e_c / sqrt k`, docs/spatial-design.md, section 3), the workspace orders those columns first
//! and their rows first. Their Householder reflectors are then the identity (`tau = 0`) and every
//! other reflector works on the remaining rows only: the QR costs what it costs without them
//! (slider-crank: 18 x 17 instead of 21 x 20, 38 % fewer flops), and `R` is still the exact
//! triangular factor of `G` with permuted rows and columns (same singular values, same
//! `|R|_F` and `|R^-1|_F`). The permutations are internal: inputs and outputs keep `G`'s order.
//!
//! Profile: each reflector ends at its column's last nonzero row (`end`), and a trailing column
//! with no entry on the reflector's rows is left alone. The spatial `B^T` touches a few bodies
//! per column, and the fill of the reflectors stays within the bodies already touched: on the
//! flyball governor (A05, 30 x 26 after its unit columns) the reflectors' updates are ~1/5 of the
//! dense sweep. Only the rows and columns the reflector cannot change are skipped, so `R` and
//! the reflectors are those of the dense sweep up to the order of the sums.
//!
//! The eigen-decomposition of `B B^T = R^T R` would be cheaper still but squares the condition
//! number: singular values below `sqrt(eps) sigma_max` come out as noise, which would break the
//! pseudoinverse's rank decision at its default tolerance `max(m, n) eps sigma_max`. Rejected.

mod cod;
mod deflate;
pub use cod::{CodRank, RankRule};

/// Column-major workspace for the QR + Jacobi SVD of an n x m matrix with m <= n.
#[derive(Debug, Clone)]
pub struct QrJacobi {
    pub n: usize,
    pub m: usize,
    /// Householder vectors below the diagonal (unit leading entry implicit), R on and above.
    qr: Vec<f64>,
    tau: Vec<f64>,
    /// `end[k]`: the reflector `k`'s rows are `k..end[k]` (column `k`'s last nonzero, module
    /// docs, "Profile"); its stored entries from `end[k]` on are zero.
    end: Vec<usize>,
    /// `W = R V` (m x m column-major), orthogonal columns at convergence.
    w: Vec<f64>,
    /// Right singular vectors, unsorted (m x m column-major).
    v: Vec<f64>,
    /// Column norms of `W` (unsorted singular values).
    norms: Vec<f64>,
    /// `order[j]` = unsorted index of the j-th largest singular value.
    order: Vec<usize>,
    /// Scratch: m and n long.
    tm: Vec<f64>,
    tn: Vec<f64>,
    /// Internal row `i` is row `rows[i]` of `G`, internal column `j` is column `cols[j]`; the
    /// first `n_unit` internal columns are the unit columns, each nonzero only in its own
    /// internal row (`j`). Identity permutations when `!permuted`.
    rows: Vec<usize>,
    cols: Vec<usize>,
    n_unit: usize,
    permuted: bool,
    /// Scratch for permuted m-vectors.
    tp: Vec<f64>,
    /// Jacobi sweeps used by the last factorization (including the final clean sweep).
    pub sweeps: usize,
    /// The complete orthogonal decomposition of `R` (rank-deficient `G` without an SVD: `cod`).
    cod: cod::Cod,
    /// The SVD's truncation at rank `m - 1` without the SVD (`deflate`; made at its first use).
    deflate: deflate::Deflate,
}

/// Maximum number of Jacobi sweeps before giving up (quadratic convergence: ~5 usually).
pub const MAX_SWEEPS: usize = 60;

impl QrJacobi {
    pub fn new(n: usize, m: usize) -> QrJacobi {
        assert!(m <= n, "QrJacobi needs a tall matrix (m <= n)");
        QrJacobi {
            n,
            m,
            qr: vec![0.0; n * m],
            tau: vec![0.0; m],
            end: vec![n; m],
            w: vec![0.0; m * m],
            v: vec![0.0; m * m],
            norms: vec![0.0; m],
            order: (0..m).collect(),
            tm: vec![0.0; m],
            tn: vec![0.0; n],
            rows: (0..n).collect(),
            cols: (0..m).collect(),
            n_unit: 0,
            permuted: false,
            tp: vec![0.0; m],
            sweeps: 0,
            cod: cod::Cod::new(m),
            deflate: deflate::Deflate::default(),
        }
    }

    /// A workspace for `G` whose columns `units[k].0` are multiples of the unit vector of row
    /// `units[k].1` (distinct columns and rows, in range): their entries off that row are taken
    /// as zero and the QR skips them (module docs).
    pub fn with_unit_columns(n: usize, m: usize, units: &[(usize, usize)]) -> QrJacobi {
        let mut s = QrJacobi::new(n, m);
        if units.is_empty() {
            return s;
        }
        let (mut col_unit, mut row_unit) = (vec![false; m], vec![false; n]);
        for &(c, r) in units {
            assert!(c < m && r < n && !col_unit[c] && !row_unit[r], "unit columns: distinct columns and rows in range");
            col_unit[c] = true;
            row_unit[r] = true;
        }
        s.cols = units.iter().map(|u| u.0).chain((0..m).filter(|&c| !col_unit[c])).collect();
        s.rows = units.iter().map(|u| u.1).chain((0..n).filter(|&r| !row_unit[r])).collect();
        s.n_unit = units.len();
        s.permuted = true;
        s
    }
    /// Factor `G` (column `j` given by `col(j)`, at least n long): QR, then Jacobi SVD of R.
    /// Returns `false` if Jacobi did not converge within `MAX_SWEEPS` (or the input is not
    /// finite).
    pub fn factor_cols<'a>(&mut self, col: impl Fn(usize) -> &'a [f64]) -> bool {
        self.qr_cols(col);
        self.svd_of_r()
    }

    /// Householder QR of `G` only (R and the reflectors stay in the workspace).
    pub fn qr_cols<'a>(&mut self, col: impl Fn(usize) -> &'a [f64]) {
        let n = self.n;
        if !self.permuted {
            for j in 0..self.m {
                self.qr[j * n..(j + 1) * n].copy_from_slice(&col(j)[..n]);
            }
        } else {
            for j in 0..self.m {
                let src = &col(self.cols[j])[..n];
                let dst = &mut self.qr[j * n..(j + 1) * n];
                if j < self.n_unit {
                    dst.fill(0.0);
                    dst[j] = src[self.rows[j]];
                } else {
                    for (d, &r) in dst.iter_mut().zip(&self.rows) {
                        *d = src[r];
                    }
                }
            }
        }
        self.householder_qr();
    }

    /// Certified full rank test after `qr_cols`: computes `R^-1` (kept for `full_rank_solve`)
    /// and returns `(|R|_F, 1 / |R^-1|_F)`, an upper bound of `sigma_max` and a lower bound of
    /// `sigma_min` (both of `G`). The lower bound is 0 (and `R^-1` unusable) when R has a zero
    /// or non-finite pivot.
    pub fn full_rank_bounds(&mut self) -> (f64, f64) {
        let (n, m) = (self.n, self.m);
        let mut rf = 0.0;
        for j in 0..m {
            for i in 0..=j {
                let x = self.qr[j * n + i];
                rf += x * x;
            }
        }
        // R^-1 column by column (upper triangular), stored in `w` (column-major); the
        // reciprocals of the diagonal go to `tm` (m divisions instead of m (m + 1) / 2)
        for i in 0..m {
            self.tm[i] = 1.0 / self.qr[i * n + i];
        }
        self.w.fill(0.0);
        let mut invf = 0.0;
        let (qr, tm) = (&self.qr, &self.tm);
        for (j, x) in self.w.chunks_exact_mut(m).enumerate() {
            // solve R x = e_j (x[i] = 0 for i > j) by columns of R: contiguous axpys
            x[j] = 1.0;
            for k in (0..=j).rev() {
                let xk = x[k] * tm[k];
                x[k] = xk;
                invf += xk * xk;
                for (xi, r) in x[..k].iter_mut().zip(&qr[k * n..k * n + k]) {
                    *xi -= xk * r;
                }
            }
        }
        let lower = if invf.is_finite() && invf > 0.0 { 1.0 / invf.sqrt() } else { 0.0 };
        (rf.sqrt(), lower)
    }

    /// With `R^-1` from `full_rank_bounds` (full rank): `y += Q [R^-T r; 0]` (that is
    /// `y += B^+ r` for `B = G^T`) and `lambda = -R^-1 R^-T r` (`-(B B^T)^-1 r`).
    pub fn full_rank_solve(&mut self, r: &[f64], y: &mut [f64], lambda: &mut [f64]) {
        let m = self.m;
        if self.permuted {
            // internal order: r gathered into tp, lambda computed in tp and scattered
            let mut tp = std::mem::take(&mut self.tp);
            for (t, &c) in tp.iter_mut().zip(&self.cols) {
                *t = r[c];
            }
            self.r_inv_solve(&mut tp);
            for (&t, &c) in tp.iter().zip(&self.cols) {
                lambda[c] = t;
            }
            self.tp = tp;
        } else {
            lambda[..m].copy_from_slice(&r[..m]);
            self.r_inv_solve(&mut lambda[..m]);
        }
        self.apply_q_tm(y);
    }

    /// `tm = R^-T x`, then `x = -R^-1 tm` (internal order, `R^-1` from `full_rank_bounds`).
    fn r_inv_solve(&mut self, x: &mut [f64]) {
        let m = self.m;
        // z = R^-T x: z_j = (column j of R^-1) . x
        for (j, cj) in self.w.chunks_exact(m).enumerate() {
            self.tm[j] = cj[..=j].iter().zip(&*x).map(|(a, b)| a * b).sum();
        }
        // x = -R^-1 z
        x.fill(0.0);
        for (j, cj) in self.w.chunks_exact(m).enumerate() {
            let zj = self.tm[j];
            for (l, c) in x[..=j].iter_mut().zip(cj) {
                *l -= c * zj;
            }
        }
    }

    /// Jacobi SVD of the R left by `qr_cols` (overwrites the `R^-1` of `full_rank_bounds`).
    pub fn svd_of_r(&mut self) -> bool {
        let (n, m) = (self.n, self.m);
        // W = R (upper triangle), V = I
        self.w.fill(0.0);
        self.v.fill(0.0);
        for j in 0..m {
            for i in 0..=j {
                self.w[j * m + i] = self.qr[j * n + i];
            }
            self.v[j * m + j] = 1.0;
        }
        let ok = self.jacobi();
        for j in 0..m {
            let wj = &self.w[j * m..(j + 1) * m];
            self.norms[j] = wj.iter().map(|x| x * x).sum::<f64>().sqrt();
        }
        // insertion sort of the order by decreasing norm (m is small)
        for j in 0..m {
            self.order[j] = j;
        }
        for j in 1..m {
            let mut k = j;
            while k > 0 && self.norms[self.order[k - 1]] < self.norms[self.order[k]] {
                self.order.swap(k - 1, k);
                k -= 1;
            }
        }
        ok && self.norms.iter().all(|x| x.is_finite())
    }

    fn householder_qr(&mut self) {
        let (n, m) = (self.n, self.m);
        for k in 0..m {
            let (head, tail) = self.qr.split_at_mut((k + 1) * n);
            let ck = &mut head[k * n..];
            // the reflector ends at the column's last nonzero (module docs, "Profile")
            let end = ck[k + 1..n].iter().rposition(|&x| x != 0.0).map_or(k + 1, |i| k + 2 + i);
            self.end[k] = end;
            let alpha = ck[k];
            let xnorm2 = crate::linalg::dot4(&ck[k + 1..end], &ck[k + 1..end]);
            if xnorm2 == 0.0 {
                self.tau[k] = 0.0;
                continue;
            }
            let norm = (alpha * alpha + xnorm2).sqrt();
            let beta = if alpha >= 0.0 { -norm } else { norm };
            self.tau[k] = (beta - alpha) / beta;
            let scale = 1.0 / (alpha - beta);
            for x in ck[k + 1..end].iter_mut() {
                *x *= scale;
            }
            ck[k] = beta;
            let vk = &ck[k + 1..end];
            let tau = self.tau[k];
            for j in 0..(m - k - 1) {
                let cj = &mut tail[j * n..(j + 1) * n];
                let s = (cj[k] + crate::linalg::dot4(&cj[k + 1..end], vk)) * tau;
                // a column without entries on the reflector's rows stays as it is
                if s == 0.0 {
                    continue;
                }
                cj[k] -= s;
                for (a, b) in cj[k + 1..end].iter_mut().zip(vk) {
                    *a -= s * b;
                }
            }
        }
    }

    fn jacobi(&mut self) -> bool {
        let m = self.m;
        let tol = (m as f64) * f64::EPSILON;
        self.sweeps = 0;
        if m < 2 {
            return true;
        }
        for j in 0..m {
            let wj = &self.w[j * m..(j + 1) * m];
            self.norms[j] = wj.iter().map(|x| x * x).sum::<f64>();
        }
        while self.sweeps < MAX_SWEEPS {
            self.sweeps += 1;
            let mut rotated = false;
            // Columns with norm <= m eps |W|_max are numerically zero (a redundant constraint
            // row leaves one of rounding-level norm). Rotating such a column against a large
            // one only replaces it by the rounding error of the update, so the sweep would never
            // converge: leave those pairs alone. Their norm (the reported singular value) stays
            // below the pinv tolerance max(m, n) eps sigma_max, so they are dropped anyway.
            let big = self.norms.iter().fold(0.0f64, |x, y| x.max(*y));
            let negligible = (m as f64 * f64::EPSILON).powi(2) * big;
            for p in 0..m - 1 {
                for q in p + 1..m {
                    let (a, b) = (self.norms[p], self.norms[q]);
                    if a <= negligible || b <= negligible {
                        continue;
                    }
                    let (lo, hi) = self.w.split_at_mut(q * m);
                    let wp = &mut lo[p * m..(p + 1) * m];
                    let wq = &mut hi[..m];
                    let c: f64 = wp.iter().zip(wq.iter()).map(|(x, y)| x * y).sum();
                    if c.abs() <= tol * (a * b).sqrt() {
                        continue;
                    }
                    rotated = true;
                    let zeta = (b - a) / (2.0 * c);
                    let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                    let cs = 1.0 / (1.0 + t * t).sqrt();
                    let sn = cs * t;
                    for (x, y) in wp.iter_mut().zip(wq.iter_mut()) {
                        let (xp, yq) = (*x, *y);
                        *x = cs * xp - sn * yq;
                        *y = sn * xp + cs * yq;
                    }
                    // exact norms of the rotated pair (recomputed: no drift)
                    self.norms[p] = wp.iter().map(|x| x * x).sum::<f64>();
                    self.norms[q] = wq.iter().map(|x| x * x).sum::<f64>();
                    let (lo, hi) = self.v.split_at_mut(q * m);
                    let vp = &mut lo[p * m..(p + 1) * m];
                    let vq = &mut hi[..m];
                    for (x, y) in vp.iter_mut().zip(vq.iter_mut()) {
                        let (xp, yq) = (*x, *y);
                        *x = cs * xp - sn * yq;
                        *y = sn * xp + cs * yq;
                    }
                }
            }
            if !rotated {
                return true;
            }
        }
        false
    }

    /// j-th largest singular value.
    #[inline]
    pub fn sigma(&self, j: usize) -> f64 {
        self.norms[self.order[j]]
    }

    /// Right singular vector of the j-th largest singular value into `out` (length m).
    #[inline]
    pub fn v_col_into(&self, j: usize, out: &mut [f64]) {
        let k = self.order[j];
        for (i, &c) in self.cols.iter().enumerate() {
            out[c] = self.v[k * self.m + i];
        }
    }

    /// `y += U c` where `c[j]` multiplies the j-th (sorted) left singular vector; entries of
    /// `c` beyond `rank` must be zero or `rank` given: only the first `rank` are used.
    pub fn add_u_times(&mut self, c: &[f64], rank: usize, y: &mut [f64]) {
        let m = self.m;
        // t = U_r c  (m-vector): U_r column k = w_k / sigma_k
        self.tm.fill(0.0);
        for (j, &cj) in c.iter().enumerate().take(rank) {
            let k = self.order[j];
            let f = cj / self.norms[k];
            let wk = &self.w[k * m..(k + 1) * m];
            for (t, w) in self.tm.iter_mut().zip(wk) {
                *t += f * w;
            }
        }
        self.apply_q_tm(y);
    }

    /// `y += Q [tm; 0]` = `H_0 H_1 ... H_{m-1} [tm; 0]`.
    fn apply_q_tm(&mut self, y: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        self.tn[..m].copy_from_slice(&self.tm);
        self.tn[m..].fill(0.0);
        for k in (0..m).rev() {
            let tau = self.tau[k];
            if tau == 0.0 {
                continue;
            }
            let end = self.end[k];
            let vk = &self.qr[k * n + k + 1..k * n + end];
            let s = (self.tn[k] + crate::linalg::dot4(&self.tn[k + 1..end], vk)) * tau;
            self.tn[k] -= s;
            for (a, b) in self.tn[k + 1..end].iter_mut().zip(vk) {
                *a -= s * b;
            }
        }
        if self.permuted {
            for (&r, b) in self.rows.iter().zip(&self.tn) {
                y[r] += b;
            }
        } else {
            for (a, b) in y.iter_mut().zip(&self.tn) {
                *a += b;
            }
        }
    }

    /// The orthonormal complement of `G`'s range after `qr_cols` (a workspace without unit
    /// columns): column `c` of `out` (`n - m` columns of n, column-major) is `Q e_{m + c}`, so
    /// with `G` of full rank (`full_rank_bounds`) they span the null space of `G^T`.
    pub fn complement_into(&self, out: &mut [f64]) {
        let (n, m) = (self.n, self.m);
        assert!(!self.permuted && out.len() == n * (n - m), "complement_into: a plain workspace, n (n - m) long");
        for (c, col) in out.chunks_exact_mut(n).enumerate() {
            col.fill(0.0);
            col[m + c] = 1.0;
            for k in (0..m).rev() {
                let (tau, end) = (self.tau[k], self.end[k]);
                if tau == 0.0 {
                    continue;
                }
                let vk = &self.qr[k * n + k + 1..k * n + end];
                let s = (col[k] + crate::linalg::dot4(&col[k + 1..end], vk)) * tau;
                col[k] -= s;
                for (a, b) in col[k + 1..end].iter_mut().zip(vk) {
                    *a -= s * b;
                }
            }
        }
    }

    /// Explicit thin `U` (n x m, column-major, sorted) -- for tests and benchmarks, not the
    /// hot path.
    pub fn u_explicit(&mut self, out: &mut [f64]) {
        let n = self.n;
        let mut c = vec![0.0; self.m];
        for j in 0..self.m {
            c.fill(0.0);
            c[j] = 1.0;
            let col = &mut out[j * n..(j + 1) * n];
            col.fill(0.0);
            if self.sigma(j) > 0.0 {
                self.add_u_times(&c, j + 1, col);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reproducible uniform numbers in `[-1, 1)` (an LCG from `seed`).
    fn uniform(mut st: u64) -> impl FnMut() -> f64 {
        move || {
            st = st.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((st >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    fn check(n: usize, m: usize, g: &[f64]) {
        check_with(QrJacobi::new(n, m), g);
    }

    fn check_with(mut s: QrJacobi, g: &[f64]) {
        let (n, m) = (s.n, s.m);
        assert!(s.factor_cols(|j| &g[j * n..(j + 1) * n]));
        let mut u = vec![0.0; n * m];
        s.u_explicit(&mut u);
        let vs: Vec<Vec<f64>> = (0..m)
            .map(|k| {
                let mut v = vec![0.0; m];
                s.v_col_into(k, &mut v);
                v
            })
            .collect();
        // G = U S V^T
        let scale = g.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for i in 0..n {
            for j in 0..m {
                let mut x = 0.0;
                for k in 0..m {
                    x += u[k * n + i] * s.sigma(k) * vs[k][j];
                }
                assert!((x - g[j * n + i]).abs() < 1e-13 * scale, "({i},{j}): {x} vs {}", g[j * n + i]);
            }
        }
        for k in 1..m {
            assert!(s.sigma(k - 1) >= s.sigma(k));
        }
        // U, V orthonormal
        for a in 0..m {
            for b in 0..m {
                let uu: f64 = (0..n).map(|i| u[a * n + i] * u[b * n + i]).sum();
                let vv: f64 = vs[a].iter().zip(&vs[b]).map(|(x, y)| x * y).sum();
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((vv - want).abs() < 1e-13);
                // left vectors of numerically zero singular values are arbitrary
                let zero = (m as f64) * f64::EPSILON * s.sigma(0);
                if s.sigma(a) > zero && s.sigma(b) > zero {
                    assert!((uu - want).abs() < 1e-13, "U^T U [{a},{b}] = {uu}");
                }
            }
        }
    }

    #[test]
    fn reconstructs_random_and_rank_deficient() {
        let mut rnd = uniform(12345);
        for &(n, m) in &[(9usize, 6usize), (20, 6), (6, 6), (5, 1), (40, 12)] {
            let g: Vec<f64> = (0..n * m).map(|_| rnd()).collect();
            check(n, m, &g);
            // duplicate a column: rank m - 1
            if m > 1 {
                let mut g2 = g.clone();
                let c0 = g2[..n].to_vec();
                g2[(m - 1) * n..].copy_from_slice(&c0);
                check(n, m, &g2);
                let mut s = QrJacobi::new(n, m);
                s.factor_cols(|j| &g2[j * n..(j + 1) * n]);
                assert!(s.sigma(m - 1) < 1e-14 * s.sigma(0));
            }
        }
    }

    /// Columns with short profiles (the reflectors end early, some trailing columns miss a
    /// reflector's rows, fill appears below a column's last entry): the factorization still
    /// reconstructs `G`, and the full-rank solve gives `G^T y = r` with the minimum-norm `y`.
    #[test]
    fn short_column_profiles_give_the_factorization() {
        let mut rnd = uniform(4242);
        let (n, m) = (30usize, 22usize);
        // column j touches two row blocks of 6: a shared "shaft" block and one further down
        let mut g = vec![0.0; n * m];
        for j in 0..m {
            let (a, b) = (6 * (j % 2), 6 + 6 * ((j / 2) % 4));
            for i in (a..a + 6).chain(b..b + 6) {
                g[j * n + i] = rnd();
            }
        }
        check(n, m, &g);
        let mut s = QrJacobi::new(n, m);
        s.qr_cols(|j| &g[j * n..(j + 1) * n]);
        assert!(s.end.iter().take(m - 1).any(|&e| e < n), "some reflector ends early: {:?}", s.end);
        let (_, lower) = s.full_rank_bounds();
        assert!(lower > 0.0);
        let r: Vec<f64> = (0..m).map(|_| rnd()).collect();
        let (mut y, mut lambda) = (vec![0.0; n], vec![0.0; m]);
        s.full_rank_solve(&r, &mut y, &mut lambda);
        // G^T y = r, and y = -G lambda (in the range of G: the minimum-norm solution)
        for j in 0..m {
            let gy: f64 = (0..n).map(|i| g[j * n + i] * y[i]).sum();
            assert!((gy - r[j]).abs() < 1e-11, "row {j}: {gy} vs {}", r[j]);
        }
        for i in 0..n {
            let gl: f64 = (0..m).map(|j| g[j * n + i] * lambda[j]).sum();
            assert!((y[i] + gl).abs() < 1e-11, "y[{i}] {} vs {}", y[i], -gl);
        }
    }

    /// Unit columns (the spatial normalization rows): the factorization reconstructs `G`, and
    /// the full-rank solve (`y += B^+ r`, `lambda = -(B B^T)^-1 r`) and the certified bounds
    /// agree with the workspace that does not know them, on a random full-rank `G` and on one
    /// with a duplicated column (rank m - 1, Jacobi path).
    #[test]
    fn unit_columns_give_the_same_factorization() {
        let mut rnd = uniform(777);
        let (n, m) = (21usize, 20usize);
        let units = [(17usize, 6usize), (18, 13), (19, 20), (3, 0)];
        let mut g: Vec<f64> = (0..n * m).map(|_| rnd()).collect();
        for &(c, r) in &units {
            let col = &mut g[c * n..(c + 1) * n];
            col.fill(0.0);
            col[r] = 0.5 + rnd().abs();
        }
        check_with(QrJacobi::with_unit_columns(n, m, &units), &g);
        let r: Vec<f64> = (0..m).map(|_| rnd()).collect();
        let (mut plain, mut unit) = (QrJacobi::new(n, m), QrJacobi::with_unit_columns(n, m, &units));
        plain.qr_cols(|j| &g[j * n..(j + 1) * n]);
        unit.qr_cols(|j| &g[j * n..(j + 1) * n]);
        let (bp, bu) = (plain.full_rank_bounds(), unit.full_rank_bounds());
        assert!((bp.0 - bu.0).abs() < 1e-13 * bp.0 && (bp.1 - bu.1).abs() < 1e-12 * bp.1, "{bp:?} vs {bu:?}");
        let (mut yp, mut yu, mut lp, mut lu) = (vec![0.1; n], vec![0.1; n], vec![0.0; m], vec![0.0; m]);
        plain.full_rank_solve(&r, &mut yp, &mut lp);
        unit.full_rank_solve(&r, &mut yu, &mut lu);
        let big = lp.iter().fold(1.0f64, |a, x| a.max(x.abs()));
        for i in 0..n {
            assert!((yp[i] - yu[i]).abs() < 1e-12, "y[{i}]: {} vs {}", yp[i], yu[i]);
        }
        for j in 0..m {
            assert!((lp[j] - lu[j]).abs() < 1e-12 * big, "lambda[{j}]: {} vs {}", lp[j], lu[j]);
        }
        // rank m - 1: a joint column duplicated
        let c0 = g[..n].to_vec();
        g[5 * n..6 * n].copy_from_slice(&c0);
        check_with(QrJacobi::with_unit_columns(n, m, &units), &g);
        let mut s = QrJacobi::with_unit_columns(n, m, &units);
        s.factor_cols(|j| &g[j * n..(j + 1) * n]);
        assert!(s.sigma(m - 1) < 1e-14 * s.sigma(0));
    }
}
