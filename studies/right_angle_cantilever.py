"""``python -m studies right-angle-cantilever``: Simo and Vu-Quoc's right-angle cantilever (1988,
"On the dynamics in space of rods undergoing large motions - a geometrically exact approach",
CMAME 66): two members of length 10 in the ``x y`` plane, the first from the clamped root
``(0, 0, 0)`` to the elbow ``(10, 0, 0)``, the second from the elbow to the tip ``(10, 10, 0)``;
``EA = GA = 1e6``, ``GJ = EI = 1e3``, ``rho A = 1``, ``rho J = diag(20, 10, 10)``; an
out-of-plane force ``F_z`` at the elbow, a triangular pulse ``0 -> 50`` at ``t = 1 -> 0`` at
``t = 2``, then free vibration to ``t = 30``.

ukflex: two ``SpatialScene.beam`` members welded at the elbow with ``fixed``, the pulse a
``point_load`` expression of ``t``. Exudyn 1.13.6: ``ObjectBeamGeometricallyExact`` elements on
``NodeRigidBodyEP`` nodes, the members joined by a ``GenericJoint``, the pulse a Python
``loadVectorUserFunction``, generalized-alpha without numerical damping (spectral radius 1).

Output: the displacement histories of the elbow and the tip, every 0.1 s; the gap between the
two codes, each converged in mesh and in time, and the wall times of ukflex's default
``simulate()`` and of Exudyn's ``SolveDynamic`` at equal accuracy (medians of interleaved
repetitions).
"""

from __future__ import annotations

import sys
import time
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

import ukflex

L, EA, GA, GJ, EI, RHO_A, RHO_J = 10.0, 1e6, 1e6, 1e3, 1e3, 1.0, (20.0, 10.0, 10.0)
T_END = 30.0
#: Exudyn's step counts over 30 s (at 20 elements per member every one of them fails Newton:
#: "SolveDynamic terminated")
STEPS = (3000, 6000, 12000, 24000)
#: the triangular pulse 50 max(0, 1 - |t - 1|), written with abs
PULSE = "25 * (1 - abs(t - 1) + abs(1 - abs(t - 1)))"


def pulse(t: float) -> float:
    return 50.0 * max(0.0, 1.0 - abs(t - 1.0))


def scene(elements: int) -> ukflex.SpatialScene:
    """The frame with ``elements`` beam elements per member."""
    s = ukflex.SpatialScene()
    sec = ukflex.CustomSection3(ea=EA, ga_y=GA, ga_z=GA, gj=GJ, ei_y=EI, ei_z=EI, mass_per_length=RHO_A, rotary_inertia=RHO_J)
    a = s.beam("a", (0, 0, 0), (L, 0, 0), sec, elements=elements)
    b = s.beam("b", (L, 0, 0), (L, L, 0), sec, elements=elements)
    s.fixed(s.ground.marker((0, 0, 0)), a.node(0), name="root")
    # the elbow: world axes on both sides (b's section frame is [y, -x, z] of the world)
    s.fixed(a.node(-1, z=(0, 0, 1), x=(1, 0, 0)), b.node(0, z=(0, 0, 1), x=(0, -1, 0)), name="elbow")
    s.point_load(a.node(-1), [0, 0, PULSE], name="pulse")
    return s


def _node_point(system: ukflex.System, q: np.ndarray, body: str, elements: int) -> np.ndarray:
    """The world position of an end node of a member (its body's ``r`` is the end segment's
    centre of mass, a quarter element inwards along the section's axis)."""
    i = system.body_names.index(body)
    qq = q[7 * i:7 * i + 7]
    p = qq[3:] / np.linalg.norm(qq[3:], axis=0)
    ax = np.array([p[0] ** 2 + p[1] ** 2 - p[2] ** 2 - p[3] ** 2, 2 * (p[1] * p[2] + p[0] * p[3]), 2 * (p[1] * p[3] - p[0] * p[2])])
    return qq[:3] + 0.25 * L / elements * ax


