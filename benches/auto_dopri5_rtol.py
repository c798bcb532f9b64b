"""What rtol means for auto's DOPRI5: achieved against requested error on scenes with closed forms,
and what running DOPRI5 at ``DOPRI5_RTOL_PER_RTOL`` x rtol costs on the scenes auto sends to it.

Achieved error (in units of the user's rtol, largest over the run's 2 001 outputs), each
against the physical answer:

* the heavy top (30 rad/s, 10 s; docs/spatial.md): energy, ``L_z`` and ``L.e3``, relative;
* a rod pendulum released from the horizontal (10 s, ~5 swings): its angle against the closed
  form ``phi = 2 asin(k sn(K - w0 t, k))``, relative to the amplitude (pi/2);
* a slider on a spring (10 rad/s, 0.1 m about x = 0.9 m, 10 s, 16 periods): x against
  ``0.9 + 0.1 cos(10 t)``, relative to the largest |x| (1 m: the scale rtol weighs x by);

``before``: DOPRI5 at the user's rtol (what auto ran until this round); ``after``: auto
(DOPRI5 at ``DOPRI5_RTOL_PER_RTOL`` rtol); ``--factors`` lists more factors (DOPRI5 at
``f`` rtol), the calibration of the constant.

The cost: ``simulate()`` on a freshly built System, the whole call, auto as it is against auto
with DOPRI5 at the user's rtol (the former rule, the same analysis), medians of interleaved
repetitions, at the default rtol, on the planar and spatial scenes auto sends to DOPRI5.

    python benches/auto_dopri5_rtol.py --repeat 31       # ~1 min: both tables of docs/integrators.md
    python benches/auto_dopri5_rtol.py --factors 1,0.5,0.3,0.2,0.1 --no-time
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
import warnings

import numpy as np
from scipy.special import ellipj, ellipk

import ukflex
from ukflex import scenes, spatial_scenes
from ukflex.reference import spatial as sp
from ukflex.run import choice as auto_rule

RTOLS = (1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
T = 10.0
OUT = np.linspace(0.0, T, 2001)


def _top_description():
    import pathlib
    import sys

    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
    from test_spatial import to_description

    return to_description(sp.scenes.heavy_top(spin=30.0))


def top_errors(**kw):
    system = ukflex.System(_top_description())
    res = ukflex.simulate(system, T, t_eval=OUT, **kw)
    out = ukflex.spatial_outputs(system, res, reactions=False)
    E, L = out["energy"], out["angular_momentum"]
    e3 = out["bodies"]["top"]["rotation"][:, :, 2]
    rel = lambda x: float(np.abs(x - x[0]).max() / abs(x[0]))  # noqa: E731
    return res, {"top E": rel(E), "top L_z": rel(L[:, 2]), "top L.e3": rel(np.einsum("ij,ij->i", L, e3))}


def pendulum_errors(**kw):
    L, g = 1.0, 9.81
    res = ukflex.simulate(scenes.pendulum(length=L, angle=0.0).build(), T, t_eval=OUT, **kw)
    phi0 = math.pi / 2
    k = math.sin(phi0 / 2)
    w0 = math.sqrt(3.0 * g / (2.0 * L))  # rod about its end: m g L/2 / (m L^2 / 3)
    sn = ellipj(ellipk(k * k) - w0 * OUT, k * k)[0]
    exact = -math.pi / 2 + 2.0 * np.arcsin(k * sn)
    return res, {"pendulum angle": float(np.abs(res.coordinate("rod.theta") - exact).max() / phi0)}


def spring_scene():
    s = ukflex.Scene(gravity=None)
    slider = s.rigid_body("slider", mass=1.0, inertia=0.01, position=(1.0, 0.0))
    s.prismatic(slider.frame(), s.ground.line((0, 0), angle=0.0), name="slide")
    s.spring_damper(slider.point(0, 0), s.ground.point(0.0, 0.0), stiffness=100.0, rest_length=0.9, name="spring")
    return s


def spring_errors(**kw):
    res = ukflex.simulate(spring_scene().build(), T, t_eval=OUT, **kw)
    exact = 0.9 + 0.1 * np.cos(10.0 * OUT)
    return res, {"slider x": float(np.abs(res.coordinate("slider.x") - exact).max() / 1.0)}


PROBLEMS = (top_errors, pendulum_errors, spring_errors)


def former_auto(fn):
    """Run ``fn`` with auto's DOPRI5 at the user's rtol (the rule until this round)."""
    stated = auto_rule._stated

    def at_user_rtol(d, span):
        c = stated(d, span)
        if c.method == "DOPRI5":
            c.rtol = None
        return c

    auto_rule._stated = at_user_rtol
    try:
        return fn()
    finally:
        auto_rule._stated = stated


def accuracy_table(factors):
    print(f"achieved error / rtol over {T:g} s (nfev): before = DOPRI5 at rtol, after = auto "
          f"(DOPRI5 at {auto_rule.DOPRI5_RTOL_PER_RTOL:g} rtol)")
    for fn in PROBLEMS:
        for rtol in RTOLS:
            runs = [("before", lambda: former_auto(lambda: fn(rtol=rtol))), ("after", lambda: fn(rtol=rtol))]
            runs += [(f"f={f:g}", lambda f=f: fn(method="DOPRI5", rtol=f * rtol)) for f in factors]
            cells = []
            for label, run in runs:
                res, errs = run()
                assert res.success, res.message
                cells.append(f"{label}: " + ", ".join(f"{v / rtol:.2f}" for v in errs.values()) + f" ({res.nfev})")
            print(f"{' / '.join(errs):36s} rtol {rtol:.0e} | " + " | ".join(cells), flush=True)


def timing_scenes():
    out = [("pendulum (planar)", lambda: scenes.pendulum(angle=0.0).build(), T),
           ("double pendulum (planar)", lambda: scenes.double_pendulum().build(), T),
           ("four-bar, driven (planar, no dof)", lambda: scenes.four_bar().build(), 0.63),
           ("slider on a spring (planar)", lambda: spring_scene().build(), T),
           ("heavy top", lambda: ukflex.System(_top_description()), T),
           ("A04 Bricard", lambda: ukflex.System(spatial_scenes.bricard()), T),
           ("spatial slider-crank", lambda: ukflex.System(spatial_scenes.slider_crank()), 2.0)]
    return out


def timing_table(repeat):
    print(f"\nthe whole simulate() call at the default rtol (t_eval: 2 001 outputs), median (and min) of {repeat} "
          "interleaved")
    for label, build, t_end in timing_scenes():
        t_out = np.linspace(0.0, t_end, 2001)
        times = {"before": [], "after": []}
        info = {}

        def run(which):
            t0 = time.perf_counter()
            res = ukflex.simulate(build(), t_end, t_eval=t_out)
            times[which].append(time.perf_counter() - t0)
            info[which] = (res.method, res.nfev)

        for k in range(repeat):
            order = ("before", "after") if k % 2 == 0 else ("after", "before")
            for which in order:
                if which == "before":
                    former_auto(lambda: run("before"))
                else:
                    run("after")
        b, a = statistics.median(times["before"]), statistics.median(times["after"])
        bm, am = min(times["before"]), min(times["after"])
        print(f"{label:34s} {info['after'][0]:6s} before {b * 1e3:6.1f} ms (min {bm * 1e3:6.1f}; {info['before'][1]:5d} "
              f"rhs)  after {a * 1e3:6.1f} ms (min {am * 1e3:6.1f}; {info['after'][1]:5d} rhs)  ratio {a / b:.2f} "
              f"(min {am / bm:.2f}; rhs {info['after'][1] / info['before'][1]:.2f})", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--factors", default="", help="more DOPRI5 factors f (DOPRI5 at f rtol), comma-separated")
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--no-time", action="store_true")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    factors = [float(f) for f in args.factors.split(",") if f]
    start = time.perf_counter()
    accuracy_table(factors)
    if not args.no_time:
        timing_table(args.repeat)
    print(f"\n({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
