//! The structure of the equations of motion in sparse form, for the implicit methods' Newton
//! matrices and the modal analysis: every stage O(n) where the dense forms are O(n^2) or O(n^3).
//!
//! `M qdd + A^T lambda = Q(t, q, qd)`, `A qdd = b(t, q, qd)`. The implicit methods factor
//!
//! `H = [M + g_c C + g_k K, A^T; A - g_c db/dqd, 0]`
//!
//! (`K = -dQ/dq` the bodies' analytic stiffness and the loads' (`Force::add_stiffness`),
//! `C = -dQ/dqd`). Every block is local:
//! `M`, `K`, `C` couple a body's own coordinates (dense for rigid, FFRF and modal bodies; an
//! ANCF cable's within an element, `Body::coupling_halfwidth`) and the coordinates of a force
//! element's markers; a constraint row depends on its markers' coordinates only
//! (`Marker::coords`: a cable marker its element's eight), and so does its `b`.
//!
//! * `Pattern` (symbolic, once per model): the coordinate block in compressed columns, the
//!   structural entries of `A` (a subset of the segment form `SegJac`, which keeps whole bodies
//!   per row), and a colouring of the coordinates such that no two of one colour share a row
//!   of `C` or of `db/dqd` (Curtis, Powell & Reid 1974): the velocity terms come from two
//!   evaluations per colour instead of two per coordinate. Each difference isolates one column
//!   exactly, so the values are those of the dense column-by-column differences to the bit.
//! * `Structure`: the values of `M`, `K`, `C`, `A`, `db/dqd` in the pattern (`fill_*`).
//! * `BandNewton`: a reverse Cuthill-McKee order of `H`'s graph (once), the band positions of
//!   every entry, and the real and complex band LU (`band_lu`) refilled and refactored in place:
//!   a chain, a rope or an ANCF cable has a band of a few coordinates whatever its length. Where
//!   the band is wide but the elimination stays sparse (`Factorization::Static`, chosen by
//!   `integrate::newton::factorization`), the sparse LU with kept pivots (`static_lu`) instead.
//! * `fill_linearized_stiffness`: the stiffness of the constrained linearization
//!   `K_eff = -d/dq (Q - M qdd - A^T lambda)` at fixed `qdd`, `lambda` (what
//!   `System.frequencies` needs, the constraint forces included), by coloured central
//!   differences in the positions.

use crate::linalg::band_lu::{BandLu, C64};
use crate::linalg::static_lu::{Factored, StaticLu};
use crate::constraint::jac::SegJac;
use crate::data::Data;
use crate::dynamics::{constraints, mass_and_forces, mass_times};
use crate::error::{Error, Result};
use crate::model::Model;

mod factor;
mod velocity;
use factor::Lu;
pub use factor::{newton_entries, BandLayout, Factorization, SparsePlan};
pub use velocity::{fill_velocity_terms, velocity_differences};

/// Symbolic analysis of the structure (once per model).
#[derive(Debug, Clone)]
pub struct Pattern {
    pub n: usize,
    pub m: usize,
    /// Coordinate block (`M`, `K`, `C`; with `hessian`, the constraint forces' stiffness too):
    /// column `j` holds rows `row[col_ptr[j]..col_ptr[j + 1]]`, sorted.
    pub col_ptr: Vec<usize>,
    pub row: Vec<usize>,
    /// Structural entries of `A` by column: column `j` holds constraint rows
    /// `arow[acol_ptr[j]..acol_ptr[j + 1]]`, with the index of each value in `SegJac::vals`.
    pub acol_ptr: Vec<usize>,
    pub arow: Vec<usize>,
    pub aseg: Vec<usize>,
    /// Columns by colour: colour `c` is `color_cols[color_ptr[c]..color_ptr[c + 1]]`.
    pub color_ptr: Vec<usize>,
    pub color_cols: Vec<usize>,
    /// On small systems (`n^2 <= DENSE_INDEX_MAX`) the value index of every coordinate entry
    /// `(i, j)` at `i n + j` (`u32::MAX` outside the pattern): `find` without a search (the
    /// stiffness of A05's two spring-dampers writes ~2 500 entries per read).
    index: Vec<u32>,
}

