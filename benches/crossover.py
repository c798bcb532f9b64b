"""Where the sparse forms start to pay (docs/scale.md, "Crossovers"): dense against sparse, in
one run, on the ANCF wire pendulum and the chain, around the thresholds
``ukflex.integrate``'s ``SPARSE_NEWTON_MIN`` (the size n + m of the Newton matrix from which
``linear_solver="auto"`` takes the band LU) and ``System.SPARSE_MODES_MIN`` (the coordinates from
which the modal analysis of ``method="auto"`` is sparse).

* Newton: time per step of RADAU5M and GENALPHA at a fixed step (wire: 1e-4 s; chain, released
  at -0.3 rad: 1e-3 s), ``--steps`` steps, ``System.integrate`` whole, ``linear_solver`` "dense"
  and "sparse".
* Modal analysis: what ``method="auto"`` needs, the lowest modes and ``omega_max``: dense
  (``frequencies()``, every mode) against sparse (``frequencies(count=8)`` and
  ``max_frequency()``), the same System with ``SPARSE_MODES_MIN`` switched.

Medians of ``--repeat`` interleaved rounds.  Usage: ``python benches/crossover.py``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ancf_wire import ukflex_wire  # noqa: E402

from ukflex import scenes  # noqa: E402


def newton_step(system, method, solver, h, steps):
    t0 = time.perf_counter()
    out = system.integrate(0.0, system.y0, steps * h, method=method, step=h, linear_solver=solver)
    wall = time.perf_counter() - t0
    assert out["status"] == 0, out["message"]
    return wall / out["naccept"]


def modal(system, sparse):
    system.SPARSE_MODES_MIN = 0 if sparse else 10**9
    t0 = time.perf_counter()
    if sparse:
        system.frequencies(count=8)
        system.max_frequency()
    else:
        w = system.frequencies()
        float(np.abs(w).max())
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wire", type=int, nargs="*", default=[4, 8, 12, 16, 24, 32, 48])
    ap.add_argument("--chain", type=int, nargs="*", default=[8, 12, 16, 24, 32, 48])
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=7)
    a = ap.parse_args()
    systems = [("wire", k, ukflex_wire(k), 1e-4) for k in a.wire] + \
              [("chain", k, scenes.chain(links=k, angle=-0.3).build(), 1e-3) for k in a.chain]
    res: dict = {}
    t_start = time.perf_counter()
    for r in range(a.repeat):
        for name, k, system, h in systems:
            for method in ("RADAU5M", "GENALPHA"):
                for solver in ("dense", "sparse"):
                    res.setdefault((name, k, method, solver), []).append(newton_step(system, method, solver, h, a.steps))
            for sparse in (False, True):
                res.setdefault((name, k, "modal", sparse), []).append(modal(system, sparse))
        print(f"round {r + 1}/{a.repeat} ({time.perf_counter() - t_start:.0f} s)", flush=True)
    med = {key: statistics.median(v) for key, v in res.items()}
    print(f"\nmedians of {a.repeat} interleaved rounds, load average {os.getloadavg()[0]:.1f}")
    print(f"{'scene':6} {'K':>4} {'n':>5} {'n+m':>5} | {'RADAU5M dense/sparse us':>26} {'ratio':>6} | "
          f"{'GENALPHA dense/sparse us':>26} {'ratio':>6} | {'modal dense/sparse ms':>24} {'ratio':>6}")
    for name, k, system, h in systems:
        n, m = system.n_coords, system.n_constraints
        line = f"{name:6} {k:4} {n:5} {n + m:5}"
        for method in ("RADAU5M", "GENALPHA"):
            d, s = med[(name, k, method, "dense")], med[(name, k, method, "sparse")]
            line += f" | {d * 1e6:12.1f} {s * 1e6:12.1f} {d / s:6.2f}"
        d, s = med[(name, k, "modal", False)], med[(name, k, "modal", True)]
        line += f" | {d * 1e3:11.2f} {s * 1e3:11.2f} {d / s:6.2f}"
        print(line)
    print(f"\nwall {time.perf_counter() - t_start:.0f} s")


if __name__ == "__main__":
    main()
