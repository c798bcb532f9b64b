"""Per-call cost of a load that is a function, against a constant load (docs/loads.md).

    .venv/bin/python benches/loads_cost.py [--repeats 31]

On the paper's slider-crank (``ukflex.scenes.slider_crank()``) with a gas force on the slider
(the coupler's end) given as

* ``none``: no load (the scene as it is);
* ``constant``: a constant ``point_force``;
* ``expression``: ``point_load`` of the crank angle and the slider speed,
  ``-(2000 (1 + cos(crank.theta))^2 + 40 d:x(coupler, 1))``;
* ``table``: ``point_load`` tabulated against ``crank.theta`` (73 knots, period 2 pi);
* ``callable``: the expression's formula as a Python function ``f(t, state)`` of
  ``crank.theta`` and ``d:crank.theta`` (the slider speed is not an input there);

it times ``System.rhs(t, y)`` (the public call scipy makes) and the Rust acceleration alone
(``ukflex.run.simulate.time_acceleration``) on 20 states of one run, the kinds interleaved in
each repetition (in a random order); reports the median per call and the ratio to ``constant``. One run; the
machine is shared, so the figures are noisy.
"""
from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

import ukflex
from ukflex import LoadTable, scenes
from ukflex.run.simulate import time_acceleration

GAS = "-(2000 * (1 + cos(crank.theta))^2 + 40 * d:x(coupler, 1))"


def gas(t, state):
    return -(2000.0 * (1.0 + math.cos(state["crank.theta"])) ** 2 + 40.0 * 0.1524 * state["d:crank.theta"])


def build(kind):
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
    args = ap.parse_args()
    kinds = ["none", "constant", "expression", "table", "callable"]
    systems = {k: build(k) for k in kinds}
    base = systems["none"]
    te = np.linspace(0.0, 0.07, 20)
    res = ukflex.simulate(base, 0.07, method="DOPRI5", rtol=1e-8, atol=1e-10, t_eval=te)
    states = [(float(t), np.concatenate([res.q[:, k], res.qd[:, k]])) for k, t in enumerate(res.t)]
    n = base.n_coords
    rhs = {k: [] for k in kinds}
    core = {k: [] for k in kinds}
    loops = 200
    rng = np.random.default_rng(0)
    for _ in range(args.repeats):
        for k in rng.permutation(kinds):  # interleaved, in a new order each repetition
            f = systems[k].rhs
            tic = time.perf_counter()
            for _ in range(loops):
                for t, y in states:
                    f(t, y)
            rhs[k].append((time.perf_counter() - tic) / (loops * len(states)))
            t, y = states[7]
            core[k].append(time_acceleration(systems[k], t, y[:n], y[n:], reps=3000, batches=3))
    print(f"{'load':12s} {'System.rhs [us]':>16s} {'ratio':>6s} {'Rust acc [us]':>14s} {'ratio':>6s}")
    mr = {k: statistics.median(v) for k, v in rhs.items()}
    mc = {k: statistics.median(v) for k, v in core.items()}
    for k in kinds:
        print(f"{k:12s} {mr[k] * 1e6:16.2f} {mr[k] / mr['constant']:6.2f} {mc[k] * 1e6:14.2f} {mc[k] / mc['constant']:6.2f}")


if __name__ == "__main__":
    main()
