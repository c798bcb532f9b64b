//! The rank-revealing factorization of a rank-deficient `G` (n x m) without an SVD: from the
//! Householder QR `G = Q1 R` already in `QrJacobi`, the column-pivoted QR of the m x m `R`,
//! `R P = Q2 [T11 T12; 0 T22]`, truncated at the rank `r`, and the complete orthogonal
//! decomposition `[T11 T12] = [L 0] Z^T` (Householder reflectors from the right, L r x r upper
//! triangular). Then `G ~ Q1 Q2_r L (P Z_r)^T` and the UK correction needs only triangular
//! solves with `L` and reflector applications:
//!
//! `y += B^+ r = Q1 Q2_r L^-T Z_r^T P^T r`,  `lambda = -(B B^T)^+ r = -P Z_r L^-1 L^-T Z_r^T P^T r`.
//!
//! **The rank decision is the SVD's, certified.** With per-index tolerances `t_j` (the pinv rule
//! `max(atol, rcond sigma_max)`, and for the last `redundant` values the drift's, `RankRule`)
//! the SVD keeps `sigma_j` iff `sigma_j > t_j`. The pivoted QR gives, without any singular
//! value: `sigma_r <= |T22|_F` (the trailing block, Frobenius), `sigma_{r-1} >= sigma_min(L) >=
//! 1/|L^-1|_F` (`L`'s singular values are those of `[T11 T12]`, rows of `R P`), and
//! `|R_00 P| <= sigma_max <= min(|R|_F, sqrt(m) |R_00 P|)`. The rank `r` is the first index
//! whose trailing norm is at or below its tolerance (taken with the lower bound of
//! `sigma_max`), and it is accepted only if `1/|L^-1|_F` is above the tolerance of index
//! `r - 1` (taken with the upper bound): then every singular value the SVD keeps is kept here
//! and every one it drops is dropped. Otherwise `cod_factor` says so and the caller runs the
//! SVD. The truncated matrix differs from `G` by `|T22|_F`, as the SVD's truncation differs by
//! `sigma_r`: both are pseudoinverses of a rank-`r` matrix within the tolerance of `G`.
//!
//! O(m^3) on the small `R` (A04: 35 x 35, rank 34), allocation free after `QrJacobi::new`.

use super::QrJacobi;

/// Per-index rank tolerance of the pseudoinverse: `max(atol, rcond sigma_max)`, and for the
/// last `redundant` of the `k` singular values `max(atol, rcond_redundant sigma_max)` when that
/// is larger (the drift rule of `uk::settings::RankTolerance::redundant_rcond`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RankRule {
    pub rcond: f64,
    pub atol: f64,
    pub redundant: usize,
    pub rcond_redundant: f64,
}

impl RankRule {
    /// The tolerance for the `j`-th largest of `k` singular values.
    pub fn tol(&self, j: usize, k: usize, sigma_max: f64) -> f64 {
        let t = self.atol.max(self.rcond * sigma_max);
        if j + self.redundant >= k {
            t.max(self.rcond_redundant * sigma_max)
        } else {
            t
        }
    }
}

/// What a certified `cod_factor` found: the rank and bounds of the singular values of `G`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CodRank {
    pub rank: usize,
    /// Upper bound of `sigma_max`.
    pub sigma_max: f64,
    /// Lower bound of the smallest kept singular value (`1/|L^-1|_F`; 0 at rank 0).
    pub sigma_min_kept: f64,
    /// Upper bound of the largest dropped one (`|T22|_F`).
    pub sigma_max_dropped: f64,
    /// The tolerance of the smallest kept index, with the upper bound of `sigma_max`.
    pub tolerance: f64,
}

/// Workspace of the decomposition (m x m and m-vectors; inside `QrJacobi`).
#[derive(Debug, Clone)]
pub(super) struct Cod {
    /// `R P` reduced in place: Q2's reflectors below the diagonal, `L` in the leading r x r
    /// upper triangle, Z's reflectors in rows `0..r`, columns `r..m`.
    a: Vec<f64>,
    /// Column `j` of `R P` is column `perm[j]` of `R`.
    perm: Vec<usize>,
    tau_q: Vec<f64>,
    tau_z: Vec<f64>,
    /// Squared partial column norms and their values at the last recomputation.
    norms: Vec<f64>,
    norms_ref: Vec<f64>,
    s: Vec<f64>,
    rank: usize,
}

