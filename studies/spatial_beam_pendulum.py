"""``python -m studies spatial-beam-pendulum``: the 3D flexible pendulum of docs/spatial-flexible.md
built twice, with the geometrically exact beam (``SpatialScene.beam``, Simo-Reissner elements) and
with the 3D modal body of the same bar from a solid FE model (``ukflex.fe3``, ``flexible3``).

The pendulum: a 0.5 m x 20 mm x 20 mm bar (rho = 7850 kg/m^3, E = 2.1 GPa, nu = 0.3) on a
spherical joint at the centroid of its end face, spin 3 rad/s about z (out of the plane in which
gravity would swing it), gravity -z, 0.3 s, DOPRI5 at rtol 1e-10. Output: the world position of
the tip (the beam's last node; the modal body's tip-face centroid, interface ``B``) at 61 instants.
The elastic part of the motion is measured against the rigid body of the same mass and inertia
(``rigid3``): the gap between the two flexible models is reported relative to the bar's length
and relative to that elastic part.
"""

from __future__ import annotations

import time
from typing import Any, List, Optional, Tuple

import numpy as np

import ukflex
from ukflex import fe3
from studies.spatial_flexible_exudyn import GRAVITY, LENGTH, OMEGA0, T_END, ukflex_tip

RHO, E, NU, SIDE = 7850.0, 2.1e9, 0.3, 0.02
RUN = dict(method="DOPRI5", rtol=1e-10, atol=1e-12)


def modal(mesh: Tuple[int, int, int], modes: int, stress_stiffening: bool = False,
          quadratic_strain: bool = False) -> fe3.FlexibleData3:
    m = fe3.bar_mesh(LENGTH, SIDE, SIDE, mesh)
    return fe3.from_mesh(m, density=RHO, youngs_modulus=E, poisson_ratio=NU,
                         interfaces={"A": lambda x: x[:, 0] < 1e-9, "B": lambda x: x[:, 0] > LENGTH - 1e-9},
                         modes=modes, frame=("clamped", "A"), stress_stiffening=stress_stiffening,
                         quadratic_strain=quadratic_strain)


def beam_tip(elements: int, t: np.ndarray, **run: Any) -> Tuple[np.ndarray, float]:
    """Tip positions (nt, 3) of the beam model and the wall time of ``ukflex.simulate`` (with
    ``run``'s options, by default ``RUN``)."""
    s = ukflex.SpatialScene(gravity=GRAVITY)
    b = s.beam("bar", (0, 0, 0), (LENGTH, 0, 0), ukflex.Rectangular(SIDE, SIDE), elements=elements, density=RHO,
               youngs_modulus=E, poisson_ratio=NU, angular_velocity=OMEGA0)
    s.spherical(s.ground.marker((0, 0, 0)), b.node(0))
    system = ukflex.System(s)
    t0 = time.perf_counter()
    res = ukflex.simulate(system, T_END, t_eval=t, **(run or RUN))
    dt = time.perf_counter() - t0
    i = system.body_names.index(b.node_name(-1))
    q = np.asarray(res.q)[7 * i:7 * i + 7].T
    # the last node body's r is its segment's centre of mass, a quarter element before the tip
    return np.array([qk[:3] + 0.25 * LENGTH / elements * _rotate(qk[3:], np.array([1.0, 0.0, 0.0])) for qk in q]), dt


def _rotate(p: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``A(p) v`` for unit Euler parameters ``p``."""
    e0, e = p[0] / np.linalg.norm(p), p[1:] / np.linalg.norm(p)
    return (e0 * e0 - e @ e) * v + 2 * e * (e @ v) + 2 * e0 * np.cross(e, v)


def rigid_tip(data: fe3.FlexibleData3, t: np.ndarray) -> np.ndarray:
    s = ukflex.SpatialScene(gravity=GRAVITY)
    r = s.rigid_body("bar", data.mass, data.inertia, com=data.com, angular_velocity=OMEGA0)
    s.spherical(s.ground.marker((0, 0, 0)), r.marker((0, 0, 0)))
    res = ukflex.simulate(ukflex.System(s), T_END, t_eval=t, **RUN)
    q = np.asarray(res.q).T
    out = np.empty((q.shape[0], 3))
    for k, qk in enumerate(q):
        out[k] = qk[0:3] + _rotate(qk[3:7], np.array([LENGTH, 0.0, 0.0]) - np.asarray(data.com))
    return out


def main(argv: Optional[List[str]] = None) -> int:
    t = np.linspace(0.0, T_END, 61)
    ref_data = modal((40, 2, 2), 8)
    ref, dt_ref = ukflex_tip(ref_data, t, **RUN)
    rig = rigid_tip(ref_data, t)
    elastic = np.max(np.linalg.norm(ref - rig, axis=1))
    print(f"elastic part of the tip motion (FFRF ref - rigid): {elastic:.3e} m = {elastic / LENGTH:.2e} L")
    rows = []
    for mesh, modes in (((10, 1, 1), 4), ((20, 2, 2), 8)):
        tip, dt = ukflex_tip(modal(mesh, modes), t, **RUN)
        rows.append((f"flexible3 {mesh} P2 tets, {modes} modes", tip, dt))
    rows.append(("flexible3 (40, 2, 2), 8 modes (ref)", ref, dt_ref))
    tip, dt = ukflex_tip(modal((20, 2, 2), 8, stress_stiffening=True), t, **RUN)
    rows.append(("flexible3 (20, 2, 2), 8, stiffened", tip, dt))
    for mesh, modes in (((40, 2, 2), 16), ((40, 2, 2), 8)):
        tip, dt = ukflex_tip(modal(mesh, modes), t, **RUN)
        rows.append((f"flexible3 {mesh}, {modes} modes", tip, dt))
        tip, dt = ukflex_tip(modal(mesh, modes, quadratic_strain=True), t, **RUN)
        rows.append((f"flexible3 {mesh}, {modes}, quadratic strain", tip, dt))
    for n in (5, 10, 20, 40):
        tip, dt = beam_tip(n, t)
        rows.append((f"beam3 {n} elements", tip, dt))
    beam20 = next(tip for name, tip, _ in rows if name == "beam3 20 elements")
    print(f"{'model':38s} | vs FFRF ref: / L | / elastic | vs beam3 20: / L | / elastic | time [s]")
    for name, tip, dt in rows:
        d = np.max(np.linalg.norm(tip - ref, axis=1))
        db = np.max(np.linalg.norm(tip - beam20, axis=1))
        print(f"{name:38s} | {d / LENGTH:.3e}        | {d / elastic:.3e} | {db / LENGTH:.3e}        | {db / elastic:.3e} | {dt:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
