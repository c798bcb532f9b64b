//! A symmetric positive definite matrix whose envelope is block tridiagonal with small blocks,
//! its `L D L^T` factor and selected inverse by fixed-size blocks, and the choice between it
//! and the generic envelope (`SpdProfile`, made once from the pattern).
//!
//! Storage. The rows are cut into consecutive blocks of at most `MAX_BLOCK` rows; block `k`
//! stores its diagonal block and the block that couples it to block `k - 1` as fixed `6 x 6`
//! arrays, and each block's kernels are instances for its size and its neighbours' (constants:
//! every loop unrolled, the block kept in registers), picked once at setup. The factor is the
//! envelope's (`linalg::envelope`) computed by blocks: for block `k`, `W = C L_{k-1}^-T` row by
//! row (the coupling block solved in place, `W = L_{k,k-1} D_{k-1}`), `L_{k,k-1} = W
//! D_{k-1}^-1`, the diagonal block less `W L_{k,k-1}^T`, then its own `L D L^T`. Every entry is
//! the envelope
//! recurrence `L_ij d_j = S_ij - sum_{k<j} L_ik d_k L_jk` evaluated in another order with
//! extra terms that are exact zeros (the entries of the blocks outside the envelope stay exact
//! zeros: `S_ij = 0` there and every product that would make them nonzero has a zero factor), so
//! the rounding bound of `linalg::envelope` holds unchanged, with the envelope's widest row `w`:
//! `L D L^T = S + E`, `|E| <= gamma_{w+2} |L| D |L|^T` (Higham, *Accuracy and Stability*,
//! Thm 9.3, which holds for any order of evaluation of the sums (Lemma 8.4), `U = D L^T`, one
//! rounding more for the pivot's reciprocal). The solve is the same triangular solves by blocks
//! (Thms 8.5 and 9.4 hold in any order too), and the selected inverse (Takahashi, Fagan and
//! Chen 1973: `Z_ij = delta_ij / d_j - sum_{k>j} L_kj Z_ki`, `i >= j`) stays inside the
//! blocks: the rows below a column are the rest of its block and the next block.

use super::envelope::EnvelopeCholesky;

/// The largest block `BlockLdl` is built for (larger ones stay on the envelope), and the
/// stored size of every block.
pub const MAX_BLOCK: usize = 6;
const P: usize = MAX_BLOCK;
type Blk = [[f64; P]; P];
type Col = [f64; P];

/// One block's kernels, for its size `S` and its neighbours' `R` (before) and `T` (after; 0
/// where there is none), chosen at setup.
#[derive(Clone, Copy)]
struct Kernels {
    factor: fn(&mut [Blk], &mut [Col], usize) -> bool,
    forward: fn(&[Blk], &mut [Col], usize),
    backward: fn(&[Blk], &[Col], &mut [Col], usize),
    selinv: fn(&[Blk], &[Col], &mut [Blk], usize) -> f64,
}

impl std::fmt::Debug for Kernels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Kernels")
    }
}

/// Block `k` (`S` rows, after a block of `R`): `W = C L_{k-1}^-T`, `L_{k,k-1} = W D_{k-1}^-1`,
/// the diagonal block less `W L_{k,k-1}^T`, then its `L D L^T`; `false` at a bad pivot.
fn factor_block<const S: usize, const R: usize>(blocks: &mut [Blk], inv: &mut [Col], k: usize) -> bool {
    let (before, rest) = blocks.split_at_mut(2 * k);
    let (a, c) = rest.split_at_mut(1);
    let a = &mut a[0];
    if R > 0 {
        let (lp, ip) = (&before[2 * k - 2], inv[k - 1]);
        let c = &mut c[0];
        for row in c.iter_mut().take(S) {
            for j in 1..R {
                let mut s = row[j];
                for m in 0..j {
                    s -= row[m] * lp[j][m];
                }
                row[j] = s;
            }
        }
        let w = *c;
        for row in c.iter_mut().take(S) {
            for j in 0..R {
                row[j] *= ip[j];
            }
        }
        for i in 0..S {
            for i2 in 0..=i {
                let mut s = 0.0;
                for j in 0..R {
                    s += w[i][j] * c[i2][j];
                }
                a[i][i2] -= s;
            }
        }
    }
    // the diagonal block's own L D L^T, right-looking
    let inv = &mut inv[k];
    let mut ok = true;
    for j in 0..S {
        let d = a[j][j];
        ok &= d > 0.0 && d.is_finite();
        let r = 1.0 / d;
        inv[j] = r;
        let u: Col = std::array::from_fn(|i| a[i][j]);
        for i in j + 1..S {
            a[i][j] = u[i] * r;
            for i2 in j + 1..=i {
                a[i][i2] -= a[i][j] * u[i2];
            }
        }
    }
    ok
}

