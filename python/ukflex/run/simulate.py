"""Time integration: ``scipy.integrate`` solvers or the native Rust integrators, with
``solve_ivp``'s interface (``t_span``, ``t_eval``, ``dense_output``, ``events``, ``args``),
work budgets and partial results on every path (docs/solve-ivp.md)."""

from __future__ import annotations

import inspect
import math
import numbers
import time
import warnings
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union, cast

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import DOP853, OdeSolver
from scipy.integrate._ivp.rk import RungeKutta
from scipy.integrate._ivp.common import OdeSolution
from scipy.integrate import DenseOutput
from scipy.integrate._ivp.ivp import METHODS as _SCIPY_SOLVERS, find_active_events, handle_events, prepare_events

from .. import _core
from ..errors import (DriftWarning, IntegrationFailure, InvalidArgumentError, NonFiniteError,
                     SingularConfigurationWarning, SolverError, UnknownOptionError)
from ..arguments import count, positive, real, real_array
from ..results.simulation import SimulationResult
from ..model.scene import Scene
from ..model.spatial import SpatialScene
from ..model.system import System
from .stabilization import configure, segment_bounds

__all__ = ["simulate", "METHODS", "NATIVE_METHODS", "FORMULATIONS", "as_system", "time_acceleration", "DenseSolution"]

METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
#: The native methods' run options as the core defines them (``rust/integrate/options.rs``):
#: method names, the options each takes, the defaults.  Nothing here restates them.
RUN_OPTIONS: Dict[str, Any] = _core.run_options()
#: Integrators that run entirely in Rust with the GIL released (``System.integrate``).
NATIVE_METHODS = tuple(RUN_OPTIONS["native_methods"])
#: The core's options that :func:`simulate` does not take as its own keywords: passed through
#: to ``System.integrate`` (``simulate(..., rho_inf=0.8)``), each refused by the methods that do
#: not take it.
_OWN_KEYWORDS = ("rtol", "atol", "t_eval", "max_steps", "max_nfev", "max_wall_time", "min_step", "dense",
                 "drift_limit", "on_drift", "monitor_singular")
_NATIVE_OPTIONS_OF = {m: tuple(o for o in RUN_OPTIONS["options"][m] if o not in _OWN_KEYWORDS) for m in NATIVE_METHODS}
_NATIVE_OPTIONS = tuple(sorted({o for opts in _NATIVE_OPTIONS_OF.values() for o in opts}))
#: ``solve_ivp`` solver options passed through on the scipy paths.
_SCIPY_OPTIONS = ("first_step", "max_step", "jac", "jac_sparsity", "lband", "uband")
FORMULATIONS = ("uk", "uk-numpy", "cp")
#: Every method name, looked up case-insensitively ("dopri5", "radau" and "Radau" work).
_METHOD_BY_KEY = {m.upper(): m for m in METHODS + NATIVE_METHODS + ("auto",)}
#: A native run reports ``progress(t)`` every this many accepted steps ...
NATIVE_PROGRESS_STEPS = 100
#: ... or every this many seconds of wall time, whichever comes first.
NATIVE_PROGRESS_INTERVAL = 0.5
#: Default work budgets: step attempts and right-hand-side evaluations of one run.
DEFAULT_MAX_STEPS = 1_000_000
DEFAULT_MAX_NFEV = 20_000_000


def as_system(scene_or_system: Union[Scene, System, Dict[str, Any]], **build_options: Any) -> System:
    """Return a :class:`System` for a scene, a description dict or an existing system."""
    if isinstance(scene_or_system, System):
        if build_options:
            raise TypeError("build options cannot be applied to an already built System")
        return scene_or_system
    if isinstance(scene_or_system, (Scene, SpatialScene, dict)):
        return System(scene_or_system, **build_options)
    raise TypeError(f"expected a Scene, a SpatialScene, a description dict or a System, got {type(scene_or_system).__name__}")


# ------------------------------------------------------------------------------ argument checks
def _method_name(method: Any) -> Union[str, type]:
    if isinstance(method, str):
        key = method.upper()
        if key not in _METHOD_BY_KEY:
            raise InvalidArgumentError(
                "method", f"unknown method {method!r}; expected 'auto', one of {METHODS}, a native method "
                f"{NATIVE_METHODS} (any case) or an OdeSolver subclass")
        return _METHOD_BY_KEY[key]
    if inspect.isclass(method) and issubclass(method, OdeSolver):
        return method
    raise InvalidArgumentError("method", f"must be a method name or an OdeSolver subclass, got {method!r}")


def _check_options(method: Any, formulation: str, options: Dict[str, Any]) -> None:
    """Refuse options the chosen path does not take, naming the valid ones."""
    if formulation != "uk":
        return  # the NumPy references forward their options to their own solve_ivp call
    if method == "auto":
        valid = sorted(set(_NATIVE_OPTIONS) | set(_SCIPY_OPTIONS))
    elif method in NATIVE_METHODS:
        valid = sorted(_NATIVE_OPTIONS_OF[method])
    else:
        valid = sorted(_SCIPY_OPTIONS)
    unknown = sorted(set(options) - set(valid))
    elsewhere = [o for o in unknown if o in _NATIVE_OPTIONS]  # an option of other native methods
    if method in NATIVE_METHODS and elsewhere:
        o = elsewhere[0]
        takers = " and ".join(m for m in NATIVE_METHODS if o in _NATIVE_OPTIONS_OF[m])
        raise UnknownOptionError(o, f"applies to {takers} only, not to {method}; {method} takes {valid}", valid)
    if unknown:
        common = ["t_span", "t_eval", "rtol", "atol", "events", "dense_output", "args", "max_steps", "max_nfev",
                  "max_wall_time", "min_step", "q0", "qd0", "progress"]
        raise UnknownOptionError(
            unknown[0], f"unknown option(s) {unknown} for method {method!r}; valid: {valid} and the keywords {common}",
            valid)


def _with_args(fn: Callable, args: Tuple) -> Callable:
    """``fn(t, y, *args)`` as ``g(t, y)``, keeping ``terminal`` and ``direction``."""
    def g(t: float, y: np.ndarray, _fn: Callable = fn) -> float:
        return _fn(t, y, *args)

    for attr in ("terminal", "direction"):
        if hasattr(fn, attr):
            setattr(g, attr, getattr(fn, attr))
    return g


