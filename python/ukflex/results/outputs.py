"""Named outputs of a simulation result, for plots and CSV files (``ukflex run --plot``).

An *output expression* is one of

* ``t``;
* a coordinate name, e.g. ``crank.theta`` or ``coupler.qf1`` (``System.coordinate_names``);
* ``d:<coordinate>``: the rate of a coordinate, e.g. ``d:crank.theta``;
* ``residual.position`` / ``residual.velocity`` / ``residual.acceleration``: constraint
  residual norms;
* ``energy``: total mechanical energy ``T + V``;
* ``u(BEAM, XI)``, ``v(BEAM, XI)``: axial / transverse elastic displacement of beam ``BEAM`` at
  ``x = XI * length`` in the beam frame (an ANCF beam's: the chord frame of its ends;
  ``v(coupler, 0.5)`` is the paper's midpoint deflection); append ``/L`` to divide by the beam
  length (``v(coupler, 0.5)/L``, the paper's Fig. 4);
* ``psi(BEAM, XI)``: cross-section rotation relative to the beam frame;
* ``x(BEAM, XI)``, ``y(BEAM, XI)``: world position of the deformed beam axis point;
* sensors (:mod:`ukflex.results.sensors`, docs/outputs.md): ``reaction(JOINT).fx`` (``fy``, ``torque``,
  ``fx_local``, ``fy_local``, ``power``), ``work(DRIVER)``, ``energy.kinetic`` (``strain``,
  ``gravity``, ``springs``, ``loads``, ``total``), ``energy(BODY).kinetic``, ``work.drivers``,
  ``work.external``, ``dissipated``, ``balance``, ``N(BEAM, XI)`` (``V``, ``M``, ``eps``,
  ``kappa``), ``clearance(JOINT).force`` (``eccentricity``, ``penetration``, ``normal_force``,
  ``tangential_force``: a revolute joint with clearance, docs/loads.md).
"""

from __future__ import annotations

import re
from typing import List, Tuple

import numpy as np

from .sensors import SENSOR_HELP, parse_xi
from .spatial import SPATIAL_SENSOR_HELP, is_spatial, sensors_class

__all__ = ["evaluate", "validate", "default_outputs", "beam_names", "OUTPUT_HELP"]

#: Body kinds that are beams (``System.body_kind``): FFRF and ANCF.

OUTPUT_HELP = (
    "t, a coordinate (crank.theta), d:<coordinate> (rate), residual.position|velocity|acceleration, energy, "
    "u(BEAM, XI), v(BEAM, XI) [optionally /L], psi(BEAM, XI), x(BEAM, XI), y(BEAM, XI), " + SENSOR_HELP
    + "; spatial scenes: " + SPATIAL_SENSOR_HELP
)

_BEAM_EXPR = re.compile(r"^(u|v|psi|x|y)\(\s*([^,()\s]+)\s*,\s*([^()\s]+)\s*\)\s*(/\s*L)?$")
_RESIDUALS = ("position", "velocity", "acceleration")


def _parse(system, expr: str):
    """Return a parsed form of ``expr`` or raise ValueError naming the problem."""
    e = expr.strip()
    if e in ("t", "energy"):
        return (e,)
    if e.startswith("residual."):
        kind = e.split(".", 1)[1]
        if kind not in _RESIDUALS:
            raise ValueError(f"output {expr!r}: residual kind must be one of {_RESIDUALS}")
        return ("residual", kind)
    sensor = sensors_class(system).parse(system, e)
    if sensor is not None:
        return ("sensor", sensor)
    m = _BEAM_EXPR.match(e)
    if m:
        what, body, xi_text, per_length = m.groups()
        beams = beam_names(system)
        if body not in beams:
            raise ValueError(f"output {expr!r}: {body!r} is not a beam; beams are {beams}")
        xi = parse_xi(expr, xi_text)
        if per_length and what not in ("u", "v"):
            raise ValueError(f"output {expr!r}: /L applies to u(...) and v(...) only")
        return ("beam", what, body, xi, bool(per_length))
    name = e[2:] if e.startswith("d:") else e
    if name not in system.coordinate_names:
        raise ValueError(f"unknown output {expr!r}; expected {OUTPUT_HELP}; coordinates are {system.coordinate_names}")
    return ("rate" if e.startswith("d:") else "coord", name)


def validate(system, expr: str) -> None:
    """Raise ``ValueError`` if ``expr`` is not a valid output expression for ``system``."""
    _parse(system, expr)


def beam_names(system) -> List[str]:
    """Names of the system's beams, in declaration order."""
    return [b for b in system.body_names if system.capabilities(b)["beam"]]


def _beam_length(system, body: str) -> float:
    return float(system.body_info(body)["length"])


def evaluate(res, expr: str) -> Tuple[str, np.ndarray]:
    """Evaluate output ``expr`` on a :class:`ukflex.SimulationResult`.

    Returns
    -------
    label : str
        Axis label with units.
    values : ndarray, shape (nt,)
    """
    system = res.system
    p = _parse(system, expr)
    if p[0] == "t":
        return "t [s]", res.t
    if p[0] == "energy":
        return "T + V [J]", res.energy()
    if p[0] == "residual":
        return f"||residual {p[1]}||", res.residuals[p[1]]
    if p[0] == "sensor":
        return res.sensors.evaluate(p[1])
    if p[0] in ("coord", "rate"):
        name = p[1]
        unit = "rad" if name.endswith(".theta") else ("-" if ".qf" in name else "m")
        if p[0] == "rate":
            return f"d{name}/dt [{unit}/s]", res.velocity(name)
        return f"{name} [{unit}]", res.coordinate(name)
    _, what, body, xi, per_length = p
    if what in ("u", "v"):
        u, v = res.beam_displacement(body, xi)
        val = u if what == "u" else v
        if per_length:
            return f"{what}({body}, {xi:g}) / L", val / _beam_length(system, body)
        return f"{what}({body}, {xi:g}) [m]", val
    if what == "psi":
        return f"psi({body}, {xi:g}) [rad]", res.beam_rotation(body, xi)
    # world position of the deformed axis point
    x, y = res.beam_position(body, xi)
    return (f"x({body}, {xi:g}) [m]", x) if what == "x" else (f"y({body}, {xi:g}) [m]", y)


def default_outputs(system) -> List[str]:
    """Outputs plotted when none are chosen: each beam's midpoint deflection ``v(B, 0.5)/L``,
    or the angles of the first (up to four) bodies of a rigid scene; for a spatial scene the
    first body's centre of mass and the total energy."""
    if is_spatial(system):
        return [f"position({system.body_names[0]}).{c}" for c in "xyz"] + ["energy.total"]
    beams = beam_names(system)
    if beams:
        return [f"v({b}, 0.5)/L" for b in beams]
    return [f"{b}.theta" for b in system.body_names[:4]]
