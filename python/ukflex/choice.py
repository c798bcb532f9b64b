"""``method="auto"``: pick the integrator from the constrained system's natural frequencies.

A scene is *stiff* for a run when the time step that resolves the motions the user asked about
is too long for its fastest mode.  The motions of interest are every flexible body's lowest
elastic mode (a mode that stores its potential energy in elastic or spring deformation, not in
gravity or constraint forces: a pendulum's swing is not elastic) and everything slower;
``omega_c`` is the highest of those (without flexible bodies: the lowest spring mode).
Generalized-alpha has a relative period error of about ``(omega h)^2 / 12``, and over the run
the phase of that mode drifts by ``eps omega_c T`` radians.  The chooser gives it a phase
budget ``phi = min(1, 1e5 rtol)`` rad (``rtol = 1e-6``: 0.1 rad over the whole run), so

    eps = min(1e-2, phi / (omega_c T)),   h = sqrt(12 eps) / omega_c   (at most T / 20).

DOPRI5 has to resolve the fastest mode instead: on these scenes its own step control settles at
``h omega_max ~ 0.5`` on average (measured 0.2-0.7 at rtol 1e-6..1e-8, paper scene and
flexible four-bar) and a DOPRI5 step (6 UK calls) costs about twice a GENALPHA step.  So when
``h omega_max > 0.5 / 2 = 0.25`` generalized-alpha is the cheaper way to the requested accuracy:
the chooser takes GENALPHA with that fixed step (``rho_inf = 0.9``, projection on), which damps
the fast modes instead of resolving them; its Newton iterations stop at ``max(rtol, eps / 10)``
of each step's motion or, while they contract fast, at ``NEWTON_LOCAL_ERROR`` of the step's
local error estimate (a tighter Newton tolerance costs iterations and changes nothing the step
size does not decide) -- the latter only on coarse steps, ``h omega_max >=
LOCAL_NEWTON_MIN_STEP_OMEGA``: on finer steps the local error estimate is small, and the Newton
error it lets through feeds back into the next estimates until it dominates them (measured: an
ANCF coupler at rtol 1e-10 ended 9 % off the strict-Newton run of the same step).  Otherwise
(rigid systems, soft or slow flexible ones, tight tolerances where a fifth-order method wins) it takes native DOPRI5 at the user's tolerances.  See
docs/integrators.md.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any, Dict, Optional

import numpy as np

#: the chooser's constants (one place): phase budget per rtol and its cap [rad], period-error
#: cap, fewest steps per run
PHASE_PER_RTOL = 1e5
PHASE_CAP = 1.0
PERIOD_ERROR_CAP = 1e-2
MIN_STEPS = 20
#: GENALPHA's Newton tolerance relative to the period-error target
NEWTON_PER_PERIOD_ERROR = 0.1
#: ... and, while Newton contracts fast, relative to each step's local error estimate
#: (``newton_local_error``: 2.3 instead of 3.2-4.4 iterations per step on the paper scene, the
#: same answer; docs/integrators.md)
NEWTON_LOCAL_ERROR = 0.3
#: ... but only on steps this coarse against the fastest mode, ``h omega_max``: on the ANCF
#: coupler (N = 4 and 8) the looser test keeps the answer at ``h omega_max`` >= 3.5 with
#: ``rho_inf`` 0.9 and >= 8.7 with 1.0, and lets it drift off at 2.2-2.6 (0.9) and 4.4 (1.0):
#: the accepted Newton error feeds the next local error estimates (docs/integrators.md)
LOCAL_NEWTON_MIN_STEP_OMEGA = 8.0
#: DOPRI5's average h omega_max on stiff flexible scenes, and its step cost over a GENALPHA step
EXPLICIT_STEP_OMEGA = 0.5
EXPLICIT_COST_RATIO = 2.0
#: a mode is elastic when more than this share of omega^2 comes from the potential energy's
#: curvature (elastic strain, springs) rather than from gravity and constraint forces
ELASTIC_SHARE = 0.5
#: a mode belongs to a flexible body when it carries at least this share of the mode's kinetic energy
BODY_SHARE = 0.2


@dataclass
class MethodChoice:
    """What ``method="auto"`` picked and why (also ``SimulationResult.extra["auto"]``)."""

    method: str
    options: Dict[str, Any] = field(default_factory=dict)
    reason: str = ""
    omega_elastic: Optional[float] = None
    omega_max: float = 0.0
    step: Optional[float] = None
    #: the integrator's rtol when it differs from the user's (GENALPHA's Newton tolerance)
    rtol: Optional[float] = None

    def as_dict(self) -> Dict[str, Any]:
        return asdict(self)


def elastic_shares(system, omega: np.ndarray, shapes: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Share of each mode's ``omega^2`` that is curvature of the potential energy along the
    mode (gravity is linear in the positions and drops out; strain and spring energy stay)."""
    shares = np.zeros(omega.size)
    U0 = system.potential_energy(q)
    for k in range(omega.size):
        if omega[k] <= 0.0:
            continue
        v = shapes[:, k]
        eps = 1e-5 / max(float(np.abs(v).max()), 1e-300)
        curv = (system.potential_energy(q + eps * v) - 2.0 * U0 + system.potential_energy(q - eps * v)) / eps**2
        # the mode is mass-normalized: its kinetic coefficient is 1, so omega^2 is its stiffness
        shares[k] = curv / omega[k] ** 2
    return shares


