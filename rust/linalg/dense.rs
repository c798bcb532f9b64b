//! Small dense kernels: the dot product of the kernels, the 3x3 Cholesky of the floating-frame
//! blocks, the dense Cholesky and triangular solves of row-major `n x n` matrices, and the
//! pseudoinverse solve of the initial-state correction.

use faer::Mat;

use super::small_svd::QrJacobi;

/// `x . y` (over the shorter length) with four independent partial sums: a plain sum is one
/// chain of dependent additions (the compiler may not reorder floating-point sums), which
/// bounds the small dot products of the kernel by the adder's latency. The order is fixed, so
/// results are reproducible.
#[inline(always)]
pub fn dot4(x: &[f64], y: &[f64]) -> f64 {
    let k = x.len().min(y.len());
    let (x, y) = (&x[..k], &y[..k]);
    let mut s = [0.0f64; 4];
    let (xc, yc) = (x.chunks_exact(4), y.chunks_exact(4));
    let (xr, yr) = (xc.remainder(), yc.remainder());
    for (a, b) in xc.zip(yc) {
        for j in 0..4 {
            s[j] += a[j] * b[j];
        }
    }
    let mut t = (s[0] + s[2]) + (s[1] + s[3]);
    for (a, b) in xr.iter().zip(yr) {
        t += a * b;
    }
    t
}

/// In-place Cholesky of a 3x3 symmetric matrix (lower triangle used and overwritten).
/// Returns false if not positive definite.
#[inline]
pub fn cholesky3(a: &mut [[f64; 3]; 3]) -> bool {
    for j in 0..3 {
        let mut d = a[j][j];
        for k in 0..j {
            d -= a[j][k] * a[j][k];
        }
        if !(d > 0.0) || !d.is_finite() {
            return false;
        }
        let d = d.sqrt();
        a[j][j] = d;
        for i in (j + 1)..3 {
            let mut s = a[i][j];
            for k in 0..j {
                s -= a[i][k] * a[j][k];
            }
            a[i][j] = s / d;
        }
    }
    for i in 0..3 {
        for j in (i + 1)..3 {
            a[i][j] = 0.0;
        }
    }
    true
}

/// Solve `L x = v` for a lower-triangular 3x3 `L`.
#[inline]
pub fn solve_lower3(l: &[[f64; 3]; 3], x: &mut [f64]) {
    x[0] /= l[0][0];
    x[1] = (x[1] - l[1][0] * x[0]) / l[1][1];
    x[2] = (x[2] - l[2][0] * x[0] - l[2][1] * x[1]) / l[2][2];
}

/// Solve `L^T x = v` for a lower-triangular 3x3 `L`.
#[inline]
pub fn solve_upper3(l: &[[f64; 3]; 3], x: &mut [f64]) {
    x[2] /= l[2][2];
    x[1] = (x[1] - l[2][1] * x[2]) / l[1][1];
    x[0] = (x[0] - l[1][0] * x[1] - l[2][0] * x[2]) / l[0][0];
}

/// In-place lower Cholesky `A = L L^T` of a symmetric `n x n` row-major matrix (the lower
/// triangle is read; on success `a` holds `L`, upper triangle zeroed). A pivot must be finite
/// and above `tol` times the largest |diagonal entry| (`tol = 0`: positive); `Err((j, d))`
/// names the first that is not.
pub fn cholesky(a: &mut [f64], n: usize, tol: f64) -> Result<(), (usize, f64)> {
    let floor = if tol > 0.0 { tol * (0..n).fold(0.0f64, |m, i| m.max(a[i * n + i].abs())) } else { 0.0 };
    for j in 0..n {
        let mut d = a[j * n + j];
        for p in 0..j {
            d -= a[j * n + p] * a[j * n + p];
        }
        if !(d > floor) || !d.is_finite() {
            return Err((j, d));
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for p in 0..j {
                s -= a[i * n + p] * a[j * n + p];
            }
            a[i * n + j] = s / d;
        }
        for i in 0..j {
            a[i * n + j] = 0.0;
        }
    }
    Ok(())
}

/// Solve `L x = v` in place with the row-major lower-triangular `n x n` `L` of `cholesky`.
pub fn solve_lower(l: &[f64], n: usize, x: &mut [f64]) {
    for i in 0..n {
        let mut s = x[i];
        for p in 0..i {
            s -= l[i * n + p] * x[p];
        }
        x[i] = s / l[i * n + i];
    }
}

/// Solve `L^T x = v` in place with the row-major lower-triangular `n x n` `L` of `cholesky`.
pub fn solve_upper(l: &[f64], n: usize, x: &mut [f64]) {
    for i in (0..n).rev() {
        let mut s = x[i];
        for p in i + 1..n {
            s -= l[p * n + i] * x[p];
        }
        x[i] = s / l[i * n + i];
    }
}

