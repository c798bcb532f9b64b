"""Every stage a user goes through, at scale (docs/scale.md, "Every stage"): the whole default
``simulate`` call on a chain, the build (initial-state correction) of the ANCF slider-crank, and
the implicit methods' time per step on the MBS benchmark A02 (N four-bar), in one run.

* ``chain``: ``simulate(system, 1e-3)`` with default settings (``method="auto"``: its modal
  analysis and the DOPRI5 run), the whole call, for ``scenes.chain(links=K).build()``; the build
  timed separately.  For K <= ``--dense-max`` also with the dense modal analysis (the same System
  with ``SPARSE_MODES_MIN`` raised): the ratio in this run.
* ``build``: ``scenes.slider_crank(elements=N, formulation="ancf").build()`` whole (scene and
  System), as given (consistent) and with the crank turned 0.05 rad off (Newton iterations).
* ``a02``: A02 with N = 40 (2N + 1 = 81 rods of 1 m and 1 kg, N + 1 cranks pinned to the ground
  1 m apart at 45 degrees, N couplers joining their tips, gravity -y; n = 243, m = 242),
  GENALPHA and RADAU5M at a fixed step of 1e-3 s for 200 steps, ``System.integrate`` whole,
  sparse and dense Newton matrices.

Every measurement runs in a fresh process (``--worker``; its start-up is not timed: a long-lived
process that has built many large systems spends more in its allocator and garbage collector).
``--baseline PYTHON``: the same measurements also with another build of ukflex (e.g. the code
before this change, installed in another virtualenv), interleaved with this one's, round by
round.  Medians of ``--repeat`` rounds.

Usage::

    python benches/scale_stages.py
    python benches/scale_stages.py --baseline /path/to/other/venv/bin/python --chain 64 256 800
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from typing import Any, Dict, List


def a02(n: int, theta0: float = math.pi / 4):
    """The MBS benchmark A02 (N four-bar mechanism) as a Scene; its exact motion is a
    one-degree-of-freedom ODE (crank angle), started with the tip velocity 1 m/s along x."""
    from ukflex import Scene

    s = Scene(gravity=(0.0, -9.81))
    m, L = 1.0, 1.0
    inertia = m * L**2 / 12
    c, sn = math.cos(theta0), math.sin(theta0)
    om = -1.0 / (L * sn)
    cranks = []
    for k in range(n + 1):
        b = s.rigid_body(f"crank{k}", mass=m, inertia=inertia, com=(L / 2, 0), position=(k * L, 0), angle=theta0,
                         angular_velocity=om)
        s.revolute(s.ground.point(k * L, 0), b.point(0, 0))
        cranks.append(b)
    for k in range(n):
        cb = s.rigid_body(f"coupler{k}", mass=m, inertia=inertia, com=(L / 2, 0), position=(k * L + c, sn), angle=0.0,
                          velocity=(-sn * om * L, c * om * L))
        s.revolute(cranks[k].point(L, 0), cb.point(0, 0))
        s.revolute(cranks[k + 1].point(L, 0), cb.point(L, 0))
    return s


def measure(kind: str, size: int, variant: str) -> float:
    """Seconds of one measurement (in this process's ukflex)."""
    import ukflex
    from ukflex import scenes

    if kind == "chain_build":
        t0 = time.perf_counter()
        scenes.chain(links=size).build()
        return time.perf_counter() - t0
    if kind == "chain_simulate":
        system = scenes.chain(links=size).build()
        if variant == "dense":
            system.SPARSE_MODES_MIN = 10**9
        t0 = time.perf_counter()
        res = ukflex.simulate(system, 1e-3)
        wall = time.perf_counter() - t0
        assert res.status == 0, res.message
        return wall
    if kind == "build":
        t0 = time.perf_counter()
        scene = scenes.slider_crank(elements=size, formulation="ancf")
        if variant == "inconsistent":
            d = scene.to_dict()
            for b in d["bodies"]:
                if b["name"] == "crank":
                    b["angle"] = 0.05
            ukflex.System(d)
        else:
            scene.build()
        return time.perf_counter() - t0
    if kind == "a02":
        system = a02(size).build()
        method, solver = variant.split("/")
        kw = {} if solver == "default" else {"linear_solver": solver}
        t0 = time.perf_counter()
        out = system.integrate(0.0, system.y0, 0.2, method=method, step=1e-3, **kw)
        wall = time.perf_counter() - t0
        assert out["status"] == 0, out["message"]
        return wall / out["naccept"]
    raise ValueError(kind)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chain", type=int, nargs="*", default=[64, 128, 256, 512, 800, 1024, 2048, 4096])
    ap.add_argument("--dense-max", type=int, default=256, help="largest K also run with the dense modal analysis")
    ap.add_argument("--build", type=int, nargs="*", default=[256, 512, 1024, 2048, 4096])
    ap.add_argument("--a02", type=int, nargs="*", default=[40])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--baseline", help="a Python whose ukflex is the build to compare with")
    ap.add_argument("--baseline-max", type=int, default=1024, help="largest size the baseline runs (it is slow)")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:  # measure in this process and print the result as JSON
        kind, size, variant = json.loads(a.worker)
        print(json.dumps(measure(kind, int(size), variant)))
        return
    cases: List[tuple] = []
    for k in a.chain:
        cases.append(("chain_build", k, "-"))
        cases.append(("chain_simulate", k, "sparse"))
        if k <= a.dense_max:
            cases.append(("chain_simulate", k, "dense"))
    for n in a.build:
        cases += [("build", n, "consistent"), ("build", n, "inconsistent")]
    for n in a.a02:
        for method in ("GENALPHA", "RADAU5M"):
            cases += [("a02", n, f"{method}/sparse"), ("a02", n, f"{method}/dense")]
    def base_of(c):
        """The baseline's counterpart of a case (None: not run there)."""
        kind, size, variant = c
        if not a.baseline or size > a.baseline_max or (kind == "chain_simulate" and variant == "dense"):
            return None
        return (kind, size, variant.split("/")[0] + "/default") if kind == "a02" else c

    def worker(python, case):
        out = subprocess.run([python, __file__, "--worker", json.dumps(list(case))], capture_output=True, text=True,
                             check=True)
        return float(out.stdout.strip().splitlines()[-1])

    times: Dict[tuple, List[float]] = {}
    t_start = time.perf_counter()
    for r in range(a.repeat):
        done = set()
        for c in cases:
            times.setdefault(("this",) + c, []).append(worker(sys.executable, c))
            b = base_of(c)
            if b is not None and b not in done:
                done.add(b)
                times.setdefault(("baseline",) + b, []).append(worker(a.baseline, b))
        print(f"round {r + 1}/{a.repeat} done ({time.perf_counter() - t_start:.0f} s)", flush=True)
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"\nmedians of {a.repeat} interleaved rounds, load average {os.getloadavg()[0]:.1f}")

    def row(key, label, unit=1.0, fmt="{:.4g}"):
        this = med.get(("this",) + key)
        b = base_of(key)
        base = med.get(("baseline",) + b) if b is not None else None
        s = f"  {label:60} {fmt.format(this * unit)}"
        if base is not None:
            s += f"   baseline {fmt.format(base * unit)}   baseline/this {base / this:.1f}x"
        return s

    print("\nchain(links=K): build [s]; simulate(system, 1e-3) default settings, whole call [s]")
    for k in a.chain:
        print(row(("chain_build", k, "-"), f"K = {k:5}: build"))
        print(row(("chain_simulate", k, "sparse"), f"K = {k:5}: simulate"))
        if ("this", "chain_simulate", k, "dense") in med:
            d, s_ = med[("this", "chain_simulate", k, "dense")], med[("this", "chain_simulate", k, "sparse")]
            print(f"  {'':60} dense modal analysis {d:.4g} s: dense/sparse {d / s_:.1f}x")
    ks = [k for k in a.chain if ("this", "chain_simulate", k, "sparse") in med]
    if len(ks) >= 2:
        t = [med[("this", "chain_simulate", k, "sparse")] for k in ks]
        print(f"  growth exponent of simulate, K = {ks[0]}..{ks[-1]}: {math.log(t[-1] / t[0]) / math.log(ks[-1] / ks[0]):.2f}")
    print("\nslider_crank(elements=N, formulation='ancf').build() [s]")
    for n in a.build:
        print(row(("build", n, "consistent"), f"N = {n:5}: as given"))
        print(row(("build", n, "inconsistent"), f"N = {n:5}: crank 0.05 rad off (Newton)"))
    if len(a.build) >= 2:
        for v in ("consistent", "inconsistent"):
            t0_, t1_ = med[("this", "build", a.build[0], v)], med[("this", "build", a.build[-1], v)]
            print(f"  growth exponent ({v}), N = {a.build[0]}..{a.build[-1]}: {math.log(t1_ / t0_) / math.log(a.build[-1] / a.build[0]):.2f}")
    print("\nA02 (N four-bar): time per step at h = 1e-3 [us], System.integrate whole")
    for n in a.a02:
        for method in ("GENALPHA", "RADAU5M"):
            s_, d = med[("this", "a02", n, f"{method}/sparse")], med[("this", "a02", n, f"{method}/dense")]
            print(row(("a02", n, f"{method}/sparse"), f"N = {n}: {method} sparse", 1e6, "{:.1f}")
                  + f"   (dense in this build {d * 1e6:.1f}: dense/sparse {d / s_:.2f}x)")
    print(f"\nwall {time.perf_counter() - t_start:.0f} s")


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    main()
