"""Scene description in plain Python.

A :class:`Scene` collects bodies, joints, drivers, forces and the initial-state guess and turns
them into the JSON-compatible dict documented in ``docs/scene-format.md`` (:meth:`Scene.to_dict`),
the contract shared by the Rust core and the NumPy reference.  :meth:`Scene.build` compiles it into
a Rust-backed :class:`ukflex.System`.

Every builder call validates its input at once and raises :class:`ukflex.InvalidSceneError`
naming the offending item; the Rust core validates the same description again.

Example
-------
>>> from ukflex import Scene, Circular, ConstantSpeed
>>> s = Scene(gravity=(0.0, -9.81))
>>> crank = s.rigid_body("crank", mass=0.04, inertia=8e-5, com=(0.0762, 0.0))
>>> s.revolute(s.ground.point(0, 0), crank.point(0, 0))
>>> s.angle_driver(crank.frame(), ConstantSpeed(124.8))
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

from .errors import InvalidSceneError

__all__ = [
    "Scene",
    "Marker",
    "BodyRef",
    "RigidBodyRef",
    "BeamRef",
    "GroundRef",
    "Circular",
    "Rectangular",
    "CustomSection",
    "ConstantSpeed",
    "Polynomial",
    "Harmonic",
    "elastic_dofs",
]

GROUND = "ground"
THEORIES = ("timoshenko", "euler-bernoulli")
FRAMES = ("pinned-pinned", "clamped")
JOINT_KINDS = ("revolute", "point_on_line", "prismatic", "weld")
DRIVER_KINDS = ("angle", "coordinate")
FORCE_KINDS = ("point_force", "torque", "spring_damper")

Vec2 = Tuple[float, float]


# --------------------------------------------------------------------------------------------
# small validation helpers
# --------------------------------------------------------------------------------------------


def _fail(item: str, message: str) -> None:
    raise InvalidSceneError(f"{item}: {message}")


def _number(item: str, field: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) and not _is_numpy_scalar(value):
        _fail(item, f"{field} must be a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        _fail(item, f"{field} must be finite, got {x!r}")
    return x


def _is_numpy_scalar(value: Any) -> bool:
    try:
        import numpy as np

        return isinstance(value, (np.floating, np.integer))
    except ImportError:  # pragma: no cover
        return False


def _positive(item: str, field: str, value: Any) -> float:
    x = _number(item, field, value)
    if x <= 0.0:
        _fail(item, f"{field} must be positive, got {x!r}")
    return x


def _non_negative(item: str, field: str, value: Any) -> float:
    x = _number(item, field, value)
    if x < 0.0:
        _fail(item, f"{field} must be non-negative, got {x!r}")
    return x


def _vec2(item: str, field: str, value: Any) -> List[float]:
    try:
        seq = list(value)
    except TypeError:
        _fail(item, f"{field} must be a 2-vector [x, y], got {value!r}")
    if len(seq) != 2:
        _fail(item, f"{field} must be a 2-vector [x, y], got {len(seq)} entries")
    return [_number(item, f"{field}[{i}]", v) for i, v in enumerate(seq)]


def _floats(item: str, field: str, value: Any, length: Optional[int] = None) -> List[float]:
    try:
        seq = list(value)
    except TypeError:
        _fail(item, f"{field} must be a list of numbers, got {value!r}")
    if length is not None and len(seq) != length:
        _fail(item, f"{field} must have length {length}, got {len(seq)}")
    return [_number(item, f"{field}[{i}]", v) for i, v in enumerate(seq)]


def _keys(item: str, d: Dict[str, Any], allowed: Iterable[str], required: Iterable[str] = ()) -> None:
    if not isinstance(d, dict):
        _fail(item, f"expected a dict, got {type(d).__name__}")
    allowed = set(allowed)
    unknown = sorted(set(d) - allowed)
    if unknown:
        _fail(item, f"unknown field(s) {unknown}; allowed: {sorted(allowed)}")
    missing = [k for k in required if k not in d]
    if missing:
        _fail(item, f"missing required field(s) {missing}")


def _name(item: str, value: Any) -> str:
    if not isinstance(value, str) or not value:
        _fail(item, f"name must be a non-empty string, got {value!r}")
    return value


def elastic_dofs(elements: int, frame: str) -> int:
    """Number of elastic coordinates ``n_f`` of a beam.

    Each of the ``elements + 1`` nodes carries ``(u, v, psi)``; both reference conditions
    (``"pinned-pinned"`` and ``"clamped"``) remove three of them, so ``n_f = 3 * elements``.
    """
    if frame not in FRAMES:
        raise InvalidSceneError(f"unknown frame {frame!r}; expected one of {FRAMES}")
    return 3 * (elements + 1) - 3


# --------------------------------------------------------------------------------------------
# sections and motions (value objects serialising to the description's sub-dicts)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Circular:
    """Solid circular section of diameter ``diameter`` [m]."""

    diameter: float

    def to_dict(self) -> Dict[str, Any]:
        return {"shape": "circular", "diameter": float(self.diameter)}


@dataclass(frozen=True)
class Rectangular:
    """Rectangular section; ``height`` lies in the bending plane (``I = width height^3 / 12``)."""

    width: float
    height: float

    def to_dict(self) -> Dict[str, Any]:
        return {"shape": "rectangular", "width": float(self.width), "height": float(self.height)}


@dataclass(frozen=True)
class CustomSection:
    """Section given by its area ``area`` [m^2] and second moment ``second_moment`` [m^4]."""

    area: float
    second_moment: float

    def to_dict(self) -> Dict[str, Any]:
        return {"shape": "custom", "area": float(self.area), "second_moment": float(self.second_moment)}


@dataclass(frozen=True)
class ConstantSpeed:
    """Motion ``f(t) = initial + speed * t``."""

    speed: float
    initial: float = 0.0

    def to_dict(self) -> Dict[str, Any]:
        return {"kind": "constant_speed", "initial": float(self.initial), "speed": float(self.speed)}


@dataclass(frozen=True)
class Polynomial:
    """Motion ``f(t) = sum_k coefficients[k] * t**k``."""

    coefficients: Sequence[float]

    def to_dict(self) -> Dict[str, Any]:
        return {"kind": "polynomial", "coefficients": [float(c) for c in self.coefficients]}


@dataclass(frozen=True)
class Harmonic:
    """Motion ``f(t) = offset + amplitude * sin(frequency * t + phase)`` (frequency in rad/s)."""

    amplitude: float
    frequency: float
    offset: float = 0.0
    phase: float = 0.0

    def to_dict(self) -> Dict[str, Any]:
        return {
            "kind": "harmonic",
            "offset": float(self.offset),
            "amplitude": float(self.amplitude),
            "frequency": float(self.frequency),
            "phase": float(self.phase),
        }


def _section_dict(item: str, section: Any) -> Dict[str, Any]:
    d = section.to_dict() if hasattr(section, "to_dict") else section
    if not isinstance(d, dict) or "shape" not in d:
        _fail(item, f"section must be Circular, Rectangular, CustomSection or a dict with 'shape', got {section!r}")
    shape = d["shape"]
    where = f"{item} section"
    if shape == "circular":
        _keys(where, d, ("shape", "diameter"), ("diameter",))
        return {"shape": shape, "diameter": _positive(where, "diameter", d["diameter"])}
    if shape == "rectangular":
        _keys(where, d, ("shape", "width", "height"), ("width", "height"))
        return {
            "shape": shape,
            "width": _positive(where, "width", d["width"]),
            "height": _positive(where, "height", d["height"]),
        }
    if shape == "custom":
        _keys(where, d, ("shape", "area", "second_moment"), ("area", "second_moment"))
        return {
            "shape": shape,
            "area": _positive(where, "area", d["area"]),
            "second_moment": _positive(where, "second_moment", d["second_moment"]),
        }
    _fail(where, f"unknown shape {shape!r}; expected 'circular', 'rectangular' or 'custom'")
    raise AssertionError  # unreachable


def _motion_dict(item: str, motion: Any) -> Dict[str, Any]:
    d = motion.to_dict() if hasattr(motion, "to_dict") else motion
    if not isinstance(d, dict) or "kind" not in d:
        _fail(item, f"motion must be ConstantSpeed, Polynomial, Harmonic or a dict with 'kind', got {motion!r}")
    kind = d["kind"]
    where = f"{item} motion"
    if kind == "constant_speed":
        _keys(where, d, ("kind", "initial", "speed"), ("speed",))
        return {
            "kind": kind,
            "initial": _number(where, "initial", d.get("initial", 0.0)),
            "speed": _number(where, "speed", d["speed"]),
        }
    if kind == "polynomial":
        _keys(where, d, ("kind", "coefficients"), ("coefficients",))
        coeffs = _floats(where, "coefficients", d["coefficients"])
        if not coeffs:
            _fail(where, "coefficients must not be empty")
        return {"kind": kind, "coefficients": coeffs}
    if kind == "harmonic":
        _keys(where, d, ("kind", "offset", "amplitude", "frequency", "phase"), ("amplitude", "frequency"))
        return {
            "kind": kind,
            "offset": _number(where, "offset", d.get("offset", 0.0)),
            "amplitude": _number(where, "amplitude", d["amplitude"]),
            "frequency": _number(where, "frequency", d["frequency"]),
            "phase": _number(where, "phase", d.get("phase", 0.0)),
        }
    _fail(where, f"unknown motion kind {kind!r}; expected 'constant_speed', 'polynomial' or 'harmonic'")
    raise AssertionError  # unreachable


# --------------------------------------------------------------------------------------------
# markers and body handles
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Marker:
    """A point and a frame on a body (or the ground), where joints, drivers and forces attach.

    Rigid bodies and the ground use ``point`` (body frame coordinates); beams use ``xi`` in
    ``[0, 1]`` (axis point at ``x = xi * length``).  ``angle`` orients the marker frame relative to
    the body frame.  Markers are usually made with :meth:`RigidBodyRef.point`,
    :meth:`RigidBodyRef.frame`, :meth:`BodyRef.line` or :meth:`BeamRef.at`.
    """

    body: str
    point: Optional[Vec2] = None
    xi: Optional[float] = None
    angle: float = 0.0

    def to_dict(self) -> Dict[str, Any]:
        d: Dict[str, Any] = {"body": self.body}
        if self.point is not None:
            d["point"] = [float(self.point[0]), float(self.point[1])]
        if self.xi is not None:
            d["xi"] = float(self.xi)
        d["angle"] = float(self.angle)
        return d


def _point_args(x: Any, y: Any) -> Vec2:
    if y is None:
        px, py = x
    else:
        px, py = x, y
    return (float(px), float(py))


class BodyRef:
    """Handle to a body of a :class:`Scene` (returned by the builder methods)."""

    kind = ""

    def __init__(self, scene: "Scene", name: str):
        self._scene = scene
        self.name = name

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, BodyRef) and other.name == self.name and other._scene is self._scene

    def __hash__(self) -> int:
        return hash((id(self._scene), self.name))

    @property
    def description(self) -> Dict[str, Any]:
        """A copy of this body's entry in the scene description."""
        return copy.deepcopy(self._scene._body(self.name))


