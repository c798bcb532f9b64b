//! The spatial path of the UK correction for small mechanisms: the Cholesky factor of the Gram
//! matrix `S = B B^T = A M^-1 A^T` on its envelope, the Euler-parameter normalization rows
//! eliminated in closed form, with the full-rank certificate of the sparse path (`uk::sparse`)
//! and one refinement step with `B`. The dense certified QR (`uk::dense`) stays the fallback,
//! and the planar models never come here (`Data::gram` is `None` for them).
//!
//! Elimination. A rigid3 body's normalization row maps to a unit vector, `F^-1 A_u^T = d e_c`
//! (`d = 1 / sqrt k`, `c` the body's `Rigid3::NORMALIZATION_COORD`; `Model::unit_columns`). With
//! the unit rows first, `B^T = [E D, J]` (`E` the unit vectors, `J` the joint and driver
//! columns), `S = [[D^2, D X], [X^T D, J^T J]]` with `X = E^T J` (each joint row's entries at
//! the unit coordinates of its bodies), and its Cholesky factor is `[[D, 0], [X^T, L_22]]` with
//! `L_22 L_22^T = S_22 = J^T J - X^T X = Y^T Y`, `Y` the rows of `J` off the unit coordinates.
//! Only `S_22` is factored: its rows couple when they share a body, so in the reverse
//! Cuthill-McKee order of that graph it lives on a narrow envelope (the spatial slider-crank's
//! 17 joint rows: 4 blocks of 3 to 5 rows, each coupled to its neighbours; `linalg::envelope`).
//! Where that envelope is block tridiagonal with blocks of at most 6 rows (the slider-crank and
//! the heavy top) `S_22` is factored by fixed-size blocks instead (`linalg::block_tridiag`,
//! chosen once at setup: the same factor evaluated in another order, with the same bounds).
//! This is the factor the dense QR computes (`R = L^T` up to signs) without the Householder
//! work on the exact zeros.
//!
//! Certificate. `trace(S^-1) = |L^-1|_F^2 = sum_b (1 + x_b^T S_22^-1 x_b) / d_b^2 +
//! trace(S_22^-1)` (`x_b` the row of `X` of unit `b`: its entries are on rows that share body
//! `b`, so the selected inverse of `S_22` on its envelope holds every product needed), and
//! `trace(S) = |R|_F^2`. The computed `L` is the exact factor of `S + E`, `E` in the `S_22` block
//! only (`D` and `X` are read off `B^T`), `|E|_2 <= delta = 2 (2 w - 1) (gamma_{w+3} +
//! gamma_l) max_i (S_22)_ii` (`w` the widest row of the envelope, `l` the longest dot product of
//! an entry of `S_22`; Higham, *Accuracy and Stability*, Thm 10.3, as in `uk::sparse`; `S_22` is
//! factored as `L_22 D_22 L_22^T`, whose bound has the same form with `gamma_{w+2}`:
//! `linalg::envelope`). Rank
//! `m` is certified when `lower = 1 / (2 trace(S^-1)) - delta > tol^2`, `tol = max(atol, rcond
//! sqrt(trace S))` with the dense path's `rcond` (`RankTolerance::rcond_at`); otherwise the
//! dense rank-revealing path decides. The report is the dense QR's: `sigma_max = sqrt(trace S)
//! = |R|_F`, `sigma_min_kept = 1 / sqrt(trace S^-1) = 1 / |R^-1|_F`, so the singular-passage
//! monitor and the Newton floor read the same quantity on either path (equal up to rounding:
//! where this certificate passes, `cond(B)^2 eps` is small).
//!
//! Accuracy. The unit rows fix the correction's unit coordinates exactly (`dy_c = r_u / d`, as
//! the QR's identity reflectors do); solving with `S_22` squares the condition number of `Y`,
//! and one refinement step with `Y` itself, `x += S_22^-1 (r~ - Y Y^T x)`, brings the error back
//! to `O(cond(B) eps)` on the certified cases (as in `uk::sparse`). The step runs only where it
//! can matter. The computed `x` solves `(S_22 + E) x = r~` with `|E_pq| <= gamma_{3w+3} (|L_22|
//! D_22 |L_22|^T)_pq <= gamma_{3w+3} sqrt(S_pp S_qq)` (Higham, Thms 9.4 and 10.4, the factor
//! `L_22 D_22 L_22^T` of `linalg::envelope`; its diagonal is `S_pp`), so `E = D H D`
//! with `D = diag(S_22)^1/2` and `|H|_2 <= (2 w - 1) gamma_{3w+3}` (at most `2 w - 1` entries a
//! row). The correction's error in the norm that matters, `|Y^T (x - x*)| = |S_22^-1/2 E x|`, is
//! then at most `|H|_2 |D S_22^-1 D|_2 |Y^T x|` (Demmel's scaling argument: the diagonally
//! scaled condition, not `cond(S_22)`), and `|D S_22^-1 D|_2 <= trace(D S_22^-1 D) = sum_p S_pp
//! Z_pp` comes from the selected inverse at no cost. Where that relative bound is below the
//! Householder QR's own bound at the same condition estimate (`n m eps sqrt(trace S trace
//! S^-1)`, Higham Thm 21.4) the unrefined solution is as accurate as the QR it replaces and the
//! step is skipped (`refine`): on the spatial slider-crank the two are 1.7e-11 and 1.3e-10
//! (its rows mix lengths and angles: `sum S_pp Z_pp` = 159 where the unscaled `cond(S_22)`
//! estimate is 1.9e6).

