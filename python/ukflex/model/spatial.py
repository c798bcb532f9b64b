"""Spatial (3D) rigid multibody scenes: the builder and the spatial outputs.

Design of the API (issue 30): the dimension is explicit in the *type* of the builder,
:class:`SpatialScene`, and in the description it produces (``"dim": 3``). A planar
:class:`ukflex.Scene` and a spatial one never mix: their bodies, markers (a point and an angle
in 2D, a point and a frame in 3D), forces (a scalar torque in 2D, a vector in 3D) and gravity
(2 vs 3 components) differ in shape, so one class holding both would accept half of its
arguments only in one dimension. A separate class keeps every signature honest and lets a
planar scene build and run exactly as before. The rest of the API is shared: ``ukflex.System``
builds a ``SpatialScene`` (or its dict), ``ukflex.simulate`` runs it, the motions
(:class:`ukflex.ConstantSpeed`, :class:`ukflex.Polynomial`, :class:`ukflex.Harmonic`,
:class:`ukflex.Expression`, :class:`ukflex.Spline`) drive its joints. Python only builds the
description; the Rust core validates it (named :class:`ukflex.InvalidSceneError` messages).

Coordinates (docs/spatial-design.md): a ``rigid3`` body has ``[x, y, z, e0, e1, e2, e3]`` (its
centre of mass and the Euler parameters of its body frame, with one normalization constraint
row each), a ``point3`` body ``[x, y, z]``.

Example::

    s = ukflex.SpatialScene(gravity=(0, 0, -9.81))
    top = s.rigid_body("top", mass=1.0, inertia=np.diag([2.5e-3, 2.5e-3, 5e-3]),
                       position=(0, 0, 0.1), angular_velocity=(0, 0, 50))
    s.spherical(s.ground.marker((0, 0, 0)), top.marker((0, 0, -0.1)), name="pivot")
    sys = ukflex.System(s)
    res = ukflex.simulate(sys, 1.0, method="DOPRI5", rtol=1e-10)
    out = ukflex.spatial_outputs(sys, res)      # positions, rotations, reactions, energies
"""

from __future__ import annotations

import copy
import json
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from .. import _core
from ..arguments import real
from ..errors import InvalidArgumentError, InvalidSceneError

__all__ = ["SpatialScene", "SpatialMarker", "SpatialBodyRef", "SpatialFlexibleRef", "SpatialBeamRef", "CustomSection3", "outputs", "normalize_spatial", "NATIVE_METHODS_3D"]

#: Native methods that run a spatial scene (the others are refused by name, see docs/spatial.md).
NATIVE_METHODS_3D = ("DOPRI5", "RADAU5", "RADAU5M", "GENALPHA")


def _motion(motion: Any) -> Dict[str, Any]:
    """A motion's description: a motion object (``ukflex.ConstantSpeed``, ...) or an expression string."""
    return {"kind": "expression", "expression": motion} if isinstance(motion, str) else motion.to_dict()


def _vec(name: str, v: Any, n: int = 3) -> List[float]:
    a = np.asarray(v, dtype=float).reshape(-1)
    if a.size != n:
        raise InvalidSceneError(f"{name} must have {n} components, got {a.size}")
    return [float(x) for x in a]


@dataclass(frozen=True)
class SpatialMarker:
    """A frame on a body (or the ground): ``point`` in body coordinates (world for the ground;
    the user's body frame, not the centre of mass), ``z`` its z axis (normalized by the core; a
    zero or non-finite axis is an error) and ``x`` an optional hint for its x axis."""

    body: str
    point: Sequence[float] = (0.0, 0.0, 0.0)
    z: Optional[Sequence[float]] = None
    x: Optional[Sequence[float]] = None

    def to_dict(self) -> Dict[str, Any]:
        d: Dict[str, Any] = {"body": self.body, "point": _vec("marker point", self.point)}
        if self.z is not None:
            d["z"] = _vec("marker axis z", self.z)
        if self.x is not None:
            d["x"] = _vec("marker axis x", self.x)
        return d


@dataclass(frozen=True)
class SpatialBodyRef:
    """A handle on a body (or the ground) of a :class:`SpatialScene`."""

    name: str

    def marker(self, point: Sequence[float] = (0.0, 0.0, 0.0), z: Optional[Sequence[float]] = None,
               x: Optional[Sequence[float]] = None) -> SpatialMarker:
        return SpatialMarker(self.name, tuple(point), None if z is None else tuple(z), None if x is None else tuple(x))


