"""Scene description in plain Python.

A :class:`Scene` collects bodies, joints, drivers, forces and the initial-state guess and turns
them into the JSON-compatible dict documented in ``docs/scene-format.md`` (:meth:`Scene.to_dict`),
the contract shared by the Rust core and the NumPy reference.  :meth:`Scene.build` compiles it into
a Rust-backed :class:`ukflex.System`.

Every builder call validates its input at once and raises :class:`ukflex.InvalidSceneError`
naming the offending item.  The rules are the Rust core's (each item goes through
``ukflex._core.SceneChecker``, the code that builds the model): Python only coerces types and
adds context.

Example
-------
>>> from ukflex import Scene, Circular, ConstantSpeed
>>> s = Scene(gravity=(0.0, -9.81))
>>> crank = s.rigid_body("crank", mass=0.04, inertia=8e-5, com=(0.0762, 0.0))
>>> s.revolute(s.ground.point(0, 0), crank.point(0, 0))
'revolute0'
>>> s.angle_driver(crank.frame(), ConstantSpeed(124.8))
'angle_driver0'
>>> system = s.build()
>>> system.coordinate_names, system.n_dof
(['crank.x', 'crank.y', 'crank.theta'], 0)
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from .description import Checker, normalize
from ..arguments import real, reals
from ..errors import InvalidArgumentError, InvalidSceneError, core
from .system import System

__all__ = [
    "Scene",
    "Marker",
    "BodyRef",
    "RigidBodyRef",
    "BeamRef",
    "PointMassRef",
    "FlexibleBodyRef",
    "GroundRef",
    "Circular",
    "Rectangular",
    "CustomSection",
    "ConstantSpeed",
    "Polynomial",
    "Harmonic",
    "Expression",
    "Spline",
    "elastic_dofs",
]

GROUND = "ground"

Vec2 = Tuple[float, float]


def elastic_dofs(elements: int, frame: str) -> int:
    """Number of elastic coordinates ``n_f`` of a beam (the core's rule: each of the
    ``elements + 1`` nodes carries ``(u, v, psi)``; both reference conditions remove three)."""
    return int(core.beam_elastic_dofs(int(elements), frame))


# --------------------------------------------------------------------------------------------
# sections and motions (value objects serialising to the description's sub-dicts)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Circular:
    """Solid circular section of diameter ``diameter`` [m]."""

    diameter: float

    def to_dict(self) -> Dict[str, Any]:
        return {"shape": "circular", "diameter": real("diameter", self.diameter, finite=False)}


@dataclass(frozen=True)
class Rectangular:
    """Rectangular section; ``height`` lies in the bending plane (``I = width height^3 / 12``)."""

    width: float
    height: float

    def to_dict(self) -> Dict[str, Any]:
        return {"shape": "rectangular", "width": real("width", self.width, finite=False), "height": real("height", self.height, finite=False)}


@dataclass(frozen=True)
class CustomSection:
    """Section given by its area ``area`` [m^2] and second moment ``second_moment`` [m^4]."""

    area: float
    second_moment: float

    def to_dict(self) -> Dict[str, Any]:
        return {"shape": "custom", "area": real("area", self.area, finite=False), "second_moment": real("second_moment", self.second_moment, finite=False)}


@dataclass(frozen=True)
class ConstantSpeed:
    """Motion ``f(t) = initial + speed * t``."""

    speed: float
    initial: float = 0.0

    def to_dict(self) -> Dict[str, Any]:
        return {"kind": "constant_speed", "initial": real("initial", self.initial, finite=False), "speed": real("speed", self.speed, finite=False)}


@dataclass(frozen=True)
class Polynomial:
    """Motion ``f(t) = sum_k coefficients[k] * t**k``."""

    coefficients: Sequence[float]

    def to_dict(self) -> Dict[str, Any]:
        return {"kind": "polynomial", "coefficients": [real("coefficients", c, finite=False) for c in self.coefficients]}


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
            "offset": real("offset", self.offset, finite=False),
            "amplitude": real("amplitude", self.amplitude, finite=False),
            "frequency": real("frequency", self.frequency, finite=False),
            "phase": real("phase", self.phase, finite=False),
        }


@dataclass(frozen=True)
class Expression:
    """Motion ``f(t)`` written as an expression of ``t``, e.g. ``"0.1 * sin(2*pi*t) + t^2"``.

    Evaluated in Rust, with ``f'`` and ``f''`` by symbolic differentiation (exact). Operators
    ``+ - * / ^`` (``**`` too; ``^`` binds tighter than a unary minus), numbers, ``t``, ``pi``,
    ``e``, functions ``sin cos tan exp log sqrt abs tanh sinh cosh atan sign``. A string given
    as a driver's ``motion`` means the same. Parse errors: :class:`ukflex.ExpressionError`
    (``.position``: the 0-based character index).
    """

    expression: str

    def to_dict(self) -> Dict[str, Any]:
        return {"kind": "expression", "expression": str(self.expression)}


@dataclass(frozen=True)
class Spline:
    """Motion from tabulated data: the C2 cubic spline through ``(times, values)``, natural
    (``f'' = 0`` at both ends) unless ``slopes = (f'(t_0), f'(t_n))`` clamps it. Outside the
    table the end pieces continue."""

    times: Sequence[float]
    values: Sequence[float]
    slopes: Optional[Sequence[float]] = None

    def to_dict(self) -> Dict[str, Any]:
        d: Dict[str, Any] = {"kind": "spline", "times": reals("times", self.times, finite=False), "values": reals("values", self.values, finite=False)}
        if self.slopes is not None:
            d["slopes"] = reals("slopes", self.slopes, finite=False)
        return d


@dataclass(frozen=True)
class LoadTable:
    """A load's value tabulated against one state quantity ``of`` (``"t"``, a coordinate such
    as ``"crank.theta"``, a rate ``"d:crank.theta"``, a motor's ``"w"``): the natural cubic
    spline through ``(x, y)``, held at its end values outside ``[x_0, x_last]``; ``period``
    wraps ``of`` into ``[x_0, x_0 + period)`` (a gas pressure against the crank angle over a
    cycle). docs/loads.md."""

    of: str
    x: Sequence[float]
    y: Sequence[float]
    period: Optional[float] = None

    def to_dict(self) -> Dict[str, Any]:
        d: Dict[str, Any] = {"of": str(self.of), "x": reals("x", self.x, finite=False), "y": reals("y", self.y, finite=False)}
        if self.period is not None:
            d["period"] = self.period
        return d


def dc_motor_torque(k: float, resistance: float, voltage: Any) -> str:
    """The torque of a DC motor (armature inductance neglected), ``k (V - k w) / R``, as a
    motor's expression: ``k`` the torque (= back-EMF) constant [N m / A], ``resistance`` [Ohm],
    ``voltage`` a number or an expression of ``t`` and state quantities [V]."""
    return f"({float(k)!r}) * (({voltage}) - ({float(k)!r}) * w) / ({float(resistance)!r})"


def _motion(motion: Any) -> Any:
    """A string motion is an :class:`Expression`."""
    return Expression(motion) if isinstance(motion, str) else motion


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
            d["point"] = [real("point", self.point[0], finite=False), real("point", self.point[1], finite=False)]
        if self.xi is not None:
            d["xi"] = real("xi", self.xi, finite=False)
        d["angle"] = real("angle", self.angle, finite=False)
        return d


def _point_args(x: Any, y: Any) -> Vec2:
    if y is None:
        try:
            px, py = x
        except (TypeError, ValueError):
            raise InvalidArgumentError("x", f"expected a point (x, y) or two numbers, got {x!r}") from None
    else:
        px, py = x, y
    return (real("x", px, finite=False), real("y", py, finite=False))


class BodyRef:
    """Handle to a body of a :class:`Scene` (returned by the builder methods)."""

    kind = ""
    _is_body_handle = True

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
        """A copy of this body's entry in the scene description (defaults filled in)."""
        return copy.deepcopy(self._scene._body(self.name))


