//! The SVD's truncated pseudoinverse of a `G` (n x m) of rank `m - 1` without the SVD: one
//! redundant constraint row (A04, Bricard's mechanism: 35 rows, rank 34).
//!
//! From the Householder QR `G = Q R` already in `QrJacobi`: inverse iteration on `R` (two
//! triangular solves per step, the pivots guarded at `eps |R|_F`) gives the smallest singular
//! triple `(sigma_m, u, v)` of `R`, converging at `(sigma_m / sigma_{m-1})^2` per step (on A04
//! ~1e-30 on the manifold, ~1e-9 at a loose run's stages). The lifted matrix
//! `R_aug = R + c u v^T` (`c = |R|_F >= sigma_max`) has the singular values of `R` with
//! `sigma_m` replaced by `sigma_m + c`, so it is as well conditioned as the kept part, and its
//! QR (a second, m x m `QrJacobi`) gives the truncated SVD's solution with triangular solves:
//!
//! `r' = r - v (v . r)`,  `y += Q [R_aug^-T r'; 0]`,  `lambda = -R_aug^-1 R_aug^-T r'`,
//!
//! which are `sum_{i<m} u_i (v_i . r) / s_i` and `-sum_{i<m} v_i (v_i . r) / s_i^2`: the SVD's
//! truncation itself (not a rank-revealing QR's, which differs from it by the dropped value
//! over the smallest kept one off the manifold: `cod`).
//!
//! **The rank decision is the SVD's, certified** (as in `cod`): `sigma_m <= |R v|` for the unit
//! `v`, so the last value is dropped when `|R v|` (with its rounding) is at or below its
//! tolerance with the lower bound of `sigma_max`; the kept ones are `>= 1/|R_aug^-1|_F` less
//! the lift's error (Weyl: `c` times the singular vectors' angle errors, bounded by the
//! residuals `|R v - s u|`, `|R^T u - s v|` over the gap), which must exceed the tolerance of
//! index `m - 2` with the upper bound. Otherwise `deflate_factor` says so and the caller runs
//! the SVD. O(m^3) for the second QR, O(m^2) per inverse-iteration step; allocation free after
//! the first call (the second workspace is made then).

use super::{CodRank, QrJacobi, RankRule};

/// Inverse-iteration steps before giving up (two are enough where the gap is wide).
const MAX_STEPS: usize = 5;

/// Workspace (inside `QrJacobi`; the lifted matrix's QR made at the first use).
#[derive(Debug, Clone, Default)]
pub(super) struct Deflate {
    u: Vec<f64>,
    v: Vec<f64>,
    /// `R v`, `R^T u` (the residuals), then the right-hand side in internal order.
    rv: Vec<f64>,
    rtu: Vec<f64>,
    /// Guarded reciprocals of `R`'s diagonal.
    dinv: Vec<f64>,
    /// `R_aug` (m x m column-major) and its QR.
    a: Vec<f64>,
    aug: Option<Box<QrJacobi>>,
    ya: Vec<f64>,
    lam: Vec<f64>,
}

fn normalize(x: &mut [f64]) -> f64 {
    let nrm = x.iter().map(|a| a * a).sum::<f64>().sqrt();
    if nrm > 0.0 && nrm.is_finite() {
        x.iter_mut().for_each(|a| *a /= nrm);
    }
    nrm
}

impl QrJacobi {
    /// `x <- R^-1 x` (back substitution by columns, guarded pivots).
    fn r_solve_guarded(qr: &[f64], n: usize, dinv: &[f64], x: &mut [f64]) {
        for k in (0..x.len()).rev() {
            let xk = x[k] * dinv[k];
            x[k] = xk;
            for (xi, r) in x[..k].iter_mut().zip(&qr[k * n..k * n + k]) {
                *xi -= xk * r;
            }
        }
    }

    /// `x <- R^-T x` (forward substitution, guarded pivots).
    fn rt_solve_guarded(qr: &[f64], n: usize, dinv: &[f64], x: &mut [f64]) {
        for i in 0..x.len() {
            let d: f64 = qr[i * n..i * n + i].iter().zip(&x[..i]).map(|(a, b)| a * b).sum();
            x[i] = (x[i] - d) * dinv[i];
        }
    }

