"""Numerical stability on stiff and extreme cases (issue 6): safeguards, diagnostics, report.

* :func:`run` -- integrate with a chosen stabilization (``None``, Baumgarte, projection onto the
  constraint manifold), rank tolerance and integrator (native Rust ``DOPRI5`` / ``RADAU5`` or any
  ``solve_ivp`` method), keeping the partial result when the integration fails
  (:class:`IntegrationFailure` carries it).
* diagnostics on a :class:`ukflex.SimulationResult`: :func:`rank_history` (rank of the UK
  pseudoinverse and the dropped singular values, reported where they change),
  :func:`drift`, :func:`axial_force` / :func:`buckling_load` / :func:`buckling_ratio`,
  :func:`ffrf_validity`, and :func:`check`, which turns them into :class:`StabilityWarning`\\ s.
* :func:`scaling_accuracy` -- loss of digits of UK accelerations as ``cond(M)`` grows, with and
  without the diagonal scaling ``D = diag(M)^-1/2``, against an extended-precision (x87 80-bit
  ``longdouble``) augmented solve.
* :func:`report` -- runs the catalogue :mod:`ukflex.extreme` and writes ``stability.md`` and
  ``stability.json`` (``python -m ukflex.stability --out DIR [--quick]``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
import traceback
import warnings
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
from scipy.integrate import solve_ivp

from .errors import SolverError, UkflexError
from .results import SimulationResult
from .simulate import as_system, simulate
from .system import System

__all__ = [
    "StabilityWarning",
    "RankDeficiencyWarning",
    "DriftWarning",
    "BucklingWarning",
    "ModelValidityWarning",
    "IntegrationFailure",
    "NATIVE_METHODS",
    "run",
    "rank_history",
    "drift",
    "beam_properties",
    "buckling_load",
    "axial_force",
    "buckling_ratio",
    "ffrf_validity",
    "check",
    "scaling_accuracy",
    "augmented_reference",
    "report",
]

NATIVE_METHODS = ("DOPRI5", "RADAU5")


# ------------------------------------------------------------------------------------ warnings
class StabilityWarning(UserWarning):
    """Base class of the numerical-stability warnings of ukflex."""


class RankDeficiencyWarning(StabilityWarning):
    """The constraint Jacobian lost rank (in the mass metric) during the run."""


class DriftWarning(StabilityWarning):
    """The constraint residual (drift) passed the threshold."""


class BucklingWarning(StabilityWarning):
    """A beam's compressive axial force approaches (or exceeds) its Euler buckling load."""


class ModelValidityWarning(StabilityWarning):
    """The linear-elastic FFRF model (small deformations) is outside its range of validity."""


class IntegrationFailure(SolverError):  # type: ignore[misc, valid-type]
    """The integration failed; ``result`` holds everything computed up to the failure.

    Attributes
    ----------
    result : SimulationResult
        Accepted steps (or requested outputs) up to the failure, ``status = -1``.
    reason : str
        The integrator's or the core's message.
    t_fail : float
        Last time reached.
    """

    def __init__(self, message: str, result: Optional[SimulationResult] = None, reason: str = "", t_fail: float = float("nan")):
        super().__init__(message)
        self.result = result
        self.reason = reason
        self.t_fail = t_fail


# ------------------------------------------------------------------------------------ running
def _configure(system: System, stabilization: Any, rank_tolerance: Any,
               pseudoinverse: Optional[str]) -> Tuple[Any, Optional[float], float]:
    """Apply stabilization, rank tolerance and pseudoinverse to the system.

    Returns ``(label, projection_tol, interval)``: ``label`` is ``"none"``, ``"projection"`` or
    ``{"kind": "baumgarte", "alpha": a, "beta": b}`` (stored in the result's ``extra``).
    """
    label: Any = "none"
    proj_tol, interval = None, 0.0
    system.set_stabilization("none")
    if stabilization is None or stabilization == "none":
        pass
    elif isinstance(stabilization, str) and stabilization == "projection":
        label, proj_tol = "projection", 1e-12
    elif isinstance(stabilization, dict):
        kind = stabilization.get("kind", "none")
        if kind == "baumgarte":
            label = _baumgarte(system, stabilization["alpha"], stabilization["beta"])
        elif kind == "projection":
            label = "projection"
            proj_tol = float(stabilization.get("tol", 1e-12))
            interval = float(stabilization.get("interval", 0.0))
        elif kind != "none":
            raise ValueError(f"unknown stabilization kind {kind!r} (use 'none', 'baumgarte', 'projection')")
    elif isinstance(stabilization, (tuple, list)) and stabilization and stabilization[0] == "baumgarte":
        label = _baumgarte(system, stabilization[1], stabilization[2])
    else:
        raise ValueError(
            "stabilization must be None, 'projection', ('baumgarte', alpha, beta) or a dict with kind "
            f"'none' | 'baumgarte' (alpha, beta) | 'projection' (tol, interval); got {stabilization!r}"
        )
    if rank_tolerance is not None:
        if isinstance(rank_tolerance, dict):
            system.set_rank_tolerance(rank_tolerance.get("rcond"), float(rank_tolerance.get("atol", 0.0)))
        else:
            rcond, atol = rank_tolerance
            system.set_rank_tolerance(rcond, float(atol))
    if pseudoinverse is not None:
        system.set_pseudoinverse(pseudoinverse)
    return label, proj_tol, interval


