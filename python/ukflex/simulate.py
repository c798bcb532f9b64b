"""Time integration with ``scipy.integrate.solve_ivp``."""

from __future__ import annotations

import inspect
import math
import time
from typing import Any, Callable, Dict, Optional, Sequence, Union

import numpy as np
from scipy.integrate import OdeSolver, solve_ivp

from .errors import NonFiniteError
from .results import SimulationResult
from .scene import Scene
from .system import System

__all__ = ["simulate", "METHODS", "NATIVE_METHODS", "FORMULATIONS", "as_system", "time_acceleration"]

METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
#: Integrators that run entirely in Rust with the GIL released (``System.integrate``):
#: Dormand-Prince 5(4) with dense output, and Radau IIA order 5 with the Rust Jacobian.
NATIVE_METHODS = ("DOPRI5", "RADAU5", "GENALPHA")
_NATIVE_OPTIONS = ("first_step", "max_step", "max_steps", "projection_tol", "rho_inf", "step", "jacobian")
FORMULATIONS = ("uk", "uk-numpy", "cp")


def as_system(scene_or_system: Union[Scene, System, Dict[str, Any]], **build_options: Any) -> System:
    """Return a :class:`System` for a scene, a description dict or an existing system."""
    if isinstance(scene_or_system, System):
        if build_options:
            raise TypeError("build options cannot be applied to an already built System")
        return scene_or_system
    if isinstance(scene_or_system, (Scene, dict)):
        return System(scene_or_system, **build_options)
    raise TypeError(f"expected a Scene, a description dict or a System, got {type(scene_or_system).__name__}")


def _finite_array(name: str, value: Any, shape: Optional[tuple] = None) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if shape is not None and arr.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {arr.shape}")
    bad = np.flatnonzero(~np.isfinite(arr.ravel()))
    if bad.size:
        raise NonFiniteError(f"{name}: contains NaN or infinity at index {int(bad[0])}")
    return arr


def _positive_scalar(name: str, value: Any) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(x) or x <= 0.0:
        raise ValueError(f"{name} must be positive and finite, got {value!r}")
    return x