    /// After `qr_cols` (m >= 2): the certified rank `m - 1` and the lifted factorization
    /// (module docs), or `None` when the bounds cannot certify that rank (the caller then
    /// needs the SVD).
    pub fn deflate_factor(&mut self, rule: &RankRule) -> Option<CodRank> {
        let (n, m) = (self.n, self.m);
        if m < 2 {
            return None;
        }
        let d = &mut self.deflate;
        if d.u.len() != m {
            *d = Deflate { u: vec![0.0; m], v: vec![0.0; m], rv: vec![0.0; m], rtu: vec![0.0; m], dinv: vec![0.0; m], a: vec![0.0; m * m], aug: Some(Box::new(QrJacobi::new(m, m))), ya: vec![0.0; m], lam: vec![0.0; m] };
        }
        let qr = &self.qr;
        let (mut total, mut big) = (0.0f64, 0.0f64);
        for j in 0..m {
            let c: f64 = qr[j * n..j * n + j + 1].iter().map(|x| x * x).sum();
            total += c;
            big = big.max(c);
        }
        if !total.is_finite() || total == 0.0 {
            return None;
        }
        let (lo, hi) = (big.sqrt(), total.sqrt().min((m as f64).sqrt() * big.sqrt()));
        let eps = f64::EPSILON;
        let guard = eps * hi;
        for k in 0..m {
            let p = qr[k * n + k];
            d.dinv[k] = 1.0 / if p.abs() >= guard { p } else { guard.copysign(p) };
        }
        // a fixed start with no symmetry (mechanisms often have some)
        for (i, x) in d.v.iter_mut().enumerate() {
            *x = 1.0 + (0.618_033_988_749_895 * (i + 1) as f64).fract();
        }
        normalize(&mut d.v);
        let slack = 4.0 * m as f64 * eps * hi;
        let mut converged = false;
        let mut res = 0.0;
        for step in 0..MAX_STEPS {
            d.u.copy_from_slice(&d.v);
            Self::rt_solve_guarded(qr, n, &d.dinv, &mut d.u);
            if !normalize(&mut d.u).is_finite() {
                return None;
            }
            d.v.copy_from_slice(&d.u);
            Self::r_solve_guarded(qr, n, &d.dinv, &mut d.v);
            if !normalize(&mut d.v).is_finite() {
                return None;
            }
            if step == 0 {
                continue;
            }
            // residuals of the pair: R v - s u and R^T u - s v, s = u . R v
            d.rv.fill(0.0);
            for (k, &vk) in d.v.iter().enumerate() {
                for (a, r) in d.rv[..=k].iter_mut().zip(&qr[k * n..k * n + k + 1]) {
                    *a += vk * r;
                }
            }
            for (i, t) in d.rtu.iter_mut().enumerate() {
                *t = qr[i * n..i * n + i + 1].iter().zip(&d.u[..=i]).map(|(a, b)| a * b).sum();
            }
            let sigma = d.u.iter().zip(&d.rv).map(|(a, b)| a * b).sum::<f64>();
            let e1 = d.rv.iter().zip(&d.u).map(|(a, b)| (a - sigma * b).powi(2)).sum::<f64>().sqrt();
            let e2 = d.rtu.iter().zip(&d.v).map(|(a, b)| (a - sigma * b).powi(2)).sum::<f64>().sqrt();
            res = e1.max(e2);
            if res <= slack {
                converged = true;
                break;
            }
        }
        if !converged {
            return None;
        }
        // the last value is dropped: sigma_m <= |R v| (as computed: the SVD's own values carry
        // rounding of the order of `eps |R|`, like this product; `cod` decides alike)
        let rv_norm = d.rv.iter().map(|x| x * x).sum::<f64>().sqrt();
        if rv_norm > rule.tol(m - 1, m, lo) {
            return None;
        }
        // R_aug = R + c u v^T, its QR and the bound of its smallest singular value
        let c = hi;
        for j in 0..m {
            let col = &mut d.a[j * m..(j + 1) * m];
            let f = c * d.v[j];
            for (i, x) in col.iter_mut().enumerate() {
                *x = f * d.u[i] + if i <= j { qr[j * n + i] } else { 0.0 };
            }
        }
        let aug = d.aug.as_mut().expect("made above");
        let a = &d.a;
        aug.qr_cols(|j| &a[j * m..(j + 1) * m]);
        let (_, lower) = aug.full_rank_bounds();
        // the lift's error: the pair's angle errors (residual over the gap) times c
        let gap = lower - rv_norm;
        if !(gap > 0.0) {
            return None;
        }
        let kept = lower - 2.0 * c * res.max(slack) / gap;
        let tolerance = rule.tol(m - 2, m, hi);
        if !(kept > tolerance) {
            return None;
        }
        Some(CodRank { rank: m - 1, sigma_max: hi, sigma_min_kept: kept, sigma_max_dropped: rv_norm, tolerance })
    }