class _PointBody(BodyRef):
    """Rigid body or ground: markers are points in the body frame."""

    def point(self, x: Any, y: Any = None, angle: float = 0.0) -> Marker:
        """Marker at body-frame point ``(x, y)`` (also accepts ``point((x, y))``)."""
        return Marker(self.name, point=_point_args(x, y), angle=float(angle))

    def frame(self, angle: float = 0.0) -> Marker:
        """Marker at the body-frame origin; its world angle is ``theta + angle``."""
        return Marker(self.name, point=(0.0, 0.0), angle=float(angle))

    def line(self, origin: Any = (0.0, 0.0), angle: float = 0.0) -> Marker:
        """Marker describing a line through ``origin`` with direction ``(cos angle, sin angle)``
        in the body frame (for :meth:`Scene.point_on_line` and :meth:`Scene.prismatic`)."""
        return Marker(self.name, point=_point_args(origin, None), angle=float(angle))


class GroundRef(_PointBody):
    """The fixed ground (world frame), always named ``"ground"``."""

    kind = "ground"

    def __init__(self, scene: "Scene"):
        super().__init__(scene, GROUND)

    @property
    def description(self) -> Dict[str, Any]:
        return {"name": GROUND, "kind": "ground"}


class RigidBodyRef(_PointBody):
    """Handle to a rigid body: ``point``, ``frame`` and ``line`` make markers."""

    kind = "rigid"


