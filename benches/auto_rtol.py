"""Does ``method="auto"`` honour rtol, and does it state its floor? Its history error against the
physical motion of the same model, at rtol 1e-3 .. 1e-8, on flexible scenes, timed around the
whole ``simulate`` call on a freshly built System (median of 3).

* the paper scene with the nonlinear FFRF coupler (N = 4), 0.1 s: v(0.5) / Lb;
* the same with the ANCF cable coupler (N = 4);
* the cantilever released under its weight, undamped and damped (2/52 s), 0.8 s: the tip deflection;
* a steel ANCF cable (1 m, d = 5 mm) clamped to a hub spun up as 0.75 t^2, 4 s: the tip's
  deflection from the hub's axis.

The reference: native DOPRI5 at rtol 1e-11 (every mode resolved: the motion of the model as it
is, fast modes included, which auto's step damps on purpose); for the damped cantilever (its
damping makes the high modes decay at up to 1e8 1/s: stiff for any explicit method) and the spun
cable (4 s of modes up to ~1e6 rad/s: hours for DOPRI5) RADAU5M at 1/32 of auto's default step (error-controlled
RADAU5M at rtol 1e-11 where auto's default is adaptive: the damped cantilever), which damps their fastest modes too (physically so for the damped cantilever). Errors: the output's largest
deviation over 401 outputs relative to its largest value, and the largest deviation of a beam
point (at xi = 0.25, 0.5, 0.75, 1) in metres, which is what ``res.extra["auto"]["floor"]`` states:
the error from the fast modes the start sets off, which no rtol lowers.

    python benches/auto_rtol.py      # ~4 min; prints the table of docs/integrators.md
"""

from __future__ import annotations

import math
import statistics
import time
import warnings

import numpy as np

import ukflex
from ukflex import Scene, scenes
from ukflex.run.choice import FLOOR_POINTS
from ukflex.results.outputs import beam_names


def spun_cable() -> Scene:
    s = Scene()
    hub = s.rigid_body("hub", mass=1.0, inertia=0.01)
    s.revolute(s.ground.point(0.0, 0.0), hub.point(0.0, 0.0))
    s.angle_driver(hub.frame(), ukflex.Polynomial([0.0, 0.0, 0.75]))
    cable = s.cable("beam", length=1.0, elements=4, section=ukflex.Circular(0.005), density=7850.0,
                   youngs_modulus=2.1e11)
    s.weld(hub.frame(), cable.at(0.0))
    return s


def tip_off_axis(system, res):
    x, y = res.beam_position("beam", 1.0)
    th = res.q[system.coordinate_index("hub.theta")]
    return -np.sin(th) * x + np.cos(th) * y


def points(system, res):
    """World positions of the beams' points at FLOOR_POINTS: (2 * beams * points, nt)."""
    return np.vstack([np.vstack(res.beam_position(b, xi)) for b in beam_names(system) for xi in FLOOR_POINTS])


def point_error(system, res, ref):
    d = points(system, res) - points(system, ref)
    return float(np.hypot(d[0::2], d[1::2]).max())


CASES = [
    ("paper, nonlinear FFRF N = 4, v(0.5)/Lb", lambda: scenes.slider_crank(strain="nonlinear", elements=4), 0.1,
     lambda s, r: r.beam_displacement("coupler", 0.5)[1]),
    ("paper, ANCF N = 4, v(0.5)/Lb", lambda: scenes.slider_crank(formulation="ancf", elements=4), 0.1,
     lambda s, r: r.beam_displacement("coupler", 0.5)[1]),
    ("cantilever under its weight, undamped, tip", lambda: scenes.cantilever(), 0.8,
     lambda s, r: r.beam_position("beam", 1.0)[1]),
    ("cantilever under its weight, damped, tip", lambda: scenes.cantilever(damping=2.0 / 52.0), 0.8,
     lambda s, r: r.beam_position("beam", 1.0)[1]),
    ("ANCF cable spun up on a hub, tip off the axis", spun_cable, 4.0, tip_off_axis),
]
RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


def main() -> None:
    warnings.simplefilter("ignore")
    print("| scene | rtol | auto's pick | error (of the peak) | beam points [m] | stated floor [m] | time [ms] |")
    print("|---|---|---|---|---|---|---|")
    for name, make, T, output in CASES:
        te = np.linspace(0.0, T, 401)
        sys0 = make().build()
        if "damped," in name or make is spun_cable:
            h0 = ukflex.simulate(sys0, T, t_eval=te).extra["auto"].get("step")
            if h0 is None:  # auto runs adaptive RADAU5M (the damped cantilever: overdamped modes)
                ref = ukflex.simulate(sys0, T, method="RADAU5M", rtol=1e-11, atol=1e-14, t_eval=te)
            else:
                ref = ukflex.simulate(sys0, T, method="RADAU5M", step=h0 / 32, rtol=1e-10, t_eval=te)
        else:
            ref = ukflex.simulate(sys0, T, method="DOPRI5", rtol=1e-11, atol=1e-14, t_eval=te)
        yref = output(sys0, ref)
        peak = np.abs(yref).max()
        for rtol in RTOLS:
            walls, res, system = [], None, None
            for _ in range(3):
                system = make().build()
                tic = time.perf_counter()
                res = ukflex.simulate(system, T, rtol=rtol, t_eval=te)
                walls.append(time.perf_counter() - tic)
            err = np.abs(output(system, res) - yref).max() / peak
            a = res.extra["auto"]
            pick = res.method + (f", h = {a['step']:.3g}" if a.get("step") else "")
            floor = a.get("floor")
            fl = "-" if floor is None else f"{floor:.1e}"
            print(f"| {name} | {rtol:g} | {pick} | {err:.2e} | {point_error(system, res, ref):.1e} | {fl} | "
                  f"{1e3 * statistics.median(walls):.1f} |", flush=True)


if __name__ == "__main__":
    main()
