"""Numerical stability on stiff and extreme cases: safeguards and diagnostics.

* diagnostics on a :class:`ukflex.SimulationResult`: :func:`rank_history` (rank of the UK
  pseudoinverse and the dropped singular values, reported where they change),
  :func:`drift`, :func:`axial_force` / :func:`buckling_load` / :func:`buckling_ratio`,
  :func:`ffrf_validity`, and :func:`check`, which turns them into :class:`StabilityWarning`\\ s.
* :func:`scaling_accuracy` -- loss of digits of UK accelerations as ``cond(M)`` grows, with and
  without the diagonal scaling ``D = diag(M)^-1/2``, against an extended-precision (x87 80-bit
  ``longdouble``) augmented solve.

Runs with a chosen stabilization (none, Baumgarte, projection), rank tolerance and
pseudoinverse are :func:`ukflex.simulate`'s (``stabilization=``, ``rank_tolerance=``,
``pseudoinverse=``; ``raise_on_failure=True`` raises :class:`IntegrationFailure` with the partial
result).  The stability *report* over the catalogue of extreme scenes is a study of the
repository: ``python -m studies stability --out DIR [--quick]``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Tuple

import numpy as np

from ..errors import UnknownNameError

if TYPE_CHECKING:  # annotations only: the diagnostics read the System and result they are given
    from ..model.system import System
    from ..results.simulation import SimulationResult

__all__ = [
    "StabilityWarning",
    "RankDeficiencyWarning",
    "DriftWarning",
    "BucklingWarning",
    "ModelValidityWarning",
    "IntegrationFailure",
    "Diagnosis",
    "rank_history",
    "drift",
    "beam_properties",
    "buckling_load",
    "axial_force",
    "joint_end_force",
    "buckling_ratio",
    "ffrf_validity",
    "check",
    "scaling_accuracy",
    "augmented_reference",
]


# ------------------------------------------------------------------------------------ warnings
# (defined with the errors, so that simulate can warn without importing this module)
from ..errors import (  # noqa: E402
    BucklingWarning,
    DriftWarning,
    IntegrationFailure,
    ModelValidityWarning,
    RankDeficiencyWarning,
    StabilityWarning,
)


# ------------------------------------------------------------------------------------ diagnostics
def rank_history(result: SimulationResult, rcond: Optional[float] = None, atol: float = 0.0) -> Dict[str, Any]:
    """Rank of the UK pseudoinverse ``(A F^-T)^+`` at every output time, and where it changes.

    Returns
    -------
    dict
        ``rank`` (nt,) ints, ``ratio`` (nt,) ``sigma_min_kept / sigma_max``, ``dropped`` (nt,)
        largest dropped singular value, ``changes``: list of ``{"t", "from", "to",
        "sigma_max_dropped", "sigma_min_kept", "tolerance"}`` at the outputs where the rank
        changed, ``full`` (= number of rows m), ``min_rank``.
    """
    s: System = result.system
    m = s.n_constraints
    nt = result.t.size
    rank = np.full(nt, m, dtype=int)
    ratio = np.ones(nt)
    dropped = np.zeros(nt)
    changes: List[Dict[str, float]] = []
    if m == 0:
        return {"rank": rank, "ratio": ratio, "dropped": dropped, "changes": changes, "full": 0, "min_rank": 0,
                "closeness": np.zeros(nt), "max_closeness": 0.0}
    # evaluate with the plain UK right-hand side (no Baumgarte term: the rank depends on q only),
    # on a private copy: the result's System may be in use by other threads
    s = s.copy()
    s.set_stabilization("none")
    s.set_rank_tolerance(rcond, atol)
    prev = None
    closeness = np.zeros(nt)
    for k in range(nt):
        info = s.rank_info(result.t[k], result.q[:, k], result.qd[:, k])
        rank[k] = int(info["rank"])
        ratio[k] = info["sigma_min_kept"] / info["sigma_max"] if info["sigma_max"] > 0 else 0.0
        dropped[k] = info["sigma_max_dropped"]
        tol = info["tolerance"]
        if tol > 0:  # how close the rank decision is to the tolerance (1 = on it)
            kept = info["sigma_min_kept"] / tol if info["sigma_min_kept"] > 0 else np.inf
            closeness[k] = max(info["sigma_max_dropped"] / tol, 1.0 / kept)
        if prev is not None and rank[k] != prev:
            changes.append({"t": float(result.t[k]), "from": int(prev), "to": int(rank[k]),
                            "sigma_max_dropped": float(info["sigma_max_dropped"]),
                            "sigma_min_kept": float(info["sigma_min_kept"]), "tolerance": float(info["tolerance"])})
        prev = rank[k]
    return {"rank": rank, "ratio": ratio, "dropped": dropped, "changes": changes, "full": m, "min_rank": int(rank.min()),
            "closeness": closeness, "max_closeness": float(closeness.max()) if nt else 0.0}


def drift(result: SimulationResult) -> Dict[str, float]:
    """Largest and final constraint residual norms (position, velocity) of a run."""
    r = result.residuals
    out = {}
    for k in ("position", "velocity", "acceleration"):
        v = r[k]
        out[f"max_{k}"] = float(v.max()) if v.size else 0.0
        out[f"final_{k}"] = float(v[-1]) if v.size else 0.0
    return out


def beam_properties(system: System, body: str) -> Dict[str, Any]:
    """``length, E, area, I, elements, frame`` of beam ``body``.

    Raises
    ------
    UnknownNameError
        ``body`` is unknown or not a beam (a ``KeyError``).
    """
    info = system.body_info(body)
    if not system.capabilities(body)["axial_forces"]:
        beams = [b for b in system.body_names if system.capabilities(b)["axial_forces"]]
        raise UnknownNameError(f"body {body!r} is not an FFRF beam; FFRF beams are {beams}", "beam", body, beams)
    area, second_moment = _section(system, body)
    return {"length": float(info["length"]), "E": float(info["youngs_modulus"]), "area": area, "I": second_moment,
            "elements": int(info["elements"]), "frame": info["frame"]}


def _section(system: System, body: str) -> Tuple[float, float]:
    """(area, second moment) of beam ``body``'s section, as the core derived them."""
    info = system.body_info(body)
    return float(info["area"]), float(info["second_moment"])


