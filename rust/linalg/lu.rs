//! Dense LU (real and complex), allocation free after construction.

/// In-place LU with partial pivoting of an n x n **column-major** matrix (`a[i + j n]` is row
/// `i`, column `j`): every inner loop runs down a contiguous column (the trailing update and both
/// triangular solves are `axpy`s), which suits the repeated solves with one factorization of the
/// implicit methods. `false` if singular.
pub(crate) fn lu_cm(a: &mut [f64], piv: &mut [usize], n: usize) -> bool {
    assert!(a.len() >= n * n && piv.len() >= n);
    for k in 0..n {
        let col = &a[k * n..(k + 1) * n];
        let mut p = k;
        let mut best = col[k].abs();
        for (i, v) in col.iter().enumerate().skip(k + 1) {
            if v.abs() > best {
                best = v.abs();
                p = i;
            }
        }
        piv[k] = p;
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        if p != k {
            for j in 0..n {
                a.swap(k + j * n, p + j * n);
            }
        }
        let inv = 1.0 / a[k + k * n];
        for v in &mut a[k * n + k + 1..(k + 1) * n] {
            *v *= inv;
        }
        let (left, right) = a.split_at_mut((k + 1) * n);
        let lk = &left[k * n + k + 1..(k + 1) * n];
        // the column's nonzeros lie within [lo, hi) (`nonzero_span`): the axpys run there only
        let (lo, hi) = if n >= SPARSE_UPDATE_MIN { nonzero_span(lk) } else { (0, lk.len()) };
        let lk = &lk[lo..hi];
        for colj in right.chunks_exact_mut(n) {
            let u = colj[k];
            if u != 0.0 {
                axpy(-u, lk, &mut colj[k + 1 + lo..k + 1 + hi]);
            }
        }
    }
    true
}

/// Up to this size the complex LU keeps the nonzeros of each pivot row in a stack buffer and
/// updates through them when they are sparse (`nonzeros`).
const SPARSE_UPDATE_MAX: usize = 256;
/// From this size on the LU kernels look for the zeros (below it the scans cost what they save:
/// Simeon's crank and the paper scene, 15 x 15 matrices, were 1-3 % slower with them).
const SPARSE_UPDATE_MIN: usize = 32;

/// The saddle-point matrices of the implicit methods (`[M + g C + g^2 K, A^T; A - g Bv, 0]`)
/// are sparse and stay so through their elimination (the zero block; a body's coordinates
/// coupled only to its joints' and springs' neighbours): A05's 64 x 64 matrix has 630 nonzeros,
/// its factors ~1 700, ~9 600 multiply-adds against ~87 000 for a dense one. The trailing
/// updates skip the zeros: the real LU runs its axpys over the span of the pivot column's
/// nonzeros (`nonzero_span`: contiguous, vectorized), the complex one over the list of the pivot
/// row's nonzeros when they are at most a third of it (`nonzeros`). The same values as the dense
/// sweeps (a zero adds nothing).
///
/// The span `[lo, hi)` of the nonzero entries of `x`.
#[inline(always)]
fn nonzero_span(x: &[f64]) -> (usize, usize) {
    let lo = x.iter().position(|v| *v != 0.0).unwrap_or(x.len());
    let hi = x.iter().rposition(|v| *v != 0.0).map_or(lo, |i| i + 1);
    (lo, hi)
}

/// The positions of the nonzero entries of `re + i im` when they are at most a third of them;
/// `None`: update densely.
#[inline(always)]
fn nonzeros<'b>(re: &[f64], im: &[f64], buf: &'b mut [u16; SPARSE_UPDATE_MAX]) -> Option<&'b [u16]> {
    let len = re.len();
    if len > SPARSE_UPDATE_MAX {
        return None;
    }
    let mut cnt = 0;
    for i in 0..len {
        if re[i] != 0.0 || im[i] != 0.0 {
            buf[cnt] = i as u16;
            cnt += 1;
        }
    }
    (3 * cnt <= len).then_some(&buf[..cnt])
}