impl Cod {
    pub(super) fn new(m: usize) -> Cod {
        Cod { a: vec![0.0; m * m], perm: (0..m).collect(), tau_q: vec![0.0; m], tau_z: vec![0.0; m], norms: vec![0.0; m], norms_ref: vec![0.0; m], s: vec![0.0; m], rank: 0 }
    }
}

/// Householder vector of `x` (leading entry `x[0]`, the rest `tail`): overwrites `tail` with
/// `v[1..]` (`v[0] = 1`), returns `(beta, tau)` with `(I - tau v v^T) x = beta e_0`.
fn householder(alpha: f64, tail: &mut [f64]) -> (f64, f64) {
    let xnorm2: f64 = tail.iter().map(|x| x * x).sum();
    if xnorm2 == 0.0 {
        return (alpha, 0.0);
    }
    let norm = (alpha * alpha + xnorm2).sqrt();
    let beta = if alpha >= 0.0 { -norm } else { norm };
    let scale = 1.0 / (alpha - beta);
    for x in tail.iter_mut() {
        *x *= scale;
    }
    (beta, (beta - alpha) / beta)
}

impl QrJacobi {
    /// After `qr_cols`: the pivoted QR of `R` and its complete orthogonal decomposition at the
    /// rank `rule` gives (module docs). `None` when the bounds cannot certify that rank (or the
    /// input is not finite): the caller then needs the SVD.
    pub fn cod_factor(&mut self, rule: &RankRule) -> Option<CodRank> {
        let (n, m) = (self.n, self.m);
        let c = &mut self.cod;
        // R P = R (upper triangle of the QR), P = I
        c.a.fill(0.0);
        for j in 0..m {
            c.a[j * m..j * m + j + 1].copy_from_slice(&self.qr[j * n..j * n + j + 1]);
            c.perm[j] = j;
            c.norms[j] = c.a[j * m..j * m + j + 1].iter().map(|x| x * x).sum();
            c.norms_ref[j] = c.norms[j];
        }
        let total: f64 = c.norms.iter().sum();
        let big = c.norms.iter().fold(0.0f64, |x, y| x.max(*y));
        if !(total.is_finite()) {
            return None;
        }
        let (lo, hi) = (big.sqrt(), total.sqrt().min((m as f64).sqrt() * big.sqrt()));
        let mut rank = m;
        let mut dropped = 0.0;
        for k in 0..m {
            // trailing block's Frobenius norm: the bound of every singular value from index k on
            let trail: f64 = c.norms[k..].iter().sum::<f64>().max(0.0).sqrt();
            if trail <= rule.tol(k, m, lo) {
                rank = k;
                dropped = trail;
                break;
            }
            // pivot: the largest remaining column
            let p = (k..m).fold(k, |b, j| if c.norms[j] > c.norms[b] { j } else { b });
            if p != k {
                let (lo_c, hi_c) = c.a.split_at_mut(p * m);
                lo_c[k * m..(k + 1) * m].swap_with_slice(&mut hi_c[..m]);
                c.perm.swap(k, p);
                c.norms.swap(k, p);
                c.norms_ref.swap(k, p);
            }
            let (head, tail) = c.a.split_at_mut((k + 1) * m);
            let ck = &mut head[k * m..];
            let (beta, tau) = householder(ck[k], &mut ck[k + 1..m]);
            ck[k] = beta;
            c.tau_q[k] = tau;
            let vk = &ck[k + 1..m];
            for (jj, cj) in tail.chunks_exact_mut(m).enumerate() {
                let j = k + 1 + jj;
                if tau != 0.0 {
                    let s = (cj[k] + cj[k + 1..m].iter().zip(vk).map(|(a, b)| a * b).sum::<f64>()) * tau;
                    cj[k] -= s;
                    for (a, b) in cj[k + 1..m].iter_mut().zip(vk) {
                        *a -= s * b;
                    }
                }
                // downdate the partial norm; recompute when cancellation took most of it
                c.norms[j] -= cj[k] * cj[k];
                if c.norms[j] <= 1e-8 * c.norms_ref[j] || c.norms[j] < 0.0 {
                    c.norms[j] = cj[k + 1..m].iter().map(|x| x * x).sum();
                    c.norms_ref[j] = c.norms[j];
                }
            }
        }
        let r = rank;
        // [T11 T12] = [L 0] Z^T: reflectors from the right, last row first, on columns {i} u r..m
        for i in (0..r).rev() {
            if r == m {
                c.tau_z[i] = 0.0;
                continue;
            }
            let alpha = c.a[i * m + i];
            // row i's tail, gathered into s
            for (j, sj) in (r..m).zip(c.s.iter_mut()) {
                *sj = c.a[j * m + i];
            }
            let (beta, tau) = householder(alpha, &mut c.s[..m - r]);
            c.a[i * m + i] = beta;
            for (j, sj) in (r..m).zip(c.s.iter()) {
                c.a[j * m + i] = *sj;
            }
            c.tau_z[i] = tau;
            if tau == 0.0 {
                continue;
            }
            // rows 0..i: row <- row (I - tau v v^T), v = (1 at i, s on r..m)
            for l in 0..i {
                let mut d = c.a[i * m + l];
                for j in r..m {
                    d += c.a[j * m + l] * c.a[j * m + i];
                }
                d *= tau;
                c.a[i * m + l] -= d;
                for j in r..m {
                    let vj = c.a[j * m + i];
                    c.a[j * m + l] -= d * vj;
                }
            }
        }
        // certificate: 1/|L^-1|_F above the tolerance of the last kept index
        let mut invf = 0.0;
        for j in 0..r {
            // column j of L^-1 into s: solve L x = e_j (x[i] = 0 for i > j)
            c.s[..=j].fill(0.0);
            c.s[j] = 1.0;
            for k in (0..=j).rev() {
                let xk = c.s[k] / c.a[k * m + k];
                c.s[k] = xk;
                invf += xk * xk;
                for i in 0..k {
                    c.s[i] -= xk * c.a[k * m + i];
                }
            }
        }
        let kept = if r == 0 { 0.0 } else if invf.is_finite() && invf > 0.0 { 1.0 / invf.sqrt() } else { return None };
        let tolerance = if r == 0 { rule.tol(0, m, hi) } else { rule.tol(r - 1, m, hi) };
        if r > 0 && kept <= tolerance {
            return None;
        }
        c.rank = r;
        Some(CodRank { rank: r, sigma_max: hi, sigma_min_kept: kept, sigma_max_dropped: dropped, tolerance })
    }

