//! Envelope (profile) storage of a symmetric positive definite matrix, its `L D L^T` factor and
//! the selected inverse inside the envelope.
//!
//! Row `i` stores the columns `first[i]..=i` of the lower triangle contiguously. The factor
//! `S = L D L^T` (`L` unit lower triangular: the Cholesky factor is `L D^1/2`) has its nonzeros
//! inside the same envelope (George and Liu, *Computer Solution of Large Sparse Positive Definite
//! Systems*, 1981, ch. 4), so it is computed in place, column by column (right-looking: each
//! column's outer product is subtracted from the later columns, updates independent of one
//! another; the row-by-row form, one dot product per entry, chains each entry on the ones before
//! it in its row and was slower on the Gram matrices of `uk::gram`); the triangular solves run
//! over the contiguous rows. `L D L^T` rather than `L L^T`: the chain from one pivot to the next
//! is a reciprocal and two products, without a square root. Rounding (Higham, *Accuracy and
//! Stability*, Thm 9.3 with `U = D L^T`, one rounding more for the pivot's reciprocal): the
//! computed factors satisfy `L D L^T = S + E` with `|E| <= gamma_{w+2} |L| D |L|^T`, `w` the
//! widest row, and `(|L| D |L|^T)_ij <= ((L D L^T)_ii (L D L^T)_jj)^1/2` (Cauchy-Schwarz, `D >
//! 0`), the form of the Cholesky bound (Thm 10.3); it does not depend on the order of the sums.
//! For a matrix whose rows couple only within a few blocks (the Gram matrix of the spatial UK
//! path, `uk::gram`) the envelope is much smaller than a band of the same rows: the work is
//! `sum_i (i - first[i])^2 / 2` instead of `n hb^2 / 2`.
//!
//! Selected inverse (Takahashi, Fagan and Chen 1973): `Z = S^-1 = L^-T D^-1 L^-1` on the
//! envelope from `Z_ij = delta_ij / d_j - sum_{k > j} L_kj Z_ki`, `i >= j`, columns from the
//! last. The rows `k > j` with `L_kj` inside the envelope (`first[k] <= j`) pairwise have their
//! entry inside it too, so the recurrence never leaves the envelope; `trace(S^-1)` is its
//! diagonal sum. Everything is allocation free after `EnvelopeCholesky::new`.

use super::dot4;

/// Lower envelope of a symmetric `n x n` matrix, then its `L D L^T` factor (`factor_in_place`).
#[derive(Debug, Clone)]
pub struct EnvelopeCholesky {
    pub n: usize,
    /// First stored column of each row (`first[i] <= i`).
    first: Vec<usize>,
    /// Start of row `i` in `data` (`n + 1` entries); its diagonal is at `ptr[i + 1] - 1`.
    ptr: Vec<usize>,
    /// The matrix's lower envelope, then `L` below the diagonal and `D` on it.
    pub data: Vec<f64>,
    /// `1 / d_i`.
    inv_diag: Vec<f64>,
    /// Column `j` of the envelope below the diagonal: `(k, index of (k, j))` for the rows `k > j`
    /// with `first[k] <= j`, at `col[col_ptr[j]..col_ptr[j + 1]]`.
    col_ptr: Vec<usize>,
    col: Vec<(usize, usize)>,
    /// For each column `j`, the indices of `(max(i, k), min(i, k))` for every ordered pair of
    /// its rows (`|col_j|^2` entries, row-major): the selected inverse's lookups.
    pair_ptr: Vec<usize>,
    pair: Vec<usize>,
    /// Most entries in one row (`max (i - first[i] + 1)`).
    pub width: usize,
    /// Scratch of `selected_inverse_trace`: one column of `L` (the longest column's length).
    lcol: Vec<f64>,
}

