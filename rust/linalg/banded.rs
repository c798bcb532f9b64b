//! Banded storage and the banded Cholesky factorization.
//!
//! The FFRF beam blocks `M_ff`, `K_ff`, `S_tilde` couple only the six nodal coordinates of an
//! element, so in nodal order they are banded with half-bandwidth 5 whatever the number of
//! elements; an ANCF cable's mass matrix and the Gram matrix of the sparse UK path (after a
//! reverse Cuthill-McKee order) are banded too. Storing them banded keeps every per-call
//! product and solve O(n hb) or O(n hb^2) instead of O(n^2) or O(n^3). Everything here is
//! allocation free after construction.

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

    /// Visit the entries inside the band: `put(i, j, self[i, j])`.
    pub fn visit(&self, put: &mut impl FnMut(usize, usize, f64)) {
        for i in 0..self.n {
            for j in i.saturating_sub(self.hb)..(i + self.hb + 1).min(self.n) {
                put(i, j, self.get(i, j));
            }
        }
    }

    /// Dense row-major copy (inspection and tests only).
    pub fn to_dense(&self) -> Vec<f64> {
        let mut d = vec![0.0; self.n * self.n];
        self.visit(&mut |i, j, v| d[i * self.n + j] = v);
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
    /// A zero `n x n` factor of half-bandwidth `hb`: the workspace of `factor_in_place`.
    pub fn zeros(n: usize, hb: usize) -> Self {
        BandedCholesky { n, hb, data: vec![0.0; n * (hb + 1)], inv_diag: vec![0.0; n] }
    }

    /// Entry `L(i, j)`, `i - hb <= j <= i`.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if j > i || i - j > self.hb {
            0.0
        } else {
            self.data[i * (self.hb + 1) + (j + self.hb - i)]
        }
    }

    /// Factor a symmetric positive-definite banded matrix (once, at model build). `Err(i)`
    /// names the failing pivot.
    pub fn factor(m: &Banded) -> std::result::Result<Self, usize> {
        let (n, hb) = (m.n, m.hb);
        let mut l = BandedCholesky::zeros(n, hb);
        for i in 0..n {
            for j in i.saturating_sub(hb)..=i {
                l.data[i * (hb + 1) + (j + hb - i)] = m.get(i, j);
            }
        }
        l.factor_band::<true>()?;
        Ok(l)
    }

    /// Factor in place, per call: `data` holds the lower band of a symmetric matrix (the layout
    /// of `L`) on entry and `L` on return; `false` on a non-positive or non-finite pivot.
    pub fn factor_in_place(&mut self) -> bool {
        self.factor_band::<false>().is_ok()
    }

    /// The band Cholesky on `data`. `DIVIDE`: the off-diagonal entries are quotients by the
    /// pivot (`factor`, once per model: the rounding the constant FFRF and ANCF factors have
    /// always had); otherwise products with its reciprocal (`factor_in_place`, per call: the
    /// divisions would be a chain of dependent long-latency operations along the band).
    fn factor_band<const DIVIDE: bool>(&mut self) -> std::result::Result<(), usize> {
        let (n, hb) = (self.n, self.hb);
        let w = hb + 1;
        let l = &mut self.data;
        for i in 0..n {
            let lo = i.saturating_sub(hb);
            for j in lo..=i {
                let klo = lo.max(j.saturating_sub(hb));
                let mut s = l[i * w + (j + hb - i)];
                for k in klo..j {
                    s -= l[i * w + (k + hb - i)] * l[j * w + (k + hb - j)];
                }
                if i == j {
                    if !(s > 0.0) || !s.is_finite() {
                        return Err(i);
                    }
                    let d = s.sqrt();
                    l[i * w + hb] = d;
                    self.inv_diag[i] = 1.0 / d;
                } else if DIVIDE {
                    l[i * w + (j + hb - i)] = s / l[j * w + hb];
                } else {
                    l[i * w + (j + hb - i)] = s * self.inv_diag[j];
                }
            }
        }
        Ok(())
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

    /// `x <- (L L^T)^-1 x`.
    pub fn solve(&self, x: &mut [f64]) {
        self.solve_lower(x);
        self.solve_upper(x);
    }

    /// `v <- (L (x) I_2)^-1 v` for `v` of length `2 n` holding pairs `(v_x, v_y)` per row: the
    /// forward substitution on both components together, from the first non-zero pair on (an
    /// ANCF cable's constraint columns touch one element).
    #[inline]
    pub fn solve_lower_pairs(&self, v: &mut [f64]) {
        let (n, hb) = (self.n, self.hb);
        let w = hb + 1;
        let start = v.chunks_exact(2).position(|p| p[0] != 0.0 || p[1] != 0.0).unwrap_or(n);
        for i in start..n {
            let lo = i.saturating_sub(hb);
            let row = &self.data[i * w + (lo + hb - i)..i * w + hb];
            let (mut s0, mut s1) = (0.0, 0.0);
            for (lk, k) in row.iter().zip(lo..i) {
                s0 += lk * v[2 * k];
                s1 += lk * v[2 * k + 1];
            }
            let inv = self.inv_diag[i];
            v[2 * i] = (v[2 * i] - s0) * inv;
            v[2 * i + 1] = (v[2 * i + 1] - s1) * inv;
        }
    }

    /// `v <- (L^T (x) I_2)^-1 v` on pairs (see `solve_lower_pairs`): back substitution (column
    /// sweep) on both components.
    #[inline]
    pub fn solve_upper_pairs(&self, v: &mut [f64]) {
        let (n, hb) = (self.n, self.hb);
        let w = hb + 1;
        for i in (0..n).rev() {
            let inv = self.inv_diag[i];
            let (x0, x1) = (v[2 * i] * inv, v[2 * i + 1] * inv);
            v[2 * i] = x0;
            v[2 * i + 1] = x1;
            let lo = i.saturating_sub(hb);
            let row = &self.data[i * w + (lo + hb - i)..i * w + hb];
            for (lk, k) in row.iter().zip(lo..i) {
                v[2 * k] -= lk * x0;
                v[2 * k + 1] -= lk * x1;
            }
        }
    }

    /// `trace((L L^T)^-1)` by the Takahashi recurrence (the selected inverse `Z = (L L^T)^-1`
    /// inside the band, which is closed under it; O(n hb^2)):
    /// `Z(i, j) = -(1/L_jj) sum_{k > j} L_kj Z(i, k)`,
    /// `Z(j, j) = (1/L_jj) (1/L_jj - sum_{k > j} L_kj Z(k, j))`. `z`: scratch in the layout of
    /// `L` (`n (hb + 1)`), left holding `Z`'s lower band.
    pub fn selected_inverse_trace(&self, z: &mut [f64]) -> f64 {
        let (m, hb) = (self.n, self.hb);
        let w = hb + 1;
        let l = &self.data;
        // symmetric access inside the band: (i, k), both > j, |i - k| <= hb
        let zi = |z: &[f64], i: usize, k: usize| if k <= i { z[i * w + (k + hb - i)] } else { z[k * w + (i + hb - k)] };
        let mut trace = 0.0;
        for j in (0..m).rev() {
            let hi = (j + hb).min(m - 1);
            let inv = self.inv_diag[j];
            for i in (j + 1..=hi).rev() {
                let mut s = 0.0;
                for k in j + 1..=hi {
                    s += l[k * w + (j + hb - k)] * zi(z, i, k);
                }
                z[i * w + (j + hb - i)] = -s * inv;
            }
            let mut s = 0.0;
            for k in j + 1..=hi {
                s += l[k * w + (j + hb - k)] * z[k * w + (j + hb - k)];
            }
            let d = (inv - s) * inv;
            z[j * w + hb] = d;
            trace += d;
        }
        trace
    }
}