/// `y = B^+ r = U S^+ V^T r` with `B^T = bt = U S V^T` (`k x m`), singular values at or below
/// `max(k, m) eps sigma_max` dropped (the cut of `scipy.linalg.pinv`). Allocates (a QR, and
/// faer's thin SVD where the QR does not certify full rank): for the initial-state correction,
/// not the per-step path.
pub fn pinv_solve(bt: &Mat<f64>, r: &[f64]) -> Result<Vec<f64>, faer::linalg::svd::SvdError> {
    let (k, m) = (bt.nrows(), bt.ncols());
    // full rank certified by the QR of `bt` (its bound of sigma_min above the tolerance that its
    // bound of sigma_max sets): the SVD would keep every value, and the pseudoinverse's solution
    // is the QR's minimum-norm one (a fraction of the SVD's cost)
    if m > 0 && m <= k {
        let mut qr = QrJacobi::new(k, m);
        qr.qr_cols(|j| bt.col_as_slice(j));
        let (upper, lower) = qr.full_rank_bounds();
        if upper.is_finite() && lower > (k.max(m) as f64) * f64::EPSILON * upper {
            let (mut y, mut lambda) = (vec![0.0; k], vec![0.0; m]);
            qr.full_rank_solve(r, &mut y, &mut lambda);
            return Ok(y);
        }
    }
    svd_pinv_solve(bt, r)
}

/// `pinv_solve` by the SVD alone.
fn svd_pinv_solve(bt: &Mat<f64>, r: &[f64]) -> Result<Vec<f64>, faer::linalg::svd::SvdError> {
    let (k, m) = (bt.nrows(), bt.ncols());
    let svd = super::simd_state::after_wide(|| bt.thin_svd())?;
    let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
    let smax = if s.nrows() > 0 { s[0] } else { 0.0 };
    let tol = (k.max(m) as f64) * f64::EPSILON * smax;
    let mut y = vec![0.0; k];
    for j in 0..s.nrows() {
        if s[j] > tol && s[j] > 0.0 {
            let mut c = 0.0;
            for i in 0..m {
                c += v[(i, j)] * r[i];
            }
            c /= s[j];
            for p in 0..k {
                y[p] += u[(p, j)] * c;
            }
        }
    }
    Ok(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The QR's solution where it certifies full rank is the SVD's (to rounding); a duplicated
    /// column (rank deficient) goes to the SVD, which drops it.
    #[test]
    fn pinv_solve_by_the_qr_matches_the_svd() {
        let (k, m) = (12usize, 7usize);
        let mut bt = Mat::<f64>::from_fn(k, m, |i, j| ((i * 7 + j * 3) as f64).sin() + if i == j { 2.0 } else { 0.0 });
        let r: Vec<f64> = (0..m).map(|i| (i as f64).cos()).collect();
        for deficient in [false, true] {
            if deficient {
                for i in 0..k {
                    bt[(i, m - 1)] = bt[(i, 0)];
                }
            }
            let (a, b) = (pinv_solve(&bt, &r).unwrap(), svd_pinv_solve(&bt, &r).unwrap());
            let big = b.iter().fold(1.0f64, |s, x| s.max(x.abs()));
            for p in 0..k {
                assert!((a[p] - b[p]).abs() < 1e-13 * big, "deficient {deficient}: y[{p}] {} vs {}", a[p], b[p]);
            }
        }
    }

    #[test]
    fn cholesky3_rejects_indefinite() {
        let mut a = [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(!cholesky3(&mut a));
    }

    #[test]
    fn dense_cholesky_solves_and_names_the_failing_pivot() {
        let n = 5;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = 1.0 / (1.0 + i as f64 + j as f64) + if i == j { 1.0 } else { 0.0 };
            }
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
        let b: Vec<f64> = (0..n).map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum()).collect();
        let mut l = a.clone();
        cholesky(&mut l, n, 0.0).unwrap();
        let mut y = b.clone();
        solve_lower(&l, n, &mut y);
        solve_upper(&l, n, &mut y);
        for i in 0..n {
            assert!((y[i] - x[i]).abs() < 1e-13);
        }
        let mut s = vec![1.0, 2.0, 2.0, 1.0];
        assert_eq!(cholesky(&mut s, 2, 0.0).unwrap_err().0, 1);
        let mut tiny = vec![1.0, 0.0, 0.0, 1e-14];
        assert!(cholesky(&mut tiny.clone(), 2, 0.0).is_ok());
        assert_eq!(cholesky(&mut tiny, 2, 1e-13).unwrap_err().0, 1);
    }
}