impl EnvelopeCholesky {
    /// A zero matrix with the envelope `first` (`first[i] <= i`, checked).
    pub fn new(first: Vec<usize>) -> Self {
        let n = first.len();
        let mut ptr = Vec::with_capacity(n + 1);
        ptr.push(0);
        for (i, &f) in first.iter().enumerate() {
            assert!(f <= i, "envelope: first[{i}] = {f} is right of the diagonal");
            ptr.push(ptr[i] + i - f + 1);
        }
        let width = (0..n).map(|i| i - first[i] + 1).max().unwrap_or(0);
        let index = |i: usize, j: usize| ptr[i] + j - first[i];
        let (mut col_ptr, mut col) = (vec![0], Vec::new());
        for j in 0..n {
            col.extend((j + 1..n).filter(|&k| first[k] <= j).map(|k| (k, index(k, j))));
            col_ptr.push(col.len());
        }
        let (mut pair_ptr, mut pair) = (vec![0], Vec::new());
        for j in 0..n {
            let c = &col[col_ptr[j]..col_ptr[j + 1]];
            for &(i, _) in c {
                for &(k, _) in c {
                    pair.push(index(i.max(k), i.min(k)));
                }
            }
            pair_ptr.push(pair.len());
        }
        let len = ptr[n];
        let lcol = vec![0.0; (0..n).map(|j| col_ptr[j + 1] - col_ptr[j]).max().unwrap_or(0)];
        EnvelopeCholesky { n, first, ptr, data: vec![0.0; len], inv_diag: vec![0.0; n], col_ptr, col, pair_ptr, pair, width, lcol }
    }

    /// Position of entry `(i, j)`, `first[i] <= j <= i`, in `data` (and in a selected inverse).
    #[inline]
    pub fn index(&self, i: usize, j: usize) -> usize {
        debug_assert!(self.first[i] <= j && j <= i, "entry ({i}, {j}) outside the envelope");
        self.ptr[i] + j - self.first[i]
    }

    /// Whether `(i, j)`, `j <= i`, is inside the envelope.
    #[inline]
    pub fn contains(&self, i: usize, j: usize) -> bool {
        self.first[i] <= j && j <= i
    }

    /// Stored entries.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The diagonal entry of row `i` (of the matrix before `factor_in_place`, `d_i` after).
    #[inline]
    pub fn diag(&self, i: usize) -> f64 {
        self.data[self.ptr[i + 1] - 1]
    }

    /// `S = L D L^T` in place. `false` at a pivot that is not positive and finite (the
    /// factor is then unusable). Right-looking, column by column: column `j` is scaled by its
    /// pivot and its outer product subtracted from the later columns (`pair`, the lookups of the
    /// selected inverse): the updates of one column are independent of one another, where the
    /// row-by-row form chains each entry of a row on the ones before it.
    pub fn factor_in_place(&mut self) -> bool {
        let data = &mut self.data;
        for j in 0..self.n {
            let dj = self.ptr[j + 1] - 1;
            let d = data[dj];
            if !(d > 0.0 && d.is_finite()) {
                return false;
            }
            let inv = 1.0 / d;
            self.inv_diag[j] = inv;
            let c = &self.col[self.col_ptr[j]..self.col_ptr[j + 1]];
            // the column before scaling, gathered (read by every update): S_ab -= L_aj (d_j L_bj)
            let uc = &mut self.lcol[..c.len()];
            for (u, &(_, kj)) in uc.iter_mut().zip(c) {
                *u = data[kj];
                data[kj] *= inv;
            }
            let p = &self.pair[self.pair_ptr[j]..self.pair_ptr[j + 1]];
            for (a, &(_, aj)) in c.iter().enumerate() {
                let la = data[aj];
                // (k_a, k_b) for b <= a: the lower triangle of the pairs
                for (&ub, &ab) in uc[..=a].iter().zip(&p[a * uc.len()..]) {
                    data[ab] -= la * ub;
                }
            }
        }
        true
    }

    /// `x <- S^-1 x` with the factor of `factor_in_place`.
    pub fn solve(&self, x: &mut [f64]) {
        let n = self.n;
        for i in 0..n {
            let (fi, pi) = (self.first[i], self.ptr[i]);
            x[i] -= dot4(&self.data[pi..pi + i - fi], &x[fi..i]);
        }
        for (x, inv) in x.iter_mut().zip(&self.inv_diag) {
            *x *= inv;
        }
        for i in (0..n).rev() {
            let (fi, pi) = (self.first[i], self.ptr[i]);
            let xi = x[i];
            for (xk, l) in x[fi..i].iter_mut().zip(&self.data[pi..pi + i - fi]) {
                *xk -= l * xi;
            }
        }
    }

