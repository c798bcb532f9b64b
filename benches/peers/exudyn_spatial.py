"""A ukflex spatial scene description (``SpatialScene.to_dict()``, ``"dim": 3``) built in Exudyn.

Item by item: a ``rigid3`` body is a ``NodeRigidBodyEP`` (Euler parameters, Exudyn's own
normalization constraint) + ``ObjectRigidBody``; a ``point3`` body a ``NodePoint`` +
``ObjectMassPoint``; a spherical joint an ``ObjectJointSpherical`` on two
``MarkerBodyPosition``; revolute, prismatic, universal and fixed joints are
``ObjectJointGeneric`` on two ``MarkerBodyRigid`` whose local frames (``exu.HT``) are the markers'
frames, with the constrained axes of that frame (revolute about ``z`` ``[1,1,1,1,1,0]``, prismatic along ``z`` ``[1,1,0,1,1,1]``, universal
``[1,1,1,0,0,1]``: Exudyn's rotation-about-``z`` condition ``x_0 . y_1 = 0`` is the universal
joint's cross-arm condition ``x_a . y_b = 0``, fixed all six); gravity is a
``LoadMassProportional`` on every body; a spring-damper an ``ObjectConnectorSpringDamper``
(force ``k (L - L0) + c Ld`` along the line, as in ukflex). Drivers, torques and the other
joint kinds are refused (``NotImplementedError``): the benchmarks of docs/spatial.md do not use them.

Exudyn (``pip install exudyn``, tested with 1.13.6) is imported on first use.
"""

from __future__ import annotations

import time
from typing import Dict, Optional, Sequence

import numpy as np

AXES = {"revolute": [1, 1, 1, 1, 1, 0], "prismatic": [1, 1, 0, 1, 1, 1],
        "universal": [1, 1, 1, 0, 0, 1], "fixed": [1, 1, 1, 1, 1, 1]}


def _frame(z: Optional[Sequence[float]], x: Optional[Sequence[float]]) -> np.ndarray:
    """The marker frame (columns x, y, z in body axes) by the core's rule (``frame_from_z``)."""
    z = np.array([0.0, 0.0, 1.0]) if z is None else np.asarray(z, float) / np.linalg.norm(z)
    h = (np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])) if x is None else np.asarray(x, float)
    xx = h - (h @ z) * z
    xx /= np.linalg.norm(xx)
    return np.column_stack([xx, np.cross(z, xx), z])


def _quaternion(o) -> np.ndarray:
    """Euler parameters ``[e0, e1, e2, e3]`` of an orientation given as a quaternion or a matrix."""
    o = np.eye(3) if o is None else np.asarray(o, float)
    if o.shape == (4,):
        return o / np.linalg.norm(o)
    from exudyn.rigidBodyUtilities import RotationMatrix2EulerParameters
    return np.asarray(RotationMatrix2EulerParameters(o), float)


class Built:
    """An assembled Exudyn system with one position sensor (stored internally)."""

    def __init__(self, SC, mbs, sensor):
        self.SC, self.mbs, self.sensor = SC, mbs, sensor