def simulate(
    scene_or_system: Union[Scene, System, Dict[str, Any]],
    t_end: Optional[float] = None,
    method: Union[str, type] = "auto",
    rtol: float = RUN_OPTIONS["defaults"]["rtol"],
    atol: Union[None, float, ArrayLike] = None,
    t_eval: Optional[ArrayLike] = None,
    formulation: str = "uk",
    *,
    t_span: Optional[Tuple[float, float]] = None,
    q0: Optional[ArrayLike] = None,
    qd0: Optional[ArrayLike] = None,
    partition: Any = None,
    progress: Optional[Callable[[float], None]] = None,
    events: Union[None, Callable, Sequence[Callable]] = None,
    dense_output: bool = False,
    args: Optional[Sequence[Any]] = None,
    max_steps: int = DEFAULT_MAX_STEPS,
    max_nfev: int = DEFAULT_MAX_NFEV,
    max_wall_time: Optional[float] = None,
    min_step: float = 0.0,
    on_drift: str = "stop",
    stabilization: Any = None,
    rank_tolerance: Any = None,
    pseudoinverse: Optional[str] = None,
    raise_on_failure: bool = False,
    **options: Any,
) -> SimulationResult:
    """Integrate the equations of motion from the system's consistent initial state to ``t_end``.

    The interface follows ``scipy.integrate.solve_ivp`` (docs/solve-ivp.md has the feature
    table): ``t_span``, ``t_eval``, ``dense_output``, ``events`` and ``args`` behave as there,
    for the scipy methods and the native ones alike, and ``res.y`` is ``solve_ivp``'s (2n, nt).

    Parameters
    ----------
    scene_or_system : Scene, dict or System
        What to simulate; scenes and dicts are built with default options.
    t_end : float
        End time [s], ``> t0`` (the system's initial time, normally 0).  Or give ``t_span``.
    method : str or scipy OdeSolver subclass
        ``"auto"`` (default): chosen from the constrained system's natural frequencies
        (:mod:`ukflex.choice`, docs/integrators.md): native ``"RADAU5M"`` with a fixed step
        that resolves the lowest elastic mode when the fastest modes are far beyond it (stiff
        flexible scenes), native ``"DOPRI5"`` otherwise; the choice and its reason are in
        ``res.method`` and ``res.extra["auto"]``.  Or any ``solve_ivp`` method: ``"Radau"``,
        ``"BDF"``, ``"LSODA"``, ``"RK45"``, ``"RK23"``, ``"DOP853"``; or a native Rust integrator
        (all steps in Rust, GIL released, same result object): ``"DOPRI5"`` (Dormand-Prince 5(4),
        dense output), ``"RADAU5"`` (Radau IIA order 5 on the UK right-hand side, Rust Jacobian),
        ``"RADAU5M"`` (Radau IIA order 5, L-stable, on the constrained second-order equations:
        the structured Newton matrix, fixed ``step`` or error-controlled steps, projection onto
        the constraints by default) or ``"GENALPHA"`` (generalized-alpha, second order:
        numerical dissipation ``rho_inf`` (default 0.9), the same Newton matrix, fixed ``step``
        or error-controlled steps, projection by default).  Names are case-insensitive.  Native
        methods take the options ``first_step``, ``max_step``, ``projection_tol`` (project onto
        the constraints after every accepted step whose residuals exceed it; 0: off) and
        ``jacobian``, RADAU5M and GENALPHA also ``step`` (with a fixed step ``rtol`` sets only
        the Newton tolerance), GENALPHA also ``rho_inf`` and ``newton_local_error`` (Newton may
        stop at this fraction of the step's local error estimate; safe only on coarse steps,
        ``h omega_max >= ukflex.run.choice.LOCAL_NEWTON_MIN_STEP_OMEGA``: on finer ones it feeds on
        its own error);
        see docs/integrators.md.
    rtol : float
        Relative tolerance (the paper used ``RelTol = 1e-6`` with ode15s); below 100 x machine
        epsilon it is raised to that floor with a warning, as ``solve_ivp`` does.  ``method="auto"``
        runs its integrator at an rtol derived from it (DOPRI5 at
        ``ukflex.run.choice.DOPRI5_RTOL_PER_RTOL`` x rtol, fixed-step RADAU5M with the Newton
        tolerance ``min(100 rtol, 1e-3)``), stated in ``res.rtol`` and ``res.extra["auto"]["rtol"]``.
    atol : float or array of shape (2n,), optional
        Absolute tolerance; default ``1e-3 * rtol``.
    t_eval : array of shape (nt,), optional
        Output times in ``[t0, t_end]``; default: the integrator's own steps.
    formulation : {"uk", "uk-numpy", "cp"}
        ``"uk"``: Udwadia-Kalaba accelerations from the Rust core.  ``"uk-numpy"`` and ``"cp"``
        (coordinate partitioning) come from the NumPy reference :mod:`ukflex.reference`
        (their own ``solve_ivp`` call: no events, dense output, args or budgets there).
    t_span : (t0, tf), optional
        ``solve_ivp``'s form of the interval; ``t0`` must be the system's initial time unless
        ``q0`` and ``qd0`` are given.
    q0, qd0 : array of shape (n,), optional
        Override the system's corrected initial state (not corrected again).
    partition : optional
        Passed to the ``"cp"`` reference integrator.
    progress : callable, optional
        ``progress(t)`` after every accepted step of a scipy method; during a native run, from
        Rust, every ``NATIVE_PROGRESS_STEPS`` (100) accepted steps or ``NATIVE_PROGRESS_INTERVAL``
        (0.5 s) of wall time, whichever comes first (the run takes the GIL only then); and once
        at the end with the last time.  An exception it raises ends the run and propagates (so
        does Ctrl-C during a native run with a progress callback).  Keep it cheap; used by the
        CLI's progress display.
    events : callable or list of callables, optional
        ``event(t, y[, *args])`` with ``solve_ivp``'s attributes ``terminal`` (bool or a count)
        and ``direction``; roots are located on the dense output of each step (scipy: by
        ``solve_ivp``'s own routine; native: on the recorded dense output after the run, the
        trajectory cut at a terminal event).  Results in ``res.t_events``, ``res.y_events``;
        ``res.status == 1`` after a terminal event.
    dense_output : bool
        Keep a continuous solution ``res.sol(t)`` -> (2n,) or (2n, k): scipy's ``OdeSolution``,
        or for native methods :class:`DenseSolution` (each method's own interpolant).
    args : tuple, optional
        Extra arguments passed to the event functions (the equations of motion come from the
        scene, so there is no user ``fun``); a user ``jac`` gets them too.
    max_steps, max_nfev : int
        Work budgets of the run: step attempts and right-hand-side evaluations (defaults
        1,000,000 and 20,000,000).  On scipy methods (about 0.1 ms of Python per step) the pace
        after 1,000 steps, and at each doubling, is extrapolated to ``t_end``: a run forecast to
        need more than 100 x ``max_steps`` stops there with status -1 and its partial result.
    max_wall_time : float, optional
        Wall-clock budget [s] (default: none).
    min_step : float
        Smallest step size [s] (default 0: the rounding limit); a ``max_step`` or fixed
        ``step`` (RADAU5M, GENALPHA) that cannot reach ``t_end`` within ``max_steps`` is refused up front.
    on_drift : {"stop", "warn"}
        What a run does when the constraint residual ``||Phi||`` of an accepted step passes the
        drift bound ``min(1000 (rtol L + atol), 0.01 L)`` (``L``: the scene's length scale;
        ``res.extra["drift_limit"]``): ``"stop"`` (default) ends it there with ``status = -1``,
        its partial result and a message naming the time and the residual (a result that left
        its constraints is not the mechanism's motion); ``"warn"`` goes on and reports it
        (:class:`ukflex.DriftWarning`, ``res.extra["drift"]``).
    stabilization : None, "none", "projection", ("baumgarte", alpha, beta) or dict
        Constraint stabilization (formulation ``"uk"``; docs/stability.md), applied to a copy
        of the system (the caller's System is never changed):

        * ``None`` (default): the method's own (the native methods, and scipy's explicit
          Runge-Kutta methods, project onto the constraints after every step);
        * ``"none"``: plain UK (the paper): nothing projects and ``Phi`` drifts;
        * ``("baumgarte", alpha, beta)`` or ``{"kind": "baumgarte", "alpha": a, "beta": b}``
          [1/s]: the acceleration constraint becomes ``Phi_dd + 2 alpha Phi_d + beta^2 Phi = 0``
          (``alpha = beta``: critically damped drift, decay time ``1/alpha``); large values make
          the system stiff (eigenvalues ~ -alpha); nothing projects;
        * ``"projection"`` or ``{"kind": "projection", "tol": 1e-12, "interval": dt}``: native
          methods project after each accepted step to ``tol``; scipy methods stop every
          ``interval`` seconds (default ``(t_end - t0) / 100``), project ``q`` onto ``Phi = 0``
          (Newton in the mass metric) and ``qd`` onto ``A qd + Phi_t = 0``
          (:meth:`ukflex.System.project`) and restart (``res.extra["projections"]``; no events
          or dense output there).

        ``res.extra["stabilization"]`` records it.
    rank_tolerance : (rcond, atol) or dict, optional
        Pseudoinverse tolerance of the UK solve: singular values of ``A F^-T`` at or below
        ``max(atol, rcond sigma_max)`` are dropped (``rcond=None``: ``max(m, n) eps``); on the
        copy of the system, as ``stabilization``.
    pseudoinverse : {"auto", "qr-jacobi", "faer"}, optional
        Pseudoinverse backend of the core, on the copy of the system.
    raise_on_failure : bool
        A run that ends early (``status = -1``) raises :class:`ukflex.stability.IntegrationFailure`
        with the partial result in ``.result`` (default: return it).
    **options
        Solver options: ``first_step``, ``max_step``, ``jac``, ... (scipy); ``first_step``,
        ``max_step``, ``projection_tol``, ``rho_inf``, ``step``, ``newton_local_error``, ``jacobian``, ``linear_solver``
        (native; ``"auto"``, ``"dense"`` or ``"sparse"`` Newton matrices, docs/scale.md).  An option
        the chosen method does not take raises :class:`UnknownOptionError` listing the valid
        ones.  For ``"Radau"`` and ``"BDF"`` the default ``jac`` is the core's finite-difference
        Jacobian ``System.jac``; ``nfev`` counts only the integrator's ``rhs`` calls.

    Returns
    -------
    SimulationResult
        ``t`` (nt,), ``y`` (2n, nt) = ``[q; qd]``, residual norms, statistics, ``t_events``,
        ``y_events``, ``sol``.  ``res.extra["singular"]``: the singular passages of the run
        (where the constraint Jacobian came close to losing rank: time, ``sigma_ratio`` of
        ``A M^-1/2`` there against the run's best, rank before, at and after; docs/integrators.md);
        a method that may leave the mechanism's branch there (``branch_keeping(method)`` is
        false) also warns with :class:`ukflex.SingularConfigurationWarning`.  A run that exceeds a budget or meets a non-finite state stops
        with ``status = -1``, keeps the trajectory up to its last accepted step and says why
        in ``res.message`` and ``res.stop`` (cause, time, coordinate).

    Raises
    ------
    InvalidArgumentError
        Bad ``t_end``/``t_span``, tolerances, ``t_eval``, method, formulation, budgets, arrays
        (a ``ValueError`` and ``TypeError`` too).
    UnknownOptionError
        An option the method does not take.
    NonFiniteError
        NaN or infinity in an input array.
    """
    call_start = time.perf_counter()  # max_wall_time covers every stage from here
    if formulation not in FORMULATIONS:
        raise InvalidArgumentError("formulation", f"unknown formulation {formulation!r}; expected one of {FORMULATIONS}")
    method = _method_name(method)
    if method in NATIVE_METHODS and formulation != "uk":
        raise InvalidArgumentError(
            "method", f"native method {method!r} integrates the Rust UK formulation only, not {formulation!r}")
    _check_options(method, formulation, options)
    if progress is not None and not callable(progress):
        raise InvalidArgumentError("progress", f"must be None or a callable progress(t), got {progress!r:.60}")
    if on_drift not in ("stop", "warn"):
        raise InvalidArgumentError("on_drift", f"must be 'stop' or 'warn', got {on_drift!r}")
    if max_wall_time is not None and not isinstance(scene_or_system, System):
        # a scene is built here: its initial-state correction spends the same budget
        system = as_system(scene_or_system, max_wall_time=positive("max_wall_time", max_wall_time))
    else:
        system = as_system(scene_or_system)
    label = proj_tol = None
    interval = 0.0
    if stabilization is not None or rank_tolerance is not None or pseudoinverse is not None:
        if formulation != "uk":
            raise InvalidArgumentError("stabilization", f"applies to formulation='uk' only, not {formulation!r}")
        if system is scene_or_system:  # never change the caller's System: another thread may be using it
            system = system.copy()
        label, proj_tol, interval = configure(system, stabilization, rank_tolerance, pseudoinverse)
    n = system.n_coords
    t0, t_end_f = _checked_span(system, t_end, t_span, q0, qd0)
    rtol, atol_v = _checked_tolerances(rtol, atol, n)
    t_eval_v = _checked_t_eval(t_eval, t0, t_end_f)
    q_init = system.q0 if q0 is None else real_array("q0", q0, (n,))
    qd_init = system.qd0 if qd0 is None else real_array("qd0", qd0, (n,))
    budget = _Budget(count("max_steps", max_steps), count("max_nfev", max_nfev),
                     None if max_wall_time is None else positive("max_wall_time", max_wall_time),
                     0.0 if min_step == 0 else positive("min_step", min_step), call_start)
    options = _checked_steps(options, budget, t0, t_end_f)
    if not isinstance(dense_output, (bool, np.bool_)):
        raise InvalidArgumentError("dense_output", f"must be True or False, got {dense_output!r}")
    ev_list, args = _checked_events(events, args)
    if args is not None and callable(options.get("jac")):
        options = dict(options, jac=_with_args(options["jac"], args))
    if formulation != "uk" and (ev_list or dense_output or args is not None):
        raise InvalidArgumentError(
            "formulation", f"events, dense_output and args need formulation='uk' (the NumPy reference {formulation!r} "
            "runs its own solve_ivp call)")
    auto_extra = None
    if method == "auto":
        from ..analysis.modes import BudgetExceeded

        start = time.perf_counter()
        try:
            method, options, choice = _resolve_auto(system, formulation, t0, t_end_f, rtol, q_init, qd_init, options,
                                                    budget.deadline)
        except BudgetExceeded as exc:
            return _spent_before_start(system, t0, q_init, qd_init, rtol, atol_v, budget, f"method='auto''s {exc.stage}",
                                       time.perf_counter() - start)
        choice_time = time.perf_counter() - start
        if budget.remaining() is not None and budget.remaining() <= 0.0:
            res = _spent_before_start(system, t0, q_init, qd_init, rtol, atol_v, budget,
                                      "method='auto''s modal analysis", choice_time)
            if choice is not None:
                res.extra["auto"] = choice.report(time=choice_time)
            return res
        if choice is not None:
            auto_extra = choice.report(time=choice_time)
            if choice.rtol is not None:  # the rtol the chosen integrator runs at, atol defaulted from it
                rtol, atol_v = _checked_tolerances(choice.rtol, atol, n)
        # the chosen method runs below with the arguments checked once above; its own options checked here
        _check_options(method, formulation, options)
        options = _checked_steps(options, budget, t0, t_end_f)
    y0 = np.concatenate([q_init, qd_init])
    guard = _Guard(drift_limit(system, rtol, atol_v), on_drift == "stop")
    if method in NATIVE_METHODS:
        if label is not None:  # "none" and Baumgarte: no projection (the native methods project by default)
            options.setdefault("projection_tol", 0.0 if proj_tol is None else proj_tol)
        res = _simulate_native(system, method, t0, t_end_f, y0, rtol, atol_v, t_eval_v, options, budget, ev_list,
                               dense_output, guard, progress)
        if progress is not None and res.t.size:
            progress(float(res.t[-1]))
    elif formulation != "uk":
        res = _simulate_reference(
            system, formulation, t_end_f, method, rtol, atol_v, t_eval_v, q_init, qd_init, partition, options
        )
        _guard_after(system, res, guard)
        if progress is not None and res.t.size:
            progress(float(res.t[-1]))
    else:
        if method in ("Radau", "BDF") and "jac" not in options:
            options["jac"] = system.jac  # Rust finite differences, GIL released
        if proj_tol is not None:
            if ev_list or dense_output:
                raise InvalidArgumentError("stabilization", "a scipy run projected at restarts takes no events or "
                                           "dense_output (use a native method, which projects after every step)")
            res = _simulate_scipy_restarts(system, method, t0, t_end_f, y0, rtol, atol_v, t_eval_v, options, budget,
                                           progress, guard, proj_tol, interval)
        else:
            res = _simulate_scipy(system, method, t0, t_end_f, y0, rtol, atol_v, t_eval_v, options, budget, ev_list,
                                  dense_output, progress, guard, project=label is None)
    res.extra.pop("_end", None)
    _report(system, res, guard, method, options)
    if label is not None:
        res.extra["stabilization"] = label
    if auto_extra is not None:
        res.extra["auto"] = auto_extra
    if raise_on_failure and res.status < 0:
        t_fail = float(res.t[-1]) if res.t.size else t0
        kind = label["kind"] if isinstance(label, dict) else (label or "default")
        raise IntegrationFailure(f"integration failed at t = {t_fail:.6g} s ({res.method}, {kind}): {res.message}; "
                                 f"the partial result ({res.t.size} outputs) is in .result", res, res.message, t_fail)
    return res


