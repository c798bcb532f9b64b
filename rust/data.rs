//! Per-call workspace: every buffer a kernel writes, sized once from the model. Kernels take
//! `&Model, &mut Data` and never allocate.

use faer::dyn_stack::{MemBuffer, StackReq};
use faer::linalg::svd::{svd_scratch, ComputeSvdVectors};
use faer::diag::Diag;
use faer::{Mat, Par};

use crate::body::BodyKind;
use crate::model::Model;

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
}

/// Per-body mass blocks and factor, in body coordinates `[x, y, theta, q_f]`.
#[derive(Debug, Clone)]
pub struct BodyData {
    /// Reference block `[[m_RR, m_Rtheta], [., m_thetatheta]]` (symmetric 3x3).
    pub m_rr: [[f64; 3]; 3],
    /// `[m_Rf; m_thetaf]`, 3 x n_f row-major (beams).
    pub m_rf: Vec<f64>,
    /// `X = M_rf L_ff^-T`, 3 x n_f row-major (beams).
    pub x: Vec<f64>,
    /// Lower Cholesky factor of the reference block's Schur complement `m_rr - X X^T`
    /// (rigid bodies: of the whole 3x3 mass matrix).
    pub ls: [[f64; 3]; 3],
    /// Scratch of length n_f: `i_rf + M_ff^tr q_f`.
    pub w: Vec<f64>,
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
    pub tolerance: RankTolerance,
    pub stabilization: Stabilization,
    pub rank_info: RankInfo,
}

impl Data {
    pub fn new(model: &Model) -> Data {
        let (n, m) = (model.n, model.m);
        let k = n.min(m);
        let bodies = model
            .bodies
            .iter()
            .map(|b| {
                let n_f = match &b.kind {
                    BodyKind::Rigid(_) => 0,
                    BodyKind::Beam(beam) => beam.n_f,
                };
                BodyData {
                    m_rr: [[0.0; 3]; 3],
                    m_rf: vec![0.0; 3 * n_f],
                    x: vec![0.0; 3 * n_f],
                    ls: [[0.0; 3]; 3],
                    w: vec![0.0; n_f],
                }
            })
            .collect();
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
            tolerance: RankTolerance::default(),
            stabilization: Stabilization::None,
            rank_info: RankInfo::default(),
        }
    }
}
