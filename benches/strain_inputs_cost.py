"""Per-call cost of a load that reads a beam's internal force or strain (docs/loads.md, "Load
values"), against one that reads its displacement and one that reads neither.

    .venv/bin/python benches/strain_inputs_cost.py [--repeats 15] [--batches 9]

On the paper's slider-crank with a 2-element nonlinear Timoshenko FFRF coupler and with a
4-element ANCF cable coupler, a gas force on the slider ``-2000 (1 + cos(crank.theta))^2`` plus
one of ``v(coupler, 0.5)``, ``M(coupler, 0.5)``, ``d:kappa(coupler, 0.5)`` (or nothing); times the
Rust acceleration alone (``ukflex.run.simulate.time_acceleration``, the best of ``--batches``
batches of 3000 calls) at 5 states of one run, the kinds interleaved in a random order within
every repetition; reports medians and the ratio to the gas force alone. One run on a shared
machine: noisy.
"""
from __future__ import annotations

import argparse
import random
import statistics

import numpy as np

import ukflex
from ukflex import scenes
from ukflex.run.simulate import time_acceleration

KINDS = {
    "gas only": "",
    "v(coupler, 0.5)": " - 1e5 * v(coupler, 0.5)",
    "M(coupler, 0.5)": " - 10 * M(coupler, 0.5)",
    "d:kappa(coupler, 0.5)": " - 50 * d:kappa(coupler, 0.5)",
}


def build(formulation: str, extra: str) -> ukflex.System:
    """The slider-crank of ``formulation`` with the gas force plus ``extra``."""
    s = scenes.slider_crank(elements=2 if formulation == "ffrf" else 4, strain="nonlinear", formulation=formulation)
    s.point_load(s["coupler"].at(1.0), fx=f"-2000 * (1 + cos(crank.theta))^2{extra}")
    return s.build()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--batches", type=int, default=9)
    args = ap.parse_args()
    print(f"{'coupler':8s} {'input':24s} {'Rust acc [us]':>14s} {'ratio':>6s}")
    for formulation in ("ffrf", "ancf"):
        systems = {k: build(formulation, e) for k, e in KINDS.items()}
        run = ukflex.simulate(systems["gas only"], 0.02, method="DOPRI5", rtol=1e-8, t_eval=np.linspace(0.0, 0.02, 5))
        times = {k: [] for k in KINDS}
        for rep in range(args.repeats):
            j = rep % run.t.size
            order = list(KINDS)
            random.shuffle(order)
            for k in order:
                times[k].append(time_acceleration(systems[k], run.t[j], run.q[:, j], run.qd[:, j], reps=3000, batches=args.batches))
        base = statistics.median(times["gas only"])
        for k in KINDS:
            m = statistics.median(times[k])
            print(f"{formulation:8s} {k:24s} {m * 1e6:14.2f} {m / base:6.2f}")


if __name__ == "__main__":
    main()