def _checked_span(system: System, t_end: Any, t_span: Any, q0: Any, qd0: Any) -> Tuple[float, float]:
    """``(t0, t_end)`` of a run from ``t_end`` or solve_ivp's ``t_span``, checked."""
    if t_span is not None:
        if t_end is not None:
            raise InvalidArgumentError("t_span", "give t_end or t_span, not both")
        if isinstance(t_span, (str, bytes)) or np.ndim(t_span) != 1 or len(t_span) != 2:
            raise InvalidArgumentError("t_span", f"must be a pair (t0, tf), got {t_span!r}")
        t0 = real("t_span[0]", t_span[0])
        t_end = t_span[1]
        if t0 != system.t0 and (q0 is None or qd0 is None):
            raise InvalidArgumentError(
                "t_span", f"t0 = {t0} differs from the system's initial time {system.t0}: give q0 and qd0 for it")
    else:
        t0 = system.t0
    if t_end is None:
        raise InvalidArgumentError("t_end", "missing: give t_end or t_span=(t0, tf)")
    t_end_f = real("t_end", t_end)
    if t_end_f <= t0:
        raise InvalidArgumentError("t_end", f"must be greater than t0 = {t0}, got {t_end!r}")
    return t0, t_end_f


def _checked_tolerances(rtol: Any, atol: Any, n: int) -> Tuple[float, Any]:
    """``(rtol, atol)`` checked by the core's one rule, ``atol`` defaulted from ``rtol``."""
    rtol = real("rtol", rtol)
    _core.check_tolerances(rtol, [0.0], 1)  # the one tolerance rule (rust/integrate/options.rs)
    if rtol < RTOL_MIN:  # as solve_ivp does: below it the error norm divides by rounding
        warnings.warn(f"rtol = {rtol:g} is below {RTOL_MIN:.3g} (100 x machine epsilon); using {RTOL_MIN:.3g}",
                      UserWarning, stacklevel=3)
        rtol = RTOL_MIN
    if atol is None:
        atol_v: Any = RUN_OPTIONS["defaults"]["atol_per_rtol"] * rtol
    elif np.ndim(atol) == 0 and not isinstance(atol, np.ma.MaskedArray):
        atol_v = real("atol", atol)
        _core.check_tolerances(rtol, [atol_v], 1)
    else:
        atol_v = real_array("atol", atol, (2 * n,))
        _core.check_tolerances(rtol, atol_v, 2 * n)
    return rtol, atol_v