def _baumgarte(system: System, alpha: Any, beta: Any) -> Dict[str, Any]:
    system.set_stabilization("baumgarte", float(alpha), float(beta))
    return {"kind": "baumgarte", "alpha": alpha, "beta": beta}


def run(
    scene_or_system: Any,
    t_end: float,
    method: str = "DOPRI5",
    rtol: float = 1e-6,
    atol: Optional[float] = None,
    t_eval: Optional[Sequence[float]] = None,
    *,
    stabilization: Any = None,
    rank_tolerance: Any = None,
    pseudoinverse: Optional[str] = None,
    max_step: Optional[float] = None,
    max_steps: int = 10_000_000,
    max_nfev: Optional[int] = None,
    raise_on_failure: bool = True,
) -> SimulationResult:
    """Integrate the UK equations (Rust core) with a stabilization option.

    Parameters
    ----------
    scene_or_system : Scene, dict or System
        What to run.  The system's stabilization and rank tolerance are set by this call.
    t_end : float
        End time [s].
    method : str
        ``"DOPRI5"`` / ``"RADAU5"`` (native Rust, GIL released) or a ``solve_ivp`` method
        (``"DOP853"``, ``"Radau"``, ...).
    rtol, atol : float
        Tolerances (``atol`` default ``1e-3 rtol``).
    t_eval : array, optional
        Output times (default: every accepted step).
    stabilization : None, "projection", ("baumgarte", alpha, beta) or dict
        * ``None``: plain UK (the paper): ``Phi`` drifts.
        * ``("baumgarte", alpha, beta)`` or ``{"kind": "baumgarte", "alpha": a, "beta": b}``
          [1/s]: the acceleration constraint becomes
          ``Phi_dd + 2 alpha Phi_d + beta^2 Phi = 0`` (``alpha = beta``: critically damped drift,
          decay time ``1/alpha``).  Large values make the system stiff (eigenvalues ~ -alpha).
        * ``"projection"`` or ``{"kind": "projection", "tol": 1e-12, "interval": dt}``: after
          each accepted step (native methods) -- or every ``interval`` seconds by restarting the
          scipy integrator (scipy methods; default ``interval = (t_end - t0) / 100``) -- project
          ``q`` onto ``Phi = 0`` (Newton in the mass metric) and ``qd`` onto
          ``A qd + Phi_t = 0`` (:meth:`ukflex.System.project`).
    rank_tolerance : (rcond, atol) or dict, optional
        Pseudoinverse tolerance: singular values of ``A F^-T`` at or below
        ``max(atol, rcond sigma_max)`` are dropped (``rcond=None``: ``max(m, n) eps``).
    pseudoinverse : {"auto", "qr-jacobi", "faer"}, optional
        Pseudoinverse backend of the core.
    max_steps : int
        Native methods: step limit.
    max_nfev : int, optional
        scipy methods: stop with a failure after this many right-hand-side calls (a step-size
        collapse -- e.g. a rank decision flipping at every call -- otherwise runs for ever).
    raise_on_failure : bool
        When the integration fails, raise :class:`IntegrationFailure` (with the partial result in
        ``.result``); with ``False`` return the partial result (``status = -1``).

    Returns
    -------
    SimulationResult
        ``extra`` holds ``stabilization``, ``projections`` (scipy) and the native statistics.
    """
    system = as_system(scene_or_system)
    label, proj_tol, interval = _configure(system, stabilization, rank_tolerance, pseudoinverse)
    atol_v = 1e-3 * rtol if atol is None else float(atol)
    te = None if t_eval is None else np.asarray(t_eval, dtype=float)
    if method.upper() in NATIVE_METHODS:
        res = simulate(system, t_end, method.upper(), rtol=rtol, atol=atol_v, t_eval=te, max_step=max_step,
                       max_steps=max_steps, projection_tol=proj_tol)
    else:
        res = _run_scipy(system, float(t_end), method, rtol, atol_v, te, proj_tol, interval, max_step, max_nfev)
    res.extra["stabilization"] = label
    if res.status < 0:
        reason = res.message
        t_fail = float(res.t[-1]) if res.t.size else system.t0
        if raise_on_failure:
            kind = label["kind"] if isinstance(label, dict) else label
            raise IntegrationFailure(
                f"integration failed at t = {t_fail:.6g} s ({res.method}, {kind}): {reason}; "
                f"the partial result ({res.t.size} outputs) is in .result", res, reason, t_fail
            )
    return res


