"""Exudyn 1.13.6's geometrically exact beam for the studies that compare ``beam3`` with it (the
right-angle cantilever, the spatial slider-crank, the 3D flexible pendulum): the section data
as ``beam3`` derives them, a straight member of ``ObjectBeamGeometricallyExact`` elements on
``NodeRigidBodyEP`` nodes, the simulation settings and the timed solve.

Exudyn's element (``CObjectBeamGeometricallyExact``) lumps its mass onto its two nodes by the
two-point Lobatto rule: a point mass ``rho A L_e / 2`` and the section's rotary inertia times
``L_e / 2`` at each node (no ``m l^2 / 12`` of the segment); ``beam3`` lumps the exact inertia
of the rigid segment around each node. Both converge to the same continuum.
"""

from __future__ import annotations

import time
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np


def rectangle_section(width: float, height: float, density: float, youngs_modulus: float, poisson_ratio: float) -> Dict[str, Any]:
    """The section data ``beam3`` derives for ``Rectangular(width, height)`` (width along the
    section's ``y``): Cowper's shear factor ``10 (1 + nu) / (12 + 11 nu)``, Saint-Venant's torsion
    constant, the rotary inertia ``rho (I_y + I_z), rho I_y, rho I_z``."""
    e, nu, rho = youngs_modulus, poisson_ratio, density
    g = e / (2 * (1 + nu))
    a, b = max(width, height), min(width, height)
    n = np.arange(1, 200, 2)
    j = a * b ** 3 * (1 / 3 - 64 / np.pi ** 5 * (b / a) * np.sum(np.tanh(n * np.pi * a / (2 * b)) / n ** 5))
    area, iy, iz = width * height, width * height ** 3 / 12, height * width ** 3 / 12
    k = 10 * (1 + nu) / (12 + 11 * nu)
    return {"ea": e * area, "ga_y": k * g * area, "ga_z": k * g * area, "gj": g * j, "ei_y": e * iy, "ei_z": e * iz,
            "mass_per_length": rho * area, "rotary_inertia": (rho * (iy + iz), rho * iy, rho * iz)}


def beam_section(ea: float, ga_y: float, ga_z: float, gj: float, ei_y: float, ei_z: float, mass_per_length: float,
                 rotary_inertia: Sequence[float]) -> Any:
    """An ``exudyn.BeamSection`` of the given data (the arguments of ``ukflex.CustomSection3``)."""
    import exudyn as exu

    bs = exu.BeamSection()
    bs.stiffnessMatrix = np.diag([ea, ga_y, ga_z, gj, ei_y, ei_z])
    bs.massPerLength = mass_per_length
    bs.inertia = np.diag(rotary_inertia)
    return bs


def add_member(mbs: Any, start: Sequence[float], rotation: np.ndarray, length: float, elements: int, section: Any,
               angular_velocity: Optional[Sequence[float]] = None) -> List[int]:
    """A straight member from ``start`` along the first column of ``rotation`` (its section frame
    ``[axis, y, z]``), ``elements`` ``ObjectBeamGeometricallyExact`` on ``elements + 1``
    ``NodeRigidBodyEP`` nodes; with ``angular_velocity`` (world) the rigid spin of the member
    about the origin as its initial velocities. The node numbers, from ``start``."""
    from exudyn.itemInterface import NodeRigidBodyEP, ObjectBeamGeometricallyExact
    from exudyn.rigidBodyUtilities import AngularVelocity2EulerParameters_t, RotationMatrix2EulerParameters

    rotation = np.asarray(rotation, dtype=float)
    ep = np.asarray(RotationMatrix2EulerParameters(rotation))
    le = length / elements
    nodes = []
    for k in range(elements + 1):
        x = np.asarray(start, dtype=float) + k * le * rotation[:, 0]
        if angular_velocity is None:
            nodes.append(mbs.AddNode(NodeRigidBodyEP(referenceCoordinates=list(x) + list(ep))))
        else:
            w = np.asarray(angular_velocity, dtype=float)
            v0 = list(np.cross(w, x)) + list(AngularVelocity2EulerParameters_t(w, ep))
            nodes.append(mbs.AddNode(NodeRigidBodyEP(referenceCoordinates=list(x) + list(ep), initialVelocities=v0)))
    for n0, n1 in zip(nodes[:-1], nodes[1:]):
        mbs.AddObject(ObjectBeamGeometricallyExact(nodeNumbers=[n0, n1], length=le, sectionData=section))
    return nodes


def settings(t_end: float, steps: int, spectral_radius: float = 1.0, newton_rtol: Optional[float] = None,
             newton_atol: Optional[float] = None, sparse: bool = False, overrides: Optional[Dict[str, Any]] = None) -> Any:
    """Exudyn's simulation settings of the studies: generalized-alpha at ``spectral_radius``
    (1: no numerical damping), ``steps`` steps over ``[0, t_end]``, the sensors at every step,
    no solution file; Newton's relative and absolute goals when given (Exudyn's defaults 1e-8
    and 1e-10 lie below the residual's rounding on some models: see each study), its sparse
    solver (``EigenSparse``) when ``sparse``; ``overrides`` dotted paths, e.g.
    ``{"timeIntegration.verboseMode": 1}``."""
    import exudyn as exu

    ss = exu.SimulationSettings()
    ss.timeIntegration.numberOfSteps = steps
    ss.timeIntegration.endTime = t_end
    ss.timeIntegration.generalizedAlpha.spectralRadius = spectral_radius
    ss.timeIntegration.verboseMode = 0
    ss.solution.file.write = False  # solutionSettings.writeSolutionToFile before Exudyn 1.13
    ss.solution.sensors.writePeriod = t_end / steps
    if newton_rtol is not None:
        ss.timeIntegration.newton.relativeTolerance = newton_rtol
    if newton_atol is not None:
        ss.timeIntegration.newton.absoluteTolerance = newton_atol
    if sparse:
        ss.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    for key, value in (overrides or {}).items():
        *path, last = key.split(".")
        obj = ss
        for p in path:
            obj = getattr(obj, p)
        setattr(obj, last, value)
    return ss


def solve(mbs: Any, ss: Any) -> float:
    """``mbs.SolveDynamic(ss)``, timed: its wall time."""
    t0 = time.perf_counter()
    mbs.SolveDynamic(ss)
    return time.perf_counter() - t0


def history(mbs: Any, sensor: int, t: np.ndarray) -> np.ndarray:
    """A 3-vector sensor's stored history interpolated at ``t``: ``(nt, 3)``."""
    d = np.asarray(mbs.GetSensorStoredData(sensor))
    return np.column_stack([np.interp(t, d[:, 0], d[:, c]) for c in (1, 2, 3)])


def run_grid(runs: Dict[Tuple[str, int, int], List[Any]], failed: List[str], meshes: Sequence[int], steps: Sequence[int],
             run: Callable[[int, int], Any], log: Callable[[str], None], prefix: str = "", unit: str = "elements") -> None:
    """Exudyn's runs of a study on each mesh at each step count, ``run(mesh, steps)`` appended
    to ``runs[("Exudyn", mesh, steps)]``; a run that Exudyn stops (its Newton failing at too
    large a step) is reported in ``failed``."""
    for n in meshes:
        for st in steps:
            log(f"{prefix}Exudyn {n} {unit}, {st} steps")
            try:
                runs.setdefault(("Exudyn", n, st), []).append(run(n, st))
            except Exception as exc:
                failed.append(f"Exudyn {n} {unit}, {st} steps failed: {type(exc).__name__}: {str(exc)[:60]}")