/// Forward substitution with block `k`'s rows of the unit `L`.
fn forward_block<const S: usize, const R: usize>(blocks: &[Blk], xs: &mut [Col], k: usize) {
    let mut v = xs[k];
    if R > 0 {
        let (c, p) = (&blocks[2 * k + 1], xs[k - 1]);
        for i in 0..S {
            let mut s = 0.0;
            for j in 0..R {
                s += c[i][j] * p[j];
            }
            v[i] -= s;
        }
    }
    let l = &blocks[2 * k];
    for i in 1..S {
        let mut s = 0.0;
        for j in 0..i {
            s += l[i][j] * v[j];
        }
        v[i] -= s;
    }
    xs[k] = v;
}

/// `D^-1`, then backward substitution with block `k`'s columns of `L^T`.
fn backward_block<const S: usize, const T: usize>(blocks: &[Blk], inv: &[Col], xs: &mut [Col], k: usize) {
    let mut v = xs[k];
    for j in 0..S {
        v[j] *= inv[k][j];
    }
    if T > 0 {
        let (c, nv) = (&blocks[2 * k + 3], xs[k + 1]);
        for j in 0..S {
            let mut s = 0.0;
            for m in 0..T {
                s += c[m][j] * nv[m];
            }
            v[j] -= s;
        }
    }
    let l = &blocks[2 * k];
    for i in (1..S).rev() {
        for j in 0..i {
            v[j] -= l[i][j] * v[i];
        }
    }
    xs[k] = v;
}

/// The selected inverse's block `k` (its diagonal block, full, and the block of rows of
/// `k + 1`) by Takahashi's recurrence, columns from the last; returns its diagonal's sum. Each
/// entry's sum is split in its part through the next block, which does not depend on the other
/// columns (`G = Z_{k+1,k+1} L_{k+1,k}`, then `K = Z_{k+1,k}^T L_{k+1,k}`, all independent
/// products), and the short part inside the block, the only chain from column to column.
fn selinv_block<const S: usize, const T: usize>(blocks: &[Blk], inv: &[Col], z: &mut [Blk], k: usize) -> f64 {
    let l = &blocks[2 * k];
    let (lo, hi) = z.split_at_mut(2 * k + 2);
    let zk = &mut lo[2 * k];
    let mut kk = [[0.0; P]; P];
    if T > 0 {
        let ln = &blocks[2 * k + 3];
        let (a, b) = hi.split_at_mut(1);
        let (zn, zs) = (&a[0], &mut b[0]);
        // Z_{k+1,k} = -(G + Z_{k+1,k} strictly-lower part of L_kk), columns from the last
        for m in 0..T {
            for j in 0..S {
                let mut g = 0.0;
                for m2 in 0..T {
                    g += ln[m2][j] * zn[m][m2];
                }
                zs[m][j] = g;
            }
        }
        for j in (0..S).rev() {
            for m in 0..T {
                let mut s = zs[m][j];
                for i in j + 1..S {
                    s += l[i][j] * zs[m][i];
                }
                zs[m][j] = -s;
            }
        }
        for i in 0..S {
            for j in 0..=i {
                let mut s = 0.0;
                for m in 0..T {
                    s += ln[m][j] * zs[m][i];
                }
                kk[i][j] = s;
            }
        }
    }
    for j in (0..S).rev() {
        // the rows i > j of this block
        for i in j + 1..S {
            let mut s = kk[i][j];
            for i2 in j + 1..S {
                s += l[i2][j] * zk[i2][i];
            }
            zk[i][j] = -s;
            zk[j][i] = -s;
        }
        let mut t = kk[j][j];
        for i in j + 1..S {
            t += l[i][j] * zk[i][j];
        }
        zk[j][j] = inv[k][j] - t;
    }
    (0..S).map(|j| zk[j][j]).sum()
}