class _Budget(Exception):
    pass


def _run_scipy(system, t_end, method, rtol, atol, t_eval, proj_tol, interval, max_step, max_nfev=None):
    """solve_ivp with an accepted-step recorder (partial results survive an exception) and
    optional projection at segment ends."""
    n = system.n_coords
    t0 = system.t0
    opts: Dict[str, Any] = {}
    if max_step is not None:
        opts["max_step"] = max_step
    if method in ("Radau", "BDF"):
        opts["jac"] = system.jac
    fun = system.rhs
    if max_nfev is not None:
        count = [0]
        core_rhs = system.rhs

        def fun(t, y):
            count[0] += 1
            if count[0] > max_nfev:
                raise _Budget(f"more than {max_nfev} right-hand-side calls (step size collapsed near t = {t:.9g} s)")
            return core_rhs(t, y)
    if proj_tol is not None:
        if interval <= 0.0:
            interval = (t_end - t0) / 100.0
        bounds = list(np.arange(t0, t_end, interval)) + [t_end]
        if len(bounds) > 1 and bounds[-1] - bounds[-2] < 1e-12 * max(1.0, abs(t_end)):
            bounds.pop(-2)
    else:
        bounds = [t0, t_end]
    ts: List[float] = []
    ys: List[np.ndarray] = []
    y = system.y0.copy()
    nfev = njev = nlu = 0
    status, message = 0, "The solver successfully reached the end of the integration interval."
    projections: List[Dict[str, float]] = []
    tic = time.perf_counter()
    for k in range(len(bounds) - 1):
        ta, tb = bounds[k], bounds[k + 1]
        rec_t: List[float] = []
        rec_y: List[np.ndarray] = []

        def recorder(t, yy):
            rec_t.append(float(t))
            rec_y.append(np.array(yy, dtype=float))
            return 1.0

        seg_eval = None
        if t_eval is not None:
            sel = (t_eval >= ta) & (t_eval <= tb) if k == 0 else (t_eval > ta) & (t_eval <= tb)
            seg_eval = t_eval[sel]
        try:
            sol = solve_ivp(fun, (ta, tb), y, method=method, rtol=rtol, atol=atol, t_eval=seg_eval,
                            events=recorder, **opts)
        except Exception as exc:  # keep the accepted steps (requested outputs are lost with solve_ivp)
            status, message = -1, f"{type(exc).__name__}: {exc}"
            for tt, yy in zip(rec_t, rec_y):
                if not ts or tt > ts[-1]:
                    ts.append(tt)
                    ys.append(yy)
            break
        nfev += int(sol.nfev)
        njev += int(sol.njev)
        nlu += int(sol.nlu)
        if t_eval is None:
            first = 0 if k == 0 else 1
            ts.extend(sol.t[first:])
            ys.extend(sol.y[:, first:].T)
        else:
            ts.extend(sol.t)
            ys.extend(sol.y.T)
        if sol.status < 0:
            status, message = -1, sol.message
            break
        y = np.array(rec_y[-1])  # the segment end state (the last accepted step, t = tb)
        if proj_tol is not None and k < len(bounds) - 2:
            qn, qdn, rep = system.project(tb, y[:n], y[n:], tol=proj_tol)
            projections.append({"t": tb, **{kk: float(v) for kk, v in rep.items()}})
            y = np.concatenate([qn, qdn])
            if t_eval is None and ts and ts[-1] == tb:
                ys[-1] = y.copy()
    wall = time.perf_counter() - tic
    extra: Dict[str, Any] = {"projections": len(projections)}
    if projections:
        extra["max_projection_correction"] = max(p["position_correction"] for p in projections)
    y_arr = np.asarray(ys, dtype=float).T if ys else np.zeros((2 * n, 0))
    return SimulationResult.from_trajectory(
        system, np.asarray(ts, dtype=float), y_arr, method=method, formulation="uk", rtol=rtol, atol=atol, nfev=nfev,
        njev=njev, nlu=nlu, wall_time=wall, status=status, message=message, extra=extra)


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
    # evaluate with the plain UK right-hand side (no Baumgarte term: the rank depends on q only)
    s.set_rank_tolerance(rcond, atol)
    prev = None
    closeness = np.zeros(nt)
    for k in range(nt):
        s.qdd(result.t[k], result.q[k], result.qd[k])
        info = s.rank_info()
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


