//! The sparse path of the UK correction: a banded Cholesky factor of the Gram matrix
//! `S = B B^T = A M^-1 A^T` with a certificate of full rank, for mechanisms whose constraint
//! rows grow with the bodies (chains, ropes, tracks, lattices).
//!
//! Structure. Every constraint row touches the coordinates of at most two bodies (its
//! markers'), and `F` is block diagonal by body, so `B^T = F^-1 A^T` keeps the block pattern
//! of `A^T`: row `i` of `B` is a few body segments. `S_ij` is nonzero only when rows `i` and
//! `j` share a body. The symbolic analysis (`SparseUk::new`, once per model) lists the
//! segments, orders the rows by reverse Cuthill-McKee on the "shares a body" graph so that
//! `S` is banded with a small half-bandwidth `hb` (3 for a chain of revolutes), and lists the
//! segment pairs that make each band entry. Per call (`factor`, allocation free):
//! `B^T` segments (`F_b^-1` on each), `S` in band storage, the in-place band Cholesky
//! `S = L L^T` (O(m hb^2)), and the trace of `S^-1` by the Takahashi recurrence of the
//! selected inverse inside the band (O(m hb^2), the band is closed under it).
//!
//! Certificate (the rank decision stays as trustworthy as the dense certified QR, which uses
//! the same quantity: there `|R^-1|_F^2 = trace((B B^T)^-1)`). With `sigma_i` the singular
//! values of `B`, `sigma_min^2 = lambda_min(S) >= 1 / trace(S^-1)` and
//! `sigma_max^2 <= trace(S)`. The computed factor is the exact factor of `S + E` with
//! `|E|_2 <= delta = 2 (2 hb + 1) (gamma_{hb+2} + gamma_{l}) max_i S_ii` (band Cholesky,
//! Higham, *Accuracy and Stability*, Thm 10.3, inner products of at most `hb + 1` terms; plus
//! the assembly of `S` from dot products of length at most `l`; `gamma_k = k eps / (1 - k eps)`;
//! `|(|L||L^T|)_ij| <= sqrt(S_ii S_jj)` by Cauchy-Schwarz). The factorization is accepted when
//! `lower = 1 / (2 trace(S^-1)) - delta > tol^2`, `tol = max(atol, rcond sqrt(trace S))` (the
//! factor 2 covers the rounding of the computed trace, whose relative error is
//! O(hb cond(S) eps) and at most ~1/(4 hb) wherever the test can pass); then every singular
//! value exceeds the pseudoinverse tolerance and rank = m is certain. Otherwise (redundant or
//! nearly dependent rows, or a non-positive pivot) `uk::factor_constraints` falls back to the
//! dense rank-revealing path, which reports the rank. Squaring the condition number is what
//! the Gram matrix costs; the certificate refuses exactly the cases where that matters
//! (`cond(B) >~ 1 / sqrt(hb^2 eps)`), and one step of refinement with `B` itself (not `S`)
//! brings the solution's error back to O(cond(B) eps) on the accepted cases.
//!
//! Rejected: faer's sparse Cholesky/LDLT (supernodal, AMD ordering; the better choice for
//! wide trees) gives no selected inverse, so its full-rank certificate would be a pivot-ratio
//! heuristic, not a bound; faer's sparse QR of `B^T` avoids squaring but `1/|R^-1|_F` needs
//! `R^-1` (O(m^2) and dense). A chain, rope or track has a narrow band after RCM; a lattice of
//! width `w` has `hb ~ 2 w`, and `data::prefer_sparse` keeps the dense path where the band is
//! too wide to pay.

use crate::body::BodyData;
use crate::constraint::jac::SegJac;
use super::settings::{RankInfo, RankTolerance};
use crate::linalg::banded::{count_eigenvalues_below, BandedCholesky};
use crate::model::Model;

/// One body segment of one row of `A` (and of `B`).
#[derive(Debug, Clone, Copy)]
struct Seg {
    body: usize,
    /// First coordinate of the body in `q`.
    col: usize,
    len: usize,
    /// Offset of the segment's values in `vals`.
    val: usize,
}

