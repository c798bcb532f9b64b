//! The implicit methods' Newton matrices, dense or sparse, behind one interface: GENALPHA's
//! `[M + gamma' C + beta' K, A^T; A - gamma' db/dqd, 0]` and RADAU5M's real and complex ones
//! (`g_k = (h lambda)^2`, `g_c = h lambda`).
//!
//! * **Dense**: `M`, `K`, `C` (n x n), `A`, `db/dqd` (m x n) from the system's `structure`, the
//!   (n+m) matrices factored by dense LU (`lu.rs`); GENALPHA solves with the inverse once a
//!   factorization has served `INVERSE_AFTER` solves (small matrices only). The fastest for
//!   small systems.
//! * **Sparse**: the same matrices from `structure_sparse` in the pattern of `sparse_newton`,
//!   ordered once (RCM) and factored in band storage (`band_lu`): O(n) per read, factorization
//!   and solve for chains, ropes, cables. Where the band is wide but the elimination stays
//!   sparse (`factorization`: Radau IIA's two matrices, a hub such as A05's shaft and slider),
//!   the sparse LU with a minimum degree order and kept pivots (`static_lu`) instead.
//!
//! `LinearSolver::Auto` takes the sparse form where it is measured to win
//! (`prefer_sparse`, docs/scale.md). Both give the same matrices to the bit; their solutions
//! agree to rounding (different pivot orders).

use super::lu::{inv_solve, inverse_from_lu_cm, lu_cm, lu_cm_solve, lu_cplx, lu_cplx_solve};
use super::SecondOrderSystem;
use crate::linalg::lu_rows::{pair_solve, RowFactors};
use crate::band_lu::C64;
use crate::error::{Error, Result};
use crate::data::Data;
use crate::model::Model;
use crate::linalg::static_lu::Ordering;
use crate::sparse_newton::{newton_entries, BandLayout, BandNewton, Pattern, SparsePlan, Structure};

/// How an implicit method factors its Newton matrices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearSolver {
    /// Sparse where it pays (`prefer_sparse`), dense otherwise.
    #[default]
    Auto,
    Dense,
    Sparse,
}

impl LinearSolver {
    pub fn parse(s: &str) -> Result<LinearSolver> {
        match s {
            "auto" => Ok(LinearSolver::Auto),
            "dense" => Ok(LinearSolver::Dense),
            "sparse" => Ok(LinearSolver::Sparse),
            other => Err(Error::argument("linear_solver", format!("unknown linear solver '{other}' (use 'auto', 'dense' or 'sparse')"))),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            LinearSolver::Auto => "auto",
            LinearSolver::Dense => "dense",
            LinearSolver::Sparse => "sparse",
        }
    }
}

/// Below this size `n + m` of the Newton matrix `Auto` stays dense: measured on the ANCF wire
/// pendulum and the chain (`benches/crossover.py`, two runs, docs/scale.md "Crossovers"):
/// GENALPHA's dense path (with its inverse solves on small matrices) wins or ties up to
/// n + m ~ 70 on the wire, the band LU wins in both runs from ~100 (1.1-1.7x) ...
pub const SPARSE_NEWTON_MIN: usize = 100;
/// ... while RADAU5M (and RADAU5), with a real and a complex matrix, wins with the band LU in
/// both runs from n + m ~ 54 (1.6-1.9x; at ~40 the runs disagree, 0.4-3.5x).
pub const SPARSE_NEWTON_MIN_COMPLEX: usize = 50;

/// `Auto`: sparse when the matrix is large enough (`complex`: with the complex one of Radau
/// IIA) and its band after RCM covers at most half of it (a scene whose flexible bodies are
/// dense FFRF blocks, or a hub that couples everything, has a band as wide as the matrix: the
/// band LU would do the dense work with more bookkeeping).
pub fn prefer_sparse(layout: &BandLayout, complex: bool) -> bool {
    layout.size >= sparse_min(complex) && narrow(layout)
}

/// The smallest `n + m` at which `Auto` may take the sparse form: below it the pattern and its
/// ordering are not built (the same choice, without their cost on every run of a small scene).
fn sparse_min(complex: bool) -> usize {
    if complex { SPARSE_NEWTON_MIN_COMPLEX } else { SPARSE_NEWTON_MIN }
}