/// Solve with the factors of `lu_cm`.
pub(crate) fn lu_cm_solve(a: &[f64], piv: &[usize], n: usize, x: &mut [f64]) {
    assert!(a.len() >= n * n && x.len() >= n && piv.len() >= n);
    for k in 0..n {
        x.swap(k, piv[k]);
    }
    for j in 0..n {
        let xj = x[j];
        if xj != 0.0 {
            axpy(-xj, &a[j * n + j + 1..(j + 1) * n], &mut x[j + 1..n]);
        }
    }
    for j in (0..n).rev() {
        x[j] /= a[j + j * n];
        let xj = x[j];
        if xj != 0.0 {
            axpy(-xj, &a[j * n..j * n + j], &mut x[..j]);
        }
    }
}

/// The inverse from the factors of `lu_cm`, **row-major** into `inv` (n x n). A solve with it
/// (`inv_solve`) is n independent dot products of contiguous rows: no chain of dependent
/// updates as in the two triangular sweeps of `lu_cm_solve`, so it runs several times faster
/// where one factorization serves many solves (generalized-alpha's Newton matrix serves tens
/// of steps; as a Newton matrix its rounding, ~cond eps, is far below the error of an aged
/// matrix, which Newton tolerates by design). The sweeps here run over whole rows of length n.
pub(crate) fn inverse_from_lu_cm(a: &[f64], piv: &[usize], n: usize, inv: &mut [f64]) {
    assert!(a.len() >= n * n && piv.len() >= n && inv.len() >= n * n);
    let x = &mut inv[..n * n];
    x.fill(0.0);
    for i in 0..n {
        x[i * n + i] = 1.0;
    }
    // X = P I: the row interchanges of the factorization, in order
    for k in 0..n {
        if piv[k] != k {
            for j in 0..n {
                x.swap(k * n + j, piv[k] * n + j);
            }
        }
    }
    // L X' = X (unit lower triangular, L[i][j] = a[i + j n])
    for j in 0..n {
        let (head, tail) = x.split_at_mut((j + 1) * n);
        let xj = &head[j * n..];
        for i in j + 1..n {
            let l = a[i + j * n];
            if l != 0.0 {
                axpy(-l, xj, &mut tail[(i - j - 1) * n..(i - j) * n]);
            }
        }
    }
    // U X'' = X' (U[i][j] = a[i + j n], i <= j)
    for j in (0..n).rev() {
        let d = 1.0 / a[j + j * n];
        for v in &mut x[j * n..(j + 1) * n] {
            *v *= d;
        }
        let (head, tail) = x.split_at_mut(j * n);
        let xj = &tail[..n];
        for i in 0..j {
            let u = a[i + j * n];
            if u != 0.0 {
                axpy(-u, xj, &mut head[i * n..(i + 1) * n]);
            }
        }
    }
}

/// `out = inv b` with the row-major inverse of `inverse_from_lu_cm`.
pub(crate) fn inv_solve(inv: &[f64], n: usize, b: &[f64], out: &mut [f64]) {
    for (o, row) in out[..n].iter_mut().zip(inv.chunks_exact(n)) {
        *o = crate::linalg::dot4(row, &b[..n]);
    }
}

/// `y += alpha x` (over the length of `y`).
#[inline(always)]
fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}