macro_rules! by_second {
    ($f:ident, $S:literal, $r:expr) => {
        match $r {
            0 => $f::<$S, 0>,
            1 => $f::<$S, 1>,
            2 => $f::<$S, 2>,
            3 => $f::<$S, 3>,
            4 => $f::<$S, 4>,
            5 => $f::<$S, 5>,
            _ => $f::<$S, 6>,
        }
    };
}

macro_rules! pick {
    ($f:ident, $s:expr, $r:expr) => {
        match $s {
            1 => by_second!($f, 1, $r),
            2 => by_second!($f, 2, $r),
            3 => by_second!($f, 3, $r),
            4 => by_second!($f, 4, $r),
            5 => by_second!($f, 5, $r),
            _ => by_second!($f, 6, $r),
        }
    };
}

/// `S = L D L^T` on block-tridiagonal storage, blocks of at most `MAX_BLOCK` rows.
#[derive(Debug, Clone)]
pub struct BlockLdl {
    /// Rows of the matrix.
    pub n: usize,
    /// Block of each row and its place in it.
    blk: Vec<(usize, usize)>,
    /// Rows in each block.
    size: Vec<usize>,
    kernels: Vec<Kernels>,
    /// `2 k`: diagonal block `k` (lower triangle; `L` below and `D` on the diagonal after
    /// `factor_in_place`), `2 k + 1`: the block of rows of `k`, columns of `k - 1`.
    blocks: Vec<Blk>,
    /// The selected inverse in the same layout (diagonal blocks stored full).
    z: Vec<Blk>,
    /// `1 / d` per block.
    inv: Vec<Col>,
    /// Scratch of `solve`.
    xs: Vec<Col>,
    /// The envelope's widest row (the rounding bound's `w`, module docs).
    pub width: usize,
}

impl BlockLdl {
    /// Blocks starting at `starts` (ascending, from 0, each at most `MAX_BLOCK` rows; the last
    /// ends at `n`) for a matrix whose envelope is `first`.
    pub fn new(first: &[usize], starts: &[usize]) -> Self {
        let n = first.len();
        let nb = starts.len();
        let mut blk = Vec::with_capacity(n);
        let mut size = Vec::with_capacity(nb);
        for (k, &s) in starts.iter().enumerate() {
            let e = starts.get(k + 1).copied().unwrap_or(n);
            assert!(e > s && e - s <= P, "block_tridiag: block {k} has {} rows", e - s);
            size.push(e - s);
            blk.extend((0..e - s).map(|l| (k, l)));
        }
        assert_eq!(blk.len(), n);
        let kernels = (0..nb)
            .map(|k| {
                let (s, r, t) = (size[k], if k > 0 { size[k - 1] } else { 0 }, size.get(k + 1).copied().unwrap_or(0));
                Kernels { factor: pick!(factor_block, s, r), forward: pick!(forward_block, s, r), backward: pick!(backward_block, s, t), selinv: pick!(selinv_block, s, t) }
            })
            .collect();
        let width = (0..n).map(|i| i - first[i] + 1).max().unwrap_or(0);
        let zero = [[0.0; P]; P];
        BlockLdl { n, blk, size, kernels, blocks: vec![zero; 2 * nb], z: vec![zero; 2 * nb], inv: vec![[0.0; P]; nb], xs: vec![[0.0; P]; nb], width }
    }

    /// Zero matrix (the rows of each block).
    pub fn clear(&mut self) {
        for (k, &s) in self.size.iter().enumerate() {
            for b in &mut self.blocks[2 * k..2 * k + 2] {
                for row in &mut b[..s] {
                    *row = [0.0; P];
                }
            }
        }
    }

    /// Position of entry `(i, j)`, `j <= i`, in `data_mut()` and `z()` (`i`'s block or the one
    /// before it).
    #[inline]
    pub fn index(&self, i: usize, j: usize) -> usize {
        let ((bi, li), (bj, lj)) = (self.blk[i], self.blk[j]);
        debug_assert!(j <= i && (bi == bj || bi == bj + 1), "entry ({i}, {j}) outside the blocks");
        ((2 * bi + (bi - bj)) * P + li) * P + lj
    }

    /// Stored entries (with the unused corners and the upper triangles).
    pub fn len(&self) -> usize {
        self.blocks.len() * P * P
    }

    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    pub fn data_mut(&mut self) -> &mut [f64] {
        self.blocks.as_flattened_mut().as_flattened_mut()
    }