use super::settings::RankInfo;
use crate::body::{BodyData, BodyKind};
use crate::constraint::jac::{Seg, SegJac};
use crate::linalg::block_tridiag::SpdProfile;
use crate::model::Model;
use super::seg::{dot6, seg_dot, t_times};

/// The Gram path serves `B` whose condition estimate `sqrt(trace S trace S^-1)` (at least
/// `cond(B)`) is at most this; beyond it the dense QR keeps its `O(cond(B) eps)` constraint
/// residual. Measured (`gram_path_matches_the_certified_qr`), a gate between two points: at an
/// estimate of 1.4e3 (the spatial slider-crank) and 21 (the heavy top) the refined Gram
/// solution's `|A qdd - b|` is below the QR's; at 9.8e3 (A05's thin rods, `|B^T|` up to 450
/// times its smallest scale) it was 60 times the QR's (the refinement's floor,
/// `eps |Y| |Y^T x|`, with a free acceleration 800 times the constrained one).
pub const GRAM_MAX_COND: f64 = 3e3;

/// After a refusal (condition estimate above `GRAM_MAX_COND`, or no certificate) this many
/// factorizations go straight to the dense QR before the Gram path is tried again: a mechanism
/// that stays badly conditioned (A05) then pays the refused attempt on one call in
/// `GRAM_RETRY + 1` (it doubled A05's call when tried every call).
pub const GRAM_RETRY: u32 = 64;

/// A normalization row: its row of `A`, the unit coordinate `c` and where `B^T[c, row]` is in
/// the values of its segment.
#[derive(Debug, Clone, Copy)]
struct Unit {
    row: usize,
    coord: usize,
    seg: Seg,
    local: usize,
}

/// Symbolic analysis (once per model) and numeric workspace of the spatial Gram path.
#[derive(Debug, Clone)]
pub struct GramUk {
    m: usize,
    /// The joint and driver rows in the envelope order: `rows[p]` is a row of `A`.
    rows: Vec<usize>,
    units: Vec<Unit>,
    /// The segments of `A`'s rows (`SegJac`'s pattern) and `B^T` in the same layout.
    seg_ptr: Vec<usize>,
    segs: Vec<Seg>,
    vals: Vec<f64>,
    /// The entries of `X`: `(position p, unit b, index of B^T[c_b, rows[p]] in vals)`, and their
    /// values (`factor` moves them out of `vals`, which then holds `Y`).
    xs: Vec<(usize, usize, usize)>,
    xval: Vec<f64>,
    /// The quadratic forms `x_b^T Z x_b`: diagonal terms `(index of Z(p, p), of x_p in xval)`,
    /// off-diagonal ones (counted twice) `(index of Z(p, q), of x_p, of x_q)`; unit `b`'s at
    /// `quad_ptr[b]..quad_ptr[b + 1]` (`.0` in `quad_d`, `.1` in `quad_o`).
    quad_d: Vec<(u32, u32)>,
    quad_o: Vec<(u32, u32, u32)>,
    quad_ptr: Vec<(usize, usize)>,
    /// `S_22[entry] += vals_a . vals_b` over `(entry, a, b, len)`.
    /// (entries of one or two six-entry products apart: `(entry, a, b)`, `(entry, a, b, a2, b2)`)
    pairs: Vec<(usize, usize, usize, usize)>,
    six1: Vec<(usize, usize, usize)>,
    six2: Vec<(usize, usize, usize, usize, usize)>,
    /// Per body: a rigid3 body's `F^-1` as `(1 / sqrt m, T^T)` (`Rigid3::finv_matrix`, `T` by
    /// columns: the product below in pairs of rows), this call's.
    finv: Vec<Option<(f64, [[f64; 4]; 4])>>,
    /// Longest dot product that makes one entry of `S_22`.
    max_dot: usize,
    /// `S_22`, its factor and selected inverse: by blocks where its envelope is block
    /// tridiagonal with small blocks (the spatial slider-crank), the envelope otherwise.
    env: SpdProfile,
    /// `d_b = B^T[c_b, row_b]`, and scratch per unit.
    d: Vec<f64>,
    zu: Vec<f64>,
    /// Scratch: three by position of the joint rows, one n long.
    rt: Vec<f64>,
    xp: Vec<f64>,
    dxp: Vec<f64>,
    wn: Vec<f64>,
    /// The diagonal of `S_22` before the factorization (the scaled bound of `refine`).
    sdiag: Vec<f64>,
    /// Whether `correct` takes the refinement step (module docs, "Accuracy").
    pub refine: bool,
    /// `trace(S)`, `trace(S^-1)` of the last `factor`.
    pub trace_s: f64,
    pub trace_sinv: f64,
    /// Factorizations left to the dense QR after the last refusal (`GRAM_RETRY`).
    pub skip: u32,
}