/// The band after RCM covers at most half of the matrix.
fn narrow(layout: &BandLayout) -> bool {
    2 * (2 * layout.hb + 1) <= layout.size
}

/// Up to this size the sparse LU with kept pivots (`static_lu`) may replace the dense one (its
/// order is chosen on bitset rows: O(n^3 / 64) once).
pub const STATIC_LU_MAX: usize = 256;

/// The methods whose Newton matrices may take the sparse LU with kept pivots: RADAU5M. RADAU5
/// (the same two matrices, far fewer factorizations per run: its Jacobian is kept over steps)
/// measured slower with it on the one planar scene that takes it, the continuous-beam lattice
/// 8 x 2 (132 unknowns: 1.07-1.08x the dense path's whole call, two runs;
/// `benches/planar_static_lu.py`, docs/spatial.md "A05 this round (i30-a05d)").
pub const STATIC_LU_METHODS: &[&str] = &["RADAU5M"];

/// How the sparse form factors (`pattern` in `layout`) for `method`: the band LU where the band
/// is narrow (`None`); with Radau IIA's complex matrix and a method of `STATIC_LU_METHODS`, from `SPARSE_NEWTON_MIN_COMPLEX` to
/// `STATIC_LU_MAX`, a wide band, and a minimum degree elimination of at most a quarter of the
/// dense one's multiply-adds, the sparse LU with kept pivots on that order (`Some`; A05, 64 x 64:
/// ~5 000 against ~87 000; a flexible body's dense FFRF block fills in and stays dense or banded).
pub fn static_order(pattern: &Pattern, layout: &BandLayout, complex: bool, method: &str) -> Option<Ordering> {
    let size = layout.size;
    if !complex || !STATIC_LU_METHODS.contains(&method) || narrow(layout) || !(SPARSE_NEWTON_MIN_COMPLEX..=STATIC_LU_MAX).contains(&size) {
        return None;
    }
    let order = Ordering::new(size, newton_entries(pattern, layout).into_iter());
    (4 * order.estimated_flops() <= (size * size * size / 3) as u64).then_some(order)
}

/// The sparse form's analysis of `structure` for `method`: the band layout and the factorization.
fn analyse(structure: Structure, complex: bool, method: &str) -> SparsePlan {
    let layout = BandLayout::new(&structure.pattern);
    let order = static_order(&structure.pattern, &layout, complex, method);
    SparsePlan { structure, layout, order, complex }
}

/// Whether the run takes the sparse form of `plan` when `asked`.
fn takes(plan: &SparsePlan, asked: LinearSolver, complex: bool) -> bool {
    asked == LinearSolver::Sparse || prefer_sparse(&plan.layout, complex) || plan.order.is_some()
}

/// The solve with a factorization at which GENALPHA forms its inverse (dense, small only).
pub(crate) const INVERSE_AFTER: usize = 3;
pub(crate) const INVERSE_MAX: usize = 64;

/// Dense structure and factors.
#[derive(Debug, Clone)]
struct Dense {
    n: usize,
    m: usize,
    mm: Vec<f64>,
    kk: Vec<f64>,
    cc: Vec<f64>,
    aa: Vec<f64>,
    bv: Vec<f64>,
    /// What the top-right block adds to `A^T` (m x n, as `aa`): `-dQ/dlambda` of the forces
    /// that read the multipliers (joint friction), when `has_af`.
    af: Vec<f64>,
    has_af: bool,
    /// Real matrix, column-major LU, pivots; its inverse (row-major) when `inverse`.
    lu: Vec<f64>,
    piv: Vec<usize>,
    inv: Vec<f64>,
    solves: usize,
    /// Complex matrix (row-major LU, real and imaginary parts).
    lu_cr: Vec<f64>,
    lu_ci: Vec<f64>,
    piv_c: Vec<usize>,
    /// `solve_pair`'s form of both factorizations (with `complex`, up to `PAIR_SOLVE_MAX`): the
    /// factors as compressed rows without their zeros; `pair`: in use.
    pair: bool,
    rows_h: RowFactors,
    rows_g: RowFactors,
}

/// Up to this size `n + m` RADAU5M's two solves per Newton iteration run side by side over the
/// factors' nonzeros (`NewtonMatrices::solve_pair`, `lu_rows`); larger matrices keep the two
/// sweeps of `lu.rs`, whose factorizations skip zeros from `SPARSE_UPDATE_MIN` (32) on.
const PAIR_SOLVE_MAX: usize = 31;