def simulate(
    scene_or_system: Union[Scene, System, Dict[str, Any]],
    t_end: float,
    method: Union[str, type] = "auto",
    rtol: float = 1e-6,
    atol: Union[None, float, Sequence[float]] = None,
    t_eval: Optional[Sequence[float]] = None,
    formulation: str = "uk",
    *,
    q0: Optional[Sequence[float]] = None,
    qd0: Optional[Sequence[float]] = None,
    partition: Any = None,
    progress: Optional[Callable[[float], None]] = None,
    **options: Any,
) -> SimulationResult:
    """Integrate the equations of motion from the system's consistent initial state to ``t_end``.

    Parameters
    ----------
    scene_or_system : Scene, dict or System
        What to simulate; scenes and dicts are built with default options.
    t_end : float
        End time [s], ``> t0`` (the system's initial time, normally 0).
    method : str or scipy OdeSolver subclass
        ``"auto"`` (default): chosen from the constrained system's natural frequencies
        (:mod:`ukflex.choice`, docs/integrators.md): native ``"GENALPHA"`` with a fixed step
        that resolves the lowest elastic mode when the fastest modes are far beyond it (stiff
        flexible scenes), native ``"DOPRI5"`` otherwise; the choice and its reason are in
        ``res.method`` and ``res.extra["auto"]``.  Or any ``solve_ivp`` method: ``"Radau"``,
        ``"BDF"``, ``"LSODA"``, ``"RK45"``, ``"RK23"``, ``"DOP853"``; or a native Rust integrator
        (all steps in Rust, GIL released, same result object): ``"DOPRI5"`` (Dormand-Prince 5(4),
        dense output), ``"RADAU5"`` (Radau IIA order 5, Rust Jacobian) or ``"GENALPHA"``
        (generalized-alpha for stiff flexible systems: numerical dissipation ``rho_inf``
        (default 0.9), a structured Newton matrix, fixed ``step`` or error-controlled steps,
        projection onto the constraints by default). Native methods take the options
        ``first_step``, ``max_step``, ``max_steps`` and ``projection_tol`` (project onto the
        constraints after every accepted step whose residuals exceed it; 0: off), GENALPHA also
        ``rho_inf`` and ``step``; see docs/integrators.md.
    rtol : float
        Relative tolerance (the paper used ``RelTol = 1e-6`` with ode15s).
    atol : float or array of shape (2n,), optional
        Absolute tolerance; default ``1e-3 * rtol``.
    t_eval : array of shape (nt,), optional
        Output times in ``[t0, t_end]``; default: the integrator's own steps.
    formulation : {"uk", "uk-numpy", "cp"}
        ``"uk"``: Udwadia-Kalaba accelerations from the Rust core.  ``"uk-numpy"`` and ``"cp"``
        (coordinate partitioning) come from the NumPy reference :mod:`ukflex.reference`.
    q0, qd0 : array of shape (n,), optional
        Override the system's corrected initial state (not corrected again).
    partition : optional
        Passed to the ``"cp"`` reference integrator.
    progress : callable, optional
        ``progress(t)`` is called at the start and after every accepted step of a scipy
        integrator (formulations ``"uk"`` and ``"uk-numpy"``; the ``"cp"`` reference integrator
        takes no step hook, so there it is called only at the end).  Keep it cheap (throttle
        output yourself); used by the CLI's progress display.
    **options
        Further ``solve_ivp`` options (``max_step``, ``first_step``, ``jac``, ...).  For
        ``"Radau"`` and ``"BDF"`` the default ``jac`` is the core's finite-difference Jacobian
        ``System.jac``; pass ``jac=None`` for scipy's own ``num_jac``, which overflows on the
        exactly-zero columns of these systems.
        ``nfev`` counts only the integrator's ``rhs`` calls, not those inside Jacobians.

    Returns
    -------
    SimulationResult
        Histories ``t`` (nt,), ``q`` and ``qd`` (n, nt) (``y`` (2n, nt), as ``solve_ivp``), residual norms (nt,) and
        integrator statistics.

    Raises
    ------
    ValueError
        Bad ``t_end``, tolerances, ``t_eval``, unknown method or formulation, wrong shapes.
    NonFiniteError
        NaN or infinity in an input array.
    """
    if formulation not in FORMULATIONS:
        raise ValueError(f"unknown formulation {formulation!r}; expected one of {FORMULATIONS}")
    if isinstance(method, str):
        if method != "auto" and method not in METHODS and method not in NATIVE_METHODS:
            raise ValueError(
                f"unknown method {method!r}; expected one of {METHODS}, a native method {NATIVE_METHODS} "
                "or an OdeSolver subclass"
            )
        if method in NATIVE_METHODS and formulation != "uk":
            raise ValueError(f"native method {method!r} integrates the Rust UK formulation only, not {formulation!r}")
    elif not (inspect.isclass(method) and issubclass(method, OdeSolver)):
        raise ValueError(f"method must be one of {METHODS} or an OdeSolver subclass, got {method!r}")
    system = as_system(scene_or_system)
    n = system.n_coords
    t0 = system.t0
    try:
        t_end_f = float(t_end)
    except (TypeError, ValueError):
        raise TypeError(f"t_end must be a number, got {t_end!r}") from None
    if not math.isfinite(t_end_f) or t_end_f <= t0:
        raise ValueError(f"t_end must be finite and greater than t0 = {t0}, got {t_end!r}")
    rtol = _positive_scalar("rtol", rtol)
    if atol is None:
        atol_v: Any = 1e-3 * rtol
    elif np.ndim(atol) == 0:
        atol_v = _positive_scalar("atol", atol)
    else:
        atol_v = _finite_array("atol", atol, (2 * n,))
        if np.any(atol_v <= 0):
            raise ValueError("atol entries must be positive")
    if t_eval is not None:
        t_eval = _finite_array("t_eval", t_eval)
        if t_eval.ndim != 1 or t_eval.size == 0:
            raise ValueError(f"t_eval must be a non-empty 1-D array, got shape {t_eval.shape}")
        if np.any(np.diff(t_eval) <= 0):
            raise ValueError("t_eval must be strictly increasing")
        if t_eval[0] < t0 or t_eval[-1] > t_end_f:
            raise ValueError(f"t_eval must lie within [t0, t_end] = [{t0}, {t_end_f}]")
    q_init = system.q0 if q0 is None else _finite_array("q0", q0, (n,))
    qd_init = system.qd0 if qd0 is None else _finite_array("qd0", qd0, (n,))
    if method == "auto":
        start = time.perf_counter()
        method, options, choice = _resolve_auto(system, formulation, t0, t_end_f, rtol, q_init, qd_init, options)
        choice_time = time.perf_counter() - start
        run_rtol = choice.rtol if choice is not None and choice.rtol is not None else rtol
        res = simulate(system, t_end_f, method, run_rtol, atol, t_eval, formulation, q0=q0, qd0=qd0,
                       partition=partition, progress=progress, **options)
        if choice is not None:
            res.extra["auto"] = dict(choice.as_dict(), time=choice_time)
        return res
    if isinstance(method, str) and method in NATIVE_METHODS:
        res = _simulate_native(system, method, t0, t_end_f, np.concatenate([q_init, qd_init]), rtol, atol_v, t_eval,
                               options)
        if progress is not None and res.t.size:
            progress(float(res.t[-1]))
        return res
    if progress is not None and formulation != "cp":
        options = _with_progress_event(options, progress)

    if formulation != "uk":
        res = _simulate_reference(
            system, formulation, t_end_f, method, rtol, atol_v, t_eval, q_init, qd_init, partition, options
        )
        if progress is not None and formulation == "cp" and res.t.size:
            progress(float(res.t[-1]))
        return res

    y0 = np.concatenate([q_init, qd_init])
    if method in ("Radau", "BDF") and "jac" not in options:
        options["jac"] = system.jac  # Rust finite differences, GIL released
    start = time.perf_counter()
    sol = solve_ivp(system.rhs, (t0, t_end_f), y0, method=method, t_eval=t_eval, rtol=rtol, atol=atol_v, **options)
    wall = time.perf_counter() - start
    return SimulationResult.from_trajectory(
        system, sol.t, sol.y, method=method if isinstance(method, str) else method.__name__, formulation="uk",
        rtol=rtol, atol=atol_v, nfev=sol.nfev, njev=sol.njev, nlu=sol.nlu, wall_time=wall, status=sol.status,
        message=sol.message)