def ukflex_run(elements: int, t: np.ndarray, **run: Any) -> Tuple[np.ndarray, np.ndarray, float]:
    """Elbow and tip displacements ``(nt, 3)`` each at ``t`` and the wall time of ``simulate``
    (a freshly built System)."""
    system = ukflex.System(scene(elements))
    t0 = time.perf_counter()
    res = ukflex.simulate(system, T_END if t[-1] >= T_END else float(t[-1]), t_eval=t, **run)
    dt = time.perf_counter() - t0
    if res.status != 0:
        raise RuntimeError(f"ukflex: {res.message}")
    q = np.asarray(res.q)
    elbow = _node_point(system, q, f"a[{elements}]", elements).T - [L, 0, 0]
    tip = _node_point(system, q, f"b[{elements}]", elements).T - [L, L, 0]
    return elbow, tip, dt


def exudyn_run(elements: int, t: np.ndarray, steps: int, spectral_radius: float = 1.0,
               settings: Optional[Dict[str, Any]] = None) -> Tuple[np.ndarray, np.ndarray, float]:
    """The same frame in Exudyn: elbow and tip displacements interpolated at ``t`` from its
    ``steps`` steps over ``[0, t[-1]]`` (generalized-alpha at ``spectral_radius``), and the wall
    time of ``mbs.SolveDynamic``."""
    import exudyn as exu
    from exudyn.itemInterface import (Force, GenericJoint, MarkerNodeRigid, NodeRigidBodyEP, ObjectBeamGeometricallyExact,
                                      ObjectGround, MarkerBodyRigid, SensorNode)
    from exudyn.rigidBodyUtilities import RotationMatrix2EulerParameters, RotationMatrixZ

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    sec = exu.BeamSection()
    sec.stiffnessMatrix = np.diag([EA, GA, GA, GJ, EI, EI])
    sec.massPerLength = RHO_A
    sec.inertia = np.diag(RHO_J)
    le = L / elements
    rot_b = RotationMatrixZ(np.pi / 2)
    ep_a, ep_b = [1.0, 0.0, 0.0, 0.0], list(RotationMatrix2EulerParameters(rot_b))

    def member(start: np.ndarray, axis: np.ndarray, ep: List[float]) -> List[int]:
        nodes = [mbs.AddNode(NodeRigidBodyEP(referenceCoordinates=list(start + k * le * axis) + ep)) for k in range(elements + 1)]
        for n0, n1 in zip(nodes[:-1], nodes[1:]):
            mbs.AddObject(ObjectBeamGeometricallyExact(nodeNumbers=[n0, n1], physicsLength=le, sectionData=sec))
        return nodes

    na = member(np.zeros(3), np.array([1.0, 0, 0]), ep_a)
    nb = member(np.array([L, 0, 0]), np.array([0, 1.0, 0]), ep_b)
    ground = mbs.AddObject(ObjectGround())
    mg = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0, 0, 0]))
    mbs.AddObject(GenericJoint(markerNumbers=[mg, mbs.AddMarker(MarkerNodeRigid(nodeNumber=na[0]))], constrainedAxes=[1] * 6))
    m_elbow = mbs.AddMarker(MarkerNodeRigid(nodeNumber=na[-1]))
    # joint frames: the elbow node of a in its own axes (the world's), b's first node turned back
    mbs.AddObject(GenericJoint(markerNumbers=[m_elbow, mbs.AddMarker(MarkerNodeRigid(nodeNumber=nb[0]))],
                               rotationMarker1=rot_b.T, constrainedAxes=[1] * 6))
    mbs.AddLoad(Force(markerNumber=m_elbow, loadVector=[0, 0, 1.0], loadVectorUserFunction=lambda mbs, t, v: [0, 0, pulse(t)]))
    s_elbow = mbs.AddSensor(SensorNode(nodeNumber=na[-1], outputVariableType=exu.OutputVariableType.Displacement, storeInternal=True))
    s_tip = mbs.AddSensor(SensorNode(nodeNumber=nb[-1], outputVariableType=exu.OutputVariableType.Displacement, storeInternal=True))
    mbs.Assemble()
    ss = exu.SimulationSettings()
    t_end = float(t[-1])
    ss.timeIntegration.numberOfSteps = steps
    ss.timeIntegration.endTime = t_end
    ss.timeIntegration.generalizedAlpha.spectralRadius = spectral_radius
    ss.timeIntegration.verboseMode = 0
    ss.solutionSettings.writeSolutionToFile = False
    ss.solutionSettings.sensorsWritePeriod = t_end / steps
    for key, value in (settings or {}).items():  # e.g. "timeIntegration.verboseMode": 1
        *path, last = key.split(".")
        obj = ss
        for p in path:
            obj = getattr(obj, p)
        setattr(obj, last, value)
    t0 = time.perf_counter()
    mbs.SolveDynamic(ss)
    dt = time.perf_counter() - t0
    out = []
    for s in (s_elbow, s_tip):
        d = np.asarray(mbs.GetSensorStoredData(s))
        out.append(np.column_stack([np.interp(t, d[:, 0], d[:, c]) for c in (1, 2, 3)]))
    return out[0], out[1], dt


