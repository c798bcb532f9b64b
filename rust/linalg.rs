//! Small dense and banded kernels for the structured parts of the mass matrix.
//!
//! The FFRF beam blocks `M_ff`, `K_ff`, `S_tilde` couple only the six nodal coordinates of an
//! element, so in nodal order they are banded with half-bandwidth 5 whatever the number of
//! elements. Storing them banded keeps every per-call product O(n_f) instead of O(n_f^2).
//! Everything here is allocation free after construction.

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

/// A square matrix stored by diagonals: entry (i, j) with |i - j| <= hb lives at
/// `data[i * (2 hb + 1) + (j + hb - i)]`.
#[derive(Debug, Clone)]
pub struct Banded {
    pub n: usize,
    pub hb: usize,
    pub data: Vec<f64>,
}

impl Banded {
    pub fn zeros(n: usize, hb: usize) -> Self {
        Banded { n, hb, data: vec![0.0; n * (2 * hb + 1)] }
    }

    #[inline]
    fn idx(&self, i: usize, j: usize) -> usize {
        i * (2 * self.hb + 1) + (j + self.hb - i)
    }

    /// Entry (i, j); zero outside the band.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if i.abs_diff(j) > self.hb {
            0.0
        } else {
            self.data[self.idx(i, j)]
        }
    }

    /// Add `v` to entry (i, j). Panics (a programming error, not user input) outside the band.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        assert!(i.abs_diff(j) <= self.hb, "entry outside the band");
        let k = self.idx(i, j);
        self.data[k] += v;
    }

    /// `y += alpha * self * x`
    #[inline]
    pub fn mul_add(&self, alpha: f64, x: &[f64], y: &mut [f64]) {
        let (n, hb) = (self.n, self.hb);
        let w = 2 * hb + 1;
        assert!(x.len() >= n && y.len() >= n && self.data.len() >= n * w);
        for i in 0..n {
            let lo = i.saturating_sub(hb);
            let hi = (i + hb + 1).min(n);
            let base = i * w + hb - i; // data index of column 0 in row i (may be "negative")
            // two accumulators; indices are in range: lo..hi within 0..n, base + j within row i
            let (mut s0, mut s1) = (0.0, 0.0);
            let mut j = lo;
            // SAFETY: lo <= j < hi <= n <= x.len(); base + j = i w + hb + (j - i) with
            // |j - i| <= hb lies in row i's w entries, within data (checked above)
            unsafe {
                while j + 1 < hi {
                    s0 += self.data.get_unchecked(base.wrapping_add(j)) * x.get_unchecked(j);
                    s1 += self.data.get_unchecked(base.wrapping_add(j + 1)) * x.get_unchecked(j + 1);
                    j += 2;
                }
                if j < hi {
                    s0 += self.data.get_unchecked(base.wrapping_add(j)) * x.get_unchecked(j);
                }
                *y.get_unchecked_mut(i) += alpha * (s0 + s1);
            }
        }
    }

    /// `x^T self y`
    pub fn bilinear(&self, x: &[f64], y: &[f64]) -> f64 {
        let w = 2 * self.hb + 1;
        let mut total = 0.0;
        for i in 0..self.n {
            let lo = i.saturating_sub(self.hb);
            let hi = (i + self.hb + 1).min(self.n);
            let row = &self.data[i * w..(i + 1) * w];
            let mut s = 0.0;
            for j in lo..hi {
                s += row[j + self.hb - i] * y[j];
            }
            total += x[i] * s;
        }
        total
    }

    /// Dense row-major copy (inspection and tests only).
    pub fn to_dense(&self) -> Vec<f64> {
        let mut d = vec![0.0; self.n * self.n];
        for i in 0..self.n {
            for j in i.saturating_sub(self.hb)..(i + self.hb + 1).min(self.n) {
                d[i * self.n + j] = self.get(i, j);
            }
        }
        d
    }
}

/// Lower-triangular banded Cholesky factor `L` (M = L L^T). Row `i` is stored contiguously as
/// `[L(i, i-hb), ..., L(i, i-1), L(i, i)]` at `data[i * (hb + 1)..]` (entries before column 0
/// are zero), so both triangular solves run over contiguous row slices; the reciprocals of the
/// diagonal are kept so the solves do no division.
#[derive(Debug, Clone)]
pub struct BandedCholesky {
    pub n: usize,
    pub hb: usize,
    pub data: Vec<f64>,
    pub inv_diag: Vec<f64>,
}

