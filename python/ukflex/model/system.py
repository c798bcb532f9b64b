"""The compiled system: a thin Python class around the Rust ``ukflex._core.System``.

:class:`System` keeps the scene description, the corrected consistent initial state ``q0``,
``qd0`` and the report of that correction, and exposes the core's per-step methods (``rhs``,
``qdd``, ``M``, ``Q``, ``phi``, ``A``, ...) as the bound methods of the compiled object: calling
``system.rhs(t, y)`` goes straight into Rust with no Python layer in between.
"""

from __future__ import annotations

import json
import reprlib
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from ..arguments import real
from .description import normalize
from ..errors import (InconsistentInitialStateError, InitialCorrectionWarning, InvalidArgumentError, InvalidSceneError, NonFiniteError,
                     UnknownNameError, core as _core)

__all__ = ["System", "InitialCorrection"]


@dataclass
class InitialCorrection:
    """Report of the initial-state correction done by :class:`System`.

    Attributes
    ----------
    iterations : int
        Newton iterations of the position correction (0 if the guess was already consistent).
    position_residual_before, position_residual_after : float
        ``max |Phi(q, t0)|`` at the guess and after the correction.
    velocity_residual_before, velocity_residual_after : float
        ``max |A qd + Phi_t|`` at the guess (with corrected positions) and after projection.
    dq, dqd : ndarray, shape (n,)
        Changes applied to the guessed positions and velocities.
    held : list of str
        Coordinates that were held at their guessed values.
    coordinate_names : list of str
        Names of the ``n`` coordinates (order of ``dq``).
    """

    iterations: int
    position_residual_before: float
    position_residual_after: float
    velocity_residual_before: float
    velocity_residual_after: float
    dq: np.ndarray
    dqd: np.ndarray
    held: List[str] = field(default_factory=list)
    coordinate_names: List[str] = field(default_factory=list)

    @property
    def max_position_change(self) -> float:
        """``max |dq|``."""
        return float(np.max(np.abs(self.dq))) if self.dq.size else 0.0

    @property
    def max_velocity_change(self) -> float:
        """``max |dqd|``."""
        return float(np.max(np.abs(self.dqd))) if self.dqd.size else 0.0

    @property
    def position_change_norm(self) -> float:
        """``||dq||_2``."""
        return float(np.linalg.norm(self.dq))

    @property
    def velocity_change_norm(self) -> float:
        """``||dqd||_2``."""
        return float(np.linalg.norm(self.dqd))

    def per_coordinate(self) -> Dict[str, Tuple[float, float]]:
        """``{coordinate name: (dq, dqd)}`` for every coordinate."""
        return {n: (float(a), float(b)) for n, a, b in zip(self.coordinate_names, self.dq, self.dqd)}

    def __str__(self) -> str:
        def worst(v: np.ndarray) -> str:
            if not v.size:
                return "-"
            i = int(np.argmax(np.abs(v)))
            return f"{abs(v[i]):.3e} ({self.coordinate_names[i]})"

        return (
            f"initial correction: {self.iterations} Newton iteration(s); "
            f"max|Phi| {self.position_residual_before:.3e} -> {self.position_residual_after:.3e}; "
            f"max|A qd + Phi_t| {self.velocity_residual_before:.3e} -> {self.velocity_residual_after:.3e}; "
            f"max|dq| {worst(self.dq)}; max|dqd| {worst(self.dqd)}"
        )