/// Largest `n^2` for which `Pattern` keeps the dense index of its entries.
const DENSE_INDEX_MAX: usize = 1 << 16;

/// Structural coordinates of each constraint row: `(global column, index in SegJac::vals)`,
/// sorted by column.
fn constraint_rows(model: &Model, ajac: &SegJac) -> Vec<Vec<(usize, usize)>> {
    let mut rows = vec![Vec::new(); model.m];
    for (k, c) in model.constraints.iter().enumerate() {
        let layout = &ajac.layouts[k];
        for r in c.row..c.row + c.rows() {
            let row = &mut rows[r];
            for mk in c.markers().into_iter().flatten() {
                let Some((b, range)) = mk.coords(&model.bodies) else { continue };
                let start = layout.iter().find(|e| e.0 == b).expect("the marker's body is in the constraint's layout").1;
                let offset = model.bodies[b].offset;
                for local in range {
                    row.push((offset + local, ajac.row_ptr[r] + start + local));
                }
            }
            row.sort_unstable();
            row.dedup();
        }
    }
    rows
}

/// The global coordinates a list of markers depends on.
fn marker_coords<'a>(model: &Model, markers: impl IntoIterator<Item = Option<&'a crate::body::Marker>>) -> Vec<usize> {
    let mut out = Vec::new();
    for mk in markers.into_iter().flatten() {
        if let Some((b, range)) = mk.coords(&model.bodies) {
            let o = model.bodies[b].offset;
            out.extend(range.map(|k| o + k));
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The coordinates a force element's generalized force depends on: its markers' and those
/// its values read (a load of another body's angle).
fn force_coords(model: &Model, f: &crate::force::Force) -> Vec<usize> {
    let mut c = marker_coords(model, f.markers().into_iter().chain(f.read_points().into_iter().map(Some)));
    c.extend(f.read_coords());
    c.sort_unstable();
    c.dedup();
    c
}

impl Pattern {
    /// Entries of the coordinate block (without building it): the memory check's estimate.
    pub fn estimate_nnz(model: &Model, hessian: bool) -> u64 {
        let mut nnz: u64 = model.bodies.iter().map(|b| (b.n_coords * (2 * b.coupling_halfwidth() + 1)) as u64).sum();
        for f in &model.forces {
            nnz += (force_coords(model, f).len() as u64).pow(2);
        }
        if hessian {
            for c in &model.constraints {
                nnz += (marker_coords(model, c.markers()).len() as u64).pow(2);
            }
        }
        nnz
    }

    /// Heap bytes of the pattern and of a `Structure` on it, estimated before building.
    pub fn bytes(model: &Model, hessian: bool) -> u64 {
        let nnz = Self::estimate_nnz(model, hessian);
        let annz: u64 = model.constraints.iter().map(|c| c.rows() as u64 * marker_coords(model, c.markers()).len() as u64).sum();
        // rows, three values; A: row, seg, two values; per column: pointers, colours, scratch
        8 * (4 * nnz + 4 * annz + 6 * model.n as u64 + 2 * model.m as u64)
    }

    /// The pattern of `model`'s structure; `hessian`: the coordinate block also couples the
    /// coordinates of every constraint row (the constraint forces' stiffness of
    /// `linearization`). Refused above `memory_limit`.
    pub fn new(model: &Model, ajac: &SegJac, hessian: bool, memory_limit: u64) -> Result<Pattern> {
        let (n, m) = (model.n, model.m);
        Error::check_memory("the sparse structure (pattern of M, K, C, A)", Self::bytes(model, hessian), memory_limit, "raise memory_limit")?;
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        for b in &model.bodies {
            let (o, nb, w) = (b.offset, b.n_coords, b.coupling_halfwidth());
            for j in 0..nb {
                cols[o + j].extend((j.saturating_sub(w)..(j + w + 1).min(nb)).map(|i| o + i));
            }
        }
        let mut clique = |set: &[usize]| {
            for &j in set {
                cols[j].extend_from_slice(set);
            }
        };
        for f in &model.forces {
            clique(&force_coords(model, f));
        }
        if hessian {
            for c in &model.constraints {
                clique(&marker_coords(model, c.markers()));
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut row = Vec::new();
        for c in cols.iter_mut() {
            c.sort_unstable();
            c.dedup();
            row.extend_from_slice(c);
            col_ptr.push(row.len());
        }
        drop(cols);
        // A by column
        let arows = constraint_rows(model, ajac);
        let mut acount = vec![0usize; n + 1];
        for r in &arows {
            for &(j, _) in r {
                acount[j + 1] += 1;
            }
        }
        for j in 0..n {
            acount[j + 1] += acount[j];
        }
        let acol_ptr = acount.clone();
        let total = acol_ptr[n];
        let (mut arow, mut aseg) = (vec![0; total], vec![0; total]);
        let mut next = acount;
        for (r, entries) in arows.iter().enumerate() {
            for &(j, s) in entries {
                arow[next[j]] = r;
                aseg[next[j]] = s;
                next[j] += 1;
            }
        }
        // colouring: columns that share a coordinate row or a constraint row get different colours
        let mut rows_cols: Vec<Vec<usize>> = vec![Vec::new(); n + m];
        for j in 0..n {
            for &i in &row[col_ptr[j]..col_ptr[j + 1]] {
                rows_cols[i].push(j);
            }
            for &r in &arow[acol_ptr[j]..acol_ptr[j + 1]] {
                rows_cols[n + r].push(j);
            }
        }
        let mut color = vec![usize::MAX; n];
        let mut mark: Vec<usize> = Vec::new();
        let mut ncolors = 0;
        for j in 0..n {
            let rows_of_j = row[col_ptr[j]..col_ptr[j + 1]].iter().copied().chain(arow[acol_ptr[j]..acol_ptr[j + 1]].iter().map(|r| n + r));
            for i in rows_of_j {
                for &k in &rows_cols[i] {
                    if color[k] != usize::MAX {
                        mark[color[k]] = j;
                    }
                }
            }
            let c = (0..ncolors).find(|&c| mark[c] != j).unwrap_or(ncolors);
            if c == ncolors {
                ncolors += 1;
                mark.push(usize::MAX);
            }
            color[j] = c;
        }
        let mut color_ptr = vec![0usize; ncolors + 1];
        for &c in &color {
            color_ptr[c + 1] += 1;
        }
        for c in 0..ncolors {
            color_ptr[c + 1] += color_ptr[c];
        }
        let mut color_cols = vec![0; n];
        let mut next = color_ptr.clone();
        for (j, &c) in color.iter().enumerate() {
            color_cols[next[c]] = j;
            next[c] += 1;
        }
        let mut index = Vec::new();
        if n * n <= DENSE_INDEX_MAX {
            index = vec![u32::MAX; n * n];
            for j in 0..n {
                for e in col_ptr[j]..col_ptr[j + 1] {
                    index[row[e] * n + j] = e as u32;
                }
            }
        }
        Ok(Pattern { n, m, col_ptr, row, acol_ptr, arow, aseg, color_ptr, color_cols, index })
    }

    /// Entries of the coordinate block.
    pub fn nnz(&self) -> usize {
        self.row.len()
    }

    /// Structural entries of `A`.
    pub fn annz(&self) -> usize {
        self.arow.len()
    }

    pub fn colors(&self) -> usize {
        self.color_ptr.len() - 1
    }

    /// Index of entry `(i, j)` of the coordinate block (panics outside the pattern: a pattern
    /// that misses an entry the kernels write is a bug, caught by the tests' dense comparison).
    #[inline]
    pub fn find(&self, i: usize, j: usize) -> usize {
        if !self.index.is_empty() {
            let e = self.index[i * self.n + j];
            if e != u32::MAX {
                return e as usize;
            }
        }
        let (a, b) = (self.col_ptr[j], self.col_ptr[j + 1]);
        a + self.row[a..b].binary_search(&i).unwrap_or_else(|_| panic!("entry ({i}, {j}) outside the sparse pattern"))
    }

    /// `(row, column)` of every coordinate entry, in value order.
    pub fn entries(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.n).flat_map(move |j| self.row[self.col_ptr[j]..self.col_ptr[j + 1]].iter().map(move |&i| (i, j)))
    }

    /// `(constraint row, column)` of every structural entry of `A`, in value order.
    pub fn a_entries(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.n).flat_map(move |j| self.arow[self.acol_ptr[j]..self.acol_ptr[j + 1]].iter().map(move |&r| (r, j)))
    }
}

/// Values of the structure in a `Pattern`: `M`, `K`, `C` (coordinate block) and `A`,
/// `db/dqd` (structural entries of `A`), plus an n-long scratch.
#[derive(Debug, Clone)]
pub struct Structure {
    pub pattern: Pattern,
    pub m: Vec<f64>,
    pub k: Vec<f64>,
    pub c: Vec<f64>,
    pub a: Vec<f64>,
    pub bv: Vec<f64>,
    /// What the top-right block adds to `A^T` (in `A`'s pattern): `-dQ/dlambda`, the forces
    /// that read the multipliers (joint friction; `fill_multiplier_terms`), zero without them.
    pub af: Vec<f64>,
    pub v: Vec<f64>,
}

impl Structure {
    pub fn new(pattern: Pattern) -> Structure {
        let (nnz, annz, n) = (pattern.nnz(), pattern.annz(), pattern.n);
        Structure { pattern, m: vec![0.0; nnz], k: vec![0.0; nnz], c: vec![0.0; nnz], a: vec![0.0; annz], bv: vec![0.0; annz], af: vec![0.0; annz], v: vec![0.0; n] }
    }

    /// `out = X x` for a coordinate-block value array `vals` (`M`, `K` or `C`).
    pub fn mul(&self, vals: &[f64], x: &[f64], out: &mut [f64]) {
        self.mul_add(vals, x, out, false);
    }

    /// `out (+)= X x` (`add`: accumulate into `out`).
    pub fn mul_add(&self, vals: &[f64], x: &[f64], out: &mut [f64], add: bool) {
        let p = &self.pattern;
        if !add {
            out[..p.n].fill(0.0);
        }
        for j in 0..p.n {
            let xj = x[j];
            if xj != 0.0 {
                for e in p.col_ptr[j]..p.col_ptr[j + 1] {
                    out[p.row[e]] += vals[e] * xj;
                }
            }
        }
    }

    /// `out = A x` (m) from the structural entries.
    pub fn mul_a(&self, x: &[f64], out: &mut [f64]) {
        let p = &self.pattern;
        out[..p.m].fill(0.0);
        for j in 0..p.n {
            let xj = x[j];
            if xj != 0.0 {
                for e in p.acol_ptr[j]..p.acol_ptr[j + 1] {
                    out[p.arow[e]] += self.a[e] * xj;
                }
            }
        }
    }

    /// Largest `|M_ij|` (the scale of the multiplier block's regularization).
    pub fn mass_scale(&self) -> f64 {
        self.m.iter().fold(0.0f64, |s, v| s.max(v.abs())).max(1e-300)
    }
}

/// `M` from the body blocks of the last `mass_and_forces` (as `dynamics::dense_mass_into`).
pub fn fill_mass(model: &Model, data: &Data, s: &mut Structure) {
    s.m.fill(0.0);
    let (p, out) = (&s.pattern, &mut s.m);
    for (body, bd) in model.bodies.iter().zip(&data.bodies) {
        let o = body.offset;
        body.dense_block(bd, &mut |i, j, v| out[p.find(o + i, o + j)] = v);
    }
}

/// The bodies' and the loads' analytic stiffness `K` (as `dynamics::stiffness_into`).
pub fn fill_stiffness(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], s: &mut Structure) {
    s.k.fill(0.0);
    let (p, out) = (&s.pattern, &mut s.k);
    for (body, bd) in model.bodies.iter().zip(&data.bodies) {
        let o = body.offset;
        body.tangent(bd, q, qd, &mut |i, j, v| out[p.find(o + i, o + j)] += v, &mut |_, _, _| {});
    }
    // within the clique of the force's markers and what it reads (`force_coords`)
    crate::dynamics::add_force_stiffness(model, data, q, qd, &mut |i, j, v| out[p.find(i, j)] += v);
}

/// `A`'s structural entries from the segment form of the last `dynamics::constraints`.
pub fn fill_a(data: &Data, s: &mut Structure) {
    for (a, &k) in s.a.iter_mut().zip(&s.pattern.aseg) {
        *a = data.ajac.vals[k];
    }
}

/// `-dQ/dlambda` of the joint friction at the multipliers `lam` and `(q, qd)` into `s.af`
/// (`FrictionWork::add_multiplier_jacobian`; nothing without friction). A friction element's
/// generalized direction lies on its joint's bodies, so its entries are in `A`'s pattern.
pub fn fill_multiplier_terms(model: &Model, data: &mut Data, q: &[f64], qd: &[f64], lam: &[f64], s: &mut Structure) {
    let Some(w) = data.friction.as_mut() else { return };
    s.af.fill(0.0);
    let (p, af) = (&s.pattern, &mut s.af);
    w.add_multiplier_jacobian(&model.forces, &model.bodies, q, qd, lam, &mut |r, j, v| {
        let e = (p.acol_ptr[j]..p.acol_ptr[j + 1]).find(|&e| p.arow[e] == r).expect("a friction element's direction lies on its joint's bodies");
        af[e] += v;
    });
}

/// Everything at `(t, q, qd)`: `M`, `K`, `A`, then `C`, `db/dqd` (as the dense `structure`).
pub fn fill_structure(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], s: &mut Structure) {
    mass_and_forces(model, data, t, q, qd);
    fill_mass(model, data, s);
    fill_stiffness(model, data, q, qd, s);
    constraints(model, data, t, q, qd, false);
    fill_a(data, s);
    fill_velocity_terms(model, data, t, q, qd, s);
}

/// The stiffness of the constrained linearization at `(t, q, qd)` with the acceleration `qdd`
/// and multipliers `lambda` held: `K_eff = -d/dq (Q(q, qd) - M(q) qdd - A(q)^T lambda)`, by
/// central differences in `q` (steps `eps^(1/3) max(|q_j|, 1e-2)`, as `System.jac`'s), one
/// pair of evaluations per colour of a pattern built with `hessian = true`. On the tangent
/// space of the constraints (`N^T K_eff N`) it is `-N^T M dqdd/dq N`, the stiffness of the
/// dense modal analysis. `out` has the pattern's coordinate entries; `f` is an n-long scratch.
/// Leaves `data` at a perturbed state.
pub fn fill_linearized_stiffness(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], lambda: &[f64], p: &Pattern, qv: &mut [f64], f: &mut [f64], out: &mut [f64]) {
    let c = f64::EPSILON.cbrt();
    let step = |x: f64| {
        let h = c * x.abs().max(1e-2);
        (x + h) - x
    };
    qv.copy_from_slice(q);
    for col in 0..p.colors() {
        let cols = &p.color_cols[p.color_ptr[col]..p.color_ptr[col + 1]];
        for sign in [1.0, -1.0] {
            for &j in cols {
                qv[j] = q[j] + sign * step(q[j]);
            }
            mass_and_forces(model, data, t, qv, qd);
            constraints(model, data, t, qv, qd, false);
            // f = M qdd + A^T lambda - Q  (= -F)
            mass_times(model, data, qdd, f);
            for i in 0..model.n {
                f[i] -= data.force[i];
            }
            for (r, &l) in lambda.iter().enumerate() {
                data.ajac.add_row(r, l, f);
            }
            for &j in cols {
                let h2 = 2.0 * step(q[j]);
                for e in p.col_ptr[j]..p.col_ptr[j + 1] {
                    let v = f[p.row[e]];
                    out[e] = if sign > 0.0 { v } else { (out[e] - v) / h2 };
                }
            }
        }
        for &j in cols {
            qv[j] = q[j];
        }
    }
}


