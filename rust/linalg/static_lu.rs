//! Sparse LU with a fill-reducing order and a pivot sequence chosen once and kept while they
//! serve (real and complex, in place, allocation free between re-orderings): the factorization
//! of the implicit methods' Newton matrices whose band is too wide for `band_lu` (a hub that
//! couples everything, as the flyball governor's shaft and slider) but whose elimination stays
//! sparse.
//!
//! * **Order (once, structural).** Minimum degree (Tinney-Walker / Markowitz on the symmetric
//!   pattern of `S + S^T`, bitset rows) gives the column order: A05's 64 x 64 saddle-point
//!   matrix (1 076 structural entries) has ~1 400 entries in its factors and ~5 000
//!   multiply-adds, against ~9 300 for partial pivoting in the natural order and ~87 000 dense.
//! * **Pivots (numeric, when the order is (re)made).** A dense LU of the matrix in that column
//!   order with threshold partial pivoting (`PIVOT_THRESHOLD`: the diagonal while it is at least
//!   that fraction of the column's largest entry, which keeps minimum degree's fill; the largest
//!   entry otherwise: the saddle point's zero block and the Euler parameters' singular mass
//!   blocks need row exchanges) fixes the row of every pivot. The fill of that sequence, from
//!   the structural pattern, gives the lists of `L`'s rows and `U`'s columns of every pivot.
//! * **Refactorizations** (every call while the sequence serves) run the lists with no search,
//!   scan or exchange. Each multiplier is checked: one above `1 / REFACTOR_THRESHOLD` in size
//!   (the kept pivot has become small against its column: the matrix changed, e.g. the step
//!   size by orders of magnitude) makes `factor` return `Reorder`; the caller assembles the
//!   matrix again and the next `factor` chooses the pivots anew on it. KLU's refactorization
//!   with a pivot check (Davis & Palamadai Natarajan 2010) is the same idea.
//!
//! Values live in an `n x n` row-major array in the caller's indices (`index(i, j)` does not
//! move when the order changes); the lists hold flat positions. The structural pattern given at
//! construction must hold every entry the caller writes.

use super::band_lu::Scalar;


/// Analysis: take the diagonal while it is at least this fraction of its column's largest entry.
pub const PIVOT_THRESHOLD: f64 = 0.1;
/// Refactorization: a multiplier larger than `1 / REFACTOR_THRESHOLD` asks for new pivots. A05
/// at rtol 1e-3 (2 s, ~200 factorizations of each matrix): pivots chosen 14 times at 1e-2, 12 at
/// 1e-3, 6 at 1e-4 (the step size grows ~500-fold out of the start: the matrix turns from
/// mass- to damping-dominated). The growth this admits is Newton's business (its matrix only
/// has to be close), not the answer's.
pub const REFACTOR_THRESHOLD: f64 = 1e-3;

/// What `factor` did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Factored {
    Ok,
    /// A zero or non-finite pivot with pivots chosen on this matrix: singular (or NaN).
    Singular,
    /// The kept pivot sequence failed its check: assemble again and call `factor` again (it
    /// then chooses the pivots on the new values).
    Reorder,
}

/// Bitset rows of an `n x n` boolean matrix.
#[derive(Debug, Clone)]
struct Bits {
    w: usize,
    b: Vec<u64>,
}

impl Bits {
    fn new(n: usize) -> Bits {
        let w = n.div_ceil(64).max(1);
        Bits { w, b: vec![0; n * w] }
    }
    fn get(&self, i: usize, j: usize) -> bool {
        self.b[i * self.w + j / 64] >> (j % 64) & 1 == 1
    }
    fn set(&mut self, i: usize, j: usize) {
        self.b[i * self.w + j / 64] |= 1 << (j % 64);
    }
    /// row `i` |= row `k`
    fn or_row(&mut self, i: usize, k: usize) {
        let w = self.w;
        for x in 0..w {
            let v = self.b[k * w + x];
            self.b[i * w + x] |= v;
        }
    }
    fn count(&self, i: usize) -> u32 {
        self.b[i * self.w..(i + 1) * self.w].iter().map(|x| x.count_ones()).sum()
    }
}

