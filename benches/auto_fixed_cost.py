"""What ``method="auto"`` adds to the run it picks, on the shortest scene of
``benches/auto_speed.py`` (the pinned beam under sudden gravity, 0.02 s, FFRF and ANCF of 4
elements): the whole ``simulate()`` call on a freshly built System with 401 outputs, auto against
RADAU5M at auto's step (the same run: 45 steps) and at twice it (23 steps, the fastest
configuration at auto's physical error in the table of docs/integrators.md, "auto on scenes
nobody tuned it for"), CPU medians of ``--repeat`` interleaved calls.  ``auto - RADAU5M at
h_auto`` is auto's own cost (its analysis and its Python), ``auto / RADAU5M at 2 h_auto`` the
table's ratio without its other configurations.

Before/after two trees of the library: run it alternately with each tree first on the path
(the extension has one ABI), e.g.

    for i in 1 2 3; do
      python benches/auto_fixed_cost.py --label new
      PYTHONPATH=/path/to/old/python python benches/auto_fixed_cost.py --label old
    done

(~5 s per call at the default ``--repeat 300``.)
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

import numpy as np

import ukflex
from ukflex import scenes

T_END, NOUT = 0.02, 401


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=300)
    ap.add_argument("--label", default="")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    te = np.linspace(0.0, T_END, NOUT)
    out = []
    for f in ("ffrf", "ancf"):
        scene = scenes.pinned_beam(elements=4, formulation=f, gravity=True)
        auto = ukflex.simulate(scene.build(), T_END)
        h, newton = auto.extra["auto"]["step"], auto.rtol
        runs = {"auto": lambda s: ukflex.simulate(s, T_END, t_eval=te),
                "h_auto": lambda s: ukflex.simulate(s, T_END, method="RADAU5M", step=h, rtol=newton, t_eval=te),
                "2 h_auto": lambda s: ukflex.simulate(s, T_END, method="RADAU5M", step=2 * h, rtol=newton, t_eval=te)}
        cpu = {k: [] for k in runs}
        for i in range(args.repeat):
            for label, run in (list(runs.items()) if i % 2 == 0 else list(runs.items())[::-1]):
                system = scene.build()
                tic = time.process_time()
                run(system)
                cpu[label].append(time.process_time() - tic)
        ms = {k: 1e3 * statistics.median(v) for k, v in cpu.items()}
        out.append(f"{f}: auto {ms['auto']:.3f}, RADAU5M at h_auto {ms['h_auto']:.3f}, at 2 h_auto {ms['2 h_auto']:.3f} ms "
                   f"CPU; auto - h_auto {ms['auto'] - ms['h_auto']:.3f} ms, auto / 2 h_auto {ms['auto'] / ms['2 h_auto']:.2f}")
    print(f"{args.label:4} pinned beam " + " | ".join(out), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
