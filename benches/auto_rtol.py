"""Does ``method="auto"`` honour rtol? Its history error against a converged run of the same
model, at rtol 1e-3 .. 1e-8, on three flexible scenes, timed around the whole ``simulate`` call
on a freshly built System (median of 3).

* the paper scene with the nonlinear FFRF coupler (N = 4), 0.1 s: v(0.5) / Lb;
* the cantilever released under its weight (damping 2/52), 0.8 s: the tip deflection;
* a steel ANCF cable (1 m, d = 5 mm) clamped to a hub spun up as t^2 / 2, 4 s: the tip's
  deflection from the hub's axis.

The reference: RADAU5M at a fixed step 1/32 of auto's default step (order 5: converged to
rounding on these outputs; DOPRI5 would resolve the axial modes, 1e5-1e6 rad/s). Error: the
largest deviation over 401 outputs, relative to the output's largest value.

    python benches/auto_rtol.py      # ~2 min; prints the table of docs/integrators.md
"""

from __future__ import annotations

import math
import statistics
import time
import warnings

import numpy as np

import ukflex
from ukflex import Scene, scenes


def spun_cable() -> Scene:
    s = Scene()
    hub = s.rigid_body("hub", mass=1.0, inertia=0.01)
    s.revolute(s.ground.point(0.0, 0.0), hub.point(0.0, 0.0))
    s.angle_driver(hub.frame(), ukflex.Polynomial([0.0, 0.0, 0.75]))
    cable = s.beam("beam", length=1.0, elements=4, section=ukflex.Circular(0.005), density=7850.0,
                   youngs_modulus=2.1e11, formulation="ancf")
    s.weld(hub.frame(), cable.at(0.0))
    return s


def tip_off_axis(system, res):
    out = []
    for k in range(res.t.size):
        x, y = system.beam_point("beam", 1.0, res.q[:, k])[:2]
        th = res.q[system.coordinate_index("hub.theta"), k]
        out.append(-math.sin(th) * x + math.cos(th) * y)
    return np.array(out)


CASES = [
    ("paper, nonlinear FFRF N = 4", lambda: scenes.slider_crank(strain="nonlinear", elements=4), 0.1,
     lambda s, r: r.beam_displacement("coupler", 0.5)[1]),
    ("cantilever under its weight", lambda: scenes.cantilever(damping=2.0 / 52.0), 0.8,
     lambda s, r: r.beam_displacement("beam", 1.0)[1]),
    ("ANCF cable spun up on a hub", spun_cable, 4.0, tip_off_axis),
]
RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


def main() -> None:
    warnings.simplefilter("ignore")
    print("| scene | rtol | auto's pick | error (of the peak) | time [ms] |")
    print("|---|---|---|---|---|")
    for name, make, T, output in CASES:
        te = np.linspace(0.0, T, 401)
        sys0 = make().build()
        h0 = ukflex.simulate(sys0, T, t_eval=te).extra["auto"]["step"]
        ref = output(sys0, ukflex.simulate(make().build(), T, method="RADAU5M", step=h0 / 32, rtol=1e-10, t_eval=te))
        peak = np.abs(ref).max()
        for rtol in RTOLS:
            walls, res, system = [], None, None
            for _ in range(3):
                system = make().build()
                tic = time.perf_counter()
                res = ukflex.simulate(system, T, rtol=rtol, t_eval=te)
                walls.append(time.perf_counter() - tic)
            err = np.abs(output(system, res) - ref).max() / peak
            a = res.extra["auto"]
            pick = res.method + (f", h = {a['step']:.3g}" if a.get("step") else "")
            print(f"| {name} | {rtol:g} | {pick} | {err:.2e} | {1e3 * statistics.median(walls):.1f} |", flush=True)


if __name__ == "__main__":
    main()