/// How many eigenvalues of the symmetric banded `S` are below `tau2`: the negative pivots of
/// the band `LDL^T` of `S - tau2 I` (Sylvester's law of inertia; no pivoting: a diagnostic).
/// `l` holds the lower band of `S` in the layout of `BandedCholesky` (`n (hb + 1)`) and is
/// overwritten by `L`; `d` (n) receives `D`.
pub fn count_eigenvalues_below(l: &mut [f64], d: &mut [f64], n: usize, hb: usize, tau2: f64) -> usize {
    let w = hb + 1;
    let mut below = 0;
    for i in 0..n {
        let lo = i.saturating_sub(hb);
        for j in lo..i {
            let klo = lo.max(j.saturating_sub(hb));
            let mut s = l[i * w + (j + hb - i)];
            for k in klo..j {
                s -= l[i * w + (k + hb - i)] * l[j * w + (k + hb - j)] * d[k];
            }
            l[i * w + (j + hb - i)] = if d[j] != 0.0 { s / d[j] } else { 0.0 };
        }
        let mut s = l[i * w + hb] - tau2;
        for k in lo..i {
            let lik = l[i * w + (k + hb - i)];
            s -= lik * lik * d[k];
        }
        d[i] = s;
        if s < 0.0 {
            below += 1;
        }
    }
    below
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test_matrix(n: usize) -> Banded {
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
        m
    }

    #[test]
    fn banded_cholesky_solves() {
        let n = 9;
        let m = test_matrix(n);
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
    fn in_place_factor_selected_inverse_and_inertia_agree_with_the_dense_matrix() {
        let n = 9;
        let m = test_matrix(n);
        let mut l = BandedCholesky::zeros(n, m.hb);
        for i in 0..n {
            for j in i.saturating_sub(m.hb)..=i {
                l.data[i * (m.hb + 1) + (j + m.hb - i)] = m.get(i, j);
            }
        }
        let band = l.data.clone();
        assert!(l.factor_in_place());
        // trace of the inverse from n solves
        let mut trace = 0.0;
        for k in 0..n {
            let mut e = vec![0.0; n];
            e[k] = 1.0;
            l.solve(&mut e);
            trace += e[k];
        }
        let mut z = vec![0.0; l.data.len()];
        assert!((l.selected_inverse_trace(&mut z) - trace).abs() < 1e-14 * trace);
        // every eigenvalue is in [4 - 3, n + 4 + 3] (Gershgorin): none below 0.5, all below 20
        let (mut s, mut d) = (band.clone(), vec![0.0; n]);
        assert_eq!(count_eigenvalues_below(&mut s, &mut d, n, m.hb, 0.5), 0);
        let (mut s, mut d) = (band, vec![0.0; n]);
        assert_eq!(count_eigenvalues_below(&mut s, &mut d, n, m.hb, 20.0), n);
        let mut bad = Banded::zeros(2, 1);
        bad.add(0, 0, 1.0);
        bad.add(1, 1, -1.0);
        assert_eq!(BandedCholesky::factor(&bad).unwrap_err(), 1);
    }
}