/// Minimum degree order of the symmetric pattern `S + S^T` (`s` row-major, `n x n`): `order[k]`
/// is the unknown eliminated `k`-th. Ties go to the lowest index.
fn minimum_degree(n: usize, s: &[bool]) -> Vec<usize> {
    let mut g = Bits::new(n);
    for i in 0..n {
        for j in 0..n {
            if s[i * n + j] {
                g.set(i, j);
                g.set(j, i);
            }
        }
        g.set(i, i);
    }
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for _ in 0..n {
        let v = (0..n).filter(|&v| !done[v]).min_by_key(|&v| g.count(v)).expect("a node is left");
        done[v] = true;
        order.push(v);
        // v's remaining neighbours become a clique; v leaves the graph
        let nb: Vec<usize> = (0..n).filter(|&u| !done[u] && g.get(v, u)).collect();
        for &u in &nb {
            g.or_row(u, v);
        }
        for u in 0..n {
            g.b[u * g.w + v / 64] &= !(1 << (v % 64));
        }
    }
    order
}

/// The structural pattern (`n x n`, row-major) with rows `rows[i]` and columns `cols[j]` at
/// `(i, j)`, into the bitset `s`.
fn permuted_pattern(pattern: &[bool], rows: &[usize], cols: &[usize], s: &mut Bits) {
    let n = rows.len();
    s.b.fill(0);
    for i in 0..n {
        for j in 0..n {
            if pattern[rows[i] * n + cols[j]] {
                s.set(i, j);
            }
        }
    }
}

/// The structural analysis of a `StaticLu`: its pattern and the minimum degree column order.
#[derive(Debug, Clone)]
pub struct Ordering {
    n: usize,
    /// Structural pattern (row-major, caller's indices).
    pattern: Vec<bool>,
    md: Vec<usize>,
}

impl Ordering {
    /// The pattern of the `n x n` matrix whose structural entries are `entries`, and its order.
    pub fn new(n: usize, entries: impl Iterator<Item = (usize, usize)>) -> Self {
        let mut pattern = vec![false; n * n];
        for (i, j) in entries {
            pattern[i * n + j] = true;
        }
        let md = minimum_degree(n, &pattern);
        Ordering { n, pattern, md }
    }

    /// Multiply-adds of a factorization with diagonal pivots in the minimum degree order (the
    /// structural estimate the choice of the linear solver reads).
    pub fn estimated_flops(&self) -> u64 {
        let n = self.n;
        let mut s = Bits::new(n);
        permuted_pattern(&self.pattern, &self.md, &self.md, &mut s);
        let mut flops = 0u64;
        for k in 0..n {
            let nu = (k + 1..n).filter(|&j| s.get(k, j)).count() as u64;
            for i in k + 1..n {
                if s.get(i, k) {
                    flops += nu;
                    s.or_row(i, k);
                }
            }
        }
        flops
    }
}

/// An `n x n` matrix and, after `factor`, its LU factors in a kept pivot sequence.
#[derive(Debug, Clone)]
pub struct StaticLu<T: Scalar> {
    n: usize,
    /// Structural pattern (row-major, caller's indices).
    pattern: Vec<bool>,
    /// The column order (minimum degree).
    md: Vec<usize>,
    a: Vec<T>,
    /// Pivot sequence (`ordered`): the row and column of the `k`-th pivot.
    ordered: bool,
    rows: Vec<usize>,
    cols: Vec<usize>,
    /// `L`'s rows of pivot `k`: `l_pos` (their place in the sequence) and `l_base`
    /// (`rows[place] n`), entries `l_ptr[k]..l_ptr[k + 1]`; `U`'s columns likewise (`u_pos`,
    /// `u_col = cols[place]`).
    l_ptr: Vec<usize>,
    l_pos: Vec<u32>,
    l_base: Vec<u32>,
    u_ptr: Vec<usize>,
    u_pos: Vec<u32>,
    u_col: Vec<u32>,
    /// Flat positions of the factors (zeroed by `clear`) and the inverted pivots.
    fill: Vec<u32>,
    dinv: Vec<T>,
    ucache: Vec<T>,
    work: Vec<T>,
    /// The analysis' dense copy, its row ids and the bitset of the fill (all sized at
    /// construction, the lists reserved for a full triangle: a new choice of pivots during a
    /// run allocates nothing).
    scratch: Vec<T>,
    rowid: Vec<usize>,
    bits: Bits,
}

impl<T: Scalar> StaticLu<T> {
    /// Storage for an `n x n` matrix whose structural entries are `entries` (all zero).
    pub fn new(n: usize, entries: impl Iterator<Item = (usize, usize)>) -> Self {
        Self::with_ordering(Ordering::new(n, entries))
    }