class BeamRef(BodyRef):
    """Handle to an FFRF beam: ``at(xi)`` makes a marker on the beam axis."""

    kind = "beam"

    def at(self, xi: float, angle: float = 0.0) -> Marker:
        """Marker at the axis point ``x = xi * length``, ``xi`` in ``[0, 1]``.

        Its world angle is ``theta + angle + psi(x)`` (the cross-section rotation).
        """
        return Marker(self.name, xi=float(xi), angle=float(angle))

    def line(self, xi: float = 0.0, angle: float = 0.0) -> Marker:
        """Same as :meth:`at`: the line through the axis point with direction ``angle``."""
        return self.at(xi, angle)

    @property
    def n_f(self) -> int:
        """Number of elastic coordinates of this beam."""
        d = self._scene._body(self.name)
        return elastic_dofs(d["elements"], d["frame"])


MarkerLike = Union[Marker, Dict[str, Any]]


# --------------------------------------------------------------------------------------------
# the scene
# --------------------------------------------------------------------------------------------


class Scene:
    """A planar multibody scene: bodies, joints, drivers, forces and the initial-state guess.

    Parameters
    ----------
    gravity : (2,) sequence of float or None
        Gravitational acceleration in the world frame [m/s^2], e.g. ``(0, -9.81)``.  ``None``
        (default) means no gravity term at all.

    Notes
    -----
    Coordinates are ordered by body declaration order, each body contributing
    ``[x, y, theta, q_f...]``; constraint rows are the joints in declaration order followed by the
    drivers.  See ``docs/scene-format.md``.
    """

    def __init__(self, gravity: Optional[Sequence[float]] = None):
        self.gravity: Optional[List[float]] = None if gravity is None else _vec2("scene", "gravity", gravity)
        self._bodies: List[Dict[str, Any]] = []
        self._joints: List[Dict[str, Any]] = []
        self._drivers: List[Dict[str, Any]] = []
        self._forces: List[Dict[str, Any]] = []
        self.ground = GroundRef(self)

    # ----------------------------------------------------------------------------- bodies
    def rigid_body(
        self,
        name: str,
        *,
        mass: float,
        inertia: float,
        com: Sequence[float] = (0.0, 0.0),
        position: Sequence[float] = (0.0, 0.0),
        angle: float = 0.0,
        velocity: Sequence[float] = (0.0, 0.0),
        angular_velocity: float = 0.0,
    ) -> RigidBodyRef:
        """Add a rigid body.

        Parameters
        ----------
        name : str
            Unique body name (not ``"ground"``).
        mass : float
            Mass [kg], positive.
        inertia : float
            Moment of inertia about the centre of mass [kg m^2], positive.
        com : (2,) sequence
            Centre of mass in the body frame [m].
        position, angle, velocity, angular_velocity
            Initial guess of the body frame's position [m], angle [rad] and their rates.
            :meth:`build` corrects it onto the constraints.

        Returns
        -------
        RigidBodyRef
        """
        d = {
            "name": name,
            "kind": "rigid",
            "mass": mass,
            "inertia": inertia,
            "com": com,
            "position": position,
            "angle": angle,
            "velocity": velocity,
            "angular_velocity": angular_velocity,
        }
        self._add_body(d)
        return RigidBodyRef(self, name)

    def beam(
        self,
        name: str,
        *,
        length: float,
        section: Any,
        density: float,
        youngs_modulus: float,
        elements: int = 1,
        theory: str = "timoshenko",
        poisson_ratio: Optional[float] = None,
        shear_modulus: Optional[float] = None,
        shear_factor: Optional[float] = None,
        frame: str = "pinned-pinned",
        rotary_inertia: Optional[bool] = None,
        damping: float = 0.0,
        position: Sequence[float] = (0.0, 0.0),
        angle: float = 0.0,
        velocity: Sequence[float] = (0.0, 0.0),
        angular_velocity: float = 0.0,
        elastic: Optional[Sequence[float]] = None,
        elastic_rates: Optional[Sequence[float]] = None,
    ) -> BeamRef:
        """Add a flexible beam (floating frame of reference, ``elements`` finite elements).

        Parameters
        ----------
        name : str
            Unique body name.
        length : float
            Undeformed length [m].
        section : Circular | Rectangular | CustomSection | dict
            Cross-section.
        density, youngs_modulus : float
            Material density [kg/m^3] and Young's modulus [N/m^2].
        elements : int
            Number of finite elements ``N >= 1``; the beam has ``n_f = 3 N`` elastic coordinates.
        theory : {"timoshenko", "euler-bernoulli"}
        poisson_ratio, shear_modulus : float, optional
            Exactly one is needed for Timoshenko (``G = E / (2 (1 + nu))``); optional otherwise.
        shear_factor : float, optional
            Shear correction factor ``k``, required for Timoshenko.
        frame : {"pinned-pinned", "clamped"}
            Reference conditions of the floating frame.
        rotary_inertia : bool, optional
            Default: true for Timoshenko, false for Euler-Bernoulli (decided by the core).
        damping : float
            Stiffness-proportional damping coefficient ``beta`` [s].
        position, angle, velocity, angular_velocity
            Initial guess of the floating frame (origin = undeformed node 1, ``xi = 0``).
        elastic, elastic_rates : (n_f,) sequence, optional
            Initial elastic coordinates and rates (default zeros).

        Returns
        -------
        BeamRef
        """
        d: Dict[str, Any] = {
            "name": name,
            "kind": "beam",
            "length": length,
            "elements": elements,
            "theory": theory,
            "density": density,
            "youngs_modulus": youngs_modulus,
            "section": section,
            "frame": frame,
            "damping": damping,
            "position": position,
            "angle": angle,
            "velocity": velocity,
            "angular_velocity": angular_velocity,
        }
        if poisson_ratio is not None:
            d["poisson_ratio"] = poisson_ratio
        if shear_modulus is not None:
            d["shear_modulus"] = shear_modulus
        if shear_factor is not None:
            d["shear_factor"] = shear_factor
        if rotary_inertia is not None:
            d["rotary_inertia"] = rotary_inertia
        if elastic is not None:
            d["elastic"] = elastic
        if elastic_rates is not None:
            d["elastic_rates"] = elastic_rates
        self._add_body(d)
        return BeamRef(self, name)

    # ----------------------------------------------------------------------------- joints
    def revolute(self, a: MarkerLike, b: MarkerLike, name: Optional[str] = None) -> str:
        """Pin joint: ``r_a - r_b = 0`` (2 rows).  Returns the joint name."""
        return self._add_joint({"kind": "revolute", "a": a, "b": b}, name)

    def point_on_line(self, point: MarkerLike, line: MarkerLike, name: Optional[str] = None) -> str:
        """Point-on-line (pin-in-slot): ``n_line . (r_point - r_line) = 0`` (1 row).

        ``line`` is a marker whose frame direction is the line direction, e.g.
        ``scene.ground.line((0, 0), angle=0)`` for the world X axis.
        """
        return self._add_joint({"kind": "point_on_line", "point": point, "line": line}, name)

    def prismatic(self, a: MarkerLike, b: MarkerLike, name: Optional[str] = None) -> str:
        """Prismatic joint: ``a`` slides along ``b``'s direction without relative rotation (2 rows)."""
        return self._add_joint({"kind": "prismatic", "a": a, "b": b}, name)

    def weld(self, a: MarkerLike, b: MarkerLike, name: Optional[str] = None) -> str:
        """Rigid connection: ``r_a = r_b`` and fixed relative angle (3 rows)."""
        return self._add_joint({"kind": "weld", "a": a, "b": b}, name)

    # ----------------------------------------------------------------------------- drivers
    def angle_driver(
        self, a: MarkerLike, motion: Any, b: Optional[MarkerLike] = None, name: Optional[str] = None
    ) -> str:
        """Rheonomic constraint ``phi_a - phi_b - f(t) = 0`` (``b`` defaults to the ground)."""
        d: Dict[str, Any] = {"kind": "angle", "a": a, "motion": motion}
        if b is not None:
            d["b"] = b
        return self._add_driver(d, name)

    def coordinate_driver(self, point: MarkerLike, axis: str, motion: Any, name: Optional[str] = None) -> str:
        """Rheonomic constraint ``r_point[axis] - f(t) = 0``, ``axis`` in ``{"x", "y"}``."""
        return self._add_driver({"kind": "coordinate", "point": point, "axis": axis, "motion": motion}, name)

    # ----------------------------------------------------------------------------- forces
    def point_force(self, point: MarkerLike, force: Sequence[float], name: Optional[str] = None) -> str:
        """Constant force ``force`` [N] (world frame) applied at marker ``point``."""
        return self._add_force({"kind": "point_force", "point": point, "force": force}, name)

    def torque(self, frame: MarkerLike, torque: float, name: Optional[str] = None) -> str:
        """Constant torque [N m] on the angle of marker ``frame`` (on a beam: ``theta + psi(x)``)."""
        return self._add_force({"kind": "torque", "frame": frame, "torque": torque}, name)

    def spring_damper(
        self,
        a: MarkerLike,
        b: MarkerLike,
        stiffness: float,
        damping: float = 0.0,
        rest_length: Optional[float] = None,
        name: Optional[str] = None,
    ) -> str:
        """Linear spring-damper between two markers.

        ``rest_length=None`` takes the distance between the markers at the initial guess
        (undeformed beams), so the spring starts unloaded.
        """
        if rest_length is None:
            ma, mb = self._marker(f"spring_damper {name or ''}".strip(), "a", a), self._marker(
                "spring_damper", "b", b
            )
            pa, pb = self._marker_position_guess(ma), self._marker_position_guess(mb)
            rest_length = math.hypot(pa[0] - pb[0], pa[1] - pb[1])
        d = {
            "kind": "spring_damper",
            "a": a,
            "b": b,
            "stiffness": stiffness,
            "damping": damping,
            "rest_length": rest_length,
        }
        return self._add_force(d, name)

    # ----------------------------------------------------------------------------- access
    @property
    def body_names(self) -> List[str]:
        """Body names in declaration (= coordinate) order."""
        return [b["name"] for b in self._bodies]

    def body(self, name: str) -> BodyRef:
        """Handle to body ``name`` (or the ground)."""
        if name == GROUND:
            return self.ground
        d = self._body(name)
        return BeamRef(self, name) if d["kind"] == "beam" else RigidBodyRef(self, name)

    def __getitem__(self, name: str) -> BodyRef:
        return self.body(name)

    @property
    def n_coords(self) -> int:
        """Number of generalized coordinates ``n``."""
        return sum(3 + (elastic_dofs(b["elements"], b["frame"]) if b["kind"] == "beam" else 0) for b in self._bodies)

    @property
    def n_constraints(self) -> int:
        """Number of constraint rows ``m`` (joints, then drivers)."""
        rows = {"revolute": 2, "point_on_line": 1, "prismatic": 2, "weld": 3}
        return sum(rows[j["kind"]] for j in self._joints) + len(self._drivers)

    def __repr__(self) -> str:
        return (
            f"Scene(bodies={self.body_names}, joints={len(self._joints)}, drivers={len(self._drivers)}, "
            f"forces={len(self._forces)}, gravity={self.gravity})"
        )

    # ----------------------------------------------------------------------------- dict I/O
    def to_dict(self) -> Dict[str, Any]:
        """The scene description (a fresh JSON-compatible dict, see ``docs/scene-format.md``)."""
        d: Dict[str, Any] = {}
        if self.gravity is not None:
            d["gravity"] = list(self.gravity)
        d["bodies"] = copy.deepcopy(self._bodies)
        d["joints"] = copy.deepcopy(self._joints)
        d["drivers"] = copy.deepcopy(self._drivers)
        d["forces"] = copy.deepcopy(self._forces)
        return d

    @classmethod
    def from_dict(cls, description: Dict[str, Any]) -> "Scene":
        """Rebuild (and validate) a scene from a description dict.

        Raises
        ------
        InvalidSceneError
            For any malformed entry; the message names it.
        """
        _keys("scene", description, ("gravity", "bodies", "joints", "drivers", "forces"), ("bodies",))
        s = cls(gravity=description.get("gravity"))
        bodies = description["bodies"]
        if not isinstance(bodies, list):
            _fail("scene", "bodies must be a list")
        for b in bodies:
            s._add_body(copy.deepcopy(b))
        for key, add in (("joints", s._add_joint), ("drivers", s._add_driver), ("forces", s._add_force)):
            items = description.get(key) or []
            if not isinstance(items, list):
                _fail("scene", f"{key} must be a list")
            for it in items:
                if not isinstance(it, dict):
                    _fail("scene", f"every entry of {key} must be a dict, got {it!r}")
                it = copy.deepcopy(it)
                name = it.pop("name", None)
                add(it, name)
        return s

    def validate(self) -> None:
        """Check the scene as a whole (at least one body). Items are validated when added."""
        if not self._bodies:
            _fail("scene", "needs at least one body")

    def build(self, **options: Any) -> "System":  # noqa: F821 - forward reference
        """Compile the scene into a Rust-backed :class:`ukflex.System`.

        Keyword arguments are passed to :class:`ukflex.System` (initial-state correction
        options: ``hold``, ``position_tol``, ``velocity_tol``, ``max_iterations``, ``correct``).
        """
        from .system import System

        return System(self, **options)

    # ----------------------------------------------------------------------------- internals
    def _body(self, name: str) -> Dict[str, Any]:
        for b in self._bodies:
            if b["name"] == name:
                return b
        raise InvalidSceneError(f"unknown body {name!r}; bodies are {self.body_names}")

    def _all_item_names(self) -> List[str]:
        return [it["name"] for it in self._joints + self._drivers + self._forces if "name" in it]

    def _add_body(self, d: Dict[str, Any]) -> None:
        if not isinstance(d, dict):
            _fail("body", f"expected a dict, got {d!r}")
        name = d.get("name")
        item = f"body {name!r}"
        _name(item, name)
        if name == GROUND:
            _fail(item, "the name 'ground' is reserved")
        if name in self.body_names:
            _fail(item, "duplicate body name")
        kind = d.get("kind")
        if kind == "rigid":
            out = self._rigid(item, d)
        elif kind == "beam":
            out = self._beam(item, d)
        else:
            _fail(item, f"unknown kind {kind!r}; expected 'rigid' or 'beam'")
        self._bodies.append(out)

    @staticmethod
    def _state(item: str, d: Dict[str, Any], out: Dict[str, Any]) -> None:
        out["position"] = _vec2(item, "position", d.get("position", (0.0, 0.0)))
        out["angle"] = _number(item, "angle", d.get("angle", 0.0))
        out["velocity"] = _vec2(item, "velocity", d.get("velocity", (0.0, 0.0)))
        out["angular_velocity"] = _number(item, "angular_velocity", d.get("angular_velocity", 0.0))

    def _rigid(self, item: str, d: Dict[str, Any]) -> Dict[str, Any]:
        _keys(
            item,
            d,
            ("name", "kind", "mass", "inertia", "com", "position", "angle", "velocity", "angular_velocity"),
            ("mass", "inertia"),
        )
        out: Dict[str, Any] = {"name": d["name"], "kind": "rigid"}
        out["mass"] = _positive(item, "mass", d["mass"])
        out["inertia"] = _positive(item, "inertia", d["inertia"])
        out["com"] = _vec2(item, "com", d.get("com", (0.0, 0.0)))
        self._state(item, d, out)
        return out

    def _beam(self, item: str, d: Dict[str, Any]) -> Dict[str, Any]:
        _keys(
            item,
            d,
            (
                "name", "kind", "length", "elements", "theory", "density", "youngs_modulus",
                "poisson_ratio", "shear_modulus", "shear_factor", "section", "frame",
                "rotary_inertia", "damping", "position", "angle", "velocity", "angular_velocity",
                "elastic", "elastic_rates",
            ),
            ("length", "theory", "density", "youngs_modulus", "section", "frame"),
        )
        out: Dict[str, Any] = {"name": d["name"], "kind": "beam"}
        out["length"] = _positive(item, "length", d["length"])
        elements = d.get("elements", 1)
        if isinstance(elements, bool) or not isinstance(elements, int) and not _is_int_like(elements):
            _fail(item, f"elements must be an integer >= 1, got {elements!r}")
        elements = int(elements)
        if elements < 1:
            _fail(item, f"elements must be an integer >= 1, got {elements}")
        out["elements"] = elements
        theory = d["theory"]
        if theory not in THEORIES:
            _fail(item, f"unknown theory {theory!r}; expected one of {THEORIES}")
        out["theory"] = theory
        out["density"] = _positive(item, "density", d["density"])
        out["youngs_modulus"] = _positive(item, "youngs_modulus", d["youngs_modulus"])
        has_nu = d.get("poisson_ratio") is not None
        has_g = d.get("shear_modulus") is not None
        if has_nu and has_g:
            _fail(item, "give either poisson_ratio or shear_modulus, not both")
        if has_nu:
            nu = _number(item, "poisson_ratio", d["poisson_ratio"])
            if not -1.0 < nu < 0.5:
                _fail(item, f"poisson_ratio must lie in (-1, 0.5), got {nu!r}")
            out["poisson_ratio"] = nu
        if has_g:
            out["shear_modulus"] = _positive(item, "shear_modulus", d["shear_modulus"])
        if d.get("shear_factor") is not None:
            out["shear_factor"] = _positive(item, "shear_factor", d["shear_factor"])
        if theory == "timoshenko":
            if not (has_nu or has_g):
                _fail(item, "a Timoshenko beam needs poisson_ratio or shear_modulus")
            if "shear_factor" not in out:
                _fail(item, "a Timoshenko beam needs shear_factor")
        out["section"] = _section_dict(item, d["section"])
        frame = d["frame"]
        if frame not in FRAMES:
            _fail(item, f"unknown frame {frame!r}; expected one of {FRAMES}")
        out["frame"] = frame
        if d.get("rotary_inertia") is not None:
            if not isinstance(d["rotary_inertia"], bool):
                _fail(item, f"rotary_inertia must be true or false, got {d['rotary_inertia']!r}")
            out["rotary_inertia"] = d["rotary_inertia"]
        out["damping"] = _non_negative(item, "damping", d.get("damping", 0.0))
        self._state(item, d, out)
        n_f = elastic_dofs(elements, frame)
        for key in ("elastic", "elastic_rates"):
            if d.get(key) is not None:
                out[key] = _floats(item, key, d[key], n_f)
        return out

    def _marker(self, item: str, field: str, m: Any) -> Dict[str, Any]:
        d = m.to_dict() if isinstance(m, Marker) else m
        where = f"{item} {field}"
        if isinstance(m, BodyRef):
            _fail(where, f"expected a marker (e.g. {m.name}.point(x, y) or .at(xi)), got the body handle {m!r}")
        _keys(where, d, ("body", "point", "xi", "angle"), ("body",))
        body = d["body"]
        if body != GROUND and body not in self.body_names:
            _fail(where, f"unknown body {body!r}; bodies are {['ground'] + self.body_names}")
        kind = "ground" if body == GROUND else self._body(body)["kind"]
        out: Dict[str, Any] = {"body": body}
        if kind == "beam":
            if d.get("point") is not None:
                _fail(where, f"a marker on beam {body!r} is given by xi in [0, 1], not by a point")
            if d.get("xi") is None:
                _fail(where, f"a marker on beam {body!r} needs xi in [0, 1]")
            xi = _number(where, "xi", d["xi"])
            if not 0.0 <= xi <= 1.0:
                _fail(where, f"xi must lie in [0, 1], got {xi!r}")
            out["xi"] = xi
        else:
            if d.get("xi") is not None:
                _fail(where, f"a marker on {kind} body {body!r} is given by a point, not by xi")
            out["point"] = _vec2(where, "point", d.get("point", (0.0, 0.0)))
        out["angle"] = _number(where, "angle", d.get("angle", 0.0))
        return out

    def _item_name(self, kind: str, name: Optional[str], index: int) -> Tuple[str, Optional[str]]:
        if name is None:
            return f"{kind} #{index}", None
        _name(f"{kind} #{index}", name)
        if name in self._all_item_names():
            _fail(f"{kind} {name!r}", "duplicate name (joint, driver and force names must be unique)")
        return f"{kind} {name!r}", name

    def _add_joint(self, d: Dict[str, Any], name: Optional[str] = None) -> str:
        kind = d.get("kind")
        item, name = self._item_name(f"joint {kind}", name, len(self._joints))
        fields = {"revolute": ("a", "b"), "point_on_line": ("point", "line"), "prismatic": ("a", "b"), "weld": ("a", "b")}
        if kind not in fields:
            _fail(item, f"unknown joint kind {kind!r}; expected one of {JOINT_KINDS}")
        _keys(item, d, ("kind",) + fields[kind], fields[kind])
        out: Dict[str, Any] = {"kind": kind}
        if name is not None:
            out["name"] = name
        for f in fields[kind]:
            out[f] = self._marker(item, f, d[f])
        if all(out[f]["body"] == out[fields[kind][0]]["body"] for f in fields[kind]):
            _fail(item, f"both markers are on the same body {out[fields[kind][0]]['body']!r}")
        self._joints.append(out)
        return name if name is not None else item

    def _add_driver(self, d: Dict[str, Any], name: Optional[str] = None) -> str:
        kind = d.get("kind")
        item, name = self._item_name(f"driver {kind}", name, len(self._drivers))
        out: Dict[str, Any] = {"kind": kind}
        if name is not None:
            out["name"] = name
        if kind == "angle":
            _keys(item, d, ("kind", "a", "b", "motion"), ("a", "motion"))
            out["a"] = self._marker(item, "a", d["a"])
            if d.get("b") is not None:
                out["b"] = self._marker(item, "b", d["b"])
                if out["b"]["body"] == out["a"]["body"]:
                    _fail(item, f"both markers are on the same body {out['a']['body']!r}")
            elif out["a"]["body"] == GROUND:
                _fail(item, "marker a is on the ground (the driver would constrain nothing)")
        elif kind == "coordinate":
            _keys(item, d, ("kind", "point", "axis", "motion"), ("point", "axis", "motion"))
            out["point"] = self._marker(item, "point", d["point"])
            if out["point"]["body"] == GROUND:
                _fail(item, "the point is on the ground (the driver would constrain nothing)")
            if d["axis"] not in ("x", "y"):
                _fail(item, f"axis must be 'x' or 'y', got {d['axis']!r}")
            out["axis"] = d["axis"]
        else:
            _fail(item, f"unknown driver kind {kind!r}; expected one of {DRIVER_KINDS}")
        out["motion"] = _motion_dict(item, d["motion"])
        self._drivers.append(out)
        return name if name is not None else item

    def _add_force(self, d: Dict[str, Any], name: Optional[str] = None) -> str:
        kind = d.get("kind")
        item, name = self._item_name(f"force {kind}", name, len(self._forces))
        out: Dict[str, Any] = {"kind": kind}
        if name is not None:
            out["name"] = name
        if kind == "point_force":
            _keys(item, d, ("kind", "point", "force"), ("point", "force"))
            out["point"] = self._marker(item, "point", d["point"])
            out["force"] = _vec2(item, "force", d["force"])
        elif kind == "torque":
            _keys(item, d, ("kind", "frame", "torque"), ("frame", "torque"))
            out["frame"] = self._marker(item, "frame", d["frame"])
            out["torque"] = _number(item, "torque", d["torque"])
        elif kind == "spring_damper":
            _keys(item, d, ("kind", "a", "b", "stiffness", "damping", "rest_length"), ("a", "b", "stiffness", "rest_length"))
            out["a"] = self._marker(item, "a", d["a"])
            out["b"] = self._marker(item, "b", d["b"])
            out["stiffness"] = _non_negative(item, "stiffness", d["stiffness"])
            out["damping"] = _non_negative(item, "damping", d.get("damping", 0.0))
            out["rest_length"] = _non_negative(item, "rest_length", d["rest_length"])
        else:
            _fail(item, f"unknown force kind {kind!r}; expected one of {FORCE_KINDS}")
        self._forces.append(out)
        return name if name is not None else item

    def _marker_position_guess(self, m: Dict[str, Any]) -> Vec2:
        """World position of a marker at the initial guess (beams taken undeformed)."""
        if m["body"] == GROUND:
            return (m["point"][0], m["point"][1])
        b = self._body(m["body"])
        th = b["angle"]
        c, s = math.cos(th), math.sin(th)
        if b["kind"] == "beam":
            px, py = m["xi"] * b["length"], 0.0
        else:
            px, py = m["point"]
        return (b["position"][0] + c * px - s * py, b["position"][1] + s * px + c * py)


def _is_int_like(value: Any) -> bool:
    try:
        import numpy as np

        return isinstance(value, np.integer)
    except ImportError:  # pragma: no cover
        return False