impl GramUk {
    /// Symbolic analysis on the pattern of `ajac` (the model's `SegJac`).
    pub fn new(model: &Model, ajac: &SegJac) -> GramUk {
        GramUk::with_profile(model, ajac, true)
    }

    /// `new`; `blocks: false` keeps `S_22` on the generic envelope whatever its pattern.
    pub fn with_profile(model: &Model, ajac: &SegJac, blocks: bool) -> GramUk {
        let (n, m) = (model.n, model.m);
        let mut unit_of_row = vec![None; m];
        let mut unit_of_body = vec![None; model.bodies.len()];
        let mut units = Vec::new();
        for (row, coord) in model.unit_columns() {
            let seg = *ajac.row_segs(row).iter().find(|s| s.col <= coord && coord < s.col + s.len).expect("a unit row touches its body");
            unit_of_row[row] = Some(units.len());
            unit_of_body[seg.body] = Some(units.len());
            units.push(Unit { row, coord, seg, local: coord - seg.col });
        }
        let joint_rows: Vec<usize> = (0..m).filter(|&i| unit_of_row[i].is_none()).collect();
        // rows of each body (joint rows only), and the reverse Cuthill-McKee order of the rows
        let mut rows_of_body: Vec<Vec<usize>> = vec![Vec::new(); model.bodies.len()];
        for (a, &i) in joint_rows.iter().enumerate() {
            for s in ajac.row_segs(i) {
                rows_of_body[s.body].push(a);
            }
        }
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); joint_rows.len()];
        for rs in &rows_of_body {
            for &a in rs {
                adj[a].extend(rs.iter().copied().filter(|&b| b != a));
            }
        }
        for a in adj.iter_mut() {
            a.sort_unstable();
            a.dedup();
        }
        let perm = crate::linalg::rcm::rcm(&adj);
        let mut order = vec![0; joint_rows.len()];
        for (a, &p) in perm.iter().enumerate() {
            order[p] = a;
        }
        let rows: Vec<usize> = order.iter().map(|&a| joint_rows[a]).collect();
        // each row's envelope starts at the first row it shares a body with
        let first: Vec<usize> = order.iter().enumerate().map(|(p, &a)| adj[a].iter().map(|&b| perm[b]).fold(p, usize::min)).collect();
        let env = SpdProfile::new(first, blocks);
        // the pairs of S_22 (off the unit coordinates) and the entries of X
        let mut pairs = Vec::new();
        let mut dots = vec![0usize; env.len()];
        let mut xs = Vec::new();
        let mut segs_of_body: Vec<Vec<(usize, Seg)>> = vec![Vec::new(); model.bodies.len()];
        for (p, &i) in rows.iter().enumerate() {
            for s in ajac.row_segs(i) {
                segs_of_body[s.body].push((p, *s));
                if let Some(b) = unit_of_body[s.body] {
                    xs.push((p, b, s.val + units[b].local));
                }
            }
        }
        for (body, list) in segs_of_body.iter().enumerate() {
            let skip = unit_of_body[body].map(|b| units[b].local);
            for &(pa, sa) in list {
                for &(pb, sb) in list.iter().filter(|(pb, _)| *pb <= pa) {
                    let e = env.index(pa, pb);
                    let ranges = match skip {
                        Some(u) => [(0, u), (u + 1, sa.len)],
                        None => [(0, sa.len), (0, 0)],
                    };
                    for (lo, hi) in ranges.into_iter().filter(|(lo, hi)| hi > lo) {
                        pairs.push((e, sa.val + lo, sb.val + lo, hi - lo));
                        dots[e] += hi - lo;
                    }
                }
            }
        }
        pairs.sort_by_key(|p| p.0);
        let (mut six1, mut six2, mut rest) = (Vec::new(), Vec::new(), Vec::new());
        for group in pairs.chunk_by(|p, q| p.0 == q.0) {
            match group {
                [(e, a, b, 6)] => six1.push((*e, *a, *b)),
                [(e, a, b, 6), (_, a2, b2, 6)] => six2.push((*e, *a, *b, *a2, *b2)),
                _ => rest.extend_from_slice(group),
            }
        }
        let pairs = rest;
        // x_b^T Z x_b = sum over the ordered pairs of X's entries of unit b
        let (mut quad_d, mut quad_o, mut quad_ptr) = (Vec::new(), Vec::new(), vec![(0, 0)]);
        for b in 0..units.len() {
            let mine: Vec<(usize, usize)> = xs.iter().enumerate().filter(|(_, x)| x.1 == b).map(|(t, x)| (t, x.0)).collect();
            for (a, &(s, ps)) in mine.iter().enumerate() {
                for &(t, pt) in &mine[..=a] {
                    let e = env.index(ps.max(pt), ps.min(pt)) as u32;
                    if pt == ps {
                        quad_d.push((e, s as u32));
                    } else {
                        quad_o.push((e, s as u32, t as u32));
                    }
                }
            }
            quad_ptr.push((quad_d.len(), quad_o.len()));
        }
        let (nu, mj) = (units.len(), rows.len());
        GramUk {
            m,
            rows,
            units,
            seg_ptr: ajac.seg_ptr.clone(),
            segs: ajac.segs.clone(),
            vals: vec![0.0; ajac.vals.len()],
            xval: vec![0.0; xs.len()],
            xs,
            quad_d,
            quad_o,
            quad_ptr,
            pairs,
            six1,
            six2,
            finv: vec![None; model.bodies.len()],
            max_dot: dots.into_iter().max().unwrap_or(0),
            env,
            d: vec![0.0; nu],
            zu: vec![0.0; nu],
            rt: vec![0.0; mj],
            xp: vec![0.0; mj],
            dxp: vec![0.0; mj],
            wn: vec![0.0; n],
            sdiag: vec![0.0; mj],
            refine: true,
            trace_s: 0.0,
            trace_sinv: f64::INFINITY,
            skip: 0,
        }
    }

    /// Whether `S_22` is factored by blocks (`linalg::block_tridiag`).
    pub fn on_blocks(&self) -> bool {
        self.env.is_blocks()
    }

    /// Heap bytes of the workspace of `GramUk::new` (a bound without building it: the pattern,
    /// the values, an envelope and pair lists no larger than those of the dense `S`, and the
    /// blocks: two 6 x 6 of `S_22` and two of `Z`, two 6-vectors, kernels and row map per row).
    pub fn bytes(model: &Model) -> u64 {
        let nnz: u64 = model.constraints.iter().map(|c| c.rows() as u64 * c.bodies().into_iter().flatten().map(|b| model.bodies[b].n_coords as u64).sum::<u64>()).sum();
        let (n, m) = (model.n as u64, model.m as u64);
        8 * (3 * nnz + 6 * m * m + 8 * m + n) + 48 * m * m + 48 * nnz + 1312 * m
    }

    /// `B^T`, `S_22`, its envelope Cholesky factor and the full-rank certificate (module docs)
    /// with the relative tolerance `rcond` and the absolute `atol`. `Some(info)` when rank = m
    /// is certified (ready for `correct`), `None` otherwise.
    pub fn factor(&mut self, model: &Model, bodies: &[BodyData], ajac: &SegJac, rcond: f64, atol: f64) -> Option<RankInfo> {
        debug_assert_eq!(self.vals.len(), ajac.vals.len());
        // B^T = F^-1 A^T, segment by segment (the segments tile the values); a rigid3 body's
        // factor once as a matrix, its segments read from `A` and written in one pass
        for (f, (body, bd)) in self.finv.iter_mut().zip(model.bodies.iter().zip(bodies)) {
            if let (BodyKind::Rigid3(k), BodyData::Rigid3(d)) = (&body.kind, bd) {
                let (im, t) = k.finv_matrix(d);
                *f = Some((im, std::array::from_fn(|l| std::array::from_fn(|i| t[i][l]))));
            }
        }
        for s in &self.segs {
            let (a, v) = (&ajac.vals[s.val..s.val + s.len], &mut self.vals[s.val..s.val + s.len]);
            match &self.finv[s.body] {
                Some((im, tc)) if s.len == 7 => {
                    let (a, v): (&[f64; 7], &mut [f64; 7]) = (a.try_into().unwrap(), v.try_into().unwrap());
                    for c in 0..3 {
                        v[c] = a[c] * im;
                    }
                    let o = t_times(tc, [a[3], a[4], a[5], a[6]]);
                    v[3..7].copy_from_slice(&o);
                }
                _ => {
                    v.copy_from_slice(a);
                    model.bodies[s.body].finv(&bodies[s.body], v);
                }
            }
        }
        let mut trace_s = 0.0;
        for (d, u) in self.d.iter_mut().zip(&self.units) {
            *d = self.vals[u.seg.val + u.local];
            trace_s += *d * *d;
        }
        // X out of the joint rows: `vals` keeps `Y`
        for (x, &(_, _, e)) in self.xval.iter_mut().zip(&self.xs) {
            *x = self.vals[e];
            self.vals[e] = 0.0;
            trace_s += *x * *x;
        }
        self.assemble_s22();
        let mut max_d = 0.0f64;
        for p in 0..self.rows.len() {
            let s = self.env.diag(p);
            self.sdiag[p] = s;
            trace_s += s;
            max_d = max_d.max(s);
        }
        self.trace_s = trace_s;
        self.trace_sinv = f64::INFINITY;
        if !trace_s.is_finite() || self.d.iter().any(|d| !(d.abs() > 0.0)) || !self.env.factor_in_place() {
            return None;
        }
        let mut trace_sinv = self.env.selected_inverse_trace();
        let z = self.env.z();
        // two partial sums per kind of term in registers; the off-diagonal terms doubled once
        let x = &self.xval;
        for (b, d) in self.d.iter().enumerate() {
            let ((d0, o0), (d1, o1)) = (self.quad_ptr[b], self.quad_ptr[b + 1]);
            let (mut a0, mut a1, mut c0, mut c1) = (0.0, 0.0, 0.0, 0.0);
            let diag = self.quad_d[d0..d1].chunks_exact(2);
            if let [(e, s)] = diag.remainder() {
                a1 = z[*e as usize] * x[*s as usize] * x[*s as usize];
            }
            for c in diag {
                let ((e0, s0), (e1, s1)) = (c[0], c[1]);
                a0 += z[e0 as usize] * x[s0 as usize] * x[s0 as usize];
                a1 += z[e1 as usize] * x[s1 as usize] * x[s1 as usize];
            }
            let off = self.quad_o[o0..o1].chunks_exact(2);
            if let [(e, s, t)] = off.remainder() {
                c1 = z[*e as usize] * x[*s as usize] * x[*t as usize];
            }
            for c in off {
                let ((e0, s0, t0), (e1, s1, t1)) = (c[0], c[1]);
                c0 += z[e0 as usize] * x[s0 as usize] * x[t0 as usize];
                c1 += z[e1 as usize] * x[s1 as usize] * x[t1 as usize];
            }
            let zu = 1.0 + ((a0 + a1) + 2.0 * (c0 + c1));
            trace_sinv += zu / (d * d);
        }
        self.trace_sinv = trace_sinv;
        let gamma = |k: usize| {
            let ke = k as f64 * f64::EPSILON;
            ke / (1.0 - ke)
        };
        let w = self.env.width().max(1);
        let delta = 2.0 * (2 * w - 1) as f64 * (gamma(w + 3) + gamma(self.max_dot)) * max_d;
        let lower = 0.5 / trace_sinv - delta;
        let sigma_max = trace_s.sqrt();
        let tol = atol.max(rcond * sigma_max);
        let conditioned = trace_s * trace_sinv <= GRAM_MAX_COND * GRAM_MAX_COND;
        // the unrefined solution's bound against the QR's (module docs, "Accuracy")
        let scaled: f64 = self.sdiag.iter().enumerate().map(|(p, s)| s * z[self.env.index(p, p)]).sum();
        let unrefined = (2 * w - 1) as f64 * gamma(3 * w + 3) * scaled;
        self.refine = !(unrefined <= (model.n * self.m) as f64 * f64::EPSILON * (trace_s * trace_sinv).sqrt());
        if lower.is_finite() && lower > 0.0 && lower > tol * tol && conditioned {
            Some(RankInfo { rank: self.m, sigma_max, sigma_min_kept: 1.0 / trace_sinv.sqrt(), sigma_max_dropped: 0.0, tolerance: tol, exact: false })
        } else {
            None
        }
    }

    /// `S_22 = Y^T Y` on its profile (`pairs`, `six1`, `six2`), each entry summed in a register
    /// and stored once (a sum through memory waits on each store). Out of line: `factor` short.
    #[inline(never)]
    fn assemble_s22(&mut self) {
        self.env.clear();
        let data = self.env.data_mut();
        let vals = &self.vals;
        let six = |a: usize| -> &[f64; 6] { vals[a..a + 6].try_into().unwrap() };
        for &(e, a, b) in &self.six1 {
            data[e] = dot6(six(a), six(b));
        }
        for &(e, a, b, a2, b2) in &self.six2 {
            data[e] = dot6(six(a), six(b)) + dot6(six(a2), six(b2));
        }
        let mut pairs = self.pairs.iter().peekable();
        while let Some(&(e, a, b, len)) = pairs.next() {
            let mut s = seg_dot(&vals[a..a + len], &vals[b..b + len]);
            while let Some(&(_, a, b, len)) = pairs.next_if(|p| p.0 == e) {
                s += seg_dot(&vals[a..a + len], &vals[b..b + len]);
            }
            data[e] = s;
        }
    }

    /// `(Y v)_p` for the joint row at position `p` (off the unit coordinates).
    #[inline]
    fn y_dot(&self, p: usize, v: &[f64]) -> f64 {
        let i = self.rows[p];
        let mut s = 0.0;
        for sg in &self.segs[self.seg_ptr[i]..self.seg_ptr[i + 1]] {
            s += seg_dot(&self.vals[sg.val..sg.val + sg.len], &v[sg.col..sg.col + sg.len]);
        }
        s
    }

    /// `out += Y^T x` (x by position, out n long).
    fn add_yt_times(&self, x: &[f64], out: &mut [f64]) {
        for (&i, &xi) in self.rows.iter().zip(x) {
            for sg in &self.segs[self.seg_ptr[i]..self.seg_ptr[i + 1]] {
                let (o, b) = (&mut out[sg.col..sg.col + sg.len], &self.vals[sg.val..sg.val + sg.len]);
                if let (Ok(o), Ok(b)) = (<&mut [f64; 7]>::try_from(&mut *o), <&[f64; 7]>::try_from(b)) {
                    for k in 0..7 {
                        o[k] += b[k] * xi;
                    }
                } else {
                    for (o, b) in o.iter_mut().zip(b) {
                        *o += b * xi;
                    }
                }
            }
        }
    }

    /// The correction with the current factorization, `y = F^-1 Q` on entry: the minimum-norm
    /// `dy` with `B dy = r = b - B y` (`r` into `residual`), `y += dy`, `lambda = -S^-1 r`. The
    /// unit rows fix `dy_c = r_u / d` exactly; the rest is `Y^T x` with `S_22 x = r_j - X^T dy_c`,
    /// plus one refinement step with `Y` (`x += S_22^-1 (r~ - Y Y^T x)`) where `refine`; the unit rows'
    /// multipliers are `-(dy_c - X x) / d`.
    pub fn correct(&mut self, gamma: &[f64], residual: &mut [f64], y: &mut [f64], lambda: &mut [f64]) {
        // r = b - B y
        for (p, &i) in self.rows.iter().enumerate() {
            residual[i] = gamma[i] - self.y_dot(p, y);
        }
        for (&(p, b, _), x) in self.xs.iter().zip(&self.xval) {
            residual[self.rows[p]] -= x * y[self.units[b].coord];
        }
        for ((zu, u), d) in self.zu.iter_mut().zip(&self.units).zip(&self.d) {
            residual[u.row] = gamma[u.row] - d * y[u.coord];
            *zu = residual[u.row] / d;
        }
        // r~ = r_j - X^T dy_c, x = S_22^-1 r~
        let (mut rt, mut xp, mut dxp, mut wn) = (std::mem::take(&mut self.rt), std::mem::take(&mut self.xp), std::mem::take(&mut self.dxp), std::mem::take(&mut self.wn));
        for (r, &i) in rt.iter_mut().zip(&self.rows) {
            *r = residual[i];
        }
        for (&(p, b, _), x) in self.xs.iter().zip(&self.xval) {
            rt[p] -= x * self.zu[b];
        }
        xp.copy_from_slice(&rt);
        self.env.solve(&mut xp);
        // one refinement step with Y, where the bound asks for it
        if self.refine {
            wn.fill(0.0);
            self.add_yt_times(&xp, &mut wn);
            for (p, dx) in dxp.iter_mut().enumerate() {
                *dx = rt[p] - self.y_dot(p, &wn);
            }
            self.env.solve(&mut dxp);
            for (x, dx) in xp.iter_mut().zip(&dxp) {
                *x += dx;
            }
        }
        // y += Y^T x + dy_c; the multipliers
        self.add_yt_times(&xp, y);
        for (&i, x) in self.rows.iter().zip(&xp) {
            lambda[i] = -x;
        }
        for (u, zu) in self.units.iter().zip(&self.zu) {
            y[u.coord] += zu;
            lambda[u.row] = *zu;
        }
        for (&(p, b, _), x) in self.xs.iter().zip(&self.xval) {
            lambda[self.units[b].row] -= x * xp[p];
        }
        for (u, d) in self.units.iter().zip(&self.d) {
            lambda[u.row] /= -d;
        }
        (self.rt, self.xp, self.dxp, self.wn) = (rt, xp, dxp, wn);
    }
}

