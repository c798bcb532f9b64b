//! Per-call workspace: every buffer a kernel writes, sized once from the model. Kernels take
//! `&Model, &mut Data` and never allocate.

use faer::dyn_stack::{MemBuffer, StackReq};
use faer::linalg::svd::{svd_scratch, ComputeSvdVectors};
use faer::diag::Diag;
use faer::{Mat, Par};

use crate::body::BodyData;
use crate::model::Model;
use crate::small_svd::QrJacobi;

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
    /// `A = Phi_q`, m x n row-major.
    pub jac: Vec<f64>,
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
}

impl Data {
    pub fn new(model: &Model) -> Data {
        let (n, m) = (model.n, model.m);
        let k = n.min(m);
        let bodies = model.bodies.iter().map(|b| b.new_data()).collect();
        let req = if m > 0 {
            svd_scratch::<f64>(n, m, ComputeSvdVectors::Thin, ComputeSvdVectors::Thin, Par::Seq, Default::default())
        } else {
            StackReq::EMPTY
        };
        Data {
            bodies,
            force: vec![0.0; n],
            phi: vec![0.0; m],
            jac: vec![0.0; m * n],
            phi_t: vec![0.0; m],
            gamma: vec![0.0; m],
            y: vec![0.0; n],
            qdd_free: vec![0.0; n],
            qdd: vec![0.0; n],
            lambda: vec![0.0; m],
            bt: Mat::zeros(n, m),
            svd_u: Mat::zeros(n, k),
            svd_s: Diag::zeros(k),
            svd_v: Mat::zeros(m, k),
            residual: vec![0.0; m],
            coeff: vec![0.0; k],
            mem: MemBuffer::new(req),
            qrj: if m > 0 && m <= n { Some(QrJacobi::new(n, m)) } else { None },
            svd_backend: SvdBackend::default(),
            factored_with: Factored::None,
            tolerance: RankTolerance::default(),
            stabilization: Stabilization::None,
            rank_info: RankInfo::default(),
        }
    }
}
