"""Where the default's whole ``simulate()`` call goes on the side-by-side scene (issue 26).

The workload is the side-by-side's default: ``simulate(system, 0.1, t_eval=1,001 times)`` on a
freshly built nonlinear FFRF coupler (N = 4), auto's pick (RADAU5M at a fixed step). Sample it
with ``perf`` (call graphs by DWARF: the core has no frame pointers) and sort the samples into
the phases of the call by the innermost frame that names one:

    python benches/paper_default_profile.py --run 600 &        # builds 600 Systems, then runs
    # when it prints "ready <pid>":
    perf record -F 2000 --call-graph dwarf,16384 -p <pid> -o /tmp/p.data -- sleep 2.5
    perf script -i /tmp/p.data -F ip,sym > /tmp/p.txt
    python benches/paper_default_profile.py --phases /tmp/p.txt

(~15 s; the 600 builds come first and are not sampled.)
"""

from __future__ import annotations

import argparse
import collections
import os
import time

#: (a frame's name contains, phase), innermost frame first
PHASES = (
    ("augmented_residual", "stage residuals (3 per Newton iteration)"),
    ("SecondOrderSystem>::acc", "UK evaluation at the step end"),
    ("project_step", "projection after the step"),
    ("lu_cplx_solve", "complex triangular solves"),
    ("lu_cm_solve", "real triangular solves"),
    ("pair_solve", "both triangular solves (side by side)"),
    ("lu_cplx", "complex LU"),
    ("lu_cm", "real LU"),
    ("stiff_structure", "structure read (M, K, A)"),
    ("::structure", "velocity terms (differences)"),
    ("dense_eval", "dense output (1,001 times)"),
    ("RadauM::stages", "stage states"),
    ("SingularMonitor", "singular monitor"),
    ("solution_dict", "result to Python (core)"),
)


def run(count: int) -> None:
    import numpy as np

    from ukflex import scenes, simulate

    grid = np.linspace(0.0, 0.1, 1001)

    def scene():
        return scenes.slider_crank(strain="nonlinear", theory="euler-bernoulli", elements=4).build()

    systems = [scene() for _ in range(count)]
    simulate(scene(), 0.1, t_eval=grid)
    print(f"ready {os.getpid()}", flush=True)
    time.sleep(1.0)
    for s in systems:
        simulate(s, 0.1, t_eval=grid)


def phase(frames: list) -> str:
    for f in frames:
        for key, name in PHASES:
            if key in f:
                return name
    if any("auto_choice" in f for f in frames):
        return "auto's analysis (core)"
    if any("RadauM" in f or "integrate_observed" in f for f in frames):
        return "RADAU5M step: Newton's loops (solves inlined), dense output"
    if any("ukflex::" in f for f in frames):
        return "core, other (the run's setup)"
    return "Python (arguments, result)"


def phases(path: str) -> None:
    counts: collections.Counter = collections.Counter()
    with open(path) as fh:
        for block in fh.read().split("\n\n"):
            frames = [ln.strip().split(" ", 1)[-1] for ln in block.strip().split("\n") if ln.strip()]
            if frames:
                counts[phase(frames)] += 1
    total = sum(counts.values())
    for name, k in counts.most_common():
        print(f"{100 * k / total:5.1f} %  {name}")
    print(f"{total} samples")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--run", type=int, metavar="CALLS", help="run the default CALLS times (after building the Systems)")
    ap.add_argument("--phases", metavar="PERF_SCRIPT", help="sort `perf script -F ip,sym` output into the call's phases")
    args = ap.parse_args(argv)
    if args.run:
        run(args.run)
    if args.phases:
        phases(args.phases)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
