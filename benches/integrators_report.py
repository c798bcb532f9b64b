"""The integrator figures of docs/integrators.md, through the public API only (~3.5 min):

    python benches/integrators_report.py

1. GENALPHA and RADAU5M per-step cost, Newton iterations, kernel calls and factorizations per step;
2. the Jacobian: structured vs central differences, per call and inside RADAU5 / scipy Radau;
3. drift over 100 crank revolutions at the default settings (what method="auto" picks);
4. numerical dissipation on an undamped free beam: GENALPHA at rho_inf = 1, 0.9, 0.6, 0; RADAU5M;
5. the second scene, the flexible four-bar: auto vs explicit methods against a tight reference;
6. method="auto" (RADAU5M) against the former default (GENALPHA at its frequency-rule step) on
   five built-in scenes, against native DOPRI5 at rtol 1e-11 of the same model.

Timings are medians of interleaved repetitions in this one run (the box is shared: compare the
ratios, not the absolute values).
"""

from __future__ import annotations

import math
import os
import time

import numpy as np

import ukflex
from ukflex import scenes, simulate
from ukflex.run.choice import choose_method
from ukflex.run.simulate import time_acceleration

REPEAT = 5


def median_time(fn, repeat=REPEAT):
    walls = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        walls.append(time.perf_counter() - t0)
    return float(np.median(walls))


def paper(model, n):
    if model == "linear":
        return scenes.slider_crank(elements=n).build()
    if model == "ancf":
        return scenes.slider_crank(formulation="ancf", elements=n).build()
    return scenes.slider_crank(strain="nonlinear", theory="euler-bernoulli", elements=n).build()


def per_step():
    print("1. Per step (paper scene, 0..0.1 s, default projection): GENALPHA at fixed h = 1e-4, rho_inf = 0.9;")
    print("   RADAU5M at the step and Newton tolerance method='auto' takes (0.3 / omega_1, rtol 1e-4);")
    print("   kernel calls: residual evaluations + UK calls")
    print(f"   {'method':8s} {'model':16s} {'N':>2s} {'n':>3s} {'h':>8s} {'us/step':>8s} {'Newton it/step':>14s} "
          f"{'kernel calls/step':>17s} {'LU per 100 steps':>16s} {'UK call us':>10s}")
    for model, n in (("linear", 1), ("nonlinear-ffrf", 4), ("ancf", 4), ("nonlinear-ffrf", 8), ("ancf", 8)):
        s = paper(model, n)
        uk = 1e6 * time_acceleration(s, 0.0, s.q0, s.qd0, reps=2000, batches=11)
        for method in ("GENALPHA", "RADAU5M"):
            # RADAU5M as auto runs it: its step and its Newton tolerance
            c = choose_method(s, 0.0, 0.1, 1e-6)
            h, rtol = (1e-4, 1e-6) if method == "GENALPHA" else (c.step, c.rtol)
            runs = [simulate(s, 0.1, method=method, step=h, rtol=rtol) for _ in range(REPEAT)]
            r = runs[-1]
            steps = r.extra["naccept"]
            us = 1e6 * float(np.median([x.wall_time for x in runs])) / steps
            print(f"   {method:8s} {model:16s} {n:2d} {s.n_coords:3d} {h:8.2e} {us:8.2f} "
                  f"{r.extra['newton_iterations'] / steps:14.2f} {r.nfev / steps:17.2f} {100 * r.nlu / steps:16.1f} {uk:10.2f}")


def jacobians():
    print("\n2. Jacobian of the UK acceleration (2n x 2n): per call, median of 200 calls")
    print(f"   {'model':16s} {'N':>2s} {'central us':>10s} {'structured us':>13s} {'ratio':>6s}")
    for model, n in (("linear", 1), ("linear", 4), ("nonlinear-ffrf", 4), ("ancf", 4), ("linear", 8), ("ancf", 16)):
        s = paper(model, n)
        y = s.y0.copy()
        tc = median_time(lambda: [s.jac(0.01, y, "central") for _ in range(200)]) / 200
        ts = median_time(lambda: [s.jac(0.01, y, "structured") for _ in range(200)]) / 200
        print(f"   {model:16s} {n:2d} {1e6 * tc:10.1f} {1e6 * ts:13.1f} {tc / ts:6.1f}")
    print("   inside the integrators (paper scene, linear FFRF N = 4, 0..0.1 s, rtol 1e-6):")
    s = paper("linear", 4)
    cases = [("RADAU5 structured", dict(method="RADAU5", jacobian="structured")),
             ("RADAU5 central", dict(method="RADAU5", jacobian="central")),
             ("scipy Radau structured", dict(method="Radau", jac=lambda t, y: s.jac(t, y, "structured"))),
             ("scipy Radau central", dict(method="Radau", jac=lambda t, y: s.jac(t, y, "central")))]
    walls = {k: [] for k, _ in cases}
    last = {}
    for rep in range(3):
        for k, kw in (cases if rep % 2 == 0 else cases[::-1]):
            r = simulate(s, 0.1, rtol=1e-6, **kw)
            walls[k].append(r.wall_time)
            last[k] = r
    for k, _ in cases:
        r = last[k]
        print(f"   {k:24s} {1e3 * np.median(walls[k]):8.1f} ms  nfev {r.nfev:6d} njev {r.njev:4d} nlu {r.nlu:5d} "
              f"status {r.status}")


