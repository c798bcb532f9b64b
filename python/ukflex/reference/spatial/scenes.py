"""Spatial scenes built with the reference (each returns a :class:`SpatialModel`).

* :func:`heavy_top` -- symmetric top on a spherical joint; :func:`nutation_period` is its
  closed-form nutation period (Goldstein's reduction to ``u = cos theta``).
* :func:`double_pendulum` -- two rods on spherical joints, started off-plane.
* :func:`bricard` -- MBS benchmark A04 (five rods of 1 m, 1 kg, 0.1 m square section, six
  revolutes, gravity -y, at rest in the cube-edge configuration).
* :func:`flyball_governor` -- MBS benchmark A05 (stiff flyball governor).
* :func:`slider_crank` -- the spatial slider-crank of Haug's textbook as the IFToMM benchmark
  library states it.

docs/spatial-design.md gives the data and where each number comes from.
"""
from __future__ import annotations

import numpy as np
from scipy.special import ellipk

from .bodies import box_inertia
from .joints import ConstantSpeed, frame_from_z
from .model import SpatialModel
from .rotations import matrix_from_axis_angle

__all__ = ["heavy_top", "nutation_period", "double_pendulum", "bricard", "flyball_governor",
           "slider_crank", "slider_crank_state", "crank_angle", "BRICARD_POINTS", "BRICARD_AXES"]

G = 9.81


# ----------------------------------------------------------------------------------------
# heavy symmetric top
# ----------------------------------------------------------------------------------------

TOP = dict(mass=1.0, A=0.0025, C=0.005, l=0.1, theta0=np.radians(30.0), spin=50.0,
           precession=0.0, nutation_rate=0.0, g=G)
"""A disc of radius 0.1 m and 1 kg (``C = m R^2/2``, ``A = m R^2/4`` about its centre) on a
massless stem, its centre 0.1 m from the fixed point; started with its axis 30 degrees from the
vertical, spinning at 50 rad/s, no precession and no nutation rate (the cusp start)."""


def heavy_top(com_offset=False, **kw):
    """Fixed point at the world origin, gravity ``-z``, symmetry axis tilted about world ``x``.

    ``com_offset=False``: the body frame sits at the centre of mass, the joint marker at
    ``(0, 0, -l)``; ``True``: the body frame sits at the fixed point and the centre of mass
    is ``(0, 0, l)`` in it (the same top, other coordinates for the offset machinery).
    """
    d = {**TOP, **kw}
    m, A, C, l = d["mass"], d["A"], d["C"], d["l"]
    R = matrix_from_axis_angle([1.0, 0.0, 0.0], d["theta0"])
    e3 = R[:, 2]
    w = d["spin"] * e3 + d["precession"] * np.array([0, 0, 1.0]) + d["nutation_rate"] * np.array([1.0, 0, 0])
    model = SpatialModel(gravity=(0.0, 0.0, -d["g"]), name="heavy_top")
    J = np.diag([A, A, C])
    if com_offset:
        top = model.add_rigid_body(m, J, com=[0, 0, l], position=np.zeros(3), orientation=R,
                                   velocity=np.zeros(3), angular_velocity=w, name="top")
        mk = model.add_marker(top, [0, 0, 0])
    else:
        top = model.add_rigid_body(m, J, position=l * e3, orientation=R,
                                   velocity=np.cross(w, l * e3), angular_velocity=w, name="top")
        mk = model.add_marker(top, [0, 0, -l])
    model.add_joint("spherical", model.add_marker(None, [0, 0, 0]), mk, name="pivot")
    model.top_data = d
    return model


