"""The checks behind the table of ``benches/auto_speed.py`` where auto is not the fastest way to
its physical error (docs/integrators.md, "auto on scenes nobody tuned it for").

* ``models``: is the reference converged, and how far off is each model?  The four-bar and the
  spinning beam as FFRF and ANCF models of 4, 8 and 16 elements, run by RADAU5M at 1/8 of auto's
  step (rtol 1e-9), against the 32-element reference of the table; on 4 and 8 elements also auto
  and (spinning beam) GENALPHA at 1/8 and 1/16 of auto's step.  ~15 s.
* ``coarse``: on a model whose own error is below 1 % (the four-bar, 8 elements), do the
  configurations that tie with auto on 4 elements still reach auto's physical error?  Medians of
  3 interleaved CPU times.  ~5 s.
* ``spin``: the steps the spinning ANCF cable lets each method's Newton take: GENALPHA and
  RADAU5M at fixed steps ``h = angle / omega`` (the hub's turn per step) for hub speeds 3, 6 and
  12 rad/s, cables of 4 and 8 elements: accepted steps and Newton failures (rejections).  ~20 s.

* ``overhead``: what auto adds to the run it picks on the shortest scene (the pinned beam, 0.02 s):
  its whole call, ``choose_method`` alone and RADAU5M at auto's step and Newton tolerance, CPU
  medians of 300 interleaved calls on one System.  ~3 s.

* ``tolerance``: does auto's step on the four-bar (4 elements) ask more than rtol and atol do?  Each
  position's error against the same model at h_auto / 16, in units of ``rtol max|q_i| + atol``,
  for auto, RADAU5M at 4 .. 1/2 h_auto (Newton at 1e-4, and at 4 and 1 h_auto at 1e-8) and
  error-controlled RADAU5M at the same rtol.  ~45 s.

    python benches/auto_speed_checks.py models|coarse|spin|overhead|tolerance
"""

from __future__ import annotations

import statistics
import sys
import time
import warnings

import numpy as np

import auto_speed as A
import ukflex
from ukflex import scenes
from ukflex.run.simulate import RUN_OPTIONS


def _h_auto(kind, f, n):
    scene, T, _ = A._scene(kind, f, n)
    return ukflex.simulate(scene.build(), T).extra["auto"]["step"], T


def models():
    refs = A.references(["four_bar", "spin_up"])
    for kind in ("four_bar", "spin_up"):
        phys = refs[kind][0]
        peak = np.abs(phys).max()
        for n in (4, 8, 16):
            for f in ("ancf", "ffrf"):
                h, _ = _h_auto(kind, f, n)
                cfg = [("RADAU5M h/8 rtol 1e-9", "RADAU5M", {"step": h / 8, "rtol": 1e-9})]
                if n < 16:
                    cfg.append(("auto", "auto", {}))
                if n < 16 and kind == "spin_up":
                    cfg += [(f"GENALPHA h/{k}", "GENALPHA", {"step": h / k}) for k in (8, 16)]
                for label, method, kw in cfg:
                    (cpu, _), y, res = A._run(kind, f, n, method, budget=120.0, **kw)
                    err = "failed" if y is None else f"{np.abs(y - phys).max() / peak:.2e}"
                    print(f"{kind:9} {f} N = {n:2}  {label:22} {1e3 * cpu:8.1f} ms CPU  physical error {err}", flush=True)


def coarse(n=8, repeat=3):
    phys = A.references(["four_bar"])["four_bar"][0]
    peak = np.abs(phys).max()
    for f in ("ffrf", "ancf"):
        h, _ = _h_auto("four_bar", f, n)
        cfg = [("auto", "auto", {}), ("auto rtol 1e-3", "auto", {"rtol": 1e-3}), ("auto rtol 1e-4", "auto", {"rtol": 1e-4}),
               ("RADAU5M 4 h_auto", "RADAU5M", {"step": 4 * h, "rtol": 1e-4}),
               ("RADAU5M 2 h_auto", "RADAU5M", {"step": 2 * h, "rtol": 1e-4})]
        cpu, err = {c[0]: [] for c in cfg}, {}
        for rep in range(repeat):
            for label, method, kw in (cfg if rep % 2 == 0 else cfg[::-1]):
                (c, _), y, _ = A._run("four_bar", f, n, method, **kw)
                cpu[label].append(c)
                err[label] = np.abs(y - phys).max() / peak
        for label, *_ in cfg:
            print(f"four_bar {f} N = {n}  {label:18} {1e3 * statistics.median(cpu[label]):7.1f} ms CPU  "
                  f"physical error {err[label]:.2e}", flush=True)


def spin():
    for n in (4, 8):
        for omega in (3.0, 6.0, 12.0):
            for method in ("GENALPHA", "RADAU5M"):
                for angle in (0.02, 0.04, 0.06, 0.08, 0.12):
                    system = scenes.spin_up(formulation="ancf", elements=n, omega=omega).build()
                    kw = {"rtol": 1e-4} if method == "RADAU5M" else {}
                    tic = time.process_time()
                    res = ukflex.simulate(system, 20.0, method=method, step=angle / omega, t_eval=np.linspace(0.0, 20.0, 401),
                                          max_wall_time=10.0, **kw)
                    print(f"N = {n}  omega {omega:4g}  {method:8}  omega h = {angle:4g} (h = {angle / omega:.4g} s, "
                          f"h^2 omega = {angle ** 2 / omega:.2e} s)  {1e3 * (time.process_time() - tic):7.1f} ms CPU  "
                          f"status {res.status}  steps {res.extra.get('naccept')}  rejected {res.extra.get('nreject')}",
                          flush=True)


