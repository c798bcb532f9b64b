"""RADAU5M error-controlled: the achieved error against the requested rtol, 1e-3 .. 1e-10.

Three problems, each against an independent reference, the error in units of rtol:

* a 1 kg mass on a 1e8 N/m spring (1e4 rad/s), 1e-5 m about x = 0.3 m, 0.01 s: x and v against
  the closed form at 201 times, each relative to its scale (0.301 m, 0.101 m/s);
* Simeon's crank (the Test Set for IVP solvers, modal coupler): its 14 positions and velocities
  at t = 0.1 against the published reference, each relative to ``|ref| + 1e-3``;
* the paper's slider-crank (linear FFRF, N = 1), 0.05 s: every coordinate and rate at 201 times
  against native DOPRI5 at rtol 1e-13, each relative to its largest value plus 1e-3.

(``+ 1e-3``: the default ``atol = 1e-3 rtol`` of the weights ``atol + rtol |y|``.)

    python benches/radau5m_rtol.py     # ~1 min; the table of docs/integrators.md
"""

from __future__ import annotations

import time
import warnings

import numpy as np

import ukflex
from ukflex import scenes

RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)


def stiff_spring():
    s = ukflex.Scene()
    m = s.point_mass("m", mass=1.0, position=(0.3 + 1e-5, 0.0))
    s.point_on_line(m.point(), s.ground.line((0, 0), angle=0.0))
    s.spring_damper(s.ground.point(0.0, 0.0), m.point(), stiffness=1e8, rest_length=0.3)
    return s


def spring_error(rtol, method="RADAU5M"):
    t = np.linspace(0.0, 1e-2, 201)
    res = ukflex.simulate(stiff_spring().build(), 1e-2, method=method, rtol=rtol, t_eval=t)
    assert res.success, res.message
    xe, ve = 0.3 + 1e-5 * np.cos(1e4 * t), -0.1 * np.sin(1e4 * t)
    return max(np.abs(res.coordinate("m.x") - xe).max() / 0.301, np.abs(res.velocity("m.x") - ve).max() / 0.101), res


def simeon_error(rtol, method="RADAU5M"):
    import sys
    from pathlib import Path

    from ukflex.reference import testset_crank as ts

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository's studies/
    from studies import simeon_crank as sc

    system = sc.crank_scene(False).build(correct=False)
    q0, qd0 = sc.crank_state(system, ts.Y0[:14])
    res = ukflex.simulate(system, 0.1, method=method, rtol=rtol, q0=q0, qd0=qd0, projection_tol=0)
    assert res.success, res.message
    y = sc.testset_components(res)
    return float(np.max(np.abs(y - ts.REFERENCE[:14]) / (np.abs(ts.REFERENCE[:14]) + 1e-3))), res


_PAPER_REF = {}


def paper_error(rtol, method="RADAU5M"):
    t = np.linspace(0.0, 0.05, 201)
    if "y" not in _PAPER_REF:
        ref = ukflex.simulate(scenes.slider_crank().build(), 0.05, method="DOPRI5", rtol=1e-13, atol=1e-16, t_eval=t)
        _PAPER_REF["y"] = ref.y
    yr = _PAPER_REF["y"]
    res = ukflex.simulate(scenes.slider_crank().build(), 0.05, method=method, rtol=rtol, t_eval=t)
    assert res.success, res.message
    scale = np.abs(yr).max(axis=1, keepdims=True) + 1e-3
    return float((np.abs(res.y - yr) / scale).max()), res


PROBLEMS = (("stiff spring", spring_error), ("Simeon's crank", simeon_error), ("paper scene", paper_error))


def main() -> None:
    warnings.simplefilter("ignore")
    print("| problem | " + " | ".join(f"{r:g}" for r in RTOLS) + " |")
    print("|---|" + "---|" * len(RTOLS))
    for name, fn in PROBLEMS:
        for method in ("RADAU5M", "DOPRI5"):
            cells = []
            for r in RTOLS:
                tic = time.perf_counter()
                e, res = fn(r, method)
                wall = time.perf_counter() - tic
                cells.append(f"{e / r:.2g} ({res.extra.get('naccept', '?')}, {1e3 * wall:.0f} ms)")
            print(f"| {name}, {method} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
