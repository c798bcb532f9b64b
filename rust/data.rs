//! Per-call workspace: every buffer a kernel writes, sized once from the model. Kernels take
//! `&Model, &mut Data` and never allocate.

use faer::dyn_stack::{MemBuffer, StackReq};
use faer::linalg::svd::{svd_scratch, ComputeSvdVectors};
use faer::diag::Diag;
use faer::{Mat, Par};

use crate::body::marker3::Marker3Work;
use crate::body::BodyData;
use crate::constraint::jac::{DenseJac, SegJac};
use crate::model::Model;
use crate::error::{Error, Result};
use crate::linalg::small_svd::QrJacobi;
use crate::uk::gram::GramUk;
use crate::uk::sparse::{RowAnalysis, SparseUk};
use crate::force::friction::FrictionWork;
/// The UK settings and rank types live in `uk::settings`; the workspace holds them (and
/// `data::RankInfo`, ... stay valid paths).
pub use crate::uk::settings::{Factored, RankInfo, RankTolerance, Stabilization, SvdBackend, UkSolver};

/// Below this many constraint rows `UkSolver::Auto` stays dense: measured on the chain
/// (`cargo bench --bench scale`), sparse and dense are level at K = 4 (m = 8, 3.4 vs 3.7 us)
/// and sparse wins 2.3x at K = 8 (m = 16); the dense path keeps the small mechanisms (the
/// paper's m = 6) where its certified QR is already ~1 us. docs/scale.md.
pub const SPARSE_MIN_ROWS: usize = 8;

