//! The factors of a small dense LU (`lu.rs`) as compressed rows without their zeros, for the
//! implicit methods' repeated solves with one factorization.
//!
//! The saddle-point Newton matrices `[M + g C + g^2 K, A^T; A - g Bv, 0]` keep most of their
//! zeros through the elimination: a body's coordinates couple only to its own and, through the
//! constraint rows, to its joints' neighbours. On the paper scene's nonlinear FFRF coupler
//! (n + m = 24) the strict lower factor holds 82 of 276 entries and the upper one 88 of 300.
//! The dense solves run over every entry; these run over the nonzeros only (a row's dot product
//! skips terms that are exactly zero, which add nothing) and multiply by the pivots' reciprocals.
//! The values agree with `lu_cm_solve`'s and `lu_cplx_solve`'s to rounding (the real sweeps of
//! `lu_cm_solve` sum by columns, these by rows).
//!
//! Built once per factorization (`RowFactors::from_cm`, `RowFactors::from_cplx`: one pass over
//! the factors), allocation free after construction.

/// A unit lower and an upper triangular factor, row by row: the strict lower part of row `i`
/// in `lo[lo_ptr[i]..lo_ptr[i + 1]]`, the strict upper part in `up[up_ptr[i]..up_ptr[i + 1]]`
/// (column index, real part, imaginary part; the imaginary parts stay zero for a real
/// factorization), the reciprocal of the pivot `u_ii` in `dinv[i]` (re, im).
#[derive(Debug, Clone, Default)]
pub(crate) struct RowFactors {
    n: usize,
    lo_ptr: Vec<u32>,
    lo: Vec<(u32, f64, f64)>,
    up_ptr: Vec<u32>,
    up: Vec<(u32, f64, f64)>,
    dinv: Vec<(f64, f64)>,
}

impl RowFactors {
    /// Room for the factors of an `n` x `n` matrix (no allocation afterwards).
    pub(crate) fn with_capacity(n: usize) -> Self {
        let tri = n * n.saturating_sub(1) / 2;
        RowFactors {
            n: 0,
            lo_ptr: Vec::with_capacity(n + 1),
            lo: Vec::with_capacity(tri),
            up_ptr: Vec::with_capacity(n + 1),
            up: Vec::with_capacity(tri),
            dinv: Vec::with_capacity(n),
        }
    }

    /// Entries kept (both factors, without the pivots).
    #[cfg(test)]
    pub(crate) fn nonzeros(&self) -> usize {
        self.lo.len() + self.up.len()
    }

    /// From `lu_cm`'s factors (column-major, `a[i + j n]`).
    pub(crate) fn from_cm(&mut self, a: &[f64], n: usize) {
        self.fill(n, |i, j| (a[i + j * n], 0.0));
    }

    /// From `lu_cplx`'s factors (row-major, real and imaginary parts).
    pub(crate) fn from_cplx(&mut self, ar: &[f64], ai: &[f64], n: usize) {
        self.fill(n, |i, j| (ar[i * n + j], ai[i * n + j]));
    }

    fn fill(&mut self, n: usize, at: impl Fn(usize, usize) -> (f64, f64)) {
        self.n = n;
        self.lo_ptr.clear();
        self.lo.clear();
        self.up_ptr.clear();
        self.up.clear();
        self.dinv.clear();
        self.lo_ptr.push(0);
        self.up_ptr.push(0);
        for i in 0..n {
            for j in 0..i {
                let (re, im) = at(i, j);
                if re != 0.0 || im != 0.0 {
                    self.lo.push((j as u32, re, im));
                }
            }
            self.lo_ptr.push(self.lo.len() as u32);
            for j in i + 1..n {
                let (re, im) = at(i, j);
                if re != 0.0 || im != 0.0 {
                    self.up.push((j as u32, re, im));
                }
            }
            self.up_ptr.push(self.up.len() as u32);
            let (pr, pi) = at(i, i);
            let s = pr * pr + pi * pi;
            self.dinv.push((pr / s, -pi / s));
        }
    }
}

