"""The cost of progress reports on native runs (issue 33): the paper's slider-crank, timed around
the whole ``ukflex.simulate()`` call on a freshly built System, medians of interleaved runs.

    python benches/progress_cost.py --repeat 15 [--baseline DIR]

Variants, interleaved round by round (each round runs every variant once, each in a fresh
process, in an order that rotates from round to round): ``off`` (``progress=None``), ``on`` (a no-op callback: Rust takes the GIL every
100 steps or 0.5 s) and, with ``--baseline DIR`` (a ``python/`` folder holding another build of
ukflex, e.g. the commit before progress reports), ``baseline`` (that build, ``progress=None``).
Public API only.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

CASES = [("DOPRI5", dict(method="DOPRI5", rtol=1e-8)), ("auto", dict())]


def _times(progress: bool, reps: int) -> dict:
    import ukflex

    out = {}
    for label, kw in CASES:
        ts = []
        for _ in range(reps):
            system = ukflex.scenes.slider_crank().build()
            tic = time.perf_counter()
            res = ukflex.simulate(system, 0.1, progress=(lambda t: None) if progress else None, **kw)
            ts.append(time.perf_counter() - tic)
            assert res.success, res.message
        out[label] = ts
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=15, help="rounds (default 15)")
    ap.add_argument("--reps", type=int, default=3, help="runs of each case per variant and round (default 3)")
    ap.add_argument("--baseline", default=None, help="python/ folder of another ukflex build")
    ap.add_argument("--worker", choices=("off", "on"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        print(json.dumps(_times(args.worker == "on", args.reps)))
        return 0
    here = os.path.dirname(os.path.abspath(__file__))
    tree = os.path.join(here, os.pardir, "python")
    variants = {"off": (tree, "off"), "on": (tree, "on")}
    if args.baseline:
        variants = {"baseline": (args.baseline, "off"), **variants}
    samples = {v: {c: [] for c, _ in CASES} for v in variants}
    names = list(variants)
    for r in range(args.repeat):
        for v in names[r % len(names):] + names[:r % len(names)]:  # the order rotates round by round
            path, mode = variants[v]
            env = dict(os.environ, PYTHONPATH=os.path.abspath(path))
            out = subprocess.run([sys.executable, __file__, "--worker", mode, "--reps", str(args.reps)], env=env,
                                 capture_output=True, text=True, check=True, cwd="/")
            for c, ts in json.loads(out.stdout).items():
                samples[v][c].extend(ts)
    for c, _ in CASES:
        med = {v: statistics.median(samples[v][c]) for v in variants}
        line = ", ".join(f"{v} {1e3 * m:.2f} ms" for v, m in med.items())
        ratios = [f"on/off {med['on'] / med['off']:.3f}"]
        if "baseline" in med:
            ratios.insert(0, f"off/baseline {med['off'] / med['baseline']:.3f}")
        print(f"{c}: medians of {len(samples['off'][c])} runs: {line}; {', '.join(ratios)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