/// The sparse Newton matrices of an implicit method: `Structure`, the positions of every entry
/// (in band order), the real LU (band or static, `Factorization`) and, for Radau IIA, the
/// complex one; all sized once.
#[derive(Debug, Clone)]
pub struct BandNewton {
    pub s: Structure,
    pub layout: BandLayout,
    /// Band index of each coordinate entry, of each `A` entry at `(n + r, j)` and its transpose
    /// at `(j, n + r)`, and of the multiplier diagonal.
    cc: Vec<usize>,
    ar: Vec<usize>,
    at: Vec<usize>,
    diag: Vec<usize>,
    real: Lu<f64>,
    cplx: Option<Lu<C64>>,
    xr: Vec<f64>,
    xc: Vec<C64>,
    /// Right-hand sides of the first-order solves (`solve_first_order_*`): real and imaginary
    /// parts, n + m each, and two n-long scratch vectors.
    fr: Vec<f64>,
    fi: Vec<f64>,
    vr: Vec<f64>,
    vi: Vec<f64>,
}

impl BandNewton {
    /// Bytes of the factorization's storage (real, and complex when `complex`) for a layout.
    pub fn bytes(layout: &BandLayout, complex: bool, kind: Factorization) -> u64 {
        let (n, hb) = (layout.size, layout.hb);
        let lu = match kind {
            Factorization::Band => BandLu::<f64>::bytes(n, hb, hb) + if complex { BandLu::<C64>::bytes(n, hb, hb) } else { 0 },
            Factorization::Static => StaticLu::<f64>::bytes(n) + if complex { StaticLu::<C64>::bytes(n) } else { 0 },
        };
        lu + 24 * n as u64
    }