def _checked_t_eval(t_eval: Any, t0: float, t_end_f: float) -> Optional[np.ndarray]:
    """The output times: ``None`` or a strictly increasing array within ``[t0, t_end]``."""
    t_eval_v: Optional[np.ndarray] = None
    if t_eval is not None:
        t_eval_v = real_array("t_eval", t_eval)
        if t_eval_v.ndim != 1 or t_eval_v.size == 0:
            raise InvalidArgumentError("t_eval", f"must be a non-empty 1-D array, got shape {t_eval_v.shape}")
        if np.any(np.diff(t_eval_v) <= 0):
            raise InvalidArgumentError("t_eval", "must be strictly increasing")
        if t_eval_v[0] < t0 or t_eval_v[-1] > t_end_f:
            raise InvalidArgumentError("t_eval", f"must lie within [t0, t_end] = [{t0}, {t_end_f}]")
    return t_eval_v


def _checked_steps(options: Dict[str, Any], budget: "_Budget", t0: float, t_end_f: float) -> Dict[str, Any]:
    """``options`` with ``first_step``, ``max_step`` and ``step`` checked positive and within the
    step budget."""
    if options.get("first_step") is not None:  # every method's: a positive number (scipy's compare it as given)
        options = dict(options, first_step=positive("first_step", options["first_step"]))
    for key in ("max_step", "step"):  # a step size that cannot reach t_end within the step budget
        if options.get(key) is not None:
            h = positive(key, options[key])
            options = dict(options, **{key: h})
            if (t_end_f - t0) / h > budget.max_steps:
                raise InvalidArgumentError(
                    key, f"{key} = {h:g} needs {(t_end_f - t0) / h:.3g} steps to reach t_end, more than max_steps = "
                    f"{budget.max_steps}")
            if h < budget.min_step:
                raise InvalidArgumentError(key, f"{key} = {h:g} is below min_step = {budget.min_step:g}")
    return options


def _checked_events(events: Any, args: Any) -> Tuple[List[Callable], Optional[Tuple]]:
    """solve_ivp's ``events`` (each callable, with its ``terminal`` and ``direction`` checked,
    ``args`` bound) and ``args`` as a tuple."""
    if args is not None:
        if isinstance(args, (str, bytes)) or not isinstance(args, (tuple, list)):
            args = (args,)  # solve_ivp: "If the function has a single argument, wrap it in a tuple"
        args = tuple(args)
    ev_list: List[Callable] = []
    if events is not None:
        ev_list = list(events) if isinstance(events, (list, tuple)) else [cast(Callable, events)]
        for k, ev in enumerate(ev_list):
            if not callable(ev):
                raise InvalidArgumentError("events", f"entry {k} is not callable: {ev!r}")
            terminal = getattr(ev, "terminal", None)
            if terminal is not None and not (isinstance(terminal, (bool, np.bool_)) or (
                    isinstance(terminal, numbers.Integral) and 0 <= terminal <= 2 ** 53)):
                raise InvalidArgumentError("events", f"entry {k}: terminal must be a boolean or a whole number of "
                                           f"occurrences up to 2**53 (solve_ivp's rule), got {terminal!r:.60}")
            direction = getattr(ev, "direction", None)
            if direction is not None:
                real(f"events[{k}].direction", direction)
        if args is not None:
            ev_list = [_with_args(ev, args) for ev in ev_list]
    return ev_list, args


#: the drift bound: a run whose constraint residual passes this many times (rtol x length scale
#: + atol) did not deliver the accuracy it was asked for ...
DRIFT_FACTOR = 1000.0
#: ... nor did a run whose constraints drifted by more than this fraction of the scene's length
#: scale, whatever the tolerances (an absolute atol of 1e-11 m cannot resolve a 1e-16 m pendulum)
DRIFT_OF_SCALE = 1e-2


def drift_limit(system: System, rtol: float, atol: Any) -> float:
    """The drift bound of a run at ``rtol``, ``atol`` on ``||Phi||``:
    ``min(DRIFT_FACTOR (rtol L + atol), DRIFT_OF_SCALE L)``, ``L`` the scene's length scale."""
    scale = system.length_scale
    return min(DRIFT_FACTOR * (rtol * scale + float(np.min(atol))), DRIFT_OF_SCALE * scale)


class _Guard:
    """What a run checks at every accepted step: the drift bound (``on_drift``)."""

    def __init__(self, limit: float, stop: bool):
        self.limit, self.stop = limit, stop


#: the methods that keep a mechanism on its branch through a singular configuration (with their
#: default projection): native DOPRI5 and scipy's explicit Runge-Kutta methods, which project
#: onto the constraints after every step and filter their error estimate onto the constraints'
#: tangent space (docs/integrators.md, singular configurations; tests/test_singular.py)
BRANCH_KEEPING = ("DOPRI5", "RK23", "RK45", "DOP853")


def branch_keeping(method: Any, options: Optional[Dict[str, Any]] = None) -> bool:
    """Whether ``method`` (with ``options``) keeps the mechanism on its branch at singular
    configurations; the others warn when a run passes one (:class:`SingularConfigurationWarning`)."""
    name = method if isinstance(method, str) else getattr(method, "__name__", "")
    if name not in BRANCH_KEEPING and not (inspect.isclass(method) and issubclass(method, RungeKutta)):
        return False
    return not (options and options.get("projection_tol") == 0)


def _drift_text(residual: float, t: float, limit: float) -> str:
    return (f"the constraints drifted to ||Phi|| = {residual:.3g} at t = {t:.6g} s, beyond the drift bound "
            f"{limit:.3g} (min({DRIFT_FACTOR:g} x (rtol x length scale + atol), {DRIFT_OF_SCALE:g} x length scale)): "
            "the result is not the mechanism's motion from there on (check the scene's units and scales, tighten "
            "rtol, or keep the default projection)")


def _guard_after(system: System, res: SimulationResult, guard: _Guard) -> None:
    """The drift guard for a run made elsewhere (the NumPy references): the residual norms of
    the outputs against the bound; with ``on_drift="stop"`` the result ends before the first
    output beyond it."""
    pos = np.asarray(res.residuals.get("position", ()), dtype=float)
    bad = np.flatnonzero(~(pos <= guard.limit))
    if bad.size == 0:
        return
    k = int(bad[0])
    text = _drift_text(float(pos[k]), float(res.t[k]), guard.limit)
    if guard.stop:
        t_bad = float(res.t[k])
        res.t, res.q, res.qd = res.t[:k], res.q[:, :k], res.qd[:, :k]
        res.residuals = {key: v[:k] for key, v in res.residuals.items()}
        res.status = -1
        res.message = text + (f"; the result holds the run up to t = {res.t[-1]:.9g} s" if k else "")
        res.stop = {"cause": "drift", "t": float(res.t[-1]) if k else t_bad, "message": res.message}
    else:
        worst = int(np.argmax(np.where(np.isfinite(pos), pos, np.inf)))
        res.extra["drift"] = dict(t_first=float(res.t[k]), max_residual=float(pos[worst]), t_max=float(res.t[worst]))


def _report(system: System, res: SimulationResult, guard: _Guard, method: Any, options: Dict[str, Any]) -> None:
    """What every run reports: the drift bound, a drift beyond it (``on_drift="warn"``), the
    singular passages (and a warning when the method may leave the branch there)."""
    res.extra["drift_limit"] = guard.limit
    d = res.extra.get("drift")
    if d is not None:
        text = _drift_text(d["max_residual"], d["t_max"], guard.limit)
        d["message"] = text
        warnings.warn(text, DriftWarning, stacklevel=3)
    passages = res.extra.get("singular")
    if passages is None:
        passages = res.extra["singular"] = _passages(system, res)
    if passages and not branch_keeping(method, options):
        name = method if isinstance(method, str) else getattr(method, "__name__", str(method))
        ts = ", ".join(f"{p['t']:.6g}" for p in passages[:3]) + (", ..." if len(passages) > 3 else "")
        warnings.warn(f"the run passed {len(passages)} singular configuration(s) of the constraints (t = {ts} s; "
                      f"res.extra['singular']): {name} may leave the mechanism's branch or lose its accuracy there; "
                      "DOPRI5 (method='auto' on non-stiff scenes) keeps the branch (docs/integrators.md)",
                      SingularConfigurationWarning, stacklevel=3)


