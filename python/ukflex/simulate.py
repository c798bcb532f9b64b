"""Time integration with ``scipy.integrate.solve_ivp``."""

from __future__ import annotations

import inspect
import math
import time
from types import SimpleNamespace
from typing import Any, Callable, Dict, Optional, Sequence, Union

import numpy as np
from scipy.integrate import OdeSolver, solve_ivp

from .errors import NonFiniteError
from .results import SimulationResult
from .scene import Scene
from .system import System

__all__ = ["simulate", "METHODS", "NATIVE_METHODS", "FORMULATIONS", "as_system", "fd_jacobian"]

METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
#: Integrators that run entirely in Rust with the GIL released (``System.core.integrate``):
#: Dormand-Prince 5(4) with dense output, and Radau IIA order 5 with the Rust Jacobian.
NATIVE_METHODS = ("DOPRI5", "RADAU5")
_NATIVE_OPTIONS = ("first_step", "max_step", "max_steps", "projection_tol")
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


def fd_jacobian(system: System, floor: float = 1e-3):
    """Forward-difference Jacobian of ``system.rhs`` for the implicit integrators.

    ``d[qd, qdd]/d[q, qd] = [[0, I], [dqdd/dq, dqdd/dqd]]``: only the lower blocks are
    differenced (``2 n`` calls of the compiled ``qdd``), with steps
    ``sqrt(eps) * max(|y_j|, floor)``.  Unlike scipy's adaptive ``num_jac`` it never grows the
    step for a column that is exactly zero (e.g. the rhs does not depend on a pinned body's
    absolute position), which overflows in scipy's BDF.

    Returns
    -------
    callable
        ``jac(t, y) -> ndarray (2n, 2n)``.
    """
    n = system.n_coords
    qdd = system.qdd
    sq = math.sqrt(np.finfo(float).eps)
    eye = np.eye(n)

    def jac(t: float, y: np.ndarray) -> np.ndarray:
        q, qd = y[:n], y[n:]
        f0 = qdd(t, q, qd)
        J = np.zeros((2 * n, 2 * n))
        J[:n, n:] = eye
        h = sq * np.maximum(np.abs(y), floor)
        for j in range(n):
            qj = q.copy()
            qj[j] += h[j]
            J[n:, j] = (qdd(t, qj, qd) - f0) / (qj[j] - q[j])
        for j in range(n):
            vj = qd.copy()
            vj[j] += h[n + j]
            J[n:, n + j] = (qdd(t, q, vj) - f0) / (vj[j] - qd[j])
        return J

    return jac


