"""MBS benchmark A02 (the N four-bar mechanism), N = 40, 20 s: ukflex's default against Exudyn's
fastest setting at the benchmark's high precision, timed around the whole solve call in one run.

The error is the largest deviation of B0's position and velocity (x, y, vx, vy) from the exact
parallelogram motion (one pendulum equation in the crank angle, DOP853 at rtol 1e-13) at the
benchmark's 400 output steps; high precision is 1e-3, low precision 1e-1.

* ukflex: ``simulate(scenes.n_four_bar(loops=40).build(), 20, t_eval=...)`` (method="auto",
  default rtol) and a few tolerances; the time is the whole ``simulate`` call on a freshly built
  System (build excluded for both codes).
* Exudyn (optional: ``pip install exudyn``, tested with 1.13.6): ObjectRigidBody2D links,
  ObjectJointRevolute2D, mass-proportional gravity, generalized-alpha (index 3, rho_inf 0.9) at
  fixed steps h = 2e-3 .. 1e-4 with modified and full Newton and its sparse solver; the time is
  ``SolveDynamic``; also h = 2e-3, 1e-3 with its adaptive step (halved where Newton fails). A
  run that fails or misses the level does not count.

Medians of interleaved repetitions (every configuration once per repetition, alternating order).

    python benches/peers/a02_side_by_side.py --repeat 3          # ~4 min (N = 40); writes benches/data/a02_side_by_side.csv
    python benches/peers/a02_side_by_side.py --loops 10 --repeat 3   # ~1 min
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import statistics
import time
import warnings

import numpy as np
from scipy.integrate import solve_ivp

import ukflex
from ukflex import scenes

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.normpath(os.path.join(HERE, "..", "data"))
T_END = 20.0
OUT = np.linspace(0.0, T_END, 401)
G = 9.81
ANGLE = math.pi / 4
LEVELS = (1e-3, 1e-1)

try:
    import exudyn as exu
    from exudyn import itemInterface as ii
except ImportError:  # pragma: no cover
    exu = None


def exact(loops: int, t: np.ndarray) -> np.ndarray:
    J, Gm = (loops + 1) / 3 + loops, G * ((loops + 1) / 2 + loops)
    sol = solve_ivp(lambda _, y: [y[1], -Gm * math.cos(y[0]) / J], (0.0, float(t[-1])),
                    [ANGLE, -1.0 / math.sin(ANGLE)], method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
    th, om = sol.y
    return np.array([np.cos(th), np.sin(th), -np.sin(th) * om, np.cos(th) * om])


def ukflex_run(loops: int, **kw) -> dict:
    system = scenes.n_four_bar(loops=loops).build()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        res = ukflex.simulate(system, T_END, t_eval=OUT, **kw)
        wall = time.perf_counter() - t0
    sl = system.body_slice("crank0")
    q, qd = res.q[sl], res.qd[sl]
    th, om = q[2], qd[2]
    b0 = np.array([q[0] + np.cos(th), q[1] + np.sin(th), qd[0] - np.sin(th) * om, qd[1] + np.cos(th) * om])
    return {"wall": wall, "b0": b0, "ok": res.status == 0 and res.t.size == OUT.size, "steps": res.extra.get("naccept"),
            "method": res.method}


def exudyn_build(loops: int):
    L, m = 1.0, 1.0
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(ii.ObjectGround(referencePosition=[0, 0, 0]))
    c, s = math.cos(ANGLE), math.sin(ANGLE)
    om = -1.0 / (L * s)
    tips, b0 = [], None
    for k in range(loops + 1):
        n = mbs.AddNode(ii.NodeRigidBody2D(referenceCoordinates=[k * L + 0.5 * L * c, 0.5 * L * s, ANGLE],
                                           initialVelocities=[-0.5 * L * s * om, 0.5 * L * c * om, om]))
        o = mbs.AddObject(ii.ObjectRigidBody2D(mass=m, inertia=m * L**2 / 12, nodeNumber=n))
        mg = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=ground, localPosition=[k * L, 0, 0]))
        mb = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=o, localPosition=[-0.5 * L, 0, 0]))
        mbs.AddObject(ii.ObjectJointRevolute2D(markerNumbers=[mg, mb]))
        tips.append(mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=o, localPosition=[0.5 * L, 0, 0])))
        mbs.AddLoad(ii.LoadMassProportional(markerNumber=mbs.AddMarker(ii.MarkerBodyMass(bodyNumber=o)),
                                            loadVector=[0, -G, 0]))
        if k == 0:
            b0 = o
    for k in range(loops):
        n = mbs.AddNode(ii.NodeRigidBody2D(referenceCoordinates=[k * L + L * c + 0.5 * L, L * s, 0.0],
                                           initialVelocities=[-L * s * om, L * c * om, 0.0]))
        o = mbs.AddObject(ii.ObjectRigidBody2D(mass=m, inertia=m * L**2 / 12, nodeNumber=n))
        ma = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=o, localPosition=[-0.5 * L, 0, 0]))
        mb = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=o, localPosition=[0.5 * L, 0, 0]))
        mbs.AddObject(ii.ObjectJointRevolute2D(markerNumbers=[tips[k], ma]))
        mbs.AddObject(ii.ObjectJointRevolute2D(markerNumbers=[tips[k + 1], mb]))
        mbs.AddLoad(ii.LoadMassProportional(markerNumber=mbs.AddMarker(ii.MarkerBodyMass(bodyNumber=o)),
                                            loadVector=[0, -G, 0]))
    sp = mbs.AddSensor(ii.SensorBody(bodyNumber=b0, localPosition=[0.5 * L, 0, 0], storeInternal=True,
                                     outputVariableType=exu.OutputVariableType.Position))
    sv = mbs.AddSensor(ii.SensorBody(bodyNumber=b0, localPosition=[0.5 * L, 0, 0], storeInternal=True,
                                     outputVariableType=exu.OutputVariableType.Velocity))
    mbs.Assemble()
    return SC, mbs, sp, sv


def exudyn_run(loops: int, h: float, modified: bool, adaptive: bool = False) -> dict:
    SC, mbs, sp, sv = exudyn_build(loops)
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime = T_END
    ti.numberOfSteps = int(round(T_END / h))
    ti.adaptiveStep = adaptive  # True: Exudyn halves the step where Newton fails, and grows it back
    ti.verboseMode = 0
    ti.generalizedAlpha.spectralRadius = 0.9
    ti.newton.useModifiedNewton = modified
    s.solution.file.write = False
    s.solution.sensors.writePeriod = T_END / 400
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.show.computationTime = False
    ok = True
    t0 = time.perf_counter()
    try:
        mbs.SolveDynamic(s)
    except Exception:  # a Newton failure at a fixed step ends the run
        ok = False
    wall = time.perf_counter() - t0
    P, V = mbs.GetSensorStoredData(sp), mbs.GetSensorStoredData(sv)
    if P is None or len(P) < 2:
        return {"wall": wall, "b0": None, "ok": False}
    b0 = np.array([np.interp(OUT, P[:, 0], P[:, 1]), np.interp(OUT, P[:, 0], P[:, 2]),
                   np.interp(OUT, V[:, 0], V[:, 1]), np.interp(OUT, V[:, 0], V[:, 2])])
    return {"wall": wall, "b0": b0, "ok": ok and P[-1, 0] > T_END - 1e-9}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--loops", type=int, default=40)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(DATA, "a02_side_by_side.csv"))
    args = ap.parse_args()
    ref = exact(args.loops, OUT)
    configs = [("ukflex default (auto, rtol 1e-6)", lambda: ukflex_run(args.loops))]
    for rtol in (1e-5, 1e-7, 1e-8):
        configs.append((f"ukflex auto rtol {rtol:g}", lambda r=rtol: ukflex_run(args.loops, rtol=r)))
    if exu is not None:
        for modified in (True, False):
            for h in (2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4):
                configs.append((f"Exudyn GA h {h:g} {'modified' if modified else 'full'} Newton",
                                lambda h=h, m=modified: exudyn_run(args.loops, h, m)))
        for h in (2e-3, 1e-3):
            configs.append((f"Exudyn GA h {h:g} modified Newton adaptive",
                            lambda h=h: exudyn_run(args.loops, h, True, adaptive=True)))
    else:
        print("exudyn is not installed: the peer series is skipped (`pip install exudyn`, tested with 1.13.6)")
    walls = {name: [] for name, _ in configs}
    errors = {}
    for rep in range(args.repeat):
        order = configs if rep % 2 == 0 else configs[::-1]
        for name, fn in order:
            r = fn()
            walls[name].append(r["wall"])
            err = float(np.abs(r["b0"] - ref).max()) if r["b0"] is not None and r["ok"] else math.inf
            errors[name] = max(errors.get(name, 0.0), err)
            print(f"  rep {rep} {name}: {r['wall']:.3f} s, error {err:.2e}", flush=True)
    rows = []
    for name, _ in configs:
        rows.append({"config": name, "median_s": statistics.median(walls[name]), "max_error": errors[name]})
    print(f"\nA02, N = {args.loops}, 20 s, 400 outputs; {exu.__version__ if exu else 'no exudyn'}; medians of {args.repeat}")
    for r in rows:
        print(f"  {r['config']:45s} {r['median_s']:8.3f} s  error {r['max_error']:.2e}")
    for level in LEVELS:
        ok = [r for r in rows if r["max_error"] <= level]
        uk = [r for r in ok if r["config"].startswith("ukflex")]
        ex = [r for r in ok if r["config"].startswith("Exudyn")]
        default = next((r for r in uk if r["config"].startswith("ukflex default")), None)
        if ex:
            best_ex = min(ex, key=lambda r: r["median_s"])
            msg = f"level {level:g}: Exudyn fastest {best_ex['config']} {best_ex['median_s']:.3f} s"
            if default:
                msg += f"; ukflex default {default['median_s']:.3f} s: {best_ex['median_s'] / default['median_s']:.1f}x"
            if uk:
                best_uk = min(uk, key=lambda r: r["median_s"])
                msg += f"; ukflex fastest {best_uk['config']} {best_uk['median_s']:.3f} s: {best_ex['median_s'] / best_uk['median_s']:.1f}x"
            print(msg)
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["config", "median_s", "max_error"])
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
