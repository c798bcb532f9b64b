//! Per-call workspace: every buffer a kernel writes, sized once from the model. Kernels take
//! `&Model, &mut Data` and never allocate.

use faer::dyn_stack::{MemBuffer, StackReq};
use faer::linalg::svd::{svd_scratch, ComputeSvdVectors};
use faer::diag::Diag;
use faer::{Mat, Par};

use crate::body::BodyData;
use crate::constraint::jac::SegJac;
use crate::model::Model;
use crate::error::{Error, Result};
use crate::linalg::small_svd::QrJacobi;
use crate::sparse_uk::SparseUk;

/// Which UK correction path a `Data` uses (a build option of the System).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UkSolver {
    /// Sparse when `prefer_sparse` says it pays (measured crossover, docs/scale.md), dense
    /// otherwise.
    #[default]
    Auto,
    /// The dense pseudoinverse of `B^T` (`svd_backend`) every call.
    Dense,
    /// The band Cholesky of `A M^-1 A^T` with its full-rank certificate (`sparse_uk`); the
    /// dense rank-revealing path when the certificate fails.
    Sparse,
}

impl UkSolver {
    pub fn parse(s: &str) -> Result<UkSolver> {
        match s {
            "auto" => Ok(UkSolver::Auto),
            "dense" => Ok(UkSolver::Dense),
            "sparse" => Ok(UkSolver::Sparse),
            other => Err(Error::argument("uk_solver", format!("unknown UK solver '{other}' (use 'auto', 'dense' or 'sparse')"))),
        }
    }
}

/// Below this many constraint rows `UkSolver::Auto` stays dense: measured on the chain
/// (`cargo bench --bench scale`), sparse and dense are level at K = 4 (m = 8, 3.4 vs 3.7 us)
/// and sparse wins 2.3x at K = 8 (m = 16); the dense path keeps the small mechanisms (the
/// paper's m = 6) where its certified QR is already ~1 us. docs/scale.md.
pub const SPARSE_MIN_ROWS: usize = 8;

/// `UkSolver::Auto`: sparse when there are enough rows and the band work is well below the
/// dense `O(n m^2)` (a narrow band after RCM).
pub fn prefer_sparse(model: &Model, sp: &SparseUk) -> bool {
    let (n, m) = (model.n as f64, model.m as f64);
    model.m >= SPARSE_MIN_ROWS && 4.0 * sp.flops() < 2.0 * n * m * m
}

/// Bytes of the dense UK buffers (`B^T`, thin SVD, QR + Jacobi, faer scratch).
pub fn dense_uk_bytes(model: &Model) -> u64 {
    let (n, m) = (model.n as u64, model.m as u64);
    if m == 0 {
        return 0;
    }
    let k = n.min(m);
    let req = svd_scratch::<f64>(model.n, model.m, ComputeSvdVectors::Thin, ComputeSvdVectors::Thin, Par::Seq, Default::default());
    // the dense A (m x n), B^T (n x m), U, V, S and the QR + Jacobi buffers
    8 * (2 * n * m + n * k + m * k + k + if m <= n { n * m + 3 * m * m + n } else { 0 }) + req.size_bytes() as u64
}

/// How the UK pseudoinverse `(A F^-T)^+` is computed. Every choice is allocation free per
/// call and gives the `scipy.linalg.pinv` semantics (singular values at or below
/// `max(atol, rcond sigma_max)` dropped); see `docs/performance.md` for the measurements.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SvdBackend {
    /// Householder QR `B^T = Q R`; when `1/|R^-1|_F > max(atol, rcond |R|_F)` (a certificate
    /// that no singular value can fall below the tolerance) the pseudoinverse is the full-rank
    /// `B^+ = Q R^-T` (triangular solves); otherwise the Jacobi SVD of R as in `QrJacobi`.
    /// `rank_info` then holds the exact rank with bounds for the singular values
    /// (`RankInfo::exact == false`); `uk::exact_rank_info` computes the exact values on demand.
    #[default]
    Auto,
    /// Householder QR of `B^T` then one-sided Jacobi SVD of the m x m factor (`small_svd`),
    /// every call. Used when `m <= n`; otherwise the faer path runs.
    QrJacobi,
    /// faer's bidiagonal SVD through its scratch (`MemBuffer`) API, every call.
    Faer,
}

/// Which factorization of `B^T` is currently held in `Data` (set by `uk::factor_constraints`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Factored {
    #[default]
    None,
    /// Certified full rank: QR with `R^-1` in `qrj`.
    FullRankQr,
    /// Jacobi SVD in `qrj` (sorted values and V also in `svd_s`, `svd_v`).
    Jacobi,
    /// faer SVD in `svd_u`, `svd_s`, `svd_v`.
    Faer,
    /// Certified full-rank band Cholesky of `A M^-1 A^T` in `sparse` (`sparse_uk`).
    SparseGram,
}

