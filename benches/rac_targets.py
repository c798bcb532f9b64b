"""The right-angle cantilever's two equal-accuracy pairs (docs/spatial-flexible.md, "Simo and
Vu-Quoc's right-angle cantilever against Exudyn"), timed as interleaved repetitions: the fastest
run of each code within 0.5 % and 0.1 % of the mesh limit in ``python -m studies
right-angle-cantilever`` (ukflex's default ``simulate()`` at 20 and 40 elements per member,
Exudyn at 20 elements and 500 steps and at 40 elements and 1000 steps), whose one-run times the
study's table gives.

    PYTHONPATH=. python benches/rac_targets.py [--repeat 4]     # ~75 s at 4 repetitions
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np

from studies import right_angle_cantilever as rac

#: (target, ukflex's elements per member, Exudyn's elements per member and steps)
PAIRS = ((5e-3, 20, (20, 500)), (1e-3, 40, (40, 1000)))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=4)
    args = ap.parse_args()
    t = np.linspace(0.0, rac.T_END, 301)
    times = {p: ([], []) for p in PAIRS}
    for _ in range(args.repeat):
        for p in PAIRS:
            _, n_uk, (n_ex, steps) = p
            times[p][0].append(rac.ukflex_run(n_uk, t)[2])
            times[p][1].append(rac.exudyn_run(n_ex, t, steps)[2])
    print("| target | ukflex default [s] | Exudyn [s] | Exudyn / ukflex |")
    print("|---|---:|---:|---:|")
    for p in PAIRS:
        target, n_uk, (n_ex, steps) = p
        u, x = statistics.median(times[p][0]), statistics.median(times[p][1])
        print(f"| {target:.1%} | {n_uk} el.: {u:.2f} | {n_ex} el., {steps} steps: {x:.2f} | {x / u:.2f} |")


if __name__ == "__main__":
    main()
