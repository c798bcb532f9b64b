"""Constraint stabilization of a run (``simulate(..., stabilization=...)``): Baumgarte's
acceleration feedback, projection onto the constraint manifold, or none at all; with the rank
tolerance and the pseudoinverse backend of the UK solve. The settings are applied to a copy of
the caller's System (settings belong to a System object, and another thread may be using it)."""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ..errors import InvalidArgumentError

__all__ = ["configure", "segment_bounds", "DEFAULT_PROJECTION_TOL", "SEGMENTS"]

#: tolerance of the projection of ``stabilization="projection"`` (positions, absolute)
DEFAULT_PROJECTION_TOL = 1e-12
#: scipy methods with ``stabilization="projection"``: restarts per run unless ``interval`` is given
SEGMENTS = 100


def configure(system: Any, stabilization: Any, rank_tolerance: Any,
              pseudoinverse: Optional[str]) -> Tuple[Any, Optional[float], float]:
    """Apply stabilization, rank tolerance and pseudoinverse to ``system`` (a copy).

    Returns ``(label, projection_tol, interval)``: ``label`` is ``None`` (``stabilization=None``:
    the method's own projection), ``"none"``, ``"projection"`` or ``{"kind": "baumgarte",
    "alpha": a, "beta": b}`` (stored in the result's ``extra["stabilization"]``);
    ``projection_tol`` is ``None`` when nothing projects.
    """
    label: Any = None
    proj_tol, interval = None, 0.0
    if stabilization is not None:
        label = "none"
        system.set_stabilization("none")
    if stabilization is None or (isinstance(stabilization, str) and stabilization == "none"):
        pass
    elif isinstance(stabilization, str) and stabilization == "projection":
        label, proj_tol = "projection", DEFAULT_PROJECTION_TOL
    elif isinstance(stabilization, dict):
        kind = stabilization.get("kind", "none")
        if kind == "baumgarte":
            label = _baumgarte(system, stabilization["alpha"], stabilization["beta"])
        elif kind == "projection":
            label = "projection"
            proj_tol = float(stabilization.get("tol", DEFAULT_PROJECTION_TOL))
            interval = float(stabilization.get("interval", 0.0))
        elif kind != "none":
            raise InvalidArgumentError("stabilization",
                                       f"unknown kind {kind!r} (use 'none', 'baumgarte', 'projection')")
    elif isinstance(stabilization, (tuple, list)) and stabilization and stabilization[0] == "baumgarte":
        label = _baumgarte(system, stabilization[1], stabilization[2])
    else:
        raise InvalidArgumentError(
            "stabilization", "must be None, 'none', 'projection', ('baumgarte', alpha, beta) or a dict with kind "
            f"'none' | 'baumgarte' (alpha, beta) | 'projection' (tol, interval); got {stabilization!r}")
    if rank_tolerance is not None:
        if isinstance(rank_tolerance, dict):
            system.set_rank_tolerance(rank_tolerance.get("rcond"), float(rank_tolerance.get("atol", 0.0)))
        else:
            rcond, atol = rank_tolerance
            system.set_rank_tolerance(rcond, float(atol))
    if pseudoinverse is not None:
        system.set_pseudoinverse(pseudoinverse)
    return label, proj_tol, interval


def _baumgarte(system: Any, alpha: Any, beta: Any) -> Dict[str, Any]:
    system.set_stabilization("baumgarte", float(alpha), float(beta))
    return {"kind": "baumgarte", "alpha": alpha, "beta": beta}


def segment_bounds(t0: float, t_end: float, interval: float) -> List[float]:
    """The restart times of a scipy run projected every ``interval`` seconds (default
    ``(t_end - t0) / SEGMENTS``), ``t0`` and ``t_end`` included; a last piece shorter than
    rounding joins the one before."""
    if interval <= 0.0:
        interval = (t_end - t0) / SEGMENTS
    bounds = list(np.arange(t0, t_end, interval)) + [t_end]
    if len(bounds) > 1 and bounds[-1] - bounds[-2] < 1e-12 * max(1.0, abs(t_end)):
        bounds.pop(-2)
    return [float(b) for b in bounds]