def _resolve_auto(system, formulation, t0, t_end, rtol, q, qd, options):
    """``method="auto"``: the chooser of :mod:`ukflex.choice` for the Rust UK formulation; the
    NumPy references keep scipy's Radau.  Options that only scipy takes (``jac``, ``events``,
    ...) map the choice to its scipy counterpart (GENALPHA -> Radau, DOPRI5 -> DOP853)."""
    from .choice import choose_method

    if formulation != "uk":
        return "Radau", options, None
    choice = choose_method(system, t0, t_end, rtol, q, qd)
    scipy_only = sorted(set(options) - set(_NATIVE_OPTIONS))
    if scipy_only:
        choice.method = "Radau" if choice.method == "GENALPHA" else "DOP853"
        choice.options, choice.rtol = {}, None
        choice.reason += f"; scipy {choice.method} because of the scipy option(s) {scipy_only}"
        return choice.method, options, choice
    genalpha_only = sorted(set(options) & {"step", "rho_inf"})
    if genalpha_only and choice.method != "GENALPHA":
        choice.method, choice.options, choice.rtol = "GENALPHA", {}, None
        choice.reason += f"; GENALPHA because of the option(s) {genalpha_only}"
    merged = dict(choice.options)
    merged.update(options)  # the user's own settings win (e.g. step=...)
    return choice.method, merged, choice


def _with_progress_event(options: Dict[str, Any], progress: Callable[[float], None]) -> Dict[str, Any]:
    """Add a never-triggering, non-terminal solve_ivp event that reports the step end time."""

    def _progress_event(t: float, y: np.ndarray) -> float:
        progress(float(t))
        return 1.0  # constant sign: solve_ivp never searches for a root

    user = options.get("events")
    events = [] if user is None else (list(user) if isinstance(user, (list, tuple)) else [user])
    return dict(options, events=events + [_progress_event])


def _simulate_native(system, method, t0, t_end, y0, rtol, atol, t_eval, options) -> SimulationResult:
    """Run a native Rust integrator (``System.integrate``: all steps in Rust, GIL released)."""
    unknown = sorted(set(options) - set(_NATIVE_OPTIONS))
    if unknown:
        raise TypeError(f"native method {method!r} does not take option(s) {unknown}; it accepts {_NATIVE_OPTIONS}")
    kwargs: Dict[str, Any] = {}
    for key in ("first_step", "max_step", "step"):
        if options.get(key) is not None:
            kwargs[key] = _positive_scalar(key, options[key])
    for key in ("projection_tol", "rho_inf"):  # 0 is meaningful (projection off, full dissipation)
        if options.get(key) is not None:
            kwargs[key] = float(options[key])
    if options.get("max_steps") is not None:
        kwargs["max_steps"] = int(options["max_steps"])
    if options.get("jacobian") is not None:
        kwargs["jacobian"] = str(options["jacobian"])
    atol_arr = np.atleast_1d(np.asarray(atol, dtype=float))
    te = None if t_eval is None else np.ascontiguousarray(t_eval, dtype=float)
    out = system.integrate(float(t0), np.ascontiguousarray(y0, dtype=float), float(t_end), method, float(rtol),
                           atol_arr, te, **kwargs)
    return SimulationResult.from_trajectory(
        system, out["t"], out["y"], method=method, formulation="uk", rtol=rtol, atol=atol, nfev=out["nfev"],
        njev=out["njev"], nlu=out["nlu"], wall_time=out["wall_time"], status=out["status"], message=out["message"],
        extra={k: out[k] for k in ("naccept", "nreject", "newton_iterations", "jac_evals")})


def _simulate_reference(system, formulation, t_end, method, rtol, atol, t_eval, q0, qd0, partition, options):
    """Run the NumPy reference (uk-numpy or coordinate partitioning) on the same description."""
    from . import reference

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