impl BandedCholesky {
    /// Entry `L(i, j)`, `i - hb <= j <= i`.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if j > i || i - j > self.hb {
            0.0
        } else {
            self.data[i * (self.hb + 1) + (j + self.hb - i)]
        }
    }

    /// Factor a symmetric positive-definite banded matrix. `Err(i)` names the failing pivot.
    pub fn factor(m: &Banded) -> std::result::Result<Self, usize> {
        let (n, hb) = (m.n, m.hb);
        let w = hb + 1;
        let mut l = vec![0.0; n * w];
        let at = |i: usize, j: usize| i * w + (j + hb - i);
        for i in 0..n {
            let lo = i.saturating_sub(hb);
            for j in lo..=i {
                let mut s = m.get(i, j);
                let klo = lo.max(j.saturating_sub(hb));
                for k in klo..j {
                    s -= l[at(i, k)] * l[at(j, k)];
                }
                if i == j {
                    if !(s > 0.0) || !s.is_finite() {
                        return Err(i);
                    }
                    l[at(i, i)] = s.sqrt();
                } else {
                    l[at(i, j)] = s / l[at(j, j)];
                }
            }
        }
        let inv_diag = (0..n).map(|i| 1.0 / l[at(i, i)]).collect();
        Ok(BandedCholesky { n, hb, data: l, inv_diag })
    }

    /// Solve `L x = v` in place.
    #[inline]
    pub fn solve_lower(&self, x: &mut [f64]) {
        let (n, hb) = (self.n, self.hb);
        let w = hb + 1;
        for i in 0..n {
            let lo = i.saturating_sub(hb);
            let row = &self.data[i * w + (lo + hb - i)..i * w + hb];
            let (done, rest) = x.split_at_mut(i);
            let s: f64 = row.iter().zip(&done[lo..]).map(|(a, b)| a * b).sum();
            rest[0] = (rest[0] - s) * self.inv_diag[i];
        }
    }

    /// Solve `L^T x = v` in place (column sweep over the rows of `L`).
    #[inline]
    pub fn solve_upper(&self, x: &mut [f64]) {
        let (n, hb) = (self.n, self.hb);
        let w = hb + 1;
        for i in (0..n).rev() {
            let xi = x[i] * self.inv_diag[i];
            x[i] = xi;
            let lo = i.saturating_sub(hb);
            let row = &self.data[i * w + (lo + hb - i)..i * w + hb];
            for (a, b) in x[lo..i].iter_mut().zip(row) {
                *a -= b * xi;
            }
        }
    }
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

/// 1D Gauss-Legendre rule on [0, 1] with 4 points: exact for polynomials of degree <= 7,
/// which covers every product of the cubic element shape functions.
pub const GAUSS4: [(f64, f64); 4] = {
    // nodes on [-1, 1]
    const A: f64 = 0.339_981_043_584_856_26;
    const B: f64 = 0.861_136_311_594_052_6;
    const WA: f64 = 0.652_145_154_862_546_1;
    const WB: f64 = 0.347_854_845_137_453_85;
    [
        (0.5 * (1.0 - B), 0.5 * WB),
        (0.5 * (1.0 - A), 0.5 * WA),
        (0.5 * (1.0 + A), 0.5 * WA),
        (0.5 * (1.0 + B), 0.5 * WB),
    ]
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss4_integrates_degree_7() {
        for p in 0..=7 {
            let s: f64 = GAUSS4.iter().map(|(x, w)| w * x.powi(p)).sum();
            assert!((s - 1.0 / (p as f64 + 1.0)).abs() < 1e-15, "degree {p}");
        }
    }

    #[test]
    fn banded_cholesky_solves() {
        let n = 9;
        let mut m = Banded::zeros(n, 2);
        for i in 0..n {
            m.add(i, i, 4.0 + i as f64);
            if i + 1 < n {
                m.add(i, i + 1, 1.0);
                m.add(i + 1, i, 1.0);
            }
            if i + 2 < n {
                m.add(i, i + 2, -0.5);
                m.add(i + 2, i, -0.5);
            }
        }
        let l = BandedCholesky::factor(&m).unwrap();
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin() + 0.3).collect();
        let mut b = vec![0.0; n];
        m.mul_add(1.0, &x, &mut b);
        l.solve_lower(&mut b);
        l.solve_upper(&mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-13);
        }
    }

    #[test]
    fn cholesky3_rejects_indefinite() {
        let mut a = [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(!cholesky3(&mut a));
    }
}