/// The first part of the symbolic analysis: segments of `A`'s rows, the rows each body enters,
/// the RCM order and the half-bandwidth; enough for the automatic choice's estimate (`flops`)
/// before any workspace is built (`data::Data::build`).
pub struct RowAnalysis {
    seg_ptr: Vec<usize>,
    segs: Vec<Seg>,
    /// `(row, segment)` of every row a body enters.
    rows_of_body: Vec<Vec<(usize, usize)>>,
    perm: Vec<usize>,
    hb: usize,
    /// Nonzeros of `A` under the segment pattern.
    val: usize,
}

impl RowAnalysis {
    pub fn new(model: &Model) -> RowAnalysis {
        let m = model.m;
        let mut seg_ptr = vec![0];
        let mut segs = Vec::new();
        let mut val = 0;
        let mut rows_of_body: Vec<Vec<(usize, usize)>> = vec![Vec::new(); model.bodies.len()];
        for c in &model.constraints {
            let mut bodies: Vec<usize> = c.bodies().into_iter().flatten().collect();
            bodies.sort_unstable();
            bodies.dedup();
            for r in c.row..c.row + c.rows() {
                for &b in &bodies {
                    let body = &model.bodies[b];
                    rows_of_body[b].push((r, segs.len()));
                    segs.push(Seg { body: b, col: body.offset, len: body.n_coords, val });
                    val += body.n_coords;
                }
                seg_ptr.push(segs.len());
            }
        }
        let perm = rcm(m, &rows_of_body);
        // half-bandwidth
        let mut hb = 0;
        for rows in &rows_of_body {
            for &(ra, _) in rows {
                for &(rb, _) in rows {
                    hb = hb.max(perm[ra].abs_diff(perm[rb]));
                }
            }
        }
        RowAnalysis { seg_ptr, segs, rows_of_body, perm, hb, val }
    }

    /// Rough flop count of one `factor` + `correct` (for the auto choice): the dot products of
    /// the band pairs, the band Cholesky and selected inverse, the segments.
    pub fn flops(&self) -> f64 {
        let w = (self.hb + 1) as f64;
        let mut dots = 0usize;
        for rows in &self.rows_of_body {
            for &(ra, sa) in rows {
                dots += self.segs[sa].len * rows.iter().filter(|&&(rb, _)| self.perm[rb] <= self.perm[ra]).count();
            }
        }
        2.0 * dots as f64 + 2.0 * self.perm.len() as f64 * w * w + 8.0 * self.val as f64
    }
}

/// Symbolic analysis and numeric workspace of the sparse UK path (sized once per model).
#[derive(Debug, Clone)]
pub struct SparseUk {
    m: usize,
    n: usize,
    /// Half-bandwidth of `S` in the RCM order.
    pub hb: usize,
    /// `perm[i]`: position of row `i` in the band order.
    perm: Vec<usize>,
    seg_ptr: Vec<usize>,
    segs: Vec<Seg>,
    /// `B^T` values, segment by segment.
    vals: Vec<f64>,
    /// `(band index, value offset a, value offset b, length)`: `S[band] += vals_a . vals_b`.
    pairs: Vec<(usize, usize, usize, usize)>,
    /// Longest dot product that makes one entry of `S`.
    max_dot: usize,
    /// `S` (its lower band), then its factor `L` (`factor_in_place`).
    chol: BandedCholesky,
    /// Selected inverse `Z = S^-1` inside the band (the layout of `L`).
    z: Vec<f64>,
    /// Work vectors: m long (band order) and n long.
    x: Vec<f64>,
    dx: Vec<f64>,
    wn: Vec<f64>,
    /// `trace(S)`, `trace(S^-1)` of the last `factor`.
    pub trace_s: f64,
    pub trace_sinv: f64,
}

impl SparseUk {
    /// Symbolic analysis: segments of `A`'s rows, RCM order, band pairs.
    pub fn new(model: &Model) -> SparseUk {
        SparseUk::from_rows(model, RowAnalysis::new(model))
    }

