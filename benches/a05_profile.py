"""Where the whole A05 call goes (the stiff flyball governor, 2 s, 201 outputs, auto at rtol
1e-3 and 1e-4): process CPU time of ``System(scene)``, of auto's modal analysis
(``choose_method``), of ``simulate()`` and of its Rust run (``res.wall_time``, measured inside
the core), medians of ``N`` interleaved repetitions; then the step statistics of the start
phase (the run to 0.02 s, the growth of the step out of the springs' fast transient) and of the
whole run: accepted and rejected steps, Newton iterations, LU factorizations (a real and a
complex matrix per factorization), difference passes of the velocity terms, right-hand sides.

Before / after a change, interleaved with a copy of the former package (as
``benches/radau5m_speed.py``):

    PYTHONPATH=/tmp/before .venv/bin/python benches/a05_profile.py 15
    .venv/bin/python benches/a05_profile.py 15          # ~10 s each
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import ukflex
from ukflex import spatial_scenes
from ukflex.run.choice import choose_method

T_END = 2.0
START = 0.02


def stats(res) -> str:
    e = res.extra
    return (f"steps {e['naccept']:4d}  rejected {e['nreject']:3d}  newton {e['newton_iterations']:4d}  "
            f"LU {res.nlu:4d}  passes {res.njev:3d}  rhs {res.nfev:5d}")


def main() -> None:
    warnings.simplefilter("ignore")
    reps = int(sys.argv[1]) if len(sys.argv) > 1 else 15
    scene = spatial_scenes.flyball_governor()
    t = np.linspace(0.0, T_END, 201)
    clock = time.process_time
    rows: dict = {}
    for _ in range(reps):
        for rtol in (1e-3, 1e-4):
            c0 = clock()
            system = ukflex.System(scene)
            c1 = clock()
            res = ukflex.simulate(system, T_END, t_eval=t, rtol=rtol)
            c2 = clock()
            for key, v in (("System(scene)", c1 - c0), ("simulate()", c2 - c1), ("whole call", c2 - c0),
                           ("Rust run (wall, in the core)", res.wall_time)):
                rows.setdefault((key, rtol), []).append(v)
            c3 = clock()
            choose_method(system, 0.0, T_END, rtol, system.q0, system.qd0)
            rows.setdefault(("auto's analysis", rtol), []).append(clock() - c3)
    print(f"ukflex from {ukflex.__file__}; process CPU ms, medians of {reps}")
    for (key, rtol), v in rows.items():
        print(f"  rtol {rtol:g}  {key:30s} {1e3 * np.median(v):7.2f}")
    for rtol in (1e-3, 1e-4):
        system = ukflex.System(scene)
        start = ukflex.simulate(system, START, rtol=rtol)
        whole = ukflex.simulate(system, T_END, t_eval=t, rtol=rtol)
        h = np.diff(np.asarray(ukflex.simulate(system, T_END, rtol=rtol).t))
        print(f"rtol {rtol:g}: start phase (0 .. {START} s): {stats(start)}")
        print(f"rtol {rtol:g}: whole run (0 .. {T_END} s):    {stats(whole)}")
        print(f"rtol {rtol:g}: first step {h[0]:.2e} s, median step {np.median(h):.2e} s, "
              f"steps below 1e-3 s: {(h < 1e-3).sum()}")


if __name__ == "__main__":
    main()
