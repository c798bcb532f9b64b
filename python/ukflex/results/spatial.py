"""Outputs and sensors of spatial (3D) runs.

:func:`outputs` (``ukflex.spatial_outputs``): per body the centre of mass, velocity,
orientation (quaternion, rotation matrix) and angular velocity; per joint the minimum-norm
reaction force and torque; momenta and energies. :class:`SpatialSensors` is ``res.sensors`` of
a spatial result: the same numbers by name, energies by kind and the energy balance (the
planar :class:`ukflex.results.sensors.Sensors` API, with 3D reactions). Everything per state is
computed in Rust by the System's own model (``System.core.spatial_outputs``,
``rust/sensors/spatial.rs``, ``rust/sensors/mod.rs``): one call for the whole history.
"""

from __future__ import annotations

import re
from functools import cached_property
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ..errors import UnknownNameError
from .sensors import Sensors, cumulative_integral

__all__ = ["outputs", "is_spatial", "sensors_of", "sensors_class", "SpatialSensors", "BODY_QUANTITIES",
           "REACTION_COLUMNS_3D"]

#: Per-body quantities (``SpatialSensors.body``) and their components.
BODY_QUANTITIES: Dict[str, Tuple[str, ...]] = {
    "position": ("x", "y", "z"), "velocity": ("x", "y", "z"), "quaternion": ("e0", "e1", "e2", "e3"),
    "omega": ("x", "y", "z"), "omega_body": ("x", "y", "z"),
    "rotation": tuple(f"R{i}{j}" for i in range(3) for j in range(3)),
}
#: Columns of a spatial reaction (``SpatialSensors.reaction``); the core's ``reaction_columns``.
REACTION_COLUMNS_3D = ("fx", "fy", "fz", "tx", "ty", "tz", "fx_joint", "fy_joint", "fz_joint", "tx_joint", "ty_joint",
                       "tz_joint", "power")
#: Force kinds whose energy is potential (``springs``); the other elements (point forces,
#: torques) are loads whose work is the integral of their power.
_SPRING_KINDS = ("spring_damper", "rotational_spring_damper")
#: Force kinds that are the elastic elements of a body (a 3D beam's): their potential is strain
#: energy, neither a spring's nor a load's.
_STRAIN_KINDS = ("beam3_element",)


def is_spatial(system: Any) -> bool:
    """True for a System built from a ``"dim": 3`` description."""
    return (getattr(system, "description", None) or {}).get("dim", 2) == 3


def _states(system: Any, t: Any, q: Any = None, qd: Any = None):
    if q is None:
        res = t
        n = system.n_coords
        t, q, qd = np.asarray(res.t), np.asarray(res.y[:n]).T, np.asarray(res.y[n:]).T
    t = np.atleast_1d(np.asarray(t, dtype=float))
    q = np.atleast_2d(np.asarray(q, dtype=float))
    qd = np.atleast_2d(np.asarray(qd, dtype=float))
    return t, np.ascontiguousarray(q), np.ascontiguousarray(qd)


def _bodies(raw: Dict[str, Any]) -> Dict[str, Dict[str, np.ndarray]]:
    b = np.asarray(raw["bodies"])
    out = {}
    for i, name in enumerate(raw["body_names"]):
        x = b[:, i, :]
        out[name] = {"position": x[:, 0:3], "velocity": x[:, 3:6], "quaternion": x[:, 6:10], "omega": x[:, 10:13],
                     "omega_body": x[:, 13:16], "rotation": x[:, 16:25].reshape(-1, 3, 3)}
    return out