class _PointBody(BodyRef):
    """Rigid body or ground: markers are points in the body frame."""

    def point(self, x: Any, y: Any = None, angle: float = 0.0) -> Marker:
        """Marker at body-frame point ``(x, y)`` (also accepts ``point((x, y))``)."""
        return Marker(self.name, point=_point_args(x, y), angle=real("angle", angle, finite=False))

    def frame(self, angle: float = 0.0) -> Marker:
        """Marker at the body-frame origin; its world angle is ``theta + angle``."""
        return Marker(self.name, point=(0.0, 0.0), angle=real("angle", angle, finite=False))

    def line(self, origin: Any = (0.0, 0.0), angle: float = 0.0) -> Marker:
        """Marker describing a line through ``origin`` with direction ``(cos angle, sin angle)``
        in the body frame (for :meth:`Scene.point_on_line` and :meth:`Scene.prismatic`)."""
        return Marker(self.name, point=_point_args(origin, None), angle=real("angle", angle, finite=False))


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


class PointMassRef(BodyRef):
    """Handle to a point mass: ``point()`` is the marker on the particle (no orientation: joints
    that need one -- weld, prismatic, angle driver, torque -- refuse it)."""

    kind = "point_mass"

    def point(self, angle: float = 0.0) -> Marker:
        """The marker on the particle; ``angle`` fixes the direction of a line through it."""
        return Marker(self.name, angle=real("angle", angle, finite=False))

    def line(self, angle: float = 0.0) -> Marker:
        """The line through the particle with the constant direction ``angle``."""
        return self.point(angle)