    /// With the decomposition of `cod_factor`: `y += B^+ r` and `lambda = -(B B^T)^+ r` for
    /// `B = G^T` (the UK correction and multipliers; inputs and outputs in `G`'s order).
    pub fn cod_solve(&mut self, r: &[f64], y: &mut [f64], lambda: &mut [f64]) {
        let m = self.m;
        let c = &mut self.cod;
        let rank = c.rank;
        // s = P^T r in QR's internal column order
        for j in 0..m {
            c.s[j] = r[self.cols[c.perm[j]]];
        }
        // s <- Z^T s = H_0 ... H_{r-1} s (H_{r-1} first)
        apply_z(c, m, rank, false);
        // z = L^-T s[..r] (forward: L^T lower triangular)
        for i in 0..rank {
            let col = &c.a[i * m..i * m + i];
            let d: f64 = col.iter().zip(&c.s[..i]).map(|(a, b)| a * b).sum();
            c.s[i] = (c.s[i] - d) / c.a[i * m + i];
        }
        // tm = Q2 [z; 0] (Q2's reflectors 0..r, the last first)
        self.tm[..rank].copy_from_slice(&c.s[..rank]);
        self.tm[rank..].fill(0.0);
        for k in (0..rank).rev() {
            let tau = c.tau_q[k];
            if tau == 0.0 {
                continue;
            }
            let vk = &c.a[k * m + k + 1..(k + 1) * m];
            let d = (self.tm[k] + self.tm[k + 1..].iter().zip(vk).map(|(a, b)| a * b).sum::<f64>()) * tau;
            self.tm[k] -= d;
            for (a, b) in self.tm[k + 1..].iter_mut().zip(vk) {
                *a -= d * b;
            }
        }
        // lambda: w = L^-1 z (back substitution), then -P Z [w; 0]
        for i in (0..rank).rev() {
            let x = c.s[i] / c.a[i * m + i];
            c.s[i] = x;
            for l in 0..i {
                c.s[l] -= x * c.a[i * m + l];
            }
        }
        c.s[rank..].fill(0.0);
        apply_z(c, m, rank, true);
        for j in 0..m {
            lambda[self.cols[c.perm[j]]] = -c.s[j];
        }
        self.apply_q_tm(y);
    }
}

