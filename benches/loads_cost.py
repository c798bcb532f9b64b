"""Per-call cost of a load that is a function, against a constant load (docs/loads.md).

    .venv/bin/python benches/loads_cost.py [--repeats 31] [--batches 9]

On the paper's slider-crank (``ukflex.scenes.slider_crank()``) with a gas force on the slider
(the coupler's end) given as

* ``none``: no load (the scene as it is);
* ``constant``: a constant ``point_force``;
* ``expression``: ``point_load`` of the crank angle and the slider speed,
  ``-(2000 (1 + cos(crank.theta))^2 + 40 d:x(coupler, 1))``;
* ``table``: ``point_load`` tabulated against ``crank.theta`` (73 knots, period 2 pi);
* ``callable``: the expression's formula as a Python function ``f(t, state)`` of
  ``crank.theta`` and ``d:crank.theta`` (the slider speed is not an input there);

and on the spatial slider-crank (``ukflex.spatial_scenes.slider_crank()``, free, turning at 6
rad/s) with a force along the slide on the slider given as

* ``3d constant``: a constant ``point_force``;
* ``3d expression``: ``point_load`` of the slider's coordinate and its point's velocity,
  ``-(200 / (1 + 30 (slider.x - 0.25)^2) + 4 d:x(slider))``;

it times ``System.rhs(t, y)`` (the public call scipy makes) and the Rust acceleration alone
(``ukflex.run.simulate.time_acceleration``) on 20 states of one run (of each scene), the kinds interleaved in
each repetition (in a random order); reports the median per call and the ratio to ``constant``
(``3d constant`` for the spatial rows). The Rust acceleration's figure of a repetition is the best
of ``--batches`` batches (9: on the shared 2-core machine a batch ran at one of two speeds, about
1.2 or 2.4 us per call on the planar scene, whatever the load kind; with 3 batches single kinds
landed on the slow one). One run; the machine is shared, so the figures are noisy.
"""
from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

import ukflex
from ukflex import LoadTable, scenes
from ukflex.model.spatial import SpatialBodyRef
from ukflex.model.spatial_scenes import slider_crank as spatial_slider_crank
from ukflex.run.simulate import time_acceleration

GAS = "-(2000 * (1 + cos(crank.theta))^2 + 40 * d:x(coupler, 1))"


def gas(t, state):
    return -(2000.0 * (1.0 + math.cos(state["crank.theta"])) ** 2 + 40.0 * 0.1524 * state["d:crank.theta"])


GAS3 = "-(200 / (1 + 30 * (slider.x - 0.25)^2) + 4 * d:x(slider))"


def build(kind):
    if kind.startswith("3d"):
        s3 = spatial_slider_crank()
        slider = SpatialBodyRef("slider").marker()
        if kind == "3d constant":
            s3.point_force(slider, (-200.0, 0.0, 0.0))
        else:
            s3.point_load(slider, [GAS3, 0.0, 0.0])
        return ukflex.System(s3)
    s = scenes.slider_crank()
    end = s["coupler"].at(1.0)
    if kind == "constant":
        s.point_force(end, (-2000.0, 0.0))
    elif kind == "expression":
        s.point_load(end, fx=GAS)
    elif kind == "table":
        x = np.linspace(0.0, 2 * math.pi, 73)
        s.point_load(end, fx=LoadTable(of="crank.theta", x=x, y=-2000.0 * (1 + np.cos(x)) ** 2, period=2 * math.pi))
    elif kind == "callable":
        s.point_load(end, fx=gas, inputs=["crank.theta", "d:crank.theta"])
    return s.build()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=31)
    ap.add_argument("--batches", type=int, default=9,
                    help="the Rust acceleration's time per repetition is the best of this many batches of 3000 calls")
    args = ap.parse_args()
    kinds = ["none", "constant", "expression", "table", "callable", "3d constant", "3d expression"]
    systems = {k: build(k) for k in kinds}
    states = {}
    for dim, (base, t_end) in {"2d": (systems["none"], 0.07), "3d": (systems["3d constant"], 1.0)}.items():
        te = np.linspace(0.0, t_end, 20)
        res = ukflex.simulate(base, t_end, method="DOPRI5", rtol=1e-8, atol=1e-10, t_eval=te)
        states[dim] = [(float(t), np.concatenate([res.q[:, k], res.qd[:, k]])) for k, t in enumerate(res.t)]
    rhs = {k: [] for k in kinds}
    core = {k: [] for k in kinds}
    loops = 200
    rng = np.random.default_rng(0)
    for _ in range(args.repeats):
        for k in rng.permutation(kinds):  # interleaved, in a new order each repetition
            f, st, n = systems[k].rhs, states["3d" if k.startswith("3d") else "2d"], systems[k].n_coords
            tic = time.perf_counter()
            for _ in range(loops):
                for t, y in st:
                    f(t, y)
            rhs[k].append((time.perf_counter() - tic) / (loops * len(st)))
            t, y = st[7]
            core[k].append(time_acceleration(systems[k], t, y[:n], y[n:], reps=3000, batches=args.batches))
    print(f"{'load':14s} {'System.rhs [us]':>14s} {'ratio':>6s} {'Rust acc [us]':>14s} {'ratio':>6s}")
    mr = {k: statistics.median(v) for k, v in rhs.items()}
    mc = {k: statistics.median(v) for k, v in core.items()}
    for k in kinds:
        ref = "3d constant" if k.startswith("3d") else "constant"
        print(f"{k:14s} {mr[k] * 1e6:14.2f} {mr[k] / mr[ref]:6.2f} {mc[k] * 1e6:14.2f} {mc[k] / mc[ref]:6.2f}")


if __name__ == "__main__":
    main()