def gap(a: Tuple[np.ndarray, np.ndarray], b: Tuple[np.ndarray, np.ndarray]) -> float:
    """Largest distance between two histories of the elbow and the tip, over the largest
    displacement of ``b``."""
    d = max(np.max(np.linalg.norm(x - y, axis=1)) for x, y in zip(a, b))
    return float(d / max(np.max(np.linalg.norm(y, axis=1)) for y in b))


def _log(msg: str) -> None:
    print(f"[right-angle-cantilever {time.perf_counter() - _T0:7.1f} s] {msg}", file=sys.stderr, flush=True)


_T0 = time.perf_counter()


def main(argv: Optional[List[str]] = None) -> int:
    """Per mesh (elements per member): ukflex's default ``simulate()`` and a tight RADAU5 run,
    Exudyn at ``STEPS`` steps; each run's error against its own code's tightest run
    on that mesh (time convergence), the gap between the codes' tightest runs (the physics), the
    elbow's and the tip's out-of-plane peaks and the wall times (one run each)."""
    t = np.linspace(0.0, T_END, 301)
    lines = ["| mesh (el./member) | run | elbow max u_z | tip max u_z | to its own code's tightest run | to the other code's tightest run | wall time [s] |",
             "|---:|---|---:|---:|---:|---:|---:|"]
    finest: Dict[int, Tuple[Tuple[np.ndarray, np.ndarray, float], ...]] = {}
    for n in (5, 10):
        runs: Dict[str, Tuple[np.ndarray, np.ndarray, float]] = {}
        _log(f"{n} el./member: ukflex default simulate()")
        runs["ukflex default simulate()"] = ukflex_run(n, t)
        _log(f"{n} el./member: ukflex RADAU5 rtol 1e-9")
        runs["ukflex RADAU5 rtol 1e-9"] = ukflex_run(n, t, method="RADAU5", rtol=1e-9, atol=1e-10)
        for steps in STEPS:
            _log(f"{n} el./member: Exudyn {steps} steps")
            try:
                runs[f"Exudyn gen-alpha {steps} steps"] = exudyn_run(n, t, steps)
            except Exception as exc:  # Exudyn's Newton failing at too large a step: reported
                lines.append(f"| {n} | Exudyn gen-alpha {steps} steps | failed: {type(exc).__name__}: {str(exc)[:60]} | | | | |")
        ref_u = runs["ukflex RADAU5 rtol 1e-9"]
        ref_x = [r for k, r in runs.items() if k.startswith("Exudyn")][-1]
        for name, r in runs.items():
            own, other = (ref_u, ref_x) if name.startswith("ukflex") else (ref_x, ref_u)
            lines.append(f"| {n} | {name} | {np.max(np.abs(r[0][:, 2])):.4f} | {np.max(np.abs(r[1][:, 2])):.4f} | "
                         f"{gap(r[:2], own[:2]):.2e} | {gap(r[:2], other[:2]):.2e} | {r[2]:.2f} |")
        finest[n] = (ref_u, ref_x)
    _log("20 el./member: ukflex RADAU5 rtol 1e-9 (the mesh reference)")
    fine = ukflex_run(20, t, method="RADAU5", rtol=1e-9, atol=1e-10)
    lines += ["", "| mesh (el./member) | tightest run | to ukflex 20 el./member, RADAU5 rtol 1e-9 |", "|---:|---|---:|"]
    for n, (ru, rx) in finest.items():
        lines += [f"| {n} | ukflex RADAU5 rtol 1e-9 | {gap(ru[:2], fine[:2]):.2e} |", f"| {n} | Exudyn finest step | {gap(rx[:2], fine[:2]):.2e} |"]
    lines.append(f"ukflex 20 el./member: elbow max u_z {np.max(np.abs(fine[0][:, 2])):.4f}, tip max u_z {np.max(np.abs(fine[1][:, 2])):.4f}")
    print("gap = max over the 301 outputs (0.1 s) of |elbow and tip displacement - reference| / max |reference displacement|")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