def _passages(system: System, res: SimulationResult) -> List[Dict[str, Any]]:
    """Singular passages of a run made elsewhere, from its recorded states (the steps when the
    run kept them, else the outputs)."""
    steps = res.extra.pop("_steps", None)
    t, y = (steps if steps is not None else (res.t, res.y))
    if system.n_constraints == 0 or np.size(t) < 3:
        return []
    keep = np.concatenate([[True], np.diff(t) > 0])
    return list(system.core.singular_passages(np.ascontiguousarray(t[keep]), np.ascontiguousarray(y[:, keep])))


#: the projection after each step of scipy's explicit methods: Newton on the positions to this
#: fraction of the smallest position atol (the native default, ``integrate::PROJECTION_PER_ATOL``)
_NATIVE_PROJECTION_PER_ATOL = float(_core.PROJECTION_PER_ATOL)
#: ... and a step whose projection moves the state further (in units of the tolerance) away
#: from singular configurations is retried shorter (``dopri5::PROJECTION_MOVE_LIMIT``)
_PROJECTION_MOVE_LIMIT = float(_core.PROJECTION_MOVE_LIMIT)

#: smallest relative tolerance (solve_ivp's own floor: 100 x machine epsilon)
RTOL_MIN = RUN_OPTIONS["defaults"]["rtol_min"]

#: scipy paths (about 0.1 ms of Python per step): after this many steps, and at each doubling,
#: the pace so far is extrapolated to t_end ...
FORECAST_FIRST = 1000
#: ... and a run forecast to need more than this many times max_steps stops there (status -1,
#: partial result), instead of grinding minutes towards a budget it cannot finish within
FORECAST_FACTOR = 100


class _Budget:
    def __init__(self, max_steps: int, max_nfev: int, max_wall_time: Optional[float], min_step: float,
                 start: Optional[float] = None):
        self.max_steps, self.max_nfev, self.max_wall_time, self.min_step = max_steps, max_nfev, max_wall_time, min_step
        #: ``time.perf_counter()`` when the wall-time budget runs out (counted from the call)
        start = time.perf_counter() if start is None else start
        self.deadline = None if max_wall_time is None else start + max_wall_time

    def remaining(self) -> Optional[float]:
        """Seconds of wall time left (None: no budget)."""
        return None if self.deadline is None else self.deadline - time.perf_counter()


def _spent_before_start(system, t0, q, qd, rtol, atol, budget, stage: str, wall: float) -> SimulationResult:
    """The result of a run whose wall-time budget ran out before its first step (status -1,
    the initial state only), naming the stage that spent it."""
    y = np.concatenate([q, qd])[:, None]
    message = (f"work budget max_wall_time = {budget.max_wall_time} s exhausted before the first step, in {stage}; "
               f"the result holds the initial state only")
    stop = {"cause": "max_wall_time", "t": float(t0), "stage": stage, "message": message}
    return _result(system, np.array([float(t0)]), y, "auto", rtol, atol, nfev=0, njev=0, nlu=0, wall=wall, status=-1,
                   message=message, stop=stop, t_events=None, y_events=None, sol=None, extra={})


class _Stop(Exception):
    """Ends a scipy run from inside the right-hand side (a budget or a non-finite value)."""

    def __init__(self, cause: str, stage: str = "", index: Optional[int] = None, detail: str = ""):
        super().__init__(cause)
        self.cause, self.stage, self.index, self.detail = cause, stage, index, detail


def _stop_info(system: System, cause: str, t: float, stage: str = "", index: Optional[int] = None,
               detail: str = "") -> Tuple[Dict[str, Any], str]:
    """``res.stop`` and the message for a run that ended early."""
    info: Dict[str, Any] = {"cause": cause, "t": float(t)}
    if cause == "non_finite" and index is not None:
        names = system.coordinate_names
        what = {"q": "coordinate", "qd": "velocity", "qdd": "acceleration"}.get(stage, stage)
        info.update(stage=stage, coordinate=names[index] if index < len(names) else str(index))
        msg = f"non-finite {what} of '{info['coordinate']}' at t = {t:.9g} s; the result holds the run up to there"
    elif cause == "non_finite":
        msg = f"non-finite state at t = {t:.9g} s ({detail}); the result holds the run up to there"
    elif cause == "max_steps" and detail.startswith("at this pace"):
        msg = f"work budget max_steps cannot suffice: stopped at t = {t:.9g} s ({detail}); the result holds the run up to there"
    elif cause in ("max_steps", "max_nfev", "max_wall_time"):
        msg = f"work budget {cause} exhausted at t = {t:.9g} s ({detail}); the result holds the run up to there"
    elif cause == "drift":
        msg = f"{detail}; the result holds the run up to t = {t:.9g} s"
    elif cause == "min_step":
        msg = f"step size below the minimum at t = {t:.9g} s ({detail}); the result holds the run up to there"
    else:
        msg = f"integration failed at t = {t:.9g} s: {detail}"
    info["message"] = msg
    return info, msg


class _EndShifted(DenseOutput):
    """A step's interpolant moved by ``theta (y_end' - y_end)``: it ends at the projected state."""

    def __init__(self, inner: DenseOutput, shift: np.ndarray):
        super().__init__(inner.t_old, inner.t)
        self.inner, self.shift = inner, shift

    def _call_impl(self, t):
        theta = (np.asarray(t) - self.t_old) / (self.t - self.t_old) if self.t != self.t_old else np.ones_like(t)
        return self.inner._call_impl(t) + (np.multiply.outer(self.shift, theta) if np.ndim(t) else self.shift * theta)


def _end_shifted(sol: DenseOutput, shift: Optional[np.ndarray]) -> DenseOutput:
    return sol if shift is None else _EndShifted(sol, shift)


def _tangent_filtered(cls: type, system: System) -> type:
    """scipy's explicit Runge-Kutta class ``cls`` with the part of its local error estimate across
    the constraints (at the step's new state, ``System.tangent_project``) weighed by
    ``normal_weight``, as native DOPRI5 does (docs/integrators.md, singular configurations)."""
    n = system.n_coords
    project = system.core.tangent_project

    def filtered(self: Any, vectors: List[np.ndarray], h: float) -> List[np.ndarray]:
        y_new = self.y + h * (self.K[:-1].T @ self.B)
        cols = np.column_stack([v[:n] for v in vectors] + [v[n:] for v in vectors])
        p, kappa = project(self.t + h, np.ascontiguousarray(y_new[:n]), np.ascontiguousarray(cols))
        kappa_ref = getattr(self, "_kappa_ref", kappa)
        self._kappa_ref = max(kappa_ref, kappa)
        # the part across the constraints kept at the weight normal_weight (as native DOPRI5)
        self._weight = _core.normal_weight(kappa, kappa_ref)
        p += math.sqrt(self._weight) * (cols - p)
        k = len(vectors)
        return [np.concatenate([p[:, i], p[:, k + i]]) for i in range(k)]

    if issubclass(cls, DOP853):
        class Filtered(cls):  # type: ignore[misc, valid-type]
            def _estimate_error_norm(self, K, h, scale):  # DOP853's own combination of its two estimates
                e5, e3 = filtered(self, [K.T @ self.E5, K.T @ self.E3], h)
                err5, err3 = e5 / scale, e3 / scale
                n5, n3 = float(np.linalg.norm(err5)) ** 2, float(np.linalg.norm(err3)) ** 2
                if n5 == 0 and n3 == 0:
                    return 0.0
                return np.abs(h) * n5 / np.sqrt((n5 + 0.01 * n3) * len(scale))
    else:
        class Filtered(cls):  # type: ignore[misc, valid-type, no-redef]
            def _estimate_error(self, K, h):
                return filtered(self, [K.T @ self.E], h)[0] * h
    Filtered.__name__ = cls.__name__
    return Filtered