@dataclass(frozen=True)
class SpatialFlexibleRef(SpatialBodyRef):
    """A handle on a ``flexible3`` body: its interfaces by name (their undeformed points)."""

    interfaces: Dict[str, Any] = None  # type: ignore[assignment]

    def interface(self, name: str, z: Optional[Sequence[float]] = None, x: Optional[Sequence[float]] = None) -> SpatialMarker:
        """The marker on the interface ``name`` (axes ``z``, ``x`` in the body frame)."""
        if name not in (self.interfaces or {}):
            raise InvalidSceneError(f"body '{self.name}' has no interface {name!r}; interfaces: {sorted(self.interfaces or {})}")
        return self.marker(self.interfaces[name], z, x)


@dataclass(frozen=True)
class CustomSection3:
    """Section of a 3D beam (:meth:`SpatialScene.beam`) given by its own data: axial stiffness
    ``ea`` [N], shear stiffnesses ``ga_y``, ``ga_z`` (``k G A``) [N], torsional stiffness ``gj`` and
    bending stiffnesses ``ei_y`` (about the section's ``y``: bending in the ``x z`` plane),
    ``ei_z`` [N m^2], ``mass_per_length`` [kg/m] and ``rotary_inertia`` [kg m], the rotary
    inertia per length about the section axes ``x, y, z``. The planar :class:`ukflex.CustomSection`
    stays what it is (area and second moment)."""

    ea: float
    ga_y: float
    ga_z: float
    gj: float
    ei_y: float
    ei_z: float
    mass_per_length: float
    rotary_inertia: Sequence[float]

    def to_dict(self) -> Dict[str, Any]:
        d: Dict[str, Any] = {"shape": "custom3"}
        for k in ("ea", "ga_y", "ga_z", "gj", "ei_y", "ei_z", "mass_per_length"):
            d[k] = float(getattr(self, k))
        d["rotary_inertia"] = _vec("rotary_inertia", self.rotary_inertia)
        return d


@dataclass(frozen=True)
class SpatialBeamRef:
    """A handle on a 3D beam (:meth:`SpatialScene.beam`): its node bodies ``name[i]`` (``i = 0``
    at ``start``, ``elements`` at ``end``), elements ``name[e j]`` and ``length``."""

    name: str
    elements: int
    length: float = float("nan")

    def node_name(self, i: int) -> str:
        """The body name of node ``i`` (negative counts from the end)."""
        k = int(i) + (self.elements + 1 if int(i) < 0 else 0)
        if not 0 <= k <= self.elements:
            raise InvalidSceneError(f"beam '{self.name}' has nodes 0..{self.elements}, got {i}")
        return f"{self.name}[{k}]"

    def node(self, i: int, z: Optional[Sequence[float]] = None, x: Optional[Sequence[float]] = None) -> SpatialMarker:
        """A marker at node ``i`` (axes ``z``, ``x`` in the section frame ``[axis, y, z]``; default the
        section frame itself): usable by every spatial joint, driver and force."""
        return SpatialMarker(self.node_name(i), (0.0, 0.0, 0.0), None if z is None else tuple(z), None if x is None else tuple(x))

    def point(self, s: float, z: Optional[Sequence[float]] = None, x: Optional[Sequence[float]] = None) -> SpatialMarker:
        """A marker at the material point at arc length ``s`` from ``start`` (axes as for
        :meth:`node`), between the nodes too: on the node whose rigid segment holds it (the
        beam's mass model, docs/spatial-flexible.md), at its offset along the section axis. It
        moves with that segment: exact at the nodes, off the elements' centreline in between by
        about the curvature times the offset squared (converging with the mesh)."""
        node, offset = _core.beam3_material_point(self.elements, float(self.length), real("s", s))
        return SpatialMarker(self.node_name(node), (offset, 0.0, 0.0), None if z is None else tuple(z), None if x is None else tuple(x))

    @property
    def element_names(self) -> List[str]:
        return [f"{self.name}[e{j}]" for j in range(self.elements)]