    pub fn z(&self) -> &[f64] {
        self.z.as_flattened().as_flattened()
    }

    /// The diagonal entry of row `i`.
    #[inline]
    pub fn diag(&self, i: usize) -> f64 {
        let (k, l) = self.blk[i];
        self.blocks[2 * k][l][l]
    }

    /// `S = L D L^T` in place; `false` at a pivot that is not positive and finite.
    pub fn factor_in_place(&mut self) -> bool {
        for (k, kern) in self.kernels.iter().enumerate() {
            if !(kern.factor)(&mut self.blocks, &mut self.inv, k) {
                return false;
            }
        }
        true
    }

    /// `x <- S^-1 x` (`x` the `n` rows) with the factor of `factor_in_place`.
    pub fn solve(&mut self, x: &mut [f64]) {
        let xs = &mut self.xs;
        for (&(k, l), &v) in self.blk.iter().zip(x.iter()) {
            xs[k][l] = v;
        }
        for (k, kern) in self.kernels.iter().enumerate() {
            (kern.forward)(&self.blocks, xs, k);
        }
        for (k, kern) in self.kernels.iter().enumerate().rev() {
            (kern.backward)(&self.blocks, &self.inv, xs, k);
        }
        for (&(k, l), v) in self.blk.iter().zip(x.iter_mut()) {
            *v = xs[k][l];
        }
    }

    /// The selected inverse on the blocks (`z()`); returns `trace(S^-1)`.
    pub fn selected_inverse_trace(&mut self) -> f64 {
        let mut trace = 0.0;
        for (k, kern) in self.kernels.iter().enumerate().rev() {
            trace += (kern.selinv)(&self.blocks, &self.inv, &mut self.z, k);
        }
        trace
    }
}

/// The shortest cut of rows `0..n` into consecutive blocks that makes the envelope `first`
/// block tridiagonal (every row's envelope starts in its block or the one before), with the
/// fewest rows in the largest block, if that is at most `bmax`: the block starts.
pub fn block_starts(first: &[usize], bmax: usize) -> Option<Vec<usize>> {
    let n = first.len();
    if n == 0 {
        return None;
    }
    // can rows c.. be cut into blocks of at most b rows when block [c, ..) follows one at p
    fn cut(first: &[usize], b: usize, p: usize, c: usize, memo: &mut Vec<Option<bool>>, out: &mut Vec<usize>) -> bool {
        let n = first.len();
        if c == n {
            return true;
        }
        if let Some(r) = memo[p * n + c] {
            if !r {
                return false;
            }
        }
        for e in c + 1..=(c + b).min(n) {
            if first[e - 1] < p {
                break;
            }
            out.push(c);
            if cut(first, b, c, e, memo, out) {
                return true;
            }
            out.pop();
        }
        memo[p * n + c] = Some(false);
        false
    }
    (1..=bmax.min(n)).find_map(|b| {
        let (mut memo, mut out) = (vec![None; n * n], Vec::new());
        cut(first, b, 0, 0, &mut memo, &mut out).then_some(out)
    })
}

/// The factor of a symmetric positive definite profile, chosen once from its pattern: by blocks
/// where the envelope is block tridiagonal with blocks of at most `MAX_BLOCK` rows, the generic
/// envelope otherwise.
#[derive(Debug, Clone)]
pub enum SpdProfile {
    Envelope(EnvelopeCholesky, Vec<f64>),
    Blocks(BlockLdl),
}

macro_rules! each {
    ($s:expr, $f:ident => $e:expr, $env:ident, $z:ident => $ee:expr) => {
        match $s {
            SpdProfile::Envelope($env, $z) => $ee,
            SpdProfile::Blocks($f) => $e,
        }
    };
}

impl SpdProfile {
    /// The profile of envelope `first`; `blocks: false` keeps the generic envelope.
    pub fn new(first: Vec<usize>, blocks: bool) -> SpdProfile {
        let starts = if blocks { block_starts(&first, MAX_BLOCK) } else { None };
        let Some(starts) = starts else {
            let env = EnvelopeCholesky::new(first);
            let len = env.len();
            return SpdProfile::Envelope(env, vec![0.0; len]);
        };
        SpdProfile::Blocks(BlockLdl::new(&first, &starts))
    }

    pub fn is_blocks(&self) -> bool {
        !matches!(self, SpdProfile::Envelope(..))
    }