    /// With the factorization of `deflate_factor`: `y += B^+ r` and `lambda = -(B B^T)^+ r`
    /// for `B = G^T`, the SVD truncated at rank `m - 1` (inputs and outputs in `G`'s order).
    pub fn deflate_solve(&mut self, r: &[f64], y: &mut [f64], lambda: &mut [f64]) {
        let d = &mut self.deflate;
        // r' = r - v (v . r), internal order
        for (t, &c) in d.rv.iter_mut().zip(&self.cols) {
            *t = r[c];
        }
        let vr: f64 = d.v.iter().zip(&d.rv).map(|(a, b)| a * b).sum();
        for (t, v) in d.rv.iter_mut().zip(&d.v) {
            *t -= vr * v;
        }
        d.ya.fill(0.0);
        d.aug.as_mut().expect("deflate_factor first").full_rank_solve(&d.rv, &mut d.ya, &mut d.lam);
        for (&l, &c) in d.lam.iter().zip(&self.cols) {
            lambda[c] = l;
        }
        self.tm.copy_from_slice(&d.ya);
        self.apply_q_tm(y);
    }
}

#[cfg(test)]
mod tests {
    use super::super::cod::tests::{unit_columns_rank_m1, with_singular_values, Rng};
    use super::*;
    use faer::Mat;

    /// The SVD's truncated answer at rank `m - 1`: `y = B^+ r`, `lambda = -(B B^T)^+ r`.
    fn by_svd(n: usize, m: usize, g: &[f64], r: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let gm = Mat::<f64>::from_fn(n, m, |i, j| g[j * n + i]);
        let svd = gm.thin_svd().unwrap();
        let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
        let (mut y, mut lam) = (vec![0.0; n], vec![0.0; m]);
        for k in 0..m - 1 {
            let c: f64 = (0..m).map(|i| v[(i, k)] * r[i]).sum::<f64>() / s[k];
            for p in 0..n {
                y[p] += u[(p, k)] * c;
            }
            for i in 0..m {
                lam[i] -= v[(i, k)] * c / s[k];
            }
        }
        (y, lam)
    }