/// Complex LU (separate real and imaginary parts, row-major), partial pivoting by modulus. The
/// trailing update runs on row slices (no index checks in the inner loop, which the compiler
/// then vectorizes); the pivot search compares squared moduli (the same order as `hypot`'s).
pub(crate) fn lu_cplx(ar: &mut [f64], ai: &mut [f64], piv: &mut [usize], n: usize) -> bool {
    assert!(ar.len() >= n * n && ai.len() >= n * n && piv.len() >= n);
    let (ar, ai) = (&mut ar[..n * n], &mut ai[..n * n]);
    let mut buf = [0u16; SPARSE_UPDATE_MAX];
    for k in 0..n {
        let mut p = k;
        let mut best = ar[k * n + k] * ar[k * n + k] + ai[k * n + k] * ai[k * n + k];
        for i in k + 1..n {
            let v = ar[i * n + k] * ar[i * n + k] + ai[i * n + k] * ai[i * n + k];
            if v > best {
                best = v;
                p = i;
            }
        }
        piv[k] = p;
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        if p != k {
            for j in 0..n {
                ar.swap(k * n + j, p * n + j);
                ai.swap(k * n + j, p * n + j);
            }
        }
        let (pr, pi) = (ar[k * n + k], ai[k * n + k]);
        let d = pr * pr + pi * pi;
        let (ir, ii) = (pr / d, -pi / d);
        let (ar_top, ar_bot) = ar.split_at_mut((k + 1) * n);
        let (ai_top, ai_bot) = ai.split_at_mut((k + 1) * n);
        let (ur, ui) = (&ar_top[k * n + k + 1..], &ai_top[k * n + k + 1..]);
        let nz = if n >= SPARSE_UPDATE_MIN { nonzeros(ur, ui, &mut buf) } else { None };
        for (rr, ri) in ar_bot.chunks_exact_mut(n).zip(ai_bot.chunks_exact_mut(n)) {
            let (xr, xi) = (rr[k], ri[k]);
            let (lr, li) = (xr * ir - xi * ii, xr * ii + xi * ir);
            rr[k] = lr;
            ri[k] = li;
            if lr != 0.0 || li != 0.0 {
                let (rr, ri) = (&mut rr[k + 1..], &mut ri[k + 1..]);
                match nz {
                    Some(idx) => {
                        for &j in idx {
                            let (j, u_r, u_i) = (j as usize, ur[j as usize], ui[j as usize]);
                            rr[j] -= lr * u_r - li * u_i;
                            ri[j] -= lr * u_i + li * u_r;
                        }
                    }
                    None => {
                        for (((a, b), &u_r), &u_i) in rr.iter_mut().zip(ri.iter_mut()).zip(ur).zip(ui) {
                            *a -= lr * u_r - li * u_i;
                            *b -= lr * u_i + li * u_r;
                        }
                    }
                }
            }
        }
    }
    true
}

pub(crate) fn lu_cplx_solve(ar: &[f64], ai: &[f64], piv: &[usize], n: usize, xr: &mut [f64], xi: &mut [f64]) {
    assert!(ar.len() >= n * n && ai.len() >= n * n && piv.len() >= n && xr.len() >= n && xi.len() >= n);
    for k in 0..n {
        xr.swap(k, piv[k]);
        xi.swap(k, piv[k]);
    }
    for i in 0..n {
        let (mut sr, mut si) = (0.0, 0.0);
        for (((&lr, &li), &yr), &yi) in ar[i * n..i * n + i].iter().zip(&ai[i * n..i * n + i]).zip(&xr[..i]).zip(&xi[..i]) {
            sr += lr * yr - li * yi;
            si += lr * yi + li * yr;
        }
        xr[i] -= sr;
        xi[i] -= si;
    }
    for i in (0..n).rev() {
        let (mut sr, mut si) = (xr[i], xi[i]);
        for (((&ur, &ui), &yr), &yi) in ar[i * n + i + 1..(i + 1) * n].iter().zip(&ai[i * n + i + 1..(i + 1) * n]).zip(&xr[i + 1..n]).zip(&xi[i + 1..n]) {
            sr -= ur * yr - ui * yi;
            si -= ur * yi + ui * yr;
        }
        let (pr, pi) = (ar[i * n + i], ai[i * n + i]);
        let d = pr * pr + pi * pi;
        xr[i] = (sr * pr + si * pi) / d;
        xi[i] = (si * pr - sr * pi) / d;
    }
}


#[cfg(test)]
mod tests {
    use super::*;

    /// A nonsymmetric test matrix that needs pivoting (column-major), n x n.
    fn matrix(n: usize) -> Vec<f64> {
        let mut a = vec![0.0; n * n];
        let mut s = 7u64;
        for v in a.iter_mut() {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            *v = ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5;
        }
        // a zero leading pivot forces a row interchange
        if n > 1 {
            a[0] = 0.0;
        }
        a
    }

