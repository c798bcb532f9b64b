//! Band LU with partial pivoting (LAPACK's `gbtf2` / `gbtrs`), real and complex, in place and
//! allocation free after construction: the factorization of the implicit methods' sparse
//! Newton matrices once a fill-reducing order has made them banded (`sparse_newton`).
//!
//! An `N x N` matrix with `kl` sub- and `ku` super-diagonals is stored column-major with
//! `ld = 2 kl + ku + 1` rows per column: entry `(i, j)` sits at row `kv + i - j` of column `j`,
//! `kv = kl + ku`; the top `kl` rows of each column take the fill that row interchanges bring
//! into `U` (whose upper bandwidth grows to `kl + ku`). Factoring costs at most
//! `N kl (kl + ku + 1)` multiply-adds, a solve `N (2 kl + ku)`. Partial pivoting makes it as
//! stable as the dense LU with partial pivoting (Golub & Van Loan, 4.3.5): the saddle-point
//! matrices of the implicit methods have a zero block that needs it.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// The scalars the band LU runs on: `f64` and `C64`.
pub trait Scalar: Copy + Default + PartialEq + std::fmt::Debug + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self> {
    /// `|re| + |im|` (LAPACK's `cabs1`): the pivot size.
    fn abs1(self) -> f64;
    fn from_real(x: f64) -> Self;
}

impl Scalar for f64 {
    #[inline(always)]
    fn abs1(self) -> f64 {
        self.abs()
    }
    #[inline(always)]
    fn from_real(x: f64) -> Self {
        x
    }
}

/// A complex number (the complex Newton matrix of Radau IIA).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct C64 {
    pub re: f64,
    pub im: f64,
}

impl C64 {
    #[inline(always)]
    pub const fn new(re: f64, im: f64) -> C64 {
        C64 { re, im }
    }
}

impl Add for C64 {
    type Output = C64;
    #[inline(always)]
    fn add(self, o: C64) -> C64 {
        C64::new(self.re + o.re, self.im + o.im)
    }
}

impl Sub for C64 {
    type Output = C64;
    #[inline(always)]
    fn sub(self, o: C64) -> C64 {
        C64::new(self.re - o.re, self.im - o.im)
    }
}

impl Mul for C64 {
    type Output = C64;
    #[inline(always)]
    fn mul(self, o: C64) -> C64 {
        C64::new(self.re * o.re - self.im * o.im, self.re * o.im + self.im * o.re)
    }
}

impl Div for C64 {
    type Output = C64;
    #[inline(always)]
    fn div(self, o: C64) -> C64 {
        let d = o.re * o.re + o.im * o.im;
        C64::new((self.re * o.re + self.im * o.im) / d, (self.im * o.re - self.re * o.im) / d)
    }
}

impl Neg for C64 {
    type Output = C64;
    #[inline(always)]
    fn neg(self) -> C64 {
        C64::new(-self.re, -self.im)
    }
}

impl Scalar for C64 {
    #[inline(always)]
    fn abs1(self) -> f64 {
        self.re.abs() + self.im.abs()
    }
    #[inline(always)]
    fn from_real(x: f64) -> Self {
        C64::new(x, 0.0)
    }
}

/// A band matrix and, after `factor`, its LU factors with the row interchanges.
#[derive(Debug, Clone)]
pub struct BandLu<T: Scalar> {
    n: usize,
    kl: usize,
    ku: usize,
    ld: usize,
    ab: Vec<T>,
    piv: Vec<usize>,
    /// After `factor`: per column, the number of nonzero entries of `L` below the diagonal and
    /// of `U` above it (their profile within the band: pivoting fills the top `kl` rows only
    /// near the rows it exchanged, so the solves skip the zeros beyond).
    lcount: Vec<u32>,
    ucount: Vec<u32>,
}

