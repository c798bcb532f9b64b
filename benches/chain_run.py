"""A pendulum chain of K rigid links (scenes.chain) simulated natively for T seconds: wall
time, energy drift and constraint drift (public API only). docs/scale.md.

    .venv/bin/python benches/chain_run.py [--links 256] [--t-end 2] [--method DOPRI5] [--rtol 1e-8]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from ukflex import scenes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--links", type=int, default=256)
    ap.add_argument("--t-end", type=float, default=2.0)
    ap.add_argument("--method", default="DOPRI5")
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--uk-solver", default="auto")
    ap.add_argument("--outputs", type=int, default=201)
    a = ap.parse_args()

    tic = time.perf_counter()
    system = scenes.chain(links=a.links).build(uk_solver=a.uk_solver)
    build = time.perf_counter() - tic
    n = system.n_coords
    t_eval = np.linspace(0.0, a.t_end, a.outputs)
    tic = time.perf_counter()
    run = system.integrate(0.0, system.y0, a.t_end, method=a.method, rtol=a.rtol, t_eval=t_eval)
    wall = time.perf_counter() - tic
    if run["status"] != 0:
        raise SystemExit(f"integration failed: {run['message']}")
    y = np.asarray(run["y"])  # (2n, nt)
    energy = np.array([system.kinetic_energy(y[:n, k], y[n:, k]) + system.potential_energy(y[:n, k]) for k in range(y.shape[1])])
    # Phi and A qd + Phi_t (Phi_t = 0 here) from the segment form of A: no dense m x n per output
    res = [system.residuals(t, y[:n, k], y[n:, k]) for k, t in enumerate(run["t"])]
    phi = max(float(np.max(np.abs(r[0]))) for r in res)
    vel = max(float(np.max(np.abs(r[1]))) for r in res)
    swing = float(np.max(np.abs(energy - energy[0])))
    scale = max(abs(system.potential_energy(y[:n, k])) for k in range(y.shape[1]))  # energy scale of the run
    system.qdd(0.0, system.q0, system.qd0)
    print(f"chain K={a.links} (n={n}, m={system.n_constraints}, UK path {system.core.uk_solver[1]}), "
          f"{a.method} rtol={a.rtol:g}, t_end={a.t_end:g} s")
    print(f"  build {build:.2f} s, integrate {wall:.2f} s wall (solver's own {run['wall_time']:.2f} s), "
          f"{run['nfev']} rhs calls, {run['naccept']} steps")
    print(f"  energy drift max|E - E0| = {swing:.3e} J (max|V| = {scale:.3e} J, relative {swing / scale:.2e})")
    print(f"  constraint drift max|Phi| = {phi:.3e} m, max|A qd| = {vel:.3e} m/s")


if __name__ == "__main__":
    main()
