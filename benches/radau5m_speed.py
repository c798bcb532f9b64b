"""RADAU5M's cost on the scenes its step-size control and Newton serve: A05 (auto, adaptive
RADAU5M at rtol 1e-3 .. 1e-5, 2 s, 201 outputs), the paper scene (auto: fixed-step RADAU5M;
adaptive RADAU5M at rtol 1e-3, 0.05 s) and Simeon's crank (adaptive RADAU5M at rtol 1e-3 and
1e-6, 0.1 s). Process CPU time of ``simulate()`` (median of ``N`` calls, a fresh System each),
accepted steps, LU factorizations, right-hand sides.

Before / after a change, interleaved: keep a copy of ``python/ukflex`` with the former build's
``_core`` extension in ``/tmp/before/ukflex`` and alternate

    PYTHONPATH=/tmp/before .venv/bin/python benches/radau5m_speed.py 5
    .venv/bin/python benches/radau5m_speed.py 5          # ~10 s each
"""

from __future__ import annotations

import os
import sys
import time
import warnings

import numpy as np

import ukflex
from ukflex import scenes, spatial_scenes
from ukflex.reference import testset_crank as ts

sys.path.insert(0, os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")))
from studies import simeon_crank as sc  # noqa: E402


def a05(rtol):
    t = np.linspace(0.0, 2.0, 201)
    system = ukflex.System(spatial_scenes.flyball_governor())
    c = time.process_time()
    res = ukflex.simulate(system, 2.0, t_eval=t, rtol=rtol)
    return time.process_time() - c, res


def paper(**kw):
    system = scenes.slider_crank().build()
    c = time.process_time()
    res = ukflex.simulate(system, 0.05, **kw)
    return time.process_time() - c, res


def simeon(rtol):
    system = sc.crank_scene(False).build(correct=False)
    q0, qd0 = sc.crank_state(system, ts.Y0[:14])
    c = time.process_time()
    res = ukflex.simulate(system, 0.1, method="RADAU5M", rtol=rtol, q0=q0, qd0=qd0, projection_tol=0)
    return time.process_time() - c, res


CASES = (
    ("A05 auto rtol 1e-3", lambda: a05(1e-3)), ("A05 auto rtol 1e-4", lambda: a05(1e-4)),
    ("A05 auto rtol 1e-5", lambda: a05(1e-5)), ("paper auto", lambda: paper()),
    ("paper RADAU5M rtol 1e-3", lambda: paper(method="RADAU5M", rtol=1e-3)),
    ("simeon RADAU5M rtol 1e-3", lambda: simeon(1e-3)), ("simeon RADAU5M rtol 1e-6", lambda: simeon(1e-6)),
)


def main() -> None:
    warnings.simplefilter("ignore")
    reps = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    print(f"ukflex from {os.path.dirname(ukflex.__file__)}")
    for name, run in CASES:
        times = []
        for _ in range(reps):
            cpu, res = run()
            times.append(cpu)
        print(f"{name:28s} {1e3 * np.median(times):8.2f} ms  steps {res.extra.get('naccept')} nlu {res.nlu} "
              f"nfev {res.nfev} {res.method}")


if __name__ == "__main__":
    main()