impl<T: Scalar> BandLu<T> {
    /// Storage for an `n x n` matrix with `kl` sub- and `ku` super-diagonals (all zero).
    pub fn new(n: usize, kl: usize, ku: usize) -> Self {
        let ld = 2 * kl + ku + 1;
        BandLu { n, kl, ku, ld, ab: vec![T::default(); ld * n], piv: vec![0; n], lcount: vec![0; n], ucount: vec![0; n] }
    }

    /// Bytes `new(n, kl, ku)` allocates.
    pub fn bytes(n: usize, kl: usize, ku: usize) -> u64 {
        (n as u64) * ((2 * kl + ku + 1) as u64 * std::mem::size_of::<T>() as u64 + 16)
    }

    pub fn n(&self) -> usize {
        self.n
    }

    /// Multiply-adds of one `factor` at most (`N kl (kl + ku + 1)`).
    pub fn factor_flops(n: usize, kl: usize, ku: usize) -> f64 {
        n as f64 * kl as f64 * (kl + ku + 1) as f64
    }

    /// Set every stored entry to zero (before assembling a new matrix).
    #[inline]
    pub fn clear(&mut self) {
        self.ab.fill(T::default());
    }

    /// Position of entry `(i, j)` in `values_mut()`; `i` within `kl` below and `j` within `ku`
    /// above the diagonal.
    #[inline(always)]
    pub fn index(&self, i: usize, j: usize) -> usize {
        debug_assert!(i <= j + self.kl && j <= i + self.ku, "({i}, {j}) outside the band ({}, {})", self.kl, self.ku);
        j * self.ld + self.kl + self.ku + i - j
    }

    /// The storage (entries at `index(i, j)`), for assembly.
    #[inline]
    pub fn values_mut(&mut self) -> &mut [T] {
        &mut self.ab
    }

    /// Entry `(i, j)` of the stored matrix (before `factor`: the matrix; after: the factors).
    pub fn get(&self, i: usize, j: usize) -> T {
        if i > j + self.kl || j > i + self.ku + self.kl {
            return T::default();
        }
        self.ab[j * self.ld + self.kl + self.ku + i - j]
    }

