"""The default against Exudyn's fastest reliable point at 0.5 % on the peak, by CPU time.

On a loaded machine the side-by-side's wall times are mostly the other processes' (at a load of
6-10 on two cores the same tree's default took 8-12 ms against ~4.5 ms at load 1, and the
ratio moved 4.1-5.9x from run to run). This times the same two calls by the calling thread's
CPU time (``time.thread_time``; Exudyn's ``SolveDynamic`` runs in the calling thread), interleaved:
ukflex's whole ``simulate()`` of the default (nonlinear FFRF coupler N = 4, 1,001 outputs, a
freshly built System) and Exudyn's ``SolveDynamic`` on the ANCF cable N = 4 at h = 2e-4 with
``rho_inf`` 0.9 and 0.8 (its fastest reliable points at 0.5 % on the peak in
``side_by_side.py``; model building excluded for both), medians, the faster Exudyn one.
Before/after two trees: run it alternately with each tree first on the path, e.g.

    for i in 1 2 3 4; do
      PYTHONPATH=/path/to/old/python python benches/peers/default_vs_exudyn_cpu.py
      python benches/peers/default_vs_exudyn_cpu.py
    done

(~3 s a call at --repeat 15; needs ``pip install exudyn``.)
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
import types

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import exudyn_slider_crank as es  # noqa: E402

import ukflex  # noqa: E402
from ukflex import scenes, simulate  # noqa: E402

GRID = np.linspace(0.0, 0.1, 1001)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=15)
    args = ap.parse_args(argv)
    # build_and_solve times SolveDynamic with time.perf_counter: the thread's CPU time instead
    es.time = types.SimpleNamespace(perf_counter=time.thread_time)
    uk, uk_wall, ex = [], [], {0.9: [], 0.8: []}
    for _ in range(args.repeat):
        system = scenes.slider_crank(strain="nonlinear", theory="euler-bernoulli", elements=4).build()
        tic, cpu = time.perf_counter(), time.thread_time()
        simulate(system, 0.1, t_eval=GRID)
        uk.append(time.thread_time() - cpu)
        uk_wall.append(time.perf_counter() - tic)
        for rho in ex:
            ex[rho].append(es.build_and_solve("ancf", 4, 2e-4, t_end=0.1, rho_inf=rho)["wall"])
    med = {k: 1e3 * statistics.median(v) for k, v in ex.items()}
    u = 1e3 * statistics.median(uk)
    tree = ukflex.__file__.rsplit("/python/", 1)[0]
    print(f"{tree}: default CPU {u:.2f} ms (wall {1e3 * statistics.median(uk_wall):.2f}); Exudyn h = 2e-4 CPU "
          f"{med[0.9]:.1f} / {med[0.8]:.1f} ms (rho_inf 0.9 / 0.8); ratio {min(med.values()) / u:.2f}x; "
          f"load {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