    /// The selected inverse `Z = S^-1` inside the envelope into `z` (the layout of `data`, at
    /// least `len()` long), from the factor of `factor_in_place`; returns `trace(S^-1)`.
    pub fn selected_inverse_trace(&mut self, z: &mut [f64]) -> f64 {
        let l = &self.data;
        let mut trace = 0.0;
        for j in (0..self.n).rev() {
            let c = &self.col[self.col_ptr[j]..self.col_ptr[j + 1]];
            let p = &self.pair[self.pair_ptr[j]..self.pair_ptr[j + 1]];
            // column j of L gathered once (each of its entries is read by every row of the column)
            let lc = &mut self.lcol[..c.len()];
            for (x, &(_, kj)) in lc.iter_mut().zip(c) {
                *x = l[kj];
            }
            // Z_ij = -s_i for the rows i of column j (only entries of columns > j are read; the
            // rows are independent), and Z_jj = 1 / d_j + sum_i L_ij s_i from the same s_i
            let mut t = [0.0; 2];
            for (a, &(_, ij)) in c.iter().enumerate() {
                let s: f64 = lc.iter().zip(&p[a * c.len()..(a + 1) * c.len()]).map(|(&lk, &ik)| lk * z[ik]).sum();
                z[ij] = -s;
                t[a & 1] += lc[a] * s;
            }
            let d = self.inv_diag[j] + (t[0] + t[1]);
            z[self.ptr[j + 1] - 1] = d;
            trace += d;
        }
        trace
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block-coupled SPD matrix: the envelope factor solves it and its selected inverse matches
    /// the dense inverse on the envelope; a matrix that is not positive definite is refused.
    #[test]
    fn factor_solve_and_selected_inverse_match_dense() {
        // blocks of rows 0..5, 5..8, 8..12, 12..17; each block couples with its neighbours
        let blocks = [0usize, 5, 8, 12, 17];
        let n = 17;
        let block = |i: usize| (0..4).find(|&b| i < blocks[b + 1]).unwrap();
        let first: Vec<usize> = (0..n).map(|i| blocks[block(i).saturating_sub(1)]).collect();
        let mut env = EnvelopeCholesky::new(first.clone());
        let mut dense = vec![0.0; n * n];
        for i in 0..n {
            for j in first[i]..=i {
                let v = if i == j { 6.0 + i as f64 * 0.1 } else { ((i * 7 + j * 3) as f64).sin() * 0.8 };
                dense[i * n + j] = v;
                dense[j * n + i] = v;
                let k = env.index(i, j);
                env.data[k] = v;
            }
        }
        assert_eq!(env.width, 9);
        assert!(env.factor_in_place());
        // solve against the dense product
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let mut b: Vec<f64> = (0..n).map(|i| (0..n).map(|j| dense[i * n + j] * x[j]).sum()).collect();
        env.solve(&mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-13, "x[{i}] {} vs {}", b[i], x[i]);
        }
        // dense inverse by solving for unit vectors
        let mut inv = vec![0.0; n * n];
        for c in 0..n {
            let mut e = vec![0.0; n];
            e[c] = 1.0;
            env.solve(&mut e);
            for r in 0..n {
                inv[r * n + c] = e[r];
            }
        }
        let mut z = vec![0.0; env.len()];
        let trace = env.selected_inverse_trace(&mut z);
        let dense_trace: f64 = (0..n).map(|i| inv[i * n + i]).sum();
        assert!((trace - dense_trace).abs() < 1e-14 * dense_trace);
        for i in 0..n {
            for j in first[i]..=i {
                assert!((z[env.index(i, j)] - inv[i * n + j]).abs() < 1e-14, "Z({i}, {j})");
            }
        }
        let mut bad = EnvelopeCholesky::new(vec![0, 0]);
        bad.data.copy_from_slice(&[1.0, 2.0, 1.0]);
        assert!(!bad.factor_in_place());
    }
}