#[cfg(test)]
mod tests {
    use crate::correct::{correct, CorrectOptions};
    use crate::data::{Data, Factored, RankTolerance, UkSolver};
    use crate::model::Model;
    use crate::uk;

    fn scene(json: &str) -> (Model, Vec<f64>, Vec<f64>) {
        let model = Model::from_json(json).unwrap();
        let mut data = Data::build(&model, UkSolver::Dense, u64::MAX).unwrap();
        let opts = CorrectOptions { hold: vec![false; model.n], rigid: false, position_tol: 1e-12, velocity_tol: 1e-10, max_iterations: 50 };
        let c = correct(&model, &mut data, 0.0, &model.q0, &model.qd0, &opts).unwrap();
        (model, c.q, c.qd)
    }

    /// The Gram path gives the accelerations, multipliers and rank report of the dense certified
    /// QR (an explicit `UkSolver::Dense`) on the spatial slider-crank and the heavy top, on the
    /// manifold and 1e-7 off it, with a constraint residual no larger; the flyball governor
    /// (A05, condition estimate 1e4 > `GRAM_MAX_COND`) and Bricard's mechanism (A04, rank 34 of
    /// 35) are refused and decided by the dense path as before.
    #[test]
    fn gram_path_matches_the_certified_qr() {
        let scenes = [
            (include_str!("../../benches/data/spatial/slider_crank.json"), Factored::Gram),
            (include_str!("../../benches/data/spatial/heavy_top.json"), Factored::Gram),
            (include_str!("../../benches/data/spatial/flyball.json"), Factored::FullRankQr),
            (include_str!("../../benches/data/spatial/bricard.json"), Factored::Deflated),
        ];
        for (si, (json, path)) in scenes.into_iter().enumerate() {
            let full_rank = path != Factored::Deflated;
            let (model, q0, qd0) = scene(json);
            let (n, m) = (model.n, model.m);
            let mut data = Data::new(&model);
            let mut plain = Data::build(&model, UkSolver::Dense, u64::MAX).unwrap();
            // (A04's 35 rows take the sparse path, its certificate fails, the dense one decides)
            assert!(data.gram.is_some() == full_rank && plain.gram.is_none());
            for (k, off) in [(0usize, 0.0), (1, 1e-7)] {
                let q: Vec<f64> = q0.iter().enumerate().map(|(i, x)| x + off * ((i * 7 + k) as f64).sin()).collect();
                let qd: Vec<f64> = qd0.iter().enumerate().map(|(i, x)| x + 0.3 * ((i * 3 + k) as f64).cos()).collect();
                uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
                uk::acceleration(&model, &mut plain, 0.1, &q, &qd).unwrap();
                let (a, b) = (data.rank_info, plain.rank_info);
                assert_eq!(a.rank, b.rank);
                assert_eq!(data.factored_with, path, "scene {si}");
                // the refinement step: idle by its bound on the two Gram scenes (so the
                // comparisons below are of the unrefined solution), asked for on A05's rods
                if let Some(g) = data.gram.as_ref() {
                    assert_eq!(g.refine, si == 2, "scene {si}");
                }
                if path != Factored::Gram {
                    // the dense path as before, to the bit
                    assert!(data.qdd == plain.qdd && data.lambda == plain.lambda);
                    continue;
                }
                if full_rank {
                    assert_eq!(plain.factored_with, Factored::FullRankQr);
                    assert!((a.sigma_max - b.sigma_max).abs() < 1e-13 * b.sigma_max);
                    assert!((a.sigma_min_kept - b.sigma_min_kept).abs() < 1e-9 * b.sigma_min_kept, "{} vs {}", a.sigma_min_kept, b.sigma_min_kept);
                    assert!((a.tolerance - b.tolerance).abs() <= 1e-13 * b.tolerance);
                } else {
                    assert_ne!(data.factored_with, Factored::Gram);
                    assert_eq!(a.rank, m - 1);
                }
                // both solutions err by O(cond(B) eps): compare at that scale, and compare
                // their acceleration residuals A qdd - b
                let tol = 64.0 * f64::EPSILON * b.sigma_max / b.sigma_min_kept.max(1e-300);
                let amax = plain.qdd.iter().fold(1.0f64, |s, x| s.max(x.abs()));
                let lmax = plain.lambda.iter().fold(1.0f64, |s, x| s.max(x.abs()));
                for i in 0..n {
                    assert!((data.qdd[i] - plain.qdd[i]).abs() < tol * amax, "scene {si}: qdd[{i}] {} vs {}", data.qdd[i], plain.qdd[i]);
                }
                for i in 0..m {
                    assert!((data.lambda[i] - plain.lambda[i]).abs() < tol * lmax, "scene {si}: lambda[{i}] {} vs {}", data.lambda[i], plain.lambda[i]);
                }
                // (the rounding of A qdd itself: eps max_i |A_i| . |qdd|)
                let res = |d: &Data| (0..m).map(|i| (d.ajac.row_dot(i, &d.qdd) - d.gamma[i]).abs()).fold(0.0f64, f64::max);
                let abs_qdd: Vec<f64> = plain.qdd.iter().map(|x| x.abs()).collect();
                let mut abs_a = plain.ajac.clone();
                abs_a.vals.iter_mut().for_each(|x| *x = x.abs());
                let floor = (0..m).map(|i| abs_a.row_dot(i, &abs_qdd)).fold(0.0f64, f64::max) * f64::EPSILON;
                assert!(res(&data) <= 4.0 * res(&plain) + 16.0 * floor, "scene {si}: |A qdd - b| {:.2e} vs {:.2e}", res(&data), res(&plain));
                // the minimum-norm correction of the projections: the same step
                let r: Vec<f64> = (0..m).map(|i| 1e-6 * (i as f64).sin()).collect();
                uk::min_norm_correction(&model, &mut data, &r);
                uk::min_norm_correction(&model, &mut plain, &r);
                let dmax = plain.qdd.iter().fold(1e-300f64, |s, x| s.max(x.abs()));
                for i in 0..n {
                    assert!((data.qdd[i] - plain.qdd[i]).abs() < tol * dmax, "scene {si}: dq[{i}] {} vs {}", data.qdd[i], plain.qdd[i]);
                }
                // the exact report on demand: the singular values of the same B
                if full_rank {
                    let e = uk::exact_rank_info(&model, &mut data).unwrap();
                    let f = uk::exact_rank_info(&model, &mut plain).unwrap();
                    assert!(e.exact && f.exact && e.rank == f.rank);
                    assert!((e.sigma_min_kept - f.sigma_min_kept).abs() < 1e-12 * f.sigma_max);
                }
            }
        }
    }

