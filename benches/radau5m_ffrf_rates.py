"""Why error-controlled RADAU5M takes ~20,000 steps on the FFRF four-bar (issue 26, item 4).

The four-bar with a flexible coupler (``scenes.four_bar``, Euler-Bernoulli, 4 elements), 0.63 s,
as an FFRF model. Every run is measured in the measure of the RADAU5M rtol table
(benches/radau5m_rtol.py): each coordinate and each rate at 401 times against a converged run of
the same model (RADAU5M at a fixed h = 1e-6 s; its own error: the run at 2e-6 against it),
relative to its largest value plus 1e-3; the largest over positions and over rates apart.

Rows: error-controlled RADAU5M at rtol 1e-2, 1e-3, 1e-4 (default ``atol = 1e-3 rtol``); the same with
the test blind to the elastic positions or to the elastic rates (their ``atol`` 1e3); scipy's
Radau (Hairer's RADAU5 estimate on the first-order system ``System.rhs``) at the user's
tolerances and at RADAU5M's transformed ones (``0.01 rtol^0.87``, ``atol`` scaled alike);
RADAU5 (ukflex's first-order Radau); auto (RADAU5M at a fixed step); the ANCF model of the
same coupler, error-controlled (steps only). Then the ringing of the coupler's rates, FFRF and
ANCF, in converged runs (an FFT over 0.2 s), against the weights of RADAU5M's test.

    python benches/radau5m_ffrf_rates.py     # ~1.5 min at load 5 (the converged runs ~15 s CPU of it)
"""

from __future__ import annotations

import time
import warnings

import numpy as np
from scipy.integrate import Radau

import ukflex
from ukflex import scenes

T = 0.63
TE = np.linspace(0.0, T, 401)
WINDOW = (0.4, 0.6)  # the FFT's window, sampled at the reference step
H_REF = 1e-6


def build(formulation="ffrf"):
    return scenes.four_bar(theory="euler-bernoulli", elements=4, formulation=formulation).build()


def reference():
    """The converged run at TE and the run at twice its step (its own error)."""
    out = {}
    for h in (2 * H_REF, H_REF):
        res = ukflex.simulate(build(), T, method="RADAU5M", step=h, rtol=1e-10, t_eval=TE)
        assert res.success, res.message
        out[h] = res.y
    return out[H_REF], out[2 * H_REF]


def ringing(formulation, rtol=1e-2):
    """The coupler's rates in a converged run (h = 2e-6) over WINDOW: their median size and the
    largest line of their spectrum above 10,000 rad/s, against the weight ``atol + rtol |qd|``
    of RADAU5M's test at ``rtol`` (transformed; at the median size)."""
    s = build(formulation)
    n = s.n_coords
    tw = np.arange(WINDOW[0], WINDOW[1], 2 * H_REF)
    res = ukflex.simulate(s, WINDOW[1], method="RADAU5M", step=2 * H_REF, rtol=1e-10, t_eval=tw)
    assert res.success, res.message
    w = 2 * np.pi * np.fft.rfftfreq(tw.size, tw[1] - tw[0])
    r = 0.01 * rtol ** 0.87
    print(f"# {formulation.upper()} coupler rates, converged run over {WINDOW[0]:g}-{WINDOW[1]:g} s: the largest "
          f"line above 1e4 rad/s against the test's weight at rtol {rtol:g}")
    for i, name in enumerate(s.coordinate_names):
        if not name.startswith("coupler"):
            continue
        v = res.y[n + i]
        spec = np.abs(np.fft.rfft((v - v.mean()) * np.hanning(v.size))) * 4 / v.size
        k = np.argmax(np.where(w > 1e4, spec, 0.0))
        med = np.median(np.abs(v))
        print(f"  {name:14s} median |qd| {med:.1e}  line {spec[k]:.1e} at {w[k]:7,.0f} rad/s  "
              f"= {spec[k] / (1e-3 * r + r * med):8.1f} x the weight")


