"""Whole paper run (slider-crank, 0..0.1 s) with every integrator path, in one run.

    .venv/bin/python benches/python_runs.py [--elements N] [--theory ...] [--skip-slow]

For each configuration: wall time (minimum of repeats), steps/evaluations, and the max error
of the coupler midpoint deflection v(0.5)/Lb over 101 equally spaced times against a tight
reference (native DOPRI5, rtol 1e-11, cross-checked with native RADAU5, rtol 1e-10).

Paths: native DOPRI5 / RADAU5 (``System.integrate``, all in Rust, GIL released); scipy
``solve_ivp`` driven by ``System.rhs`` -- explicit RK45 / DOP853, and implicit Radau / BDF with
the Rust Jacobian ``System.jac`` and (``--skip-slow`` leaves it out) with scipy's own
finite-difference Jacobian. Not a test: figures depend on the machine and its load.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.integrate import solve_ivp

import ukflex


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, default=1)
    ap.add_argument("--theory", default="timoshenko")
    ap.add_argument("--skip-slow", action="store_true", help="leave out scipy Radau with its own FD Jacobian")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()

    system = ukflex.System(ukflex.scenes.slider_crank(theory=args.theory, elements=args.elements))
    n = system.n_coords
    t_end = 0.1
    te = np.linspace(0.0, t_end, 101)
    S, _ = system.beam_shape("coupler", 0.5)
    sl = system.elastic_slice("coupler")
    Lb = system.description["bodies"][1]["length"]

    def v(Y):  # Y (2n, nt)
        return S[1] @ Y[sl.start:sl.stop, :] / Lb

    ref = system.integrate(system.t0, system.y0, t_end, "DOPRI5", 1e-11, np.array([1e-14]), te)
    chk = system.integrate(system.t0, system.y0, t_end, "RADAU5", 1e-10, np.array([1e-13]), te)
    v_ref = v(ref["y"])
    print(f"paper slider-crank, {args.theory}, N = {args.elements} (n = {n}): max |v(0.5)/Lb| = {np.max(np.abs(v_ref)):.4e}")
    print(f"reference: native DOPRI5 rtol 1e-11 ({ref['wall_time'] * 1e3:.0f} ms); native RADAU5 rtol 1e-10 differs by "
          f"{np.max(np.abs(v(chk['y']) - v_ref)):.1e}")
    print(f"{'path':44s} {'rtol':>7s} {'wall [ms]':>10s} {'steps':>7s} {'nfev':>8s} {'njev':>6s} {'max err v/Lb':>13s}")

    def row(name, rtol, fn, repeats=args.repeats):
        best, out = np.inf, None
        for _ in range(repeats):
            tic = time.perf_counter()
            out = fn()
            best = min(best, time.perf_counter() - tic)
        Y, steps, nfev, njev = out
        err = np.max(np.abs(v(Y) - v_ref))
        st = f"{steps:7d}" if steps >= 0 else f"{'-':>7s}"
        print(f"{name:44s} {rtol:7.0e} {best * 1e3:10.2f} {st} {nfev:8d} {njev:6d} {err:13.2e}", flush=True)

    def native(method, rtol):
        r = system.integrate(system.t0, system.y0, t_end, method, rtol, None, te)
        assert r["status"] == 0, r["message"]
        return r["y"], r["naccept"], r["nfev"], r["njev"]

    def scipy(method, rtol, jac=None):
        kw = {"jac": jac} if jac is not None else {}
        sol = solve_ivp(system.rhs, (system.t0, t_end), system.y0, method=method, t_eval=te, rtol=rtol,
                        atol=1e-3 * rtol, **kw)
        assert sol.status == 0, sol.message
        return sol.y, -1, sol.nfev, sol.njev

    for rtol in (1e-3, 1e-4, 5e-5, 3e-5, 1e-5, 1e-6):
        row("native DOPRI5", rtol, lambda: native("DOPRI5", rtol))
    for rtol in (1e-3, 1e-4, 1e-6):
        row("native RADAU5 (Rust FD Jacobian)", rtol, lambda: native("RADAU5", rtol))
    for rtol in (1e-4, 3e-5, 1e-6):
        row("scipy RK45 <- System.rhs", rtol, lambda: scipy("RK45", rtol), repeats=1)
    for rtol in (1e-3, 3e-4, 1e-4, 1e-6):
        row("scipy DOP853 <- System.rhs", rtol, lambda: scipy("DOP853", rtol), repeats=1)
    for rtol in (1e-3, 1e-6):
        row("scipy Radau <- rhs + Rust jac", rtol, lambda: scipy("Radau", rtol, system.jac), repeats=1)
        row("scipy BDF <- rhs + Rust jac", rtol, lambda: scipy("BDF", rtol, system.jac), repeats=1)
    if not args.skip_slow:
        row("scipy Radau <- rhs, scipy FD Jacobian", 1e-6, lambda: scipy("Radau", 1e-6), repeats=1)
    print("(scipy does not report its step count; nfev excludes the UK calls inside the Rust Jacobian)")


if __name__ == "__main__":
    main()