    /// The block factor of `S_22` against the generic envelope on the same scenes: the same
    /// decisions, traces, corrections and multipliers to rounding. The slider-crank (4 blocks of
    /// 3 to 5 rows) and the heavy top (one block of 3) take the blocks, A05 (a block of more
    /// than 6 rows) keeps the envelope, A04 (blocks, rank 34 of 35) is refused by both (their
    /// `GramUk` is called directly here: `uk` refuses them by condition and rank).
    #[test]
    fn blocks_match_the_envelope_path() {
        let scenes = [
            (include_str!("../../benches/data/spatial/slider_crank.json"), true),
            (include_str!("../../benches/data/spatial/heavy_top.json"), true),
            (include_str!("../../benches/data/spatial/flyball.json"), false),
            (include_str!("../../benches/data/spatial/bricard.json"), true),
        ];
        for (si, (json, blocks)) in scenes.into_iter().enumerate() {
            let (model, q, qd) = scene(json);
            let mut data = Data::build(&model, UkSolver::Dense, u64::MAX).unwrap();
            uk::evaluate(&model, &mut data, 0.1, &q, &qd, false).unwrap();
            let mut blk = super::GramUk::with_profile(&model, &data.ajac, true);
            let mut env = super::GramUk::with_profile(&model, &data.ajac, false);
            assert!(!env.on_blocks());
            assert_eq!(blk.on_blocks(), blocks, "scene {si}");
            let (a, b) = (blk.factor(&model, &data.bodies, &data.ajac, 1e-12, 0.0), env.factor(&model, &data.bodies, &data.ajac, 1e-12, 0.0));
            assert_eq!(a.map(|i| i.rank), b.map(|i| i.rank), "scene {si}");
            assert!((blk.trace_s - env.trace_s).abs() <= 1e-14 * env.trace_s, "scene {si}");
            // A04 (rank 34 of 35): S_22 is singular to rounding, nothing more to compare
            if si == 3 {
                assert!(a.is_none());
                continue;
            }
            let rel = (blk.trace_sinv - env.trace_sinv).abs() / env.trace_sinv;
            assert!(rel < 1e-10, "scene {si}: trace(S^-1) {} vs {}", blk.trace_sinv, env.trace_sinv);
            assert_eq!(blk.refine, env.refine);
            let (n, m) = (model.n, model.m);
            let y0: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
            let mut out = [(vec![0.0; m], y0.clone(), vec![0.0; m]), (vec![0.0; m], y0, vec![0.0; m])];
            blk.correct(&data.gamma, &mut out[0].0, &mut out[0].1, &mut out[0].2);
            env.correct(&data.gamma, &mut out[1].0, &mut out[1].1, &mut out[1].2);
            // the two differ by the rounding of a solve with S_22: cond(S_22) eps at most
            let tol = 1e3 * f64::EPSILON * env.trace_s * env.trace_sinv;
            let ymax = out[1].1.iter().fold(1e-300f64, |s, x| s.max(x.abs()));
            let lmax = out[1].2.iter().fold(1e-300f64, |s, x| s.max(x.abs()));
            for i in 0..n {
                assert!((out[0].1[i] - out[1].1[i]).abs() <= tol * ymax, "scene {si}: y[{i}] {} vs {}", out[0].1[i], out[1].1[i]);
            }
            for i in 0..m {
                assert!((out[0].2[i] - out[1].2[i]).abs() <= tol * lmax, "scene {si}: lambda[{i}] {} vs {}", out[0].2[i], out[1].2[i]);
            }
        }
    }