def buckling_load(system: System, body: str) -> float:
    """Euler load of the pinned-pinned beam ``body``: ``P_cr = pi^2 E I / L^2`` [force units]."""
    p = beam_properties(system, body)
    return math.pi**2 * p["E"] * p["I"] / p["length"] ** 2


def axial_force(result: SimulationResult, body: str) -> np.ndarray:
    """Axial force of each element of beam ``body`` from its elastic strain, shape (N, nt).

    ``N_k = E a eps_k`` with the element's axial strain as the model defines it (the core's
    ``System.axial_forces``): ``(u(x_{k+1}) - u(x_k)) / l`` for linear strain, plus the averaged
    ``v'^2 / 2`` for nonlinear strain; tension positive.
    """
    s: System = result.system
    return np.array([np.asarray(s.axial_forces(body, q)) for q in result.q.T]).reshape(result.t.size, -1).T


def joint_end_force(result: SimulationResult, joint: str, body: str) -> np.ndarray:
    """Axial force on beam ``body`` at a revolute ``joint`` attached to it (at ``xi = 0``), from
    the multipliers: ``-A^T lambda`` on the marker; positive = compression of the beam.

    Returns shape (nt,).
    """
    s: System = result.system
    ix, iy = s.constraint_names.index(f"{joint}.x"), s.constraint_names.index(f"{joint}.y")
    jd = next(j for j in s.description["joints"] if j.get("name") == joint)
    sign = 1.0 if jd["b"]["body"] == body else -1.0  # Phi = r_a - r_b
    lam = result.multipliers()
    th = result.coordinate(f"{body}.theta")
    F = sign * lam[[ix, iy]].T  # force on the beam end
    ex = np.column_stack([np.cos(th), np.sin(th)])  # the beam frame's axis
    return np.sum(F * ex, axis=1)


