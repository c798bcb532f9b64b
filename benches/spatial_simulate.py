"""Whole `ukflex.simulate()` on the spatial slider-crank (a freshly built System each run), the
default call and DOPRI5 at rtol 1e-8, median of repetitions, plus the kernel per call
(`System.time_acceleration`, best of batches). Run one process per build and alternate builds
(`PYTHONPATH=<tree>/python`) to compare them; docs/spatial.md, "Performance".
Run: .venv/bin/python benches/spatial_simulate.py [reps]   (about 20 s)"""
import sys
import time

import numpy as np
import ukflex
from ukflex import spatial_scenes

reps = int(sys.argv[1]) if len(sys.argv) > 1 else 30


def run(**kw):
    system = ukflex.System(spatial_scenes.slider_crank())
    t0 = time.perf_counter()
    ukflex.simulate(system, 1.0, **kw)
    return time.perf_counter() - t0


for kw in ({}, {"method": "DOPRI5", "rtol": 1e-8}):
    [run(**kw) for _ in range(2)]
    print(f"simulate(slider_crank, 1 s, {kw or 'default'}): median {np.median([run(**kw) for _ in range(reps)]) * 1e3:.2f} ms")
system = ukflex.System(spatial_scenes.slider_crank())
print(f"kernel per call: {system.time_acceleration(0.1, system.q0, system.qd0, 20000, 7) * 1e6:.2f} us")