    /// A tolerance above the smallest singular value: the certificate refuses and the dense
    /// rank-revealing path drops it, as without the Gram path.
    #[test]
    fn the_certificate_refuses_below_the_tolerance() {
        let (model, q, qd) = scene(include_str!("../../benches/data/spatial/slider_crank.json"));
        let mut data = Data::new(&model);
        uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
        assert_eq!(data.factored_with, Factored::Gram);
        assert!(data.gram.as_ref().unwrap().on_blocks());
        let exact = uk::singular_values(&model, &mut data).unwrap().unwrap();
        let ratio = exact[model.m - 1] / exact[0];
        // just above sigma_min: the Gram certificate (and the QR's) cannot pass
        data.tolerance = RankTolerance { rcond: Some(1.5 * ratio), atol: 0.0 };
        uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
        assert_ne!(data.factored_with, Factored::Gram);
        assert_eq!(data.rank_info.rank, model.m - 1);
        // and just below the certificate's reach (a factor sqrt 2 and the rounding), it passes,
        // once the refused attempt's `GRAM_RETRY` calls on the QR are over
        data.tolerance = RankTolerance { rcond: Some(0.5 * ratio / (model.m as f64).sqrt()), atol: 0.0 };
        for _ in 0..super::GRAM_RETRY {
            uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
            assert_eq!((data.factored_with, data.rank_info.rank), (Factored::FullRankQr, model.m));
        }
        uk::acceleration(&model, &mut data, 0.1, &q, &qd).unwrap();
        assert_eq!(data.factored_with, Factored::Gram);
        assert_eq!(data.rank_info.rank, model.m);
    }
}