def outputs(system: Any, t: Any, q: Any = None, qd: Any = None, reactions: bool = True) -> Dict[str, Any]:
    """Spatial outputs at stored states: ``outputs(system, result)`` or ``outputs(system, t, q, qd)``
    (q, qd: (nt, n) or (n,)). Returns a dict of arrays: ``bodies[name]`` -> dict with
    ``position`` (nt, 3, centre of mass), ``velocity``, ``quaternion`` (nt, 4, unit),
    ``rotation`` (nt, 3, 3), ``omega`` (world), ``omega_body``; ``reactions[name]`` -> dict with
    ``force``, ``torque`` (world, on the first marker's body about that marker's point),
    ``force_joint``, ``torque_joint`` (the first marker's axes) and ``power``, from the
    minimum-norm multipliers at the system's rank tolerance (``System.set_rank_tolerance`` if
    set, else the default, tied to each state's drift); ``momentum`` (nt, 3) and
    ``angular_momentum`` (about the origin); ``kinetic_energy``, ``potential_energy``,
    ``energy``; ``driver_values``; ``beams[element]`` -> (nt, 6) section forces and moments
    ``N, Q_y, Q_z, M_t, M_y, M_z`` of each 3D beam element (section axes, element midpoint;
    ``beam[e j]`` is element ``j`` of beam ``beam``). Computed by the System's compiled model
    (``System.core.spatial_outputs``)."""
    t, q, qd = _states(system, t, q, qd)
    raw = system.core.spatial_outputs(t, q, qd, reactions)
    out: Dict[str, Any] = {"bodies": _bodies(raw), "momentum": raw["momentum"][:, :3],
                           "angular_momentum": raw["momentum"][:, 3:], "kinetic_energy": raw["kinetic_energy"],
                           "potential_energy": raw["potential_energy"],
                           "energy": raw["kinetic_energy"] + raw["potential_energy"]}
    if reactions:
        r = raw["reactions"]
        out["reactions"] = {name: {"force": r[:, k, 0:3], "torque": r[:, k, 3:6], "force_joint": r[:, k, 6:9],
                                   "torque_joint": r[:, k, 9:12], "power": r[:, k, 12]}
                            for k, name in enumerate(raw["reaction_names"]) if not name.endswith(".normalization")}
    bf = raw["beam_forces"]
    out["beams"] = {name: bf[:, k, :] for k, name in enumerate(raw["beam_element_names"])}
    dv = raw["driver_values"]
    out["driver_values"] = {name: dv[:, k] for k, name in enumerate(raw["reaction_names"]) if not np.all(np.isnan(dv[:, k]))}
    return out


