"""RADAU5M and GENALPHA on scenes with redundant constraints (issue 26): the continuous-beam lattice
(``columns - 1`` redundant rows per level), 0.5 s at the default rtol (1e-6), with each linear
solver. Per run: the time reached, status, accepted/rejected steps, factorizations (LU),
right-hand sides, the largest coordinate difference against DOPRI5 at rtol = atol = 1e-10 at
11 times (up to the time reached), and the whole call ``System(scene)`` + ``simulate()``
(process CPU, median of ``N`` interleaved repetitions). docs/integrators.md "Redundant
constraints" quotes it.

    .venv/bin/python benches/radau5m_redundant.py 5
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import ukflex
from ukflex import scenes

T_END = 0.5
LATTICES = [(2, 2), (8, 2)]
SOLVERS = ("dense", "sparse", "auto")


METHODS = ("RADAU5M", "GENALPHA")


def run(cols: int, rows: int, method: str, ls: str):
    t = np.linspace(0.0, T_END, 11)
    c0 = time.process_time()
    res = ukflex.simulate(ukflex.System(scenes.lattice(cols, rows, beams="continuous")), T_END, method=method,
                          linear_solver=ls, t_eval=t)
    return time.process_time() - c0, res


def main() -> None:
    warnings.simplefilter("ignore")
    reps = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    print(f"ukflex from {ukflex.__file__}")
    for cols, rows in LATTICES:
        t = np.linspace(0.0, T_END, 11)
        ref = ukflex.simulate(ukflex.System(scenes.lattice(cols, rows, beams="continuous")), T_END, method="DOPRI5",
                              rtol=1e-10, atol=1e-10, t_eval=t)
        keys = [(m, ls) for m in METHODS for ls in SOLVERS]
        times: dict = {key: [] for key in keys}
        last: dict = {}
        for _ in range(reps):
            for key in keys:
                dt, res = run(cols, rows, *key)
                times[key].append(dt)
                last[key] = res
        for key in keys:
            res = last[key]
            k = res.q.shape[1]
            err = float(np.abs(res.q - ref.q[:, :k]).max())
            reached = res.t[-1] if res.status == 0 else float(res.message.split("at t = ")[1].split(" s")[0])
            print(f"lattice {cols}x{rows} (n = {res.q.shape[0]}) {key[0]:8s} {key[1]:6s} "
                  f"reached {reached:.4g} s  status {res.status:2d}  steps {res.extra['naccept']}/{res.extra['nreject']}  "
                  f"LU {res.nlu:5d}  rhs {res.nfev:5d}  max |q - q_DOPRI5| {err:.2e}  "
                  f"whole call {1e3 * float(np.median(times[key])):7.1f} ms", flush=True)


if __name__ == "__main__":
    main()