/// Rank decision of the pseudoinverse: singular values below
/// `max(atol, rcond * sigma_max)` are dropped; `rcond = None` means `max(m, n) * eps`
/// (the default of `scipy.linalg.pinv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RankTolerance {
    pub rcond: Option<f64>,
    pub atol: f64,
}

impl Default for RankTolerance {
    fn default() -> Self {
        RankTolerance { rcond: None, atol: 0.0 }
    }
}

/// Constraint stabilization applied inside the acceleration kernel.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Stabilization {
    /// Plain UK (the paper): position and velocity drift are left alone.
    #[default]
    None,
    /// Baumgarte (1972): enforce `Phi_dd + 2 alpha Phi_d + beta^2 Phi = 0`, i.e.
    /// `b <- gamma - 2 alpha (A qd + Phi_t) - beta^2 Phi`. `alpha = beta` gives critical damping
    /// of the drift; values of order 1/(time scale of interest) are usual.
    Baumgarte { alpha: f64, beta: f64 },
}

/// What the last pseudoinverse found.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RankInfo {
    pub rank: usize,
    pub sigma_max: f64,
    /// Smallest singular value kept (0 if none kept).
    pub sigma_min_kept: f64,
    /// Largest singular value dropped (0 if none dropped).
    pub sigma_max_dropped: f64,
    pub tolerance: f64,
    /// `false` when the certified full-rank path ran: `rank` is exact, `sigma_max` is the upper
    /// bound `|R|_F`, `sigma_min_kept` the lower bound `1/|R^-1|_F`, `tolerance` the bound
    /// `max(atol, rcond |R|_F)`; `uk::exact_rank_info` gives the exact values.
    pub exact: bool,
}

pub struct Data {
    pub bodies: Vec<BodyData>,
    /// Generalized forces `Q(t, q, qd)` (n).
    pub force: Vec<f64>,
    /// `Phi` (m).
    pub phi: Vec<f64>,
    /// `A = Phi_q` in per-row segment form (always current after `dynamics::constraints`).
    pub ajac: SegJac,
    /// `A = Phi_q`, m x n row-major: empty until `ensure_dense_jac` (the dense UK path, the
    /// implicit integrators, `System.A`); once allocated, `dynamics::constraints` keeps it current.
    pub jac: Vec<f64>,
    pub dense_jac: bool,
    /// `Phi_t` (m).
    pub phi_t: Vec<f64>,
    /// `b = gamma` (m).
    pub gamma: Vec<f64>,
    /// `F^-1 Q` then `F^-1 Q + B^+ (b - A a)` (n).
    pub y: Vec<f64>,
    /// Unconstrained acceleration `a = M^-1 Q` (n).
    pub qdd_free: Vec<f64>,
    /// Constrained acceleration (n).
    pub qdd: Vec<f64>,
    /// Multipliers, `M qdd + A^T lambda = Q` (m).
    pub lambda: Vec<f64>,
    /// `B^T = F^-1 A^T`, n x m.
    pub bt: Mat<f64>,
    /// Thin SVD of `B^T = U S V^T`.
    pub svd_u: Mat<f64>,
    pub svd_s: Diag<f64>,
    pub svd_v: Mat<f64>,
    /// `b - A a` (m) and its image in the singular basis (min(m, n)).
    pub residual: Vec<f64>,
    pub coeff: Vec<f64>,
    pub mem: MemBuffer,
    /// QR + Jacobi SVD workspace (present when `0 < m <= n`).
    pub qrj: Option<QrJacobi>,
    pub svd_backend: SvdBackend,
    /// Which factorization is current (set by `uk::factor_constraints`).
    pub factored_with: Factored,
    pub tolerance: RankTolerance,
    pub stabilization: Stabilization,
    pub rank_info: RankInfo,
    /// The UK path asked for at build, and the sparse workspace when it is used.
    pub uk_solver: UkSolver,
    pub sparse: Option<Box<SparseUk>>,
    /// Whether the dense UK buffers (`bt`, `svd_*`, `qrj`, `mem`) are allocated: at build on
    /// the dense path, on the first certificate failure on the sparse one.
    pub dense_ready: bool,
    /// Largest allocation (bytes) a lazily sized buffer may take (`Error::Memory` above).
    pub memory_limit: u64,
}

impl Data {
    /// Workspace with the automatic UK path and no memory limit.
    pub fn new(model: &Model) -> Data {
        Data::build(model, UkSolver::Auto, u64::MAX).expect("no memory limit")
    }