    /// The matrices of a plan's structure, factored as it says.
    pub fn new(plan: SparsePlan) -> BandNewton {
        let SparsePlan { structure: s, layout, order, complex, .. } = plan;
        let n = s.pattern.n;
        let size = layout.size;
        let real = Lu::<f64>::new(&layout, order.clone());
        let perm = &layout.perm;
        let cc = s.pattern.entries().map(|(i, j)| real.index(perm[i], perm[j])).collect();
        let ar = s.pattern.a_entries().map(|(r, j)| real.index(perm[n + r], perm[j])).collect();
        let at = s.pattern.a_entries().map(|(r, j)| real.index(perm[j], perm[n + r])).collect();
        let diag = (0..s.pattern.m).map(|r| real.index(perm[n + r], perm[n + r])).collect();
        let cplx = complex.then(|| Lu::<C64>::new(&layout, order));
        let z = |k: usize| vec![0.0; k];
        BandNewton { s, layout, cc, ar, at, diag, real, cplx, xr: z(size), xc: vec![C64::default(); if complex { size } else { 0 }], fr: z(size), fi: z(size), vr: z(n), vi: z(n) }
    }

    /// Whether the factorization is the static sparse LU.
    pub fn is_static(&self) -> bool {
        matches!(self.real, Lu::Static(_))
    }

