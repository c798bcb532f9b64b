"""``method="auto"``: pick the integrator from the constrained system's natural frequencies.

A scene is *stiff* for a run when the time step that resolves the motions the user asked about
is too long for its fastest mode.  The motions of interest are every flexible body's lowest
elastic mode (a mode that stores its potential energy in elastic or spring deformation, not in
gravity or constraint forces: a pendulum's swing is not elastic) and everything slower;
``omega_c`` is the highest of those (without flexible bodies: the lowest spring mode).

The stiff choice is ``RADAU5M`` (Radau IIA, order 5, L-stable, on the constrained second-order
equations) with a fixed step.  On a resolved mode ``omega`` its amplitude falls by about
``RADAU_DECAY (omega h)^6`` per step (the phase lags by less), so over the run ``omega_c`` loses
``RADAU_DECAY y^5 omega_c T`` of its amplitude, ``y = omega_c h``.  The chooser gives that the
budget ``phi = min(1, PHASE_PER_RTOL rtol)`` (20 rtol: 2e-5 over the whole run at the default
``rtol = 1e-6``) and caps ``y`` at ``RADAU_MAX_STEP_OMEGA`` (1: ~6 steps per period of
``omega_c``), so

    y = min(1, (phi / (RADAU_DECAY omega_c T))^(1/5)),   h = y / omega_c   (at most T / 20):

the step follows rtol (``y`` ~ ``rtol^(1/5)``): 0.2-0.33 on the built-in scenes at the default
rtol (where the former rule, budget ``1e5 rtol`` and cap 0.3, sat at its cap at every rtol, so
that tightening rtol did not tighten the answer), 0.8-1 at rtol 1e-3, 0.08-0.13 at 1e-8.

DOPRI5 has to resolve the fastest mode instead: on these scenes its own step control settles at
``h omega_max ~ 0.5`` on average (measured 0.2-0.7 at rtol 1e-6..1e-8, paper scene and flexible
four-bar), and a RADAU5M step costs about ``RADAU_COST_RATIO`` = 1.6 DOPRI5 steps.  So when
``h omega_max > 0.5 x 1.6`` RADAU5M is the cheaper way to the requested accuracy: the chooser
takes it with that fixed step (projection on; Newton to ``min(100 rtol, 1e-3)``), which damps
the fast modes instead of resolving them.  Otherwise (rigid systems, soft or slow flexible ones)
it takes native DOPRI5 at ``DOPRI5_RTOL_PER_RTOL`` x the user's rtol (0.3: at the user's rtol its
global error is 5-30 rtol over ~10 s on scenes with closed forms, at 0.3 rtol at most 5.6 rtol),
unless overdamped modes make it stiff: stiff
dampers turn a mode into a fast decay ``omega (zeta + sqrt(zeta^2 - 1))`` that holds DOPRI5 to
``h <= 3.3`` over it (its stability interval on the negative real axis) while the motion moves at
the slow rate ``omega (zeta - sqrt(zeta^2 - 1))``; when the step that motion needs (the rule above
on the slow rates) exceeds 1.6 such explicit steps, adaptive RADAU5M at the user's tolerances
(:func:`_overdamped_choice`; MBS benchmark A05, whose undamped frequencies stop at 404 rad/s while
its dampers decay at 8.1e3 1/s).  GENALPHA (second order) runs when the user
gives its own options (``rho_inf``, ``newton_local_error``).  See docs/integrators.md.

The analysis and the rule run in the core in one call (``rust/integrate/choice/``,
``System.core.auto_choice``: the constraint rank, the dense modal analysis, the elastic shares,
the floor, the overdamped modes, with the constants below in one place); this module states
the decision (:class:`MethodChoice`, its reason) and, for large systems, hands the core the
lowest modes of the sparse analysis (:mod:`ukflex.analysis.modes`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any, Callable, Dict, Optional, Tuple

import numpy as np

from .. import _core
from ..errors import SolverError

#: the chooser's constants, read from the core (``rust/integrate/choice/mod.rs``, the one place):
#: amplitude budget per rtol and its cap, fewest steps per run; RADAU5M's amplitude loss per
#: step ``RADAU_DECAY (omega h)^6`` and its largest step ``RADAU_MAX_STEP_OMEGA`` rad of omega_c;
#: its Newton tolerance ``min(NEWTON_PER_RTOL rtol, NEWTON_MAX_RTOL)`` (on a scene with a
#: geometrically exact beam ``NEWTON_MAX_RTOL_BEAM`` instead of ``NEWTON_MAX_RTOL``, and below
#: ``NEWTON_BEAM_FULL_RTOL`` at most ``NEWTON_MAX_RTOL_BEAM (rtol / NEWTON_BEAM_FULL_RTOL)^
#: NEWTON_BEAM_EXPONENT``); DOPRI5's average
#: ``h omega_max`` and a RADAU5M step's cost in DOPRI5 steps; DOPRI5's real stability interval;
#: GENALPHA's looser Newton test and the coarsest ``h omega_max`` where it is safe; the elastic
#: and body shares of a mode; the sparse analysis' first modes; the floor's body points; DOPRI5's
#: rtol per rtol (auto runs DOPRI5 tighter than asked: its global error at rtol is 5-30 rtol)
PHASE_PER_RTOL = _core.AUTO["PHASE_PER_RTOL"]
PHASE_CAP = _core.AUTO["PHASE_CAP"]
MIN_STEPS = int(_core.AUTO["MIN_STEPS"])
RADAU_DECAY = _core.AUTO["RADAU_DECAY"]
RADAU_MAX_STEP_OMEGA = _core.AUTO["RADAU_MAX_STEP_OMEGA"]
NEWTON_PER_RTOL = _core.AUTO["NEWTON_PER_RTOL"]
NEWTON_MAX_RTOL = _core.AUTO["NEWTON_MAX_RTOL"]
NEWTON_MAX_RTOL_BEAM = _core.AUTO["NEWTON_MAX_RTOL_BEAM"]
NEWTON_BEAM_FULL_RTOL = _core.AUTO["NEWTON_BEAM_FULL_RTOL"]
NEWTON_BEAM_EXPONENT = _core.AUTO["NEWTON_BEAM_EXPONENT"]
EXPLICIT_STEP_OMEGA = _core.AUTO["EXPLICIT_STEP_OMEGA"]
RADAU_COST_RATIO = _core.AUTO["RADAU_COST_RATIO"]
DOPRI5_REAL_STABILITY = _core.AUTO["DOPRI5_REAL_STABILITY"]
NEWTON_LOCAL_ERROR = _core.AUTO["NEWTON_LOCAL_ERROR"]
LOCAL_NEWTON_MIN_STEP_OMEGA = _core.AUTO["LOCAL_NEWTON_MIN_STEP_OMEGA"]
ELASTIC_SHARE = _core.AUTO["ELASTIC_SHARE"]
BODY_SHARE = _core.AUTO["BODY_SHARE"]
FIRST_MODES = int(_core.AUTO["FIRST_MODES"])
#: large systems up to this many coordinates get their floor from the whole dense spectrum
FLOOR_DENSE_MAX = int(_core.AUTO["FLOOR_DENSE_MAX"])
DOPRI5_RTOL_PER_RTOL = _core.AUTO["DOPRI5_RTOL_PER_RTOL"]
FLOOR_POINTS = tuple(_core.AUTO["FLOOR_POINTS"])


@dataclass
class MethodChoice:
    """What ``method="auto"`` picked and why (also ``SimulationResult.extra["auto"]``)."""

    method: str
    options: Dict[str, Any] = field(default_factory=dict)
    reason: str = ""
    omega_elastic: Optional[float] = None
    omega_max: float = 0.0
    step: Optional[float] = None
    #: the integrator's rtol when it differs from the user's
    rtol: Optional[float] = None
    #: RADAU5M's error floor [m]: the fast modes the initial state sets off, which its step damps
    #: (``rust/integrate/choice/floor.rs``); the history error stays above it whatever rtol
    floor: Optional[float] = None
    #: the largest contributions to it: ``(omega, amplitude at a body point [m], error [m])``
    floor_modes: list = field(default_factory=list)
    #: ``choose_method(..., floor=False)`` on a fixed-step RADAU5M choice: what computes the
    #: whole choice (``floor``, ``floor_modes``, the reason with its floor clause), and the
    #: reason as the core's decision stated it
    _floor_later: Optional[Tuple[Callable[[], "MethodChoice"], str]] = field(default=None, repr=False, compare=False)

    def as_dict(self) -> Dict[str, Any]:
        """The fields as a plain dict (the options dict and the floor's list copied)."""
        d = {name: getattr(self, name) for name in _STATED}
        d["options"], d["floor_modes"] = dict(self.options), list(self.floor_modes)
        return d

    def report(self, **more: Any) -> Dict[str, Any]:
        """``res.extra["auto"]``: :meth:`as_dict` with ``more``; a floor left out
        (``floor=False``) is an :class:`AutoReport` that computes it when read."""
        d = dict(self.as_dict(), **more)
        return d if self._floor_later is None else AutoReport(d, *self._floor_later)


#: the fields :meth:`MethodChoice.as_dict` states (read once: ``dataclasses.fields`` on every call
#: was ~2 us of auto's Python)
_STATED = tuple(f.name for f in fields(MethodChoice) if not f.name.startswith("_"))


class AutoReport(dict):
    """``res.extra["auto"]`` of a fixed-step RADAU5M run: a dict whose ``floor``, ``floor_modes``
    and ``reason`` (the floor's clause) are computed on their first read, and kept.

    The floor decides nothing (it is what the run's history error cannot go below,
    ``rust/integrate/choice/floor.rs``), and its analysis was ~40 % of auto's on small systems
    (the excitation of every fast mode and its history over the run), up to 62 ms on large ones
    (a dense spectrum of its own): ``simulate`` leaves it to the reader, as it leaves the
    residual norms (``SimulationResult.residuals``).  Every read of the whole dict (iteration,
    ``items``, ``dict(...)``, ``repr``, ``==``, pickling) computes it first."""

    _LATE = ("floor", "floor_modes", "reason")

    def __init__(self, values: Dict[str, Any], later: Callable[[], MethodChoice], bare_reason: str):
        super().__init__(values)
        self._later: Optional[Tuple[Callable[[], MethodChoice], str]] = (later, bare_reason)

    def _fill(self) -> None:
        if self._later is None:
            return
        later, bare = self._later
        self._later = None
        full = later()
        # the reason as stated now, with the floor's clause where the bare reason ended (a
        # scipy or GENALPHA mapping appended its own after it)
        said = dict.__getitem__(self, "reason")
        dict.update(self, floor=full.floor, floor_modes=list(full.floor_modes),
                    reason=full.reason + said[len(bare):] if said.startswith(bare) else said)

    def __getitem__(self, key: Any) -> Any:
        if key in self._LATE:
            self._fill()
        return dict.__getitem__(self, key)

    def get(self, key: Any, default: Any = None) -> Any:
        if key in self._LATE:
            self._fill()
        return dict.get(self, key, default)


def _filled_first(name: str) -> Callable:
    method = getattr(dict, name)

    def filled(self: AutoReport, *args: Any, **kwargs: Any) -> Any:
        self._fill()
        return method(self, *args, **kwargs)

    filled.__name__ = filled.__qualname__ = name
    filled.__doc__ = method.__doc__
    return filled


for _name in ("__iter__", "items", "values", "copy", "__repr__", "__eq__", "__ne__", "pop", "popitem", "setdefault",
              "update", "__setitem__", "__delitem__", "__or__", "__ror__", "__ior__"):
    setattr(AutoReport, _name, _filled_first(_name))
AutoReport.__hash__ = None  # type: ignore[assignment]


def _as_plain_dict(self: AutoReport) -> Tuple[Any, ...]:
    """Pickling and copying: a plain dict of the filled values."""
    return (dict, (dict(self),))


AutoReport.__reduce__ = _as_plain_dict  # type: ignore[assignment]


def elastic_shares(system, omega: np.ndarray, shapes: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Share of each mode's ``omega^2`` that is elastic: ``2 E_m / omega^2``, ``E_m`` the strain
    energy of the mode's first-order strains with the material stiffness alone, plus its springs'
    (``System.core.material_energies``; the mode is mass-normalized, so ``omega^2`` is its whole
    stiffness).  A swing stores none, whether the body is a rigid link, an FFRF beam (whose
    reference frame turns) or an ANCF cable (whose nodes turn, and whose tension's geometric
    stiffness is the same gravity restoring force): the models of one body get the same rule
    (the chooser's own copy is in the core: ``rust/integrate/choice/spectrum.rs``)."""
    shares = np.zeros(omega.size)
    live = omega > 0.0
    if live.any():
        e = np.asarray(system.core.material_energies(np.ascontiguousarray(q, dtype=float),
                                                     np.ascontiguousarray(shapes[:, live], dtype=float)))
        shares[live] = 2.0 * e / omega[live] ** 2
    return shares


def local_newton_ok(h: float, omega_max: float) -> bool:
    """Whether GENALPHA's Newton may stop at the local error level (``newton_local_error``) with
    step ``h`` on a system whose fastest mode is ``omega_max``: only on coarse steps."""
    return h * omega_max >= LOCAL_NEWTON_MIN_STEP_OMEGA


def _sparse_decision(system, t0, q, qd, t_end, rtol, deadline, floor=True) -> Tuple[Dict[str, Any], Dict[str, Any]]:
    """The core's decision for a large system (``System.SPARSE_MODES_MIN`` coordinates and more):
    ``omega_max`` from ``System.max_frequency`` and the lowest modes by shift-invert Lanczos,
    ``FIRST_MODES`` then four times more until the core has every flexible body's lowest elastic
    mode among them.  Returns the decision and the spectrum it was made on (the core's keywords)."""
    n_dof = system.n_dof
    d = system.core.auto_choice(t0, q, qd, t_end, rtol, n_dof=n_dof)
    if d["method"] is not None:  # no degree of freedom or no elastic potential: no spectrum needed
        return d, {"n_dof": n_dof}
    omega_max = system.max_frequency(t0, q, qd, deadline=deadline)
    k = FIRST_MODES
    while True:
        omega, shapes = system.frequencies(t0, q, qd, modes=True, count=min(k, n_dof), deadline=deadline)
        spectrum = {"n_dof": n_dof, "omega": np.ascontiguousarray(omega), "shapes": np.ascontiguousarray(shapes),
                    "omega_max": max(omega_max, float(np.abs(omega).max()))}
        d = system.core.auto_choice(t0, q, qd, t_end, rtol, floor=floor, **spectrum)
        if d["verdict"] != "need_more_modes" or omega.size >= n_dof:
            return d, spectrum
        k *= 4


def _stated(d: Dict[str, Any], span: float) -> MethodChoice:
    """The core's decision ``d`` as a :class:`MethodChoice` with its reason."""
    verdict, w_max = d["verdict"], d["omega_max"]
    if d["method"] == "DOPRI5":
        tight = (f"; DOPRI5 at rtol {d['rtol']:.3g} ({DOPRI5_RTOL_PER_RTOL:g} x rtol: at the user's rtol its "
                 "global error is 5-30 rtol over ~10 s on scenes with closed forms)")
    if verdict == "no_dof":
        return MethodChoice("DOPRI5", rtol=d["rtol"], reason="no degrees of freedom: the motion is prescribed" + tight)
    if verdict == "no_elastic_potential":
        return MethodChoice("DOPRI5", rtol=d["rtol"],
                            reason="no elastic mode (rigid bodies, no springs: no frequency analysis needed): not "
                                   "stiff, explicit" + tight)
    if verdict == "no_elastic_mode":
        return MethodChoice("DOPRI5", omega_max=w_max, rtol=d["rtol"],
                            reason=f"no elastic mode (fastest mode {w_max:.4g} rad/s): not stiff, explicit" + tight)
    w_c, h = d["omega_elastic"], d["step"]
    if verdict == "stiff":
        said = ""
        if d["floor"]:
            said = (f"; the fast modes the start sets off (largest at {d['floor_modes'][0][0]:.4g} rad/s) are "
                    f"damped: the history stays ~{d['floor']:.1e} m off at a body point whatever rtol "
                    "(method='DOPRI5' keeps them)")
        floor = {} if d["floor"] is None else {"floor": d["floor"], "floor_modes": [tuple(m) for m in d["floor_modes"]]}
        return MethodChoice(
            "RADAU5M", options={"step": h}, omega_elastic=w_c, omega_max=w_max, step=h, rtol=d["rtol"], **floor,
            reason=(f"stiff: the step {h:.3g} s ({w_c * h:.2g} rad of the lowest elastic mode, {w_c:.4g} rad/s, "
                    f"amplitude loss {RADAU_DECAY * (w_c * h) ** 5 * w_c * span:.1e} over the run) is "
                    f"{h * w_max:.3g}/omega_max ({w_max:.4g} rad/s), beyond what an explicit method may take "
                    f"(~{EXPLICIT_STEP_OMEGA * RADAU_COST_RATIO:g}/omega_max at equal cost): Radau IIA (order 5, "
                    "L-stable) damps the fast modes instead of resolving them" + said))
    if verdict == "stiff_contact":
        return MethodChoice(
            "RADAU5M", omega_elastic=w_c, omega_max=w_max,
            reason=(f"stiff (the fastest mode, {w_max:.4g} rad/s, is beyond an explicit step that resolves the "
                    f"lowest elastic one, {w_c:.4g} rad/s) and with contacts, whose impacts a step chosen before "
                    "the run cannot see: Radau IIA (L-stable) with its own step control at the user's tolerances"))
    if verdict == "overdamped":
        o = d["overdamped"]
        return MethodChoice(
            "RADAU5M", omega_elastic=w_c, omega_max=w_max,
            reason=(f"stiff by damping: the mode at {o['omega']:.4g} rad/s is overdamped (zeta {o['zeta']:.3g}): it "
                    f"decays at {o['fast']:.4g} 1/s, which holds an explicit step to {o['h_explicit']:.2g} s, while "
                    f"the motion (slowest elastic rate {w_c:.4g} 1/s) needs only ~{h:.2g} s: Radau IIA (L-stable) "
                    "with its own step control"))
    return MethodChoice(
        "DOPRI5", omega_elastic=w_c, omega_max=w_max, rtol=d["rtol"],
        reason=(f"not stiff at this tolerance: the step {h:.3g} s that resolves the lowest elastic mode "
                f"({w_c:.4g} rad/s) to an amplitude loss of {d['phase']:.2g} over the run is only "
                f"{h * w_max:.3g}/omega_max ({w_max:.4g} rad/s): explicit, fifth order, is cheaper" + tight))


def choose_method(system, t0: float, t_end: float, rtol: float, q: Optional[np.ndarray] = None,
                  qd: Optional[np.ndarray] = None, deadline: Optional[float] = None, floor: bool = True) -> MethodChoice:
    """The integrator ``method="auto"`` runs for ``system`` over ``[t0, t_end]`` at ``rtol``
    (``deadline``: a ``time.perf_counter()`` value; past it ``ukflex.analysis.modes.BudgetExceeded``;
    a small system's analysis is one call of the core, checked after it).

    ``floor=False`` leaves out the error floor of a fixed-step RADAU5M choice (it decides
    nothing): ``floor`` None and the reason without its clause, which :meth:`MethodChoice.report`
    (``simulate``'s ``res.extra["auto"]``) computes when read, from the same state and spectrum."""
    t0, t_end = float(t0), float(t_end)
    span = t_end - t0
    if not (math.isfinite(span) and span > 0.0):
        raise ValueError(f"t_end must be finite and greater than t0 = {t0}, got {t_end!r}")
    q = system.q0 if q is None else np.array(q, dtype=float)
    qd = system.qd0 if qd is None else np.array(qd, dtype=float)
    spectrum: Dict[str, Any] = {}
    if system.n_coords >= system.SPARSE_MODES_MIN:
        d, spectrum = _sparse_decision(system, t0, q, qd, t_end, rtol, deadline, floor)
    else:
        d = system.core.auto_choice(t0, q, qd, t_end, rtol, floor=floor)
    choice = _stated(d, span)
    if not floor and d["verdict"] == "stiff":
        decided = (choice.method, choice.step)

        def later() -> MethodChoice:
            full = _stated(system.core.auto_choice(t0, q, qd, t_end, rtol, **spectrum), span)
            if (full.method, full.step) != decided:  # the same analysis on the same state: never
                raise SolverError(f"method='auto': the floor's analysis decided {full.method} at step {full.step}, "
                                  f"the run's analysis {decided[0]} at {decided[1]}")
            return full

        choice._floor_later = (later, choice.reason)
    return choice