class SpatialSensors(Sensors):
    """Sensors of a spatial :class:`ukflex.SimulationResult` (``res.sensors``), computed once on
    first use: :meth:`body` (position, velocity, quaternion, rotation, angular velocity),
    :meth:`reaction` (force and torque, world and joint axes, power), energies by body and kind,
    the drivers' and loads' work, the dissipated energy and :meth:`energy_balance` (inherited).

    Energies: ``kinetic``, ``gravity`` (the scene's gravity element), ``springs``
    (spring-dampers, rotational spring-dampers), ``total`` = their sum. A constant torque or a
    body-frame force has no potential in 3D, so the loads' work ``work.external`` is the time
    integral of their power ``qd . Q_f`` over the output samples (``loads`` is minus it)."""

    reaction_columns = REACTION_COLUMNS_3D

    @cached_property
    def _raw(self) -> Dict[str, Any]:
        from .sensors import _states as states

        t, q, qd = states(self.result)
        return dict(self.system.core.spatial_outputs(t, np.ascontiguousarray(q), np.ascontiguousarray(qd), True))

    @cached_property
    def _reaction_index(self) -> Dict[str, int]:
        return {n: k for k, n in enumerate(self._raw["reaction_names"]) if not n.endswith(".normalization")}

    @property
    def joint_names(self) -> List[str]:
        """Names of the joints and drivers, in order (not the normalization rows)."""
        return list(self._reaction_index)

    def reaction(self, joint: str) -> Dict[str, Any]:
        """Reaction of ``joint`` (or driver) on its first marker's body about that marker's point:
        columns ``fx fy fz tx ty tz`` (world), ``fx_joint ... tz_joint`` (the first marker's axes),
        ``power``, each (nt,); ``force``, ``torque``, ``force_joint``, ``torque_joint`` (nt, 3);
        ``body`` (None: the first marker is on the ground, and the wrench is what the ground
        receives)."""
        if joint not in self._reaction_index:
            raise UnknownNameError.of("joint or driver", joint, self.joint_names)
        k = self._reaction_index[joint]
        r = np.asarray(self._raw["reactions"])[:, k, :]
        out: Dict[str, Any] = {c: r[:, i].copy() for i, c in enumerate(REACTION_COLUMNS_3D)}
        for key, cols in (("force", slice(0, 3)), ("torque", slice(3, 6)), ("force_joint", slice(6, 9)),
                          ("torque_joint", slice(9, 12))):
            out[key] = r[:, cols].copy()
        out["body"] = self._raw["reaction_bodies"][k]
        return out

    @property
    def body_names(self) -> List[str]:
        return list(self._raw["body_names"])

    def body(self, name: str) -> Dict[str, np.ndarray]:
        """Kinematics of body ``name``: ``position`` (nt, 3: centre of mass), ``velocity``,
        ``quaternion`` (nt, 4: unit, scalar first), ``rotation`` (nt, 3, 3: body -> world),
        ``omega`` (world axes), ``omega_body`` (body axes). A point mass: identity orientation."""
        if name not in self.body_names:
            raise UnknownNameError.of("body", name, self.body_names)
        return _bodies(self._raw)[name]

    def momentum(self) -> Dict[str, np.ndarray]:
        """``linear`` and ``angular`` (about the world origin) momentum of the system, each (nt, 3)."""
        m = np.asarray(self._raw["momentum"])
        return {"linear": m[:, :3].copy(), "angular": m[:, 3:].copy()}

    def _forces(self, springs: bool, key: str) -> np.ndarray:
        """Sum of ``key`` (``force_potentials`` or ``force_powers``) over the springs
        (``springs=True``) or the loads; gravity is neither (``energies()["gravity"]``)."""
        a = np.asarray(self._raw[key])
        cols = [i for i, k in enumerate(self._raw["force_kinds"])
                if k != "gravity" and k not in _STRAIN_KINDS and (k in _SPRING_KINDS) == springs]
        return a[:, cols].sum(axis=1) if cols else np.zeros(a.shape[0])

    def energies(self) -> Dict[str, np.ndarray]:
        """Energies by kind, each (nt,): ``kinetic``, ``strain`` (0: rigid bodies; a 3D beam's is
        the sum of its elements' energies), ``gravity``, ``springs``, ``loads`` (minus the loads'
        work from ``t_0``) and ``total = kinetic + strain + gravity + springs``."""
        e = np.asarray(self._raw["body_energies"])
        fp = np.asarray(self._raw["force_potentials"])
        beams = [i for i, k in enumerate(self._raw["force_kinds"]) if k in _STRAIN_KINDS]
        strain = e[:, :, 1].sum(axis=1) + (fp[:, beams].sum(axis=1) if beams else 0.0)
        out = {"kinetic": e[:, :, 0].sum(axis=1), "strain": strain, "gravity": e[:, :, 2].sum(axis=1),
               "springs": self._forces(True, "force_potentials"), "loads": -self.external_work()}
        out["total"] = out["kinetic"] + out["strain"] + out["gravity"] + out["springs"]
        return out

    def external_work(self) -> np.ndarray:
        """Work of the loads (point forces, torques) from ``t_0``: the integral of their power
        over the output samples, shape (nt,)."""
        return cumulative_integral(self.t, self._forces(False, "force_powers"))

    def columns(self) -> Dict[str, np.ndarray]:
        """Every sensor as a named column (nt,): the planar set (reactions, energies, work,
        balance) and each body's kinematics (``position(B).x``, ``quaternion(B).e0``, ...)."""
        out = super().columns()
        for b in self.body_names:
            kin = self.body(b)
            for quantity, comps in BODY_QUANTITIES.items():
                v = kin[quantity].reshape(self.t.size, -1)
                for i, c in enumerate(comps):
                    out[f"{quantity}({b}).{c}"] = v[:, i]
        return out

    # ----------------------------------------------------------------------- expressions
    _BODY = re.compile(r"^(position|velocity|quaternion|omega|omega_body|rotation)\(\s*([^()\s]+)\s*\)\.(\w+)$")
    _REACTION = re.compile(r"^reaction\(\s*([^()\s]+)\s*\)\.(\w+)$")

    @classmethod
    def parse(cls, system, expr: str) -> Optional[Tuple[Any, ...]]:
        """A parsed spatial sensor expression (``SPATIAL_SENSOR_HELP``), ``None`` if ``expr`` is
        not one; ``ValueError`` naming the problem if it is one with a wrong argument."""
        e = expr.strip()
        m = cls._BODY.match(e)
        if m:
            quantity, body, comp = m.groups()
            if body not in system.body_names:
                raise ValueError(f"output {expr!r}: unknown body {body!r}; bodies are {system.body_names}")
            if comp not in BODY_QUANTITIES[quantity]:
                raise ValueError(f"output {expr!r}: components of {quantity} are {BODY_QUANTITIES[quantity]}")
            return ("body", quantity, body, comp)
        m = cls._REACTION.match(e)
        if m:
            items = [c for c in system.core.constraint_items if not c.endswith(".normalization")]
            if m.group(1) not in items:
                raise ValueError(f"output {expr!r}: unknown joint or driver {m.group(1)!r}; joints and drivers are {items}")
            if m.group(2) not in REACTION_COLUMNS_3D:
                raise ValueError(f"output {expr!r}: reaction columns are {REACTION_COLUMNS_3D}")
            return ("reaction", m.group(1), m.group(2))
        return cls._parse_common(system, e, expr)

    def evaluate(self, p: Tuple[Any, ...]) -> Tuple[str, np.ndarray]:
        """``(label, values (nt,))`` of a parsed expression (:meth:`parse`)."""
        if p[0] == "body":
            _, quantity, body, comp = p
            v = self.body(body)[quantity].reshape(self.t.size, -1)[:, BODY_QUANTITIES[quantity].index(comp)]
            unit = {"position": "m", "velocity": "m/s", "omega": "rad/s", "omega_body": "rad/s"}.get(quantity, "-")
            return f"{quantity}({body}).{comp} [{unit}]", v
        if p[0] == "reaction":
            unit = "W" if p[2] == "power" else ("N m" if p[2].startswith("t") else "N")
            return f"reaction({p[1]}).{p[2]} [{unit}]", self.reaction(p[1])[p[2]]
        return super().evaluate(p)


#: Output expressions of spatial sensors (``ukflex run --plot``).
SPATIAL_SENSOR_HELP = ("position|velocity|omega|omega_body(BODY).x|y|z, quaternion(BODY).e0..e3, rotation(BODY).R00..R22, "
                       "reaction(JOINT).fx|fy|fz|tx|ty|tz|fx_joint|...|tz_joint|power, work(DRIVER), "
                       "energy.kinetic|gravity|springs|loads|total, energy(BODY).kinetic|gravity, work.drivers|external, "
                       "dissipated, balance")


def sensors_class(system: Any) -> type:
    """The sensor class of a System: :class:`SpatialSensors` for a spatial one, else
    :class:`ukflex.results.sensors.Sensors`."""
    return SpatialSensors if is_spatial(system) else Sensors


def sensors_of(res: Any) -> Sensors:
    """The sensors of a result (``SimulationResult.sensors``)."""
    return sensors_class(res.system)(res)