    /// Assemble `[M + gc C + gk K, A^T; A - gc db/dqd, reg I]` and factor it. `false`: singular.
    pub fn factor_real(&mut self, gk: f64, gc: f64, reg: f64) -> bool {
        // a kept pivot sequence that fails its check asks for one more assembly (`static_lu`)
        for _ in 0..2 {
            let s = &self.s;
            self.real.clear();
            let ab = self.real.values_mut();
            for (e, &pos) in self.cc.iter().enumerate() {
                ab[pos] = s.m[e] + gc * s.c[e] + gk * s.k[e];
            }
            for (e, (&pr, &pt)) in self.ar.iter().zip(&self.at).enumerate() {
                ab[pr] = s.a[e] - gc * s.bv[e];
                ab[pt] = s.a[e] + s.af[e];
            }
            for &pos in &self.diag {
                ab[pos] = reg;
            }
            match self.real.factor() {
                Factored::Ok => return true,
                Factored::Singular => return false,
                Factored::Reorder => {}
            }
        }
        false
    }

    /// The same with complex coefficients `gk`, `gc` (Radau IIA's complex eigenvalue).
    pub fn factor_complex(&mut self, gk: C64, gc: C64, reg: f64) -> bool {
        for _ in 0..2 {
            let s = &self.s;
            let lu = self.cplx.as_mut().expect("a complex factorization was asked for at construction");
            lu.clear();
            let ab = lu.values_mut();
            for (e, &pos) in self.cc.iter().enumerate() {
                ab[pos] = C64::new(s.m[e] + gc.re * s.c[e] + gk.re * s.k[e], gc.im * s.c[e] + gk.im * s.k[e]);
            }
            for (e, (&pr, &pt)) in self.ar.iter().zip(&self.at).enumerate() {
                ab[pr] = C64::new(s.a[e] - gc.re * s.bv[e], -gc.im * s.bv[e]);
                ab[pt] = C64::new(s.a[e] + s.af[e], 0.0);
            }
            for &pos in &self.diag {
                ab[pos] = C64::new(reg, 0.0);
            }
            match lu.factor() {
                Factored::Ok => return true,
                Factored::Singular => return false,
                Factored::Reorder => {}
            }
        }
        false
    }