def beam_properties(system: System, body: str) -> Dict[str, float]:
    """``length, E, area, I, elements`` of beam ``body`` from the description."""
    for b in system.description["bodies"]:
        if b["name"] == body:
            if b["kind"] != "beam":
                raise KeyError(f"body {body!r} is not a beam")
            sec = b["section"]
            if sec["shape"] == "circular":
                d = sec["diameter"]
                area, I = math.pi * d * d / 4.0, math.pi * d**4 / 64.0
            elif sec["shape"] == "rectangular":
                area, I = sec["width"] * sec["height"], sec["width"] * sec["height"] ** 3 / 12.0
            else:
                area, I = sec["area"], sec["second_moment"]
            return {"length": float(b["length"]), "E": float(b["youngs_modulus"]), "area": float(area), "I": float(I),
                    "elements": int(b.get("elements", 1)), "frame": b.get("frame", "pinned-pinned")}
    raise KeyError(f"unknown body {body!r}")


def buckling_load(system: System, body: str) -> float:
    """Euler load of the pinned-pinned beam ``body``: ``P_cr = pi^2 E I / L^2`` [force units]."""
    p = beam_properties(system, body)
    return math.pi**2 * p["E"] * p["I"] / p["length"] ** 2


def axial_force(result: SimulationResult, body: str) -> np.ndarray:
    """Axial force of each element of beam ``body`` from its elastic strain, shape (nt, N).

    ``N_k = E a (u(x_{k+1}) - u(x_k)) / l`` (the axial displacement is linear in each element),
    tension positive.  This is the elastic force the model carries; it excludes any geometric
    (axial load - bending) coupling, which the linear FFRF model does not have.
    """
    s: System = result.system
    p = beam_properties(s, body)
    N = p["elements"]
    rows = np.array([np.asarray(s.beam_shape(body, k / N)[0])[0] for k in range(N + 1)])  # (N+1, n_f)
    u = result.q[:, s.elastic_slice(body)] @ rows.T  # (nt, N+1)
    return p["E"] * p["area"] * np.diff(u, axis=1) / (p["length"] / N)


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
    th = result.q[:, s.coordinate_index(f"{body}.theta")]
    _, npsi = s.beam_shape(body, 0.0)
    psi0 = result.q[:, s.elastic_slice(body)] @ np.asarray(npsi)
    F = sign * lam[:, [ix, iy]]  # force on the beam end
    ex = np.column_stack([np.cos(th + 0 * psi0), np.sin(th + 0 * psi0)])
    return np.sum(F * ex, axis=1)


def buckling_ratio(result: SimulationResult, body: str) -> Dict[str, float]:
    """Peak compressive axial force over the run against the Euler load.

    Returns ``P_cr``, ``max_compression`` (largest element compression, strain-based),
    ``ratio = max_compression / P_cr`` and ``t`` (time of the peak).
    """
    s = result.system
    P = axial_force(result, body)
    comp = -P.min(axis=1)
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
    qf = result.q[:, s.elastic_slice(body)]
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
    for b in s.description["bodies"]:
        if b["kind"] != "beam":
            continue
        name = b["name"]
        if b.get("frame", "pinned-pinned") == "pinned-pinned":
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
    from .reference.uk import uk_qdd

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


# ------------------------------------------------------------------------------------ report
def _v_mid(result: SimulationResult, body: str = "coupler") -> np.ndarray:
    _, v = result.beam_displacement(body, 0.5)
    return v / beam_properties(result.system, body)["length"]


def _observable(result: SimulationResult) -> Tuple[str, np.ndarray]:
    """What the report compares: coupler midpoint ``v/Lb`` if there is a coupler beam, else every
    coordinate (rigid mechanisms)."""
    kinds = {b["name"]: b["kind"] for b in result.system.description["bodies"]}
    if kinds.get("coupler") == "beam":
        return "v(Lb/2)/Lb", _v_mid(result)
    return "q", result.q


def _closed_form_error(name: str, result: SimulationResult) -> Optional[Tuple[str, float]]:
    s = result.system
    q = result.q
    if name == "singular_slider_crank":  # slider branch: coupler angle = -omega t
        w = s.description["drivers"][0]["motion"]["speed"]
        return "closed form (coupler angle = -omega t)", float(np.abs(q[:, s.coordinate_index("coupler.theta")] + w * result.t).max())
    if name in ("flat_parallelogram", "redundant_parallelogram"):
        th = q[:, s.coordinate_index("crank.theta")]
        e = np.abs(q[:, s.coordinate_index("rocker.theta")] - th).max()
        e = max(e, np.abs(q[:, s.coordinate_index("coupler.theta")]).max())
        if "extra.theta" in s.coordinate_names:
            e = max(e, np.abs(q[:, s.coordinate_index("extra.theta")] - th).max())
        return "closed form (parallelogram branch: rocker angle = crank angle, coupler angle 0)", float(e)
    return None