def _after_step(system, solver, fun, project, position_tol, atol, rtol, n, saved):
    """After an accepted step of a scipy solver on a constrained system: the projection of the
    explicit methods (with the step undone when its Newton does not converge: the error across
    the constraints, which the filtered estimate leaves to it, is then beyond its reach) and
    ``||Phi||`` of the state. Returns ``(||Phi||, the dense output's end shift, undone)``."""
    q1, v1 = solver.y[:n], solver.y[n:]
    if not project:
        return float(np.linalg.norm(system.phi(float(solver.t), q1))), None, False
    q1, v1, phi, converged = system.core.project_step(float(solver.t), q1, v1, position_tol)
    if not converged:
        solver.t, solver.y, solver.f = saved[:3]
        solver.h_abs = 0.3 * saved[3]
        solver.status = "running"
        return phi, None, True
    y_new = np.concatenate([q1, v1])
    floor = 100.0 * np.finfo(float).eps * np.abs(y_new).max()  # the rounding of the largest entry
    moved = np.sqrt(np.mean(((y_new - solver.y) / (atol + rtol * np.abs(y_new) + floor)) ** 2))
    if getattr(solver, "_weight", 1.0) == 1.0 and moved > _PROJECTION_MOVE_LIMIT and getattr(solver, "_projected", False):
        # away from singular configurations: an estimate blind to an error the projection
        # would hide (as native DOPRI5)
        solver.t, solver.y, solver.f = saved[:3]
        solver.h_abs = 0.3 * saved[3]
        solver.status = "running"
        return phi, None, True
    # RK23/RK45 interpolate from the step's start and stages: moved to the new end; DOP853's
    # interpolant reads the end state itself
    shift = None if isinstance(solver, DOP853) else y_new - solver.y
    solver.y = y_new
    solver._projected = True  # a start off the constraints moves the first step only
    if moved > 1.0:
        solver.f = fun(solver.t, y_new)
    return phi, shift, False


def _simulate_scipy(system, method, t0, tf, y0, rtol, atol, t_eval, options, budget, events, dense, progress, guard,
                    project=True):
    """``solve_ivp``'s loop over a scipy ``OdeSolver`` (the one scipy driver loop), with work
    budgets, a non-finite check with its cause, the drift guard at every step, and the
    trajectory kept when the run stops early. With ``project``, scipy's explicit Runge-Kutta
    methods project onto the constraints after every step and filter their error estimate
    (``_tangent_filtered``), as native DOPRI5 does; ``extra["_end"]`` is the last accepted
    state."""
    n = system.n_coords
    rhs = system.rhs
    nfev = [0]
    restart = getattr(getattr(system, "core", None), "restart_turns", None)
    if restart is not None:  # the spatial angles are counted from this run's start (not a NumPy reference)
        restart()

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        nfev[0] += 1
        if nfev[0] > budget.max_nfev:
            raise _Stop("max_nfev")
        try:
            out = rhs(t, y)  # the core refuses a non-finite y (and a non-finite result)
        except NonFiniteError:
            bad = np.flatnonzero(~np.isfinite(y))
            if not bad.size:
                raise _Stop("non_finite", "qdd", 0) from None
            i = int(bad[0])
            raise _Stop("non_finite", "q" if i < n else "qd", i % n) from None
        if not np.isfinite(out).all():
            raise _Stop("non_finite", "qdd", int(np.flatnonzero(~np.isfinite(out[n:]))[0]))
        return out

    solver_cls = _SCIPY_SOLVERS[method] if isinstance(method, str) else method
    name = method if isinstance(method, str) else method.__name__
    # explicit Runge-Kutta on a constrained system: projection after every step, filtered estimate
    project = project and system.n_constraints > 0 and issubclass(solver_cls, RungeKutta)
    if project:
        solver_cls = _tangent_filtered(solver_cls, system)
    atol_q = float(np.min(np.broadcast_to(atol, (2 * n,))[:n]))
    position_tol = _NATIVE_PROJECTION_PER_ATOL * atol_q
    saved = None
    t_steps: List[float] = [t0]
    y_steps: List[np.ndarray] = [y0]
    start = time.perf_counter()
    ts: List[Any] = [] if t_eval is not None else [t0]
    ys: List[Any] = [] if t_eval is not None else [y0]
    ti = [t0]
    interpolants: List[Any] = []
    t_events: Optional[List[List[float]]] = None
    y_events: Optional[List[List[np.ndarray]]] = None
    stop = None
    status: Optional[int] = None
    message = ""
    t_eval_i = 0
    steps = 0
    solver = None
    drift: Dict[str, Any] = {}
    try:
        solver = solver_cls(fun, t0, y0, tf, rtol=rtol, atol=atol, **options)
        if events:
            events, max_events, event_dir = prepare_events(events)
            event_count = np.zeros(len(events))
            g = [ev(t0, y0) for ev in events]
            t_events, y_events = [[] for _ in events], [[] for _ in events]
        if t_eval is not None and t_eval[0] == t0:
            ts.append(t_eval[:1])
            ys.append(y0[:, None])
            t_eval_i = 1
        if progress is not None:
            progress(float(t0))
        forecast_at = FORECAST_FIRST
        while status is None:
            if steps >= budget.max_steps:
                raise _Stop("max_steps")
            if steps == forecast_at:  # a run that cannot finish within the budget stops early
                forecast_at *= 2
                done = abs(float(solver.t) - t0)
                needed = steps * abs(tf - t0) / done if done > 0.0 else math.inf
                if needed > FORECAST_FACTOR * budget.max_steps:
                    raise _Stop("max_steps", detail=f"at this pace ({steps} steps for {done:.3g} s) reaching t_end needs "
                                                    f"about {needed:.3g} steps, more than {FORECAST_FACTOR} x max_steps = "
                                                    f"{budget.max_steps}; shorten t_end or raise max_steps")
            if budget.deadline is not None and time.perf_counter() > budget.deadline:
                raise _Stop("max_wall_time")
            if project:
                saved = (solver.t, solver.y, solver.f, solver.h_abs)
            try:
                message = solver.step()
            except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:  # e.g. lu_factor on infinities
                text = str(exc)
                cause = "non_finite" if ("inf" in text or "NaN" in text) else "solver"
                stop, message = _stop_info(system, cause, solver.t, detail=text)
                status = -1
                break
            steps += 1
            shift = None
            try:
                phi, shift, undo = _after_step(system, solver, fun, project, position_tol, atol, rtol, n, saved) \
                    if solver.status != "failed" and system.n_constraints > 0 else (0.0, None, False)
            except (NonFiniteError, SolverError) as exc:
                cause = "non_finite" if isinstance(exc, NonFiniteError) else "solver"
                stop, message = _stop_info(system, cause, float(solver.t_old or t0), detail=str(exc))
                status = -1
                break
            if undo:
                continue
            if solver.status != "failed" and system.n_constraints > 0:
                if not phi <= guard.limit:
                    if guard.stop:
                        stop, message = _stop_info(system, "drift", float(solver.t_old or t0),
                                                   detail=_drift_text(phi, float(solver.t), guard.limit))
                        status = -1
                        break
                    d = drift.setdefault("report", dict(t_first=float(solver.t), max_residual=phi, t_max=float(solver.t)))
                    if phi > d["max_residual"]:
                        d.update(max_residual=phi, t_max=float(solver.t))
                t_steps.append(float(solver.t))
                y_steps.append(solver.y.copy())
            if solver.status == "finished":
                status = 0
            elif solver.status == "failed":
                stop, message = _stop_info(system, "solver", solver.t, detail=str(message))
                status = -1
                break
            t_old, t, y = solver.t_old, solver.t, solver.y
            sol = _end_shifted(solver.dense_output(), shift) if dense else None
            if dense:
                interpolants.append(sol)
            if events:
                g_new = [ev(t, y) for ev in events]
                active = find_active_events(g, g_new, event_dir)
                if active.size > 0:
                    if sol is None:
                        sol = _end_shifted(solver.dense_output(), shift)
                    event_count[active] += 1
                    root_indices, roots, terminate = handle_events(sol, events, active, event_count, max_events,
                                                                   t_old, t)
                    for e, te in zip(root_indices, roots):
                        t_events[e].append(te)
                        y_events[e].append(sol(te))
                    if terminate:
                        status = 1
                        t = roots[-1]
                        y = sol(t)
                g = g_new
            if dense:
                ti.append(t)  # the step end, or the terminal event's root (as solve_ivp)
            if t_eval is None:
                ts.append(t)
                ys.append(y)
            else:
                i_new = np.searchsorted(t_eval, t, side="right")
                if i_new > t_eval_i:
                    if sol is None:
                        sol = _end_shifted(solver.dense_output(), shift)
                    ts.append(t_eval[t_eval_i:i_new])
                    ys.append(sol(t_eval[t_eval_i:i_new]))
                    t_eval_i = i_new
            if progress is not None:
                progress(float(t))
            if status is None and budget.min_step > 0 and solver.step_size is not None \
                    and solver.step_size < budget.min_step and solver.t < tf:
                raise _Stop("min_step")
    except _Stop as s:
        t_last = float(solver.t) if solver is not None else t0
        if solver is not None and s.cause == "non_finite":
            t_last = float(solver.t)  # the last accepted step: the non-finite value came from a stage beyond it
        detail = {"max_steps": f"{steps} steps", "max_nfev": f"{nfev[0] - 1} right-hand-side calls",
                  "max_wall_time": f"{budget.max_wall_time} s",
                  "min_step": f"h = {getattr(solver, 'step_size', None) or 0.0:.3g} s < min_step = {budget.min_step:g} s"}
        stop, message = _stop_info(system, s.cause, t_last, s.stage, s.index, s.detail or detail.get(s.cause, ""))
        status = -1
    wall = time.perf_counter() - start
    if status == 0:
        message = "The solver successfully reached the end of the integration interval."
    elif status == 1:
        message = "A termination event occurred."
    if t_eval is None:
        t_arr, y_arr = np.array(ts, dtype=float), np.vstack(ys).T
    elif ts:
        t_arr, y_arr = np.hstack(ts), np.hstack(ys)
    else:
        t_arr, y_arr = np.zeros(0), np.zeros((2 * n, 0))
    sol_obj = None
    if dense and interpolants:
        sol_obj = OdeSolution(ti, interpolants, alt_segment=method in ("BDF", "LSODA"))
    extra: Dict[str, Any] = {"steps": steps}
    if solver is not None:
        extra["_end"] = (float(solver.t), np.array(solver.y, dtype=float))
    if "report" in drift:
        extra["drift"] = drift["report"]
    if system.n_constraints > 0:
        extra["_steps"] = (np.asarray(t_steps), np.column_stack(y_steps))
    return _result(system, t_arr, y_arr, name, rtol, atol, nfev=solver.nfev if solver is not None else nfev[0],
                   njev=getattr(solver, "njev", 0), nlu=getattr(solver, "nlu", 0), wall=wall, status=status,
                   message=message, stop=stop, t_events=t_events, y_events=y_events, sol=sol_obj, extra=extra)