def drift():
    print("\n3. Drift over 100 crank revolutions (5.03 s), default settings (method='auto', rtol 1e-6)")
    for model, n in (("nonlinear-ffrf", 4), ("ancf", 4), ("linear", 1)):
        s = paper(model, n)
        t_end = 100 * 2 * math.pi / scenes.PAPER["omega"]
        t0 = time.perf_counter()
        r = simulate(s, t_end)
        wall = time.perf_counter() - t0
        step = r.extra["auto"]["step"]
        print(f"   {model:16s} N={n}: {r.method}" + (f" h={step:.3g}" if step else "") + f", {r.extra['naccept']} steps, "
              f"max ||Phi|| {r.max_residual('position'):.1e}, max ||A qd + Phi_t|| {r.max_residual('velocity'):.1e}, "
              f"{wall:.2f} s")


def dissipation():
    print("\n4. Numerical dissipation: undamped free beam spinning at 10 rad/s, elastic velocities over all modes,")
    print("   0.2 s with h = 2e-4; relative energy change (E0 - E) / E0")
    s = ukflex.Scene()
    rates = 0.5 * np.random.default_rng(0).standard_normal(12)
    s.beam("b", length=0.5, elements=4, theory="euler-bernoulli", section=ukflex.Circular(0.01), density=1200.0,
           youngs_modulus=2e9, angular_velocity=10.0, elastic_rates=list(rates))
    system = s.build(hold=None)
    w, V = system.frequencies(modes=True)
    print(f"   frequencies {np.abs(w[w > 10]).min():.0f} .. {np.abs(w).max():.0f} rad/s (omega h "
          f"{2e-4 * np.abs(w[w > 10]).min():.2f} .. {2e-4 * np.abs(w).max():.1f})")
    for rho in (1.0, 0.9, 0.6, 0.0):
        r = simulate(system, 0.2, method="GENALPHA", step=2e-4, rho_inf=rho, t_eval=[0.0, 0.2])
        e = r.energy()
        print(f"   GENALPHA rho_inf = {rho:3.1f}: {(e[0] - e[-1]) / e[0]:+.3e}")
    for h in (2e-4, 1e-3):
        r = simulate(system, 0.2, method="RADAU5M", step=h)
        e = r.energy()
        print(f"   RADAU5M h = {h:g}: {(e[0] - e[-1]) / e[0]:+.3e} (largest step-to-step gain {np.max(np.diff(e)) / e[0]:+.1e})")


def four_bar():
    print("\n5. Second scene: flexible four-bar (examples/four_bar_flexible.toml, Timoshenko coupler N = 2,")
    print("   crank 10 rad/s, one revolution 0.63 s); error of the coupler midpoint v(0.5) history against")
    print("   DOP853 at rtol 1e-11, relative to its peak")
    sc = ukflex.scenes.four_bar(theory="timoshenko")
    s = sc.build()
    t_end = 0.63
    te = np.linspace(0.0, t_end, 6301)
    ref = simulate(s, t_end, method="DOP853", rtol=1e-11, atol=1e-14, t_eval=te)
    _, vr = ref.beam_displacement("coupler", 0.5)
    pk = np.abs(vr).max()
    w = s.frequencies()
    print(f"   frequencies {w[0]:.0f} .. {w[-1]:.0f} rad/s; reference peak |v| = {pk:.3e} m")
    cases = [("auto rtol 1e-6", dict()), ("auto rtol 1e-7", dict(rtol=1e-7)), ("auto rtol 1e-8", dict(rtol=1e-8)),
             ("DOPRI5 rtol 1e-6", dict(method="DOPRI5")), ("DOPRI5 rtol 1e-8", dict(method="DOPRI5", rtol=1e-8)),
             ("GENALPHA h 1e-4", dict(method="GENALPHA", step=1e-4)),
             ("GENALPHA h 5.9e-5", dict(method="GENALPHA", step=5.9e-5)),
             ("RADAU5M rtol 1e-3", dict(method="RADAU5M", rtol=1e-3))]
    walls = {k: [] for k, _ in cases}
    last = {}
    for rep in range(REPEAT):
        for k, kw in (cases if rep % 2 == 0 else cases[::-1]):
            t0 = time.perf_counter()
            r = simulate(s, t_end, t_eval=te, **kw)
            walls[k].append(time.perf_counter() - t0)
            last[k] = r
    for k, _ in cases:
        r = last[k]
        _, v = r.beam_displacement("coupler", 0.5)
        extra = f" h={r.extra['auto']['step']:.3g}" if "auto" in r.extra and r.extra["auto"]["step"] else ""
        print(f"   {k:18s} -> {r.method:8s}{extra:12s} {1e3 * np.median(walls[k]):8.1f} ms  error "
              f"{np.abs(v - vr).max() / pk:.2e}  peak error {abs(np.abs(v).max() - pk) / pk:.2e}")