def _energy_drift(result: SimulationResult) -> float:
    """``(max E - min E) / max T`` over the run (``T + V`` may start at 0: normalize by the
    largest kinetic energy reached)."""
    s = result.system
    E = result.energy()
    T = np.array([s.kinetic_energy(q, qd) for q, qd in zip(result.q, result.qd)])
    return float(np.ptp(E) / max(T.max(), 1e-300))


def _fmt(x: Any, spec: str = ".2e") -> str:
    if x is None:
        return "-"
    if isinstance(x, float) and not math.isfinite(x):
        return str(x)
    return format(x, spec)


def _case_runs(c, quick: bool, log) -> Dict[str, Any]:
    from . import extreme

    T = c.duration(quick)
    nt = 201
    t_eval = np.linspace(0.0, T, nt)
    rec: Dict[str, Any] = {"name": c.name, "group": c.group, "title": c.title, "t_end": T, "runs": [], "diagnoses": []}
    try:
        system = System(c.build_scene(quick))
    except UkflexError as exc:
        rec["build_error"] = f"{type(exc).__name__}: {exc}"
        return rec
    rec["n"], rec["m"] = system.n_coords, system.n_constraints
    rec["has_beam"] = any(b["kind"] == "beam" for b in system.description["bodies"])
    rec["cond_M"] = float(np.linalg.cond(system.M(system.q0)))
    rank_tol = (1e-10, 0.0) if c.group == 5 else None
    # reference we trust: UK DOPRI5 at rtol 1e-10 (self-convergence), closed forms where known
    tic = time.perf_counter()
    ref = None
    try:
        ref = run(system, T, "DOPRI5", rtol=1e-10, t_eval=t_eval, rank_tolerance=rank_tol)
        rec["reference"] = "UK (Rust) DOPRI5, rtol 1e-10"
    except IntegrationFailure as exc:
        rec["reference_error"] = str(exc)
    log(f"  {c.name}: reference {time.perf_counter() - tic:.1f}s")
    label, ref_obs = _observable(ref) if ref is not None else ("", None)
    rec["observable"] = label
    if ref is not None:
        cf = _closed_form_error(c.name, ref)
        if cf:
            rec["reference_closed_form"] = {"what": cf[0], "error": cf[1]}
        rec["diagnoses"] = [str(d) for d in check(ref, warn=False)]
        kinds = {b["name"]: b["kind"] for b in system.description["bodies"]}
        if kinds.get("coupler") == "beam":
            rec["buckling"] = buckling_ratio(ref, "coupler")
            rec["ffrf"] = ffrf_validity(ref, "coupler")
        if system.description.get("drivers") in (None, []):
            rec["energy_drift_rel"] = _energy_drift(ref)
        rh = rank_history(ref, *(rank_tol or (None, 0.0)))
        rec["rank"] = {"full": rh["full"], "min": rh["min_rank"], "changes": rh["changes"][:4],
                       "min_ratio": float(rh["ratio"].min())}
    skip_scipy = c.name in ("stiff_E1e4", "stiff_N32", "stiff_N64", "long_run")
    has_beam = any(b["kind"] == "beam" for b in system.description["bodies"])
    configs = [("UK", "DOPRI5"), ("UK", "RADAU5")] + ([] if skip_scipy else [("UK", "DOP853")])
    if not has_beam:  # scipy's Radau costs ~10 ms per step in Python on the flexible scenes
        configs.append(("UK", "Radau"))
    if c.group == 5:
        configs += [("UK default rcond", "DOP853")]
    for form, meth in configs:
        tic = time.perf_counter()
        entry: Dict[str, Any] = {"formulation": form, "method": meth, "rtol": 1e-6}
        try:
            rt = None if form == "UK default rcond" else rank_tol
            r = run(system, T, meth, rtol=1e-6, t_eval=t_eval, rank_tolerance=rt, max_nfev=2_000_000)
            entry.update(ok=True, wall=time.perf_counter() - tic, nfev=r.nfev, drift=drift(r)["max_position"])
            if ref is not None:
                entry["error"] = float(np.abs(_observable(r)[1] - ref_obs).max())
            if system.description.get("drivers") in (None, []):
                entry["energy_drift_rel"] = _energy_drift(r)
        except IntegrationFailure as exc:
            entry.update(ok=False, wall=time.perf_counter() - tic, error_message=exc.reason,
                         t_fail=exc.t_fail, partial_outputs=int(exc.result.t.size) if exc.result is not None else 0)
        except UkflexError as exc:
            entry.update(ok=False, wall=time.perf_counter() - tic, error_message=f"{type(exc).__name__}: {exc}")
        log(f"  {c.name}: {form} {meth} {'ok' if entry['ok'] else 'FAILED'} {entry['wall']:.1f}s")
        rec["runs"].append(entry)
    if c.cp_t_end is not None:
        Tc = min(c.cp_t_end, T, 0.001 if (quick and has_beam) else np.inf)
        te = t_eval[t_eval <= Tc + 1e-15]
        entry = {"formulation": "CP (NumPy)", "method": "DOP853", "rtol": 1e-8, "t_end": Tc}
        tic = time.perf_counter()
        try:
            from .simulate import simulate

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = simulate(system, Tc, method="DOP853", rtol=1e-8, atol=1e-11, t_eval=te, formulation="cp")
            entry["wall"] = time.perf_counter() - tic
            entry["ok"] = bool(r.status >= 0 and r.t.size == te.size)
            entry["drift"] = drift(r)["max_position"]
            entry["repartitions"] = int(r.extra.get("repartitions", 0) or 0)
            if not entry["ok"]:
                entry["error_message"] = r.message
            elif ref is not None:
                entry["error"] = float(np.abs(_observable(r)[1] - ref_obs[: te.size]).max())
        except Exception as exc:  # the reference CP raises plain NumPy / Python errors
            entry.update(ok=False, wall=time.perf_counter() - tic, error_message=f"{type(exc).__name__}: {exc}")
        log(f"  {c.name}: CP {'ok' if entry['ok'] else 'FAILED'} {entry['wall']:.1f}s")
        rec["runs"].append(entry)
    return rec