#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
enum Inner {
    Dense(Dense),
    Sparse(Box<BandNewton>),
}

/// The Newton matrices of one implicit run.
#[derive(Debug, Clone)]
pub struct NewtonMatrices {
    inner: Inner,
}

impl NewtonMatrices {
    /// Bytes of the dense form (`complex`: RADAU5M's second matrix; `inverse`: GENALPHA's).
    pub fn dense_bytes(n: usize, m: usize, complex: bool, inverse: bool) -> u64 {
        let (n, m) = (n as u64, m as u64);
        let nm = n + m;
        8 * (3 * n * n + 3 * m * n + nm * nm + if complex { 2 * nm * nm } else { 0 } + if complex && nm <= PAIR_SOLVE_MAX as u64 { 6 * nm * nm } else { 0 } + if inverse && nm <= INVERSE_MAX as u64 { nm * nm } else { 0 })
    }

    pub fn dense(n: usize, m: usize, complex: bool, inverse: bool) -> Self {
        let nm = n + m;
        let z = |k: usize| vec![0.0; k];
        let c = |k: usize| if complex { z(k) } else { Vec::new() };
        let pair = complex && nm <= PAIR_SOLVE_MAX;
        NewtonMatrices {
            inner: Inner::Dense(Dense {
                n,
                m,
                mm: z(n * n),
                kk: z(n * n),
                cc: z(n * n),
                aa: z(m * n),
                bv: z(m * n),
                af: z(m * n),
                has_af: false,
                lu: z(nm * nm),
                piv: vec![0; nm],
                inv: z(if inverse && nm <= INVERSE_MAX { nm * nm } else { 0 }),
                solves: 0,
                lu_cr: c(nm * nm),
                lu_ci: c(nm * nm),
                piv_c: if complex { vec![0; nm] } else { Vec::new() },
                pair,
                rows_h: if pair { RowFactors::with_capacity(nm) } else { RowFactors::default() },
                rows_g: if pair { RowFactors::with_capacity(nm) } else { RowFactors::default() },
            }),
        }
    }

    pub fn sparse(structure: Structure, complex: bool) -> Self {
        let layout = BandLayout::new(&structure.pattern);
        let plan = SparsePlan { structure, layout, order: None, complex };
        NewtonMatrices { inner: Inner::Sparse(Box::new(BandNewton::new(plan))) }
    }

    /// The Newton matrices `method` runs on with `system` (n coordinates, m rows), for the
    /// linear solver `asked`: the sparse form when asked for or when `Auto` prefers it (and the
    /// system has the sparse structure), the dense one otherwise.
    pub fn for_system<S: SecondOrderSystem>(sys: &mut S, asked: LinearSolver, complex: bool, inverse: bool, method: &str) -> Result<Self> {
        let (n, m) = (sys.n(), sys.n_constraints());
        Ok(match Self::band_for_system(sys, asked, complex, method)? {
            Some(b) => NewtonMatrices { inner: Inner::Sparse(Box::new(b)) },
            None => Self::dense(n, m, complex, inverse),
        })
    }

    /// The sparse form alone: `Some` when `asked` is `Sparse`, or `Auto` and it pays
    /// (`prefer_sparse`); `None` for the dense form. `Sparse` on a system without a sparse
    /// structure is an error.
    pub fn band_for_system<S: SecondOrderSystem>(sys: &mut S, asked: LinearSolver, complex: bool, method: &str) -> Result<Option<BandNewton>> {
        if asked == LinearSolver::Dense || (asked == LinearSolver::Auto && sys.n() + sys.n_constraints() < sparse_min(complex)) {
            return Ok(None);
        }
        let plan = match sys.sparse_structure() {
            // `Auto`: a pattern above the memory limit (a dense body of many coordinates) means the
            // dense form, whose own check then speaks
            Err(Error::Memory { .. }) if asked == LinearSolver::Auto => return Ok(None),
            Ok(Some(s)) => analyse(s, complex, method),
            Ok(None) if asked == LinearSolver::Sparse => return Err(Error::argument("linear_solver", format!("{method}: this system has no sparse structure (use 'dense' or 'auto')"))),
            Ok(None) => return Ok(None),
            Err(e) => return Err(e),
        };
        if takes(&plan, asked, complex) {
            sys.check_memory("the sparse Newton matrices (band LU)", BandNewton::bytes(&plan.layout, complex, plan.kind()))?;
            return Ok(Some(BandNewton::new(plan)));
        }
        Ok(None)
    }

