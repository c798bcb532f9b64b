//! Dense LU (real and complex), allocation free after construction.

/// In-place LU with partial pivoting of an n x n row-major matrix. `false` if singular.
pub(crate) fn lu_real(a: &mut [f64], piv: &mut [usize], n: usize) -> bool {
    for k in 0..n {
        let mut p = k;
        let mut best = a[k * n + k].abs();
        for i in k + 1..n {
            let v = a[i * n + k].abs();
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
                a.swap(k * n + j, p * n + j);
            }
        }
        let inv = 1.0 / a[k * n + k];
        let (top, bottom) = a.split_at_mut((k + 1) * n);
        let rowk = &top[k * n..];
        for i in 0..n - k - 1 {
            let row = &mut bottom[i * n..(i + 1) * n];
            let l = row[k] * inv;
            row[k] = l;
            if l != 0.0 {
                for (x, r) in row[k + 1..].iter_mut().zip(&rowk[k + 1..]) {
                    *x -= l * r;
                }
            }
        }
    }
    true
}

pub(crate) fn lu_real_solve(a: &[f64], piv: &[usize], n: usize, x: &mut [f64]) {
    for k in 0..n {
        x.swap(k, piv[k]);
    }
    for i in 0..n {
        let s: f64 = a[i * n..i * n + i].iter().zip(&x[..i]).map(|(l, v)| l * v).sum();
        x[i] -= s;
    }
    for i in (0..n).rev() {
        let s: f64 = a[i * n + i + 1..(i + 1) * n].iter().zip(&x[i + 1..]).map(|(u, v)| u * v).sum();
        x[i] = (x[i] - s) / a[i * n + i];
    }
}

/// Complex LU (separate real and imaginary parts), partial pivoting by modulus.
pub(crate) fn lu_cplx(ar: &mut [f64], ai: &mut [f64], piv: &mut [usize], n: usize) -> bool {
    for k in 0..n {
        let mut p = k;
        let mut best = ar[k * n + k].hypot(ai[k * n + k]);
        for i in k + 1..n {
            let v = ar[i * n + k].hypot(ai[i * n + k]);
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
        for i in k + 1..n {
            let (xr, xi) = (ar[i * n + k], ai[i * n + k]);
            let (lr, li) = (xr * ir - xi * ii, xr * ii + xi * ir);
            ar[i * n + k] = lr;
            ai[i * n + k] = li;
            if lr != 0.0 || li != 0.0 {
                for j in k + 1..n {
                    let (ur, ui) = (ar[k * n + j], ai[k * n + j]);
                    ar[i * n + j] -= lr * ur - li * ui;
                    ai[i * n + j] -= lr * ui + li * ur;
                }
            }
        }
    }
    true
}

pub(crate) fn lu_cplx_solve(ar: &[f64], ai: &[f64], piv: &[usize], n: usize, xr: &mut [f64], xi: &mut [f64]) {
    for k in 0..n {
        xr.swap(k, piv[k]);
        xi.swap(k, piv[k]);
    }
    for i in 0..n {
        let (mut sr, mut si) = (0.0, 0.0);
        for j in 0..i {
            let (lr, li) = (ar[i * n + j], ai[i * n + j]);
            sr += lr * xr[j] - li * xi[j];
            si += lr * xi[j] + li * xr[j];
        }
        xr[i] -= sr;
        xi[i] -= si;
    }
    for i in (0..n).rev() {
        let (mut sr, mut si) = (xr[i], xi[i]);
        for j in i + 1..n {
            let (ur, ui) = (ar[i * n + j], ai[i * n + j]);
            sr -= ur * xr[j] - ui * xi[j];
            si -= ur * xi[j] + ui * xr[j];
        }
        let (pr, pi) = (ar[i * n + i], ai[i * n + i]);
        let d = pr * pr + pi * pi;
        xr[i] = (sr * pr + si * pi) / d;
        xi[i] = (si * pr - sr * pi) / d;
    }
}

