"""``python -m studies spatial-flexible-exudyn``: the 3D flexible pendulum of
docs/spatial-flexible.md side by side with Exudyn's ``ObjectFFRFreducedOrder`` (Exudyn 1.13.6),
both on the same FE model and the same mode basis.

The pendulum: a 0.5 m x 20 mm x 20 mm bar (rho = 7850 kg/m^3, E = 2.1 GPa, nu = 0.3; 10 x 1 x 1
boxes of P2 tetrahedra), 4 modes clamped at the pivot face, a spherical joint at that face's
centroid, spin 3 rad/s about z, gravity -z, 0.3 s. Output: the world position of the tip face's
centroid (the mean of its nodes: ukflex's interface ``B``, Exudyn's
``MarkerSuperElementPosition`` with equal weights) at 301 instants.

Exudyn computes its own invariants from the same nodes, mass and stiffness matrices and mode
basis (the nodal-based FFRF with modal reduction of Zwoelfer and Gerstmayr), so the two are
independent implementations of the same model. The reference is ukflex DOPRI5 at rtol 1e-11;
Exudyn runs generalized-alpha (spectral radius 1) at growing step counts; every run is timed
around its whole solve call (a fresh system each time, median of 3).
"""

from __future__ import annotations

import sys
import time
from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import scipy.sparse as sp

import ukflex
from ukflex import fe3

T_END = 0.3
OMEGA0 = (0.0, 0.0, 3.0)
GRAVITY = (0.0, 0.0, -9.81)
LENGTH = 0.5


def model() -> Tuple[fe3.FlexibleData3, Any]:
    mesh = fe3.bar_mesh(LENGTH, 0.02, 0.02, (10, 1, 1))
    data = fe3.from_mesh(mesh, density=7850.0, youngs_modulus=2.1e9, poisson_ratio=0.3,
                         interfaces={"A": lambda x: x[:, 0] < 1e-9, "B": lambda x: x[:, 0] > LENGTH - 1e-9},
                         modes=4, frame=("clamped", "A"))
    return data, mesh


def ukflex_tip(data: fe3.FlexibleData3, t: np.ndarray, **run: Any) -> Tuple[np.ndarray, float]:
    """Tip-centroid positions (nt, 3) and the wall time of ``ukflex.simulate``."""
    s = ukflex.SpatialScene(gravity=GRAVITY)
    bar = s.flexible_body("bar", data, angular_velocity=OMEGA0)
    s.spherical(s.ground.marker((0, 0, 0)), bar.interface("A"))
    system = ukflex.System(s)
    t0 = time.perf_counter()
    res = ukflex.simulate(system, T_END, t_eval=t, **run)
    dt = time.perf_counter() - t0
    q = np.asarray(res.q).T
    tip = data.interfaces["B"]
    out = np.empty((q.shape[0], 3))
    for k, qk in enumerate(q):
        e0, e1, e2, e3 = qk[3:7] / np.linalg.norm(qk[3:7])
        rot = np.array([[1 - 2 * (e2 * e2 + e3 * e3), 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2)],
                        [2 * (e1 * e2 + e0 * e3), 1 - 2 * (e1 * e1 + e3 * e3), 2 * (e2 * e3 - e0 * e1)],
                        [2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), 1 - 2 * (e1 * e1 + e2 * e2)]])
        out[k] = qk[0:3] + rot @ (np.asarray(tip.point) + tip.phi.T @ qk[7:])
    return out, dt