    /// The rest of the analysis (the band pairs) and the workspace, on the rows' analysis.
    pub fn from_rows(model: &Model, rows: RowAnalysis) -> SparseUk {
        let (n, m) = (model.n, model.m);
        let RowAnalysis { seg_ptr, segs, rows_of_body, perm, hb, val } = rows;
        let w = hb + 1;
        let mut pairs = Vec::new();
        let mut max_dot = vec![0usize; m * w];
        for rows in &rows_of_body {
            for &(ra, sa) in rows {
                for &(rb, sb) in rows {
                    let (pa, pb) = (perm[ra], perm[rb]);
                    if pb > pa {
                        continue;
                    }
                    let idx = pa * w + (pb + hb - pa);
                    let s = segs[sa];
                    pairs.push((idx, s.val, segs[sb].val, s.len));
                    max_dot[idx] += s.len;
                }
            }
        }
        // rows with no body at all (ground to ground cannot be built, but stay safe): S_ii = 0
        pairs.sort_unstable_by_key(|p| p.0);
        SparseUk {
            m,
            n,
            hb,
            perm,
            seg_ptr,
            segs,
            vals: vec![0.0; val],
            pairs,
            max_dot: max_dot.into_iter().max().unwrap_or(0),
            chol: BandedCholesky::zeros(m, hb),
            z: vec![0.0; m * w],
            x: vec![0.0; m],
            dx: vec![0.0; m],
            wn: vec![0.0; n],
            trace_s: 0.0,
            trace_sinv: 0.0,
        }
    }

    /// Nonzeros of `A` (= of `B`) under the segment pattern.
    pub fn nnz(&self) -> usize {
        self.vals.len()
    }

    /// Heap bytes of this workspace.
    pub fn bytes(model: &Model) -> u64 {
        // segments, values, band, z and pairs: a generous bound without building it
        let nnz: u64 = model.constraints.iter().map(|c| c.rows() as u64 * c.bodies().into_iter().flatten().map(|b| model.bodies[b].n_coords as u64).sum::<u64>()).sum();
        8 * (2 * nnz + 16 * model.m as u64 + model.n as u64) + 32 * nnz
    }

    /// `B^T`, `S`, its band Cholesky factor and the full-rank certificate. `Some(info)` when
    /// rank = m is certified (the factorization is then ready for `correct`), `None` otherwise.
    pub fn factor(&mut self, model: &Model, bodies: &[BodyData], ajac: &SegJac, tol: &RankTolerance) -> Option<RankInfo> {
        let (n, m, hb) = (self.n, self.m, self.hb);
        let w = hb + 1;
        // B^T segments: the segment form of A has the same layout (rows in order, each row's
        // bodies in increasing order, one after the other); then F_b^-1 on each segment
        debug_assert_eq!(self.vals.len(), ajac.vals.len());
        self.vals.copy_from_slice(&ajac.vals);
        for s in &self.segs {
            model.bodies[s.body].finv(&bodies[s.body], &mut self.vals[s.val..s.val + s.len]);
        }
        // S = B B^T in band storage
        gram(&self.pairs, &self.vals, &mut self.chol.data);
        let (mut trace_s, mut max_d) = (0.0f64, 0.0f64);
        for p in 0..m {
            let d = self.chol.data[p * w + hb];
            trace_s += d;
            max_d = max_d.max(d);
        }
        self.trace_s = trace_s;
        self.trace_sinv = f64::INFINITY;
        if !trace_s.is_finite() || !self.chol.factor_in_place() {
            return None;
        }
        let trace_sinv = self.chol.selected_inverse_trace(&mut self.z);
        self.trace_sinv = trace_sinv;
        let gamma = |k: usize| {
            let ke = k as f64 * f64::EPSILON;
            ke / (1.0 - ke)
        };
        let delta = 2.0 * (2 * hb + 1) as f64 * (gamma(hb + 2) + gamma(self.max_dot)) * max_d;
        let lower = 0.5 / trace_sinv - delta;
        let sigma_max = trace_s.sqrt();
        let rcond = tol.rcond.unwrap_or((n.max(m) as f64) * f64::EPSILON);
        let t = tol.atol.max(rcond * sigma_max);
        if lower.is_finite() && lower > 0.0 && lower > t * t {
            Some(RankInfo { rank: m, sigma_max, sigma_min_kept: lower.sqrt(), sigma_max_dropped: 0.0, tolerance: t, exact: false })
        } else {
            None
        }
    }

    /// After a `factor` whose Cholesky succeeded (`S` numerically positive definite, certified
    /// or not): estimates `(sigma_min, sigma_max)` of `B` from `1 / sqrt(trace(S^-1))` (within
    /// a factor `sqrt(m)` of `sigma_min`) and `sqrt(trace(S))` (within `sqrt(m)` of
    /// `sigma_max`). `None` when the Cholesky failed. For diagnostics (the singular-passage
    /// monitor), not for rank decisions.
    pub fn conditioning_estimate(&self) -> Option<(f64, f64)> {
        (self.trace_sinv.is_finite() && self.trace_sinv > 0.0).then(|| (1.0 / self.trace_sinv.sqrt(), self.trace_s.sqrt()))
    }

