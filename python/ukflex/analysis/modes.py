"""Modal analysis of large systems without a dense eigenproblem (``System.frequencies`` above
its crossover, ``System.max_frequency``).

The constrained linearization at a state is ``M x'' + K x + A^T mu = 0``, ``A x = 0`` with the
core's sparse ``M``, ``A`` and ``K = -d/dq (Q - M qdd - A^T lambda)`` at the state's UK
acceleration and multipliers (``_core.System.linearization``: coloured central differences,
O(n)); on the tangent space of the constraints it is the dense analysis' stiffness
``-N^T M dqdd/dq N``.  Its symmetric part gives the undamped frequencies
``omega = sign(lam) sqrt(|lam|)``.

* The lowest ``k`` modes: shift-invert Lanczos (ARPACK through ``scipy.sparse.linalg.eigsh``)
  with the saddle-point solve ``[K - sigma M, A^T; A, 0]`` (sparse LU, ``splu``) as the
  inverse: its solutions lie in the null space of ``A``, where the operator is symmetric in
  the mass inner product, so the Ritz vectors are constrained modes, mass-normalized.  The
  shift ``sigma`` sits just below zero: the ``k`` modes nearest it are the slowest ones
  (the free rigid-body modes, ``lam = 0``, included).
* The fastest mode: Lanczos on ``M^-1 K`` restricted to the constraints (the saddle-point
  solve with ``M``), ``LANCZOS_STEPS`` steps with full reorthogonalization: its largest Ritz
  value approaches ``omega_max^2`` from below (within 1e-6 on the scenes measured,
  docs/scale.md).

Budgets: ``deadline`` (a ``time.perf_counter()`` value) is checked between the stages and at
every operator application; past it :class:`BudgetExceeded` is raised naming the stage.
"""

from __future__ import annotations

import math
import time
from typing import Any, Optional, Tuple

import numpy as np

__all__ = ["BudgetExceeded", "linearization", "lowest_modes", "max_frequency"]

#: Lanczos steps of the fastest-mode estimate
LANCZOS_STEPS = 40


class BudgetExceeded(Exception):
    """A wall-time budget ran out inside the modal analysis (``stage`` names where)."""

    def __init__(self, stage: str):
        super().__init__(f"the wall-time budget ran out in {stage}")
        self.stage = stage


def _check(deadline: Optional[float], stage: str) -> None:
    if deadline is not None and time.perf_counter() > deadline:
        raise BudgetExceeded(stage)


def linearization(system, t: float, q: np.ndarray, qd: np.ndarray):
    """``(M, K, A, lin)``: the sparse mass matrix, the symmetric part of the linearized
    stiffness (both CSC, n x n), ``A`` (CSR, m x n) at ``(t, q, qd)`` and the core's dict."""
    from scipy.sparse import coo_array

    n, m = system.n_coords, system.n_constraints
    lin = system.core.linearization(float(t), np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(qd, dtype=float))
    rc = (np.asarray(lin["rows"]), np.asarray(lin["cols"]))
    M = coo_array((np.asarray(lin["M"]), rc), shape=(n, n)).tocsc()
    K = coo_array((np.asarray(lin["K"]), rc), shape=(n, n)).tocsc()
    K = ((K + K.T) * 0.5).tocsc()
    A = coo_array((np.asarray(lin["A"]), (np.asarray(lin["a_rows"]), np.asarray(lin["a_cols"]))), shape=(m, n)).tocsr()
    return M, K, A, lin


def _saddle_solver(X, A, reg: float):
    """``b -> x`` with ``[X, A^T; A, -reg I] [x; mu] = [b; 0]`` (sparse LU, factored once)."""
    from scipy.sparse import bmat, identity
    from scipy.sparse.linalg import splu

    n, m = X.shape[0], A.shape[0]
    if m == 0:
        lu = splu(X.tocsc())
        return lambda b: lu.solve(np.asarray(b, dtype=float))
    S = bmat([[X, A.T], [A, -reg * identity(m) if reg else None]], format="csc")
    lu = splu(S)
    zeros = np.zeros(m)
    return lambda b: lu.solve(np.concatenate([np.asarray(b, dtype=float), zeros]))[:n]


def _rank(system, t, q, qd) -> int:
    if system.n_constraints == 0:
        return 0
    return int(system.core.rank_info(float(t), np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(qd, dtype=float), exact=False)["rank"])


def _regularization(X, A, rank: int) -> float:
    """The multiplier block's regularization: none with full-rank rows; with redundant ones a
    small ``-reg I`` (1e-12 of ``|X| / |A|^2``: the constraint directions stay enforced to
    that order) so that the saddle-point matrix is not singular."""
    if A.shape[0] == 0 or rank >= A.shape[0]:
        return 0.0
    xs = float(abs(X).max()) if X.nnz else 1.0
    as2 = float(abs(A).max()) ** 2 if A.nnz else 1.0
    return 1e-12 * xs / max(as2, 1e-300)


