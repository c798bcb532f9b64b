"""ANCF wire pendulum: time per step of the implicit methods against the number of elements,
ukflex sparse and dense Newton matrices and Exudyn's generalized-alpha with its sparse solver,
in one run (docs/scale.md, "The implicit methods").

A steel wire (1 m, d = 2 mm, E = 210 GPa, rho = 7850 kg/m^3) of N ANCF cable elements, pinned
at one end, released horizontal from rest under gravity; fixed step 1e-4 s, ``--steps`` steps
from the start.  Timed: the whole public call that integrates (ukflex: ``System.integrate``;
Exudyn: ``mbs.SolveDynamic``), model building excluded for both.  Repetitions are interleaved
(every configuration once per round); the figures are medians over the rounds.

Exudyn: ``ObjectANCFCable2D`` with ``useReducedOrderIntegration=2`` (the axial and bending rules
ukflex uses), ``ObjectJointRevolute2D`` to the ground, generalized-alpha (rho_inf 0.9, index 3,
fixed step), ``LinearSolverType.EigenSparse``, modified Newton; its relative Newton tolerance is
the first of 1e-8 (its default), 1e-6, 1e-4 at which every run of that N converges (at 1e-8 it
fails on this wire at every N tried).  Both codes end at the same tip position (printed).

Usage::

    python benches/ancf_wire.py                      # N = 8 .. 1024, 100 steps, 5 rounds
    python benches/ancf_wire.py --elements 8 32 128 --steps 50 --repeat 3 --no-exudyn
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import statistics
import time
from typing import Any, Dict, List

import numpy as np

import ukflex
from ukflex import Scene
from ukflex.model.scene import Circular

L, D, RHO, E = 1.0, 0.002, 7850.0, 2.1e11
H = 1e-4


def ukflex_wire(elements: int):
    s = Scene(gravity=(0.0, -9.81))
    b = s.cable("wire", length=L, elements=elements, section=Circular(D), density=RHO,
               youngs_modulus=E)
    s.revolute(s.ground.point(0.0, 0.0), b.at(0.0), name="pin")
    return s.build()


def ukflex_run(system, method: str, linear_solver: str, steps: int):
    t0 = time.perf_counter()
    out = system.integrate(0.0, system.y0, steps * H, method=method, step=H, linear_solver=linear_solver)
    wall = time.perf_counter() - t0
    if out["status"] != 0:
        raise RuntimeError(f"{method} {linear_solver}: {out['message']}")
    y = np.asarray(out["y"])[:, -1]
    n = system.n_coords
    return wall / out["naccept"], (float(y[n - 4]), float(y[n - 3]))


class ExudynWire:
    """The same wire in Exudyn (built once; each solve starts from the initial state)."""

    def __init__(self, elements: int, steps: int):
        import exudyn as exu
        import exudyn.itemInterface as ii

        self.exu = exu
        self.SC = exu.SystemContainer()
        mbs = self.mbs = self.SC.AddSystem()
        area, inertia = math.pi * D**2 / 4, math.pi * D**4 / 64
        ground = mbs.AddObject(ii.ObjectGround())
        mg = mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=ground, localPosition=[0, 0, 0]))
        le = L / elements
        self.nodes = [mbs.AddNode(ii.NodePoint2DSlope1(referenceCoordinates=[i * le, 0.0, 1.0, 0.0]))
                      for i in range(elements + 1)]
        for i in range(elements):
            e = mbs.AddObject(ii.ObjectANCFCable2D(length=le, massPerLength=RHO * area, bendingStiffness=E * inertia,
                                                   axialStiffness=E * area, nodeNumbers=[self.nodes[i], self.nodes[i + 1]],
                                                   useReducedOrderIntegration=2))
            mbs.AddLoad(ii.LoadMassProportional(markerNumber=mbs.AddMarker(ii.MarkerBodyMass(bodyNumber=e)),
                                                loadVector=[0.0, -9.81, 0.0]))
        m0 = mbs.AddMarker(ii.MarkerNodePosition(nodeNumber=self.nodes[0]))
        mbs.AddObject(ii.ObjectJointRevolute2D(markerNumbers=[mg, m0]))
        mbs.Assemble()
        self.steps = steps
        self.rtol = None
        for rtol in (1e-8, 1e-6, 1e-4):  # the tightest Newton tolerance that converges
            if self._solve(rtol) is not None:
                self.rtol = rtol
                break
        if self.rtol is None:
            raise RuntimeError(f"Exudyn did not converge on the wire with N = {elements}")

    def _settings(self, rtol: float):
        exu = self.exu
        s = exu.SimulationSettings()
        ti = s.timeIntegration
        ti.endTime, ti.numberOfSteps, ti.adaptiveStep, ti.verboseMode = self.steps * H, self.steps, False, 0
        ti.generalizedAlpha.spectralRadius = 0.9
        ti.newton.useModifiedNewton = True
        ti.newton.relativeTolerance = rtol
        s.solution.file.write = False
        s.solution.sensors.active = False
        s.show.computationTime = False
        s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
        return s

    def _solve(self, rtol: float):
        import contextlib
        import io

        sim = self._settings(rtol)
        t0 = time.perf_counter()
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                self.mbs.SolveDynamic(sim)
        except Exception:
            return None
        return (time.perf_counter() - t0) / self.steps

    def run(self):
        per = self._solve(self.rtol)
        if per is None:
            raise RuntimeError("Exudyn failed")
        tip = self.mbs.GetNodeOutput(self.nodes[-1], self.exu.OutputVariableType.Position)
        return per, (float(tip[0]), float(tip[1]))


def exponent(ns: List[int], ts: List[float], lo: int, hi: int) -> float:
    d = dict(zip(ns, ts))
    if lo not in d or hi not in d:
        return float("nan")
    return math.log(d[hi] / d[lo]) / math.log(hi / lo)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, nargs="+", default=[8, 16, 32, 64, 128, 256, 512, 1024])
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--dense-max", type=int, default=512, help="largest N run with the dense Newton matrices")
    ap.add_argument("--no-exudyn", action="store_true")
    ap.add_argument("--csv", default=os.path.join(os.path.dirname(__file__), "data", "ancf_wire.csv"))
    a = ap.parse_args()
    try:
        import exudyn  # noqa: F401
        have_exudyn = not a.no_exudyn
    except ImportError:
        have_exudyn = False
    configs: List[tuple] = []
    systems: Dict[int, Any] = {}
    peers: Dict[int, Any] = {}
    for N in a.elements:
        systems[N] = ukflex_wire(N)
        for method in ("RADAU5M", "GENALPHA"):
            configs.append((N, "ukflex", method, "sparse"))
            if N <= a.dense_max:
                configs.append((N, "ukflex", method, "dense"))
        if have_exudyn:
            peers[N] = ExudynWire(N, a.steps)
            configs.append((N, "exudyn", "GA", f"EigenSparse, Newton rtol {peers[N].rtol:g}"))
    times: Dict[tuple, List[float]] = {c: [] for c in configs}
    tips: Dict[tuple, tuple] = {}
    t_start = time.perf_counter()
    for r in range(a.repeat):
        for c in configs:
            N, code, method, solver = c
            if code == "ukflex":
                per, tip = ukflex_run(systems[N], method, solver, a.steps)
            else:
                per, tip = peers[N].run()
            times[c].append(per)
            tips[c] = tip
        print(f"round {r + 1}/{a.repeat} done ({time.perf_counter() - t_start:.0f} s)", flush=True)
    load = os.getloadavg()[0]
    med = {c: statistics.median(v) for c, v in times.items()}
    print(f"\nANCF wire, h = {H:g} s, {a.steps} steps from rest, medians of {a.repeat} interleaved rounds, "
          f"load average {load:.1f}; time per step [us]")
    rows = []
    for N in a.elements:
        n = systems[N].n_coords
        line = {"N": N, "n": n}
        for method in ("RADAU5M", "GENALPHA"):
            for solver in ("sparse", "dense"):
                c = (N, "ukflex", method, solver)
                line[f"{method} {solver}"] = med[c] * 1e6 if c in med else float("nan")
        pc = [c for c in configs if c[0] == N and c[1] == "exudyn"]
        line["Exudyn GA sparse"] = med[pc[0]] * 1e6 if pc else float("nan")
        line["Exudyn Newton rtol"] = peers[N].rtol if pc else float("nan")
        line["tip y ukflex"] = tips[(N, "ukflex", "GENALPHA", "sparse")][1]
        line["tip y Exudyn"] = tips[pc[0]][1] if pc else float("nan")
        rows.append(line)
    keys = list(rows[0].keys())
    print(" | ".join(f"{k:>16}" for k in keys))
    for row in rows:
        print(" | ".join(f"{row[k]:16.6g}" if isinstance(row[k], float) else f"{row[k]:>16}" for k in keys))
    print("\nratios in this run:")
    for row in rows:
        parts = []
        for method in ("RADAU5M", "GENALPHA"):
            d, s = row[f"{method} dense"], row[f"{method} sparse"]
            if d == d:
                parts.append(f"{method} dense/sparse {d / s:.2f}")
        if row["Exudyn GA sparse"] == row["Exudyn GA sparse"]:
            parts.append(f"Exudyn/ukflex GENALPHA {row['Exudyn GA sparse'] / row['GENALPHA sparse']:.2f}")
            parts.append(f"Exudyn/ukflex RADAU5M {row['Exudyn GA sparse'] / row['RADAU5M sparse']:.2f}")
        print(f"  N = {row['N']:5}: " + ", ".join(parts))
    ns = [r["N"] for r in rows]
    print("\ngrowth exponents (log t(N2)/t(N1) / log(N2/N1)):")
    for col in ("RADAU5M sparse", "GENALPHA sparse", "RADAU5M dense", "GENALPHA dense", "Exudyn GA sparse"):
        ts = [r[col] for r in rows]
        print(f"  {col:18}: 32..512 {exponent(ns, ts, 32, 512):.2f}, 128..1024 {exponent(ns, ts, 128, 1024):.2f}")
    os.makedirs(os.path.dirname(a.csv), exist_ok=True)
    with open(a.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    print(f"\nwritten {a.csv}; wall {time.perf_counter() - t_start:.0f} s")


if __name__ == "__main__":
    main()