    /// What `for_system` will take for the UK system of `model` (its workspace `data`):
    /// `Sparse` or `Dense` (checks the sparse form's memory; the caller checks the dense one's):
    /// the binding asks before the run where the dense matrices would not fit.
    pub fn resolve(model: &Model, data: &Data, asked: LinearSolver, complex: bool, method: &str) -> Result<LinearSolver> {
        if asked == LinearSolver::Dense || (asked == LinearSolver::Auto && model.n + model.m < sparse_min(complex)) {
            return Ok(LinearSolver::Dense);
        }
        let p = match Pattern::new(model, &data.ajac, false, data.memory_limit) {
            Err(Error::Memory { .. }) if asked == LinearSolver::Auto => return Ok(LinearSolver::Dense),
            r => r?,
        };
        let plan = analyse(Structure::new(p), complex, method);
        if takes(&plan, asked, complex) {
            Error::check_memory("the sparse Newton matrices (band LU)", BandNewton::bytes(&plan.layout, complex, plan.kind()), data.memory_limit, "raise memory_limit")?;
            return Ok(LinearSolver::Sparse);
        }
        Ok(LinearSolver::Dense)
    }

    pub fn is_sparse(&self) -> bool {
        matches!(self.inner, Inner::Sparse(_))
    }

    /// Band half-width of the sparse form (`None`: dense).
    pub fn bandwidth(&self) -> Option<usize> {
        match &self.inner {
            Inner::Sparse(b) => Some(b.layout.hb),
            Inner::Dense(_) => None,
        }
    }

    /// `M`, `K`, `C`, `A`, `db/dqd` at `(t, q, qd)`, and the multipliers' terms.
    pub fn read<S: SecondOrderSystem>(&mut self, sys: &mut S, t: f64, q: &[f64], qd: &[f64]) -> Result<bool> {
        let ok = match &mut self.inner {
            Inner::Dense(d) => sys.structure(t, q, qd, &mut d.mm, &mut d.kk, &mut d.cc, &mut d.aa, &mut d.bv)?,
            Inner::Sparse(b) => sys.structure_sparse(t, q, qd, &mut b.s)?,
        };
        self.read_multiplier_terms(sys, q, qd);
        Ok(ok)
    }

    /// `M`, `K`, `A` (and the force elements' damping in `C`) where the system's last
    /// evaluation left them, and the multipliers' terms.
    pub fn read_stiff<S: SecondOrderSystem>(&mut self, sys: &mut S, q: &[f64], qd: &[f64]) -> Result<bool> {
        let ok = match &mut self.inner {
            Inner::Dense(d) => sys.stiff_structure(q, qd, &mut d.mm, &mut d.kk, &mut d.cc, &mut d.aa)?,
            Inner::Sparse(b) => sys.stiff_structure_sparse(q, qd, &mut b.s)?,
        };
        self.read_multiplier_terms(sys, q, qd);
        Ok(ok)
    }

    /// `-dQ/dlambda` at `(q, qd)` and the system's last multipliers
    /// (`SecondOrderSystem::multiplier_terms`): the forces that read the multipliers.
    fn read_multiplier_terms<S: SecondOrderSystem>(&mut self, sys: &mut S, q: &[f64], qd: &[f64]) {
        match &mut self.inner {
            Inner::Dense(d) => d.has_af = sys.multiplier_terms(q, qd, &mut d.af),
            Inner::Sparse(b) => {
                sys.multiplier_terms_sparse(q, qd, &mut b.s);
            }
        }
    }

    /// Largest `|M_ij|`: the scale of the multiplier block's regularization.
    pub fn mass_scale(&self) -> f64 {
        match &self.inner {
            Inner::Dense(d) => d.mm.iter().fold(0.0f64, |s, v| s.max(v.abs())).max(1e-300),
            Inner::Sparse(b) => b.s.mass_scale(),
        }
    }