def lowest_modes(system, t: float, q: np.ndarray, qd: np.ndarray, count: int, modes: bool = False,
                 deadline: Optional[float] = None) -> Any:
    """The ``count`` modes nearest zero (``omega`` ascending; with ``modes`` also the
    mass-normalized shapes, (n, count)) by shift-invert Lanczos; ``count`` is clipped to the
    degrees of freedom minus one (ARPACK needs one more)."""
    from scipy.sparse.linalg import LinearOperator, eigsh

    _check(deadline, "the modal analysis (linearization)")
    M, K, A, lin = linearization(system, t, q, qd)
    n = system.n_coords
    n_dof = n - _rank(system, t, q, qd)
    k = int(min(count, n_dof - 1))
    if k < 1:
        raise ValueError(f"count: need 1 <= count < degrees of freedom ({n_dof}) for the sparse modal analysis")
    # a shift just below zero on the scale of the slowest dynamics: the diagonal ratio
    # K_ii / M_ii (its median: the bulk of the coordinates, not the stiffest ones)
    d = np.abs(K.diagonal()) / np.maximum(M.diagonal(), 1e-300)
    d = d[d > 0]
    sigma = -1e-6 * float(np.median(d)) if d.size else -1e-6
    _check(deadline, "the modal analysis (factorization)")
    X = (K - sigma * M).tocsc()
    solve = _saddle_solver(X, A, _regularization(X, A, n - n_dof))

    def opinv(b):
        _check(deadline, "the modal analysis (Lanczos)")
        return solve(b)

    OPinv = LinearOperator((n, n), matvec=opinv, dtype=float)
    Mop = LinearOperator((n, n), matvec=lambda x: M @ x, dtype=float)
    Kop = LinearOperator((n, n), matvec=lambda x: K @ x, dtype=float)
    v0 = solve(M @ np.random.default_rng(7).standard_normal(n))
    lam, V = eigsh(Kop, k=k, M=Mop, sigma=sigma, which="LM", OPinv=OPinv, v0=v0, tol=1e-10)
    order = np.argsort(lam)
    lam, V = lam[order], V[:, order]
    omega = np.sign(lam) * np.sqrt(np.abs(lam))
    if not modes:
        return omega
    V = V / np.sqrt(np.einsum("ik,ik->k", V, M @ V))
    return omega, V


def max_frequency(system, t: float, q: np.ndarray, qd: np.ndarray, deadline: Optional[float] = None,
                  steps: int = LANCZOS_STEPS) -> float:
    """``omega_max``: the square root of the largest Ritz value of ``steps`` Lanczos steps on
    ``M^-1 K`` in the constraints' tangent space (mass inner product, full
    reorthogonalization); an estimate from below."""
    _check(deadline, "the fastest-mode estimate (linearization)")
    M, K, A, lin = linearization(system, t, q, qd)
    n = system.n_coords
    rank = _rank(system, t, q, qd)
    n_dof = n - rank
    if n_dof == 0:
        return 0.0
    _check(deadline, "the fastest-mode estimate (factorization)")
    solve = _saddle_solver(M, A, _regularization(M, A, rank))
    steps = max(1, min(steps, n_dof))
    V = np.zeros((steps + 1, n))
    alpha, beta = np.zeros(steps), np.zeros(steps)
    v = solve(M @ np.random.default_rng(11).standard_normal(n))
    v /= math.sqrt(max(float(v @ (M @ v)), 1e-300))
    V[0] = v
    j_end = steps
    for j in range(steps):
        _check(deadline, "the fastest-mode estimate (Lanczos)")
        w = solve(K @ V[j])
        alpha[j] = float(w @ (M @ V[j]))
        # full reorthogonalization against every Lanczos vector, in the mass inner product
        MV = (M @ V[: j + 1].T).T
        for _ in range(2):
            w = w - V[: j + 1].T @ (MV @ w)
        Mw = M @ w
        b = math.sqrt(max(float(w @ Mw), 0.0))
        if j + 1 == steps or b <= 1e-12 * max(abs(alpha[: j + 1]).max(), 1e-300):
            j_end = j + 1
            break
        beta[j] = b
        V[j + 1] = w / b
    T = np.diag(alpha[:j_end]) + np.diag(beta[: j_end - 1], 1) + np.diag(beta[: j_end - 1], -1)
    lam = float(np.linalg.eigvalsh(T).max())
    return math.copysign(math.sqrt(abs(lam)), lam)