/// `s <- Z s` (`forward`: `H_{r-1} ... H_0 s`, `H_0` first) or `s <- Z^T s` (`H_{r-1}` first);
/// reflector `i` acts on entries `{i} u r..m` with its vector in row `i`, columns `r..m`.
fn apply_z(c: &mut Cod, m: usize, r: usize, forward: bool) {
    if r == m {
        return;
    }
    for step in 0..r {
        let i = if forward { step } else { r - 1 - step };
        let tau = c.tau_z[i];
        if tau == 0.0 {
            continue;
        }
        let mut d = c.s[i];
        for j in r..m {
            d += c.a[j * m + i] * c.s[j];
        }
        d *= tau;
        c.s[i] -= d;
        for j in r..m {
            c.s[j] -= d * c.a[j * m + i];
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use faer::Mat;

    pub(in crate::linalg::small_svd) struct Rng(pub u64);
    impl Rng {
        pub(in crate::linalg::small_svd) fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    /// `G = X diag(s) Y^T` (n x m, column-major) with random orthogonal-ish `X`, `Y` (QR of
    /// random matrices through faer) and the given singular values.
    pub(in crate::linalg::small_svd) fn with_singular_values(rng: &mut Rng, n: usize, m: usize, s: &[f64]) -> Vec<f64> {
        let x = Mat::<f64>::from_fn(n, m, |_, _| rng.next()).qr().compute_thin_Q();
        let y = Mat::<f64>::from_fn(m, m, |_, _| rng.next()).qr().compute_thin_Q();
        let mut g = vec![0.0; n * m];
        for j in 0..m {
            for i in 0..n {
                g[j * n + i] = (0..m).map(|k| x[(i, k)] * s[k] * y[(j, k)]).sum();
            }
        }
        g
    }

    /// `G` (21 x 20) with three unit columns (normalization rows) and a duplicated joint
    /// column: rank m - 1 whatever the rest. Returns `(n, m, units, G)`.
    pub(in crate::linalg::small_svd) fn unit_columns_rank_m1(rng: &mut Rng) -> (usize, usize, [(usize, usize); 3], Vec<f64>) {
        let (n, m) = (21usize, 20usize);
        let units = [(17usize, 6usize), (18, 13), (19, 20)];
        let mut s: Vec<f64> = (0..m).map(|k| 1.0 - 0.03 * k as f64).collect();
        s[m - 1] = 0.0;
        let mut g = with_singular_values(rng, n, m, &s);
        for &(c, r) in &units {
            let col = &mut g[c * n..(c + 1) * n];
            col.fill(0.0);
            col[r] = 0.7;
        }
        let c0 = g[..n].to_vec();
        g[5 * n..6 * n].copy_from_slice(&c0);
        (n, m, units, g)
    }

    /// The SVD's answer: rank by `rule`, `y = B^+ r`, `lambda = -(B B^T)^+ r` for `B = G^T`.
    fn by_svd(n: usize, m: usize, g: &[f64], rule: &RankRule, r: &[f64]) -> (usize, Vec<f64>, Vec<f64>) {
        let gm = Mat::<f64>::from_fn(n, m, |i, j| g[j * n + i]);
        let svd = gm.thin_svd().unwrap();
        let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
        let (mut y, mut lam, mut rank) = (vec![0.0; n], vec![0.0; m], 0);
        for k in 0..m {
            if !(s[k] > rule.tol(k, m, s[0]) && s[k] > 0.0) {
                break;
            }
            rank += 1;
            let c: f64 = (0..m).map(|i| v[(i, k)] * r[i]).sum::<f64>() / s[k];
            for p in 0..n {
                y[p] += u[(p, k)] * c;
            }
            for i in 0..m {
                lam[i] -= v[(i, k)] * c / s[k];
            }
        }
        (rank, y, lam)
    }

    fn check(work: QrJacobi, g: &[f64], rule: &RankRule, rng: &mut Rng, tol: f64) -> usize {
        let (n, m) = (work.n, work.m);
        let mut w = work;
        w.qr_cols(|j| &g[j * n..(j + 1) * n]);
        let c = w.cod_factor(rule).expect("certified");
        let r: Vec<f64> = (0..m).map(|_| rng.next()).collect();
        let (rank, ys, ls) = by_svd(n, m, g, rule, &r);
        assert_eq!(c.rank, rank, "rank: decomposition {} vs SVD {rank}", c.rank);
        let (mut y, mut lam) = (vec![0.0; n], vec![0.0; m]);
        w.cod_solve(&r, &mut y, &mut lam);
        let (ybig, lbig) = (ys.iter().fold(1e-300f64, |a, x| a.max(x.abs())), ls.iter().fold(1e-300f64, |a, x| a.max(x.abs())));
        for i in 0..n {
            assert!((y[i] - ys[i]).abs() <= tol * ybig, "y[{i}] {} vs {}", y[i], ys[i]);
        }
        for i in 0..m {
            assert!((lam[i] - ls[i]).abs() <= tol * lbig, "lambda[{i}] {} vs {}", lam[i], ls[i]);
        }
        c.rank
    }

    /// Random rank-deficient matrices (exact deficiency, and deficiency blurred by a drift-sized
    /// perturbation), square like A04's and tall, with and without unit columns: the certified
    /// decomposition finds the SVD's rank and gives its minimum-norm correction and
    /// multipliers; with the drift rule for the smallest values too.
    #[test]
    fn decomposition_matches_the_svd_on_rank_deficient_matrices() {
        let mut rng = Rng(4242);
        let eps = f64::EPSILON;
        for &(n, m, def) in &[(35usize, 35usize, 1usize), (40, 30, 5), (20, 14, 0), (36, 35, 2), (14, 13, 13)] {
            let mut s: Vec<f64> = (0..m).map(|k| 10f64.powf(-2.0 * k as f64 / m as f64)).collect();
            for x in s[m - def..].iter_mut() {
                *x = 0.0;
            }
            let g = with_singular_values(&mut rng, n, m, &s);
            let rule = RankRule { rcond: (n.max(m) as f64) * eps, atol: 0.0, redundant: 0, rcond_redundant: 0.0 };
            assert_eq!(check(QrJacobi::new(n, m), &g, &rule, &mut rng, 1e-9), m - def);
            // the deficient directions at 1e-7 (a drifted redundant row): kept by the plain
            // rule (and inverted), dropped by the drift rule for the `def` smallest
            let mut sd = s.clone();
            for x in sd[m - def..].iter_mut() {
                *x = 1e-7;
            }
            let gd = with_singular_values(&mut rng, n, m, &sd);
            let drift = RankRule { rcond: 1e-5, atol: 0.0, redundant: def, rcond_redundant: 1e-4 };
            if def < m {
                // the two truncations differ by the dropped 1e-7 over the smallest kept value
                // (0.01 .. 1): the solutions by up to ~1e-5 relative
                assert_eq!(check(QrJacobi::new(n, m), &gd, &drift, &mut rng, 1e-4), m - def);
            }
            let plain = RankRule { rcond: (n.max(m) as f64) * eps, atol: 0.0, redundant: 0, rcond_redundant: 0.0 };
            assert_eq!(check(QrJacobi::new(n, m), &gd, &plain, &mut rng, 1e-6), m);
        }
        // unit columns (normalization rows): same answers
        let (n, m, units, g) = unit_columns_rank_m1(&mut rng);
        let rule = RankRule { rcond: (n as f64) * eps, atol: 0.0, redundant: 0, rcond_redundant: 0.0 };
        let r = check(QrJacobi::with_unit_columns(n, m, &units), &g, &rule, &mut rng, 1e-9);
        assert!(r < m);
    }

    /// Singular values straddling the tolerance within the bounds' slack: no certificate (the
    /// caller runs the SVD), never a wrong rank.
    #[test]
    fn undecidable_ranks_are_not_certified() {
        let mut rng = Rng(99);
        let (n, m) = (30usize, 30usize);
        let mut s: Vec<f64> = vec![1.0; m];
        s[m - 1] = 1.05e-6;
        let g = with_singular_values(&mut rng, n, m, &s);
        let rule = RankRule { rcond: 1e-6, atol: 0.0, redundant: 0, rcond_redundant: 0.0 };
        let mut w = QrJacobi::new(n, m);
        w.qr_cols(|j| &g[j * n..(j + 1) * n]);
        if let Some(c) = w.cod_factor(&rule) {
            let (rank, _, _) = by_svd(n, m, &g, &rule, &vec![0.0; m]);
            assert_eq!(c.rank, rank);
        }
    }
}