def exudyn_tip(data: fe3.FlexibleData3, mesh: Any, t: np.ndarray, steps: int, user_functions: bool = False) -> Tuple[np.ndarray, float]:
    """The same pendulum in Exudyn: tip-centroid positions at ``t`` (interpolated from its
    steps) and the wall time of ``mbs.SolveDynamic``. ``user_functions``: Exudyn's Python
    user-function variant of the object (its gravity written out as ``Psi^T M Phi_t A^T g``)
    instead of the C++ one (gravity as a ``LoadMassProportional``)."""
    import exudyn as exu
    from exudyn.FEM import FEMinterface, ObjectFFRFreducedOrderInterface
    from exudyn.itemInterface import MarkerBodyPosition, MarkerSuperElementPosition, ObjectGround, SensorMarker, SphericalJoint

    nodes, k, ms = fe3.solid_matrices(mesh, density=7850.0, youngs_modulus=2.1e9, poisson_ratio=0.3)
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    fem = FEMinterface()
    fem.nodes = {"Position": nodes}
    fem.massMatrix = sp.kron(ms, sp.eye(3)).tocsr()
    fem.stiffnessMatrix = k.tocsr()
    fem.modeBasis = {"matrix": data.info["modes"], "type": "NormalModes"}
    cms = ObjectFFRFreducedOrderInterface(fem)
    add = (lambda **kw: cms.AddObjectFFRFreducedOrderWithUserFunctions(exu=exu, mbs=mbs, **kw)) if user_functions else \
        (lambda **kw: cms.AddObjectFFRFreducedOrder(mbs, **kw))
    obj = add(positionRef=[0, 0, 0], initialVelocity=[0, 0, 0], initialAngularVelocity=list(OMEGA0), gravity=list(GRAVITY))
    body = obj["oFFRFreducedOrder"]

    def face(name: str) -> int:
        idx = [int(i) for i in data.interfaces[name].nodes]
        return mbs.AddMarker(MarkerSuperElementPosition(bodyNumber=body, meshNodeNumbers=idx, weightingFactors=[1.0 / len(idx)] * len(idx)))

    ma, mb = face("A"), face("B")
    ground = mbs.AddObject(ObjectGround(referencePosition=[0, 0, 0]))
    mg = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0, 0, 0]))
    mbs.AddObject(SphericalJoint(markerNumbers=[mg, ma], constrainedAxes=[1, 1, 1]))
    sensor = mbs.AddSensor(SensorMarker(markerNumber=mb, outputVariableType=exu.OutputVariableType.Position, storeInternal=True))
    mbs.Assemble()
    ss = exu.SimulationSettings()
    ss.timeIntegration.numberOfSteps = steps
    ss.timeIntegration.endTime = T_END
    ss.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    ss.timeIntegration.verboseMode = 0
    ss.solutionSettings.writeSolutionToFile = False
    ss.solutionSettings.sensorsWritePeriod = T_END / steps
    t0 = time.perf_counter()
    mbs.SolveDynamic(ss)
    dt = time.perf_counter() - t0
    d = np.asarray(mbs.GetSensorStoredData(sensor))
    return np.column_stack([np.interp(t, d[:, 0], d[:, c]) for c in (1, 2, 3)]), dt


def _median(f, reps: int = 3) -> Tuple[np.ndarray, float]:
    outs = [f() for _ in range(reps)]
    return outs[-1][0], float(np.median([o[1] for o in outs]))


CASES = (("gravity -z, spin 3 rad/s about z", (0.0, 0.0, -9.81), (0.0, 0.0, 3.0)),
         ("no gravity, tumbling (0, 2, 3) rad/s", (0.0, 0.0, 0.0), (0.0, 2.0, 3.0)))


def report() -> str:
    global GRAVITY, OMEGA0
    data, mesh = model()
    t = np.linspace(0.0, T_END, 301)
    lines = [f"modes {np.round(data.info['frequencies'], 3).tolist()} Hz; reference: ukflex DOPRI5 rtol 1e-11; "
             "error = max over the 301 outputs of |tip - reference| / length"]
    for title, GRAVITY, OMEGA0 in CASES:
        ref, _ = ukflex_tip(data, t, method="DOPRI5", rtol=1e-11, atol=1e-13)
        lines += ["", f"{title}:", "", "| run | error | wall time [s] |", "|---|---:|---:|"]
        runs = [("ukflex default (auto, rtol 1e-6)", lambda: ukflex_tip(data, t, rtol=1e-6)),
                ("ukflex auto, rtol 1e-8", lambda: ukflex_tip(data, t, rtol=1e-8))]
        runs += [(f"Exudyn generalized-alpha, {n} steps", (lambda n=n: exudyn_tip(data, mesh, t, n))) for n in (300, 1200, 4800, 19200)]
        for name, f in runs:
            print(f"[spatial-flexible-exudyn] {title}: {name}", file=sys.stderr)
            tip, dt = _median(f)
            err = np.max(np.linalg.norm(tip - ref, axis=1)) / LENGTH
            lines.append(f"| {name} | {err:.2e} | {dt:.4f} |")
    return "\n".join(lines)


def main(argv: Optional[List[str]] = None) -> int:
    print(report())
    return 0
