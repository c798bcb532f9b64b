"""Built-in spatial (3D) scenes: the public benchmarks of issue 30, built with :class:`SpatialScene`.

* :func:`flyball_governor` -- MBS benchmark A05, the stiff flyball governor (spring-damper rods,
  ``K = 8e5`` N/m, ``C = 4e4`` N s/m);
* :func:`bricard` -- MBS benchmark A04, Bricard's over-constrained mechanism;
* :func:`slider_crank` -- the spatial slider-crank of Haug's textbook (IFToMM library).

Each function returns a :class:`ukflex.SpatialScene` whose initial state is consistent (so
``ukflex.System(scene)`` corrects nothing); ``TRACKED`` names the point each benchmark follows
(a body and a point in its frame) and its characteristic length. The data and where each number
comes from: docs/spatial-design.md (section 6) and docs/spatial.md. The independent NumPy
reference builds the same scenes (``ukflex.reference.spatial.scenes``); the tests check that both
give the same state and accelerations.
"""

from __future__ import annotations

import math
from typing import Dict, Tuple

import numpy as np

from .scene import ConstantSpeed
from .spatial import SpatialScene

__all__ = ["flyball_governor", "bricard", "slider_crank", "TRACKED"]

G = 9.81

#: per scene: (body, point in the body frame, characteristic length in m) of the tracked point
TRACKED: Dict[str, Tuple[str, Tuple[float, float, float], float]] = {
    "flyball_governor": ("slider", (0.0, 0.0, 0.0), 1.0),   # the benchmark's output: the slider height s
    "bricard": ("rod3", (0.5, 0.0, 0.0), 1.0),               # joint point P3 = (1, -1, 1) at the start
    "slider_crank": ("slider", (0.0, 0.0, 0.0), 0.3),        # the slider on world x; length: the connecting rod
}


def _box(mass: float, a: float, b: float, c: float) -> list:
    """Principal moments of a homogeneous box with sides ``a, b, c`` along body ``x, y, z``."""
    return [mass * (b * b + c * c) / 12.0, mass * (a * a + c * c) / 12.0, mass * (a * a + b * b) / 12.0]