    /// The same on an analysis already made (the real and the complex matrix of one pattern
    /// share it: the minimum degree order is found once).
    pub fn with_ordering(o: Ordering) -> Self {
        let Ordering { n, pattern, md } = o;
        let z = |k: usize| vec![T::default(); k];
        let tri = n * n.saturating_sub(1) / 2;
        StaticLu {
            n,
            pattern,
            md,
            a: z(n * n),
            ordered: false,
            rows: vec![0; n],
            cols: vec![0; n],
            l_ptr: vec![0; n + 1],
            l_pos: Vec::with_capacity(tri),
            l_base: Vec::with_capacity(tri),
            u_ptr: vec![0; n + 1],
            u_pos: Vec::with_capacity(tri),
            u_col: Vec::with_capacity(tri),
            fill: Vec::with_capacity(n * n),
            dinv: z(n),
            ucache: z(n),
            work: z(n),
            scratch: z(n * n),
            rowid: vec![0; n],
            bits: Bits::new(n),
        }
    }

    /// Bytes of the storage for `n` (values, the analysis' copy, the pattern; the lists at most
    /// the same again).
    pub fn bytes(n: usize) -> u64 {
        let n = n as u64;
        // values and the analysis' copy; the pattern; the four lists (half each) and the fill
        (2 * std::mem::size_of::<T>() as u64 + 1 + 12) * n * n
    }

    pub fn n(&self) -> usize {
        self.n
    }

    /// Position of entry `(i, j)` in `values_mut`.
    #[inline(always)]
    pub fn index(&self, i: usize, j: usize) -> usize {
        i * self.n + j
    }

    pub fn values_mut(&mut self) -> &mut [T] {
        &mut self.a
    }

    /// Zero the factors' positions before an assembly (all of them before a new order).
    pub fn clear(&mut self) {
        if self.ordered {
            for &p in &self.fill {
                self.a[p as usize] = T::default();
            }
        } else {
            self.a.fill(T::default());
        }
    }

    /// Factor in place (the kept sequence, or a new one chosen on these values).
    pub fn factor(&mut self) -> Factored {
        if !self.ordered {
            if !self.choose_pivots() {
                return Factored::Singular;
            }
            self.symbolic();
            self.ordered = true;
            return match self.refactor() {
                // the sequence was chosen on these values: a failed check is rounding's (the
                // threshold holds) unless a pivot vanished
                Factored::Reorder => Factored::Ok,
                r => r,
            };
        }
        let r = self.refactor();
        if r != Factored::Ok {
            self.ordered = false;
            if r == Factored::Singular {
                return Factored::Reorder;
            }
        }
        r
    }

    /// The kept sequence on the current values; `Reorder` when a multiplier fails the check,
    /// `Singular` on a zero or non-finite pivot.
    fn refactor(&mut self) -> Factored {
        let n = self.n;
        let mut ok = true;
        for k in 0..n {
            let bk = self.rows[k] * n;
            let ck = self.cols[k];
            let piv = self.a[bk + ck];
            let pabs = piv.abs1();
            if !(pabs > 0.0) || !pabs.is_finite() {
                return Factored::Singular;
            }
            let inv = T::from_real(1.0) / piv;
            self.dinv[k] = inv;
            let (u0, u1) = (self.u_ptr[k], self.u_ptr[k + 1]);
            for e in u0..u1 {
                self.ucache[e - u0] = self.a[bk + self.u_col[e] as usize];
            }
            let bound = pabs / REFACTOR_THRESHOLD;
            for e in self.l_ptr[k]..self.l_ptr[k + 1] {
                let base = self.l_base[e] as usize;
                let x = self.a[base + ck];
                if x == T::default() {
                    continue;
                }
                ok &= x.abs1() <= bound;
                let l = x * inv;
                self.a[base + ck] = l;
                let row = &mut self.a[base..base + n];
                for (&c, &u) in self.u_col[u0..u1].iter().zip(&self.ucache[..u1 - u0]) {
                    // SAFETY: `u_col` holds columns below n (`symbolic`)
                    let v = unsafe { row.get_unchecked_mut(c as usize) };
                    *v = *v - l * u;
                }
            }
        }
        if ok {
            Factored::Ok
        } else {
            Factored::Reorder
        }
    }