    /// `x <- H^-1 x` with the real factors (`x`: n + m, coordinates then multipliers).
    pub fn solve_real(&mut self, x: &mut [f64]) {
        let perm = &self.layout.perm;
        for (i, &p) in perm.iter().enumerate() {
            self.xr[p] = x[i];
        }
        self.real.solve(&mut self.xr);
        for (i, &p) in perm.iter().enumerate() {
            x[i] = self.xr[p];
        }
    }

    /// `out (+)= X x` for an `A`-pattern value array (`A` or `db/dqd`), `sign` times.
    fn mul_a_into(&self, vals: &[f64], sign: f64, x: &[f64], out: &mut [f64], add: bool) {
        let p = &self.s.pattern;
        if !add {
            out[..p.m].fill(0.0);
        }
        for j in 0..p.n {
            let xj = sign * x[j];
            if xj != 0.0 {
                for e in p.acol_ptr[j]..p.acol_ptr[j + 1] {
                    out[p.arow[e]] += vals[e] * xj;
                }
            }
        }
    }

    /// RADAU5's real solve with the structured Jacobian `J = [[0, I], [Jq, Jv]]`
    /// (`M Jq + A^T . = -K`, `A Jq = 0`; `M Jv + A^T . = -C`, `A Jv = db/dqd`):
    /// `(g I - J) [x1; x2] = [r1; r2]` (`x`: 2n, in place) through the saddle point
    /// `[M + C/g + K/g^2, A^T; A - Bv/g, 0] [x1; mu] = [M (r2 + g r1) + C r1; A (r2 + g r1) - Bv r1] / g^2`,
    /// `x2 = g x1 - r1` (no product with the dense `Jq`, `Jv`). Needs `factor_real(1/g^2, 1/g, .)`.
    pub fn solve_first_order_real(&mut self, g: f64, x: &mut [f64]) {
        let (n, m) = (self.s.pattern.n, self.s.pattern.m);
        let (r1, r2) = x.split_at_mut(n);
        let mut fr = std::mem::take(&mut self.fr);
        let mut vr = std::mem::take(&mut self.vr);
        for i in 0..n {
            vr[i] = r2[i] + g * r1[i];
        }
        self.s.mul_add(&self.s.m, &vr, &mut fr[..n], false);
        self.s.mul_add(&self.s.c, r1, &mut fr[..n], true);
        self.mul_a_into(&self.s.a, 1.0, &vr, &mut fr[n..n + m], false);
        self.mul_a_into(&self.s.bv, -1.0, r1, &mut fr[n..n + m], true);
        let s = 1.0 / (g * g);
        for v in fr.iter_mut() {
            *v *= s;
        }
        self.solve_real(&mut fr);
        for i in 0..n {
            let x1 = fr[i];
            r2[i] = g * x1 - r1[i];
            r1[i] = x1;
        }
        self.fr = fr;
        self.vr = vr;
    }