def buckling_ratio(result: SimulationResult, body: str) -> Dict[str, float]:
    """Peak compressive axial force over the run against the Euler load.

    Returns ``P_cr``, ``max_compression`` (largest element compression, strain-based),
    ``ratio = max_compression / P_cr`` and ``t`` (time of the peak).
    """
    s = result.system
    P = axial_force(result, body)
    comp = -P.min(axis=0)
    k = int(np.argmax(comp))
    Pcr = buckling_load(s, body)
    return {"P_cr": Pcr, "max_compression": float(comp[k]), "ratio": float(comp[k] / Pcr), "t": float(result.t[k])}


def ffrf_validity(result: SimulationResult, body: str, points: int = 21) -> Dict[str, float]:
    """Size of the elastic deformation of beam ``body`` against the small-deformation range.

    Returns ``max_v_over_L`` (largest transverse elastic displacement / length over ``points``
    abscissae), ``max_psi`` (largest elastic rotation [rad]) and ``max_u_over_L``.
    """
    s = result.system
    L = beam_properties(s, body)["length"]
    qf = result.q[s.elastic_slice(body)].T
    vmax = umax = pmax = 0.0
    for xi in np.linspace(0.0, 1.0, points):
        S, npsi = s.beam_shape(body, float(xi))
        uv = qf @ np.asarray(S).T
        umax = max(umax, float(np.abs(uv[:, 0]).max()))
        vmax = max(vmax, float(np.abs(uv[:, 1]).max()))
        pmax = max(pmax, float(np.abs(qf @ np.asarray(npsi)).max()))
    return {"max_v_over_L": vmax / L, "max_u_over_L": umax / L, "max_psi": pmax}


@dataclass
class Diagnosis:
    """One finding of :func:`check`."""

    kind: str
    message: str
    value: float = float("nan")

    def __str__(self) -> str:
        return f"{self.kind}: {self.message}"


def check(
    result: SimulationResult,
    *,
    drift_threshold: float = 1e-6,
    buckling_fraction: float = 0.5,
    deflection_limit: float = 0.05,
    rotation_limit: float = 0.1,
    rank: bool = True,
    warn: bool = True,
) -> List[Diagnosis]:
    """Diagnose a run; with ``warn`` each finding is also issued as a :class:`StabilityWarning`.

    * rank loss of ``A F^-T`` at an output (:class:`RankDeficiencyWarning`, with the time and
      the dropped singular value), or redundant rows throughout;
    * position drift ``||Phi|| > drift_threshold`` (:class:`DriftWarning`);
    * beams: compressive axial force ``> buckling_fraction * P_cr`` (:class:`BucklingWarning`:
      the linear FFRF model has no geometric stiffening, so near ``P_cr`` it is out of range);
      ``max |v|/L > deflection_limit`` or ``|psi| > rotation_limit``
      (:class:`ModelValidityWarning`).
    """
    out: List[Diagnosis] = []
    s: System = result.system
    if rank and s.n_constraints:
        rh = rank_history(result)
        if rh["changes"] and rh["min_rank"] < rh["full"]:
            c = rh["changes"][0]
            out.append(Diagnosis("rank", (
                f"the constraint Jacobian lost rank during the run: {len(rh['changes'])} change(s), first at "
                f"t = {c['t']:.6g} s ({c['from']} -> {c['to']} of {rh['full']} rows, dropped sigma "
                f"{c['sigma_max_dropped']:.3e} <= tol {c['tolerance']:.3e}); UK used the minimum-norm "
                "(Gauss) acceleration there"), float(rh["min_rank"])))
        elif rh["min_rank"] < rh["full"]:
            out.append(Diagnosis("redundant", (
                f"{rh['full'] - rh['min_rank']} redundant constraint row(s) throughout (rank {rh['min_rank']} of "
                f"{rh['full']}): multipliers are the minimum-norm ones, reactions in redundant joints are not unique"),
                float(rh["min_rank"])))
        if rh["max_closeness"] > 1e-2 and rh["min_rank"] < rh["full"]:
            out.append(Diagnosis("fragile-rank", (
                f"a singular value came within {rh['max_closeness']:.2g} x of the pseudoinverse tolerance: the rank "
                "decision may flip from call to call (discontinuous accelerations, step-size collapse); set a looser "
                "rank tolerance, e.g. System.set_rank_tolerance(rcond=1e-10)"), rh["max_closeness"]))
        if not rh["changes"] and rh["min_rank"] == rh["full"]:
            worst = float(rh["ratio"].min())
            if worst < 1e-3:
                out.append(Diagnosis("near-singular", (
                    f"smallest sigma_min/sigma_max of A F^-T = {worst:.3e}: near a singular configuration"), worst))
    d = drift(result)
    if d["max_position"] > drift_threshold:
        out.append(Diagnosis("drift", (
            f"constraint drift ||Phi|| reached {d['max_position']:.3e} (> {drift_threshold:.1e}); use "
            "stabilization=('baumgarte', a, b) or 'projection'"), d["max_position"]))
    for name in s.body_names:
        if not s.capabilities(name)["axial_forces"]:
            continue
        if s.body_info(name)["frame"] == "pinned-pinned":
            br = buckling_ratio(result, name)
            if br["ratio"] > buckling_fraction:
                out.append(Diagnosis("buckling", (
                    f"beam {name!r}: compressive axial force {br['max_compression']:.4g} at t = {br['t']:.4g} s is "
                    f"{br['ratio']:.2f} x its Euler load {br['P_cr']:.4g}; the linear FFRF model has no geometric "
                    "stiffening and is not valid near buckling"), br["ratio"]))
        v = ffrf_validity(result, name)
        if v["max_v_over_L"] > deflection_limit or v["max_psi"] > rotation_limit:
            out.append(Diagnosis("ffrf-validity", (
                f"beam {name!r}: max |v|/L = {v['max_v_over_L']:.3g}, max |psi| = {v['max_psi']:.3g} rad: beyond the "
                f"small-deformation range of the linear FFRF model (limits {deflection_limit}, {rotation_limit} rad)"),
                v["max_v_over_L"]))
    if warn:
        cls = {"rank": RankDeficiencyWarning, "redundant": RankDeficiencyWarning, "near-singular": RankDeficiencyWarning, "fragile-rank": RankDeficiencyWarning,
               "drift": DriftWarning, "buckling": BucklingWarning, "ffrf-validity": ModelValidityWarning}
        for dg in out:
            warnings.warn(dg.message, cls[dg.kind], stacklevel=2)
    return out