/// `UkSolver::Auto`: sparse when there are enough rows and the band work is well below the
/// dense `O(n m^2)` (a narrow band after RCM).
pub fn prefer_sparse(model: &Model, rows: &RowAnalysis) -> bool {
    let (n, m) = (model.n as f64, model.m as f64);
    model.m >= SPARSE_MIN_ROWS && 4.0 * rows.flops() < 2.0 * n * m * m
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

pub struct Data {
    pub bodies: Vec<BodyData>,
    /// Generalized forces `Q(t, q, qd)` (n).
    pub force: Vec<f64>,
    /// `Phi` (m).
    pub phi: Vec<f64>,
    /// `A = Phi_q` in per-row segment form (always current after `dynamics::constraints`).
    pub ajac: SegJac,
    /// `A = Phi_q`, m x n row-major: none until `ensure_dense_jac` (the dense UK path, the
    /// implicit integrators, `System.A`); once allocated, read through `jac.read(&ajac)` (or
    /// `dense_jac`), which scatters the segment form when `dynamics::constraints` changed it.
    pub jac: DenseJac,
    /// `Phi_t` (m).
    pub phi_t: Vec<f64>,
    /// `b = gamma` (m).
    pub gamma: Vec<f64>,
    /// Where drivers' motion expressions evaluate (the longest tape of the model's drivers).
    pub motion_scratch: Vec<f64>,
    /// Where loads' expressions evaluate (the longest need of the model's forces).
    pub load_scratch: Vec<f64>,
    /// Two n-long rows for the loads' analytic stiffness (`Force::add_stiffness`; empty when
    /// no force has one).
    pub load_rows: Vec<f64>,
    /// The time of the last `dynamics::mass_and_forces` (the loads' stiffness is read at the
    /// state that call left, as the bodies' blocks are).
    pub t_forces: f64,
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
    /// Spatial models: `max |Phi_i|` at the last `dynamics::constraints` (the state's drift,
    /// which sets the default rank tolerance, `uk::dense`); `None` for planar models.
    pub spatial_drift: Option<f64>,
    /// Spatial models: each body's rotations at the last `dynamics::constraints` and the
    /// buffer of a joint's two marker states (`Marker3Work`); `None` for planar models.
    pub marker3: Option<Box<Marker3Work>>,
    /// Spatial models: how many singular values of `B` the last rank decision at a nearly
    /// consistent state dropped (`RankTolerance::decides_redundancy`); far off the manifold
    /// they are dropped up to the drift (`RankTolerance::redundant_rcond`, `uk::dense`).
    pub redundant: usize,
    /// Per force element: the angle `theta - angle0` a spatial rotational spring-damper (the
    /// angle a spatial motor, `force::motor3`) read at the last evaluation, continuous over any
    /// number of turns (NaN until its first reading; `force::spatial`); unused by the other
    /// elements.
    pub turns: Vec<f64>,
    pub stabilization: Stabilization,
    pub rank_info: RankInfo,
    /// The UK path asked for at build, and the sparse workspace when it is used.
    pub uk_solver: UkSolver,
    pub sparse: Option<Box<SparseUk>>,
    /// The spatial Gram path's workspace (`uk::gram`): spatial models on the dense path with
    /// `0 < m <= n`; `None` for planar models.
    pub gram: Option<Box<GramUk>>,
    /// Whether the dense UK buffers (`bt`, `svd_*`, `qrj`, `mem`) are allocated: at build on
    /// the dense path, on the first certificate failure on the sparse one.
    pub dense_ready: bool,
    /// Largest allocation (bytes) a lazily sized buffer may take (`Error::Memory` above).
    pub memory_limit: u64,
    /// The joint friction elements' buffers (`None` without any: `uk::friction`).
    pub friction: Option<Box<FrictionWork>>,
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
                // the band pairs and the workspace only where the estimate takes the sparse path
                let rows = RowAnalysis::new(model);
                if prefer_sparse(model, &rows) { Some(Box::new(SparseUk::from_rows(model, rows))) } else { None }
            }
        };
        let hint = if sparse.is_some() { "raise memory_limit" } else { "use uk_solver='sparse' for a long chain or rope, or raise memory_limit" };
        let base = SegJac::bytes(&model.constraints, &model.bodies, m) + 8 * (6 * n as u64 + 8 * m as u64);
        let dense = if sparse.is_none() { dense_uk_bytes(model) } else { 0 };
        let sparse_bytes = if sparse.is_some() { SparseUk::bytes(model) } else { 0 };
        // the spatial Gram path where the automatic choice stays dense (an explicit 'dense' keeps
        // the pseudoinverse of `svd_backend` every call)
        let with_gram = solver == UkSolver::Auto && sparse.is_none() && model.is_spatial() && m > 0 && m <= n;
        let gram_bytes = if with_gram { GramUk::bytes(model) } else { 0 };
        Error::check_memory("the UK workspace (constraint Jacobian and factorization buffers)", base + dense + sparse_bytes + gram_bytes, memory_limit, hint)?;
        let ajac = SegJac::new(&model.constraints, &model.bodies, n, m);
        let gram = with_gram.then(|| Box::new(GramUk::new(model, &ajac)));
        let bodies = model.bodies.iter().map(|b| b.new_data()).collect();
        let mut data = Data {
            bodies,
            force: vec![0.0; n],
            phi: vec![0.0; m],
            ajac,
            jac: DenseJac::default(),
            phi_t: vec![0.0; m],
            gamma: vec![0.0; m],
            motion_scratch: vec![0.0; model.constraints.iter().map(|c| c.scratch_len()).max().unwrap_or(0)],
            load_scratch: vec![0.0; model.forces.iter().map(|f| f.scratch_len()).max().unwrap_or(0)],
            load_rows: vec![0.0; if model.forces.iter().any(|f| f.has_stiffness()) { 2 * n } else { 0 }],
            t_forces: 0.0,
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
            spatial_drift: model.is_spatial().then_some(0.0),
            marker3: model.is_spatial().then(|| Box::new(Marker3Work::new(model.bodies.len()))),
            redundant: 0,
            turns: vec![f64::NAN; model.forces.len()],
            stabilization: Stabilization::None,
            rank_info: RankInfo::default(),
            uk_solver: solver,
            dense_ready: false,
            sparse,
            gram,
            memory_limit,
            friction: FrictionWork::new(&model.forces, &model.constraints, n, m),
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
        self.qrj = if m > 0 && m <= n { Some(QrJacobi::with_unit_columns(n, m, &model.unit_columns())) } else { None };
        self.dense_ready = true;
        Ok(())
    }

    /// Allocate the dense `m x n` copy of `A` (`jac`) if it is not there yet; each read
    /// (`dense_jac`, `jac.read`) returns the segment form as it is then. Refused (before
    /// allocating) above `memory_limit`.
    pub fn ensure_dense_jac(&mut self) -> Result<()> {
        if self.jac.is_on() {
            return Ok(());
        }
        let (m, n) = (self.ajac.m, self.ajac.n);
        let hint = "the dense m x n constraint Jacobian is this large; use DOPRI5 with uk_solver='sparse' for a long chain or rope, or raise memory_limit";
        Error::check_memory("the dense constraint Jacobian A (m x n)", 8 * m as u64 * n as u64, self.memory_limit, hint)?;
        self.jac.allocate(m, n);
        Ok(())
    }

    /// The dense `A` (m x n row-major) of the last `dynamics::constraints` (allocated by
    /// `ensure_dense_jac`; empty before).
    pub fn dense_jac(&mut self) -> &[f64] {
        self.jac.read(&self.ajac)
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