/// RADAU5M's two solves of one Newton iteration: `x <- H^-1 x` with the real factors `h`
/// (row interchanges `piv`) and `(xr + i xi) <- G^-1 (xr + i xi)` with the complex ones `g`
/// (`piv_c`). Both are chains of dependent updates; row by row side by side, each fills the
/// other's waits.
pub(crate) fn pair_solve(h: &RowFactors, piv: &[usize], x: &mut [f64], g: &RowFactors, piv_c: &[usize], xr: &mut [f64], xi: &mut [f64]) {
    let n = h.n;
    assert!(g.n == n && piv.len() >= n && piv_c.len() >= n && x.len() >= n && xr.len() >= n && xi.len() >= n);
    for k in 0..n {
        x.swap(k, piv[k]);
        xr.swap(k, piv_c[k]);
        xi.swap(k, piv_c[k]);
    }
    let (x, xr, xi) = (&mut x[..n], &mut xr[..n], &mut xi[..n]);
    for i in 0..n {
        let mut s = 0.0;
        for &(j, l, _) in &h.lo[h.lo_ptr[i] as usize..h.lo_ptr[i + 1] as usize] {
            s += l * x[j as usize];
        }
        x[i] -= s;
        let (mut sr, mut si) = (0.0, 0.0);
        for &(j, lr, li) in &g.lo[g.lo_ptr[i] as usize..g.lo_ptr[i + 1] as usize] {
            let (yr, yi) = (xr[j as usize], xi[j as usize]);
            sr += lr * yr - li * yi;
            si += lr * yi + li * yr;
        }
        xr[i] -= sr;
        xi[i] -= si;
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for &(j, u, _) in &h.up[h.up_ptr[i] as usize..h.up_ptr[i + 1] as usize] {
            s -= u * x[j as usize];
        }
        x[i] = s * h.dinv[i].0;
        let (mut sr, mut si) = (xr[i], xi[i]);
        for &(j, ur, ui) in &g.up[g.up_ptr[i] as usize..g.up_ptr[i + 1] as usize] {
            let (yr, yi) = (xr[j as usize], xi[j as usize]);
            sr -= ur * yr - ui * yi;
            si -= ur * yi + ui * yr;
        }
        let (dr, di) = g.dinv[i];
        xr[i] = sr * dr - si * di;
        xi[i] = sr * di + si * dr;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::lu::{lu_cm, lu_cm_solve, lu_cplx, lu_cplx_solve};

    /// A saddle-point matrix `[H, A^T; A, 0]` (column-major) with block-diagonal `H` (blocks of
    /// 4) and two entries per constraint row, and a nonsymmetric perturbation.
    fn saddle(n: usize, m: usize) -> Vec<f64> {
        let nm = n + m;
        let mut a = vec![0.0; nm * nm];
        let mut s = 11u64;
        let mut rnd = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for j in 0..n {
            for i in 0..n {
                if i / 4 == j / 4 {
                    a[i + j * nm] = rnd() + if i == j { 3.0 } else { 0.0 };
                }
            }
        }
        for k in 0..m {
            for j in [k % n, (3 * k + 5) % n] {
                a[(n + k) + j * nm] = 1.0 + rnd();
                a[j + (n + k) * nm] = 1.0 + rnd();
            }
        }
        a
    }

    #[test]
    fn the_compressed_rows_solve_as_the_dense_factors() {
        for (n, m) in [(1, 0), (6, 2), (18, 6), (27, 9)] {
            let nm = n + m;
            let a0 = saddle(n, m);
            let mut lu = a0.clone();
            let mut piv = vec![0; nm];
            assert!(lu_cm(&mut lu, &mut piv, nm));
            // the complex matrix a0 + 0.3 i a0 on the H block (row-major)
            let (mut ar, mut ai) = (vec![0.0; nm * nm], vec![0.0; nm * nm]);
            for i in 0..nm {
                for j in 0..nm {
                    ar[i * nm + j] = a0[i + j * nm];
                    ai[i * nm + j] = if i < n && j < n { 0.3 * a0[i + j * nm] } else { 0.0 };
                }
            }
            let mut piv_c = vec![0; nm];
            assert!(lu_cplx(&mut ar, &mut ai, &mut piv_c, nm));
            let (mut h, mut g) = (RowFactors::with_capacity(nm), RowFactors::with_capacity(nm));
            h.from_cm(&lu, nm);
            g.from_cplx(&ar, &ai, nm);
            if nm >= 24 {
                assert!(h.nonzeros() < nm * (nm - 1) / 2, "the zeros are skipped: {} kept", h.nonzeros());
            }
            let b: Vec<f64> = (0..nm).map(|i| (i as f64 + 1.0).sin()).collect();
            let c: Vec<f64> = (0..nm).map(|i| (i as f64 + 0.5).cos()).collect();
            let (mut x1, mut r1, mut i1) = (b.clone(), c.clone(), b.clone());
            lu_cm_solve(&lu, &piv, nm, &mut x1);
            lu_cplx_solve(&ar, &ai, &piv_c, nm, &mut r1, &mut i1);
            let (mut x2, mut r2, mut i2) = (b.clone(), c.clone(), b.clone());
            pair_solve(&h, &piv, &mut x2, &g, &piv_c, &mut r2, &mut i2);
            let scale = x1.iter().chain(&r1).chain(&i1).fold(0.0f64, |s, v| s.max(v.abs()));
            for (u, v) in x1.iter().chain(&r1).chain(&i1).zip(x2.iter().chain(&r2).chain(&i2)) {
                assert!((u - v).abs() <= 1e-12 * scale, "n + m = {nm}: {u} vs {v}");
            }
        }
    }
}