# ------------------------------------------------------------------------------------ scaling
def _solve_longdouble(K: np.ndarray, r: np.ndarray, refine: int = 3) -> np.ndarray:
    """Gaussian elimination with partial pivoting in ``np.longdouble`` (x87 80-bit: 64-bit
    mantissa, eps 1.1e-19) plus iterative refinement in the same precision."""
    K = np.asarray(K, dtype=np.longdouble)
    r = np.asarray(r, dtype=np.longdouble)
    n = K.shape[0]
    LU = K.copy()
    piv = np.arange(n)
    for k in range(n - 1):
        p = k + int(np.argmax(np.abs(LU[k:, k])))
        if p != k:
            LU[[k, p]] = LU[[p, k]]
            piv[[k, p]] = piv[[p, k]]
        if LU[k, k] == 0:
            raise np.linalg.LinAlgError("singular augmented matrix")
        LU[k + 1:, k] /= LU[k, k]
        LU[k + 1:, k + 1:] -= np.outer(LU[k + 1:, k], LU[k, k + 1:])

    def lu_solve(bv):
        x = bv[piv].copy()
        for i in range(1, n):
            x[i] -= LU[i, :i] @ x[:i]
        for i in range(n - 1, -1, -1):
            x[i] = (x[i] - LU[i, i + 1:] @ x[i + 1:]) / LU[i, i]
        return x

    x = lu_solve(r)
    for _ in range(refine):
        x += lu_solve(r - K @ x)
    return x


def augmented_reference(M, Q, A, b) -> np.ndarray:
    """``qdd`` from ``[[M, A^T], [A, 0]] [qdd; lam] = [Q; b]`` in extended precision (the same
    double-precision terms; only the solve is exact to ~cond * 1e-19).  Needs full row rank."""
    n, m = M.shape[0], A.shape[0]
    K = np.zeros((n + m, n + m))
    K[:n, :n] = M
    K[:n, n:] = A.T
    K[n:, :n] = A
    x = _solve_longdouble(K, np.concatenate([Q, b]))
    return np.asarray(x[:n], dtype=np.longdouble)