def _frame_x(u) -> np.ndarray:
    """A rotation matrix (body -> world) whose ``x`` column is the unit vector ``u``."""
    u = np.asarray(u, float) / np.linalg.norm(u)
    h = np.array([0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    y = np.cross(h, u)
    y /= np.linalg.norm(y)
    return np.column_stack([u, y, np.cross(u, y)])


def flyball_governor(omega: float = 2.0 * math.pi, stiffness: float = 8e5, damping: float = 4e4,
                     rest_length: float = 0.5, density: float = 3000.0, point_mass: float = 5.0,
                     alpha: float = math.radians(30.0), slider_height: float = 0.5, gravity: float = G,
                     driven: bool = False) -> SpatialScene:
    """MBS benchmark A05. A shaft (1 x 0.01 x 0.01 m) on a revolute about world ``z`` at the
    origin, a slider (0.1 m cube) on a prismatic joint along it at height ``s = 0.5`` m, two rods
    (1 x 0.01 x 0.01 m) hinged at ``(+-0.05, 0, 1)`` about ``y``, hanging ``alpha = 30`` degrees
    below the horizontal, 5 kg point masses on spherical joints at their far ends, and two
    spring-dampers (``K``, ``C``, rest length 0.5 m) from the slider's sides ``(+-0.05, 0, 0.5)``
    to the rods' midpoints (0.5 m long at the start). Density 3000 kg/m^3, gravity ``-z``. The
    shaft turns freely (``driven=True``: at constant speed), everything starting rigidly at
    ``omega`` about ``z``. Bodies ``shaft``, ``slider``, ``rod_right``, ``rod_left``,
    ``ball_right``, ``ball_left``."""
    s = SpatialScene(gravity=(0.0, 0.0, -gravity))
    w = np.array([0.0, 0.0, omega])
    vel = lambda r: np.cross(w, r)  # noqa: E731
    m_bar = density * 1.0 * 0.01 * 0.01
    m_sl = density * 0.1 ** 3
    shaft = s.rigid_body("shaft", m_bar, _box(m_bar, 0.01, 0.01, 1.0), position=(0, 0, 0.5), angular_velocity=w)
    slider = s.rigid_body("slider", m_sl, _box(m_sl, 0.1, 0.1, 0.1), position=(0, 0, slider_height),
                          angular_velocity=w)
    s.revolute(s.ground.marker((0, 0, 0)), shaft.marker((0, 0, -0.5)), name="shaft_ground")
    if driven:
        s.rotation_driver(s.ground.marker((0, 0, 0)), shaft.marker((0, 0, -0.5)), ConstantSpeed(omega),
                          name="shaft_drive")
    s.prismatic(shaft.marker((0, 0, slider_height - 0.5)), slider.marker((0, 0, 0)), name="slider_shaft")
    for side, sgn in (("right", 1.0), ("left", -1.0)):
        u = np.array([sgn * math.cos(alpha), 0.0, -math.sin(alpha)])      # along the rod, outwards
        R = np.column_stack([u, [0.0, 1.0, 0.0], np.cross(u, [0.0, 1.0, 0.0])])
        pivot = np.array([sgn * 0.05, 0.0, 1.0])
        mid, end = pivot + 0.5 * u, pivot + u
        rod = s.rigid_body(f"rod_{side}", m_bar, _box(m_bar, 1.0, 0.01, 0.01), position=mid, orientation=R,
                           velocity=vel(mid), angular_velocity=w)
        ball = s.point_mass(f"ball_{side}", point_mass, position=end, velocity=vel(end))
        s.revolute(shaft.marker(pivot - [0.0, 0.0, 0.5], z=(0, 1, 0), x=(1, 0, 0)),
                   rod.marker(R.T @ (pivot - mid), z=R.T @ [0.0, 1.0, 0.0], x=R.T @ [1.0, 0.0, 0.0]),
                   name=f"hinge_{side}")
        s.spherical(rod.marker((0.5, 0, 0)), ball.marker(), name=f"ball_{side}")
        s.spring_damper(slider.marker((sgn * 0.05, 0, 0)), rod.marker((0, 0, 0)), stiffness, damping, rest_length,
                        name=f"spring_{side}")
    return s


BRICARD_POINTS = ((0, 0, 0), (1, 0, 0), (1, -1, 0), (1, -1, 1), (0, -1, 1), (0, 0, 1))
BRICARD_AXES = ((0, 1, 0), (0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 0))


def bricard(length: float = 1.0, mass: float = 1.0, section: float = 0.1, gravity: float = G) -> SpatialScene:
    """MBS benchmark A04: five rods (``length``, ``mass``, square ``section``) along the cube
    edges ``P0 = (0,0,0) -> P1 = (1,0,0) -> P2 = (1,-1,0) -> P3 = (1,-1,1) -> P4 = (0,-1,1) -> P5 =
    (0,0,1)``, six revolutes at ``P0..P5`` about ``y, z, x, y, z, x`` (the ground closes the loop
    from ``P5`` to ``P0``), gravity ``-y``, at rest. Gruebler's count gives 0 degrees of freedom,
    the mechanism has 1: one constraint row is redundant. Rods ``rod1..rod5`` (body ``x`` along
    the rod, from ``P(k-1)`` to ``Pk``)."""
    s = SpatialScene(gravity=(0.0, -gravity, 0.0))
    P = np.asarray(BRICARD_POINTS, float) * length
    rods = []
    for k in range(5):
        R = _frame_x(P[k + 1] - P[k])
        c = 0.5 * (P[k] + P[k + 1])
        rods.append((s.rigid_body(f"rod{k + 1}", mass, _box(mass, length, section, section), position=c,
                                  orientation=R), R, c))
    for k in range(6):
        axis = np.asarray(BRICARD_AXES[k], float)
        ends = []
        for j in (k - 1, k):                       # the link before the point and the one after
            if j < 0 or j > 4:
                ends.append(s.ground.marker(P[k], z=axis))
            else:
                ref, R, c = rods[j]
                ends.append(ref.marker(R.T @ (P[k] - c), z=R.T @ axis))
        s.revolute(ends[0], ends[1], name=f"R{k}")
    return s


def slider_crank(driven: bool = False, omega: float = 6.0, crank: float = 0.08, rod: float = 0.3,
                 pivot: Tuple[float, float, float] = (0.0, 0.1, 0.12), masses: Tuple[float, float, float] = (0.12, 0.5, 2.0),
                 gravity: float = G) -> SpatialScene:
    """The spatial slider-crank (Haug; the IFToMM library's "spatial rigid slider-crank"): a crank
    (0.08 m, 0.12 kg, inertia ``diag(1e-4, 1e-5, 1e-4)``, along its ``y``, centre of mass halfway)
    on a revolute about world ``x`` at ``A = (0, 0.1, 0.12)``, pointing ``+z``; a connecting rod
    (0.3 m, 0.5 kg, ``diag(4e-4, 4e-3, 4e-3)`` along its ``x``) on a spherical joint at the crank
    pin and a universal joint at the slider (cross arms: world ``x`` on the slider, the rod's
    ``y = x_rod x e_x / |.|``); a slider (2 kg, ``1e-4 I``) on a prismatic joint along world
    ``x``; gravity ``-z``. Free, started with the crank turning at ``omega`` about world ``x``
    and the velocities that the joints then imply (``driven=True``: the crank is driven at
    ``omega``)."""
    s = SpatialScene(gravity=(0.0, 0.0, -gravity))
    A = np.asarray(pivot, float)
    ex = np.array([1.0, 0.0, 0.0])
    Rc = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])           # crank y along world z
    B = A + crank * Rc[:, 1]
    C = np.array([B[0] + math.sqrt(rod ** 2 - B[1] ** 2 - B[2] ** 2), 0.0, 0.0])
    u = (C - B) / rod
    yr = np.cross(u, ex)
    yr /= np.linalg.norm(yr)
    Rr = np.column_stack([u, yr, np.cross(u, yr)])
    # velocities: crank about x at omega, the slider from |C - B| = rod, the rod's spin from the
    # universal joint (d/dt (e_x . y_rod) = 0)
    wc = omega * ex
    cc = A + 0.5 * crank * Rc[:, 1]
    vB = np.cross(wc, B - A)
    vC = ((C - B) @ vB) / (C - B)[0] * ex
    w_perp = np.cross(u, vC - vB) / rod
    lam = -ex @ np.cross(w_perp, yr) / (ex @ Rr[:, 2])
    wr = w_perp + lam * u
    mc, mr, ms = masses
    crank_b = s.rigid_body("crank", mc, [1e-4, 1e-5, 1e-4], position=cc, orientation=Rc, velocity=np.cross(wc, cc - A),
                           angular_velocity=wc)
    rod_b = s.rigid_body("rod", mr, [4e-4, 4e-3, 4e-3], position=0.5 * (B + C), orientation=Rr,
                         velocity=0.5 * (vB + vC), angular_velocity=wr)
    slider_b = s.rigid_body("slider", ms, [1e-4, 1e-4, 1e-4], position=C, velocity=vC)
    ground_a = s.ground.marker(A, z=ex, x=(0, 1, 0))
    crank_a = crank_b.marker(Rc.T @ (A - cc), z=Rc.T @ ex, x=Rc.T @ [0.0, 1.0, 0.0])
    s.revolute(ground_a, crank_a, name="crank_ground")
    if driven:
        s.rotation_driver(ground_a, crank_a, ConstantSpeed(omega), name="crank_drive")
    s.spherical(crank_b.marker(Rc.T @ (B - cc)), rod_b.marker(Rr.T @ (B - 0.5 * (B + C))), name="crank_rod")
    s.universal(slider_b.marker((0, 0, 0), z=np.cross(ex, yr), x=ex),
                rod_b.marker(Rr.T @ (C - 0.5 * (B + C))), name="rod_slider")
    s.prismatic(s.ground.marker((0, 0, 0), z=ex, x=(0, 1, 0)), slider_b.marker((0, 0, 0), z=ex, x=(0, 1, 0)),
                name="slider_ground")
    return s