    #[test]
    fn the_inverse_solve_agrees_with_the_triangular_solves() {
        for n in [1, 2, 5, 24, 29] {
            let a0 = matrix(n);
            let mut lu = a0.clone();
            let mut piv = vec![0; n];
            assert!(lu_cm(&mut lu, &mut piv, n));
            let mut inv = vec![0.0; n * n];
            inverse_from_lu_cm(&lu, &piv, n, &mut inv);
            // A inv = I (inv row-major, A column-major)
            for i in 0..n {
                for j in 0..n {
                    let s: f64 = (0..n).map(|k| a0[i + k * n] * inv[k * n + j]).sum();
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((s - want).abs() < 1e-10, "n = {n}: (A inv)[{i}][{j}] = {s}");
                }
            }
            let b: Vec<f64> = (0..n).map(|i| (i as f64 + 1.0).sin()).collect();
            let mut x_lu = b.clone();
            lu_cm_solve(&lu, &piv, n, &mut x_lu);
            let mut x_inv = vec![0.0; n];
            inv_solve(&inv, n, &b, &mut x_inv);
            let scale = x_lu.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (u, v) in x_lu.iter().zip(&x_inv) {
                assert!((u - v).abs() <= 1e-11 * scale, "n = {n}: {u} vs {v}");
            }
        }
    }

    /// A saddle-point matrix `[H, A^T; A, 0]` (column-major, `n + m` square) with `H` block
    /// diagonal (blocks of 5, a coupling between neighbours) and `A` two entries a row: sparse
    /// enough that both kernels take their sparse updates (from `SPARSE_UPDATE_MIN` on).
    fn saddle(n: usize, m: usize) -> Vec<f64> {
        let nm = n + m;
        let mut a = vec![0.0; nm * nm];
        let r = matrix(nm);
        for j in 0..n {
            for i in 0..n {
                if i / 5 == j / 5 || i.abs_diff(j) == 5 {
                    a[i + j * nm] = r[i + j * nm] + if i == j { 2.0 } else { 0.0 };
                }
            }
        }
        for k in 0..m {
            for j in [k % n, (3 * k + 7) % n] {
                a[(n + k) + j * nm] = 1.0 + r[k + j * nm];
                a[j + (n + k) * nm] = 1.0 + r[k + j * nm];
            }
        }
        a
    }

    #[test]
    fn the_sparse_updates_solve_saddle_point_systems() {
        let (n, m) = (34, 12);
        let nm = n + m;
        assert!(nm >= SPARSE_UPDATE_MIN);
        let a0 = saddle(n, m);
        let b: Vec<f64> = (0..nm).map(|i| (i as f64 + 1.0).cos()).collect();
        let residual = |x: &[f64], im: Option<&[f64]>| -> f64 {
            // |A x - b| for the real system, |(A + i 0.3 A_H) x - b| for the complex one
            (0..nm)
                .map(|i| {
                    let (mut sr, mut si) = (-b[i], 0.0);
                    for j in 0..nm {
                        let re = a0[i + j * nm];
                        let ai = if im.is_some() && i < n && j < n { 0.3 * re } else { 0.0 };
                        let (xr, xi) = (x[j], im.map_or(0.0, |v| v[j]));
                        sr += re * xr - ai * xi;
                        si += re * xi + ai * xr;
                    }
                    sr.hypot(si)
                })
                .fold(0.0, f64::max)
        };
        let mut lu = a0.clone();
        let mut piv = vec![0; nm];
        assert!(lu_cm(&mut lu, &mut piv, nm));
        let mut x = b.clone();
        lu_cm_solve(&lu, &piv, nm, &mut x);
        assert!(residual(&x, None) < 1e-12, "real: {}", residual(&x, None));
        // the complex matrix A + i 0.3 H, row-major
        let (mut ar, mut ai) = (vec![0.0; nm * nm], vec![0.0; nm * nm]);
        for i in 0..nm {
            for j in 0..nm {
                ar[i * nm + j] = a0[i + j * nm];
                ai[i * nm + j] = if i < n && j < n { 0.3 * a0[i + j * nm] } else { 0.0 };
            }
        }
        assert!(lu_cplx(&mut ar, &mut ai, &mut piv, nm));
        let (mut xr, mut xi) = (b.clone(), vec![0.0; nm]);
        lu_cplx_solve(&ar, &ai, &piv, nm, &mut xr, &mut xi);
        assert!(residual(&xr, Some(&xi)) < 1e-12, "complex: {}", residual(&xr, Some(&xi)));
    }
}