def nutation_period(mass, A, C, l, theta0, spin, precession=0.0, nutation_rate=0.0, g=G):
    """Closed-form nutation period of the heavy symmetric top (``A`` about the centre of mass).

    With ``I1 = A + m l^2`` (about the fixed point), ``u = cos theta`` obeys
    ``ud^2 = f(u) = (1 - u^2)(alpha - beta u) - (b - a u)^2`` with ``a = C w3 / I1``,
    ``b = p_phi / I1``, ``alpha = 2 E' / I1``, ``beta = 2 m g l / I1``;
    ``f = beta (u - u1)(u - u2)(u - u3)``, ``u1 <= u <= u2 <= 1 <= u3``, and the period is
    ``T = 4 K(k) / sqrt(beta (u3 - u1) / 1) `` with ``k^2 = (u2 - u1)/(u3 - u1)``
    (``u = u1 + (u2 - u1) sin^2 s``). Returns ``(T, (u1, u2, u3))``.
    """
    I1 = A + mass * l * l
    u0 = np.cos(theta0)
    w3 = spin + precession * u0              # spin about the symmetry axis (psid + phid cos th)
    a = C * w3 / I1
    b = (I1 * precession * (1 - u0 * u0) + C * w3 * u0) / I1
    Eprime = 0.5 * I1 * (nutation_rate ** 2 + precession ** 2 * (1 - u0 * u0)) + mass * g * l * u0
    alpha = 2 * Eprime / I1
    beta = 2 * mass * g * l / I1
    # f(u) = (1 - u^2)(alpha - beta u) - (b - a u)^2 = beta u^3 - (alpha + a^2) u^2 + (2ab - beta) u + alpha - b^2
    roots = np.sort(np.roots([beta, -(alpha + a * a), 2 * a * b - beta, alpha - b * b]).real)
    u1, u2, u3 = roots
    k2 = (u2 - u1) / (u3 - u1)
    T = 4.0 * ellipk(k2) / np.sqrt(beta * (u3 - u1))
    return float(T), (float(u1), float(u2), float(u3))


# ----------------------------------------------------------------------------------------
# spatial double pendulum
# ----------------------------------------------------------------------------------------

DOUBLE_PENDULUM = dict(L1=1.0, L2=0.8, m1=1.0, m2=0.6, a=0.05,
                       d1=(0.4, 0.3, -1.0), d2=(-0.3, 0.5, -1.0),
                       w1=(0.0, 0.0, 0.0), w2=(0.5, 0.0, 1.5), g=G)
"""Rods (square section ``a``) hanging from the origin; ``d1, d2`` point down the rods
(normalized), ``w1, w2`` are the rods' initial angular velocities (world)."""


def double_pendulum(**kw):
    d = {**DOUBLE_PENDULUM, **kw}
    model = SpatialModel(gravity=(0.0, 0.0, -d["g"]), name="double_pendulum")
    d1 = np.asarray(d["d1"], float) / np.linalg.norm(d["d1"])
    d2 = np.asarray(d["d2"], float) / np.linalg.norm(d["d2"])
    w1, w2 = np.asarray(d["w1"], float), np.asarray(d["w2"], float)
    L1, L2 = d["L1"], d["L2"]
    # body z axis along the rod, pointing up the rod (from the lower end to the upper one)
    R1, R2 = frame_from_z(-d1), frame_from_z(-d2)
    c1 = 0.5 * L1 * d1
    B = L1 * d1
    c2 = B + 0.5 * L2 * d2
    v1 = np.cross(w1, c1)
    vB = np.cross(w1, B)
    v2 = vB + np.cross(w2, c2 - B)
    r1 = model.add_rigid_body(d["m1"], box_inertia(d["m1"], d["a"], d["a"], L1), position=c1,
                              orientation=R1, velocity=v1, angular_velocity=w1, name="rod1")
    r2 = model.add_rigid_body(d["m2"], box_inertia(d["m2"], d["a"], d["a"], L2), position=c2,
                              orientation=R2, velocity=v2, angular_velocity=w2, name="rod2")
    model.add_joint("spherical", model.add_marker(None, [0, 0, 0]), model.add_marker(r1, [0, 0, 0.5 * L1]),
                    name="S1")
    model.add_joint("spherical", model.add_marker(r1, [0, 0, -0.5 * L1]), model.add_marker(r2, [0, 0, 0.5 * L2]),
                    name="S2")
    model.pendulum_data = d
    return model


# ----------------------------------------------------------------------------------------
# MBS benchmark A04: Bricard's mechanism
# ----------------------------------------------------------------------------------------

