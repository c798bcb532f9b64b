"""Write examples/slider_crank_holed_link.toml: the paper's slider-crank whose coupler is a flat
steel link with two lightening holes (a part a beam cannot represent), meshed with quads,
assembled by scikit-fem in plane stress and reduced to 6 free-free (mean-axis) modes.

    python examples/holed_link.py                     # needs the 'fe' extra (scikit-fem)
    ukflex run examples/slider_crank_holed_link.toml --animate
"""

import math
import os

import numpy as np

from ukflex import ConstantSpeed, Scene, fe
from ukflex.model import scenefile

L, LB, OMEGA = 0.1524, 0.3048, 124.8
W, T = 0.024, 0.004  # link height and thickness [m]
NX, NY = 48, 8
HOLES = [(LB / 3, 0.0, 0.007), (2 * LB / 3, 0.0, 0.007)]  # centre x, y, radius


def mesh():
    xs, ys = np.linspace(0.0, LB, NX + 1), np.linspace(-W / 2, W / 2, NY + 1)
    pts = np.array([(x, y) for y in ys for x in xs])
    quads = []
    for j in range(NY):
        for i in range(NX):
            a = j * (NX + 1) + i
            c = pts[[a, a + 1, a + NX + 2, a + NX + 1]].mean(axis=0)
            if any(math.hypot(c[0] - hx, c[1] - hy) < r for hx, hy, r in HOLES):
                continue
            quads.append((a, a + 1, a + NX + 2, a + NX + 1))
    quads = np.array(quads)
    used = np.unique(quads)
    renum = -np.ones(len(pts), dtype=int)
    renum[used] = np.arange(used.size)
    return pts[used], renum[quads]


def node_near(pts, x, y):
    return int(np.argmin((pts[:, 0] - x) ** 2 + (pts[:, 1] - y) ** 2))


def main(out=os.path.join(os.path.dirname(__file__), "slider_crank_holed_link.toml")):
    pts, quads = mesh()
    left = [i for i, p in enumerate(pts) if p[0] < 1e-12]
    right = [i for i, p in enumerate(pts) if p[0] > LB - 1e-12]
    # interface points: the pins (rigid averages of the end edges) and outline points to draw it
    interfaces = {"A": left, "top_left": node_near(pts, 0, W / 2), "top_right": node_near(pts, LB, W / 2), "B": right,
                  "bottom_right": node_near(pts, LB, -W / 2), "bottom_left": node_near(pts, 0, -W / 2)}
    data = fe.from_mesh(pts, cells=quads, thickness=T, density=7850.0, youngs_modulus=2.1e11, poisson_ratio=0.3,
                        interfaces=interfaces, modes=6, frame="mean-axis", damping_ratio=0.01)
    # the frame origin is the mesh origin (pin A); mean axes: the frame follows the link's mean motion
    s = Scene(gravity=(0.0, -9.81))
    m_crank = 7850.0 * math.pi * 0.00635**2 / 4 * L
    crank = s.rigid_body("crank", mass=m_crank, inertia=m_crank * L * L / 12, com=(L / 2, 0.0), angular_velocity=OMEGA)
    link = s.flexible_body("link", data, position=(L, 0.0), velocity=(0.0, L * OMEGA), angular_velocity=-L * OMEGA / LB)
    s.revolute(s.ground.point(0.0, 0.0), crank.point(0.0, 0.0), name="crank_pivot")
    s.revolute(crank.point(L, 0.0), link.marker("A"), name="crank_link")
    s.point_on_line(link.marker("B"), s.ground.line((0.0, 0.0), angle=0.0), name="slider")
    s.angle_driver(crank.frame(), ConstantSpeed(OMEGA), name="crank_speed")
    scenefile.dump(out, s, name="slider_crank_holed_link", solver={"t_end": 0.1, "method": "DOPRI5", "rtol": 1e-6},
                   output={"animate": True})
    f = data.info["frequencies"] / (2 * math.pi)
    print(f"wrote {out}: {len(pts)} nodes, {len(quads)} quads, modes at {np.round(f).astype(int).tolist()} Hz")


if __name__ == "__main__":
    main()