    /// Assemble and factor `[M + gc C + gk K, A^T; A - gc db/dqd, reg I]`. `false`: singular.
    pub fn factor_real(&mut self, gk: f64, gc: f64, reg: f64) -> bool {
        match &mut self.inner {
            Inner::Dense(d) => {
                let (n, m) = (d.n, d.m);
                let nm = n + m;
                for j in 0..n {
                    let col = &mut d.lu[j * nm..(j + 1) * nm];
                    for i in 0..n {
                        col[i] = d.mm[i * n + j] + gc * d.cc[i * n + j] + gk * d.kk[i * n + j];
                    }
                    for r in 0..m {
                        col[n + r] = d.aa[r * n + j] - gc * d.bv[r * n + j];
                    }
                }
                for r in 0..m {
                    let col = &mut d.lu[(n + r) * nm..(n + r + 1) * nm];
                    col[..n].copy_from_slice(&d.aa[r * n..(r + 1) * n]);
                    if d.has_af {
                        for (x, f) in col[..n].iter_mut().zip(&d.af[r * n..(r + 1) * n]) {
                            *x += f;
                        }
                    }
                    for s in 0..m {
                        col[n + s] = if r == s { reg } else { 0.0 };
                    }
                }
                d.solves = 0;
                let ok = lu_cm(&mut d.lu, &mut d.piv, nm);
                if ok && d.pair {
                    d.rows_h.from_cm(&d.lu, nm);
                }
                ok
            }
            Inner::Sparse(b) => b.factor_real(gk, gc, reg),
        }
    }

    /// The same with complex `gk`, `gc` (RADAU5M's complex eigenvalue).
    pub fn factor_complex(&mut self, gk: C64, gc: C64, reg: f64) -> bool {
        match &mut self.inner {
            Inner::Dense(d) => {
                let (n, m) = (d.n, d.m);
                let nm = n + m;
                let (g2r, g2i, gr, gi) = (gk.re, gk.im, gc.re, gc.im);
                for j in 0..n {
                    for i in 0..n {
                        let (mij, cij, kij) = (d.mm[i * n + j], d.cc[i * n + j], d.kk[i * n + j]);
                        d.lu_cr[i * nm + j] = mij + gr * cij + g2r * kij;
                        d.lu_ci[i * nm + j] = gi * cij + g2i * kij;
                    }
                    for r in 0..m {
                        let (arj, brj) = (d.aa[r * n + j], d.bv[r * n + j]);
                        d.lu_cr[(n + r) * nm + j] = arj - gr * brj;
                        d.lu_ci[(n + r) * nm + j] = -gi * brj;
                        d.lu_cr[j * nm + n + r] = if d.has_af { arj + d.af[r * n + j] } else { arj };
                        d.lu_ci[j * nm + n + r] = 0.0;
                    }
                }
                for r in 0..m {
                    for s in 0..m {
                        d.lu_cr[(n + r) * nm + n + s] = if r == s { reg } else { 0.0 };
                        d.lu_ci[(n + r) * nm + n + s] = 0.0;
                    }
                }
                let ok = lu_cplx(&mut d.lu_cr, &mut d.lu_ci, &mut d.piv_c, nm);
                if ok && d.pair {
                    d.rows_g.from_cplx(&d.lu_cr, &d.lu_ci, nm);
                }
                ok
            }
            Inner::Sparse(b) => b.factor_complex(gk, gc, reg),
        }
    }

    /// `x <- H^-1 x` with the real factors.
    pub fn solve_real(&mut self, x: &mut [f64]) {
        match &mut self.inner {
            Inner::Dense(d) => lu_cm_solve(&d.lu, &d.piv, d.n + d.m, x),
            Inner::Sparse(b) => b.solve_real(x),
        }
    }

    /// `out = H^-1 res` with the real factors; on the dense form of a small matrix, with its
    /// inverse from the `INVERSE_AFTER`-th solve of a factorization on (GENALPHA: a matrix that
    /// serves many steps pays the inverse back many times; the solve is then independent dot
    /// products instead of two chains of dependent updates).
    pub fn solve_real_reusing(&mut self, res: &[f64], out: &mut [f64]) {
        match &mut self.inner {
            Inner::Dense(d) => {
                let nm = d.n + d.m;
                d.solves += 1;
                if d.solves < INVERSE_AFTER || d.inv.is_empty() {
                    out.copy_from_slice(res);
                    lu_cm_solve(&d.lu, &d.piv, nm, out);
                    return;
                }
                if d.solves == INVERSE_AFTER {
                    inverse_from_lu_cm(&d.lu, &d.piv, nm, &mut d.inv);
                }
                inv_solve(&d.inv, nm, res, out);
            }
            Inner::Sparse(b) => {
                out.copy_from_slice(res);
                b.solve_real(out);
            }
        }
    }