def _simulate_scipy_restarts(system, method, t0, tf, y0, rtol, atol, t_eval, options, budget, progress, guard,
                             proj_tol, interval):
    """``stabilization="projection"`` on a scipy method: the driver loop of :func:`_simulate_scipy`
    over the pieces between :func:`segment_bounds`, each restarted from the previous end projected
    onto the constraints (``System.project``); one result (``extra["projections"]``,
    ``extra["max_projection_correction"]``)."""
    n = system.n_coords
    bounds = segment_bounds(t0, tf, interval)
    ts: List[np.ndarray] = []
    ys: List[np.ndarray] = []
    steps_t: List[np.ndarray] = []
    steps_y: List[np.ndarray] = []
    projections: List[float] = []
    nfev = njev = nlu = steps = 0
    wall = 0.0
    drift: Optional[Dict[str, Any]] = None
    y = np.array(y0, dtype=float)
    part = None
    for k in range(len(bounds) - 1):
        ta, tb = bounds[k], bounds[k + 1]
        seg_eval = None
        if t_eval is not None:
            seg_eval = t_eval[(t_eval >= ta) & (t_eval <= tb)] if k == 0 else t_eval[(t_eval > ta) & (t_eval <= tb)]
        seg_budget = _Budget(max(1, budget.max_steps - steps), max(1, budget.max_nfev - nfev), budget.max_wall_time,
                             budget.min_step)
        seg_budget.deadline = budget.deadline
        part = _simulate_scipy(system, method, ta, tb, y, rtol, atol, seg_eval if seg_eval is None or seg_eval.size
                               else None, options, seg_budget, [], False, progress, guard, project=False)
        nfev, njev, nlu = nfev + int(part.nfev), njev + int(part.njev), nlu + int(part.nlu)
        steps += int(part.extra.get("steps", 0))
        wall += float(part.wall_time)
        if "drift" in part.extra and (drift is None or part.extra["drift"]["max_residual"] > drift["max_residual"]):
            drift = dict(part.extra["drift"], t_first=(drift or part.extra["drift"])["t_first"])
        if "_steps" in part.extra:
            st, sy = part.extra["_steps"]
            steps_t.append(st if k == 0 else st[1:])
            steps_y.append(sy if k == 0 else sy[:, 1:])
        if seg_eval is None or seg_eval.size:
            t_part, y_part = part.t, np.vstack([part.q, part.qd])
            if t_eval is None and k > 0:  # the restart state replaces the previous piece's end
                ts[-1], ys[-1] = ts[-1][:-1], ys[-1][:, :-1]
            ts.append(t_part)
            ys.append(y_part)
        if part.status != 0 or "_end" not in part.extra:
            break
        t_end_part, y = part.extra["_end"]
        if k < len(bounds) - 2:
            qn, qdn, rep = system.project(tb, y[:n], y[n:], tol=proj_tol)
            projections.append(float(rep["position_correction"]))
            y = np.concatenate([np.asarray(qn), np.asarray(qdn)])
    t_arr = np.concatenate(ts) if ts else np.zeros(0)
    y_arr = np.concatenate(ys, axis=1) if ys else np.zeros((2 * n, 0))
    extra: Dict[str, Any] = {"steps": steps, "projections": len(projections)}
    if projections:
        extra["max_projection_correction"] = max(projections)
    if drift is not None:
        extra["drift"] = drift
    if steps_t:
        extra["_steps"] = (np.concatenate(steps_t), np.concatenate(steps_y, axis=1))
    return _result(system, t_arr, y_arr, part.method, rtol, atol, nfev=nfev, njev=njev, nlu=nlu, wall=wall,
                   status=part.status, message=part.message, stop=part.stop, t_events=None, y_events=None, sol=None,
                   extra=extra)


def _result(system, t, y, method, rtol, atol, *, nfev, njev, nlu, wall, status, message, stop, t_events, y_events,
            sol, extra) -> SimulationResult:
    res = SimulationResult.from_trajectory(
        system, t, y, method=method, formulation="uk", rtol=rtol, atol=atol, nfev=nfev, njev=njev, nlu=nlu,
        wall_time=wall, status=status, message=message, extra=extra)
    res.stop = stop
    res.sol = sol
    if t_events is not None:
        res.t_events = [np.asarray(te, dtype=float) for te in t_events]
        res.y_events = [np.asarray(ye, dtype=float).reshape(-1, 2 * system.n_coords) for ye in y_events]
    return res


class DenseSolution:
    """The continuous solution of a native run (``res.sol`` with ``dense_output=True``), like
    scipy's ``OdeSolution``: ``sol(t)`` -> (2n,) for a scalar, (2n, k) for k times.

    Each accepted step keeps its method's own interpolant, recorded in Rust during the run and
    evaluated in Rust: DOPRI5 its 4th-order continuous extension (Hairer's CONTD5), RADAU5 the
    step's collocation polynomial (CONTR5), RADAU5M a quintic Hermite polynomial in ``q`` from
    ``q``, ``qd`` and ``qdd`` at the step's ends, GENALPHA a cubic one from ``q`` and ``qd``
    (``qd`` from its derivative).  Outside ``[t_min, t_max]``
    the first or last step's polynomial is extrapolated (as ``OdeSolution`` does).

    Attributes
    ----------
    ts : ndarray, shape (nseg + 1,)
        Step boundaries.
    t_min, t_max : float
    """

    def __init__(self, method: str, meta: np.ndarray, data: np.ndarray, part_len: Sequence[int]):
        self.method = method
        # real numbers only (complex values are not cast to their real parts); the layout is the core's
        self.meta = np.ascontiguousarray(real_array("meta", meta))
        self.data = np.ascontiguousarray(real_array("data", data))
        self.part_len = list(part_len)
        # the core checks the record against the method's layout (a ValueError naming what is
        # inconsistent; NonFiniteError for NaN in it), here once and at every evaluation
        _core.dense_eval(self.method, self.meta, self.data, self.part_len, np.zeros(0))
        self.ts = np.concatenate([self.meta[:1, 0], self.meta[:, 1]]) if len(self.meta) else np.zeros(0)
        self.t_min = float(self.ts[0]) if self.ts.size else float("nan")
        self.t_max = float(self.ts[-1]) if self.ts.size else float("nan")

    def __call__(self, t: ArrayLike) -> np.ndarray:
        tt = np.asarray(t)  # the core converts numbers and refuses the rest (strings, complex, ...)
        if tt.ndim > 1:
            raise InvalidArgumentError("t", f"expected a time or a 1-D array of times, got shape {tt.shape}")
        out = _core.dense_eval(self.method, self.meta, self.data, self.part_len, np.atleast_1d(tt))
        return out[:, 0] if tt.ndim == 0 else out

    def truncated(self, t_stop: float) -> "DenseSolution":
        """The steps up to the one that holds ``t_stop``."""
        k = int(np.searchsorted(self.meta[:, 1], t_stop, side="left")) + 1
        return DenseSolution(self.method, self.meta[:k], self.data[:k], self.part_len)