def _residual_history(system: System, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> Dict[str, np.ndarray]:
    nt = t.size
    out = {k: np.zeros(nt) for k in ("position", "velocity", "acceleration")}
    if system.n_constraints == 0:
        return out
    res = system.residuals
    for i in range(nt):
        rp, rv, ra = res(t[i], q[i], qd[i])
        out["position"][i] = np.linalg.norm(rp)
        out["velocity"][i] = np.linalg.norm(rv)
        out["acceleration"][i] = np.linalg.norm(ra)
    return out


def simulate(
    scene_or_system: Union[Scene, System, Dict[str, Any]],
    t_end: float,
    method: Union[str, type] = "Radau",
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
        Any ``solve_ivp`` method: ``"Radau"`` (default, implicit, for the stiff elastic modes),
        ``"BDF"``, ``"LSODA"``, ``"RK45"``, ``"RK23"``, ``"DOP853"``; or a native Rust integrator
        (all steps in Rust, GIL released, same result object): ``"DOPRI5"`` (Dormand-Prince 5(4),
        dense output) or ``"RADAU5"`` (Radau IIA order 5, Rust Jacobian). Native methods take the
        options ``first_step``, ``max_step``, ``max_steps`` and ``projection_tol`` (project onto
        the constraints after every accepted step); see docs/performance.md.
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
        ``System.core.jac`` (or :func:`fd_jacobian` if the core lacks it); pass ``jac=None`` for
        scipy's own ``num_jac``, which overflows on the exactly-zero columns of these systems.
        ``nfev`` counts only the integrator's ``rhs`` calls, not those inside Jacobians.

    Returns
    -------
    SimulationResult
        Histories ``t`` (nt,), ``q`` and ``qd`` (nt, n), constraint-residual norms (nt,) and
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
        if method not in METHODS and method not in NATIVE_METHODS:
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
        core_jac = getattr(system.core, "jac", None)  # Rust finite differences, GIL released
        options["jac"] = core_jac if core_jac is not None else fd_jacobian(system)
    start = time.perf_counter()
    sol = solve_ivp(system.rhs, (t0, t_end_f), y0, method=method, t_eval=t_eval, rtol=rtol, atol=atol_v, **options)
    wall = time.perf_counter() - start
    return _make_result(system, sol.t, sol.y, sol, wall, method, "uk", rtol, atol_v)


def _with_progress_event(options: Dict[str, Any], progress: Callable[[float], None]) -> Dict[str, Any]:
    """Add a never-triggering, non-terminal solve_ivp event that reports the step end time."""

    def _progress_event(t: float, y: np.ndarray) -> float:
        progress(float(t))
        return 1.0  # constant sign: solve_ivp never searches for a root

    user = options.get("events")
    events = [] if user is None else (list(user) if isinstance(user, (list, tuple)) else [user])
    return dict(options, events=events + [_progress_event])


def _simulate_native(system, method, t0, t_end, y0, rtol, atol, t_eval, options) -> SimulationResult:
    """Run a native Rust integrator (``System.core.integrate``: all steps in Rust, GIL released)."""
    unknown = sorted(set(options) - set(_NATIVE_OPTIONS))
    if unknown:
        raise TypeError(f"native method {method!r} does not take option(s) {unknown}; it accepts {_NATIVE_OPTIONS}")
    kwargs: Dict[str, Any] = {}
    for key in ("first_step", "max_step", "projection_tol"):
        if options.get(key) is not None:
            kwargs[key] = _positive_scalar(key, options[key])
    if options.get("max_steps") is not None:
        kwargs["max_steps"] = int(options["max_steps"])
    atol_arr = np.atleast_1d(np.asarray(atol, dtype=float))
    te = None if t_eval is None else np.ascontiguousarray(t_eval, dtype=float)
    out = system.core.integrate(float(t0), np.ascontiguousarray(y0, dtype=float), float(t_end), method, float(rtol),
                                atol_arr, te, **kwargs)
    info = SimpleNamespace(nfev=out["nfev"], njev=out["njev"], nlu=out["nlu"], status=out["status"],
                           message=out["message"])
    extra = {k: out[k] for k in ("naccept", "nreject", "jac_evals")}
    return _make_result(system, out["t"], out["y"], info, out["wall_time"], method, "uk", rtol, atol, extra=extra)


def _make_result(system, t, y, sol, wall, method, formulation, rtol, atol, extra=None) -> SimulationResult:
    n = system.n_coords
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    q = np.ascontiguousarray(y[:n].T)
    qd = np.ascontiguousarray(y[n : 2 * n].T)
    return SimulationResult(
        t=t,
        q=q,
        qd=qd,
        residuals=_residual_history(system, t, q, qd),
        nfev=int(getattr(sol, "nfev", 0)),
        njev=int(getattr(sol, "njev", (extra or {}).get("njev", 0))),
        nlu=int(getattr(sol, "nlu", (extra or {}).get("nlu", 0))),
        wall_time=float(wall),
        status=int(getattr(sol, "status", 0)),
        message=str(getattr(sol, "message", "")),
        system=system,
        method=method if isinstance(method, str) else method.__name__,
        formulation=formulation,
        rtol=rtol,
        atol=atol,
        extra=extra or {},
    )


def _simulate_reference(system, formulation, t_end, method, rtol, atol, t_eval, q0, qd0, partition, options):
    """Run the NumPy reference (uk-numpy or coordinate partitioning) on the same description."""
    try:
        from . import reference  # noqa: F401
        fn = getattr(reference, "simulate_uk_numpy" if formulation == "uk-numpy" else "simulate_cp")
    except (ImportError, AttributeError) as exc:
        name = "simulate_uk_numpy" if formulation == "uk-numpy" else "simulate_cp"
        raise NotImplementedError(
            f"formulation {formulation!r} needs ukflex.reference.{name}, which is not available yet ({exc})"
        ) from exc
    kwargs: Dict[str, Any] = dict(method=method, rtol=rtol, atol=atol, t_eval=t_eval, q0=q0, qd0=qd0)
    if formulation == "cp" and partition is not None:
        kwargs["partition"] = partition
    kwargs.update(options)
    start = time.perf_counter()
    out = fn(system.description, t_end, **kwargs)
    wall = time.perf_counter() - start
    if isinstance(out, SimulationResult):
        if out.system is None:
            out.system = system
        return out
    t = getattr(out, "t", None)
    y = getattr(out, "y", None)
    if t is None or y is None:
        raise TypeError(f"ukflex.reference returned {type(out).__name__}, expected an object with t and y")
    extra = dict(getattr(out, "extra", None) or {})
    for key in ("accel_time", "repartitions"):
        if hasattr(out, key):
            extra[key] = getattr(out, key)
    return _make_result(system, t, y, out, getattr(out, "wall_time", wall), method, formulation, rtol, atol, extra)
