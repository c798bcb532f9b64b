"""The error floor ``method="auto"`` states on the geometrically exact beam's scenes
(``res.extra["auto"]["floor"]``) against the error its run shows (docs/spatial-flexible.md,
"Limits"; issue 26 item 3: within 3x).

The error: the largest distance, over the run's ``t_eval`` and over the beam's node bodies
(their ``r``), between the default ``simulate()`` (auto at rtol 1e-6) and a tight run of the
same mesh: DOPRI5 at rtol 1e-10, which keeps every mode the start sets off (the floor's physical
motion), and RADAU5M at rtol 1e-9 with its own step control.

    PYTHONPATH=. python benches/beam3_floor.py                    # minutes
    PYTHONPATH=. python benches/beam3_floor.py --scenes pendulum4 --refs DOPRI5
    PYTHONPATH=. python benches/beam3_floor.py --sweep spin_up8 --refs RADAU5M   # 10-30 s: where the error comes from
    PYTHONPATH=. python benches/beam3_floor.py --sweep rac5 --refs DOPRI5        # 10-30 s: the same on the frame
    PYTHONPATH=. python benches/beam3_floor.py --sweep rac5 --refs DOPRI5 --steps 0.1,0.0826,0.07,0.06,0.05,0.04
"""

from __future__ import annotations

import argparse
import math
import time
from typing import Any, Callable, Dict, Tuple

import numpy as np

import ukflex
from studies import right_angle_cantilever as rac
from studies import spatial_beam_pendulum as pen
from studies import spatial_beam_spin_up as spin
from studies.spatial_flexible_exudyn import GRAVITY, LENGTH, OMEGA0
from studies.spatial_flexible_exudyn import T_END as PEN_T_END

REFS = {"DOPRI5": dict(method="DOPRI5", rtol=1e-10, atol=1e-12),
        "RADAU5M": dict(method="RADAU5M", rtol=1e-9, atol=1e-11),
        "RADAU5": dict(method="RADAU5", rtol=1e-9, atol=1e-11)}


def pendulum(n: int) -> ukflex.System:
    s = ukflex.SpatialScene(gravity=GRAVITY)
    b = s.beam("bar", (0, 0, 0), (LENGTH, 0, 0), ukflex.Rectangular(pen.SIDE, pen.SIDE), elements=n, density=pen.RHO,
               youngs_modulus=pen.E, poisson_ratio=pen.NU, angular_velocity=OMEGA0)
    s.spherical(s.ground.marker((0, 0, 0)), b.node(0))
    return ukflex.System(s)


def spin_up(n: int) -> ukflex.System:
    """``studies/spatial_beam_spin_up.py``'s ``beam3`` scene."""
    s = ukflex.SpatialScene()
    hub = s.rigid_body("hub", 1.0, (1.0, 1.0, 1.0))
    s.revolute(s.ground.marker((0, 0, 0)), hub.marker((0, 0, 0)), name="axle")
    u = f"((t + {spin.T_SPIN!r} - abs(t - {spin.T_SPIN!r})) / 2)"
    c = (spin.T_SPIN / (2.0 * math.pi)) ** 2
    motion = (f"{spin.OMEGA / spin.T_SPIN!r} * ({u}^2 / 2 + {c!r} * (cos({2.0 * math.pi / spin.T_SPIN!r} * {u}) - 1))"
              f" + {spin.OMEGA!r} * (t - {u})")
    s.rotation_driver(s.ground.marker((0, 0, 0)), hub.marker((0, 0, 0)), motion, name="spin")
    rho_i = spin.MU / 4e-4 * spin.EI / 7e10
    sec = ukflex.CustomSection3(ea=spin.EA, ga_y=spin.GA, ga_z=spin.GA, gj=spin.EI, ei_y=3 * spin.EI, ei_z=spin.EI,
                                mass_per_length=spin.MU, rotary_inertia=(4 * rho_i, 3 * rho_i, rho_i))
    b = s.beam("beam", (0, 0, 0), (spin.L, 0, 0), sec, elements=n)
    s.fixed(hub.marker((0, 0, 0)), b.node(0), name="clamp")
    return ukflex.System(s)


SCENES: Dict[str, Tuple[str, Callable[[], ukflex.System], float]] = {
    "pendulum4": ("3D beam pendulum, 4 elements, 0.3 s", lambda: pendulum(4), PEN_T_END),
    "pendulum10": ("3D beam pendulum, 10 elements, 0.3 s", lambda: pendulum(10), PEN_T_END),
    "spin_up8": ("spin-up beam, 8 elements, 20 s", lambda: spin_up(8), spin.T_END),
    "rac5": ("right-angle cantilever, 5 el./member, 30 s", lambda: ukflex.System(rac.scene(5)), rac.T_END),
}


def node_positions(system: ukflex.System, q: np.ndarray) -> np.ndarray:
    """The node bodies' ``r`` (every body with 7 coordinates but a hub), (bodies, 3, nt)."""
    idx = [i for i, name in enumerate(system.body_names) if "[" in name]
    return np.stack([q[7 * i:7 * i + 3] for i in idx])