def _native_events(sol: DenseSolution, events: List[Callable], t0: float, y0: np.ndarray):
    """solve_ivp's event search over the recorded steps of a native run: the sign of each event
    at the step ends, roots by ``handle_events`` on the step's interpolant.  Returns t_events,
    y_events and the terminal time (None if no terminal event)."""
    events, max_events, event_dir = prepare_events(events)
    event_count = np.zeros(len(events))
    t_events: List[List[float]] = [[] for _ in events]
    y_events: List[List[np.ndarray]] = [[] for _ in events]
    g = [ev(t0, y0) for ev in events]
    ends = sol.meta[:, 1]
    y_ends = sol(ends) if ends.size else np.zeros((y0.size, 0))
    for k in range(ends.size):
        t_old, t = float(sol.meta[k, 0]), float(ends[k])
        y = y_ends[:, k]
        g_new = [ev(t, y) for ev in events]
        active = find_active_events(g, g_new, event_dir)
        if active.size > 0:
            event_count[active] += 1
            root_indices, roots, terminate = handle_events(sol, events, active, event_count, max_events, t_old, t)
            for e, te in zip(root_indices, roots):
                t_events[e].append(te)
                y_events[e].append(sol(te))
            if terminate:
                return t_events, y_events, float(roots[-1])
        g = g_new
    return t_events, y_events, None


def _simulate_native(system, method, t0, t_end, y0, rtol, atol, t_eval, options, budget, events, dense, guard,
                     progress=None):
    """Run a native Rust integrator (``System.integrate``: all steps in Rust, GIL released).

    Dense output is recorded in Rust during the run; events are located on it afterwards and a
    terminal event cuts the trajectory there (one-step methods: the states up to the event do
    not depend on what follows, so the cut run equals a run stopped at the event)."""
    kwargs: Dict[str, Any] = {}
    for key in ("first_step", "max_step", "step"):
        if options.get(key) is not None:
            kwargs[key] = positive(key, options[key])
    for key in ("projection_tol", "rho_inf", "newton_local_error"):  # 0 is meaningful (projection off, full dissipation)
        if options.get(key) is not None:
            kwargs[key] = real(key, options[key])
    for key in ("jacobian", "linear_solver"):
        if options.get(key) is not None:
            kwargs[key] = str(options[key])
    atol_arr = np.atleast_1d(np.asarray(atol, dtype=float))
    te = None if t_eval is None else np.ascontiguousarray(t_eval, dtype=float)
    out = system.integrate(float(t0), np.ascontiguousarray(y0, dtype=float), float(t_end), method, float(rtol),
                           atol_arr, te, max_steps=budget.max_steps, max_nfev=budget.max_nfev,
                           max_wall_time=None if budget.deadline is None else max(budget.remaining(), 1e-9),
                           min_step=budget.min_step,
                           dense=bool(dense or events), drift_limit=guard.limit,
                           on_drift="stop" if guard.stop else "warn", progress=progress,
                           progress_steps=NATIVE_PROGRESS_STEPS, progress_interval=NATIVE_PROGRESS_INTERVAL, **kwargs)
    t, y, status, message = np.asarray(out["t"]), np.asarray(out["y"]), int(out["status"]), str(out["message"])
    stop = None
    if out["failure"] is not None:
        f = out["failure"]
        stop, msg = _stop_info(system, f["cause"], f["t"], f["stage"], f["index"], message)
        message = msg if f["cause"] != "solver" else message + f" (the result holds the run up to t = {f['t']:.9g} s)"
        if f["cause"] == "max_wall_time" and out["naccept"] == 0:  # spent before the first step
            stop["stage"] = f"{method}'s setup (before its first step)"
            message += f"; spent before the first step, in {stop['stage']}"
        stop["message"] = message
    sol = None
    if out["dense"] is not None and len(out["dense"]["meta"]):
        d = out["dense"]
        sol = DenseSolution(method, d["meta"], d["data"], d["part_len"])
    t_events = y_events = None
    t_term = None
    if events and sol is not None:
        t_events, y_events, t_term = _native_events(sol, events, t0, y0)
        if t_term is not None:
            keep = t <= t_term
            t, y = t[keep], y[:, keep]
            if t_eval is None and (t.size == 0 or t[-1] < t_term):
                t = np.append(t, t_term)
                y = np.column_stack([y, sol(t_term)])
            sol = sol.truncated(t_term)
            status, message, stop = 1, "A termination event occurred.", None
    elif events:
        t_events, y_events = [[] for _ in events], [[] for _ in events]
    extra = {k: out[k] for k in ("naccept", "nreject", "newton_iterations", "jac_evals")}
    extra["singular"] = [dict(p) for p in out["singular"] if t_term is None or p["t"] <= t_term] if events else \
        [dict(p) for p in out["singular"]]
    if out["drift"] is not None:
        extra["drift"] = dict(out["drift"])
    return _result(system, t, y, method, rtol, atol, nfev=out["nfev"], njev=out["njev"], nlu=out["nlu"],
                   wall=out["wall_time"], status=status, message=message, stop=stop, t_events=t_events,
                   y_events=y_events, sol=sol if dense else None, extra=extra)


def _simulate_reference(system, formulation, t_end, method, rtol, atol, t_eval, q0, qd0, partition, options):
    """Run the NumPy reference (uk-numpy or coordinate partitioning) on the same description."""
    from .. import reference

    fn = reference.simulate_uk_numpy if formulation == "uk-numpy" else reference.simulate_cp
    kwargs: Dict[str, Any] = dict(method=method, rtol=rtol, atol=atol, t_eval=t_eval, q0=q0, qd0=qd0)
    if formulation == "cp" and partition is not None:
        kwargs["partition"] = partition
    kwargs.update(options)
    out = fn(system.description, t_end, **kwargs)
    extra = dict(out.extra, accel_time=out.accel_time, repartitions=out.repartitions)
    return SimulationResult.from_trajectory(
        system, out.t, out.y, method=method if isinstance(method, str) else method.__name__, formulation=formulation,
        rtol=rtol, atol=atol, nfev=out.nfev, njev=out.extra.get("njev", 0), nlu=out.extra.get("nlu", 0),
        wall_time=out.wall_time, status=out.status, message=out.message, extra=extra)


def _resolve_auto(system, formulation, t0, t_end, rtol, q, qd, options, deadline=None):
    """``method="auto"``: the chooser of :mod:`ukflex.choice` for the Rust UK formulation; the
    NumPy references keep scipy's Radau.  Options that only scipy takes (``jac``, ``events``,
    ...) map the choice to its scipy counterpart (RADAU5M -> Radau, DOPRI5 -> DOP853); options
    that only GENALPHA takes (``rho_inf``, ``newton_local_error``) make it GENALPHA."""
    from .choice import choose_method

    if formulation != "uk":
        return "Radau", options, None
    choice = choose_method(system, t0, t_end, rtol, q, qd, deadline=deadline, floor=False)
    scipy_only = sorted(set(options) - set(_NATIVE_OPTIONS))
    if scipy_only:
        choice.method = "Radau" if choice.method == "RADAU5M" else "DOP853"
        choice.options, choice.rtol = {}, None
        choice.reason += f"; scipy {choice.method} because of the scipy option(s) {scipy_only}"
        return choice.method, options, choice
    genalpha_only = sorted(set(options) & {"rho_inf", "newton_local_error"})
    if genalpha_only:
        choice.method, choice.options, choice.rtol = "GENALPHA", {}, None
        choice.reason += f"; GENALPHA because of the option(s) {genalpha_only}"
    elif "step" in options and choice.method == "DOPRI5":
        choice.method, choice.options, choice.rtol = "RADAU5M", {}, None
        choice.reason += "; RADAU5M because of the option step (DOPRI5 has no fixed step), at the user's rtol"
    merged = dict(choice.options)
    merged.update(options)  # the user's own settings win (e.g. step=...)
    return choice.method, merged, choice


def time_acceleration(system: System, t: float, q: Sequence[float], qd: Sequence[float], reps: int = 1000,
                      batches: int = 21) -> float:
    """Seconds per call of the Rust UK acceleration alone at ``(t, q, qd)`` (benchmark helper).

    The minimum over ``batches`` batches of ``reps`` calls, timed inside Rust with the GIL
    released: the core's cost without the Python binding's argument checks and copies (compare
    with timing ``system.qdd(t, q, qd)`` from Python).

    Parameters
    ----------
    system : System
    t : float
    q, qd : array of shape (n,)
    reps, batches : int
        Calls per batch and batches.
    """
    return float(system.time_acceleration(float(t), np.ascontiguousarray(q, dtype=float),
                                                np.ascontiguousarray(qd, dtype=float), int(reps), int(batches)))