class BeamRef(BodyRef):
    """Handle to a beam (FFRF or ANCF): ``at(xi)`` makes a marker on the beam axis."""

    kind = "beam"

    def at(self, xi: float, angle: float = 0.0) -> Marker:
        """Marker at the axis point ``x = xi * length``, ``xi`` in ``[0, 1]``.

        Its world angle is ``theta + angle + psi(x)`` (the cross-section rotation); on an ANCF
        beam ``angle`` plus the direction of the tangent ``r'(x)``, measured continuously from the
        beam's initial ``angle`` (valid while the tangent stays within +-pi of it).
        """
        return Marker(self.name, xi=real("xi", xi, finite=False), angle=real("angle", angle, finite=False))

    def line(self, xi: float = 0.0, angle: float = 0.0) -> Marker:
        """Same as :meth:`at`: the line through the axis point with direction ``angle``."""
        return self.at(xi, angle)

    @property
    def n_f(self) -> int:
        """Number of elastic coordinates of this beam."""
        return int(self._scene._info(self.name)["n_f"])


class FlexibleBodyRef(BodyRef):
    """Handle to a flexible body (:meth:`Scene.flexible_body`): ``marker(name)`` is one of its
    interface points."""

    kind = "flexible"

    def marker(self, name: str, angle: float = 0.0) -> Marker:
        """Marker at the interface point ``name``; its world angle is ``theta + angle + psi``
        (``psi`` its elastic rotation, if the body gives one)."""
        for m in self._scene._body(self.name)["markers"]:
            if m["name"] == name:
                return Marker(self.name, point=(float(m["point"][0]), float(m["point"][1])), angle=real("angle", angle, finite=False))
        names = [m["name"] for m in self._scene._body(self.name)["markers"]]
        raise InvalidSceneError(f"flexible body {self.name!r} has no interface point {name!r}; its points are {names}")

    @property
    def marker_names(self) -> List[str]:
        return [m["name"] for m in self._scene._body(self.name)["markers"]]

    @property
    def n_f(self) -> int:
        """Number of elastic coordinates."""
        return int(self._scene._info(self.name)["n_f"])


MarkerLike = Union[Marker, Dict[str, Any]]
_REFS = {"rigid": RigidBodyRef, "beam": BeamRef, "cable": BeamRef, "point_mass": PointMassRef, "flexible": FlexibleBodyRef}


# --------------------------------------------------------------------------------------------
# the scene
# --------------------------------------------------------------------------------------------


def _given(**fields: Any) -> Dict[str, Any]:
    """The fields that were given (``None`` means: the core's default)."""
    return {k: v for k, v in fields.items() if v is not None}