def _long_run_study(quick: bool, log) -> Dict[str, Any]:
    from . import extreme

    revs = 10 if quick else 100
    T = revs * extreme.REVOLUTION
    system = System(extreme.long_run())
    t_eval = np.linspace(0.0, T, 20 * revs + 1)
    out: Dict[str, Any] = {"revolutions": revs, "t_end": T, "method": "DOPRI5", "rtol": 1e-6, "rows": []}
    for label, stab in [("none", None), ("Baumgarte alpha = beta = 10/s", ("baumgarte", 10.0, 10.0)),
                        ("Baumgarte alpha = beta = 100/s", ("baumgarte", 100.0, 100.0)), ("projection every step", "projection")]:
        tic = time.perf_counter()
        r = run(system, T, "DOPRI5", rtol=1e-6, t_eval=t_eval, stabilization=stab)
        wall = time.perf_counter() - tic
        d = drift(r)
        out["rows"].append({"stabilization": label, "max_position": d["max_position"], "final_position": d["final_position"],
                            "max_velocity": d["max_velocity"], "wall": wall, "nfev": r.nfev,
                            "peak_v": float(np.abs(_v_mid(r)).max())})
        log(f"  long run {label}: {wall:.1f}s drift {d['max_position']:.2e}")
    system.set_stabilization("none")
    # scipy path: projection by restarts
    tic = time.perf_counter()
    Ts = min(T, 10 * extreme.REVOLUTION)
    r = run(system, Ts, "DOP853", rtol=1e-6, t_eval=np.linspace(0, Ts, 201))
    r2 = run(system, Ts, "DOP853", rtol=1e-6, t_eval=np.linspace(0, Ts, 201),
             stabilization={"kind": "projection", "interval": extreme.REVOLUTION / 10})
    out["scipy"] = {"revolutions": round(Ts / extreme.REVOLUTION), "none": drift(r)["max_position"],
                    "projection_every_0.1_rev": drift(r2)["max_position"], "projections": r2.extra.get("projections")}
    log(f"  long run scipy: {time.perf_counter() - tic:.1f}s")
    return out


def _scaling_study(quick: bool) -> List[Dict[str, Any]]:
    from . import extreme

    rows = []
    cases = [("paper, N = 1", extreme.stiff(1.0)), ("paper, N = 64", extreme.stiff(1.0, elements=64)),
             ("double pendulum 1 : 1e-6", extreme.mass_ratio(1e-6)), ("double pendulum 1 : 1e-9", extreme.mass_ratio(1e-9)),
             ("slider block 1e-9 kg", extreme.near_massless()), ("paper N = 2, SI", extreme.slider_crank_units("m")),
             ("paper N = 2, mm", extreme.slider_crank_units("mm"))]
    for label, sc in cases:
        system = System(sc)
        r = run(system, 0.01, "DOPRI5", rtol=1e-8, t_eval=[0.0, 0.01])
        a = scaling_accuracy(system, r.t[-1], r.q[-1], r.qd[-1])
        a["case"] = label
        rows.append(a)
    return rows