    /// `(xr + i xi) <- H^-1 (xr + i xi)` with the complex factors.
    pub fn solve_complex(&mut self, xr: &mut [f64], xi: &mut [f64]) {
        match &mut self.inner {
            Inner::Dense(d) => lu_cplx_solve(&d.lu_cr, &d.lu_ci, &d.piv_c, d.n + d.m, xr, xi),
            Inner::Sparse(b) => b.solve_complex(xr, xi),
        }
    }

    /// RADAU5M's Newton correction: `x <- H^-1 x` with the real factors and
    /// `(xr + i xi) <- G^-1 (xr + i xi)` with the complex ones. On small dense matrices
    /// (`PAIR_SOLVE_MAX`) both triangular solves run side by side over the factors' nonzeros
    /// (`lu_rows::pair_solve`: each a latency-bound chain filling the other's waits). Measured
    /// on their own at n + m = 24 (`lu_cm_solve` then `lu_cplx_solve` against `pair_solve`):
    /// with the paper scene's pattern (188 of 552 entries kept) 1.21 -> 0.42 us, on a dense
    /// matrix 1.12 -> 1.01 us.
    pub fn solve_pair(&mut self, x: &mut [f64], xr: &mut [f64], xi: &mut [f64]) {
        match &mut self.inner {
            Inner::Dense(d) if d.pair => pair_solve(&d.rows_h, &d.piv, x, &d.rows_g, &d.piv_c, xr, xi),
            Inner::Dense(d) => {
                let nm = d.n + d.m;
                lu_cm_solve(&d.lu, &d.piv, nm, x);
                lu_cplx_solve(&d.lu_cr, &d.lu_ci, &d.piv_c, nm, xr, xi);
            }
            Inner::Sparse(b) => {
                b.solve_real(x);
                b.solve_complex(xr, xi);
            }
        }
    }

    /// RADAU5M's filtered error estimate's right-hand side into `tmp` (n + m):
    /// `[g^2 (M ev + C eq) + g M eq; A (g^2 ev + g eq)]`.
    pub fn filtered_rhs(&mut self, g: f64, eq: &[f64], ev: &[f64], tmp: &mut [f64]) {
        let g2 = g * g;
        match &mut self.inner {
            Inner::Dense(d) => {
                let (n, m) = (d.n, d.m);
                for i in 0..n {
                    let mrow = &d.mm[i * n..(i + 1) * n];
                    let crow = &d.cc[i * n..(i + 1) * n];
                    let mut s = 0.0;
                    for j in 0..n {
                        s += g2 * (mrow[j] * ev[j] + crow[j] * eq[j]) + g * mrow[j] * eq[j];
                    }
                    tmp[i] = s;
                }
                for r in 0..m {
                    let arow = &d.aa[r * n..(r + 1) * n];
                    tmp[n + r] = (0..n).map(|j| arow[j] * (g2 * ev[j] + g * eq[j])).sum();
                }
            }
            Inner::Sparse(b) => {
                let s = &mut b.s;
                let (n, m) = (s.pattern.n, s.pattern.m);
                // tmp[..n] = g^2 M ev + g M eq + g^2 C eq; scratch: s.v
                for j in 0..n {
                    s.v[j] = g2 * ev[j] + g * eq[j];
                }
                let v = std::mem::take(&mut s.v);
                s.mul(&s.m, &v, &mut tmp[..n]);
                s.mul_a(&v, &mut tmp[n..n + m]);
                s.v = v;
                let (pat, c) = (&s.pattern, &s.c);
                for j in 0..n {
                    let x = g2 * eq[j];
                    if x != 0.0 {
                        for e in pat.col_ptr[j]..pat.col_ptr[j + 1] {
                            tmp[pat.row[e]] += c[e] * x;
                        }
                    }
                }
            }
        }
    }
}
