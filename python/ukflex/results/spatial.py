"""Outputs of spatial (3D) runs (:func:`ukflex.spatial_outputs`): per body the centre of mass,
velocity, orientation (quaternion, rotation matrix) and angular velocity; per joint the
minimum-norm reaction force and torque; momenta and energies (computed in Rust,
``rust/bindings/spatial.rs``)."""

from __future__ import annotations

import json
from typing import Any, Dict

import numpy as np

from .. import _core


def outputs(system: Any, t: Any, q: Any = None, qd: Any = None, reactions: bool = True) -> Dict[str, Any]:
    """Spatial outputs at stored states: ``outputs(system, result)`` or ``outputs(system, t, q, qd)``
    (q, qd: (nt, n) or (n,)). Returns a dict of arrays: ``bodies[name]`` -> dict with
    ``position`` (nt, 3, centre of mass), ``velocity``, ``quaternion`` (nt, 4, unit),
    ``rotation`` (nt, 3, 3), ``omega`` (world), ``omega_body``; ``reactions[name]`` -> dict with
    ``force``, ``torque`` (world, on the first marker's body about that marker's point) and
    ``force_joint``, ``torque_joint`` (the first marker's axes), from the minimum-norm
    multipliers at the system's rank tolerance (``System.set_rank_tolerance`` if set, else the
    default, tied to each state's drift); ``momentum`` (nt, 3) and ``angular_momentum``
    (about the origin); ``kinetic_energy``, ``potential_energy``, ``energy``; ``driver_values``."""
    if q is None:
        res = t
        n = system.n_coords
        t, q, qd = np.asarray(res.t), np.asarray(res.y[:n]).T, np.asarray(res.y[n:]).T
    t = np.atleast_1d(np.asarray(t, dtype=float))
    q = np.atleast_2d(np.asarray(q, dtype=float))
    qd = np.atleast_2d(np.asarray(qd, dtype=float))
    # the System's own rank tolerance when one was set; else the kernel's default, which for a
    # spatial model rises with the state's drift (docs/spatial.md, redundant constraints)
    tol = getattr(system, "_settings", {}).get("set_rank_tolerance", (None, 0.0))
    raw = _core.spatial_outputs(json.dumps(system.description), t, q, qd, reactions, tol[0], tol[1])
    b = raw["bodies"]
    bodies = {}
    for i, name in enumerate(raw["body_names"]):
        x = b[:, i, :]
        bodies[name] = {"position": x[:, 0:3], "velocity": x[:, 3:6], "quaternion": x[:, 6:10], "omega": x[:, 10:13],
                        "omega_body": x[:, 13:16], "rotation": x[:, 16:25].reshape(-1, 3, 3)}
    out: Dict[str, Any] = {"bodies": bodies, "momentum": raw["momentum"][:, :3], "angular_momentum": raw["momentum"][:, 3:],
                           "kinetic_energy": raw["kinetic_energy"], "potential_energy": raw["potential_energy"],
                           "energy": raw["kinetic_energy"] + raw["potential_energy"]}
    if reactions:
        r = raw["reactions"]
        out["reactions"] = {name: {"force": r[:, k, 0:3], "torque": r[:, k, 3:6], "force_joint": r[:, k, 6:9],
                                   "torque_joint": r[:, k, 9:12]}
                            for k, name in enumerate(raw["reaction_names"]) if not name.endswith(".normalization")}
    dv = raw["driver_values"]
    out["driver_values"] = {name: dv[:, k] for k, name in enumerate(raw["reaction_names"]) if not np.all(np.isnan(dv[:, k]))}
    return out