def sweep(key: str, ref: str, points: int) -> None:
    """Where a scene's error comes from: auto at rtol 1e-4 .. 1e-9 (its step, its Newton
    tolerance), and RADAU5M at auto's steps with Newton at 1e-9, and at 1/4 and 1/16 of the step
    of rtol 1e-6. Each run's accepted and rejected steps beside the steps its fixed step makes:
    where Newton cannot converge at the fixed step it cuts it (``radau_m.rs``, patience), and
    the run is not at the step it was given (docs/spatial-flexible.md, "Limits")."""
    label, make, T = SCENES[key]
    te = np.linspace(0.0, T, points)

    def run(**kw: Any) -> Tuple[np.ndarray, Any]:
        system = make()
        r = ukflex.simulate(system, T, t_eval=te, **kw)
        return node_positions(system, np.asarray(r.q)), r

    base, _ = run(**REFS[ref])
    steps = {}
    print(f"{label}, against {ref} at rtol {REFS[ref]['rtol']:g}")
    def counts(r: Any, h: float) -> str:
        return f"{r.extra['naccept']} accepted + {r.extra['nreject']} rejected steps for {math.ceil(T / h)}"

    for rtol in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9):
        x, r = run(rtol=rtol)
        a = r.extra["auto"]
        steps[rtol] = a["step"]
        print(f"auto rtol {rtol:g}: step {a['step']:.3g} s ({counts(r, a['step'])}), stated floor {a.get('floor')}, "
              f"error {np.linalg.norm(x - base, axis=1).max():.2e} m", flush=True)
    for h in (steps[1e-6], steps[1e-7], steps[1e-8], steps[1e-6] / 4, steps[1e-6] / 16):
        for newton in (1e-6, 1e-9):
            x, r = run(method="RADAU5M", step=h, rtol=newton)
            print(f"RADAU5M step {h:.3g} s, Newton {newton:g} ({counts(r, h)}): "
                  f"error {np.linalg.norm(x - base, axis=1).max():.2e} m", flush=True)


def steps(key: str, ref: str, points: int, hs: str) -> None:
    """RADAU5M at the fixed steps ``hs`` (Newton 1e-6), each run's steps and its error, also up to
    1, 1.5 and 2 s (the right-angle cantilever's load has its kinks at 0, 1 and 2 s)."""
    label, make, T = SCENES[key]
    te = np.linspace(0.0, T, points)
    ref_system = make()
    base = node_positions(ref_system, np.asarray(ukflex.simulate(ref_system, T, t_eval=te, **REFS[ref]).q))
    print(f"{label}, against {ref} at rtol {REFS[ref]['rtol']:g}")
    for h in (float(x) for x in hs.split(",")):
        system = make()
        r = ukflex.simulate(system, T, t_eval=te, method="RADAU5M", step=h, rtol=1e-6)
        e = np.linalg.norm(node_positions(system, np.asarray(r.q)) - base, axis=1).max(axis=0)
        upto = ", ".join(f"to {t:g} s {e[te <= t].max():.1e}" for t in (1.0, 1.5, 2.0))
        print(f"RADAU5M step {h:g} s ({r.extra['naccept']} accepted + {r.extra['nreject']} rejected steps for "
              f"{math.ceil(T / h)}): error {e.max():.2e} m ({upto})", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sweep", default="")
    ap.add_argument("--steps", default="", help="fixed steps for --sweep's scene, e.g. 0.1,0.0826,0.05")
    ap.add_argument("--scenes", default="pendulum4,pendulum10,spin_up8,rac5")
    ap.add_argument("--refs", default="DOPRI5,RADAU5M")
    ap.add_argument("--points", type=int, default=2001)
    args = ap.parse_args()
    if args.sweep and args.steps:
        steps(args.sweep, args.refs.split(",")[0], args.points, args.steps)
        return
    if args.sweep:
        sweep(args.sweep, args.refs.split(",")[0], args.points)
        return
    print("| scene | coordinates | stated floor [m] | reference | measured [m] | floor / measured | auto [s] | reference [s] |")
    print("|---|---:|---:|---|---:|---:|---:|---:|")
    for key in args.scenes.split(","):
        label, make, T = SCENES[key]
        te = np.linspace(0.0, T, args.points)
        system = make()
        t0 = time.perf_counter()
        res = ukflex.simulate(system, T, t_eval=te)
        ta = time.perf_counter() - t0
        floor = res.extra["auto"].get("floor")
        mine = node_positions(system, np.asarray(res.q))
        for ref in args.refs.split(","):
            system = make()
            t0 = time.perf_counter()
            r = ukflex.simulate(system, T, t_eval=te, **REFS[ref])
            tr = time.perf_counter() - t0
            err = float(np.linalg.norm(mine - node_positions(system, np.asarray(r.q)), axis=1).max())
            ratio = "-" if floor is None else f"{floor / err:.2f}"
            fl = "None" if floor is None else f"{floor:.2e}"
            print(f"| {label} | {system.n_coords} | {fl} | {ref} {REFS[ref]['rtol']:g} | {err:.2e} | {ratio} | {ta:.2f} | {tr:.1f} |",
                  flush=True)


if __name__ == "__main__":
    t0 = time.perf_counter()
    main()
    print(f"({time.perf_counter() - t0:.0f} s)")