class System:
    """A compiled multibody system (Rust core) with a consistent initial state.

    Parameters
    ----------
    description : Scene or dict
        The scene (a :class:`ukflex.Scene` or its description dict, validated by the core).
    correct : bool
        Correct the initial guess onto the constraints (default True).  With ``False``, ``q0`` and
        ``qd0`` are the guess itself.
    hold : "elastic", None or sequence of str
        Coordinates held at their guessed values during the correction: ``"elastic"`` (default)
        holds every body's deformation (so an undeformed guess stays undeformed: the elastic
        coordinates of FFRF and modal bodies; an ANCF cable is moved rigidly), ``None`` holds
        none, or give coordinate names such as ``"crank.theta"``; ``"elastic"`` may be combined
        with names in a list.
    position_tol : float
        Newton stops when ``max |Phi| <= position_tol`` (absolute, m and rad); a scene smaller
        than a millimetre is corrected to ``1e-9`` of its length scale instead when that is
        tighter (:data:`System.RESOLUTION`).
    velocity_tol : float
        Accepted ``max |A qd + Phi_t|`` after the velocity projection (absolute).
    max_iterations : int
        Newton iteration limit.
    t0 : float
        Initial time (drivers are evaluated there).
    uk_solver : {"auto", "dense", "sparse"}
        How the UK correction is solved: ``"dense"`` (pseudoinverse of ``A F^-T``),
        ``"sparse"`` (band Cholesky of ``A M^-1 A^T`` with a full-rank certificate, dense
        rank-revealing fallback) or ``"auto"`` (sparse for long chains, ropes and tracks).
        See docs/scale.md. ``core.uk_solver`` tells which path the last call took.
    memory_limit : float, optional
        Bytes any lazily sized group of buffers may take (default 2 GiB): every dense
        ``n x n`` array (``M``, ``jac``, ``tangent_stiffness``, the implicit native integrators'
        dense Newton matrices, the dense modal analysis), the sparse structures, the dense UK
        fallback. Above it :class:`ukflex.MemoryLimitError` is raised before allocating.
    max_wall_time : float, optional
        Wall-time budget [s] of the initial-state correction (default: none); past it
        :class:`ukflex.BudgetError` is raised saying how far the correction got.

    Attributes
    ----------
    description : dict
        The validated description.
    q0, qd0 : ndarray, shape (n,)
        Consistent initial positions and velocities.
    initial_correction : InitialCorrection
        What the correction changed.
    core : ukflex._core.System
        The compiled object.

    Notes
    -----
    Per-step methods are the bound methods of the compiled object (no Python wrapper):
    ``M(q)`` (n, n); ``Q(t, q, qd)`` (n,); ``phi(t, q)`` (m,); ``A(q)`` (m, n);
    ``phi_t(t)`` (m,); ``b(t, q, qd)`` (m,); ``qdd(t, q, qd)`` (n,); ``rhs(t, y)`` (2n,);
    ``multipliers(t, q, qd)`` (m,) with ``M qdd + A^T lam = Q``; ``residuals(t, q, qd)`` ->
    (position, velocity, acceleration), each (m,); ``rank()``; ``beam_shape(body, xi)``;
    ``beam_point(body, xi, q)`` -> x, y (world), u, v (displacement in the beam frame:
    an FFRF beam's floating frame, an ANCF beam's chord frame of the ends), psi: shape (5,) for
    q (n,), (5, nt) for q (n, nt) (time along the last axis); ``tangent_stiffness(body, q)`` (n_b, n_b); ``kinetic_energy(q, qd)``;
    ``potential_energy(q)``.

    Raises
    ------
    InvalidSceneError
        Malformed description (Python or Rust validation).
    SingularMassError
        The mass matrix is not positive definite at the initial guess.
    InconsistentInitialStateError
        The guess cannot be corrected onto ``Phi = 0`` / ``A qd = -Phi_t``.
    """

    def __init__(
        self,
        description: Any,
        *,
        correct: bool = True,
        hold: Union[str, None, Sequence[str]] = "elastic",
        position_tol: float = 1e-12,
        velocity_tol: float = 1e-10,
        max_iterations: int = 50,
        t0: float = 0.0,
        uk_solver: str = "auto",
        memory_limit: Optional[float] = None,
        max_wall_time: Optional[float] = None,
    ):
        text = None
        if isinstance(description, dict):
            _, self.description = normalize(description)
        elif hasattr(description, "core_text"):
            # a spatial scene: the core's build below is its validation (one build, not two:
            # 0.4 of A05's 1.3 ms); the description kept is the text, read back (a deep copy) at
            # its first use (`description`)
            text = description.core_text()
            self._description_text = text
        elif hasattr(description, "to_dict") and hasattr(description, "validate"):
            description.validate()
            self.description = description.to_dict()
        else:
            raise TypeError(f"System needs a Scene or a description dict, got {type(description).__name__}")
        self._build_options: Dict[str, Any] = {
            "correct": correct, "hold": hold if hold is None or isinstance(hold, str) else list(hold),
            "position_tol": position_tol, "velocity_tol": velocity_tol, "max_iterations": max_iterations, "t0": t0,
            "max_wall_time": max_wall_time,
        }
        self._settings: Dict[str, tuple] = {}
        self._core_options: Dict[str, Any] = {"uk_solver": uk_solver, "memory_limit": memory_limit}
        # the loads' Python callables (docs/loads.md): not plain data, kept beside the description
        self._callables: Dict[str, Any] = getattr(description, "callables", {}) if not isinstance(description, dict) else {}
        self._bind(_core.System(text or json.dumps(self.description), callables=self._callables, **self._core_options))
        core = self.core
        self.t0 = float(t0)
        q_guess, qd_guess = core.initial_guess()
        self.q_guess = np.asarray(q_guess, dtype=float)
        self.qd_guess = np.asarray(qd_guess, dtype=float)
        # Let the core check the mass matrix (and everything else a step needs) at the guess:
        # raises SingularMassError if M is not positive definite.
        try:
            core.qdd(self.t0, self.q_guess, self.qd_guess)
        except NonFiniteError as exc:
            raise InvalidSceneError(
                "the scene's properties are out of the range double precision can evaluate: the "
                f"accelerations at the initial guess are not finite ({exc}); check masses, gravity, "
                "stiffnesses, initial velocities and their units"
            ) from exc

        scale = self.length_scale
        if correct:
            # a tolerance in metres must not be coarser than the scene itself (a 1e-30 m rod
            # would be "corrected" onto the pivot): 1e-9 of the length scale when that is tighter
            tol = max(min(float(position_tol), self.RESOLUTION * scale), np.finfo(float).tiny)
            self._tol_note = (f" = {self.RESOLUTION:g} of the scene's length scale {scale:.3g} m"
                              if tol < float(position_tol) else "")
            self.q0, self.qd0, self.initial_correction = self._correct(
                self.q_guess, self.qd_guess, hold, tol, velocity_tol, max_iterations, max_wall_time
            )
        else:
            self.q0, self.qd0 = self.q_guess.copy(), self.qd_guess.copy()
            rp = self._max_abs(core.phi(self.t0, self.q0))
            rv = self._max_abs(core.A(self.q0) @ self.qd0 + core.phi_t(self.t0))
            self.initial_correction = InitialCorrection(
                0, rp, rp, rv, rv, np.zeros(self.n_coords), np.zeros(self.n_coords), [], self.coordinate_names
            )
        self._check_state()
        try:  # energies are outputs of every run: they must be representable at the start
            core.kinetic_energy(self.q0, self.qd0)
            core.potential_energy(self.q0)
        except NonFiniteError as exc:
            raise InvalidSceneError(
                f"the scene's energy at the initial state is out of the double-precision range ({exc}); "
                "check lengths, masses, gravity and their units"
            ) from exc

    @property
    def description(self) -> Dict[str, Any]:
        """The validated description (a spatial scene's read back from the core's text at the
        first use: a run does not need it, 0.09 ms of A05's 0.6 ms build)."""
        d = self.__dict__.get("_description")
        if d is None:
            d = self._description = json.loads(self.__dict__["_description_text"])
        return d

    @description.setter
    def description(self, value: Dict[str, Any]) -> None:
        self._description = value

    def _bind(self, core: Any) -> None:
        """Attach the compiled object and its bound per-step methods (no Python layer per call)."""
        self.core = core

        # hot per-step methods: the compiled object's bound methods, no Python layer
        self.rhs = core.rhs
        self.qdd = core.qdd
        self.M = core.M
        self.Q = core.Q
        self.phi = core.phi
        self.A = core.A
        self.phi_t = core.phi_t
        self.b = core.b
        self.multipliers = core.multipliers
        self.residuals = core.residuals
        self.rank = core.rank
        self.beam_shape = core.beam_shape
        self.beam_point = core.beam_point
        self.tangent_stiffness = core.tangent_stiffness
        self.kinetic_energy = core.kinetic_energy
        self.potential_energy = core.potential_energy
        # Jacobian of rhs, d[qd, qdd]/d[q, qd], shape (2n, 2n): finite differences in Rust (GIL released)
        self.jac = core.jac
        # solver settings, diagnostics and native integration (the compiled object's methods)
        self.rank_info = core.rank_info
        self.project = core.project
        self.integrate = core.integrate
        # benchmark helper: seconds per Rust UK call (minimum over batches, GIL released)
        self.time_acceleration = core.time_acceleration

        self.n_coords: int = int(core.n_coords)
        self.n_constraints: int = int(core.n_constraints)
        self.body_names: List[str] = list(core.body_names)
        self.body_slices: Dict[str, Tuple[int, int]] = {k: (int(v[0]), int(v[1])) for k, v in dict(core.body_slices).items()}
        self.coordinate_names: List[str] = list(core.coordinate_names)
        self.constraint_names: List[str] = list(core.constraint_names)
        self.body_kind = core.body_kind
        self.body_info = core.body_info
        #: what a body can be asked (a dict of booleans: beam, elastic, elastic_coordinates,
        #: axial_forces, named_markers, oriented, nodal_deformation, damped), from the core's
        #: kinds, so that no Python code keeps lists of kinds
        self.capabilities = core.body_capabilities
        self.axial_forces = core.axial_forces

    # ------------------------------------------------------------------------------ settings
    def set_stabilization(self, *args: Any) -> None:
        """Constraint stabilization of the UK accelerations (core ``set_stabilization``)."""
        self.core.set_stabilization(*args)
        self._settings["set_stabilization"] = args

    def set_rank_tolerance(self, rcond: Optional[float] = None, atol: float = 0.0) -> None:
        """Drop singular values of ``A F^-T`` at or below ``max(atol, rcond sigma_max)``."""
        self.core.set_rank_tolerance(rcond, atol)
        self._settings["set_rank_tolerance"] = (rcond, atol)

    def set_pseudoinverse(self, kind: str = "auto") -> None:
        """Pseudoinverse backend: ``"auto"``, ``"qr-jacobi"`` or ``"faer"``."""
        self.core.set_pseudoinverse(kind)
        self._settings["set_pseudoinverse"] = (kind,)

    # ------------------------------------------------------------------------------ pickling
    def __getstate__(self) -> Dict[str, Any]:
        """The description, build options, solver settings and the initial state (not the compiled
        object: :meth:`__setstate__` rebuilds it from the description)."""
        return {
            "description": self.description,
            "build_options": self._build_options,
            "core_options": self._core_options,
            "settings": self._settings,
            "t0": self.t0,
            "q_guess": self.q_guess,
            "qd_guess": self.qd_guess,
            "q0": self.q0,
            "qd0": self.qd0,
            "initial_correction": self.initial_correction,
        }

    #: The settings a pickled System replays (``_settings``).
    SETTINGS = ("set_stabilization", "set_rank_tolerance", "set_pseudoinverse")

    def __setstate__(self, state: Dict[str, Any]) -> None:
        """Rebuild from :meth:`__getstate__`'s dict, checking it: a state that is not one (a key
        missing or unknown, a setting that is not one, states of the wrong shape or not finite)
        is an :class:`InvalidArgumentError` naming the entry; the description is validated by
        the core as any scene is."""
        def bad(entry: str, message: str) -> InvalidArgumentError:
            return InvalidArgumentError(f"System pickle state[{entry!r}]", message)

        if not isinstance(state, Mapping):
            raise InvalidArgumentError("System pickle state", f"expected a dict, got {type(state).__name__}")
        keys = ("description", "build_options", "settings", "t0", "q_guess", "qd_guess", "q0", "qd0",
                "initial_correction")
        missing = [k for k in keys if k not in state]
        unknown = [k for k in state if k not in keys + ("core_options",)]
        if missing or unknown:
            raise InvalidArgumentError("System pickle state", f"missing entries {missing}, unknown entries {unknown}")
        for key in ("build_options", "settings", "core_options"):
            if not isinstance(state.get(key, {}), Mapping):
                raise bad(key, f"expected a dict, got {type(state[key]).__name__}")
        core_options = dict(state.get("core_options", {}))
        if set(core_options) - {"uk_solver", "memory_limit"}:
            raise bad("core_options", f"unknown options {sorted(set(core_options) - {'uk_solver', 'memory_limit'})}")
        settings = dict(state["settings"])
        for name, args in settings.items():
            if name not in self.SETTINGS or not isinstance(args, tuple):
                raise bad("settings", f"expected {{name: args tuple}} with names in {list(self.SETTINGS)}, got "
                                      f"{reprlib.repr(name)}: {reprlib.repr(args)}")
        _, description = normalize(state["description"])
        try:
            t0 = real("t0", state["t0"])
        except InvalidArgumentError as exc:
            raise bad("t0", str(exc)) from None
        if not isinstance(state["initial_correction"], InitialCorrection):
            raise bad("initial_correction", f"expected an InitialCorrection, got {type(state['initial_correction']).__name__}")
        try:
            self._restore(dict(state, description=description, core_options=core_options, settings=settings, t0=float(t0)))
        except (ValueError, TypeError) as exc:  # a setting or core option the core refuses
            raise bad("settings", f"{type(exc).__name__}: {exc}") from exc
        for key in ("q_guess", "qd_guess", "q0", "qd0"):
            try:
                v = np.array(state[key], dtype=float)
            except (TypeError, ValueError, OverflowError) as exc:
                raise bad(key, f"expected an array of {self.n_coords} floats ({exc})") from None
            if v.shape != (self.n_coords,) or not np.all(np.isfinite(v)):
                raise bad(key, f"expected {self.n_coords} finite floats (the scene's coordinates), got shape {v.shape}")
            setattr(self, key, v)

    def _restore(self, state: Dict[str, Any]) -> None:
        """Rebuild from a state known to be one (:meth:`copy`, or checked by :meth:`__setstate__`)."""
        self.description = state["description"]
        self._build_options = dict(state["build_options"])
        self._settings = {}
        self._core_options = dict(state.get("core_options", {}))
        # a copy keeps the callables; a pickle does not carry them (building then names them)
        self._callables = getattr(self, "_callables", {})
        self._bind(_core.System(json.dumps(self.description), callables=self._callables, **self._core_options))
        for name, args in state["settings"].items():
            getattr(self, name)(*args)
        for key in ("t0", "initial_correction", "q_guess", "qd_guess", "q0", "qd0"):
            setattr(self, key, state[key])

    def copy(self) -> "System":
        """An independent System: same description, build options, settings and initial state,
        its own compiled object and workspace.  Settings (``set_stabilization``,
        ``set_rank_tolerance``, ``set_pseudoinverse``) belong to a System object; threads that
        need different settings at the same time each use their own copy (``simulate(..., stabilization=...)`` and
        ``stability.rank_history`` do this for you)."""
        new = System.__new__(System)
        new._callables = self._callables
        new._restore(self.__getstate__())
        return new

    # ------------------------------------------------------------------------------ info
    @property
    def y0(self) -> np.ndarray:
        """Initial integrator state ``[q0, qd0]``, shape (2n,)."""
        return np.concatenate([self.q0, self.qd0])

    @property
    def n_dof(self) -> int:
        """``n - rank(A(q0))``: degrees of freedom at the initial state (above
        :attr:`SPARSE_MODES_MIN` coordinates the rank of the UK solve at the initial state:
        the sparse path's certified full rank, or the dense rank-revealing fallback's)."""
        if self.n_constraints == 0:
            return self.n_coords
        if self.n_coords >= self.SPARSE_MODES_MIN:
            info = self.core.rank_info(self.t0, self.q0, self.qd0, exact=False)
            return self.n_coords - int(info["rank"])
        return self.n_coords - int(np.linalg.matrix_rank(self.A(self.q0)))

    def __repr__(self) -> str:
        return f"System(bodies={self.body_names}, n_coords={self.n_coords}, n_constraints={self.n_constraints})"

    def coordinate_index(self, name: str) -> int:
        """Index in ``q`` of coordinate ``name`` (e.g. ``"crank.theta"``, ``"coupler.qf0"``)."""
        try:
            return self.coordinate_names.index(name)
        except ValueError:
            raise UnknownNameError.of("coordinate", name, self.coordinate_names) from None

    def body_slice(self, body: str) -> slice:
        """Slice of ``q`` holding body ``body``'s coordinates ``[x, y, theta, q_f...]``."""
        if not isinstance(body, str) or body not in self.body_slices:
            raise UnknownNameError.of("body", body, self.body_names)
        start, stop = self.body_slices[body]
        return slice(start, stop)

    def elastic_slice(self, body: str) -> slice:
        """Slice of ``q`` holding body ``body``'s elastic coordinates ``q_f``."""
        if not isinstance(body, str) or body not in self.body_slices:
            raise UnknownNameError.of("body", body, self.body_names)
        start, stop = self.core.elastic_range(body)
        if start == stop:
            flexible = [b for b in self.body_names if self.core.elastic_range(b)[0] != self.core.elastic_range(b)[1]]
            raise UnknownNameError(f"body {body!r} is {self.body_kind(body)}: it has no elastic coordinates; bodies "
                                   f"with elastic coordinates: {flexible}", "flexible body", body, flexible)
        return slice(start, stop)

    def elastic_mask(self) -> np.ndarray:
        """Boolean mask (n,) of the elastic coordinates of every flexible body."""
        mask = np.zeros(self.n_coords, dtype=bool)
        for name in self.body_names:
            start, stop = self.core.elastic_range(name)
            mask[start:stop] = True
        return mask

    def energy(self, q: np.ndarray, qd: np.ndarray) -> float:
        """Total mechanical energy ``T + V`` (gravity, elastic, springs)."""
        return float(self.kinetic_energy(q, qd) + self.potential_energy(q))

    def beam_matrices(self, body: str) -> Tuple[np.ndarray, np.ndarray]:
        """Constant elastic blocks ``(M_ff, K_ff)`` of beam ``body`` from the core, each (n_f, n_f)."""
        M_ff, K_ff = self.core.beam_matrices(body)
        return np.asarray(M_ff), np.asarray(K_ff)

    def stiffness_matrix(self, body: str, finite_difference: bool = False, h: float = 1e-7) -> np.ndarray:
        """Elastic stiffness ``K_ff`` of beam ``body``, shape (n_f, n_f).

        By default the core's constant ``K_ff``.  With ``finite_difference=True``: central
        differences of ``-Q`` with respect to ``q_f`` at ``q_f = 0``, zero velocities, reference
        coordinates of ``q0`` (an independent check of the elastic force).  The elastic force
        ``-K_ff q_f`` is linear; gravity, point forces and torques give generalized forces on
        ``q_f`` that do not depend on ``q_f`` and cancel in the difference; spring-dampers attached
        to the beam would not (leave them out for a clean ``K_ff``).
        """
        if not finite_difference:
            return self.beam_matrices(body)[1]
        sl = self.elastic_slice(body)
        q = self.q0.copy()
        q[sl] = 0.0
        qd = np.zeros(self.n_coords)
        idx = np.arange(sl.start, sl.stop)
        K = np.empty((idx.size, idx.size))
        for j, k in enumerate(idx):
            qp, qm = q.copy(), q.copy()
            qp[k] += h
            qm[k] -= h
            K[:, j] = -(self.Q(self.t0, qp, qd)[idx] - self.Q(self.t0, qm, qd)[idx]) / (2.0 * h)
        return K

    def mass_matrix_elastic(self, body: str, q: Optional[np.ndarray] = None) -> np.ndarray:
        """Elastic block ``M_ff`` of beam ``body`` at ``q`` (default ``q0``), shape (n_f, n_f)."""
        sl = self.elastic_slice(body)
        M = self.M(self.q0 if q is None else np.asarray(q, dtype=float))
        return M[sl, sl]

    def M_sparse(self, q: Optional[np.ndarray] = None):
        """The mass matrix at ``q`` (default ``q0``) as a ``scipy.sparse`` CSR array (n, n): the
        body blocks, no dense ``n x n`` allocation."""
        from scipy.sparse import coo_array

        n = self.n_coords
        r, c, v = self.core.M_sparse(np.ascontiguousarray(self.q0 if q is None else q, dtype=float))
        return coo_array((np.asarray(v), (np.asarray(r), np.asarray(c))), shape=(n, n)).tocsr()

    #: from this many coordinates on, ``frequencies(count=k)``, ``max_frequency`` and ``n_dof``
    #: take the sparse path (sparse linearization, shift-invert Lanczos, the UK solve's rank):
    #: measured crossover, docs/scale.md
    SPARSE_MODES_MIN = 64

    def frequencies(
        self,
        t: Optional[float] = None,
        q: Optional[np.ndarray] = None,
        qd: Optional[np.ndarray] = None,
        modes: bool = False,
        count: Optional[int] = None,
        deadline: Optional[float] = None,
    ):
        """Natural frequencies [rad/s] of the constrained system linearized at a state (default
        the initial state): :func:`ukflex.analysis.frequencies.frequencies`."""
        from ..analysis.frequencies import frequencies

        return frequencies(self, t, q, qd, modes=modes, count=count, deadline=deadline)

    def max_frequency(self, t: Optional[float] = None, q: Optional[np.ndarray] = None,
                      qd: Optional[np.ndarray] = None, deadline: Optional[float] = None) -> float:
        """The fastest natural frequency [rad/s] at a state (default the initial state):
        :func:`ukflex.analysis.frequencies.max_frequency`."""
        from ..analysis.frequencies import max_frequency

        return max_frequency(self, t, q, qd, deadline=deadline)

    def equilibrium(self, t: Optional[float] = None, q: Optional[np.ndarray] = None, tol: float = 1e-10,
                    max_iterations: int = 50):
        """Static equilibrium at time ``t`` (default ``t0``) from ``q`` (default ``q0``):
        :func:`ukflex.analysis.equilibrium.equilibrium`."""
        from ..analysis.equilibrium import equilibrium

        return equilibrium(self, t, q, tol=tol, max_iterations=max_iterations)

    # ------------------------------------------------------------------------------ correction
    @staticmethod
    def _max_abs(v: np.ndarray) -> float:
        v = np.asarray(v)
        return float(np.max(np.abs(v))) if v.size else 0.0

    def _held_mask(self, hold: Union[str, None, Sequence[str]]) -> np.ndarray:
        mask = np.zeros(self.n_coords, dtype=bool)
        if hold is None:
            return mask
        items = [hold] if isinstance(hold, str) else list(hold)
        for h in items:
            if h == "elastic":
                mask |= self.elastic_mask()
            else:
                mask[self.coordinate_index(h)] = True
        return mask

    def _worst_rows(self, residual: np.ndarray, k: int = 3) -> List[str]:
        order = np.argsort(-np.abs(residual))[:k]
        return [self.constraint_names[i] for i in order if abs(residual[i]) > 0.0]

    def _detail(self, residual: np.ndarray, k: int = 3) -> str:
        order = [i for i in np.argsort(-np.abs(residual))[:k] if abs(residual[i]) > 0.0]
        return ", ".join(f"{self.constraint_names[i]} = {residual[i]:.3e}" for i in order)

    #: positions must be resolved by double precision to this fraction of the scene's length scale
    #: (the core's rule, ``rust/model/scale.rs``, ``rust/correct/conditioning.rs``; the initial correction's tolerance is never coarser)
    RESOLUTION = _core.RESOLUTION

    def _check_state(self) -> None:
        """Refuse a corrected start double precision cannot resolve (positions or angles far from
        the origin, masses too disparate for the rank decision): the core's rules,
        ``rust/model/scale.rs``, ``rust/correct/conditioning.rs``."""
        self.core.check_state(self.t0, self.q0, self.qd0)

    @property
    def length_scale(self) -> float:
        """The scene's length scale [m]: the largest body dimension (beam lengths, centre-of-mass
        and marker offsets on bodies, distance lengths; 1 m for a scene without any), from the
        core (``rust/model/scale.rs``, ``rust/correct/conditioning.rs``); tolerances in metres are read against it."""
        return self.core.length_scale

    #: A driven coordinate moved by the initial correction by more than this (rad for angle and
    #: rotation drivers; times the scene's length scale, m, for coordinate and translation
    #: drivers) raises an :class:`ukflex.errors.InitialCorrectionWarning`.
    DRIVEN_MOVE_TOL = 1e-3

    def _driven_values(self, q: np.ndarray) -> Dict[str, float]:
        """The coordinate each driver holds at ``q``, up to the driver's value at ``t0`` (rad or m),
        by driver name: planar drivers' rows are ``driven value - f(t)`` (so ``Phi(t0, q)`` plus a
        constant); a spatial rotation driver's row is its angle error wrapped to the nearest turn,
        so its angle is the core's (``driver_values`` of :func:`ukflex.spatial_outputs`)."""
        names = list(self.core.driver_names)  # the core's names (declaration order; defaults for unnamed drivers)
        if not names:
            return {}
        q = np.asarray(q, dtype=float)
        if self.description.get("dim") == 3:  # one value per constraint item
            raw = self.core.spatial_outputs(np.array([self.t0]), q[None, :], np.zeros((1, q.size)), False)
            values, items = np.asarray(raw["driver_values"])[0], list(raw["reaction_names"])
        else:  # one value per row (a planar driver has one row, named as the driver)
            values, items = np.asarray(self.core.phi(self.t0, q), dtype=float), self.constraint_names
        return {name: float(values[items.index(name)]) for name in names if name in items}

    def _warn_driven_moves(self, q_guess: np.ndarray, q: np.ndarray) -> None:
        """Warn once (:class:`InitialCorrectionWarning`) naming every driver whose driven
        coordinate the correction moved by more than :data:`DRIVEN_MOVE_TOL`."""
        before, after = self._driven_values(q_guess), self._driven_values(q)
        if not before:
            return
        scale = self.length_scale
        kinds = dict(zip(self.core.driver_names, (d.get("kind") for d in self.description.get("drivers") or [])))
        moves, parts = {}, []
        for name, b in before.items():
            move = after[name] - b
            angular = kinds[name] in ("angle", "rotation")
            if abs(move) > self.DRIVEN_MOVE_TOL * (1.0 if angular else scale):
                moves[name] = move
                parts.append(f"driver '{name}' by {move:+.4g} rad ({np.degrees(move):+.4g} degrees)" if angular
                             else f"driver '{name}' by {move:+.4g} m")
        if moves:
            warnings.warn(InitialCorrectionWarning(
                "the initial-state correction moved driven coordinates to the drivers' values at t0: " + "; ".join(parts)
                + ". The initial guess disagrees with the driver: give the driver's initial value (e.g. "
                "ConstantSpeed(speed, initial=angle)) or place the body where the driver starts", moves), stacklevel=4)

    def _correct(self, q_guess, qd_guess, hold, position_tol, velocity_tol, max_iterations, max_wall_time=None):
        held = self._held_mask(hold)
        rigid = hold is not None and "elastic" in ([hold] if isinstance(hold, str) else list(hold))
        c = self.core.correct(self.t0, q_guess, qd_guess, [bool(h) for h in held], position_tol=position_tol,
                              velocity_tol=velocity_tol, max_iterations=max_iterations, max_wall_time=max_wall_time,
                              rigid=rigid)
        if not c["positions_ok"]:
            phi = np.asarray(c["phi"])
            raise InconsistentInitialStateError(
                f"initial positions cannot be corrected onto the constraints Phi(q, t0) = 0: after {c['iterations']} "
                f"Newton iteration(s) max |Phi| = {c['position_residual_after']:.3e} (tolerance {position_tol:.1e}{getattr(self, '_tol_note', '')}); "
                f"largest residual rows: {self._detail(phi)}" + (" (held coordinates: elastic)" if np.any(held) else ""),
                rows=self._worst_rows(phi),
                residuals=phi,
            )
        if not c["velocities_ok"]:
            vres = np.asarray(c["velocity"])
            raise InconsistentInitialStateError(
                f"initial velocities cannot be projected onto A qd = -Phi_t with the held coordinates fixed: "
                f"max |A qd + Phi_t| = {c['velocity_residual_after']:.3e}; largest residual rows: {self._detail(vres)}",
                rows=self._worst_rows(vres),
                residuals=vres,
            )
        q, qd = np.asarray(c["q"]), np.asarray(c["qd"])
        self._warn_driven_moves(q_guess, q)
        report = InitialCorrection(
            iterations=int(c["iterations"]),
            position_residual_before=float(c["position_residual_before"]),
            position_residual_after=float(c["position_residual_after"]),
            velocity_residual_before=float(c["velocity_residual_before"]),
            velocity_residual_after=float(c["velocity_residual_after"]),
            dq=q - q_guess,
            dqd=qd - qd_guess,
            held=[n for n, h in zip(self.coordinate_names, held) if h],
            coordinate_names=self.coordinate_names,
        )
        return q, qd, report