def lowest_elastic_frequency(system, omega, shapes, shares, q) -> Optional[float]:
    """The frequency the step must resolve: every flexible body's lowest elastic mode (the
    lowest elastic mode with at least ``BODY_SHARE`` of its kinetic energy in that body), the
    highest of those; without flexible bodies the lowest elastic (spring) mode; ``None`` if no
    mode is elastic."""
    elastic = (omega > 0.0) & (shares > ELASTIC_SHARE)
    if not elastic.any():
        return None
    M = np.asarray(system.M(q))
    per_body = []
    for body in system.body_names:
        if system.body_kind(body) in ("rigid", "point_mass"):
            continue
        sl = system.body_slice(body)
        kinetic = np.einsum("ik,ij,jk->k", shapes[sl], M[sl, sl], shapes[sl])  # mass-normalized: sums to 1
        mine = elastic & (kinetic > BODY_SHARE)
        if mine.any():
            per_body.append(float(omega[mine].min()))
    return max(per_body) if per_body else float(omega[elastic].min())


def local_newton_ok(h: float, omega_max: float) -> bool:
    """Whether GENALPHA's Newton may stop at the local error level (``NEWTON_LOCAL_ERROR``) with
    step ``h`` on a system whose fastest mode is ``omega_max``: only on coarse steps."""
    return h * omega_max >= LOCAL_NEWTON_MIN_STEP_OMEGA


def choose_method(system, t0: float, t_end: float, rtol: float, q: Optional[np.ndarray] = None,
                  qd: Optional[np.ndarray] = None) -> MethodChoice:
    """The integrator ``method="auto"`` runs for ``system`` over ``[t0, t_end]`` at ``rtol``."""
    span = float(t_end) - float(t0)
    if not (math.isfinite(span) and span > 0.0):
        raise ValueError(f"t_end must be finite and greater than t0 = {t0}, got {t_end!r}")
    if not (math.isfinite(rtol) and rtol > 0.0):
        raise ValueError(f"rtol must be positive and finite, got {rtol!r}")
    if system.n_dof == 0:
        return MethodChoice("DOPRI5", reason="no degrees of freedom: the motion is prescribed")
    omega, shapes = system.frequencies(t0, q, qd, modes=True)
    q = system.q0 if q is None else np.asarray(q, dtype=float)
    omega_max = float(np.abs(omega).max())
    shares = elastic_shares(system, omega, shapes, q)
    omega_c = lowest_elastic_frequency(system, omega, shapes, shares, q)
    if omega_c is None:
        return MethodChoice("DOPRI5", omega_max=omega_max,
                            reason=f"no elastic mode (fastest mode {omega_max:.4g} rad/s): not stiff, explicit")
    phase = min(PHASE_CAP, PHASE_PER_RTOL * rtol)
    eps = min(PERIOD_ERROR_CAP, phase / (omega_c * span))
    h = min(math.sqrt(12.0 * eps) / omega_c, span / MIN_STEPS)
    if h * omega_max > EXPLICIT_STEP_OMEGA / EXPLICIT_COST_RATIO:
        options = {"step": h}
        if local_newton_ok(h, omega_max):
            options["newton_local_error"] = NEWTON_LOCAL_ERROR
        return MethodChoice(
            "GENALPHA", options=options, omega_elastic=omega_c, omega_max=omega_max, step=h,
            rtol=max(rtol, NEWTON_PER_PERIOD_ERROR * eps),
            reason=(f"stiff: the step {h:.3g} s that resolves the lowest elastic mode ({omega_c:.4g} rad/s) to a "
                    f"period error of {eps:.2g} is {h * omega_max:.3g}/omega_max ({omega_max:.4g} rad/s), beyond what an explicit method may take "
                    f"(~{EXPLICIT_STEP_OMEGA / EXPLICIT_COST_RATIO:g}/omega_max at equal cost): generalized-alpha damps "
                    "the fast modes instead of resolving them"))
    return MethodChoice(
        "DOPRI5", omega_elastic=omega_c, omega_max=omega_max,
        reason=(f"not stiff at this tolerance: the step {h:.3g} s that resolves the lowest elastic mode "
                f"({omega_c:.4g} rad/s) to a period error of {eps:.2g} (phase {phase:.2g} rad over the run) is only "
                f"{h * omega_max:.3g}/omega_max ({omega_max:.4g} rad/s): explicit, fifth order, is cheaper"))
