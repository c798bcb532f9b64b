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

Round i26-bal (auto's step balanced against its floor, tried and not kept: docs/integrators.md,
"The pinned beams, at the edge"): the comparators are RADAU5M at the rtol step ``h_auto``
(``extra["auto"]["step_rtol"]`` where a tree balances the step, else auto's step) and at twice
it, fixed whatever step auto takes; a balanced step adds RADAU5M at auto's own step (``at h``).
``--errors``: each run's integration error instead (the mid-point deflection's largest
deviation, relative to its peak, from RADAU5M at ``h_auto / 16``, Newton at 1e-10) and the floor
auto states.
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
    ap.add_argument("--errors", action="store_true")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    te = np.linspace(0.0, T_END, NOUT)
    out = []
    for f in ("ffrf", "ancf"):
        scene = scenes.pinned_beam(elements=4, formulation=f, gravity=True)
        auto = ukflex.simulate(scene.build(), T_END)
        h, newton = auto.extra["auto"]["step"], auto.rtol
        h_rtol = auto.extra["auto"].get("step_rtol") or h

        def fixed(step):
            return lambda s: ukflex.simulate(s, T_END, method="RADAU5M", step=step, rtol=newton, t_eval=te)

        runs = {"auto": lambda s: ukflex.simulate(s, T_END, t_eval=te), "h_auto": fixed(h_rtol), "2 h_auto": fixed(2 * h_rtol)}
        if h != h_rtol:
            runs["h"] = fixed(h)
        if args.errors:
            mid = lambda res: np.asarray(res.beam_position("beam", 0.5)[1])  # noqa: E731
            ref = mid(ukflex.simulate(scene.build(), T_END, method="RADAU5M", step=h_rtol / 16, rtol=1e-10, t_eval=te))
            done = {k: run(scene.build()) for k, run in runs.items()}
            out.append(f"{f}: floor {auto.extra['auto']['floor']:.3g} m; " + ", ".join(
                f"{k} {np.abs(mid(r) - ref).max() / np.abs(ref).max():.2e} ({r.extra.get('naccept')} steps)" for k, r in done.items()))
            continue
        cpu = {k: [] for k in runs}
        for i in range(args.repeat):
            for label, run in (list(runs.items()) if i % 2 == 0 else list(runs.items())[::-1]):
                system = scene.build()
                tic = time.process_time()
                run(system)
                cpu[label].append(time.process_time() - tic)
        ms = {k: 1e3 * statistics.median(v) for k, v in cpu.items()}
        out.append(f"{f}: auto {ms['auto']:.3f}, RADAU5M at h_auto {ms['h_auto']:.3f}, at 2 h_auto {ms['2 h_auto']:.3f} ms "
                   f"CPU; auto - h_auto {ms['auto'] - ms['h_auto']:.3f} ms, auto / 2 h_auto {ms['auto'] / ms['2 h_auto']:.2f}"
                   + (f"; at h {ms['h']:.3f} ms, auto - h {ms['auto'] - ms['h']:.3f} ms" if "h" in ms else ""))
    print(f"{args.label:4} pinned beam " + " | ".join(out), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
