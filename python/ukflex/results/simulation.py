"""Simulation results: time histories, residuals, solver statistics and post-processing helpers."""

from __future__ import annotations

import csv
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
from numpy.typing import ArrayLike

from ..errors import UnknownNameError

__all__ = ["SimulationResult"]

#: The residual histories of a result (``SimulationResult.residuals``).
RESIDUAL_KINDS = ("position", "velocity", "acceleration")


@dataclass
class SimulationResult:
    """Outcome of :func:`ukflex.simulate`.

    Attributes
    ----------
    t : ndarray, shape (nt,)
        Output times [s].
    q, qd : ndarray, shape (n, nt)
        Generalized coordinates and velocities at the output times, time along the last axis
        (``q[:, k]`` is the state at ``t[k]``); ``y`` stacks them as ``solve_ivp`` does,
        shape (2n, nt).  Per coordinate: :meth:`coordinate`, :meth:`velocity` (1-D over time).
    residuals : mapping of str -> ndarray, shape (nt,)
        Euclidean norms of the constraint residuals at each output time: ``"position"``
        (``Phi``), ``"velocity"`` (``A qd + Phi_t``), ``"acceleration"`` (``A qdd - b``).
        Evaluated on first access (one UK solve per output: on a 1001-output run of the paper
        scene about as long as the integration itself); the run's own drift check is made in
        the integrator at every accepted step.
    nfev, njev, nlu : int
        Right-hand-side evaluations, Jacobian evaluations and LU decompositions of the integrator.
    wall_time : float
        Wall-clock time of the integration [s] (residual evaluation excluded).
    status : int
        ``solve_ivp`` status (0: reached ``t_end``, -1: the run stopped early (failure, budget,
        non-finite state; see ``stop``), 1: a terminal event).
    message : str
        Integrator message.
    system : ukflex.System
        The system that was simulated (its description, names and per-step methods).
    method, formulation : str
        Integrator and formulation used.
    rtol, atol : float
        Tolerances used.
    t_events, y_events : list of ndarray or None
        With ``events``: per event, the times (k,) and states (k, 2n) of its roots, as
        ``solve_ivp`` returns them.
    sol : callable or None
        With ``dense_output=True``: ``sol(t)`` -> (2n,) or (2n, k) (scipy's ``OdeSolution`` or
        :class:`ukflex.run.simulate.DenseSolution`).
    stop : dict or None
        Why a run ended early (``status == -1``): ``cause`` (``"max_steps"``, ``"max_nfev"``,
        ``"max_wall_time"``, ``"min_step"``, ``"non_finite"``, ``"solver"``), ``t`` (the last
        accepted time, where the kept trajectory ends), for ``non_finite`` the ``coordinate``
        and ``stage`` (``"q"``, ``"qd"`` or ``"qdd"``), and the ``message``.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    residuals: Dict[str, np.ndarray]
    nfev: int
    njev: int
    nlu: int
    wall_time: float
    status: int
    message: str
    system: Any = None
    method: str = ""
    formulation: str = "uk"
    rtol: float = float("nan")
    atol: Any = float("nan")
    extra: Dict[str, Any] = field(default_factory=dict)
    t_events: Optional[List[np.ndarray]] = None
    y_events: Optional[List[np.ndarray]] = None
    sol: Optional[Callable[..., np.ndarray]] = None
    stop: Optional[Dict[str, Any]] = None

    @classmethod
    def from_trajectory(
        cls,
        system: Any,
        t: ArrayLike,
        y: ArrayLike,
        *,
        method: str = "",
        formulation: str = "uk",
        rtol: float = float("nan"),
        atol: Any = float("nan"),
        nfev: int = 0,
        njev: int = 0,
        nlu: int = 0,
        wall_time: float = float("nan"),
        status: int = 0,
        message: str = "",
        extra: Optional[Dict[str, Any]] = None,
    ) -> "SimulationResult":
        """A result from states computed elsewhere (a native run, a custom integration loop).

        The residual histories are evaluated here with the system's compiled ``residuals``.

        Parameters
        ----------
        system : ukflex.System
            The system the states belong to.
        t : array of shape (nt,)
            Output times [s].
        y : array of shape (2n, nt)
            States ``[q; qd]`` column by column, as ``solve_ivp`` and ``System.integrate``
            return them.
        method, formulation, rtol, atol, nfev, njev, nlu, wall_time, status, message, extra
            Stored as given (see the class attributes).

        Raises
        ------
        ValueError
            ``t`` or ``y`` has the wrong shape.

        Examples
        --------
        >>> out = system.integrate(system.t0, system.y0, 0.1, "DOPRI5")      # doctest: +SKIP
        >>> res = SimulationResult.from_trajectory(system, out["t"], out["y"], method="DOPRI5",  # doctest: +SKIP
        ...                                        nfev=out["nfev"], status=out["status"])
        """
        n = system.n_coords
        tv = np.asarray(t, dtype=float)
        yv = np.asarray(y, dtype=float)
        if tv.ndim != 1 or yv.shape != (2 * n, tv.size):
            raise ValueError(f"from_trajectory: expected t of shape (nt,) and y of shape (2n, nt) = "
                             f"({2 * n}, {tv.size}), got {tv.shape} and {yv.shape}")
        q = np.ascontiguousarray(yv[:n])
        qd = np.ascontiguousarray(yv[n:])
        return cls(t=tv, q=q, qd=qd, residuals=_LazyResiduals(system, tv, q, qd), nfev=int(nfev), njev=int(njev),
                   nlu=int(nlu), wall_time=float(wall_time), status=int(status), message=str(message), system=system,
                   method=method, formulation=formulation, rtol=rtol, atol=atol, extra=dict(extra or {}))

    @property
    def success(self) -> bool:
        """True if the integrator reached the end time or stopped at a terminal event (status >= 0)."""
        return self.status >= 0

    @property
    def y(self) -> np.ndarray:
        """``[q; qd]`` stacked, shape (2n, nt), exactly as ``solve_ivp``'s ``sol.y``."""
        return np.vstack([self.q, self.qd])

    def __repr__(self) -> str:
        t_end = self.t[-1] if self.t.size else float("nan")
        return (
            f"SimulationResult(formulation={self.formulation!r}, method={self.method!r}, nt={self.t.size}, "
            f"t_end={t_end:g}, status={self.status}, nfev={self.nfev}, wall_time={self.wall_time:.3g}s)"
        )

    @property
    def sensors(self):
        """Reactions, energies, work, beam internal forces (:class:`ukflex.results.sensors.Sensors`;
        a spatial run's: :class:`ukflex.results.spatial.SpatialSensors`)."""
        from .spatial import sensors_of

        return self.__dict__.setdefault("_sensors", sensors_of(self))

    # ------------------------------------------------------------------------------ access
    def coordinate(self, name: str) -> np.ndarray:
        """History of coordinate ``name`` (e.g. ``"crank.theta"``), shape (nt,)."""
        return self.q[self.system.coordinate_index(name)]

    def velocity(self, name: str) -> np.ndarray:
        """History of the rate of coordinate ``name``, shape (nt,)."""
        return self.qd[self.system.coordinate_index(name)]

    def _beam_point(self, body: str, xi: float) -> np.ndarray:
        """The core's ``beam_point`` over the run: rows x, y, u, v, psi, shape (5, nt)."""
        return np.asarray(self.system.beam_point(body, float(xi), self.q)).reshape(5, -1)

    def beam_displacement(self, body: str, xi: float) -> Tuple[np.ndarray, np.ndarray]:
        """Displacement of the axis point of beam ``body`` at ``x = xi * length``, in the beam frame.

        The beam frame is an FFRF beam's floating frame (``u_f = S(x) q_f``; for the
        pinned-pinned frame the chord of the two ends) and an ANCF beam's chord frame (origin at
        the ``xi = 0`` end, X axis towards the ``xi = 1`` end), so that the two formulations
        compare one to one.

        Returns
        -------
        u, v : ndarray, shape (nt,)
            Axial and transverse displacement [m] from the undeformed ``(xi * length, 0)``.  The
            paper's Fig. 4 plots ``v(xi = 0.5) / length``.
        """
        p = self._beam_point(body, xi)
        return p[2], p[3]

    def beam_rotation(self, body: str, xi: float) -> np.ndarray:
        """Cross-section rotation ``psi`` of beam ``body`` at ``xi`` relative to its beam frame
        (FFRF: the elastic rotation; ANCF: the tangent's angle to the chord), shape (nt,)."""
        return self._beam_point(body, xi)[4]

    def beam_position(self, body: str, xi: float) -> Tuple[np.ndarray, np.ndarray]:
        """World position ``(x, y)`` of the (deformed) axis point of beam ``body`` at ``xi``, each (nt,)."""
        p = self._beam_point(body, xi)
        return p[0], p[1]

    def energy(self) -> np.ndarray:
        """Total mechanical energy ``T + V`` at each output time, shape (nt,)."""
        s = self.system
        return np.array([s.kinetic_energy(q, qd) + s.potential_energy(q) for q, qd in zip(self.q.T, self.qd.T)])

    def multipliers(self) -> np.ndarray:
        """Lagrange multipliers (``M qdd + A^T lam = Q``) at each output time, shape (m, nt)."""
        s = self.system
        lam = [s.multipliers(t, q, qd) for t, q, qd in zip(self.t, self.q.T, self.qd.T)]
        return np.array(lam).reshape(self.t.size, -1).T

    def qdd(self) -> np.ndarray:
        """Accelerations at each output time, shape (n, nt)."""
        s = self.system
        acc = [s.qdd(t, q, qd) for t, q, qd in zip(self.t, self.q.T, self.qd.T)]
        return np.array(acc).reshape(self.t.size, -1).T

    def max_residual(self, kind: str = "position") -> float:
        """Largest residual norm of ``kind`` (``"position"``, ``"velocity"`` or
        ``"acceleration"``) over the run."""
        if kind not in RESIDUAL_KINDS:
            raise UnknownNameError.of("residual kind", kind, RESIDUAL_KINDS)
        r = self.residuals[kind]
        return float(np.max(r)) if r.size else 0.0

    # ------------------------------------------------------------------------------ output
    def _column(self, name: str) -> np.ndarray:
        if name == "t":
            return self.t
        if name.startswith("d:"):
            return self.velocity(name[2:])
        if name.startswith("residual."):
            return self.residuals[name.split(".", 1)[1]]
        return self.coordinate(name)

    def to_csv(self, path: str, columns: Optional[Sequence[str]] = None) -> None:
        """Write a CSV file with a header row.

        Parameters
        ----------
        path : str
            Output file.
        columns : sequence of str, optional
            Column names: ``"t"``, coordinate names (``"crank.theta"``), ``"d:<coordinate>"`` for
            rates, ``"residual.position"`` etc.  Default: ``t``, every coordinate, every rate.
        """
        if columns is None:
            names = self.system.coordinate_names
            columns = ["t"] + list(names) + ["d:" + n for n in names]
        data = np.column_stack([self._column(c) for c in columns])
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(columns)
            for row in data:
                w.writerow([repr(float(x)) for x in row])

    def save_npz(self, path: str) -> None:
        """Save ``t, q, qd`` (``q``, ``qd`` of shape (n, nt)), the residual histories, statistics and names to ``path`` (NumPy .npz)."""
        np.savez(
            path,
            t=self.t,
            q=self.q,
            qd=self.qd,
            residual_position=self.residuals["position"],
            residual_velocity=self.residuals["velocity"],
            residual_acceleration=self.residuals["acceleration"],
            nfev=self.nfev,
            njev=self.njev,
            nlu=self.nlu,
            wall_time=self.wall_time,
            status=self.status,
            coordinate_names=np.array(self.system.coordinate_names),
            method=self.method,
            formulation=self.formulation,
        )


