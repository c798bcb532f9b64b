"""The 3D flexible pendulum's equal-accuracy pair (docs/spatial-flexible.md, "The 3D flexible
pendulum's beam against Exudyn"), timed as interleaved repetitions: the fastest run of each code
within 0.5 % of the elastic part of the tip motion in ``python -m studies
spatial-beam-pendulum-exudyn`` (ukflex's default ``simulate()``, only rtol set; Exudyn's
``ObjectBeamGeometricallyExact``), whose one-run times the study's table gives. Within 0.1 %
Exudyn has no run in the study (160 elements at 8000 steps: 2.5e-3), so no pair to time.

    PYTHONPATH=. python benches/pendulum_exudyn_targets.py [--repeat 3]     # ~70 s at load 5
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np

from studies import spatial_beam_pendulum_exudyn as sbe

#: (target, ukflex's elements and rtol, Exudyn's elements and steps)
PAIRS = ((5e-3, (20, 1e-7), (160, 4000)),)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    t = np.linspace(0.0, sbe.T_END, 61)
    times = {p: ([], []) for p in PAIRS}
    for _ in range(args.repeat):
        for p in PAIRS:
            _, (n_uk, rtol), (n_ex, steps) = p
            times[p][0].append(sbe.beam_tip(n_uk, t, rtol=rtol)[1])
            times[p][1].append(sbe.exudyn_tip(n_ex, t, steps)[1])
    print("| target | ukflex default [s] | Exudyn [s] | Exudyn / ukflex |")
    print("|---|---:|---:|---:|")
    for p in PAIRS:
        target, (n_uk, rtol), (n_ex, steps) = p
        u, x = statistics.median(times[p][0]), statistics.median(times[p][1])
        print(f"| {target:.1%} | {n_uk} el., rtol {rtol:g}: {u:.3f} | {n_ex} el., {steps} steps: {x:.2f} | {x / u:.0f} |")


if __name__ == "__main__":
    main()