def former_default(system, t_end):
    """The step and options the former chooser gave GENALPHA (rtol 1e-6): a phase budget of
    0.1 rad over the run for omega_c, period error (omega h)^2 / 12; Newton at the local error
    level where h omega_max >= 8."""
    from ukflex.run.choice import LOCAL_NEWTON_MIN_STEP_OMEGA, NEWTON_LOCAL_ERROR
    c = choose_method(system, 0.0, t_end, 1e-6)
    eps = min(1e-2, 0.1 / (c.omega_elastic * t_end))
    h = min(math.sqrt(12.0 * eps) / c.omega_elastic, t_end / 20)
    kw = dict(method="GENALPHA", step=h, rtol=max(1e-6, 0.1 * eps))
    if h * c.omega_max >= LOCAL_NEWTON_MIN_STEP_OMEGA:
        kw["newton_local_error"] = NEWTON_LOCAL_ERROR
    return kw


def auto_against_former():
    print("\n6. method='auto' (RADAU5M) against the former default (GENALPHA, frequency-rule step), rtol 1e-6;")
    print("   errors of the flexible body's v(0.5) (cantilever: tip) against native DOPRI5 at rtol 1e-11 (it resolves")
    print("   every mode), relative to its peak")
    cases = [("paper N = 1", scenes.slider_crank().build(), 0.1), ("nonlinear FFRF N = 4", paper("nonlinear-ffrf", 4), 0.1),
             ("ANCF N = 4", paper("ancf", 4), 0.1), ("cantilever", scenes.cantilever(damping=1e-4).build(), 0.8),
             ("four-bar", scenes.four_bar(theory="timoshenko").build(), 0.63)]
    for name, s, t_end in cases:
        body = "coupler" if "coupler" in s.body_names else s.body_names[-1]
        xi = 0.5 if body == "coupler" else 1.0
        te = np.linspace(0.0, t_end, 2001)
        ref = simulate(s, t_end, method="DOPRI5", rtol=1e-11, atol=1e-14, t_eval=te)
        assert ref.success, ref.message
        vr = ref.beam_displacement(body, xi)[1]
        pk = np.abs(vr).max()
        runs = [("auto", {}), ("former", former_default(s, t_end))]
        walls = {k: [] for k, _ in runs}
        last = {}
        for rep in range(REPEAT):
            for k, kw in (runs if rep % 2 == 0 else runs[::-1]):
                t0 = time.perf_counter()
                last[k] = simulate(s, t_end, t_eval=te, **kw)
                walls[k].append(time.perf_counter() - t0)
        for k, kw in runs:
            r = last[k]
            v = r.beam_displacement(body, xi)[1]
            h = r.extra["auto"]["step"] if k == "auto" else kw["step"]
            print(f"   {name:22s} {k:6s} {r.method:8s} h={h:.3g} {r.extra['naccept']:6d} steps {1e3 * np.median(walls[k]):8.1f} ms  "
                  f"history {np.abs(v - vr).max() / pk:.2e}  peak {abs(np.abs(v).max() - pk) / pk:.2e}")


if __name__ == "__main__":
    print(f"ukflex {ukflex.__version__}, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.2f}\n")
    t0 = time.perf_counter()
    per_step()
    jacobians()
    drift()
    dissipation()
    four_bar()
    auto_against_former()
    print(f"\n{time.perf_counter() - t0:.0f} s, load {os.getloadavg()[0]:.2f}")