    /// The same with a complex `g` (RADAU5's complex eigenvalue; `xr`, `xi`: 2n each); needs
    /// `factor_complex(1/g^2, 1/g, .)`.
    pub fn solve_first_order_complex(&mut self, g: C64, xr: &mut [f64], xi: &mut [f64]) {
        let (n, m) = (self.s.pattern.n, self.s.pattern.m);
        let (r1r, r2r) = xr.split_at_mut(n);
        let (r1i, r2i) = xi.split_at_mut(n);
        let (mut fr, mut fi) = (std::mem::take(&mut self.fr), std::mem::take(&mut self.fi));
        let (mut vr, mut vi) = (std::mem::take(&mut self.vr), std::mem::take(&mut self.vi));
        for i in 0..n {
            vr[i] = r2r[i] + g.re * r1r[i] - g.im * r1i[i];
            vi[i] = r2i[i] + g.re * r1i[i] + g.im * r1r[i];
        }
        for (f, v, r1) in [(&mut fr, &vr, &*r1r), (&mut fi, &vi, &*r1i)] {
            self.s.mul_add(&self.s.m, v, &mut f[..n], false);
            self.s.mul_add(&self.s.c, r1, &mut f[..n], true);
            self.mul_a_into(&self.s.a, 1.0, v, &mut f[n..n + m], false);
            self.mul_a_into(&self.s.bv, -1.0, r1, &mut f[n..n + m], true);
        }
        // times 1 / g^2
        let g2 = g * g;
        let d = g2.re * g2.re + g2.im * g2.im;
        let (sr, si) = (g2.re / d, -g2.im / d);
        for k in 0..n + m {
            let (a, b) = (fr[k], fi[k]);
            fr[k] = a * sr - b * si;
            fi[k] = a * si + b * sr;
        }
        self.solve_complex(&mut fr, &mut fi);
        for i in 0..n {
            let (x1r, x1i) = (fr[i], fi[i]);
            r2r[i] = g.re * x1r - g.im * x1i - r1r[i];
            r2i[i] = g.re * x1i + g.im * x1r - r1i[i];
            r1r[i] = x1r;
            r1i[i] = x1i;
        }
        self.fr = fr;
        self.fi = fi;
        self.vr = vr;
        self.vi = vi;
    }

    /// `(xr + i xi) <- H^-1 (xr + i xi)` with the complex factors.
    pub fn solve_complex(&mut self, xr: &mut [f64], xi: &mut [f64]) {
        let perm = &self.layout.perm;
        for (i, &p) in perm.iter().enumerate() {
            self.xc[p] = C64::new(xr[i], xi[i]);
        }
        self.cplx.as_mut().expect("complex factors").solve(&mut self.xc);
        for (i, &p) in perm.iter().enumerate() {
            xr[i] = self.xc[p].re;
            xi[i] = self.xc[p].im;
        }
    }
}