    /// Threshold partial pivoting on a dense copy in the minimum degree column order: the row of
    /// every pivot. `false`: a zero column (singular to working precision) or a non-finite value.
    fn choose_pivots(&mut self) -> bool {
        let n = self.n;
        // b[i][k] = a[md[i]][md[k]]; `rowid[i]`: the caller's row now at place i
        for i in 0..n {
            for k in 0..n {
                self.scratch[i * n + k] = self.a[self.md[i] * n + self.md[k]];
            }
        }
        let b = &mut self.scratch;
        let rowid = &mut self.rowid;
        rowid.copy_from_slice(&self.md);
        for k in 0..n {
            let (mut p, mut best) = (k, 0.0f64);
            for i in k..n {
                let v = b[i * n + k].abs1();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if !(best > 0.0) || !best.is_finite() {
                return false;
            }
            if b[k * n + k].abs1() >= PIVOT_THRESHOLD * best {
                p = k;
            }
            if p != k {
                for j in 0..n {
                    b.swap(k * n + j, p * n + j);
                }
                rowid.swap(k, p);
            }
            let inv = T::from_real(1.0) / b[k * n + k];
            for i in k + 1..n {
                let x = b[i * n + k];
                if x != T::default() {
                    let l = x * inv;
                    for j in k + 1..n {
                        let u = b[k * n + j];
                        if u != T::default() {
                            b[i * n + j] = b[i * n + j] - l * u;
                        }
                    }
                }
            }
        }
        self.rows.copy_from_slice(rowid);
        self.cols.copy_from_slice(&self.md);
        true
    }

    /// The fill of the pivot sequence from the structural pattern: the lists.
    fn symbolic(&mut self) {
        let n = self.n;
        let s = &mut self.bits;
        permuted_pattern(&self.pattern, &self.rows, &self.cols, s);
        for v in [&mut self.l_pos, &mut self.l_base, &mut self.u_pos, &mut self.u_col, &mut self.fill] {
            v.clear();
        }
        for k in 0..n {
            self.fill.push((self.rows[k] * n + self.cols[k]) as u32);
            for j in k + 1..n {
                if s.get(k, j) {
                    self.u_pos.push(j as u32);
                    self.u_col.push(self.cols[j] as u32);
                    self.fill.push((self.rows[k] * n + self.cols[j]) as u32);
                }
            }
            self.u_ptr[k + 1] = self.u_pos.len();
            for i in k + 1..n {
                if s.get(i, k) {
                    self.l_pos.push(i as u32);
                    self.l_base.push((self.rows[i] * n) as u32);
                    self.fill.push((self.rows[i] * n + self.cols[k]) as u32);
                    // row i takes row k's pattern right of k (its own left part is already in)
                    s.or_row(i, k);
                }
            }
            self.l_ptr[k + 1] = self.l_pos.len();
        }
    }

    /// Solve `A x = b` in place with the factors.
    pub fn solve(&mut self, x: &mut [T]) {
        let n = self.n;
        let w = &mut self.work;
        for k in 0..n {
            w[k] = x[self.rows[k]];
        }
        for k in 0..n {
            let wk = w[k];
            if wk != T::default() {
                let ck = self.cols[k];
                for e in self.l_ptr[k]..self.l_ptr[k + 1] {
                    // SAFETY: `symbolic` makes every place below n and every base + column below n^2
                    unsafe {
                        let i = *self.l_pos.get_unchecked(e) as usize;
                        let l = *self.a.get_unchecked(*self.l_base.get_unchecked(e) as usize + ck);
                        *w.get_unchecked_mut(i) = *w.get_unchecked(i) - l * wk;
                    }
                }
            }
        }
        for k in (0..n).rev() {
            let bk = self.rows[k] * n;
            let mut s = w[k];
            for e in self.u_ptr[k]..self.u_ptr[k + 1] {
                // SAFETY: as above
                unsafe {
                    s = s - *self.a.get_unchecked(bk + *self.u_col.get_unchecked(e) as usize) * *w.get_unchecked(*self.u_pos.get_unchecked(e) as usize);
                }
            }
            w[k] = s * self.dinv[k];
        }
        for k in 0..n {
            x[self.cols[k]] = w[k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::band_lu::C64;

    pub(super) struct Lcg(pub u64);
    impl Lcg {
        pub(super) fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        }
    }

    /// A saddle-point pattern `[H, A^T; A, 0]`: `H` blocks of 7 (the last two of 3) coupled by
    /// two "springs" through block 1, `A` rows on two blocks each, as A05's.
    pub(super) fn saddle_pattern(n: usize, m: usize) -> Vec<(usize, usize)> {
        let blocks = [(0, 7), (7, 14), (14, 21), (21, 24), (24, 31), (31, 34)];
        assert_eq!(n, 34);
        let mut e = Vec::new();
        for &(a, b) in &blocks {
            for i in a..b {
                for j in a..b {
                    e.push((i, j));
                }
            }
        }
        for other in [2usize, 4] {
            let (a, b) = blocks[other];
            for i in (7..14).chain(a..b) {
                for j in (7..14).chain(a..b) {
                    e.push((i, j));
                }
            }
        }
        for r in 0..m {
            let (a, b) = blocks[r % 6];
            let (c, d) = blocks[(r / 6 + r % 6 + 1) % 6];
            for j in (a..b).chain(c..d) {
                e.push((n + r, j));
                e.push((j, n + r));
            }
        }
        e
    }

    fn fill_values<T: Scalar>(lu: &mut StaticLu<T>, pat: &[(usize, usize)], rng: &mut Lcg, make: impl Fn(f64, f64) -> T, n: usize) -> Vec<T> {
        let size = lu.n();
        let mut dense = vec![T::default(); size * size];
        lu.clear();
        for &(i, j) in pat {
            if i < n && j < n {
                let v = make(rng.next() + if i == j { 3.0 } else { 0.0 }, rng.next());
                dense[i * size + j] = v;
            } else if dense[i * size + j] == T::default() {
                let v = make(1.0 + rng.next(), 0.0);
                dense[i * size + j] = v;
                dense[j * size + i] = v;
            }
        }
        let idx: Vec<usize> = (0..size * size).collect();
        let vals = lu.values_mut();
        for &p in &idx {
            vals[p] = dense[p];
        }
        dense
    }

    fn residual<T: Scalar>(dense: &[T], size: usize, x: &[T], b: &[T]) -> f64 {
        (0..size)
            .map(|i| {
                let mut s = -b[i];
                for j in 0..size {
                    s = s + dense[i * size + j] * x[j];
                }
                s.abs1()
            })
            .fold(0.0, f64::max)
    }

    fn check<T: Scalar>(make: impl Fn(f64, f64) -> T + Copy) {
        let (n, m) = (34, 30);
        let size = n + m;
        let pat = saddle_pattern(n, m);
        let order = Ordering::new(size, pat.iter().copied());
        let flops = order.estimated_flops();
        assert!(flops * 4 < (size * size * size / 3) as u64, "{flops}");
        let mut lu = StaticLu::<T>::with_ordering(order);
        let mut rng = Lcg(11);
        // several matrices on one pattern: the first chooses the pivots, the next ones reuse
        // them or ask for new ones; every solve is exact to rounding
        let mut reorders = 0;
        for _ in 0..6 {
            let dense = fill_values(&mut lu, &pat, &mut rng, make, n);
            let mut r = lu.factor();
            if r == Factored::Reorder {
                reorders += 1;
                fill_values(&mut lu, &pat, &mut Lcg(0), make, n);
                // the same values again
                let vals = lu.values_mut();
                vals.copy_from_slice(&dense);
                r = lu.factor();
            }
            assert_eq!(r, Factored::Ok);
            let b: Vec<T> = (0..size).map(|i| make((i as f64 + 1.0).sin(), (i as f64).cos())).collect();
            let mut x = b.clone();
            lu.solve(&mut x);
            let scale = x.iter().fold(0.0f64, |s, v| s.max(v.abs1()));
            assert!(residual(&dense, size, &x, &b) < 1e-11 * scale.max(1.0), "residual {}", residual(&dense, size, &x, &b));
        }
        assert!(reorders < 6);
    }

    #[test]
    fn the_kept_pivots_solve_saddle_point_systems_real_and_complex() {
        check(|re, _| re);
        check(|re, im| C64::new(re, 0.3 * im));
    }

    #[test]
    fn a_singular_matrix_is_refused() {
        // two equal rows
        let pat: Vec<(usize, usize)> = (0..3).flat_map(|i| (0..3).map(move |j| (i, j))).collect();
        let mut lu = StaticLu::<f64>::new(3, pat.into_iter());
        lu.clear();
        lu.values_mut().copy_from_slice(&[1.0, 2.0, 3.0, 1.0, 2.0, 3.0, 0.0, 1.0, 1.0]);
        assert_eq!(lu.factor(), Factored::Singular);
        lu.clear();
        lu.values_mut().copy_from_slice(&[1.0, 2.0, 3.0, 1.0, 2.5, 3.0, 0.0, 1.0, 1.0]);
        assert_eq!(lu.factor(), Factored::Ok);
        let mut x = [1.0, 2.0, 3.0];
        lu.solve(&mut x);
        let r = [x[0] + 2.0 * x[1] + 3.0 * x[2] - 1.0, x[0] + 2.5 * x[1] + 3.0 * x[2] - 2.0, x[1] + x[2] - 3.0];
        assert!(r.iter().all(|v| v.abs() < 1e-12), "{r:?}");
        // a NaN
        lu.clear();
        lu.values_mut().copy_from_slice(&[f64::NAN, 2.0, 3.0, 1.0, 2.5, 3.0, 0.0, 1.0, 1.0]);
        assert_ne!(lu.factor(), Factored::Ok);
    }
}

