"""The default's Newton on the paper scene: what its tolerance buys (issue 26, the default 5x).

``method="auto"`` runs the nonlinear FFRF coupler (N = 4) with RADAU5M at a fixed step
(3.26e-4 s, 307 steps) and Newton at ``rtol`` 1e-4 (``ukflex.run.choice`` NEWTON_PER_RTOL x the
default 1e-6). This runs that fixed step with the Newton tolerance (a fixed step's ``rtol``) from
1e-8 to 1e-3 and prints, for each: Newton iterations, the median whole ``simulate()`` call with
1,001 outputs (0..0.1 s, fresh Systems, interleaved), the peak and history errors of v(0.5)/Lb
against Exudyn's converged ANCF cable (benches/data/exudyn_ref_ancf.csv, as
benches/peers/side_by_side.py measures them), and the energy balance's residual at 7,001
outputs over 0..0.07 s (what the crank driver's work leaves unexplained).

    python benches/paper_default_newton.py            # ~2 s at --repeat 9
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "peers"))
import exudyn_slider_crank as es  # noqa: E402  (the reference and the error measures; Exudyn not needed)

from ukflex import scenes, simulate  # noqa: E402

T_END, PEAK_END = 0.1, 0.07
GRID = np.linspace(0.0, T_END, 1001)
BALANCE_GRID = np.linspace(0.0, PEAK_END, 7001)
TOLS = (1e-8, 1e-6, 1e-5, 1e-4, 1e-3)


def scene():
    return scenes.slider_crank(strain="nonlinear", theory="euler-bernoulli", elements=4).build()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=9)
    args = ap.parse_args(argv)
    t_ref, v_ref, _ = es.load_reference(os.path.join(HERE, "data", "exudyn_ref_ancf.csv"))
    peak_ref, _ = es.refined_peak(t_ref, v_ref, PEAK_END)
    lb = scenes.PAPER["coupler_length"]
    default = simulate(scene(), T_END, t_eval=GRID)
    h = default.extra["auto"]["step"]
    runs = [("default (auto)", {})] + [(f"step, Newton rtol {tol:g}", {"method": "RADAU5M", "step": h, "rtol": tol})
                                       for tol in TOLS]
    times = {name: [] for name, _ in runs}
    for _ in range(args.repeat):
        for name, kw in runs:
            system = scene()
            tic = time.perf_counter()
            simulate(system, T_END, t_eval=GRID, **kw)
            times[name].append(time.perf_counter() - tic)
    print(f"auto's step {h:.4g} s; whole call, median of {args.repeat} (load {os.getloadavg()[0]:.1f})")
    print(f"{'run':28s} {'Newton it.':>10s} {'ms':>7s} {'peak err':>9s} {'history':>8s} {'balance [J]':>12s}")
    for name, kw in runs:
        res = simulate(scene(), T_END, t_eval=GRID, **kw)
        _, v = res.beam_displacement("coupler", 0.5)
        peak, _ = es.refined_peak(res.t, v / lb, PEAK_END)
        hist = es.history_error(res.t, v / lb, t_ref, v_ref, peak_ref, T_END)
        bal = simulate(scene(), PEAK_END, t_eval=BALANCE_GRID, **kw).sensors.energy_balance()
        print(f"{name:28s} {res.extra['newton_iterations']:10d} {1e3 * statistics.median(times[name]):7.2f} "
              f"{100 * abs(peak - peak_ref) / peak_ref:8.4f}% {100 * hist:7.3f}% {bal['residual'][-1]:+12.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
