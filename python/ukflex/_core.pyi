"""Type stubs of the compiled Rust extension ``ukflex._core`` (private; use ``ukflex.System``).

tests/test_stubs.py checks these against the compiled module: every name, parameter name,
parameter kind and default must match.
"""

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union, final

import numpy as np
import numpy.typing as npt

_F64 = npt.NDArray[np.float64]
_I64 = npt.NDArray[np.int64]

__all__ = [
    "System",
    "SceneChecker",
    "item_name",
    "beam_elastic_dofs",
    "beam3_default_elements",
    "beam3_material_point",
    "frame_options",
    "motion_values",
    "dense_eval",
    "run_options",
    "check_tolerances",
    "UkflexError",
    "InvalidSceneError",
    "SingularMassError",
    "NonFiniteError",
    "SolverError",
    "ExpressionError",
    "MemoryLimitError",
    "PROJECTION_PER_ATOL",
    "RESOLUTION",
    "AUTO",
    "PROJECTION_MOVE_LIMIT",
    "normal_weight",
    "BudgetError",
]

#: The native methods' projection after each step: Newton on the positions to this fraction of
#: the smallest position atol.
PROJECTION_PER_ATOL: float
#: Away from singular configurations a step whose projection moves the state by more than this
#: many tolerance units is retried shorter.
PROJECTION_MOVE_LIMIT: float
#: positions are resolved to this fraction of the scene's length scale, angles to this many
#: radians (rust/model/scale.rs)
RESOLUTION: float
#: method="auto"'s constants by name (rust/integrate/choice/mod.rs): PHASE_PER_RTOL, ...,
#: FLOOR_POINTS (a list)
AUTO: Dict[str, Any]
def normal_weight(kappa: float, kappa_ref: float) -> float:
    """Weight of the part of an error estimate across the constraints: min(1, kappa / kappa_ref)^2."""

class UkflexError(Exception): ...
class InvalidSceneError(UkflexError): ...
class SingularMassError(UkflexError): ...
class SolverError(UkflexError): ...
class NonFiniteError(UkflexError): ...
class ExpressionError(InvalidSceneError):
    position: int
    expression: str
class MemoryLimitError(UkflexError): ...
class BudgetError(SolverError): ...