    fn close(a: &[f64], b: &[f64], tol: f64, what: &str) {
        let big = b.iter().fold(1e-300f64, |x, y| x.max(y.abs()));
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            assert!((x - y).abs() <= tol * big, "{what}[{i}]: {x} vs {y}");
        }
    }

    /// After `deflate_factor`: the correction and multipliers of a random residual are the
    /// SVD's truncated ones to rounding.
    fn solves_like_the_svd(w: &mut QrJacobi, g: &[f64], rng: &mut Rng) {
        let (n, m) = (w.n, w.m);
        let r: Vec<f64> = (0..m).map(|_| rng.next()).collect();
        let (ys, ls) = by_svd(n, m, g, &r);
        let (mut y, mut lam) = (vec![0.0; n], vec![0.0; m]);
        w.deflate_solve(&r, &mut y, &mut lam);
        close(&y, &ys, 1e-12, "y");
        close(&lam, &ls, 1e-12, "lambda");
    }

    /// Rank `m - 1` exactly (A04's shape, a tall one, unit columns with a duplicated joint
    /// column) and blurred by a drift-sized smallest value that the drift rule drops: the
    /// certified rank and the SVD's truncated correction and multipliers to rounding (the
    /// rank-revealing QR's truncation, `cod`, differs from the SVD's there by ~1e-5).
    #[test]
    fn deflation_gives_the_svds_truncation() {
        let mut rng = Rng(2026);
        let eps = f64::EPSILON;
        for &(n, m, last) in &[(35usize, 35usize, 0.0), (40, 30, 0.0), (35, 35, 1e-7), (12, 9, 3e-8)] {
            let mut s: Vec<f64> = (0..m).map(|k| 10f64.powf(-2.0 * k as f64 / m as f64)).collect();
            s[m - 1] = last;
            let g = with_singular_values(&mut rng, n, m, &s);
            let rule = if last == 0.0 {
                RankRule { rcond: (n.max(m) as f64) * eps, atol: 0.0, redundant: 0, rcond_redundant: 0.0 }
            } else {
                RankRule { rcond: 1e-5, atol: 0.0, redundant: 1, rcond_redundant: 1e-4 }
            };
            let mut w = QrJacobi::new(n, m);
            w.qr_cols(|j| &g[j * n..(j + 1) * n]);
            let c = w.deflate_factor(&rule).expect("certified");
            assert_eq!(c.rank, m - 1);
            // bounds (to the rounding of the test matrix's values)
            assert!(c.sigma_max_dropped >= last * (1.0 - 1e-8) && c.sigma_min_kept <= s[m - 2] && c.sigma_max >= s[0] * (1.0 - 1e-12));
            solves_like_the_svd(&mut w, &g, &mut rng);
            // the SVD keeps a 1e-7 value under the plain rule: no certificate of rank m - 1
            if last > 0.0 {
                let plain = RankRule { rcond: (n.max(m) as f64) * eps, atol: 0.0, redundant: 0, rcond_redundant: 0.0 };
                assert!(w.deflate_factor(&plain).is_none());
            }
        }
        // unit columns (normalization rows) and a duplicated joint column
        let (n, m, units, g) = unit_columns_rank_m1(&mut rng);
        let rule = RankRule { rcond: (n as f64) * eps, atol: 0.0, redundant: 0, rcond_redundant: 0.0 };
        let mut w = QrJacobi::with_unit_columns(n, m, &units);
        w.qr_cols(|j| &g[j * n..(j + 1) * n]);
        assert_eq!(w.deflate_factor(&rule).expect("certified").rank, m - 1);
        solves_like_the_svd(&mut w, &g, &mut rng);
    }

    /// Two dropped values, full rank, or a last value straddling the tolerance: no certificate
    /// of rank `m - 1` (the caller runs the SVD), never a wrong rank.
    #[test]
    fn other_ranks_are_not_certified() {
        let mut rng = Rng(7);
        let (n, m) = (30usize, 30usize);
        let rule = RankRule { rcond: 1e-6, atol: 0.0, redundant: 0, rcond_redundant: 0.0 };
        for tail in [[0.0, 0.0], [0.5, 0.4], [1.0, 1.05e-6], [1.0, 0.95e-6]] {
            let mut s: Vec<f64> = vec![1.0; m];
            s[m - 2] = tail[0];
            s[m - 1] = tail[1];
            let g = with_singular_values(&mut rng, n, m, &s);
            let mut w = QrJacobi::new(n, m);
            w.qr_cols(|j| &g[j * n..(j + 1) * n]);
            let got = w.deflate_factor(&rule);
            if tail == [1.0, 0.95e-6] {
                // below the tolerance by 5 %: certified or not, never another rank
                assert!(got.map_or(true, |c| c.rank == m - 1));
            } else {
                assert!(got.is_none(), "{tail:?}");
            }
        }
    }
}
