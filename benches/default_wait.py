"""The default's whole wait on the paper scene: ``simulate(scenes.slider_crank().build(), 0.1)``
(and the nonlinear FFRF coupler of 4 elements, the side-by-side's default) timed around the whole
call on a freshly built System, with where the time goes: auto's analysis
(``res.extra["auto"]["time"]``), the run inside the core (``res.wall_time``) and the rest (the
Python around them: arguments, the result).

Before/after two trees of the library in one session: run it alternately with each tree first
on the path (the extension has one ABI), e.g.

    for i in 1 2 3 4 5; do
      PYTHONPATH=/path/to/old/python python benches/default_wait.py --repeat 20 --label old
      python benches/default_wait.py --repeat 20 --label new
    done

(~2 s per call of the script), and take the medians of the medians. ``--outputs 1001`` times the
side-by-side's default (1,001 dense outputs); CPU is the calling thread's time (``time.thread_time``),
less sensitive than the wall time to the other processes of a loaded machine.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import ukflex
from ukflex import scenes, simulate

CASES = {
    "paper (linear FFRF, N = 1)": lambda: scenes.slider_crank(),
    "nonlinear FFRF, N = 4": lambda: scenes.slider_crank(strain="nonlinear", elements=4),
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--label", default="")
    ap.add_argument("--outputs", type=int, default=0,
                    help="t_eval of this many equally spaced times (the side-by-side's default: 1001); 0: the steps")
    args = ap.parse_args(argv)
    t_eval = np.linspace(0.0, 0.1, args.outputs) if args.outputs else None
    for name, make in CASES.items():
        total, auto, run, cpu = [], [], [], []
        for _ in range(args.repeat):
            system = make().build()  # fresh; the build is not timed
            tic, cpu0 = time.perf_counter(), time.thread_time()
            res = simulate(system, 0.1, t_eval=t_eval)
            total.append(time.perf_counter() - tic)
            cpu.append(time.thread_time() - cpu0)
            auto.append(res.extra["auto"].get("time", 0.0))
            run.append(res.wall_time)
        med = lambda v: 1e3 * statistics.median(v)  # noqa: E731
        rest = [t - a - r for t, a, r in zip(total, auto, run)]
        print(f"{args.label:5s} {name:28s} whole {med(total):6.3f} ms (min {1e3 * min(total):6.3f}); auto "
              f"{med(auto):6.3f}, run {med(run):6.3f}, rest {med(rest):6.3f}; CPU {med(cpu):6.3f}; {res.method} {res.extra['naccept']} steps; "
              f"load {np.round(__import__('os').getloadavg()[0], 2)}; {ukflex.__file__.rsplit('/python/', 1)[0]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