@final
class System:
    """Compiled model + workspace built from a JSON scene description (docs/scene-format.md)."""

    def __new__(cls, description_json: str, uk_solver: str = "auto", memory_limit: Optional[float] = None, callables: Optional[Dict[str, Any]] = None) -> "System": ...
    @property
    def uk_solver(self) -> Tuple[str, str]:
        """(asked at build: "auto" | "dense" | "sparse", taken by the last acceleration)."""
    @property
    def memory_limit(self) -> int:
        """Bytes any lazily sized group of buffers may take (MemoryLimitError above)."""
    def M(self, q: _F64) -> _F64:
        """Mass matrix, shape (n, n) (MemoryLimitError above memory_limit)."""
    def M_sparse(self, q: _F64) -> Tuple[_I64, _I64, _F64]:
        """Mass matrix in coordinate form: (rows, cols, values) of the body blocks."""
    def linearization(
        self, t: float, q: _F64, qd: _F64, qdd: Optional[_F64] = None, lam: Optional[_F64] = None, stiffness: bool = True
    ) -> Dict[str, Any]:
        """Constrained linearization in sparse form: rows, cols, M, K (coordinate pattern),
        a_rows, a_cols, A, qdd, lambda, colors (ukflex.modes); qdd, lam held if given."""
    def Q(self, t: float, q: _F64, qd: _F64) -> _F64:
        """Generalized forces (applied + quadratic velocity + elastic), shape (n,)."""
    def phi(self, t: float, q: _F64) -> _F64:
        """Constraint residual Phi(q, t), shape (m,)."""
    def A(self, q: _F64) -> _F64:
        """Constraint Jacobian Phi_q, shape (m, n)."""
    def phi_t(self, t: float) -> _F64:
        """Partial time derivative of Phi, shape (m,)."""
    def b(self, t: float, q: _F64, qd: _F64) -> _F64:
        """Right-hand side gamma of A qdd = b, shape (m,)."""
    def qdd(self, t: float, q: _F64, qd: _F64) -> _F64:
        """Udwadia-Kalaba accelerations, shape (n,)."""
    def rhs(self, t: float, y: _F64) -> _F64:
        """First-order right-hand side [qd, qdd] of y = [q, qd], shape (2n,)."""
    def time_acceleration(self, t: float, q: _F64, qd: _F64, reps: int = 1000, batches: int = 21) -> float:
        """Benchmark helper: seconds per call of the Rust UK acceleration alone (min over batches)."""
    def multipliers(self, t: float, q: _F64, qd: _F64) -> _F64:
        """Lagrange multipliers with M qdd + A^T lam = Q, shape (m,)."""
    def residuals(self, t: float, q: _F64, qd: _F64) -> Tuple[_F64, _F64, _F64]:
        """(Phi, A qd + Phi_t, A qdd - b), each shape (m,)."""
    def rank(self) -> Tuple[int, float]:
        """(rank, smallest kept singular value) of the last UK solve."""
    def initial_guess(self) -> Tuple[_F64, _F64]:
        """(q, qd) from the description's state fields, each shape (n,)."""
    def beam_shape(self, body: str, xi: float) -> Tuple[_F64, _F64]:
        """At x = xi * length of beam ``body``: FFRF (S (2, n_f), N_psi (n_f,)), elastic
        displacement S q_f in the beam frame; ANCF (S (2, n_b), S' (2, n_b)), world position
        S e and slope S' e of the body's coordinates e."""
    def beam_matrices(self, body: str) -> Tuple[_F64, _F64]:
        """Constant elastic blocks (M_ff, K_ff) of beam ``body``, each (n_f, n_f); ANCF: the
        constant mass matrix and the stiffness at the undeformed guess, each (n_b, n_b)."""
    def tangent_stiffness(self, body: str, q: _F64) -> _F64:
        """-dQ_el/dq_b of beam or flexible body ``body``'s elastic forces at q (n,), shape (n_b, n_b)."""
    def outline(self, body: str, q: _F64, deform_scale: float = 1.0, points_per_element: int = 8) -> _F64:
        """World points (k, 2) drawing planar body `body` at `q`, elastic displacements magnified."""
    def marker_points(self, q: _F64, deform_scale: float = 1.0) -> Dict[str, List[Optional[_F64]]]:
        """World points of every joint's and driver's markers at `q`: {name: [a or None, b or None]}."""
    def beam_point(self, body: str, xi: float, q: _F64) -> _F64:
        """Rows x, y (world), u, v (displacement in the beam frame; ANCF: the chord frame of
        the ends), psi of the axis point at xi; shape (5,) for q (n,), (5, nt) for q (n, nt)."""
    def residual_norms(self, t: _F64, q: _F64, qd: _F64) -> _F64:
        """Norms of the position, velocity and acceleration residuals along a trajectory, (3, nt)."""
    def rank_info(self, t: Optional[float] = None, q: Optional[_F64] = None, qd: Optional[_F64] = None, exact: bool = True) -> Dict[str, Any]:
        """uk_path, rank, sigma_max, sigma_min_kept, sigma_max_dropped, tolerance, exact of the UK solve at
        (t, q, qd) (one lock: thread-safe), or of the last solve of any thread without a state; exact is
        False after the sparse path with m > 256 (the certified bounds, no dense SVD), and after any
        certified full-rank solve with exact=False (no on-demand singular values)."""
    def set_rank_tolerance(self, rcond: Optional[float] = None, atol: float = 0.0) -> None:
        """Drop singular values of A F^-T at or below max(atol, rcond sigma_max)."""
    def set_pseudoinverse(self, kind: str = "auto") -> None:
        """Pseudoinverse backend: "auto", "qr-jacobi", "faer" or "cod" (rank-deficient B by a complete orthogonal decomposition)."""
    def set_stabilization(self, kind: str = "none", alpha: float = 0.0, beta: float = 0.0) -> None:
        """Constraint stabilization: kind "none" or "baumgarte" (Phi_dd + 2 alpha Phi_d + beta^2 Phi = 0)."""
    def jac(self, t: float, y: _F64, scheme: str = "central") -> _F64:
        """d[qd, qdd]/d[q, qd], shape (2n, 2n) (finite differences in Rust)."""
    def integrate(
        self,
        t0: float,
        y0: _F64,
        t_end: float,
        method: str = "RADAU5",
        rtol: float = 1e-6,
        atol: Union[None, float, _F64] = None,
        t_eval: Optional[Sequence[float]] = None,
        first_step: Optional[float] = None,
        max_step: Optional[float] = None,
        max_steps: int = 1_000_000,
        projection_tol: Optional[float] = None,
        rho_inf: Optional[float] = None,
        step: Optional[float] = None,
        jacobian: str = "structured",
        max_nfev: Optional[int] = None,
        max_wall_time: Optional[float] = None,
        min_step: float = 0.0,
        dense: bool = False,
        newton_local_error: Optional[float] = None,
        linear_solver: str = "auto",
        drift_limit: Optional[float] = None,
        on_drift: str = "stop",
        monitor_singular: bool = True,
        progress: Optional[Callable[[float], Any]] = None,
        progress_steps: int = 100,
        progress_interval: float = 0.5,
    ) -> Dict[str, Any]:
        """Native integration; dict with t (nt,), y (2n, nt), status, message, failure (None or
        cause, t, stage, index), statistics, dense (None or meta (nseg, 3), data, part_len),
        singular (the singular passages), drift (None or t_first, max_residual, t_max).
        linear_solver: how GENALPHA and RADAU5M factor their Newton matrices ("auto", "dense",
        "sparse": band LU after a fill-reducing order, docs/scale.md).
        progress: progress(t) every progress_steps accepted steps or progress_interval seconds
        (the run takes the GIL only then); an exception it raises ends the run and is raised."""
    def project(
        self, t: float, q: _F64, qd: _F64, tol: float = 1e-12, max_iter: int = 20
    ) -> Tuple[_F64, _F64, Dict[str, Any]]:
        """Project (q, qd) onto Phi = 0, A qd + Phi_t = 0 in the mass metric."""
    def project_step(self, t: float, q: _F64, qd: _F64, position_tol: float, max_iter: int = 3) -> Tuple[_F64, _F64, float, bool]:
        """The native methods' projection after a step: Newton on the positions until the correction is at
        most position_tol, then the velocities; returns (q, qd, ||Phi||, whether Newton converged)."""
    def tangent_project(self, t: float, q: _F64, v: _F64) -> Tuple[_F64, float]:
        """The columns of v (n, k) projected onto the constraints' tangent space at (t, q) in the mass metric,
        and sigma_min / sigma_max of A M^-1/2 there."""
    def auto_choice(self, t0: float, q: _F64, qd: _F64, t_end: float, rtol: float, n_dof: Optional[int] = None,
                    omega: Optional[_F64] = None, shapes: Optional[_F64] = None,
                    omega_max: Optional[float] = None, floor: bool = True) -> Dict[str, Any]:
        """method="auto"'s decision (rust/integrate/choice/): verdict, method, omega_elastic, omega_max, step,
        newton_rtol, rtol (the integrator's), phase, floor, floor_modes, overdamped; a large system gives n_dof
        and its lowest modes; floor=False leaves the floor out (None)."""
    def material_energies(self, q: _F64, shapes: _F64) -> _F64:
        """1/2 v^T K_m v per column v of shapes (n, k): the bodies' material stiffness and the springs."""
    def rigid_motions(self, q: _F64, qd: _F64) -> Tuple[_F64, _F64]:
        """Basis B (n, r) of the bodies' rigid motions at (q, qd) and the centripetal acceleration cen (n,) of that motion."""
    def singular_passages(self, t: _F64, y: _F64) -> List[Dict[str, Any]]:
        """Singular passages of a trajectory of accepted states t (k,), y (2n, k)."""
    def sensors(self, t: _F64, q: _F64, qd: _F64, reactions: bool = True) -> Dict[str, Any]:
        """Reactions (nt, items, 6), body energies (nt, bodies, 3), force potentials, dissipation power, load power, clearance (nt, clearance joints, 5)."""
        ...
    def restart_turns(self) -> None:
        """Start the spatial rotational springs' and motors' turn counts afresh (a scipy run's start)."""
        ...
    def spatial_outputs(self, t: _F64, q: Any, qd: Any, reactions: bool = True) -> Dict[str, Any]:
        """Spatial outputs at stored states: bodies (nt, bodies, 25), reactions (nt, items, 13), momentum, energies, force potentials and powers, dissipation power, driver values (ukflex.spatial_outputs, res.sensors)."""
        ...
    def beam_internal_forces(self, body: str, xi: _F64, q: _F64) -> _F64:
        """(nt, nx, 5): N, V, M, eps, kappa at the axis points xi."""
        ...
    def kinetic_energy(self, q: _F64, qd: _F64) -> float:
        """1/2 qd^T M(q) qd."""
    def potential_energy(self, q: _F64) -> float:
        """Gravity + elastic strain + springs (and -F.r of constant loads)."""
    @property
    def n_coords(self) -> int: ...
    @property
    def n_constraints(self) -> int: ...
    @property
    def body_names(self) -> List[str]: ...
    @property
    def body_slices(self) -> Dict[str, Tuple[int, int]]: ...
    @property
    def length_scale(self) -> float: ...
    def check_state(self, t: float, q: _F64, qd: _F64) -> None: ...
    @property
    def coordinate_names(self) -> List[str]: ...
    @property
    def constraint_names(self) -> List[str]: ...
    @property
    def constraint_items(self) -> List[str]:
        """Names of the joints and drivers (joints first), as sensors report them."""
    @property
    def driver_names(self) -> List[str]: ...
    def axial_forces(self, body: str, q: _F64) -> _F64:
        """Axial force of each element of a beam at q, shape (elements,)."""
    def body_kind(self, body: str) -> str:
        """Kind of a body, as in the description: "rigid", "beam" (FFRF), "cable" (ANCF), "point_mass", "flexible", "rigid3" or "point3"."""
    def elastic_range(self, body: str) -> Tuple[int, int]:
        """(start, stop) of a body's elastic coordinates in q."""
    def body_info(self, body: str) -> Dict[str, Any]:
        """Properties of a body as the core derived them."""
    def body_capabilities(self, body: str) -> Dict[str, bool]:
        """What a body can be asked: beam, elastic, elastic_coordinates, axial_forces,
        named_markers, oriented (so that Python keeps no lists of kinds)."""
    def correct(
        self,
        t: float,
        q: _F64,
        qd: _F64,
        hold: Sequence[bool],
        position_tol: float = 1e-12,
        velocity_tol: float = 1e-10,
        max_iterations: int = 50,
        max_wall_time: Optional[float] = None,
        rigid: bool = False,
    ) -> Dict[str, Any]:
        """Initial-state correction with held coordinates (rigid: every body's deformation held,
        an ANCF cable moved rigidly); a report dict (BudgetError past max_wall_time seconds)."""