def measure(y, yr, n):
    e = np.abs(y - yr) / (np.abs(yr).max(axis=1, keepdims=True) + 1e-3)
    return e[:n].max(), e[n:].max()


def scipy_radau(rtol, atol):
    """Steps of scipy's Radau and its solution at TE (its dense output per step)."""
    s = build()
    sol = Radau(s.rhs, 0.0, s.y0, T, rtol=rtol, atol=atol)
    y = np.empty((s.y0.size, TE.size))
    y[:, 0] = s.y0
    k, j = 0, 1
    while sol.status == "running":
        sol.step()
        k += 1
        d = sol.dense_output()
        while j < TE.size and TE[j] <= sol.t:
            y[:, j] = d(TE[j])
            j += 1
    assert sol.status == "finished"
    return k, y


def main():
    warnings.simplefilter("ignore")
    tic = time.perf_counter()
    yr, y2 = reference()
    s = build()
    n = s.n_coords
    el = np.asarray(s.elastic_mask(), bool)
    print(f"# reference RADAU5M h = {H_REF:g}: the run at h = {2 * H_REF:g} against it: "
          "positions %.1e, rates %.1e" % measure(y2, yr, n))
    print(f"{'run':52s} {'steps':>7s} {'rejected':>8s} {'CPU s':>6s} {'pos err':>8s} {'rate err':>8s}")

    def row(label, steps, rej, cpu, y):
        eq, ev = measure(y, yr, n)
        print(f"{label:52s} {steps:7d} {rej:>8} {cpu:6.2f} {eq:8.1e} {ev:8.1e}", flush=True)

    for rtol in (1e-2, 1e-3, 1e-4):
        for tag in ("", "elastic positions out", "elastic rates out"):
            atol = np.full(2 * n, 1e-3 * rtol)
            if tag == "elastic positions out":
                atol[:n][el] = 1e3
            elif tag == "elastic rates out":
                atol[n:][el] = 1e3
            c = time.process_time()
            res = ukflex.simulate(build(), T, method="RADAU5M", rtol=rtol, atol=atol, t_eval=TE)
            c = time.process_time() - c
            row(f"RADAU5M rtol {rtol:g} {tag}", res.extra["naccept"], res.extra["nreject"], c, res.y)
    for rtol in (1e-2,):
        for tag, r in (("user's", rtol), ("RADAU5M's transformed", 0.01 * rtol ** 0.87)):
            c = time.process_time()
            k, y = scipy_radau(r, 1e-3 * r)
            row(f"scipy Radau rtol {rtol:g}, {tag} tolerance", k, "", time.process_time() - c, y)
        c = time.process_time()
        res = ukflex.simulate(build(), T, method="RADAU5", rtol=rtol, t_eval=TE)
        row(f"RADAU5 rtol {rtol:g}", res.extra["naccept"], res.extra["nreject"], time.process_time() - c, res.y)
    c = time.process_time()
    res = ukflex.simulate(build(), T, t_eval=TE)
    row("auto (RADAU5M at a fixed step)", res.extra["naccept"], res.extra["nreject"], time.process_time() - c, res.y)
    for rtol in (1e-2, 1e-3):
        c = time.process_time()
        res = ukflex.simulate(build("ancf"), T, method="RADAU5M", rtol=rtol, t_eval=TE)
        print(f"{'ANCF model, RADAU5M rtol %g' % rtol:52s} {res.extra['naccept']:7d} {res.extra['nreject']:>8} "
              f"{time.process_time() - c:6.2f}")
    print(f"# coupler modes (rad/s), FFRF: {', '.join(f'{x:,.0f}' for x in s.frequencies())}")
    for formulation in ("ffrf", "ancf"):
        ringing(formulation)
    print(f"# {time.perf_counter() - tic:.0f} s")


if __name__ == "__main__":
    main()