def _uk_symmetric(M, Q, A, b):
    from ..reference.uk import uk_qdd

    return uk_qdd(M, Q, A, b)


def _uk_cholesky(M, Q, A, b):
    import scipy.linalg as sla

    L = np.linalg.cholesky(M)
    y = sla.solve_triangular(L, Q, lower=True)
    a = sla.solve_triangular(L.T, y, lower=False)
    B = sla.solve_triangular(L, A.T, lower=True).T
    y = y + np.linalg.pinv(B) @ (b - A @ a)
    return sla.solve_triangular(L.T, y, lower=False)


def _augmented_double(M, Q, A, b):
    n, m = M.shape[0], A.shape[0]
    K = np.zeros((n + m, n + m))
    K[:n, :n], K[:n, n:], K[n:, :n] = M, A.T, A
    return np.linalg.solve(K, np.concatenate([Q, b]))[:n]


def scaling_accuracy(system: System, t: Optional[float] = None, q=None, qd=None) -> Dict[str, Any]:
    """Accuracy of the acceleration solve at ``(t, q, qd)`` (default: the initial state).

    The terms ``M, Q, A, b`` are taken from the core in double precision; the reference is the
    augmented system solved in 80-bit extended precision with refinement.  Errors are
    ``||qdd - qdd_ref||_M / ||qdd_ref||_M`` (the kinetic-energy norm, so that coordinates of
    different units are weighed physically) for:

    * ``rust_uk``: the core (block-Cholesky factor ``F``, ``(A F^-T)^+``);
    * ``uk_symmetric`` / ``uk_symmetric_scaled``: the paper's eq. (70) with the symmetric root
      ``M^-1/2`` (eigh), without / with the diagonal scaling ``q = D z``,
      ``D = diag(M)^-1/2`` (``M_z = D M D``, ``Q_z = D Q``, ``A_z = A D``, ``qdd = D zdd``);
    * ``uk_cholesky`` / ``uk_cholesky_scaled``: the same with a dense Cholesky factor;
    * ``augmented`` / ``augmented_scaled``: double-precision LU of the KKT matrix.

    Also returns ``cond_M``, ``cond_M_scaled``, ``cond_B`` (of ``A F^-T``).
    """
    t = system.t0 if t is None else float(t)
    q = system.q0 if q is None else np.asarray(q, dtype=float)
    qd = system.qd0 if qd is None else np.asarray(qd, dtype=float)
    system.set_stabilization("none")
    M, Q, A, b = system.M(q), system.Q(t, q, qd), system.A(q), system.b(t, q, qd)
    ref = augmented_reference(M, Q, A, b)
    Ml = M.astype(np.longdouble)
    nref = float(np.sqrt(ref @ Ml @ ref))

    def err(x):
        e = np.asarray(x, dtype=np.longdouble) - ref
        return float(np.sqrt(abs(e @ Ml @ e)) / nref)

    D = 1.0 / np.sqrt(np.diag(M))
    Ms, Qs, As = M * np.outer(D, D), Q * D, A * D
    out = {
        "n": int(M.shape[0]), "m": int(A.shape[0]),
        "cond_M": float(np.linalg.cond(M)), "cond_M_scaled": float(np.linalg.cond(Ms)),
        "rust_uk": err(system.qdd(t, q, qd)),
        "uk_symmetric": err(_uk_symmetric(M, Q, A, b)),
        "uk_symmetric_scaled": err(D * _uk_symmetric(Ms, Qs, As, b)),
        "uk_cholesky": err(_uk_cholesky(M, Q, A, b)),
        "uk_cholesky_scaled": err(D * _uk_cholesky(Ms, Qs, As, b)),
        "augmented": err(_augmented_double(M, Q, A, b)),
        "augmented_scaled": err(D * _augmented_double(Ms, Qs, As, b)),
    }
    L = np.linalg.cholesky(M)
    B = np.linalg.solve(L, A.T).T
    out["cond_B"] = float(np.linalg.cond(B))
    return out
