"""The Newton matrices' sparse LU with kept pivots (`rust/linalg/static_lu.rs`, chosen by
`rust/integrate/newton.rs::factorization`) on planar scenes with 50 - 256 unknowns and a wide
band: the whole call ``System(scene)`` + ``simulate(..., linear_solver=ls)`` for ``ls`` in
"dense" and "auto" alternately, process CPU, medians of ``N`` interleaved repetitions, and the
largest difference of the coordinates between the two.

Which factorization each scene gets (measured once with a temporary print in `factorization`,
docs/spatial.md "A05 this round (i30-a05d)"): the continuous-beam lattice 8 x 2 (132 unknowns)
the sparse LU; the four-bar with a 16-element FFRF coupler (66) and the 16-element FFRF
pendulum (53) the dense LU (their fill stays above a quarter of the dense work).

    .venv/bin/python benches/planar_static_lu.py 9
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import ukflex
from ukflex import scenes

CASES = [
    ("lattice 8x2 continuous", lambda: scenes.lattice(8, 2, beams="continuous"), 0.1, "RADAU5M"),
    ("lattice 8x2 continuous", lambda: scenes.lattice(8, 2, beams="continuous"), 0.5, "RADAU5"),
    ("four-bar, FFRF coupler 16 el.", lambda: scenes.four_bar(theory="euler-bernoulli", elements=16), 0.002, "RADAU5M"),
    ("flexible pendulum FFRF 16 el.", lambda: scenes.flexible_pendulum(elements=16), 0.02, "RADAU5M"),
]


def run(make, t_end, method, ls):
    t = time.process_time()
    res = ukflex.simulate(ukflex.System(make()), t_end, method=method, linear_solver=ls,
                          t_eval=np.linspace(0.0, t_end, 21))
    return time.process_time() - t, res


def main() -> None:
    warnings.simplefilter("ignore")
    reps = int(sys.argv[1]) if len(sys.argv) > 1 else 9
    for name, make, t_end, method in CASES:
        times = {"dense": [], "auto": []}
        last = {}
        for _ in range(reps):
            for ls in ("dense", "auto"):
                dt, res = run(make, t_end, method, ls)
                times[ls].append(dt)
                last[ls] = res
        d, a = (float(np.median(times[k])) for k in ("dense", "auto"))
        diff = float(np.max(np.abs(last["dense"].q - last["auto"].q)))
        print(f"{name:32s} {method:8s} t_end {t_end:<6g} dense {1e3 * d:8.2f} ms  auto {1e3 * a:8.2f} ms  "
              f"auto/dense {a / d:5.2f}  max |dq| {diff:.1e}  LU {last['auto'].nlu}", flush=True)


if __name__ == "__main__":
    main()
