"""Natural frequencies and modes of a compiled system linearized at a state
(:meth:`ukflex.System.frequencies`, :meth:`ukflex.System.max_frequency` delegate here): a dense
constrained modal analysis below ``System.SPARSE_MODES_MIN`` coordinates, the sparse one of
:mod:`ukflex.analysis.modes` above."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ..arguments import count as positive_count, real, real_array
from ..errors import MemoryLimitError

__all__ = ["frequencies", "max_frequency"]


def frequencies(
    system: Any,
    t: Optional[float] = None,
    q: Optional[np.ndarray] = None,
    qd: Optional[np.ndarray] = None,
    modes: bool = False,
    count: Optional[int] = None,
    deadline: Optional[float] = None,
):
    """Natural frequencies [rad/s] of the constrained system linearized at a state.

    The UK accelerations ``qdd(t, q, qd)`` are linearized in ``q`` by the core's central
    differences (everything that depends on ``q``: elastic and spring stiffness, gravity and
    the constraint forces through the multipliers, which give a pendulum its frequency;
    the structured Jacobian of the integrators leaves the last out); the motion is restricted to the
    tangent space ``N`` of the constraints (an orthonormal basis of the null space of
    ``A(q)``, from an SVD) and the symmetric part of ``K_r = -N^T M (dqdd/dq) N`` is solved
    against ``M_r = N^T M N``.  Velocity terms (damping, gyroscopic) are left out: these are
    the undamped frequencies of the frozen state.  At an equilibrium this is the classical
    constrained modal analysis; on a moving state (a driven crank) the centrifugal stiffening
    at that state is included.

    With ``count=k`` only the ``k`` modes nearest zero (the slowest; ascending).  From
    :attr:`SPARSE_MODES_MIN` coordinates on (and ``k`` below half the degrees of freedom)
    they come without a dense eigenproblem: the core's sparse linearization (coloured
    differences, O(n); the same stiffness on the tangent space) and shift-invert Lanczos
    with a sparse saddle-point factorization (:mod:`ukflex.modes`).  All modes of a system
    that large are dense work: its ``n x n`` arrays are checked against ``memory_limit``.

    Parameters
    ----------
    t, q, qd : optional
        The state; default the system's initial state ``t0, q0, qd0``.
    modes : bool
        Also return the mode shapes in ``q`` coordinates.
    count : int, optional
        Only the ``count`` modes nearest zero.
    deadline : float, optional
        A ``time.perf_counter()`` value: past it :class:`ukflex.analysis.modes.BudgetExceeded` is
        raised naming the stage (``simulate``'s ``max_wall_time`` for ``method="auto"``).

    Returns
    -------
    omega : ndarray (k,)
        ``k = n - rank(A)`` frequencies (or ``count``) in ascending order,
        ``omega = sign(lam) sqrt(|lam|)`` for the eigenvalues ``lam`` of the reduced problem:
        a negative value is an unstable (divergent) direction, ~0 a free rigid-body motion.
    shapes : ndarray (n, k), only with ``modes=True``
        Mass-normalized (``shapes.T @ M @ shapes = I``) mode shapes.
    """
    from scipy.linalg import eigh, null_space

    n = system.n_coords
    t = system.t0 if t is None else real("t", t)
    q = system.q0 if q is None else real_array("q", q, (n,))
    qd = system.qd0 if qd is None else real_array("qd", qd, (n,))
    if count is not None:
        count = positive_count("count", count)
    large = n >= system.SPARSE_MODES_MIN
    if large and count is not None:
        from . import modes as _modes

        n_dof = n - _modes._rank(system, t, q, qd)
        if 2 * count < n_dof:
            return _modes.lowest_modes(system, t, q, qd, count, modes=modes, deadline=deadline)
    if large:
        # every mode (or most of them) of a large system: dense eigenproblem on the sparse
        # linearization (no 4n UK calls of differences); its n x n arrays checked first
        from . import modes as _modes

        _check_dense(system, "the dense modal analysis (n x n arrays)", 6 * 8 * n * n)
        Ms, Ks, As, _ = _modes.linearization(system, t, q, qd)
        M = Ms.toarray()
        N = null_space(As.toarray()) if system.n_constraints else np.eye(n)
        Mr = N.T @ M @ N
        Kr = N.T @ (Ks @ N)
    else:
        jac = np.asarray(system.core.jac(t, np.concatenate([q, qd]), "central"))
        Jq = jac[n:, :n]
        M = np.asarray(system.M(q))
        N = null_space(np.asarray(system.A(q))) if system.n_constraints else np.eye(n)
        Mr = N.T @ M @ N
        Kr = -(N.T @ (M @ Jq) @ N)
    Kr = 0.5 * (Kr + Kr.T)
    lam, V = eigh(Kr, 0.5 * (Mr + Mr.T))
    omega = np.sign(lam) * np.sqrt(np.abs(lam))
    if count is not None and count < omega.size:
        keep = np.sort(np.argsort(np.abs(omega), kind="stable")[:count])
        omega, V = omega[keep], V[:, keep]
    return (omega, N @ V) if modes else omega

def max_frequency(system: Any, t: Optional[float] = None, q: Optional[np.ndarray] = None,
                  qd: Optional[np.ndarray] = None, deadline: Optional[float] = None) -> float:
    """The fastest natural frequency ``omega_max`` [rad/s] of the constrained system
    linearized at a state (default the initial state): below :attr:`SPARSE_MODES_MIN`
    coordinates the largest ``|omega|`` of :meth:`frequencies`; above, Lanczos on the sparse
    linearization in the constraints' tangent space (:func:`ukflex.analysis.modes.max_frequency`: an
    estimate from below, within 1e-3 on the scenes measured, docs/scale.md)."""
    t = system.t0 if t is None else float(t)
    q = system.q0 if q is None else np.asarray(q, dtype=float)
    qd = system.qd0 if qd is None else np.asarray(qd, dtype=float)
    if system.n_coords >= system.SPARSE_MODES_MIN:
        from . import modes as _modes

        return abs(_modes.max_frequency(system, t, q, qd, deadline=deadline))
    omega = frequencies(system, t, q, qd)
    return float(np.abs(omega).max()) if omega.size else 0.0

def _check_dense(system: Any, what: str, nbytes: float) -> None:
    """Refuse a dense Python-side allocation above the System's ``memory_limit``."""
    limit = int(system.core.memory_limit)
    if nbytes > limit:
        raise MemoryLimitError(
            f"{what} needs about {nbytes / 2**20:.1f} MiB, above the memory limit of {limit / 2**20:.1f} MiB; "
            "ask for the lowest modes only (count=k: sparse), or raise memory_limit")