    /// How many eigenvalues of `S = B B^T` (squared singular values of `B`) are below `tau2`:
    /// the negative pivots of the band `LDL^T` of `S - tau2 I` (Sylvester's law of inertia; no
    /// pivoting: a diagnostic). From the `B^T` values of the last `factor`; leaves its
    /// factorization intact (scratch: the selected-inverse band and a work vector).
    pub fn count_below(&mut self, tau2: f64) -> usize {
        gram(&self.pairs, &self.vals, &mut self.z);
        count_eigenvalues_below(&mut self.z, &mut self.dx, self.m, self.hb, tau2)
    }

    /// `(B v)_i` for the row `i` (segments of `B^T`).
    #[inline]
    fn b_row_dot(&self, i: usize, v: &[f64]) -> f64 {
        let mut s = 0.0;
        for sg in &self.segs[self.seg_ptr[i]..self.seg_ptr[i + 1]] {
            s += self.vals[sg.val..sg.val + sg.len].iter().zip(&v[sg.col..sg.col + sg.len]).map(|(a, b)| a * b).sum::<f64>();
        }
        s
    }

    /// The correction with the current factorization, `y = F^-1 Q` on entry:
    /// `r = b - A a = b - B y` (into `residual`),
    /// `x = S^-1 r` plus one refinement step with `B` (`x += S^-1 (r - B B^T x)`),
    /// `y += B^T x`, `lambda = -x`.
    pub fn correct(&mut self, gamma: &[f64], residual: &mut [f64], y: &mut [f64], lambda: &mut [f64]) {
        let m = self.m;
        // A a = B F^T a = B y with y = F^-1 Q (a = F^-T y): no pass over the rows of A
        for i in 0..m {
            residual[i] = gamma[i] - self.b_row_dot(i, y);
            self.x[self.perm[i]] = residual[i];
        }
        self.chol.solve(&mut self.x);
        // refinement: r - B (B^T x)
        self.wn.fill(0.0);
        for i in 0..m {
            let xi = self.x[self.perm[i]];
            for sg in &self.segs[self.seg_ptr[i]..self.seg_ptr[i + 1]] {
                for (wv, b) in self.wn[sg.col..sg.col + sg.len].iter_mut().zip(&self.vals[sg.val..sg.val + sg.len]) {
                    *wv += b * xi;
                }
            }
        }
        for i in 0..m {
            self.dx[self.perm[i]] = residual[i] - self.b_row_dot(i, &self.wn);
        }
        self.chol.solve(&mut self.dx);
        for (x, d) in self.x.iter_mut().zip(&self.dx) {
            *x += d;
        }
        for i in 0..m {
            let xi = self.x[self.perm[i]];
            lambda[i] = -xi;
            for sg in &self.segs[self.seg_ptr[i]..self.seg_ptr[i + 1]] {
                for (yv, b) in y[sg.col..sg.col + sg.len].iter_mut().zip(&self.vals[sg.val..sg.val + sg.len]) {
                    *yv += b * xi;
                }
            }
        }
    }
}

/// `S = B B^T` (its lower band, the layout of `L`) into `out` from the `B^T` values `vals`:
/// `S[band] = sum of vals_a . vals_b` over the segment pairs of each band entry.
fn gram(pairs: &[(usize, usize, usize, usize)], vals: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for &(idx, a, b, len) in pairs {
        let d: f64 = vals[a..a + len].iter().zip(&vals[b..b + len]).map(|(x, y)| x * y).sum();
        out[idx] += d;
    }
}

/// Reverse Cuthill-McKee order of the rows (rows adjacent when they share a body);
/// `perm[row] = position`. Each connected component starts from a row of least degree.
fn rcm(m: usize, rows_of_body: &[Vec<(usize, usize)>]) -> Vec<usize> {
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); m];
    for rows in rows_of_body {
        for &(a, _) in rows {
            for &(b, _) in rows {
                if a != b {
                    adj[a].push(b);
                }
            }
        }
    }
    for a in adj.iter_mut() {
        a.sort_unstable();
        a.dedup();
    }
    crate::linalg::rcm::rcm(&adj)
}
