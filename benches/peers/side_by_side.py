"""ukflex and Exudyn side by side on the paper scene: time to reach the physical answer.

Both codes run the paper's slider-crank with gravity, 0..0.1 s, in ONE process, interleaved
(every configuration of both codes once per repetition, alternating order), and report the
median wall time of the whole solve call: ukflex's ``simulate()`` on a freshly built System
(auto's modal analysis, the dense output and the result's assembly included), Exudyn's
``SolveDynamic`` (model building excluded for both).  Exudyn records its sensors at every step; ukflex's
GENALPHA series record the state at every step, its RADAU5M and auto series (a few hundred
steps: too sparse to place the peak) on a 0.1 ms grid from the dense output, the interpolation
included in the time; ``--outputs grid`` records every ukflex series at 10001 times from the
dense output instead.  Errors are measured against the same physical answer:
Exudyn's converged ANCF cable (benches/data/exudyn_ref_ancf.csv, N = 32, h = 7.8e-7), on the peak
|v(0.5)|/Lb over 0..0.07 s (parabolic refinement) and on the whole v(0.5)/Lb history over
0..0.1 s (max difference relative to the peak).

A point counts at an error level only if it is *reliable*: within the level, and the next finer
step of the same configuration (same code, model and N) is within it too; a peak that lands
on another lobe (peak time more than 2 ms off) or whose history error exceeds 10x the level is
luck, not accuracy.  For each level the fastest reliable point of each code and the ratio.

Optional (needs ``pip install exudyn``); not run in CI:

    python benches/peers/side_by_side.py --repeat 15      # ~1 min, writes benches/data/side_by_side.csv
    python benches/peers/side_by_side.py --repeat 3 --quick   # ~30 s
    python benches/peers/side_by_side.py --repeat 15 --fine  # ~2 min: also h = 2.5e-6, 1.25e-6 (ANCF N = 8)

History within 0.1 % needs ``--fine``: the reference carries the axial ripple (~4.2 kHz, ~0.09 %
of the peak) undamped over the run, and a run is within 0.1 % of its history only if it keeps
that ripple's phase over ~400 periods (period error below ~1e-4: h ~ 2e-6).  Coarser steps damp
it or let its phase drift: at h = 5e-6 .. 1.25e-5 both codes stay at ~0.18 % whatever N.
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import exudyn_slider_crank as es  # noqa: E402

import ukflex  # noqa: E402
from ukflex import scenes, simulate  # noqa: E402
from ukflex.run.choice import NEWTON_LOCAL_ERROR  # noqa: E402

DATA = os.path.normpath(os.path.join(HERE, "..", "data"))
T_END, PEAK_END = 0.1, 0.07
GRID = np.linspace(0.0, T_END, 10001)
LEVELS = (5e-3, 1e-3)
#: ``--fine``: steps added to both codes' ANCF N = 8 series (history within 0.1 %)
FINE_STEPS = (2.5e-6, 1.25e-6)

# (label, model, N, list of steps or None for auto, list of rtols for auto, GENALPHA options)
# one step grid for the N = 4 series of both codes (denser where both cross 0.1 % and 0.5 %)
GA_STEPS = (4e-4, 2e-4, 1.75e-4, 1.5e-4, 1e-4, 9e-5, 8e-5, 7.5e-5, 7e-5, 6.5e-5, 6e-5, 5e-5, 2.5e-5)
LOCAL = {"newton_local_error": NEWTON_LOCAL_ERROR}  # GENALPHA's looser Newton test (set by hand)
# rho_inf = 0.8 as well as the default 0.9, for both codes: more damping of the unresolved axial
# ripple (29 krad/s) makes the nonlinear FFRF coupler's error a smooth function of the step
RHO = 0.8
UK_CONFIGS = [
    ("ukflex auto", "nonlinear-ffrf", 4, None, (1e-5, 1e-6, 1e-7, 1e-8), {}),
    ("ukflex auto", "ancf", 4, None, (1e-5, 1e-6, 1e-7, 1e-8), {}),
    ("ukflex auto", "ancf", 8, None, (1e-6, 1e-7, 1e-8), {}),
    ("ukflex GENALPHA", "nonlinear-ffrf", 4, GA_STEPS, None, {}),
    ("ukflex GENALPHA local", "nonlinear-ffrf", 4, GA_STEPS, None, LOCAL),
    (f"ukflex GENALPHA local rho {RHO}", "nonlinear-ffrf", 4, GA_STEPS, None, {**LOCAL, "rho_inf": RHO}),
    ("ukflex GENALPHA", "nonlinear-ffrf", 8, (2e-4, 1e-4, 5e-5, 2.5e-5), None, {}),
    ("ukflex GENALPHA", "ancf", 4, (4e-4, 2e-4, 1e-4, 7.5e-5, 5e-5, 2.5e-5), None, {}),
    ("ukflex GENALPHA local", "ancf", 4, (4e-4, 2e-4, 1e-4, 7.5e-5, 5e-5, 2.5e-5), None, LOCAL),
    ("ukflex GENALPHA", "ancf", 8, (2e-4, 1e-4, 5e-5, 2.5e-5), None, {}),
    # Radau IIA on the second-order equations, error-controlled: a few hundred steps, so its
    # outputs (and auto's, which picks it with a fixed step) come from the dense output on a
    # 0.1 ms grid (step ends alone are too sparse to place the peak: ~20 per bending period);
    # the interpolation is part of its time
    # error-controlled RADAU5M: its tolerance is the achieved error of every coordinate and rate,
    # so it resolves the axial ripple's velocities (~4,000 steps even at rtol 0.1)
    ("ukflex RADAU5M", "nonlinear-ffrf", 4, None, (1e-1, 1e-2), {"method": "RADAU5M"}),
    # auto at looser tolerances: its step follows rtol (1.16e-3 at 1e-3, 8.2e-4 at 1e-4)
    ("ukflex auto", "nonlinear-ffrf", 4, None, (1e-3, 1e-4), {}),
    # RADAU5M at fixed steps around auto's (3.26e-4 for N = 4): what the default's rule leaves;
    # its rtol is then Newton's tolerance (the default 1e-6, and auto's 1e-3 at rtol 1e-3)
    ("ukflex RADAU5M step", "nonlinear-ffrf", 4, (3.47e-4, 5e-4, 7e-4, 1e-3, 1.4e-3), None, {"method": "RADAU5M"}),
    ("ukflex RADAU5M step newton 1e-3", "nonlinear-ffrf", 4, (5e-4, 7e-4, 1e-3, 1.4e-3), None, {"method": "RADAU5M", "rtol": 1e-3}),
    ("ukflex RADAU5M step", "nonlinear-ffrf", 2, (3.47e-4, 5e-4, 7e-4, 1e-3, 1.4e-3), None, {"method": "RADAU5M"}),
]
#: the output grid of RADAU5M and auto runs (dense output)
DENSE_GRID = np.linspace(0.0, T_END, 1001)
# (label, model, N, steps, rho_inf)
EXU_CONFIGS = [("Exudyn GA", "ancf", 2, (4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5), 0.9), ("Exudyn GA", "ancf", 4, GA_STEPS, 0.9),
               (f"Exudyn GA rho {RHO}", "ancf", 4, GA_STEPS, RHO),
               ("Exudyn GA", "ancf", 8, (4e-4, 2e-4, 1.75e-4, 1.5e-4, 1e-4, 7.5e-5, 6e-5, 5e-5, 2.5e-5), 0.9)]


def uk_scene(model: str, n: int):
    if model == "ancf":
        return scenes.slider_crank(formulation="ancf", elements=n).build()
    return scenes.slider_crank(strain="nonlinear", theory="euler-bernoulli", elements=n).build()


def metrics(t, v, ref):
    peak, t_peak = es.refined_peak(t, v, PEAK_END)
    return {"peak": peak, "t_peak": t_peak, "peak_err": abs(peak - ref["peak"]) / ref["peak"],
            "hist_err": es.history_error(t, v, ref["t"], ref["v"], ref["peak"], T_END)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--quick", action="store_true", help="fewer configurations")
    ap.add_argument("--fine", action="store_true", help=f"also the steps {FINE_STEPS} for both codes' ANCF N = 8 series")
    ap.add_argument("--out", default=os.path.join(DATA, "side_by_side.csv"))
    ap.add_argument("--outputs", choices=("steps", "grid"), default="steps",
                    help="ukflex records the state at its step ends (default; Exudyn records its sensors at every "
                         "step) or at 10001 times from the dense output (the old scope: ~25 %% of a run's time)")
    args = ap.parse_args(argv)
    t_ref, v_ref, _ = es.load_reference(os.path.join(DATA, "exudyn_ref_ancf.csv"))
    ref = {"t": t_ref, "v": v_ref}
    ref["peak"], ref["t_peak"] = es.refined_peak(t_ref, v_ref, PEAK_END)
    lb = scenes.PAPER["coupler_length"]

    runs = []  # (key, callable) -> callable returns (wall, t, v, info)
    systems = {}
    def finer(model, n, steps):
        return tuple(steps) + FINE_STEPS if args.fine and steps is not None and (model, n) == ("ancf", 8) else steps

    for label, model, n, steps, rtols, extra in UK_CONFIGS[: 3 if args.quick else None]:
        steps = finer(model, n, steps)
        for par in (rtols if steps is None else steps):
            def run(model=model, n=n, par=par, by_rtol=steps is None, extra=extra):
                kw = {"rtol": par, **extra} if by_rtol else {"method": "GENALPHA", "step": par, **extra}
                te = GRID if args.outputs == "grid" else (DENSE_GRID if kw.get("method", "auto") in ("RADAU5M", "auto") else None)
                sys_ = uk_scene(model, n)  # a freshly built System; the build is not timed (nor Exudyn's)
                tic = time.perf_counter()
                res = simulate(sys_, T_END, t_eval=te, **kw)
                wall = time.perf_counter() - tic  # the whole call, as the user waits
                _, v = res.beam_displacement("coupler", 0.5)
                info = {"method": res.method, "step": res.extra.get("auto", {}).get("step", None if by_rtol else par),
                        "ok": res.success, "steps": res.extra.get("naccept", 0)}
                return wall, res.t, v / lb, info
            runs.append(((label, model, n, par), run))
    for label, model, n, steps, rho in EXU_CONFIGS[: 2 if args.quick else None]:
        for h in finer(model, n, steps):
            def run(model=model, n=n, h=h, rho=rho):
                r = es.build_and_solve(model, n, h, t_end=T_END, rho_inf=rho)
                return r["wall"], r["t"], r["v"], {"method": "generalized-alpha", "step": h, "ok": r["ok"],
                                                   "steps": r["steps"]}
            runs.append(((label, model, n, h), run))

    walls = {key: [] for key, _ in runs}
    last = {}
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    for rep in range(args.repeat):
        order = runs if rep % 2 == 0 else runs[::-1]
        for key, run in order:
            wall, t, v, info = run()
            walls[key].append(wall)
            last[key] = (t, v, info)
        print(f"repetition {rep + 1}/{args.repeat}, load {os.getloadavg()[0]:.2f}", flush=True)
    elapsed = time.perf_counter() - t0
    rows = []
    for key, _ in runs:
        t, v, info = last[key]
        m = metrics(t, v, ref) if info["ok"] else {"peak": np.nan, "t_peak": np.nan, "peak_err": np.inf, "hist_err": np.inf}
        rows.append({"code": key[0], "model": key[1], "N": key[2], "param": key[3], "method": info["method"],
                     "step": info["step"], "steps": info["steps"], "median_ms": 1e3 * float(np.median(walls[key])),
                     "min_ms": 1e3 * float(np.min(walls[key])), **m})
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w", newline="") as fh:
        fh.write(f"# ukflex {ukflex.__version__} vs Exudyn {es.EXUDYN_VERSION}, paper scene with gravity, 0..0.1 s, solve-only "
                 f"medians of {args.repeat} interleaved repetitions, load {load0:.2f} -> {os.getloadavg()[0]:.2f}; "
                 f"errors vs exudyn_ref_ancf.csv; written by: python benches/peers/side_by_side.py --repeat {args.repeat}"
                 f"{' --quick' if args.quick else ''}{' --fine' if args.fine else ''} --outputs {args.outputs}\n")
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"\n{elapsed:.0f} s; load {load0:.2f} -> {os.getloadavg()[0]:.2f}; wrote {args.out}\n")
    print(f"{'code':30s} {'model':15s} {'N':>2s} {'param':>8s} {'method':9s} {'step':>9s} {'median ms':>9s} "
          f"{'peak err':>9s} {'hist err':>9s}")
    for r in rows:
        step = f"{r['step']:.3g}" if r["step"] else "-"
        print(f"{r['code']:30s} {r['model']:15s} {r['N']:2d} {r['param']:8.3g} {r['method'][:9]:9s} {step:>9s} "
              f"{r['median_ms']:9.1f} {100 * r['peak_err']:8.3f}% {100 * r['hist_err']:8.3f}%")
    print()
    for level in LEVELS:
        for metric in ("peak", "hist"):
            best = {}
            for code in ("ukflex", "Exudyn"):
                cand = [r for r in rows if r["code"].startswith(code) and reliable(r, rows, metric, level, ref)]
                best[code] = min(cand, key=lambda r: r["median_ms"]) if cand else None
            cells = []
            for code in ("ukflex", "Exudyn"):
                b = best[code]
                cells.append(f"{code}: " + ("none" if b is None else
                                            f"{b['code']} {b['model']} N={b['N']} {b['param']:g} {b['median_ms']:.1f} ms "
                                            f"({100 * b[metric + '_err']:.3f} %)"))
            ratio = (best["Exudyn"]["median_ms"] / best["ukflex"]["median_ms"]
                     if best["ukflex"] and best["Exudyn"] else float("nan"))
            print(f"{metric} within {100 * level:g} %: " + "; ".join(cells) + f"; ukflex {ratio:.1f}x faster")
    return 0


def reliable(r, rows, metric, level, ref) -> bool:
    """Within the level, not by luck, and the next finer setting of the same series is within it too."""
    def ok(x):
        if x[metric + "_err"] > level:
            return False
        if metric == "peak" and (abs(x["t_peak"] - ref["t_peak"]) > 2e-3 or x["hist_err"] > 10 * level):
            return False
        return True
    if not ok(r):
        return False
    series = [x for x in rows if (x["code"], x["model"], x["N"]) == (r["code"], r["model"], r["N"])]
    finer = [x for x in series if x["param"] < r["param"]]
    if not finer:
        return True  # the finest of its series: nothing to check against
    nxt = max(finer, key=lambda x: x["param"])
    return ok(nxt)


if __name__ == "__main__":
    raise SystemExit(main())