class Scene:
    """A planar multibody scene: bodies, joints, drivers, forces and the initial-state guess.

    Parameters
    ----------
    gravity : (2,) sequence of float or None
        Gravitational acceleration in the world frame [m/s^2], e.g. ``(0, -9.81)``.  ``None``
        (default) means no gravity term at all.

    Notes
    -----
    Coordinates are ordered by body declaration order, each body contributing its coordinates
    (rigid ``[x, y, theta]``, beam ``[x, y, theta, q_f...]``, point mass ``[x, y]``); constraint
    rows are the joints in declaration order followed by the drivers.  See
    ``docs/scene-format.md``.  A scene pickles and deep-copies through its description.
    """

    def __init__(self, gravity: Optional[Sequence[float]] = None):
        self._checker = Checker(gravity)
        self.ground = GroundRef(self)
        self._callables: Dict[str, Any] = {}

    @property
    def callables(self) -> Dict[str, Any]:
        """The Python callables of the loads, by the name the description gives them
        (``{"callable": name, "inputs": [...]}``); :meth:`build` hands them to the System.
        They are not part of :meth:`to_dict` (a description is plain data)."""
        return dict(getattr(self, "_callables", {}))

    def _value(self, value: Any, inputs: Sequence[str]) -> Any:
        """A load value as the description holds it: a Python callable becomes a reference."""
        if callable(value) and not isinstance(value, (str, LoadTable)):
            if not hasattr(self, "_callables"):
                self._callables = {}
            name = f"callable{len(self._callables)}"
            self._callables[name] = value
            return {"callable": name, "inputs": [str(i) for i in inputs]}
        return value

    @staticmethod
    def _check_inputs(inputs: Sequence[str], *values: Any) -> None:
        if inputs and not any(callable(v) and not isinstance(v, (str, LoadTable)) for v in values):
            raise InvalidArgumentError("inputs", "name the state quantities of a Python callable only (an expression or a table names its own)")

    @property
    def gravity(self) -> Optional[List[float]]:
        """The gravity vector, or ``None``."""
        g = self._checker.gravity
        return None if g is None else list(g)

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
            Moment of inertia about the centre of mass [kg m^2], positive (a body without one
            is a :meth:`point_mass`).
        com : (2,) sequence
            Centre of mass in the body frame [m].
        position, angle, velocity, angular_velocity
            Initial guess of the body frame's position [m], angle [rad] and their rates.
            :meth:`build` corrects it onto the constraints.

        Returns
        -------
        RigidBodyRef
        """
        return self._add_body(dict(name=name, kind="rigid", mass=mass, inertia=inertia, com=com, position=position,
                                   angle=angle, velocity=velocity, angular_velocity=angular_velocity))

    def point_mass(
        self,
        name: str,
        *,
        mass: float,
        position: Sequence[float] = (0.0, 0.0),
        velocity: Sequence[float] = (0.0, 0.0),
    ) -> PointMassRef:
        """Add a point mass (particle): coordinates ``[x, y]``, no orientation.

        Parameters
        ----------
        name : str
            Unique body name.
        mass : float
            Mass [kg], positive.
        position, velocity : (2,) sequence
            Initial guess [m], [m/s].

        Returns
        -------
        PointMassRef
        """
        return self._add_body(dict(name=name, kind="point_mass", mass=mass, position=position, velocity=velocity))

    def beam(
        self,
        name: str,
        *,
        length: float,
        section: Any,
        density: float,
        youngs_modulus: float,
        elements: int = 1,
        theory: Optional[str] = None,
        strain: Optional[str] = None,
        poisson_ratio: Optional[float] = None,
        shear_modulus: Optional[float] = None,
        shear_factor: Optional[float] = None,
        frame: Optional[str] = None,
        rotary_inertia: Optional[bool] = None,
        damping: float = 0.0,
        position: Sequence[float] = (0.0, 0.0),
        angle: float = 0.0,
        velocity: Sequence[float] = (0.0, 0.0),
        angular_velocity: float = 0.0,
        elastic: Optional[Sequence[float]] = None,
        elastic_rates: Optional[Sequence[float]] = None,
    ) -> BeamRef:
        """Add a flexible beam of ``elements`` finite elements in the floating frame of reference
        (FFRF: small elastic coordinates on a moving frame, the paper's model).  For large
        deformation, the geometrically exact cable is :meth:`cable`.

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
            Number of finite elements ``N >= 1``; the beam has ``n_f = 3 N`` elastic
            coordinates.
        theory : {"timoshenko", "euler-bernoulli"}, optional
            Default (the core's): ``"timoshenko"``.
        strain : {"nonlinear", "linear"}, optional
            Strain measure of an FFRF beam's elastic forces.  Default (the core's):
            ``"nonlinear"``, the second-order axial strain ``u' + v'^2 / 2`` averaged over each
            element (a constant axial force per element, free of membrane locking): the axial
            force couples with bending (geometric stiffening), which matters as soon as it is a
            noticeable fraction of the Euler load.  ``"linear"`` is the paper's linear FFRF
            model.
        poisson_ratio, shear_modulus : float, optional
            Exactly one is needed for Timoshenko (``G = E / (2 (1 + nu))``); optional otherwise.
        shear_factor : float, optional
            Shear correction factor ``k``, required for Timoshenko.
        frame : {"pinned-pinned", "clamped"}, optional
            Reference conditions of the floating frame: which nodal coordinates the frame
            takes out (it is not a boundary condition; clamp a beam with a weld).  Default (the
            core's): ``"pinned-pinned"``.  The words are those of every FFRF body
            (``ukflex.fe.FRAMES``); a beam's frame is on its end nodes, so ``"mean-axis"`` is
            refused.
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
        d = dict(name=name, kind="beam", length=length, elements=elements, density=density,
                 youngs_modulus=youngs_modulus, section=section, damping=damping, position=position,
                 angle=angle, velocity=velocity, angular_velocity=angular_velocity)
        d.update(_given(theory=theory, frame=frame, strain=strain, poisson_ratio=poisson_ratio, shear_modulus=shear_modulus,
                        shear_factor=shear_factor, rotary_inertia=rotary_inertia, elastic=elastic, elastic_rates=elastic_rates))
        return self._add_body(d)

    def cable(
        self,
        name: str,
        *,
        length: float,
        section: Any,
        density: float,
        youngs_modulus: float,
        elements: int = 1,
        damping: float = 0.0,
        position: Sequence[float] = (0.0, 0.0),
        angle: float = 0.0,
        velocity: Sequence[float] = (0.0, 0.0),
        angular_velocity: float = 0.0,
    ) -> BeamRef:
        """Add a geometrically exact planar cable of ``elements`` ANCF elements: absolute nodal
        positions and slopes (``4 (N + 1)`` coordinates), axial strain ``|r'| - 1`` and curvature
        ``r' x r'' / |r'|^2``, Euler-Bernoulli, constant mass matrix, no floating frame
        (docs/scene-format.md).  Right for large deformation and fast rotation, where an FFRF
        :meth:`beam`'s small elastic coordinates do not hold.

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
            Number of elements ``N >= 1``.
        damping : float
            Stiffness-proportional damping coefficient ``beta`` [s].
        position, angle, velocity, angular_velocity
            The straight undeformed cable from ``position`` (its ``xi = 0`` end) along
            ``angle``, in the rigid motion of ``velocity`` (of that end) and
            ``angular_velocity``.

        Returns
        -------
        BeamRef
            Markers at ``xi`` along its axis (``.at(xi)``), as on a beam.
        """
        return self._add_body(dict(name=name, kind="cable", length=length, elements=elements, density=density,
                                   youngs_modulus=youngs_modulus, section=section, damping=damping, position=position,
                                   angle=angle, velocity=velocity, angular_velocity=angular_velocity))

    def flexible_body(
        self,
        name: str,
        data: Any,
        *,
        strain: Optional[str] = None,
        position: Sequence[float] = (0.0, 0.0),
        angle: float = 0.0,
        velocity: Sequence[float] = (0.0, 0.0),
        angular_velocity: float = 0.0,
        elastic: Optional[Sequence[float]] = None,
        elastic_rates: Optional[Sequence[float]] = None,
    ) -> FlexibleBodyRef:
        """Add a general flexible body on a floating frame (FFRF) given by its invariants.

        Parameters
        ----------
        name : str
            Unique body name.
        data : ukflex.FlexibleData or dict
            Mass, inertia, centre of mass, shape integrals, ``m_ff``, ``k_ff`` (optional ``d_ff``,
            ``k3``/``k4``) and interface points (docs/flexible-bodies.md).  The builders of
            :mod:`ukflex.fe` compute it from finite-element data.
        strain : {"linear", "nonlinear"}, optional
            Default (the core's) ``"linear"``; ``"nonlinear"`` adds the strain energy of the
            stiffness tensors ``k3`` (and ``k4``) of ``data``.
        position, angle, velocity, angular_velocity
            Initial guess of the floating frame.
        elastic, elastic_rates : (n_f,) sequence, optional
            Initial elastic coordinates and rates (default zeros).

        Returns
        -------
        FlexibleBodyRef
        """
        fields = data.to_dict() if hasattr(data, "to_dict") else dict(data)
        d = dict(name=name, kind="flexible", **fields)
        d.update(position=position, angle=angle, velocity=velocity, angular_velocity=angular_velocity)
        d.update(_given(strain=strain, elastic=elastic, elastic_rates=elastic_rates))
        return self._add_body(d)  # type: ignore[return-value]

    # ----------------------------------------------------------------------------- joints
    def revolute(self, a: MarkerLike, b: MarkerLike, name: Optional[str] = None) -> str:
        """Pin joint: ``r_a - r_b = 0`` (2 rows).  Returns the joint name."""
        return self._add("joints", dict(kind="revolute", a=a, b=b), name)

    def point_on_line(self, point: MarkerLike, line: MarkerLike, name: Optional[str] = None) -> str:
        """Point-on-line (pin-in-slot): ``n_line . (r_point - r_line) = 0`` (1 row).

        ``line`` is a marker whose frame direction is the line direction, e.g.
        ``scene.ground.line((0, 0), angle=0)`` for the world X axis.
        """
        return self._add("joints", dict(kind="point_on_line", point=point, line=line), name)

    def prismatic(self, a: MarkerLike, b: MarkerLike, name: Optional[str] = None) -> str:
        """Prismatic joint: ``a`` slides along ``b``'s direction without relative rotation (2 rows)."""
        return self._add("joints", dict(kind="prismatic", a=a, b=b), name)

    def weld(self, a: MarkerLike, b: MarkerLike, name: Optional[str] = None) -> str:
        """Rigid connection: ``r_a = r_b`` and fixed relative angle (3 rows)."""
        return self._add("joints", dict(kind="weld", a=a, b=b), name)

    def distance(self, a: MarkerLike, b: MarkerLike, length: Optional[float] = None, name: Optional[str] = None) -> str:
        """Massless rod: ``|r_a - r_b| = length`` (1 row); ``length=None`` takes the distance
        between the markers at the initial guess."""
        return self._add("joints", dict(kind="distance", a=a, b=b, **_given(length=length)), name)

    # ----------------------------------------------------------------------------- drivers
    def angle_driver(
        self, a: MarkerLike, motion: Any, b: Optional[MarkerLike] = None, name: Optional[str] = None
    ) -> str:
        """Rheonomic constraint ``phi_a - phi_b - f(t) = 0`` (``b`` defaults to the ground)."""
        return self._add("drivers", dict(kind="angle", a=a, motion=_motion(motion), **_given(b=b)), name)

    def coordinate_driver(self, point: MarkerLike, axis: str, motion: Any, name: Optional[str] = None) -> str:
        """Rheonomic constraint ``r_point[axis] - f(t) = 0``, ``axis`` in ``{"x", "y"}``."""
        return self._add("drivers", dict(kind="coordinate", point=point, axis=axis, motion=_motion(motion)), name)

    # ----------------------------------------------------------------------------- forces
    def point_force(self, point: MarkerLike, force: Sequence[float], name: Optional[str] = None) -> str:
        """Constant force ``force`` [N] (world frame) applied at marker ``point``."""
        return self._add("forces", dict(kind="point_force", point=point, force=force), name)

    def torque(self, frame: MarkerLike, torque: float, name: Optional[str] = None) -> str:
        """Constant torque [N m] on the angle of marker ``frame`` (on a beam: ``theta + psi(x)``)."""
        return self._add("forces", dict(kind="torque", frame=frame, torque=torque), name)

    def point_load(
        self, point: MarkerLike, fx: Any = 0.0, fy: Any = 0.0, name: Optional[str] = None, *, inputs: Sequence[str] = ()
    ) -> str:
        """Force at marker ``point`` whose world components are functions (docs/loads.md): each
        of ``fx``, ``fy`` a number, an expression of ``t`` and state quantities (``"-2e4 *
        sin(crank.theta) - 5 * d:slider.x"``), a :class:`LoadTable`, or a Python callable
        ``f(t, state) -> float`` with ``state`` the dict of the quantities named by ``inputs``.
        Expressions and tables are compiled in Rust; an unknown quantity is an
        :class:`ukflex.ExpressionError` (a table's or a callable's input: an
        :class:`ukflex.InvalidSceneError`)."""
        self._check_inputs(inputs, fx, fy)
        d = dict(kind="point_load", point=point, fx=self._value(fx, inputs), fy=self._value(fy, inputs))
        return self._add("forces", d, name)

    def torque_load(self, frame: MarkerLike, torque: Any, name: Optional[str] = None, *, inputs: Sequence[str] = ()) -> str:
        """Torque [N m] on the angle of marker ``frame`` that is a function (a number, an
        expression, a :class:`LoadTable` or a callable, as :meth:`point_load`)."""
        self._check_inputs(inputs, torque)
        return self._add("forces", dict(kind="torque_load", frame=frame, torque=self._value(torque, inputs)), name)

    def motor(
        self,
        a: MarkerLike,
        torque: Any,
        b: Optional[MarkerLike] = None,
        *,
        rotor_inertia: float = 0.0,
        name: Optional[str] = None,
        inputs: Sequence[str] = (),
    ) -> str:
        """Motor torque ``tau`` on the frame of ``a`` (the rotor), ``-tau`` on ``b`` (the
        stator; the ground when ``None``): ``torque`` a number, an expression or a
        :class:`LoadTable` that may read ``angle = phi_a - phi_b`` and ``w = omega_a -
        omega_b`` besides ``t`` and the state quantities (:func:`dc_motor_torque` writes a DC
        motor's), or a callable of ``inputs`` (as :meth:`point_load`). ``rotor_inertia`` [kg m^2] is added to the inertia of ``a``'s body (rigid)."""
        self._check_inputs(inputs, torque)
        d = dict(kind="motor", a=a, torque=self._value(torque, inputs), rotor_inertia=rotor_inertia, **_given(b=b))
        return self._add("forces", d, name)

    def rotational_spring_damper(
        self,
        a: MarkerLike,
        b: Optional[MarkerLike] = None,
        *,
        stiffness: float = 0.0,
        damping: float = 0.0,
        rest_angle: Optional[float] = None,
        name: Optional[str] = None,
    ) -> str:
        """Torque ``-k (angle - rest_angle) - c w`` between the frames of ``a`` and ``b`` (the
        ground when ``None``), ``angle = phi_a - phi_b``; ``rest_angle=None`` takes the angle at
        the initial guess. With ``stiffness=0`` the viscous friction of a hinge."""
        d = dict(kind="rotational_spring_damper", a=a, stiffness=stiffness, damping=damping, **_given(b=b, rest_angle=rest_angle))
        return self._add("forces", d, name)

    def joint_friction(
        self,
        joint: str,
        *,
        mu: float,
        radius: Optional[float] = None,
        length: Optional[float] = None,
        damping: float = 0.0,
        v_eps: Optional[float] = None,
        name: Optional[str] = None,
    ) -> str:
        """Regularized Coulomb and viscous friction in the revolute or prismatic joint named
        ``joint`` (added before), from its reaction: a revolute's torque
        ``-mu radius |F| sat(w / v_eps) - damping w`` (``radius``: the pin radius), a
        prismatic's force ``-mu N_eff sat(v / v_eps) - damping v`` along the slide axis
        (``N_eff = |N|``, or ``max(|N|, 2 |M| / length)`` with a slider ``length`` that
        carries the reaction moment ``M``). ``sat(x) = clamp(x, -1, 1)``; ``v_eps=None`` takes
        the core's default (docs/loads.md, "Joint friction"). The friction is closed with the
        reactions in every acceleration call."""
        d = dict(kind="joint_friction", joint=joint, mu=mu, damping=damping, **_given(radius=radius, length=length, v_eps=v_eps))
        return self._add("forces", d, name)

    def bushing(
        self,
        a: MarkerLike,
        b: MarkerLike,
        *,
        stiffness: Sequence[float],
        damping: Sequence[float] = (0.0, 0.0, 0.0),
        name: Optional[str] = None,
    ) -> str:
        """Linear stiffness and damping ``(x, y, angle)`` between two marker frames: the
        offset of ``a`` from ``b`` in ``b``'s frame and the relative angle, unloaded at the
        initial guess."""
        return self._add("forces", dict(kind="bushing", a=a, b=b, stiffness=stiffness, damping=damping), name)

    def revolute_clearance(
        self,
        journal: MarkerLike,
        bearing: MarkerLike,
        *,
        clearance: float,
        journal_radius: float,
        stiffness: float,
        restitution: float,
        impact_velocity: float,
        exponent: Optional[float] = None,
        law: Optional[str] = None,
        friction: Optional[float] = None,
        friction_velocities: Optional[Sequence[float]] = None,
        name: Optional[str] = None,
    ) -> str:
        """A revolute joint with clearance: the journal (marker ``journal``, radius
        ``journal_radius``) moves inside the bearing (marker ``bearing``, radius
        ``journal_radius + clearance``) with no constraint rows; in contact the normal force is
        ``K delta^exponent (1 + D delta')`` (``law``: ``"lankarani_nikravesh"``, ``D = 3 (1 -
        c_e^2) / (4 v_0)``, or ``"flores"``, ``D = 8 (1 - c_e) / (5 c_e v_0)``, ``c_e =
        restitution`` at the impact velocity ``v_0 = impact_velocity``) and the friction
        Ambrosio's modified Coulomb law with coefficient ``friction`` (none below
        ``friction_velocities[0]``, full above ``[1]``). ``None``: the core's defaults
        (``exponent`` 1.5, Lankarani-Nikravesh, no friction, ``(1e-4, 1e-3)`` m/s). Its contact
        is in ``res.sensors.clearance(name)`` (docs/loads.md)."""
        d = dict(kind="revolute_clearance", journal=journal, bearing=bearing, clearance=clearance,
                 journal_radius=journal_radius, stiffness=stiffness, restitution=restitution,
                 impact_velocity=impact_velocity,
                 **_given(exponent=exponent, law=law, friction=friction, friction_velocities=friction_velocities))
        return self._add("forces", d, name)

    def spring_damper(
        self,
        a: MarkerLike,
        b: MarkerLike,
        *,
        stiffness: Optional[float] = None,
        damping: float = 0.0,
        rest_length: Optional[float] = None,
        name: Optional[str] = None,
    ) -> str:
        """Linear spring-damper between two markers: ``spring_damper(a, b, stiffness=k,
        damping=c, rest_length=l0, name=...)``, everything after the markers by keyword.

        ``rest_length=None`` (the default) takes the distance between the markers at the
        initial guess (undeformed beams), so the spring starts unloaded; the description
        records the value.
        """
        if stiffness is None:
            raise TypeError("spring_damper() missing the keyword argument 'stiffness'")
        d = dict(kind="spring_damper", a=a, b=b, stiffness=stiffness, damping=damping, **_given(rest_length=rest_length))
        return self._add("forces", d, name)

    # ----------------------------------------------------------------------------- access
    @property
    def body_names(self) -> List[str]:
        return [b["name"] for b in self._checker.items["bodies"]]

    def body(self, name: str) -> BodyRef:
        """Handle of body ``name`` (``"ground"`` gives :attr:`ground`)."""
        if name == GROUND:
            return self.ground
        return _REFS[self._info(name)["kind"]](self, name)

    def __getitem__(self, name: str) -> BodyRef:
        return self.body(name)

    @property
    def n_coords(self) -> int:
        """Number of generalized coordinates ``n``."""
        return sum(int(i["n_coords"]) for i in self._checker.info["bodies"])

    @property
    def n_constraints(self) -> int:
        """Number of constraint rows ``m`` (joints, then drivers)."""
        return sum(int(i["rows"]) for s in ("joints", "drivers") for i in self._checker.info[s])

    def __repr__(self) -> str:
        c = self._checker.items
        return (
            f"Scene(bodies={self.body_names}, joints={len(c['joints'])}, drivers={len(c['drivers'])}, "
            f"forces={len(c['forces'])}, gravity={self.gravity})"
        )

    # ----------------------------------------------------------------------------- dict I/O
    def to_dict(self) -> Dict[str, Any]:
        """The scene description (a fresh JSON-compatible dict, see ``docs/scene-format.md``)."""
        return self._checker.to_dict()

    @classmethod
    def from_dict(cls, description: Dict[str, Any]) -> "Scene":
        """Rebuild (and validate) a scene from a description dict.

        Raises
        ------
        InvalidSceneError
            For any malformed entry; the message names it (``exc.entry = (section, index)``).
        """
        scene = cls.__new__(cls)
        scene._checker, _ = normalize(description)
        scene.ground = GroundRef(scene)
        return scene

    def __getstate__(self) -> Dict[str, Any]:
        return self.to_dict()

    def __setstate__(self, state: Dict[str, Any]) -> None:
        self._checker, _ = normalize(state)
        self.ground = GroundRef(self)

    def validate(self) -> None:
        """Check the scene as a whole (at least one body). Items are validated when added."""
        self._checker.finish()

    def build(self, **options: Any) -> System:
        """Compile the scene into a Rust-backed :class:`ukflex.System`.

        Keyword arguments are passed to :class:`ukflex.System` (initial-state correction
        options: ``hold``, ``position_tol``, ``velocity_tol``, ``max_iterations``, ``correct``).
        """
        return System(self, **options)

    # ----------------------------------------------------------------------------- internals
    def _index(self, name: str) -> int:
        names = self.body_names
        if name not in names:
            raise InvalidSceneError(f"unknown body {name!r}; bodies are {names}")
        return names.index(name)

    def _body(self, name: str) -> Dict[str, Any]:
        return self._checker.items["bodies"][self._index(name)]

    def _info(self, name: str) -> Dict[str, Any]:
        return self._checker.info["bodies"][self._index(name)]

    def _add_body(self, d: Dict[str, Any]) -> BodyRef:
        info = self._checker.add("bodies", d)
        return _REFS[info["kind"]](self, d["name"])

    def _add(self, section: str, d: Dict[str, Any], name: Optional[str]) -> str:
        if name is not None:
            d["name"] = name
        return str(self._checker.add(section, d)["name"])
