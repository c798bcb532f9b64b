"""Run time of the scenes with a revolute joint with clearance, by integrator (docs/loads.md).

    PYTHONPATH=. .venv/bin/python benches/clearance_cost.py [--repeats 5]

Times the whole public call, ``ukflex.simulate`` on a freshly built ``System``, for

* Flores's rigid slider-crank (``studies.clearance.flores_scene``), two crank turns: the ideal
  revolute with DOPRI5 at rtol 1e-8, the 0.5 mm clearance with DOPRI5 and with RADAU5M (adaptive)
  at rtol 1e-8;
* the paper's flexible coupler with a 0.5 mm clearance (``studies.clearance.coupler_scene``),
  two crank turns: DOPRI5 at rtol 1e-8, ``method="auto"`` at rtol 1e-7 (RADAU5M with step
  control) and RADAU5M at the fixed step ``auto`` took before it knew about contacts;

the cases interleaved in each repetition (in a random order); reports the median and the ratio
to the first case of each scene. One run on the shared machine: the figures are noisy.
"""
from __future__ import annotations

import argparse
import math
import random
import statistics
import time

import ukflex
from ukflex import scenes
from studies.clearance import FLORES, coupler_scene, flores_scene


def _cases():
    tf = 2 * 2 * math.pi / FLORES["omega"]
    tc = 2 * 2 * math.pi / scenes.PAPER["omega"]
    from ukflex.run.choice import choose_method

    fixed = choose_method(coupler_scene(None).build(), 0.0, tc, 1e-7)  # the fixed step without contacts
    return {
        "flores ideal, DOPRI5 1e-8": (lambda: flores_scene(None), tf, dict(method="DOPRI5", rtol=1e-8)),
        "flores 0.5 mm, DOPRI5 1e-8": (lambda: flores_scene(0.5e-3), tf, dict(method="DOPRI5", rtol=1e-8)),
        "flores 0.5 mm, RADAU5M 1e-8": (lambda: flores_scene(0.5e-3), tf, dict(method="RADAU5M", rtol=1e-8)),
        "coupler 0.5 mm, DOPRI5 1e-8": (lambda: coupler_scene(0.5e-3), tc, dict(method="DOPRI5", rtol=1e-8)),
        "coupler 0.5 mm, auto 1e-7": (lambda: coupler_scene(0.5e-3), tc, dict(method="auto", rtol=1e-7)),
        "coupler 0.5 mm, RADAU5M fixed step": (lambda: coupler_scene(0.5e-3), tc,
                                                dict(method="RADAU5M", rtol=fixed.rtol, **fixed.options)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    cases = _cases()
    times = {k: [] for k in cases}
    rng = random.Random(1)
    for _ in range(args.repeats):
        order = list(cases)
        rng.shuffle(order)
        for k in order:
            build, t_end, kw = cases[k]
            system = build().build()
            t0 = time.perf_counter()
            ukflex.simulate(system, t_end, **kw)
            times[k].append(time.perf_counter() - t0)
    base = {"flores": statistics.median(times["flores ideal, DOPRI5 1e-8"]),
            "coupler": statistics.median(times["coupler 0.5 mm, DOPRI5 1e-8"])}
    print("| case | median [s] | ratio |")
    print("|---|---:|---:|")
    for k, v in times.items():
        m = statistics.median(v)
        print(f"| {k} | {m:.3f} | {m / base[k.split()[0]]:.2f} |")


if __name__ == "__main__":
    main()