def overhead(repeat=300):
    from ukflex.run.choice import choose_method

    te = np.linspace(0.0, 0.02, A.NOUT)
    for f in ("ffrf", "ancf"):
        system = scenes.pinned_beam(elements=A.N_MODEL, formulation=f, gravity=True).build()
        h = ukflex.simulate(system, 0.02).extra["auto"]["step"]
        runs = {"auto": lambda: ukflex.simulate(system, 0.02, t_eval=te),
                "choose_method": lambda: choose_method(system, 0.0, 0.02, 1e-6, floor=False),
                "RADAU5M at h_auto": lambda: ukflex.simulate(system, 0.02, method="RADAU5M", step=h, rtol=1e-4, t_eval=te)}
        cpu = {k: [] for k in runs}
        for _ in range(repeat):
            for label, run in runs.items():
                tic = time.process_time()
                run()
                cpu[label].append(time.process_time() - tic)
        ms = {k: 1e3 * statistics.median(v) for k, v in cpu.items()}
        rest = ms["auto"] - ms["choose_method"] - ms["RADAU5M at h_auto"]
        print(f"pinned beam {f}: " + ", ".join(f"{k} {v:.3f} ms" for k, v in ms.items()) + f", the rest {rest:.3f} ms CPU",
              flush=True)


def tolerance(rtol=1e-6):
    """The four-bar (4 elements) at the user's ``rtol`` (atol defaulted from it): each run's error
    against the same model at h_auto / 16 (rtol 1e-10), per coordinate, in units of the tolerance
    ``rtol max|q_i| + atol`` that rtol and atol set on it (the largest over the outputs and the
    positions, the FFRF model's rigid and elastic coordinates apart), and the coupler's
    deflection error in m.  auto's step against what rtol and atol ask; error-controlled RADAU5M
    at the same rtol is what they ask step by step (solve_ivp's meaning); RADAU5M at 4 and 1
    h_auto with Newton at 1e-8 separates the step's error from Newton's; the reference's own error
    against DOPRI5 at rtol 1e-10 (FFRF).  ~45 s."""
    atol = RUN_OPTIONS["defaults"]["atol_per_rtol"] * rtol
    for f in ("ffrf", "ancf"):
        scene, T, out = A._scene("four_bar", f, A.N_MODEL)
        system = scene.build()
        te = np.linspace(0.0, T, A.NOUT)
        h = ukflex.simulate(system, T).extra["auto"]["step"]
        ref = ukflex.simulate(scene.build(), T, method="RADAU5M", step=h / 16, rtol=1e-10, t_eval=te)
        yref, vref = ref.y, out(system, ref)
        elastic = system.elastic_mask() if f == "ffrf" else None
        tol = rtol * np.abs(yref).max(axis=1) + atol  # per coordinate, at its largest |y| (the loosest reading)
        n = system.n_coords
        if f == "ffrf":  # the reference's own error: DOPRI5 keeps every mode (FFRF only: ~15 s)
            tight = ukflex.simulate(scene.build(), T, method="DOPRI5", rtol=1e-10, t_eval=te, max_wall_time=120.0)
            e = np.abs(yref[:n] - tight.y[:n]).max(axis=1) / tol[:n]
            print(f"four_bar ffrf N = {A.N_MODEL}  the reference (h_auto / 16) against DOPRI5 rtol 1e-10 "
                  f"({tight.extra['naccept']} steps): deflection {np.abs(vref - out(system, tight)).max() * 0.3:.1e} m, "
                  f"position error / (rtol |q| + atol): rigid {e[~elastic].max():.2g}, elastic {e[elastic].max():.2g}", flush=True)
        cfg = [("auto", "auto", {"rtol": rtol})] + [(f"RADAU5M {k:g} h_auto", "RADAU5M", {"step": k * h, "rtol": 1e-4})
                                                   for k in (4, 2, 1, 0.5)]
        # the step's own error: Newton converged far below auto's 1e-4
        cfg += [(f"RADAU5M {k:g} h_auto, Newton 1e-8", "RADAU5M", {"step": k * h, "rtol": 1e-8}) for k in (4, 1)]
        cfg.append((f"RADAU5M rtol {rtol:g}", "RADAU5M", {"rtol": rtol}))  # error-controlled: solve_ivp's meaning
        for label, method, kw in cfg:
            (cpu, _), v, res = A._run("four_bar", f, A.N_MODEL, method, budget=60.0, **kw)
            e = np.abs(res.y[:n] - yref[:n]).max(axis=1) / tol[:n]
            parts = {"positions": e} if elastic is None else {"rigid": e[~elastic], "elastic": e[elastic]}
            dv = np.abs(v - vref).max() * 0.3  # the deflection is read per coupler length (0.3 m)
            print(f"four_bar {f} N = {A.N_MODEL}  {label:32} {1e3 * cpu:6.1f} ms CPU  {res.extra['naccept']:5} steps  "
                  f"deflection error {dv:.1e} m = {dv / atol:6.1f} atol;  position error / (rtol |q| + atol): "
                  + ", ".join(f"{k} {x.max():.2g}" for k, x in parts.items())
                  + (f";  stated floor {res.extra['auto']['floor']:.1e} m" if method == "auto" else ""), flush=True)


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    part = sys.argv[1] if len(sys.argv) > 1 else ""
    if part not in ("models", "coarse", "spin", "overhead", "tolerance"):
        sys.exit(__doc__.rstrip().splitlines()[-1].strip())
    {"models": models, "coarse": coarse, "spin": spin, "overhead": overhead, "tolerance": tolerance}[part]()
