"""Udwadia-Kalaba accelerations, multipliers and the augmented (saddle-point) solve in NumPy.

Sign convention everywhere: ``M qdd + A^T lam = Q`` (the paper's eq. 42), ``A qdd = b``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
from scipy.integrate import solve_ivp

from ._blas import single_blas_thread

__all__ = ["uk_qdd", "uk_multipliers", "augmented_qdd", "inv_sqrt_spd", "uk_rank",
           "simulate_uk_numpy", "SimulationResult", "correct_initial_state", "fd_jacobian"]


def inv_sqrt_spd(M):
    """Symmetric inverse square root M^-1/2 of a symmetric positive definite matrix (eigh)."""
    w, V = np.linalg.eigh(0.5 * (M + M.T))
    if w[0] <= 0.0:
        raise np.linalg.LinAlgError(f"mass matrix not positive definite (min eig {w[0]:.3e})")
    return (V / np.sqrt(w)) @ V.T


def _pinv(D, rcond):
    if rcond is None:
        return sla.pinv(D)   # default rtol = max(m, n) * eps (relative to sigma_max)
    return sla.pinv(D, rtol=rcond)


def uk_qdd(M, Q, A, b, rcond=None):
    """UK accelerations, paper eq. (70): ``qdd = a + M^-1/2 (A M^-1/2)^+ (b - A a)``,
    ``a = M^-1 Q``, with the symmetric root of M (eigh) and scipy.linalg.pinv.

    Shapes: M (n, n), Q (n,), A (m, n), b (m,) -> qdd (n,).
    """
    Mih = inv_sqrt_spd(M)
    a = Mih @ (Mih @ Q)
    if A.shape[0] == 0:
        return a
    D = A @ Mih
    return a + Mih @ (_pinv(D, rcond) @ (b - A @ a))


def uk_rank(M, A, rcond=None):
    """Numerical rank of D = A M^-1/2 at the pinv tolerance."""
    D = A @ inv_sqrt_spd(M)
    s = np.linalg.svd(D, compute_uv=False)
    if s.size == 0:
        return 0
    tol = (max(D.shape) * np.finfo(float).eps if rcond is None else rcond) * s[0]
    return int(np.sum(s > tol))


def uk_multipliers(M, Q, A, b, rcond=None):
    """Multipliers of eq. (74) with the sign of eq. (42) (``M qdd + A^T lam = Q``):
    ``lam = (A M^-1 A^T)^+ (A a - b)``. The printed eq. (74) has the opposite sign.
    """
    Mi = np.linalg.inv(M)
    a = Mi @ Q
    S = A @ Mi @ A.T
    return _pinv(S, rcond) @ (A @ a - b)


def augmented_qdd(M, Q, A, b):
    """Saddle-point solve of eq. (42): ``[[M, A^T], [A, 0]] [qdd; lam] = [Q; b]``.

    Uses an LU solve when the KKT matrix is regular (A of full row rank) and a least-squares
    (minimum-norm multipliers) solve otherwise. Returns (qdd, lam).
    """
    n, m = M.shape[0], A.shape[0]
    K = np.zeros((n + m, n + m))
    K[:n, :n] = M
    K[:n, n:] = A.T
    K[n:, :n] = A
    rhs = np.concatenate([Q, b])
    full_rank = m == 0 or np.linalg.matrix_rank(A) == m
    if full_rank:
        x = np.linalg.solve(K, rhs)
    else:
        x = np.linalg.lstsq(K, rhs, rcond=None)[0]
    return x[:n], x[n:]


# ----------------------------------------------------------------------------------------
# initial state correction
# ----------------------------------------------------------------------------------------

def correct_initial_state(model, q0=None, qd0=None, hold=None, t0=0.0, tol=1e-12, maxit=50):
    """Make (q0, qd0) consistent: ``Phi(t0, q) = 0`` and ``A qd + Phi_t = 0``.

    Minimum-norm Gauss-Newton corrections on the free coordinates (those not in ``hold``).
    By default the elastic coordinates of every beam are held (the paper's "no initial
    deformation, no deformation rate"). ``hold`` is a boolean mask or index array (n,).
    """
    qi, qdi = model.initial_guess()
    q = np.array(qi if q0 is None else q0, dtype=float)
    qd = np.array(qdi if qd0 is None else qd0, dtype=float)
    n = model.n
    if hold is None:
        mask = np.zeros(n, dtype=bool)
        for body in model.bodies:
            if body.kind == "beam":
                mask[body.offset + 3:body.offset + body.n] = True
    else:
        hold = np.asarray(hold)
        mask = hold.astype(bool) if hold.dtype == bool else np.isin(np.arange(n), hold)
    free = ~mask
    if model.m == 0:
        return q, qd
    for _ in range(maxit):
        r = model.phi(t0, q)
        if np.linalg.norm(r) <= tol * max(1.0, np.linalg.norm(q)):
            break
        A = model.A(q)[:, free]
        q[free] -= np.linalg.lstsq(A, r, rcond=None)[0]
    else:
        raise RuntimeError(f"initial position correction did not converge (|Phi|={np.linalg.norm(r):.3e})")
    A = model.A(q)
    vr = A @ qd + model.phi_t(t0)
    qd[free] -= np.linalg.lstsq(A[:, free], vr, rcond=None)[0]
    return q, qd


# ----------------------------------------------------------------------------------------
# simulation driver for UK (NumPy)
# ----------------------------------------------------------------------------------------

@dataclass
class SimulationResult:
    t: np.ndarray
    q: np.ndarray            # (n, nt)
    qd: np.ndarray           # (n, nt)
    status: int = 0
    message: str = ""
    nfev: int = 0
    wall_time: float = 0.0
    accel_time: float = 0.0
    repartitions: int = 0
    success: bool = True
    formulation: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def y(self):
        return np.vstack([self.q, self.qd])


def fd_jacobian(fun, atol=1e-9):
    """A plain forward-difference Jacobian ``jac(t, y)`` for scipy's implicit methods.

    Why not scipy's own ``num_jac``: it multiplies the difference step of a column by 10 at
    every Jacobian evaluation in which that column shows no response, without an upper
    bound. Multibody right-hand sides have such columns exactly (the rhs is translation
    invariant: e.g. the crank pivot's x, y enter it nowhere), so after ~300 Jacobian
    evaluations (long BDF runs, tight tolerances) the step overflows to inf and the state
    passed to ``fun`` contains NaN/inf. Here the step is fixed:
    ``h_j = sqrt(eps) * max(|y_j|, atol_j)``.
    """
    atol = np.asarray(atol, dtype=float)
    sq = np.sqrt(np.finfo(float).eps)

    def jac(t, y):
        f0 = np.asarray(fun(t, y), dtype=float)
        h = sq * np.maximum(np.abs(y), np.broadcast_to(atol, y.shape))
        J = np.empty((f0.size, y.size))
        for j in range(y.size):
            yj = y.copy()
            yj[j] += h[j]
            J[:, j] = (np.asarray(fun(t, yj), dtype=float) - f0) / (yj[j] - y[j])
        return J
    return jac


def _as_model(description_or_model):
    if hasattr(description_or_model, "M") and hasattr(description_or_model, "gamma"):
        return description_or_model
    from .model import ReferenceModel
    return ReferenceModel(description_or_model)


def simulate_uk_numpy(description_or_model, t_end, method="BDF", rtol=1e-6, atol=1e-9,
                      t_eval=None, q0=None, qd0=None, t0=0.0, accel="uk",
                      **solve_ivp_kwargs):
    """Integrate ``y = [q, qd]`` with scipy's solve_ivp, accelerations from the NumPy UK
    formula (``accel="uk"``) or the augmented solve (``accel="augmented"``).

    Initial states passed in must be consistent; if None, ``initial_guess()``
    corrected by :func:`correct_initial_state` (elastic coordinates held) is used.
    """
    model = _as_model(description_or_model)
    if q0 is None or qd0 is None:
        qc, qdc = correct_initial_state(model, q0, qd0, t0=t0)
        q0 = qc if q0 is None else q0
        qd0 = qdc if qd0 is None else qd0
    n = model.n
    acc_time = [0.0]
    nfev = [0]

    def rhs(t, y):
        tic = time.perf_counter()
        q, qd = y[:n], y[n:]
        M, Q, A, b = model.terms(t, q, qd)
        if accel == "uk":
            qdd = uk_qdd(M, Q, A, b)
        else:
            qdd = augmented_qdd(M, Q, A, b)[0]
        acc_time[0] += time.perf_counter() - tic
        nfev[0] += 1
        return np.concatenate([qd, qdd])

    y0 = np.concatenate([np.asarray(q0, float), np.asarray(qd0, float)])
    if method in ("BDF", "Radau") and "jac" not in solve_ivp_kwargs:
        solve_ivp_kwargs = dict(solve_ivp_kwargs, jac=fd_jacobian(rhs, atol))
    tic = time.perf_counter()
    with single_blas_thread():
        sol = solve_ivp(rhs, (t0, t_end), y0, method=method, rtol=rtol, atol=atol,
                        t_eval=t_eval, **solve_ivp_kwargs)
    wall = time.perf_counter() - tic
    return SimulationResult(t=sol.t, q=sol.y[:n], qd=sol.y[n:], status=sol.status,
                            message=sol.message, nfev=nfev[0], wall_time=wall,
                            accel_time=acc_time[0], repartitions=0, success=sol.success,
                            formulation="uk-numpy" if accel == "uk" else "augmented-numpy",
                            extra={"njev": sol.njev, "nlu": sol.nlu})
