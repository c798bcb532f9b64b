"""Static equilibrium of a compiled system (:meth:`ukflex.System.equilibrium` delegates here):
Newton on the force balance and the constraints, dense below ``System.SPARSE_MODES_MIN``
coordinates, with a sparse tangent above."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from ..arguments import count, positive, real, real_array
from ..errors import SolverError

__all__ = ["Equilibrium", "equilibrium"]


@dataclass
class Equilibrium:
    """A static equilibrium (:meth:`ukflex.System.equilibrium`)."""

    q: np.ndarray
    multipliers: np.ndarray
    iterations: int
    force_residual: float
    position_residual: float


def equilibrium(
    system: Any,
    t: Optional[float] = None,
    q: Optional[np.ndarray] = None,
    tol: float = 1e-10,
    max_iterations: int = 50,
) -> Equilibrium:
    """Static equilibrium at time ``t`` (drivers held at their values there), from ``q``.

    Newton on ``Q(t, q, 0) = A(q)^T lambda`` and ``Phi(t, q) = 0`` (zero velocities, so the
    applied, elastic, spring and gravity forces balance the constraint forces), with the
    tangent of both sides by central differences of the core's ``Q`` and ``A`` and a
    backtracking line search on the residual.  Use it to start a run from a preloaded state
    (``simulate(system, T, q0=eq.q, qd0=zeros)``) or to check a structure's static deflection.

    Parameters
    ----------
    t, q : optional
        Time and starting positions (default ``t0``, ``q0``).
    tol : float
        Converged when the Newton step is below ``tol`` (per coordinate, relative to
        ``max(1, |q|)``), ``max |Phi| <= tol`` and the forces balance to 1e-8 of
        ``max |Q|``.
    max_iterations : int
        Newton iterations.

    Returns
    -------
    Equilibrium
        ``q``, ``multipliers`` (with ``M qdd + A^T lambda = Q``), ``iterations``,
        ``force_residual`` (``max |Q - A^T lambda|``), ``position_residual``.

    Raises
    ------
    ValueError, NonFiniteError
        Bad arguments.
    SolverError
        No convergence (e.g. no equilibrium: a free body under gravity).
    """
    n, m = system.n_coords, system.n_constraints
    t = system.t0 if t is None else real("t", t)
    q = np.array(system.q0, dtype=float) if q is None else real_array("q", q, (n,))
    tol = positive("tol", tol)
    max_iterations = count("max_iterations", max_iterations)
    zero = np.zeros(n)
    if n >= system.SPARSE_MODES_MIN:
        residual, step_of, lam = _sparse_parts(system, t, q)
    else:
        lam = np.zeros(m)

        def residual(q, lam):
            A = np.asarray(system.A(q)).reshape(m, n)
            return np.concatenate([np.asarray(system.Q(t, q, zero)) - A.T @ lam, np.asarray(system.phi(t, q))])

        def step_of(q, lam, r):
            J = np.zeros((n + m, n + m))
            for j in range(n):
                h = 1e-6 * max(1.0, abs(q[j]))
                qp, qm = q.copy(), q.copy()
                qp[j] += h
                qm[j] -= h
                J[:, j] = (residual(qp, lam) - residual(qm, lam)) / (2.0 * h)
            A = np.asarray(system.A(q)).reshape(m, n)
            J[:n, n:] = -A.T
            return np.linalg.lstsq(J, -r, rcond=None)[0]

    r = residual(q, lam)
    for it in range(1, int(max_iterations) + 1):
        step = step_of(q, lam, r)
        alpha, norm0 = 1.0, np.linalg.norm(r)
        while True:  # backtracking on |R|
            q_new, lam_new = q + alpha * step[:n], lam + alpha * step[n:]
            r_new = residual(q_new, lam_new)
            if np.linalg.norm(r_new) <= (1.0 - 1e-4 * alpha) * norm0 or alpha < 1e-4:
                break
            alpha *= 0.5
        q, lam, r = q_new, lam_new, r_new
        if not np.all(np.isfinite(r)):
            break
        small = np.all(np.abs(alpha * step[:n]) <= tol * np.maximum(1.0, np.abs(q)))
        force_scale = max(float(np.max(np.abs(np.asarray(system.Q(t, q, zero))), initial=0.0)), 1e-300)
        balanced = np.max(np.abs(r[:n]), initial=0.0) <= 1e-8 * force_scale
        if small and balanced and np.max(np.abs(r[n:]), initial=0.0) <= tol:
            return Equilibrium(q, lam, it, float(np.max(np.abs(r[:n]), initial=0.0)),
                               float(np.max(np.abs(r[n:]), initial=0.0)))
    raise SolverError(
        f"equilibrium: no convergence after {max_iterations} Newton iteration(s) at t = {t}: "
        f"max |Q - A^T lambda| = {np.max(np.abs(r[:n]), initial=0.0):.3e}, max |Phi| = "
        f"{np.max(np.abs(r[n:]), initial=0.0):.3e} (a scene without a static equilibrium, e.g. a free body "
        "under gravity, or a start too far from it)")

def _sparse_parts(system: Any, t: float, q: np.ndarray):
    """``equilibrium`` above :attr:`SPARSE_MODES_MIN` coordinates: ``(residual, step,
    lam0)`` for the same Newton iteration and line search, with the sparse tangent
    ``[-K, -A^T; A, 0]`` (``K = -d/dq (Q - A^T lambda)`` at the iterate's multipliers: the
    core's coloured differences, O(n)) and a sparse LU.  The multipliers start from the UK
    solution at rest (the constraint forces that hold the start; from zero, a mechanism
    whose links carry their weight only through its joints has a singular first tangent,
    which the dense path passes with a least-squares step); a tangent still exactly singular
    is shifted by 1e-10 of its scale on the stiffness block and 1e-12 on the multiplier
    block."""
    from scipy.sparse import bmat, coo_array, identity
    from scipy.sparse.linalg import splu

    n, m = system.n_coords, system.n_constraints
    zero = np.zeros(n)

    def parts(q, lam, stiffness):
        lin = system.core.linearization(t, q, zero, zero, lam, stiffness)
        A = coo_array((np.asarray(lin["A"]), (np.asarray(lin["a_rows"]), np.asarray(lin["a_cols"]))), shape=(m, n)).tocsr()
        K = coo_array((np.asarray(lin["K"]), (np.asarray(lin["rows"]), np.asarray(lin["cols"]))), shape=(n, n)).tocsc()
        return A, K

    def residual(q, lam):
        A, _ = parts(q, lam, False)
        return np.concatenate([np.asarray(system.Q(t, q, zero)) - A.T @ lam, np.asarray(system.phi(t, q))])

    def step_of(q, lam, r):
        A, K = parts(q, lam, True)
        J = bmat([[-K, -A.T], [A, None]], format="csc") if m else (-K).tocsc()
        try:
            return splu(J).solve(-r)
        except RuntimeError:  # exactly singular: a neutral direction or redundant rows
            scale = max(float(abs(K).max()) if K.nnz else 0.0, float(abs(A).max()) if A.nnz else 0.0, 1e-300)
            shift = -K - 1e-10 * scale * identity(n)
            Js = bmat([[shift, -A.T], [A, -1e-12 * scale * identity(m)]], format="csc") if m else shift.tocsc()
            return splu(Js).solve(-r)

    lam = np.asarray(system.multipliers(t, q, zero), dtype=float) if m else np.zeros(0)
    return residual, step_of, lam