BRICARD_POINTS = np.array([[0, 0, 0], [1, 0, 0], [1, -1, 0], [1, -1, 1], [0, -1, 1], [0, 0, 1]], float)
"""Joint points P0..P5 (m): the rods run P0-P1, ..., P4-P5 along cube edges; the ground closes
the loop from P5 back to P0."""
BRICARD_AXES = np.array([[0, 1, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 0]], float)
"""Revolute axes at P0..P5, each perpendicular to both links it joins."""


def bricard(length=1.0, mass=1.0, section=0.1, g=G):
    model = SpatialModel(gravity=(0.0, -g, 0.0), name="bricard")
    P = BRICARD_POINTS * length
    rods = []
    for k in range(5):
        u = (P[k + 1] - P[k]) / length
        R = frame_from_z(u)[:, [2, 0, 1]]          # body x along the rod (columns x=u, y, z)
        rods.append(model.add_rigid_body(mass, box_inertia(mass, length, section, section),
                                         position=0.5 * (P[k] + P[k + 1]), orientation=R,
                                         name=f"rod{k + 1}"))
    chain = [None] + rods + [None]                 # ground, rod1..rod5, ground
    for k in range(6):
        Fw = frame_from_z(BRICARD_AXES[k])         # the joint frame in world axes
        mk = []
        for body in (chain[k], chain[k + 1]):
            if body is None:
                mk.append(model.add_marker(None, P[k], Fw))
            else:
                Rb = body.orientation
                mk.append(model.add_marker(body, Rb.T @ (P[k] - body.position), Rb.T @ Fw))
        model.add_joint("revolute", mk[0], mk[1], name=f"R{k}")
    model.bricard_points = P
    return model


# ----------------------------------------------------------------------------------------
# MBS benchmark A05: stiff flyball governor
# ----------------------------------------------------------------------------------------

FLYBALL = dict(density=3000.0, shaft=(0.01, 0.01, 1.0), rod=(1.0, 0.01, 0.01), slider=0.1,
               point_mass=5.0, K=8e5, C=4e4, L0=0.5, s=0.5, alpha=np.radians(30.0),
               omega=2 * np.pi, pivot_offset=0.05, g=G)


