"""The default ``simulate()`` on the geometrically exact beam's scenes, before and after auto saw
the beam as elastic (docs/spatial-flexible.md, "Speed of the default").

``method="auto"`` once took a scene made of ``beam3`` node bodies (rigid) and elements (force
elements) for a rigid scene and ran DOPRI5 at the user's tolerances, resolving the beam's axial
modes; it now sees the elements' strain energy and takes RADAU5M at the step of the lowest
elastic mode. "before" is ``method="DOPRI5"`` (what auto picked then, at the same tolerances),
"after" the default ``simulate()``; each on a freshly built System, the whole call timed, medians
of interleaved repetitions; the error of each against a tight run of the same model (the largest
distance over the run of the scene's output, over its largest displacement; for the pendulum
over the elastic part of the tip motion, 4.30e-4 m).

    PYTHONPATH=. python benches/beam3_default.py               # minutes: DOPRI5 takes 8-40 s a run here
    PYTHONPATH=. python benches/beam3_default.py --repeat 1 --scenes rac20   # the 20-element frame
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any, Callable, Dict, List, Tuple

import numpy as np

from studies import right_angle_cantilever as rac
from studies import spatial_beam_pendulum as pen
from studies import spatial_beam_spin_up as spin

#: the elastic part of the pendulum's tip motion (docs/spatial-flexible.md)
PENDULUM_ELASTIC = 4.30e-4


def _rac(n: int) -> Tuple[Callable[..., Tuple[Any, float]], Dict[str, Any], Callable[[Any, Any], float]]:
    t = np.linspace(0.0, rac.T_END, 301)

    def run(**kw: Any) -> Tuple[Any, float]:
        e, tip, dt = rac.ukflex_run(n, t, **kw)
        return (e, tip), dt

    return run, dict(method="RADAU5", rtol=1e-9, atol=1e-10), rac.gap


def _pendulum(n: int):
    t = np.linspace(0.0, pen.T_END, 61)
    return (lambda **kw: pen.beam_tip(n, t, **kw)), dict(pen.RUN), lambda a, b: float(np.abs(a - b).max() / PENDULUM_ELASTIC)


def _spin_up(n: int):
    t = np.linspace(0.0, spin.T_END, 41)

    def run(**kw: Any) -> Tuple[Any, float]:
        u, v, dt = spin.beam3(t, n, **kw)
        return np.column_stack([u, v]), dt

    return run, dict(method="RADAU5M", rtol=1e-10, atol=1e-12), lambda a, b: float(np.abs(a - b).max() / np.abs(b[:, 1]).max())


SCENES = {
    "rac5": ("right-angle cantilever, 5 el./member, 30 s", lambda: _rac(5)),
    "rac10": ("right-angle cantilever, 10 el./member, 30 s", lambda: _rac(10)),
    "rac20": ("right-angle cantilever, 20 el./member, 30 s", lambda: _rac(20)),
    "pendulum": ("spatial beam pendulum, 10 elements, 0.3 s", lambda: _pendulum(10)),
    "spin_up": ("spin-up beam, 8 elements, 20 s", lambda: _spin_up(8)),
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--scenes", default="rac5,rac10,pendulum,spin_up")
    args = ap.parse_args()
    print("| scene | before: DOPRI5 [s] | error | after: default simulate() [s] | error | before / after |")
    print("|---|---:|---:|---:|---:|---:|")
    for key in args.scenes.split(","):
        label, make = SCENES[key]
        run, tight, err = make()
        ref, _ = run(**tight)
        times: Dict[str, List[float]] = {"before": [], "after": []}
        errors: Dict[str, float] = {}
        for _ in range(args.repeat):
            for name, kw in (("before", dict(method="DOPRI5")), ("after", dict(method="auto"))):
                out, dt = run(**kw)
                times[name].append(dt)
                errors[name] = err(out, ref)
        tb, ta = statistics.median(times["before"]), statistics.median(times["after"])
        print(f"| {label} | {tb:.2f} | {errors['before']:.1e} | {ta:.2f} | {errors['after']:.1e} | {tb / ta:.0f} |", flush=True)


if __name__ == "__main__":
    t0 = time.perf_counter()
    main()
    print(f"({time.perf_counter() - t0:.0f} s)")