def _units_study(quick: bool) -> Dict[str, Any]:
    from . import extreme

    T = 0.02 if quick else 0.07
    te = np.linspace(0, T, 201)
    out = {}
    res = {}
    for u in ("m", "mm"):
        system = System(extreme.slider_crank_units(u))
        res[u] = run(system, T, "DOPRI5", rtol=1e-10, t_eval=te)
    out["max_abs_diff_v_over_Lb"] = float(np.abs(_v_mid(res["m"]) - _v_mid(res["mm"])).max())
    out["peak_v_over_Lb"] = float(np.abs(_v_mid(res["m"])).max())
    out["t_end"] = T
    return out


def report(out_dir: str, quick: bool = False, cases: Optional[Sequence[str]] = None, verbose: bool = True) -> Dict[str, Any]:
    """Run the catalogue :data:`ukflex.extreme.CASES` and write ``stability.md`` and
    ``stability.json`` into ``out_dir``.

    Per case: the UK core with the native ``DOPRI5`` / ``RADAU5`` and scipy's ``DOP853`` /
    ``Radau`` at ``rtol = 1e-6``, and the NumPy coordinate partitioning (``DOP853``, ``rtol =
    1e-8``) on a short interval; error against the reference (UK ``DOPRI5`` at ``rtol = 1e-10``
    and closed forms where they exist), drift, run time, diagnoses and failure messages.  Then
    the long-run drift study, the scaling/accuracy study and the units check.
    ``quick=True`` runs the reduced sizes (about a minute).

    Returns the data written to ``stability.json``.
    """
    from . import extreme

    os.makedirs(out_dir, exist_ok=True)

    def log(msg):
        if verbose:
            print(msg, flush=True)

    tic = time.perf_counter()
    data: Dict[str, Any] = {"quick": quick, "cases": []}
    for c in extreme.CASES:
        if cases is not None and c.name not in cases:
            continue
        try:
            data["cases"].append(_case_runs(c, quick, log))
        except Exception as exc:  # a report must not die on one case
            data["cases"].append({"name": c.name, "group": c.group, "title": c.title,
                                  "report_error": "".join(traceback.format_exception_only(type(exc), exc)).strip()})
    if cases is None:
        data["long_run"] = _long_run_study(quick, log)
        data["scaling"] = _scaling_study(quick)
        data["units"] = _units_study(quick)
    data["wall_time"] = time.perf_counter() - tic
    with open(os.path.join(out_dir, "stability.json"), "w") as fh:
        json.dump(data, fh, indent=1, default=lambda o: o.tolist() if isinstance(o, np.ndarray) else str(o))
    with open(os.path.join(out_dir, "stability.md"), "w") as fh:
        fh.write(_markdown(data))
    return data