def flyball_governor(point_masses="separate", driven=False, **kw):
    """Shaft on a revolute about world ``z`` at the origin (free, or driven at ``omega`` with
    ``driven=True``), slider on a prismatic joint along the shaft at height ``s``, two rods
    hinged at ``(+-0.05, 0, 1)`` about ``y`` hanging ``alpha`` below the horizontal, 5 kg at
    their far ends, spring-dampers from the slider's sides ``(+-0.05, 0, 0)`` to the rods'
    midpoints (0.5 m, their rest length). Everything starts turning rigidly at ``omega``.

    ``point_masses="separate"``: the 5 kg masses are point masses on spherical joints;
    ``"composite"``: each rod and its mass are one rigid body with the centre of mass offset.
    """
    d = {**FLYBALL, **kw}
    rho = d["density"]
    model = SpatialModel(gravity=(0.0, 0.0, -d["g"]), name="flyball_governor")
    wv = np.array([0.0, 0.0, d["omega"]])
    vel = lambda r: np.cross(wv, r)  # noqa: E731
    sx, sy, sz = d["shaft"]
    m_shaft = rho * sx * sy * sz
    shaft = model.add_rigid_body(m_shaft, box_inertia(m_shaft, sx, sy, sz), position=[0, 0, sz / 2],
                                 angular_velocity=wv, name="shaft")
    a = d["slider"]
    m_sl = rho * a ** 3
    zs = d["s"]
    slider = model.add_rigid_body(m_sl, box_inertia(m_sl, a, a, a), position=[0, 0, zs],
                                  angular_velocity=wv, name="slider")
    mg = model.add_marker(None, [0, 0, 0])
    ms = model.add_marker(shaft, [0, 0, -sz / 2])
    model.add_joint("revolute", mg, ms, name="shaft_ground")
    if driven:
        model.add_driver("rotation", mg, ms, ConstantSpeed(0.0, d["omega"]), name="shaft_drive")
    model.add_joint("prismatic", model.add_marker(shaft, [0, 0, zs - sz / 2]), model.add_marker(slider, [0, 0, 0]),
                    name="slider_shaft")
    lx, ly, lz = d["rod"]
    m_rod = rho * lx * ly * lz
    mp = d["point_mass"]
    al, e = d["alpha"], d["pivot_offset"]
    for side, sgn in (("right", 1.0), ("left", -1.0)):
        u = np.array([sgn * np.cos(al), 0.0, -np.sin(al)])   # along the rod, outwards
        piv = np.array([sgn * e, 0.0, sz])
        R = np.column_stack([u, [0, 1.0, 0], np.cross(u, [0, 1.0, 0])])   # body x along the rod
        mid = piv + 0.5 * lx * u
        Jr = box_inertia(m_rod, lx, ly, lz)
        if point_masses == "composite":
            s_end = np.array([0.5 * lx, 0, 0])
            mt = m_rod + mp
            c = mp * s_end / mt
            Jc = Jr + m_rod * ((c @ c) * np.eye(3) - np.outer(c, c)) \
                + mp * (((s_end - c) @ (s_end - c)) * np.eye(3) - np.outer(s_end - c, s_end - c))
            rod = model.add_rigid_body(mt, Jc, com=c, position=mid, orientation=R,
                                       velocity=vel(mid), angular_velocity=wv, name=f"rod_{side}")
        else:
            rod = model.add_rigid_body(m_rod, Jr, position=mid, orientation=R, velocity=vel(mid),
                                       angular_velocity=wv, name=f"rod_{side}")
            end = piv + lx * u
            ball = model.add_point_mass(mp, position=end, velocity=vel(end), name=f"ball_{side}")
            model.add_joint("spherical", model.add_marker(rod, [0.5 * lx, 0, 0]), model.add_marker(ball),
                            name=f"ball_{side}")
        hinge_frame = frame_from_z([0, 1.0, 0])
        model.add_joint("revolute", model.add_marker(shaft, piv - [0, 0, sz / 2], hinge_frame),
                        model.add_marker(rod, R.T @ (piv - mid), R.T @ hinge_frame), name=f"hinge_{side}")
        model.add_spring_damper(model.add_marker(slider, [sgn * a / 2, 0, 0]), model.add_marker(rod, [0, 0, 0]),
                                d["K"], d["C"], d["L0"], name=f"spring_{side}")
    model.flyball_data = d
    return model


# ----------------------------------------------------------------------------------------
# spatial slider-crank (Haug; IFToMM benchmark "spatial rigid slider-crank mechanism")
# ----------------------------------------------------------------------------------------

SLIDER_CRANK = dict(crank=0.08, rod=0.3, A=(0.0, 0.1, 0.12), m_crank=0.12, m_rod=0.5, m_slider=2.0,
                    J_crank=(1e-4, 1e-5, 1e-4), J_rod=(4e-4, 4e-3, 4e-3), J_slider=(1e-4, 1e-4, 1e-4),
                    omega0=6.0, theta0=0.0, g=G, crank_com="middle",
                    slider_arm=(1.0, 0.0, 0.0))