    /// In-place LU with partial pivoting (`gbtf2`). `false` if a pivot is zero or not finite
    /// (the matrix is singular to working precision or holds a NaN).
    pub fn factor(&mut self) -> bool {
        let (n, kl, ld) = (self.n, self.kl, self.ld);
        let kv = self.kl + self.ku;
        // the fill rows (above the original band) start at zero: `clear` before assembly
        let mut ju = 0usize;
        for j in 0..n {
            let km = kl.min(n - 1 - j);
            let col = j * ld + kv;
            let mut p = 0;
            let mut best = self.ab[col].abs1();
            for i in 1..=km {
                let v = self.ab[col + i].abs1();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            self.piv[j] = j + p;
            if best == 0.0 || !best.is_finite() {
                return false;
            }
            ju = ju.max((j + self.ku + p).min(n - 1));
            if p != 0 {
                for c in j..=ju {
                    let base = c * ld + kv - (c - j);
                    self.ab.swap(base, base + p);
                }
            }
            if km == 0 {
                continue;
            }
            let inv = T::from_real(1.0) / self.ab[col];
            for v in &mut self.ab[col + 1..=col + km] {
                *v = *v * inv;
            }
            // rank-1 update of rows j+1..j+km, columns j+1..ju (contiguous down each column)
            let (left, right) = self.ab.split_at_mut((j + 1) * ld);
            let l = &left[col + 1..=col + km];
            for c in j + 1..=ju {
                let base = (c - j - 1) * ld + kv - (c - j);
                let u = right[base];
                if u != T::default() {
                    for (x, &li) in right[base + 1..=base + km].iter_mut().zip(l) {
                        *x = *x - li * u;
                    }
                }
            }
        }
        // the profile of the factors inside the band, for the solves
        let zero = T::default();
        for j in 0..n {
            let col = j * ld + kv;
            let km = kl.min(n - 1 - j);
            self.lcount[j] = (1..=km).rev().find(|&i| self.ab[col + i] != zero).unwrap_or(0) as u32;
            let top = kv.min(j);
            self.ucount[j] = (1..=top).rev().find(|&d| self.ab[col - d] != zero).unwrap_or(0) as u32;
        }
        true
    }

    /// Solve `A x = b` in place with the factors (`gbtrs`, no transpose).
    pub fn solve(&self, x: &mut [T]) {
        let (n, ld) = (self.n, self.ld);
        let kv = self.kl + self.ku;
        debug_assert!(x.len() >= n);
        // L (unit, with the interchanges in the order they were made)
        for j in 0..n.saturating_sub(1) {
            let p = self.piv[j];
            if p != j {
                x.swap(j, p);
            }
            let xj = x[j];
            if xj != T::default() {
                let km = self.lcount[j] as usize;
                let col = j * ld + kv;
                for (xi, &l) in x[j + 1..=j + km].iter_mut().zip(&self.ab[col + 1..=col + km]) {
                    *xi = *xi - l * xj;
                }
            }
        }
        // U (upper bandwidth kl + ku)
        for j in (0..n).rev() {
            let col = j * ld + kv;
            let xj = x[j] / self.ab[col];
            x[j] = xj;
            if xj != T::default() {
                let lo = j - self.ucount[j] as usize;
                for (r, xr) in x[lo..j].iter_mut().enumerate() {
                    *xr = *xr - self.ab[col - (j - lo) + r] * xj;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        }
    }

    /// A random band matrix whose last diagonal entry is zero (a saddle point's multiplier:
    /// pivoting is needed), and its dense copy.
    fn random_band<T: Scalar>(n: usize, kl: usize, ku: usize, rng: &mut Lcg, make: impl Fn(f64, f64) -> T) -> (BandLu<T>, Vec<T>) {
        let mut b = BandLu::new(n, kl, ku);
        let mut d = vec![T::default(); n * n];
        for j in 0..n {
            for i in j.saturating_sub(ku)..(j + kl + 1).min(n) {
                let v = if n > 1 && i == n - 1 && j == n - 1 { T::default() } else { make(rng.next(), rng.next()) };
                let k = b.index(i, j);
                b.values_mut()[k] = v;
                d[i * n + j] = v;
            }
        }
        (b, d)
    }

    fn check<T: Scalar>(make: impl Fn(f64, f64) -> T + Copy, tol: f64) {
        let mut rng = Lcg(3);
        for (n, kl, ku) in [(1, 0, 0), (5, 1, 2), (12, 3, 3), (30, 4, 2), (40, 7, 7), (9, 8, 8)] {
            let (mut b, d) = random_band(n, kl, ku, &mut rng, make);
            assert!(b.factor(), "n = {n}");
            let x0: Vec<T> = (0..n).map(|_| make(rng.next(), rng.next())).collect();
            let mut x: Vec<T> = (0..n).map(|i| (0..n).fold(T::default(), |s, j| s + d[i * n + j] * x0[j])).collect();
            b.solve(&mut x);
            for (a, e) in x.iter().zip(&x0) {
                assert!((*a - *e).abs1() < tol, "n = {n}, kl = {kl}, ku = {ku}: {a:?} vs {e:?}");
            }
        }
    }

    #[test]
    fn band_lu_solves_real_and_complex_band_systems_with_pivoting() {
        check(|a, _| a, 1e-9);
        check(C64::new, 1e-9);
    }

    #[test]
    fn band_lu_refuses_a_singular_matrix() {
        let mut b = BandLu::<f64>::new(3, 1, 1);
        for (i, j, v) in [(0, 0, 1.0), (0, 1, 2.0), (1, 0, 2.0), (1, 1, 4.0), (2, 2, 1.0)] {
            let k = b.index(i, j);
            b.values_mut()[k] = v;
        }
        assert!(!b.factor());
    }
}
