"""``python -m studies spatial-beam-spin-up``: Kane's spin-up beam (``ukflex.scenes.spin_up``: 10 m,
EA = 2.8e7 N, EI = 1.4e4 N m^2, rho A = 1.2 kg/m, hub driven smoothly to 6 rad/s in 15 s) built in 3D
with the geometrically exact beam (``SpatialScene.beam``: a ``rigid3`` hub on a revolute joint about
world z with a rotation driver, the beam welded to it, bending out of the plane three times
stiffer) against the planar geometrically exact ANCF cable of the same beam (the planar
``spin_up(formulation="ancf")``), an independent model of the same physics in the plane of the
spin. The cable has neither shear nor rotary inertia; the beam has the section's (an aluminium
section, G = 2.63e10 Pa: kGA = 5/6 G A = 8.77e6 N, rotary inertia rho I per length), which at
L/h = 130 change the answer by far less than the discretization does. RADAU5M at rtol 1e-8 for
both.

Output: the tip's deflection in the hub frame, ``v`` (across the beam, in the plane) and ``u``
(along it), at 0.5 s intervals to 20 s.
"""

from __future__ import annotations

import math
import time
from typing import Any, List, Optional, Tuple

import numpy as np

import ukflex
from ukflex import scenes

L, EA, EI, MU, OMEGA, T_SPIN, T_END = 10.0, 2.8e7, 1.4e4, 1.2, 6.0, 15.0, 20.0
GA = 5.0 / 6.0 * 2.63e10 * 4e-4
RUN = dict(method="RADAU5M", rtol=1e-8, atol=1e-10)


def hub_angle(t: np.ndarray) -> np.ndarray:
    u = np.minimum(t, T_SPIN)
    c = (T_SPIN / (2 * math.pi)) ** 2
    return OMEGA / T_SPIN * (u ** 2 / 2 + c * (np.cos(2 * math.pi / T_SPIN * u) - 1)) + OMEGA * (t - u)


def _in_hub_frame(t: np.ndarray, x: np.ndarray, y: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    th = hub_angle(t)
    c, s = np.cos(th), np.sin(th)
    return c * x + s * y - L, -s * x + c * y


def cable(t: np.ndarray, elements: int) -> Tuple[np.ndarray, np.ndarray, float]:
    system = ukflex.System(scenes.spin_up(formulation="ancf", elements=elements, omega=OMEGA, spin_up_time=T_SPIN))
    t0 = time.perf_counter()
    res = ukflex.simulate(system, T_END, t_eval=t, **RUN)
    dt = time.perf_counter() - t0
    x, y = res.beam_position("beam", 1.0)
    return (*_in_hub_frame(t, np.asarray(x), np.asarray(y)), dt)


def beam3(t: np.ndarray, elements: int, **run: Any) -> Tuple[np.ndarray, np.ndarray, float]:
    """The tip's ``(u, v)`` in the hub frame at ``t`` and the wall time of ``simulate`` (with
    ``run``'s options, by default ``RUN``)."""
    s = ukflex.SpatialScene()
    hub = s.rigid_body("hub", 1.0, (1.0, 1.0, 1.0))
    s.revolute(s.ground.marker((0, 0, 0)), hub.marker((0, 0, 0)), name="axle")
    u = f"((t + {T_SPIN!r} - abs(t - {T_SPIN!r})) / 2)"
    c = (T_SPIN / (2.0 * math.pi)) ** 2
    motion = f"{OMEGA / T_SPIN!r} * ({u}^2 / 2 + {c!r} * (cos({2.0 * math.pi / T_SPIN!r} * {u}) - 1)) + {OMEGA!r} * (t - {u})"
    s.rotation_driver(s.ground.marker((0, 0, 0)), hub.marker((0, 0, 0)), motion, name="spin")
    rho_i = MU / 4e-4 * EI / 7e10  # rho I (I = EI / E, rho = rho A / A)
    sec = ukflex.CustomSection3(ea=EA, ga_y=GA, ga_z=GA, gj=EI, ei_y=3 * EI, ei_z=EI, mass_per_length=MU,
                                rotary_inertia=(4 * rho_i, 3 * rho_i, rho_i))
    b = s.beam("beam", (0, 0, 0), (L, 0, 0), sec, elements=elements)
    s.fixed(hub.marker((0, 0, 0)), b.node(0), name="clamp")
    system = ukflex.System(s)
    t0 = time.perf_counter()
    res = ukflex.simulate(system, T_END, t_eval=t, **(run or RUN))
    dt = time.perf_counter() - t0
    i = system.body_names.index(b.node_name(-1))
    q = np.asarray(res.q)[7 * i:7 * i + 7]
    p = q[3:] / np.linalg.norm(q[3:], axis=0)
    # the last node body's r is a quarter element before the tip, along the section's x axis
    ax = np.array([p[0] ** 2 + p[1] ** 2 - p[2] ** 2 - p[3] ** 2, 2 * (p[1] * p[2] + p[0] * p[3]), 2 * (p[1] * p[3] - p[0] * p[2])])
    tip = q[:3] + 0.25 * L / elements * ax
    assert np.max(np.abs(tip[2])) < 1e-9 * L  # stays in its plane
    return (*_in_hub_frame(t, tip[0], tip[1]), dt)


def main(argv: Optional[List[str]] = None) -> int:
    t = np.linspace(0.0, T_END, 41)
    ref_u, ref_v, dt = cable(t, 16)
    print(f"ANCF cable 16 elements: min v = {ref_v.min():.5f} m, v(20 s) = {ref_v[-1]:.5f} m, u(20 s) = {ref_u[-1]:.6f} m  ({dt:.1f} s)")
    for n in (8, 16, 32):
        u, v, dt = beam3(t, n)
        print(f"beam3 {n:3d} elements: min v = {v.min():.5f} m, max |v - cable| = {np.max(np.abs(v - ref_v)):.3e} m, "
              f"max |u - cable| = {np.max(np.abs(u - ref_u)):.3e} m  ({dt:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