class SpatialScene:
    """Builder of a spatial scene description (``"dim": 3``); see the module docstring."""

    def __init__(self, gravity: Sequence[float] = (0.0, 0.0, 0.0)):
        self._d: Dict[str, Any] = {"dim": 3, "gravity": _vec("gravity", gravity), "bodies": [], "joints": [],
                                   "drivers": [], "forces": []}
        self.ground = SpatialBodyRef("ground")

    # -- bodies ---------------------------------------------------------------------------
    def rigid_body(self, name: str, mass: float, inertia: Any, *, com: Sequence[float] = (0, 0, 0),
                   position: Sequence[float] = (0, 0, 0), orientation: Any = None,
                   velocity: Sequence[float] = (0, 0, 0), angular_velocity: Sequence[float] = (0, 0, 0)) -> SpatialBodyRef:
        """A rigid body: ``inertia`` (3x3, or its 3 principal moments) about the centre of mass in
        body axes; ``com`` in the body frame; ``position`` and ``velocity`` of the body frame
        origin; ``orientation`` a unit quaternion ``[e0, e1, e2, e3]`` or a rotation matrix (body
        -> world); ``angular_velocity`` in world axes."""
        J = np.asarray(inertia, dtype=float)
        if J.shape == (3,):
            J = np.diag(J)
        if J.shape != (3, 3):
            raise InvalidSceneError(f"body '{name}': inertia must be 3x3 or 3 principal moments, got shape {J.shape}")
        b: Dict[str, Any] = {"kind": "rigid3", "name": name, "mass": float(mass), "inertia": J.tolist(),
                             "com": _vec("com", com), "position": _vec("position", position),
                             "velocity": _vec("velocity", velocity), "angular_velocity": _vec("angular_velocity", angular_velocity)}
        if orientation is not None:
            o = np.asarray(orientation, dtype=float)
            b["orientation"] = o.tolist() if o.shape in ((4,), (3, 3)) else _vec("orientation", o, 4)
        self._d["bodies"].append(b)
        return SpatialBodyRef(name)

    def flexible_body(self, name: str, data: Any, *, position: Sequence[float] = (0, 0, 0), orientation: Any = None,
                      velocity: Sequence[float] = (0, 0, 0), angular_velocity: Sequence[float] = (0, 0, 0),
                      elastic: Optional[Sequence[float]] = None, elastic_rates: Optional[Sequence[float]] = None,
                      stress_stiffening: Optional[bool] = None) -> "SpatialFlexibleRef":
        """A 3D floating-frame modal body (kind ``flexible3``, docs/spatial-flexible.md) from its
        data (:class:`ukflex.fe3.FlexibleData3`, e.g. :func:`ukflex.fe3.from_mesh`, or the
        description dict of its invariants): ``position``, ``orientation``, ``velocity`` and
        ``angular_velocity`` (world axes) of its floating frame, ``elastic`` and ``elastic_rates``
        the initial modal coordinates (default zero). Markers sit on its interfaces:
        ``ref.interface("A", z=...)``. ``stress_stiffening``: ``None`` (default) uses the data's
        ``geometric_stiffness`` if they carry it, ``True`` requires it, ``False`` leaves it out
        (docs/spatial-flexible.md, "Stress stiffening")."""
        d = data.to_dict() if hasattr(data, "to_dict") else dict(data)
        if stress_stiffening is not None and not isinstance(stress_stiffening, bool):
            raise InvalidArgumentError("stress_stiffening", f"expected None, True or False, got {stress_stiffening!r}")
        if stress_stiffening is False:
            d.pop("geometric_stiffness", None)
        elif stress_stiffening and d.get("geometric_stiffness") is None:
            raise InvalidArgumentError("stress_stiffening", f"body {name!r}: its data carry no geometric_stiffness (the "
                                       "load cases of stress stiffening): build them with ukflex.fe3.from_mesh(..., "
                                       "frame=('clamped', NAME), stress_stiffening=True)")
        b: Dict[str, Any] = {"kind": "flexible3", "name": name, **d, "position": _vec("position", position),
                             "velocity": _vec("velocity", velocity), "angular_velocity": _vec("angular_velocity", angular_velocity)}
        if orientation is not None:
            o = np.asarray(orientation, dtype=float)
            b["orientation"] = o.tolist() if o.shape in ((4,), (3, 3)) else _vec("orientation", o, 4)
        for key, v in (("elastic", elastic), ("elastic_rates", elastic_rates)):
            if v is not None:
                b[key] = [float(x) for x in np.asarray(v, dtype=float).reshape(-1)]
        self._d["bodies"].append(b)
        names = list(getattr(data, "interfaces", {}) or {})
        points = [tuple(f["point"]) for f in d.get("interfaces", [])]
        return SpatialFlexibleRef(name, dict(zip(names, points)) if names else {})

    def beam(self, name: str, start: Sequence[float], end: Sequence[float], section: Any, *,
             elements: Optional[int] = None, density: Optional[float] = None, youngs_modulus: Optional[float] = None,
             shear_modulus: Optional[float] = None, poisson_ratio: Optional[float] = None,
             shear_factor: Optional[float] = None, y_axis: Optional[Sequence[float]] = None,
             velocity: Sequence[float] = (0, 0, 0), angular_velocity: Sequence[float] = (0, 0, 0)) -> SpatialBeamRef:
        """A geometrically exact 3D beam (Simo-Reissner, kind ``beam3``, docs/spatial-flexible.md),
        straight from ``start`` to ``end`` (world), cut into ``elements`` two-node elements (default:
        the core's, 10). Each node is a body ``name[i]`` of kind ``rigid3`` (``[x, y, z, e0..e3]``)
        carrying the lumped mass and rotary inertia of its part of the beam; the elements are the
        force elements ``name[e j]``.

        ``section``: :class:`ukflex.Circular`, :class:`ukflex.Rectangular` (``width`` along the
        section's ``y``, ``height`` along its ``z``), both with the material ``density``,
        ``youngs_modulus`` and one of ``shear_modulus``/``poisson_ratio`` (``shear_factor``
        default: Cowper's); or :class:`CustomSection3` (no material). ``y_axis``: hint for the
        section's ``y`` axis (default: the section's ``z`` as close to world ``z`` as the axis
        allows). ``velocity`` (of ``start``) and ``angular_velocity``: a rigid initial motion.
        Markers: ``ref.node(i)``."""
        sec = section.to_dict() if hasattr(section, "to_dict") else dict(section)
        b: Dict[str, Any] = {"kind": "beam3", "name": name, "start": _vec("start", start), "end": _vec("end", end),
                             "section": sec, "velocity": _vec("velocity", velocity),
                             "angular_velocity": _vec("angular_velocity", angular_velocity)}
        for key, v in (("density", density), ("youngs_modulus", youngs_modulus), ("shear_modulus", shear_modulus),
                       ("poisson_ratio", poisson_ratio), ("shear_factor", shear_factor)):
            if v is not None:
                b[key] = float(v)
        if elements is not None:
            if isinstance(elements, bool) or not isinstance(elements, (int, np.integer)):
                raise InvalidSceneError(f"body '{name}': elements must be an integer, got {elements!r}")
            b["elements"] = int(elements)
        if y_axis is not None:
            b["y_axis"] = _vec("y_axis", y_axis)
        self._d["bodies"].append(b)
        n = int(elements) if elements is not None else int(_core.beam3_default_elements())
        return SpatialBeamRef(name, n, float(np.linalg.norm(np.subtract(b["end"], b["start"]))))

    def point_mass(self, name: str, mass: float, *, position: Sequence[float] = (0, 0, 0),
                   velocity: Sequence[float] = (0, 0, 0)) -> SpatialBodyRef:
        self._d["bodies"].append({"kind": "point3", "name": name, "mass": float(mass),
                                  "position": _vec("position", position), "velocity": _vec("velocity", velocity)})
        return SpatialBodyRef(name)

    # -- joints ---------------------------------------------------------------------------
    def _pair(self, section: str, kind: str, a: SpatialMarker, b: SpatialMarker, name: Optional[str], **extra: Any) -> str:
        item: Dict[str, Any] = {"kind": kind, "a": a.to_dict(), "b": b.to_dict(), **extra}
        if name is not None:
            item["name"] = name
        self._d[section].append(item)
        return name or f"{kind}{len(self._d[section]) - 1}"

    def spherical(self, a: SpatialMarker, b: SpatialMarker, name: Optional[str] = None) -> str:
        return self._pair("joints", "spherical", a, b, name)

    def revolute(self, a: SpatialMarker, b: SpatialMarker, name: Optional[str] = None) -> str:
        """About the markers' common ``z`` axis."""
        return self._pair("joints", "revolute", a, b, name)

    def prismatic(self, a: SpatialMarker, b: SpatialMarker, name: Optional[str] = None) -> str:
        """Along ``z_a``; no rotation."""
        return self._pair("joints", "prismatic", a, b, name)

    def cylindrical(self, a: SpatialMarker, b: SpatialMarker, name: Optional[str] = None) -> str:
        return self._pair("joints", "cylindrical", a, b, name)

    def universal(self, a: SpatialMarker, b: SpatialMarker, name: Optional[str] = None) -> str:
        """Cross arms ``x_a`` (body of ``a``) and ``y_b`` (body of ``b``)."""
        return self._pair("joints", "universal", a, b, name)

    def fixed(self, a: SpatialMarker, b: SpatialMarker, name: Optional[str] = None) -> str:
        return self._pair("joints", "fixed", a, b, name)

    def planar(self, a: SpatialMarker, b: SpatialMarker, name: Optional[str] = None) -> str:
        """``b``'s point in ``a``'s ``x y`` plane, rotation about ``z`` only."""
        return self._pair("joints", "planar", a, b, name)

    def distance(self, a: SpatialMarker, b: SpatialMarker, length: Optional[float] = None, name: Optional[str] = None) -> str:
        extra = {} if length is None else {"length": float(length)}
        return self._pair("joints", "distance", a, b, name, **extra)

    def point_on_line(self, line: SpatialMarker, point: SpatialMarker, name: Optional[str] = None) -> str:
        """``point`` on the ``z`` line of ``line``."""
        return self._pair("joints", "point_on_line", line, point, name)

    def point_on_plane(self, plane: SpatialMarker, point: SpatialMarker, name: Optional[str] = None) -> str:
        """``point`` on the ``x y`` plane of ``plane``."""
        return self._pair("joints", "point_on_plane", plane, point, name)

    # -- drivers --------------------------------------------------------------------------
    def rotation_driver(self, a: SpatialMarker, b: SpatialMarker, motion: Any, name: Optional[str] = None) -> str:
        """The angle of ``x_b`` about ``z_a`` from ``x_a`` follows ``motion`` (any number of turns)."""
        return self._pair("drivers", "rotation", a, b, name, motion=_motion(motion))

    def translation_driver(self, a: SpatialMarker, b: SpatialMarker, motion: Any, name: Optional[str] = None) -> str:
        """``z_a . (P_b - P_a)`` follows ``motion``."""
        return self._pair("drivers", "translation", a, b, name, motion=_motion(motion))

    # -- forces ---------------------------------------------------------------------------
    def _force(self, item: Dict[str, Any], name: Optional[str]) -> str:
        if name is not None:
            item["name"] = name
        self._d["forces"].append(item)
        return name or f"{item['kind']}{len(self._d['forces']) - 1}"

    def point_force(self, point: SpatialMarker, force: Sequence[float], frame: str = "world", name: Optional[str] = None) -> str:
        """A constant force at a marker, world components or the marker's axes (``frame="body"``)."""
        return self._force({"kind": "point_force", "point": point.to_dict(), "force": _vec("force", force), "frame": frame}, name)

    def torque(self, body: SpatialBodyRef, torque: Sequence[float], frame: str = "world", name: Optional[str] = None) -> str:
        return self._force({"kind": "torque", "body": body.name, "torque": _vec("torque", torque), "frame": frame}, name)

    def point_load(self, point: SpatialMarker, force: Sequence[Any], frame: str = "world", name: Optional[str] = None, *,
                   inputs: Sequence[str] = ()) -> str:
        """A force at a marker whose three components (world axes, or the marker's with
        ``frame="body"``) are each a number, an expression of ``t`` and the coordinates by name
        (``"50 * sin(2 * t)"``, ``"-10 * m.x - 0.5 * d:m.x"``), a :class:`ukflex.LoadTable`, or a
        Python callable ``f(t, state) -> float`` with ``state`` the dict of the quantities named
        by ``inputs`` (docs/loads.md, "In 3D"). Expressions and tables are compiled in Rust; an
        unknown quantity is an :class:`ukflex.ExpressionError`."""
        values = self._values("force", force, inputs)
        return self._force({"kind": "point_load", "point": point.to_dict(), "force": values, "frame": frame}, name)

    def torque_load(self, body: SpatialBodyRef, torque: Sequence[Any], frame: str = "world", name: Optional[str] = None, *,
                    inputs: Sequence[str] = ()) -> str:
        """A torque on a rigid body whose three components (world or body axes) are functions, as
        :meth:`point_load`'s."""
        return self._force({"kind": "torque_load", "body": body.name, "torque": self._values("torque", torque, inputs),
                            "frame": frame}, name)

    @property
    def callables(self) -> Dict[str, Any]:
        """The Python callables of the loads, by the name the description gives them; the
        System is given them when it is built (they are not part of :meth:`to_dict`)."""
        return dict(getattr(self, "_callables", {}))

    def _values(self, what: str, values: Any, inputs: Sequence[str]) -> List[Any]:
        """The three components of a load as the description holds them: a table as its dict,
        a callable as a reference ``{"callable": name, "inputs": [...]}``."""
        if isinstance(values, (str, dict)) or callable(values) or not hasattr(values, "__len__"):
            raise InvalidSceneError(f"{what} must have 3 components (numbers, expressions, tables or callables), got {values!r}")
        if len(values) != 3:
            raise InvalidSceneError(f"{what} must have 3 components, got {len(values)}")
        out = [self._value(v, inputs) for v in values]
        if inputs and not any(isinstance(v, dict) and "callable" in v for v in out):
            raise InvalidArgumentError("inputs", "name the state quantities of a Python callable only (an expression or a table names its own)")
        return out

    def _value(self, v: Any, inputs: Sequence[str]) -> Any:
        """One load value as the description holds it (a table's dict, a callable's reference)."""
        if hasattr(v, "to_dict"):
            return v.to_dict()
        if callable(v):
            self._callables = getattr(self, "_callables", {})
            name = f"callable{len(self._callables)}"
            self._callables[name] = v
            return {"callable": name, "inputs": [str(i) for i in inputs]}
        if isinstance(v, str):
            return v
        return float(v)

    def motor(self, joint: str, torque: Any, rotor_inertia: float = 0.0, name: Optional[str] = None, *,
              inputs: Sequence[str] = ()) -> str:
        """A motor on the revolute, cylindrical or prismatic joint named ``joint`` (added
        before): on a revolute or cylindrical joint a torque ``tau`` about its axis, on the body
        of the joint's marker ``a`` (the rotor) and ``-tau`` on ``b``'s (the stator); on a
        prismatic joint a force along its axis (a linear motor). ``torque`` is a load value as
        :meth:`point_load`'s components: a number, an expression that may read ``angle`` and
        ``w`` (the relative angle about the axis, counted over turns, and its rate; on a
        prismatic joint ``s`` and ``v``, the slide and its rate) besides ``t``, the coordinates
        and the point quantities (``ukflex.model.scene.dc_motor_torque`` writes a DC motor's),
        a :class:`ukflex.LoadTable`, or a callable of ``inputs``. ``rotor_inertia`` [kg m^2]
        about the axis is added to the inertia tensor of ``a``'s body (a rigid3 body;
        docs/loads.md, "Motors in 3D")."""
        value = self._value(torque, inputs)
        if inputs and not (isinstance(value, dict) and "callable" in value):
            raise InvalidArgumentError("inputs", "name the state quantities of a Python callable only (an expression or a table names its own)")
        return self._force({"kind": "motor", "joint": joint, "torque": value, "rotor_inertia": float(rotor_inertia)}, name)

    def spring_damper(self, a: SpatialMarker, b: SpatialMarker, stiffness: float, damping: float = 0.0,
                      rest_length: Optional[float] = None, name: Optional[str] = None) -> str:
        item: Dict[str, Any] = {"kind": "spring_damper", "a": a.to_dict(), "b": b.to_dict(), "stiffness": float(stiffness),
                                "damping": float(damping)}
        if rest_length is not None:
            item["rest_length"] = float(rest_length)
        return self._force(item, name)

    def rotational_spring_damper(self, a: SpatialMarker, b: SpatialMarker, stiffness: float, damping: float = 0.0,
                                 angle0: float = 0.0, name: Optional[str] = None) -> str:
        """About ``z_a`` (a revolute's axis): torque ``-k (theta - angle0) - c thetad``."""
        return self._force({"kind": "rotational_spring_damper", "a": a.to_dict(), "b": b.to_dict(),
                            "stiffness": float(stiffness), "damping": float(damping), "angle0": float(angle0)}, name)

    def joint_friction(self, joint: str, *, mu: float, radius: Optional[float] = None,
                       collar_radius: Optional[float] = None, damping: float = 0.0,
                       v_eps: Optional[float] = None, name: Optional[str] = None) -> str:
        """Regularized Coulomb and viscous friction in the revolute, prismatic or spherical joint
        named ``joint`` (added before), from its reaction, as :meth:`ukflex.Scene.joint_friction`
        in the plane: a revolute's torque about its axis
        ``-mu (radius |F_radial| + collar_radius |F_axial|) sat(w / v_eps) - damping w``, a
        prismatic's force along its axis ``-mu |N| sat(v / v_eps) - damping v`` (``N`` the
        reaction across the axis), a spherical joint's torque about the relative rotation axis
        ``-mu radius |F| sat(|w| / v_eps) - damping |w|``. ``sat(x) = clamp(x, -1, 1)``;
        ``v_eps=None`` takes the core's default (docs/loads.md, "Joint friction in spatial
        joints"). Closed with the reactions in every acceleration call."""
        item: Dict[str, Any] = {"kind": "joint_friction", "joint": joint, "mu": mu, "damping": damping}
        for key, value in (("radius", radius), ("collar_radius", collar_radius), ("v_eps", v_eps)):
            if value is not None:
                item[key] = value
        return self._force(item, name)

    # -- description ----------------------------------------------------------------------
    def to_dict(self) -> Dict[str, Any]:
        return copy.deepcopy(self._d)

    @classmethod
    def from_dict(cls, description: Dict[str, Any]) -> "SpatialScene":
        """A spatial scene from its description dict (``"dim": 3``; a TOML scene file's tables),
        validated whole by the core (named :class:`ukflex.InvalidSceneError`)."""
        _, d = normalize_spatial(dict(description))
        scene = cls.__new__(cls)
        scene._d = {"dim": d.get("dim", 3), "gravity": d.get("gravity", [0.0, 0.0, 0.0]),
                    **{k: list(d.get(k) or []) for k in ("bodies", "joints", "drivers", "forces")}}
        scene.ground = SpatialBodyRef("ground")
        return scene

    def validate(self) -> None:
        """Build the description in the core (every rule is the core's; named errors)."""
        normalize_spatial(self._d, self.callables, copy_back=False)

    def core_text(self) -> str:
        """The description as the core reads it (JSON; a NaN or infinity refused by name):
        :class:`ukflex.System` builds its core from it once, and that build is the validation
        (the same named errors as :meth:`validate`, without a second build)."""
        return _core_text(self._d)