    #[inline]
    pub fn index(&self, i: usize, j: usize) -> usize {
        each!(self, f => f.index(i, j), e, _z => e.index(i, j))
    }

    pub fn len(&self) -> usize {
        each!(self, f => f.len(), e, _z => e.len())
    }

    pub fn is_empty(&self) -> bool {
        each!(self, f => f.is_empty(), e, _z => e.is_empty())
    }

    pub fn width(&self) -> usize {
        each!(self, f => f.width, e, _z => e.width)
    }

    #[inline]
    pub fn diag(&self, i: usize) -> f64 {
        each!(self, f => f.diag(i), e, _z => e.diag(i))
    }

    /// Zero matrix, ready for its entries through `data_mut()[index(i, j)]`.
    pub fn clear(&mut self) {
        each!(self, f => f.clear(), e, _z => e.data.fill(0.0))
    }

    pub fn data_mut(&mut self) -> &mut [f64] {
        each!(self, f => f.data_mut(), e, _z => &mut e.data)
    }

    pub fn factor_in_place(&mut self) -> bool {
        each!(self, f => f.factor_in_place(), e, _z => e.factor_in_place())
    }

    pub fn solve(&mut self, x: &mut [f64]) {
        each!(self, f => f.solve(x), e, _z => e.solve(x))
    }

    /// The selected inverse (read with `z()` at `index(i, j)`), returning `trace(S^-1)`.
    pub fn selected_inverse_trace(&mut self) -> f64 {
        each!(self, f => f.selected_inverse_trace(), e, z => e.selected_inverse_trace(z))
    }

    pub fn z(&self) -> &[f64] {
        each!(self, f => f.z(), _e, z => z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An envelope that is block tridiagonal but not block aligned (rows whose envelope starts
    /// inside the block before): the block factor finds its blocks, and its solve, selected
    /// inverse and trace equal the envelope's to rounding; a matrix that is not positive
    /// definite is refused; a pattern with a block above `MAX_BLOCK` stays on the envelope.
    #[test]
    fn blocks_match_the_envelope() {
        let n = 17;
        let first: Vec<usize> = (0..n).map(|i: usize| [0, 0, 0, 0, 1, 3, 4, 5, 6, 6, 9, 9, 10, 11, 12, 12, 13][i]).collect();
        let starts = block_starts(&first, MAX_BLOCK).expect("block tridiagonal");
        assert_eq!(starts, vec![0, 1, 4, 6, 8, 10, 12, 14]);
        let mut blk = SpdProfile::new(first.clone(), true);
        let mut env = SpdProfile::new(first.clone(), false);
        assert!(blk.is_blocks() && !env.is_blocks());
        assert_eq!(blk.width(), env.width());
        for f in [&mut blk, &mut env] {
            f.clear();
            for i in 0..n {
                for j in first[i]..=i {
                    let v = if i == j { 6.0 + i as f64 * 0.1 } else { ((i * 7 + j * 3) as f64).sin() * 0.8 };
                    let k = f.index(i, j);
                    f.data_mut()[k] = v;
                }
            }
            assert!(f.factor_in_place());
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let (mut a, mut b) = (x.clone(), x.clone());
        blk.solve(&mut a);
        env.solve(&mut b);
        for i in 0..n {
            assert!((a[i] - b[i]).abs() < 1e-14 * b[i].abs().max(1.0), "x[{i}] {} vs {}", a[i], b[i]);
        }
        let (ta, tb) = (blk.selected_inverse_trace(), env.selected_inverse_trace());
        assert!((ta - tb).abs() < 1e-14 * tb);
        for i in 0..n {
            for j in first[i]..=i {
                let (za, zb) = (blk.z()[blk.index(i, j)], env.z()[env.index(i, j)]);
                assert!((za - zb).abs() < 1e-14, "Z({i}, {j}) {za} vs {zb}");
            }
        }
        let mut bad = SpdProfile::new(vec![0, 0, 2], true);
        assert!(bad.is_blocks());
        bad.clear();
        for (i, j, v) in [(0, 0, 1.0), (1, 0, 2.0), (1, 1, 1.0), (2, 2, 1.0)] {
            let k = bad.index(i, j);
            bad.data_mut()[k] = v;
        }
        assert!(!bad.factor_in_place());
        // 13 rows all coupled: two blocks, one of at least 7 rows
        assert!(!SpdProfile::new(vec![0; 13], true).is_blocks());
    }
}
