"""The default ``simulate()`` on the beam3 scenes of issue 31's speed targets, timed as
interleaved repetitions on freshly built Systems (docs/spatial-flexible.md, "Speed of the
default on the beam"): Kane's spin-up beam at 8 and 20 elements (rtol 1e-5, the study's
fastest runs within 0.5 % and 0.1 %) and the right-angle cantilever at 20 elements per member
(the default, its 0.5 % run). Prints the medians, the solver's counts (``nfev``, ``njev``,
``nlu``) of one more run, and with ``--save``/``--compare`` the answers'
largest change against a saved run (a build before a change), in units of each scene's output
scale (the spin-up's 0.57 m dip, the frame's largest tip displacement).

    PYTHONPATH=. python benches/beam3_speed.py [--repeat 3] [--save before.npz] [--compare before.npz]

Before / after a change of the extension: run it once per build, alternating, with
``PYTHONPATH=<a copy of python/ with the other build's _core>:.`` for the other build.
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any, Callable, Dict, List, Tuple

import numpy as np
import ukflex

from studies import right_angle_cantilever as rac
from studies import spatial_beam_spin_up as spin


def _spin_up(n: int) -> Callable[[], Tuple[np.ndarray, float, Any]]:
    t = np.linspace(0.0, spin.T_END, 201)

    def run() -> Tuple[np.ndarray, float, Any]:
        u, v, dt = spin.beam3(t, n, rtol=1e-5)
        return np.column_stack([u, v]), dt, None

    return run


def _rac(n: int) -> Callable[[], Tuple[np.ndarray, float, Any]]:
    t = np.linspace(0.0, rac.T_END, 301)

    def run() -> Tuple[np.ndarray, float, Any]:
        _, tip, dt = rac.ukflex_run(n, t)
        return tip, dt, None

    return run


SCENES: Dict[str, Tuple[str, Callable[[], Callable[[], Tuple[np.ndarray, float, Any]]]]] = {
    "spin8": ("spin-up beam, 8 elements, rtol 1e-5", lambda: _spin_up(8)),
    "spin20": ("spin-up beam, 20 elements, rtol 1e-5", lambda: _spin_up(20)),
    "rac20": ("right-angle cantilever, 20 el./member, default", lambda: _rac(20)),
}


def counts(key: str) -> str:
    """The method, nfev, njev and nlu of one default run (simulate's result)."""
    seen: Dict[str, Any] = {}
    orig = ukflex.simulate

    def spy(*a: Any, **kw: Any) -> Any:
        seen["res"] = orig(*a, **kw)
        return seen["res"]

    ukflex.simulate = spy
    try:
        SCENES[key][1]()()
    finally:
        ukflex.simulate = orig
    r = seen["res"]
    return f"method {r.method}, nfev {r.nfev}, njev {r.njev}, nlu {r.nlu}"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--save", default=None)
    ap.add_argument("--compare", default=None)
    args = ap.parse_args()
    keys = args.scenes.split(",")
    runs = {k: SCENES[k][1]() for k in keys}
    times: Dict[str, List[float]] = {k: [] for k in keys}
    out: Dict[str, np.ndarray] = {}
    t0 = time.perf_counter()
    for _ in range(args.repeat):
        for k in keys:
            y, dt, _ = runs[k]()
            times[k].append(dt)
            out[k] = y
    print(f"ukflex {ukflex.__file__}; {args.repeat} interleaved repetitions, {time.perf_counter() - t0:.0f} s")
    ref = dict(np.load(args.compare)) if args.compare else {}
    for k in keys:
        line = f"{SCENES[k][0]}: median {statistics.median(times[k]):.3f} s ({', '.join(f'{x:.2f}' for x in times[k])}); {counts(k)}"
        if k in ref:
            scale = np.abs(ref[k]).max() if k.startswith("rac") else np.abs(ref[k][:, 1]).max()
            line += f"; change against the saved run {np.abs(out[k] - ref[k]).max() / scale:.2e}"
        print(line)
    if args.save:
        np.savez(args.save, **out)


if __name__ == "__main__":
    main()