def _check_transportable(v: Any, path: str) -> None:
    """JSON carries no NaN or infinity: name where one stands (every other rule is the core's)."""
    if isinstance(v, float) and not np.isfinite(v):
        raise InvalidSceneError(f"scene: {path.lstrip('.')} must be finite, got {v}")
    if isinstance(v, dict):
        for k, x in v.items():
            _check_transportable(x, f"{path}.{k}")
    elif isinstance(v, (list, tuple)):
        for i, x in enumerate(v):
            _check_transportable(x, f"{path}[{i}]")


def _core_text(description: Dict[str, Any]) -> str:
    """The description's JSON text for the core; a NaN or infinity named where it stands."""
    try:
        return json.dumps(description, allow_nan=False)
    except (TypeError, ValueError) as exc:
        # name where a NaN or infinity stands (the walk only when the fast encoder refused:
        # 0.2 of A05's 2 ms build otherwise)
        _check_transportable(description, "")
        raise InvalidSceneError(f"scene: not a JSON-compatible description ({exc})") from exc


def normalize_spatial(description: Dict[str, Any], callables: Optional[Dict[str, Any]] = None,
                      copy_back: bool = True):
    """Validate a spatial description dict in the core (with the loads' Python ``callables`` by
    name); returns ``(None, dict)`` like :func:`ukflex.description.normalize` (spatial scenes
    have no item-by-item checker; ``copy_back=False``: ``(None, None)``, no copy)."""
    _core.System(_core_text(description), callables=callables)
    return None, copy.deepcopy(dict(description)) if copy_back else None