    /// Workspace for the UK path `solver`; refuses (before allocating) when the buffers would
    /// take more than `memory_limit` bytes.
    pub fn build(model: &Model, solver: UkSolver, memory_limit: u64) -> Result<Data> {
        let (n, m) = (model.n, model.m);
        let sparse = match solver {
            UkSolver::Dense => None,
            _ if m == 0 => None,
            UkSolver::Sparse => Some(Box::new(SparseUk::new(model))),
            UkSolver::Auto => {
                let sp = SparseUk::new(model);
                if prefer_sparse(model, &sp) { Some(Box::new(sp)) } else { None }
            }
        };
        let hint = if sparse.is_some() { "raise memory_limit" } else { "use uk_solver='sparse' for a long chain or rope, or raise memory_limit" };
        let base = SegJac::bytes(model) + 8 * (6 * n as u64 + 8 * m as u64);
        let dense = if sparse.is_none() { dense_uk_bytes(model) } else { 0 };
        let sparse_bytes = if sparse.is_some() { SparseUk::bytes(model) } else { 0 };
        Error::check_memory("the UK workspace (constraint Jacobian and factorization buffers)", base + dense + sparse_bytes, memory_limit, hint)?;
        let bodies = model.bodies.iter().map(|b| b.new_data()).collect();
        let mut data = Data {
            bodies,
            force: vec![0.0; n],
            phi: vec![0.0; m],
            ajac: SegJac::new(model),
            jac: Vec::new(),
            dense_jac: false,
            phi_t: vec![0.0; m],
            gamma: vec![0.0; m],
            y: vec![0.0; n],
            qdd_free: vec![0.0; n],
            qdd: vec![0.0; n],
            lambda: vec![0.0; m],
            bt: Mat::zeros(0, 0),
            svd_u: Mat::zeros(0, 0),
            svd_s: Diag::zeros(0),
            svd_v: Mat::zeros(0, 0),
            residual: vec![0.0; m],
            coeff: Vec::new(),
            mem: MemBuffer::new(StackReq::EMPTY),
            qrj: None,
            svd_backend: SvdBackend::default(),
            factored_with: Factored::None,
            tolerance: RankTolerance::default(),
            stabilization: Stabilization::None,
            rank_info: RankInfo::default(),
            uk_solver: solver,
            dense_ready: false,
            sparse,
            memory_limit,
        };
        if data.sparse.is_none() {
            data.ensure_dense(model)?;
        }
        Ok(data)
    }

    /// Allocate the dense UK buffers if they are not there yet (once per workspace).
    pub fn ensure_dense(&mut self, model: &Model) -> Result<()> {
        if self.dense_ready {
            return Ok(());
        }
        let (n, m) = (model.n, model.m);
        if m > 0 && self.sparse.is_some() {
            let hint = "the sparse UK path could not certify full rank here (redundant or nearly dependent constraints) and the dense rank-revealing fallback is this large; remove redundant constraints or raise memory_limit";
            Error::check_memory("the dense UK fallback", dense_uk_bytes(model), self.memory_limit, hint)?;
        }
        self.ensure_dense_jac()?;
        let k = n.min(m);
        let req = if m > 0 {
            svd_scratch::<f64>(n, m, ComputeSvdVectors::Thin, ComputeSvdVectors::Thin, Par::Seq, Default::default())
        } else {
            StackReq::EMPTY
        };
        self.bt = Mat::zeros(n, m);
        self.svd_u = Mat::zeros(n, k);
        self.svd_s = Diag::zeros(k);
        self.svd_v = Mat::zeros(m, k);
        self.coeff = vec![0.0; k];
        self.mem = MemBuffer::new(req);
        self.qrj = if m > 0 && m <= n { Some(QrJacobi::new(n, m)) } else { None };
        self.dense_ready = true;
        Ok(())
    }

    /// Allocate the dense `m x n` copy of `A` (`jac`) if it is not there yet, filled from the
    /// segment form; from then on `dynamics::constraints` keeps it current. Refused (before
    /// allocating) above `memory_limit`.
    pub fn ensure_dense_jac(&mut self) -> Result<()> {
        if self.dense_jac {
            return Ok(());
        }
        let (m, n) = (self.ajac.m, self.ajac.n);
        let hint = "the dense m x n constraint Jacobian is this large; use DOPRI5 with uk_solver='sparse' for a long chain or rope, or raise memory_limit";
        Error::check_memory("the dense constraint Jacobian A (m x n)", 8 * m as u64 * n as u64, self.memory_limit, hint)?;
        self.jac = vec![0.0; m * n];
        self.ajac.scatter(&mut self.jac);
        self.dense_jac = true;
        Ok(())
    }

    /// Which UK path the last factorization took: "sparse" or "dense" (or "none").
    pub fn uk_path(&self) -> &'static str {
        match self.factored_with {
            Factored::SparseGram => "sparse",
            Factored::None => "none",
            _ => "dense",
        }
    }
}