def _markdown(data: Dict[str, Any]) -> str:
    from . import extreme

    L: List[str] = []
    L.append(f"# Stability report ({'quick, reduced sizes' if data['quick'] else 'full size'})\n")
    L.append("Generated by `python -m ukflex.stability --out DIR" + (" --quick" if data["quick"] else "") +
             f"` ({data['wall_time']:.0f} s). Error = max abs difference of the observable against the reference "
             "(UK DOPRI5 at rtol 1e-10 on the same output grid of 201 points); drift = max ||Phi||; runs at rtol 1e-6 "
             "unless stated.\n")
    L.append("| case | group | n / m | cond(M) | UK DOPRI5 | UK RADAU5 | UK scipy DOP853 | UK scipy Radau | CP (NumPy) | physics / diagnosis |")
    L.append("|---|---|---|---|---|---|---|---|---|---|")
    for c in data["cases"]:
        if "report_error" in c or "build_error" in c:
            L.append(f"| {c['name']} | {extreme.GROUPS[c['group']]} | - | - | refused | refused | refused | refused | - | "
                     f"{c.get('build_error') or c.get('report_error')} |")
            continue
        cells = {}
        for r in c["runs"]:
            key = (r["formulation"], r["method"])
            if r.get("ok"):
                txt = f"ok: err {_fmt(r.get('error'))}, drift {_fmt(r.get('drift'))}, {r['wall']:.2f} s"
                if "energy_drift_rel" in r:
                    txt += f", dE/E {_fmt(r['energy_drift_rel'])}"
                if r["formulation"].startswith("CP"):
                    txt += f" (0..{r['t_end']:.3g} s, {r.get('repartitions', 0)} repart.)"
            else:
                txt = f"**failed**: {r.get('error_message', '')[:160]}"
                if "t_fail" in r:
                    txt += f" (t = {r['t_fail']:.4g} s, {r.get('partial_outputs', 0)} outputs kept)"
            cells[key] = txt
        cp = cells.get(("CP (NumPy)", "DOP853"), "not run (too slow in NumPy at this size)")
        phys = []
        if "buckling" in c:
            b = c["buckling"]
            phys.append(f"max compression {b['max_compression']:.4g} = {b['ratio']:.3f} P_cr")
        if "ffrf" in c:
            phys.append(f"max v/Lb {c['ffrf']['max_v_over_L']:.3g}, max psi {c['ffrf']['max_psi']:.3g} rad")
        if "reference_closed_form" in c:
            phys.append(f"ref. vs {c['reference_closed_form']['what']}: {c['reference_closed_form']['error']:.1e}")
        if "energy_drift_rel" in c:
            phys.append(f"ref. dE/E {c['energy_drift_rel']:.1e}")
        if "rank" in c:
            rk = c["rank"]
            phys.append(f"rank {rk['min']}..{rk['full']} of {rk['full']}, min sigma ratio {rk['min_ratio']:.1e}")
        phys += c.get("diagnoses", [])
        extra_uk = cells.get(("UK default rcond", "DOP853"))
        if extra_uk:
            phys.append(f"scipy DOP853 with the default rcond = max(m, n) eps: {extra_uk}")
        L.append(f"| {c['name']} ({c['title']}, {c['t_end']:.4g} s) | {extreme.GROUPS[c['group']]} | {c['n']} / {c['m']} | "
                 f"{c['cond_M']:.1e} | {cells.get(('UK', 'DOPRI5'), '-')} | {cells.get(('UK', 'RADAU5'), '-')} | "
                 f"{cells.get(('UK', 'DOP853'), 'not run')} | {cells.get(('UK', 'Radau'), 'not run (flexible: slow in Python)' if c.get('has_beam') else 'not run')} | {cp} | "
                 + "; ".join(phys).replace("|", "/") + " |")
    if "long_run" in data:
        lr = data["long_run"]
        L.append(f"\n## Long run: {lr['revolutions']} revolutions ({lr['t_end']:.3f} s), native DOPRI5, rtol 1e-6\n")
        L.append("| stabilization | max ||Phi|| | final ||Phi|| | max ||A qd + Phi_t|| | peak v/Lb | nfev | wall [s] |")
        L.append("|---|---|---|---|---|---|---|")
        for r in lr["rows"]:
            L.append(f"| {r['stabilization']} | {r['max_position']:.2e} | {r['final_position']:.2e} | {r['max_velocity']:.2e} | "
                     f"{r['peak_v']:.4e} | {r['nfev']} | {r['wall']:.2f} |")
        s = lr["scipy"]
        L.append(f"\nscipy DOP853 over {s['revolutions']} revolutions: max ||Phi|| {s['none']:.2e} without, "
                 f"{s['projection_every_0.1_rev']:.2e} with projection every 0.1 revolution ({s['projections']} restarts).")
    if "scaling" in data:
        L.append("\n## Accuracy of the acceleration solve and diagonal scaling\n")
        L.append("Relative error `||qdd - qdd_ref||_M / ||qdd_ref||_M` at the state of t = 0.01 s; reference: the augmented "
                 "system in 80-bit extended precision (same double-precision M, Q, A, b). Scaled: `D = diag(M)^-1/2`.\n")
        L.append("| case | n | cond(M) | cond(DMD) | cond(A F^-T) | Rust UK | UK symmetric root | scaled | UK dense Cholesky | scaled | augmented LU | scaled |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for a in data["scaling"]:
            L.append(f"| {a['case']} | {a['n']} | {a['cond_M']:.1e} | {a['cond_M_scaled']:.1e} | {a['cond_B']:.1e} | {a['rust_uk']:.1e} | "
                     f"{a['uk_symmetric']:.1e} | {a['uk_symmetric_scaled']:.1e} | {a['uk_cholesky']:.1e} | {a['uk_cholesky_scaled']:.1e} | "
                     f"{a['augmented']:.1e} | {a['augmented_scaled']:.1e} |")
    if "units" in data:
        u = data["units"]
        L.append(f"\n## Units\n\nPaper scene (N = 2) in m and in mm (kg, s), DOPRI5 rtol 1e-10, 0..{u['t_end']} s: "
                 f"max |v/Lb (m) - v/Lb (mm)| = {u['max_abs_diff_v_over_Lb']:.2e} (peak {u['peak_v_over_Lb']:.3e}).")
    return "\n".join(L) + "\n"


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m ukflex.stability", description="Run the extreme-case catalogue and write the stability report.")
    ap.add_argument("--out", required=True, help="output directory (stability.md, stability.json)")
    ap.add_argument("--quick", action="store_true", help="reduced sizes (about a minute)")
    ap.add_argument("--case", action="append", help="run only this case (repeatable; skips the studies)")
    a = ap.parse_args(argv)
    report(a.out, quick=a.quick, cases=a.case)
    print(f"wrote {os.path.join(a.out, 'stability.md')}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
