//! The settings of the UK solve and what a factorization reports: which path (`UkSolver`),
//! which dense backend (`SvdBackend`), the rank tolerance of the pseudoinverse, the constraint
//! stabilization, the rank found (`RankInfo`) and which factorization is held (`Factored`).
//! Plain types: the workspace (`data::Data`) holds them, the kernels (`uk`) read them.

use crate::error::{Error, Result};

/// Which UK correction path a `Data` uses (a build option of the System).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UkSolver {
    /// Sparse when `data::prefer_sparse` says it pays (measured crossover, docs/scale.md), dense
    /// otherwise.
    #[default]
    Auto,
    /// The dense pseudoinverse of `B^T` (`svd_backend`) every call.
    Dense,
    /// The band Cholesky of `A M^-1 A^T` with its full-rank certificate (`uk::sparse`); the
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
    /// As `Auto`, but a rank-deficient `B` (m above `AUTO_JACOBI_MAX_ROWS`) goes through the
    /// certified complete orthogonal decomposition of `R` (`QrJacobi::cod_factor`) instead of
    /// faer's SVD: ~2x cheaper per call on A04, but off the manifold its truncation differs from
    /// the SVD's by about the drift (docs/spatial.md), so not the default.
    Cod,
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
    /// Certified rank-revealing complete orthogonal decomposition of the QR's `R` in `qrj`
    /// (`QrJacobi::cod_factor`: rank-deficient `B` without an SVD).
    Cod,
    /// Certified rank `m - 1`: the SVD's truncation by the lifted QR of `R` in `qrj`
    /// (`QrJacobi::deflate_factor`: one redundant row without an SVD).
    Deflated,
    /// Certified full-rank band Cholesky of `A M^-1 A^T` in `sparse` (`uk::sparse`).
    SparseGram,
    /// Certified full-rank envelope Cholesky of `A M^-1 A^T`, the normalization rows
    /// eliminated, in `gram` (`uk::gram`: small spatial models).
    Gram,
}

/// Rank decision of the pseudoinverse: singular values below
/// `max(atol, rcond * sigma_max)` are dropped; `rcond = None` means `max(m, n) * eps`
/// (the default of `scipy.linalg.pinv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RankTolerance {
    pub rcond: Option<f64>,
    pub atol: f64,
}

/// Spatial models without an explicit `rcond`: singular values at or below
/// `min(DRIFT_RANK_FACTOR max|Phi|, DRIFT_RANK_CAP)` (relative to `sigma_max`) are dropped as
/// well, because off the constraint manifold a redundant row's singular value grows with `|Phi|`
/// (measured at most 6e-3 `max|Phi|` relative on A04 for drifts 1e-12..1e-4: a margin of 180;
/// docs/spatial-design.md, section 5; docs/spatial.md).
pub const DRIFT_RANK_FACTOR: f64 = 1.0;
/// The most the drift raises the relative rank tolerance: a well-posed mechanism whose smallest
/// relative singular value is above it keeps full rank at any state (an inconsistent initial
/// guess included); A04's redundant value stays below it up to a drift of 1e-3, the default
/// run's drift bound.
pub const DRIFT_RANK_CAP: f64 = 1e-5;

impl RankTolerance {
    /// The relative tolerance in force: `rcond` when set; otherwise `max(m, n) eps`, raised to
    /// `min(DRIFT_RANK_FACTOR drift, DRIFT_RANK_CAP)` for a spatial model (`drift = max|Phi|` at
    /// the state).
    pub fn rcond_at(&self, n: usize, m: usize, drift: Option<f64>) -> f64 {
        let floor = (n.max(m) as f64) * f64::EPSILON;
        match (self.rcond, drift) {
            (Some(r), _) => r,
            (None, Some(d)) if d.is_finite() => floor.max((DRIFT_RANK_FACTOR * d).min(DRIFT_RANK_CAP)),
            _ => floor,
        }
    }

    /// Whether the default drift-tied tolerance decides the rank reliably at this drift (no
    /// explicit `rcond`, a spatial model, `DRIFT_RANK_FACTOR drift <= DRIFT_RANK_CAP`): a
    /// redundant row's singular value (at most 6e-3 `drift` relative on A04) is then surely
    /// dropped and a well-posed row's surely kept. The rank deficiency found at such a state is
    /// kept (`Data::redundant`) for the states where the cap binds (`redundant_rcond`).
    pub fn decides_redundancy(&self, drift: Option<f64>) -> bool {
        self.rcond.is_none() && matches!(drift, Some(d) if d.is_finite() && DRIFT_RANK_FACTOR * d <= DRIFT_RANK_CAP)
    }

    /// Where the cap binds (no explicit `rcond`, `DRIFT_RANK_FACTOR drift > DRIFT_RANK_CAP`,
    /// e.g. the stages of a long explicit step): the relative tolerance
    /// `min(DRIFT_RANK_FACTOR drift, 1)` for the smallest singular values that were redundant at
    /// the last state where the rank was decided reliably (`decides_redundancy`). They are
    /// dropped while the drift explains them; a row that stopped being redundant (a singular
    /// configuration left) grows past it and is kept. `None` where the ordinary tolerance rules.
    pub fn redundant_rcond(&self, drift: Option<f64>) -> Option<f64> {
        match (self.rcond, drift) {
            (None, Some(d)) if d.is_finite() && DRIFT_RANK_FACTOR * d > DRIFT_RANK_CAP => Some((DRIFT_RANK_FACTOR * d).min(1.0)),
            _ => None,
        }
    }

    /// This tolerance with `rcond` resolved (`rcond_at`).
    pub fn resolved(&self, n: usize, m: usize, drift: Option<f64>) -> RankTolerance {
        RankTolerance { rcond: Some(self.rcond_at(n, m, drift)), atol: self.atol }
    }
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
