"""Per-call cost of the accelerations seen from Python, all on the same states, in one run.

    .venv/bin/python benches/python_bench.py [--elements N] [--theory timoshenko|euler-bernoulli]

Reports, per call (minimum over repeats, and median), for the paper's slider-crank:

* the Rust UK acceleration alone (``ukflex.run.simulate.time_acceleration``: a loop inside Rust),
* ``System.qdd(t, q, qd)`` and ``System.rhs(t, y)`` (the binding: argument checks, copies,
  a fresh output array),
* ``System.jac(t, y)`` (Rust finite-difference Jacobian, 2n x 2n),
* NumPy UK: ``ReferenceModel(description)`` terms ``M, Q, A, gamma`` + ``uk_qdd``,
* NumPy CP: ``choose_partition(A)`` + ``reduced_accelerations`` (coordinate partitioning with
  the partition recomputed every call, as in the paper's implementation) and with a fixed
  partition,

and the ratios. Not a test: figures depend on the machine and its load.
"""
from __future__ import annotations

import argparse
import platform
import statistics
import time

import numpy as np

import ukflex
from ukflex.reference import ReferenceModel, uk_qdd
from ukflex.reference.cp import choose_partition, reduced_accelerations
from ukflex.run.simulate import time_acceleration


def per_call(fn, states, repeats=15, min_time=0.05):
    """(min, median) seconds per call of fn(state) over the states, over `repeats` batches."""
    loops = 1
    while True:
        tic = time.perf_counter()
        for _ in range(loops):
            for s in states:
                fn(s)
        if time.perf_counter() - tic > min_time / 5 or loops > 1 << 20:
            break
        loops *= 2
    out = []
    for _ in range(repeats):
        tic = time.perf_counter()
        for _ in range(loops):
            for s in states:
                fn(s)
        out.append((time.perf_counter() - tic) / (loops * len(states)))
    return min(out), statistics.median(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, default=1)
    ap.add_argument("--theory", default="timoshenko")
    ap.add_argument("--states", type=int, default=20)
    args = ap.parse_args()

    scene = ukflex.scenes.slider_crank(theory=args.theory, elements=args.elements)
    system = ukflex.System(scene)
    n = system.n_coords
    # states along a trajectory (native run), so all methods see realistic, consistent states
    te = np.linspace(0.0, 0.07, args.states)
    run = system.integrate(system.t0, system.y0, 0.07, "DOPRI5", 1e-8, None, te)
    Y = np.ascontiguousarray(run["y"].T)
    states = [(float(t), Y[k].copy(), Y[k, :n].copy(), Y[k, n:].copy()) for k, t in enumerate(run["t"])]

    ref = ReferenceModel(system.description)
    parts = {}

    def numpy_uk(s):
        t, _, q, qd = s
        return uk_qdd(ref.M(q), ref.Q(t, q, qd), ref.A(q), ref.gamma(t, q, qd))

    def numpy_cp_every_call(s):
        t, _, q, qd = s
        part = choose_partition(ref.A(q))
        return reduced_accelerations(ref, part, t, q, qd)[1]

    def numpy_cp_fixed(s):
        t, _, q, qd = s
        part = parts.setdefault(0, choose_partition(ref.A(q)))
        return reduced_accelerations(ref, part, t, q, qd)[1]

    # agreement on the states (sanity: same accelerations)
    worst = 0.0
    for s in states:
        a = system.qdd(s[0], s[2], s[3])
        b = numpy_uk(s)
        c = numpy_cp_every_call(s)
        scale = np.max(np.abs(a))
        worst = max(worst, np.max(np.abs(a - b)) / scale, np.max(np.abs(a - c)) / scale)

    rust_only = [time_acceleration(system, s[0], s[2], s[3], reps=2000, batches=9) for s in states]
    rust_min = min(rust_only)
    rust_med = statistics.median(rust_only)
    rows = [("Rust UK acceleration (loop inside Rust)", (rust_min, rust_med))]
    rows.append(("System.qdd(t, q, qd)", per_call(lambda s: system.qdd(s[0], s[2], s[3]), states)))
    rows.append(("System.rhs(t, y)", per_call(lambda s: system.rhs(s[0], s[1]), states)))
    rows.append(("System.jac(t, y) (2n x 2n)", per_call(lambda s: system.jac(s[0], s[1]), states, repeats=7)))
    rows.append(("NumPy UK (ReferenceModel + uk_qdd)", per_call(numpy_uk, states, repeats=5)))
    rows.append(("NumPy CP, partition every call", per_call(numpy_cp_every_call, states, repeats=5)))
    rows.append(("NumPy CP, fixed partition", per_call(numpy_cp_fixed, states, repeats=5)))

    print(f"ukflex python benchmark: paper slider-crank, {args.theory}, N = {args.elements} "
          f"(n = {n}, m = {system.n_constraints}), {len(states)} states along a trajectory")
    print(f"machine: {platform.machine()} {platform.processor() or ''} | Python {platform.python_version()} | "
          f"numpy {np.__version__} | {platform.platform()}")
    print(f"max relative difference of the accelerations Rust UK vs NumPy UK / CP on these states: {worst:.1e}")
    print(f"{'':44s} {'min/call':>12s} {'median/call':>12s}")
    for name, (mn, md) in rows:
        print(f"{name:44s} {mn * 1e6:10.3f} us {md * 1e6:10.3f} us")
    d = dict(rows)
    print("ratios (minimum times; medians in brackets):")

    def ratio(a, b):
        return f"{d[a][0] / d[b][0]:8.1f}x  [{d[a][1] / d[b][1]:.1f}x]"

    print(f"  Python rhs overhead over the Rust call:   {(d['System.rhs(t, y)'][0] - rust_min) * 1e6:6.3f} us "
          f"[{(d['System.rhs(t, y)'][1] - rust_med) * 1e6:.3f} us]")
    print(f"  Python qdd overhead over the Rust call:   {(d['System.qdd(t, q, qd)'][0] - rust_min) * 1e6:6.3f} us "
          f"[{(d['System.qdd(t, q, qd)'][1] - rust_med) * 1e6:.3f} us]")
    print(f"  NumPy CP (every call) / Rust UK:          {ratio('NumPy CP, partition every call', 'Rust UK acceleration (loop inside Rust)')}")
    print(f"  NumPy CP (every call) / System.rhs:       {ratio('NumPy CP, partition every call', 'System.rhs(t, y)')}")
    print(f"  NumPy CP (fixed partition) / Rust UK:     {ratio('NumPy CP, fixed partition', 'Rust UK acceleration (loop inside Rust)')}")
    print(f"  NumPy UK / Rust UK:                       {ratio('NumPy UK (ReferenceModel + uk_qdd)', 'Rust UK acceleration (loop inside Rust)')}")
    print(f"  NumPy CP (every call) / NumPy UK:         {ratio('NumPy CP, partition every call', 'NumPy UK (ReferenceModel + uk_qdd)')}")


if __name__ == "__main__":
    main()