def slider_crank(driven=False, **kw):
    """Crank on a revolute about world ``x`` at ``A``, pointing ``+z`` at ``theta0 = 0``;
    connecting rod on a spherical joint at the crank pin ``B`` and a universal joint at the
    slider ``C``; slider on a prismatic joint along world ``x`` through the origin; gravity
    ``-z``. Free, started with crank speed ``omega0`` (``driven=True``: the crank is driven at
    ``omega0``). Body axes: crank ``y`` along the crank, rod ``x`` along the rod (B -> C).
    ``crank_com``: ``"middle"`` (centre of mass halfway along the crank) or ``"pivot"``.
    Universal joint at ``C``: its cross arms are world ``x`` (on the slider) and the rod's
    ``y`` axis, ``y_rod = x_rod x e_x / |...|`` at the start (perpendicular to both).
    Initial velocities: :func:`slider_crank_state`.
    """
    d = {**SLIDER_CRANK, **kw}
    model = SpatialModel(gravity=(0.0, 0.0, -d["g"]), name="slider_crank")
    Lc, Lr = d["crank"], d["rod"]
    A = np.asarray(d["A"], float)
    th = d["theta0"]
    Rc = matrix_from_axis_angle([1.0, 0, 0], th) @ np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])  # y -> z
    ucr = Rc[:, 1]
    B = A + Lc * ucr
    # slider on the x axis: |C - B| = Lr with C = (xC, 0, 0)
    xC = B[0] + np.sqrt(Lr ** 2 - B[1] ** 2 - B[2] ** 2)
    C = np.array([xC, 0.0, 0.0])
    ur = (C - B) / Lr
    crank_c = A + (0.5 * Lc * ucr if d["crank_com"] == "middle" else 0.0)
    crank = model.add_rigid_body(d["m_crank"], np.diag(d["J_crank"]), position=crank_c, orientation=Rc,
                                 name="crank")
    # rod frame: x along B->C, y = the universal cross arm on the rod (perpendicular to the rod
    # and to the slider's arm, world x), z completes
    h = np.asarray(d["slider_arm"], float) / np.linalg.norm(d["slider_arm"])
    yr = np.cross(ur, h)
    yr /= np.linalg.norm(yr)
    Rr = np.column_stack([ur, yr, np.cross(ur, yr)])
    rod = model.add_rigid_body(d["m_rod"], np.diag(d["J_rod"]), position=0.5 * (B + C), orientation=Rr,
                               name="rod")
    slider = model.add_rigid_body(d["m_slider"], np.diag(d["J_slider"]), position=C, name="slider")
    Fx = frame_from_z([1.0, 0, 0])                  # joint frame with z along world x
    mgA = model.add_marker(None, A, Fx)
    mcA = model.add_marker(crank, Rc.T @ (A - crank_c), Rc.T @ Fx)
    model.add_joint("revolute", mgA, mcA, name="crank_ground")
    if driven:
        model.add_driver("rotation", mgA, mcA, ConstantSpeed(0.0, d["omega0"]), name="crank_drive")
    model.add_joint("spherical", model.add_marker(crank, Rc.T @ (B - crank_c)),
                    model.add_marker(rod, Rr.T @ (B - 0.5 * (B + C))), name="crank_rod")
    # universal at C: cross arms x_i = world x on the slider and y_j = rod's y axis
    model.add_joint("universal", model.add_marker(slider, [0, 0, 0], frame_from_z(np.cross(h, yr), h)),
                    model.add_marker(rod, Rr.T @ (C - 0.5 * (B + C))), name="rod_slider")
    model.add_joint("prismatic", model.add_marker(None, [0, 0, 0], Fx), model.add_marker(slider, [0, 0, 0], Fx),
                    name="slider_ground")
    model.crank_data = d
    model.crank_body = crank
    model.slider_body = slider
    model.driven = driven
    return model


def slider_crank_state(model):
    """Consistent initial state of :func:`slider_crank`: positions as built, velocities the
    mass-metric closest to rest with ``A qd + Phi_t = 0`` and (free crank) the crank's angular
    velocity about world ``x`` equal to ``omega0``."""
    from .rotations import rot_E
    from .uk import consistent_velocities
    q, qd = model.initial_guess()
    if model.driven:
        return q, consistent_velocities(model, q, qd)
    c = model.crank_body
    row = np.zeros(model.n)
    row[c.offset + 3:c.offset + 7] = 2.0 * rot_E(c.p(q))[0]
    return q, consistent_velocities(model, q, qd, extra_rows=row, extra_values=model.crank_data["omega0"])


def crank_angle(model, q):
    """Crank angle about world ``x`` from ``+z`` (in (-pi, pi])."""
    c = model.crank_body
    from .rotations import rot_A
    u = rot_A(c.p(q)) @ np.array([0.0, 1.0, 0.0])
    return float(np.arctan2(-u[1], u[2]))
