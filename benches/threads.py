"""Parallel independent simulations in Python threads (native integrators release the GIL).

    .venv/bin/python benches/threads.py [--runs 8] [--threads 2]

Runs `--runs` independent paper simulations (0..0.1 s, native DOPRI5, rtol 1e-4; each with a
different crank speed) serially, then on a ThreadPoolExecutor with `--threads` workers, (a)
one System per run and (b) all runs on one shared System (`integrate` uses a private
workspace per call, so a shared System does not serialize). Reports wall times, the speed-up,
and checks that the threaded results equal the serial ones bit for bit. Two controls separate
"the GIL is held" from "the machine has no free core": the same jobs in 2 *processes*
(multiprocessing: no GIL involved), and the progress a pure-Python main thread makes while one
native run is in flight. Not a test: the speed-up depends on free cores (load is printed).
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import ukflex


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=8)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--method", default="DOPRI5")
    ap.add_argument("--rtol", type=float, default=1e-4)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()

    omegas = [124.8 * (1.0 + 0.02 * k) for k in range(args.runs)]
    systems = [ukflex.System(ukflex.scenes.slider_crank(omega=w)) for w in omegas]
    shared = systems[0]
    te = np.linspace(0.0, 0.1, 101)

    def job(k, system=None):
        s = system if system is not None else systems[k]
        y0 = systems[k].y0
        r = s.integrate(0.0, y0, 0.1, args.method, args.rtol, None, te)
        assert r["status"] == 0, r["message"]
        return r["y"]

    def serial(shared_system=False):
        return [job(k, shared if shared_system else None) for k in range(args.runs)]

    def threaded(shared_system=False):
        with ThreadPoolExecutor(args.threads) as ex:
            return list(ex.map(lambda k: job(k, shared if shared_system else None), range(args.runs)))

    def best(fn):
        t, out = np.inf, None
        for _ in range(args.repeats):
            tic = time.perf_counter()
            out = fn()
            t = min(t, time.perf_counter() - tic)
        return t, out

    print(f"cores: {os.cpu_count()} | load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(f"{args.runs} independent runs, native {args.method} rtol {args.rtol:g}, 0..0.1 s each")
    for shared_system in (False, True):
        ts, ys = best(lambda: serial(shared_system))
        tt, yt = best(lambda: threaded(shared_system))
        same = all(np.array_equal(a, b) for a, b in zip(ys, yt))
        label = "one shared System" if shared_system else "one System per run"
        print(f"{label:20s}: serial {ts * 1e3:8.1f} ms | {args.threads} threads {tt * 1e3:8.1f} ms | "
              f"speed-up {ts / tt:4.2f}x | threaded == serial: {same}")
    # control 1: processes (no GIL at all)
    ctx = mp.get_context("fork")
    tp1, tp2 = np.inf, np.inf
    for _ in range(args.repeats):
        tic = time.perf_counter()
        with ctx.Pool(1) as pool:
            pool.map(_proc_job, [(w, args.method, args.rtol) for w in omegas])
        tp1 = min(tp1, time.perf_counter() - tic)
        tic = time.perf_counter()
        with ctx.Pool(args.threads) as pool:
            pool.map(_proc_job, [(w, args.method, args.rtol) for w in omegas])
        tp2 = min(tp2, time.perf_counter() - tic)
    print(f"{'control: processes':20s}: 1 process {tp1 * 1e3:8.1f} ms | {args.threads} processes {tp2 * 1e3:8.1f} ms | "
          f"speed-up {tp1 / tp2:4.2f}x  (what the machine's free cores allow)")
    # control 2: a pure-Python thread keeps running while a native run is in flight
    box = {}

    def long_run():
        box["t0"] = time.perf_counter()
        shared.integrate(0.0, shared.y0, 0.1, args.method, 1e-6, None, te)
        box["t1"] = time.perf_counter()

    stamps = []
    with ThreadPoolExecutor(1) as ex:
        fut = ex.submit(long_run)
        while not fut.done():
            stamps.append(time.perf_counter())
        fut.result()
    inside = sum(1 for s in stamps if box["t0"] < s < box["t1"])
    print(f"GIL check: the Python main thread ran {inside} loop iterations during a {(box['t1'] - box['t0']) * 1e3:.0f} ms "
          f"native run in another thread (0 would mean the GIL was held)")
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


def _proc_job(arg):
    w, method, rtol = arg
    s = ukflex.System(ukflex.scenes.slider_crank(omega=w))
    r = s.integrate(0.0, s.y0, 0.1, method, rtol, None, np.linspace(0.0, 0.1, 101))
    return r["status"]


if __name__ == "__main__":
    main()