def build(description: Dict, tracked: Sequence, output_period: float) -> Built:
    """Build ``description`` in Exudyn; ``tracked = (body, point in its frame)`` gets a position
    sensor written every ``output_period`` seconds."""
    import exudyn as exu
    from exudyn import itemInterface as ii
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(ii.ObjectGround())
    g = list(map(float, description.get("gravity", [0.0, 0.0, 0.0])))
    bodies = {"ground": ground}
    for b in description["bodies"]:
        if b["kind"] == "rigid3":
            if any(abs(c) > 0.0 for c in b.get("com", [0, 0, 0])):
                raise NotImplementedError("a centre of mass off the body frame's origin")
            p = _quaternion(b.get("orientation"))
            e0, e = p[0], p[1:]
            E = np.column_stack([-e, np.array([[e0, -e[2], e[1]], [e[2], e0, -e[0]], [-e[1], e[0], e0]])])
            pd = 0.5 * E.T @ np.asarray(b.get("angular_velocity", [0, 0, 0]), float)
            node = mbs.AddNode(ii.NodeRigidBodyEP(referenceCoordinates=list(b["position"]) + list(p),
                                                  initialVelocities=list(b.get("velocity", [0, 0, 0])) + list(pd)))
            J = np.asarray(b["inertia"], float)
            bodies[b["name"]] = mbs.AddObject(ii.ObjectRigidBody(
                mass=b["mass"], inertia=[J[0, 0], J[1, 1], J[2, 2], J[1, 2], J[0, 2], J[0, 1]], nodeNumber=node))
        elif b["kind"] == "point3":
            node = mbs.AddNode(ii.NodePoint(referenceCoordinates=list(b["position"]),
                                            initialVelocities=list(b.get("velocity", [0, 0, 0]))))
            bodies[b["name"]] = mbs.AddObject(ii.ObjectMassPoint(mass=b["mass"], nodeNumber=node))
        else:
            raise NotImplementedError(f"body kind {b['kind']}")
        if any(g):
            mbs.AddLoad(ii.LoadMassProportional(markerNumber=mbs.AddMarker(ii.MarkerBodyMass(bodyNumber=bodies[b["name"]])),
                                                loadVector=g))

    def marker(m: Dict) -> int:
        """A frame (``MarkerBodyRigid`` with the marker's axes)."""
        C = _frame(m.get("z"), m.get("x"))
        ht = exu.HT(rotation=C.tolist(), translation=list(m.get("point", [0.0, 0.0, 0.0])))
        return mbs.AddMarker(ii.MarkerBodyRigid(bodyNumber=bodies[m["body"]], localHT=ht))

    def point(m: Dict) -> int:
        """A point (``MarkerBodyPosition``: point masses have no frame)."""
        return mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=bodies[m["body"]], localPosition=list(m.get("point", [0.0, 0.0, 0.0]))))

    for j in description["joints"]:
        if j["kind"] == "spherical":
            mbs.AddObject(ii.ObjectJointSpherical(markerNumbers=[point(j["a"]), point(j["b"])]))
        elif j["kind"] in AXES:
            mbs.AddObject(ii.ObjectJointGeneric(markerNumbers=[marker(j["a"]), marker(j["b"])], constrainedAxes=AXES[j["kind"]]))
        else:
            raise NotImplementedError(f"joint kind {j['kind']}")
    if description.get("drivers"):
        raise NotImplementedError("drivers")
    for f in description["forces"]:
        if f["kind"] != "spring_damper":
            raise NotImplementedError(f"force kind {f['kind']}")
        mbs.AddObject(ii.ObjectConnectorSpringDamper(markerNumbers=[point(f["a"]), point(f["b"])], stiffness=f["stiffness"],
                                                     damping=f.get("damping", 0.0), referenceLength=f["rest_length"]))
    body, local = tracked
    sensor = mbs.AddSensor(ii.SensorBody(bodyNumber=bodies[body], localPosition=list(map(float, local)), storeInternal=True,
                                         outputVariableType=exu.OutputVariableType.Position))
    mbs.Assemble()
    return Built(SC, mbs, sensor)


def settings(t_end: float, h: float, output_period: float, rho_inf: float = 0.9, modified_newton: bool = True,
             newton_rtol: float = 1e-8, newton_atol: float = 1e-10, index2: bool = False, solver: str = "EigenSparse",
             ignore_singular: bool = False):
    """Generalized-alpha at the fixed step ``h`` with Exudyn's linear solver ``solver`` (default its
    sparse LU, Eigen); ``ignore_singular``: Exudyn's ``ignoreSingularJacobian`` (its dense solver
    then goes on past a redundant constraint row)."""
    import exudyn as exu
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime = t_end
    ti.numberOfSteps = int(round(t_end / h))
    ti.verboseMode = 0
    ti.adaptiveStep = False
    ti.generalizedAlpha.spectralRadius = rho_inf
    ti.generalizedAlpha.computeInitialAccelerations = True
    ti.generalizedAlpha.useIndex2Constraints = index2
    ti.generalizedAlpha.useNewmark = index2
    ti.newton.useModifiedNewton = modified_newton
    ti.newton.relativeTolerance = newton_rtol
    ti.newton.absoluteTolerance = newton_atol
    s.linearSolver.solverType = getattr(exu.LinearSolverType, solver)
    s.linearSolver.ignoreSingularJacobian = ignore_singular
    s.solution.file.write = False
    s.solution.sensors.writePeriod = output_period
    s.show.computationTime = False
    return s


def run(description: Dict, tracked: Sequence, t_end: float, h: float, t_out: np.ndarray, **kw) -> Dict:
    """Build and solve; ``wall`` times the build and ``SolveDynamic`` together. Returns the
    tracked point's positions interpolated at ``t_out`` (``None`` if the run failed)."""
    period = float(t_out[1] - t_out[0])
    t0 = time.perf_counter()
    built = build(description, tracked, period)
    s = settings(t_end, h, period, **kw)
    ok = True
    try:
        built.mbs.SolveDynamic(s)
    except Exception:  # a Newton failure at a fixed step ends the run
        ok = False
    wall = time.perf_counter() - t0
    P = built.mbs.GetSensorStoredData(built.sensor)
    if P is None or len(P) < 2 or not ok or P[-1, 0] < t_end - 1e-9 or not np.all(np.isfinite(P)):
        return {"wall": wall, "p": None, "ok": False}
    p = np.column_stack([np.interp(t_out, P[:, 0], P[:, k]) for k in (1, 2, 3)])
    return {"wall": wall, "p": p, "ok": True}