class _LazyResiduals(Mapping):
    """``SimulationResult.residuals``: the three residual histories, evaluated together on the
    first access (``_residual_norms``) and kept."""

    def __init__(self, system: Any, t: np.ndarray, q: np.ndarray, qd: np.ndarray):
        self._args: Optional[Tuple[Any, ...]] = (system, t, q, qd)
        self._values: Optional[Dict[str, np.ndarray]] = None

    def _get(self) -> Dict[str, np.ndarray]:
        if self._values is None:
            assert self._args is not None
            self._values = _residual_norms(*self._args)
            self._args = None
        return self._values

    def __getitem__(self, key: str) -> np.ndarray:
        if key not in RESIDUAL_KINDS:
            raise UnknownNameError.of("residual kind", key, RESIDUAL_KINDS)
        return self._get()[key]

    def __iter__(self):
        return iter(RESIDUAL_KINDS)

    def __len__(self) -> int:
        return 3

    def __repr__(self) -> str:
        return repr(self._get())

    def __reduce__(self):  # pickles its values (evaluated now)
        return (_residuals_of, (self._get(),))


def _residuals_of(values: Dict[str, np.ndarray]) -> "_LazyResiduals":
    """A :class:`_LazyResiduals` holding ``values`` (unpickling)."""
    r = _LazyResiduals.__new__(_LazyResiduals)
    r._args, r._values = None, {k: np.asarray(values[k]) for k in RESIDUAL_KINDS}
    return r


def _residual_norms(system: Any, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> Dict[str, np.ndarray]:
    """Euclidean norms of the position, velocity and acceleration residuals, each shape (nt,)."""
    out = {k: np.zeros(t.size) for k in RESIDUAL_KINDS}
    if system.n_constraints == 0:
        return out
    core = getattr(system, "core", None)
    if core is not None and hasattr(core, "residual_norms") and t.size:
        norms = core.residual_norms(t, np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(qd, dtype=float))
        return {k: np.asarray(norms[i]) for i, k in enumerate(RESIDUAL_KINDS)}
    for i in range(t.size):
        for key, r in zip(RESIDUAL_KINDS, system.residuals(t[i], q[:, i], qd[:, i])):
            out[key][i] = np.linalg.norm(r)
    return out