@final
class SceneChecker:
    """Validates a scene item by item with the core's rules (used by ``ukflex.Scene``)."""

    def __new__(cls, gravity_json: Optional[str] = None) -> "SceneChecker": ...
    @staticmethod
    def check_top_level(description_json: str) -> None: ...
    def add_body(self, item_json: str) -> Dict[str, Any]: ...
    def add_joint(self, item_json: str) -> Dict[str, Any]: ...
    def add_driver(self, item_json: str) -> Dict[str, Any]: ...
    def add_force(self, item_json: str) -> Dict[str, Any]: ...
    def finish(self) -> None: ...

def item_name(section: str, kind: str, name: Optional[str], index: int) -> str:
    """How errors name a scene item."""

def motion_values(motion_json: str, t: _F64) -> _F64:
    """(f, f', f'') of a driver motion at the times t, shape (3, nt)."""
    ...
def beam3_default_elements() -> int:
    """Number of elements of a 3D beam whose description gives none."""
    ...
def beam3_material_point(elements: int, length: float, s: float) -> Tuple[int, float]:
    """The node of a 3D beam whose rigid segment holds the material point at arc length s, and the
    point's offset from it along the axis."""
    ...
def beam_elastic_dofs(elements: int, frame: str) -> int:
    """Number of elastic coordinates of a beam."""

def frame_options() -> List[str]:
    """The words of the floating-frame option, in order."""

def dense_eval(method: str, meta: _F64, data: _F64, part_len: List[int], t: _F64) -> _F64:
    """Evaluate the dense output recorded by ``System.integrate(..., dense=True)`` at t (k,): (dim, k)."""
def run_options() -> Dict[str, Any]:
    """The native methods' run options as the core defines them: native_methods, common,
    options ({method: options}), defaults (rtol, atol_per_rtol, rtol_min, projection_per_atol)."""
def check_tolerances(rtol: float, atol: _F64, dim: int) -> _F64:
    """The tolerance rule of every run: rtol > 0 and finite, atol >= 0 and finite (one value or
    dim); returns atol as a (dim,) array."""
