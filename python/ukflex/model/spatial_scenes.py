"""Built-in spatial (3D) scenes: the public benchmarks of issue 30, built with :class:`SpatialScene`.

* :func:`flyball_governor` -- MBS benchmark A05, the stiff flyball governor (spring-damper rods,
  ``K = 8e5`` N/m, ``C = 4e4`` N s/m);
* :func:`bricard` -- MBS benchmark A04, Bricard's over-constrained mechanism;
* :func:`slider_crank` -- the spatial slider-crank of Haug's textbook (IFToMM library);
* :func:`flexible_slider_crank` -- the same with a flexible connecting rod, a ``beam3`` or a
  ``flexible3`` modal body (:func:`slider_crank_rod_data`), the crank spun up smoothly
  (:func:`spin_up`) to a constant speed (issue 31; docs/spatial-flexible.md).

Each scene function returns a :class:`ukflex.SpatialScene` whose initial state is consistent (so
``ukflex.System(scene)`` corrects nothing); ``TRACKED`` names the point each benchmark follows
(a body and a point in its frame) and its characteristic length. The data and where each number
comes from: docs/spatial-design.md (section 6) and docs/spatial.md. The independent NumPy
reference builds the same scenes (``ukflex.reference.spatial.scenes``); the tests check that both
give the same state and accelerations.
"""

from __future__ import annotations

import functools
import math
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

from ..arguments import count, non_negative, positive, real
from ..errors import InvalidArgumentError
from .scene import ConstantSpeed, Rectangular
from .spatial import SpatialScene

__all__ = ["flyball_governor", "bricard", "slider_crank", "flexible_slider_crank", "slider_crank_rod_data", "rod_modes", "clear_rod_data_cache", "spin_up",
           "crank_geometry", "ROD_DEFAULTS", "TRACKED"]

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
    A, Rc, B, C, Rr = crank_geometry(crank, rod, pivot)
    ex = np.array([1.0, 0.0, 0.0])
    u, yr = Rr[:, 0], Rr[:, 1]
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


def crank_geometry(crank: float, rod: float, pivot: Sequence[float]) -> Tuple[np.ndarray, ...]:
    """The spatial slider-crank at crank angle 0: the pivot ``A``, the crank's rotation ``Rc``
    (its ``y`` along world ``z``), the crank pin ``B``, the slider's point ``C`` on world ``x``
    and the rod's rotation ``Rr`` (``x`` from ``B`` to ``C``, ``y`` the universal joint's arm
    ``x_rod x e_x / |.|``)."""
    ex = np.array([1.0, 0.0, 0.0])
    A = np.asarray(pivot, float)
    Rc = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])
    B = A + crank * Rc[:, 1]
    C = np.array([B[0] + math.sqrt(rod ** 2 - B[1] ** 2 - B[2] ** 2), 0.0, 0.0])
    u = (C - B) / rod
    yr = np.cross(u, ex)
    yr /= np.linalg.norm(yr)
    return A, Rc, B, C, np.column_stack([u, yr, np.cross(u, yr)])


#: the flexible slider-crank's rod: a square steel bar (side, density, Young's modulus, Poisson's ratio)
ROD_SECTION = (0.008, 7850.0, 2.1e11, 0.3)
RODS = ("beam", "modal")
#: the default modal rod, the builder's rule and its constants (docs/spatial-flexible.md, "The
#: builder's default modal rod": 0.11 % from the converged beam on the deflection, where the
#: linear rod of the lowest modes is 4.9 % off): the P2 tetrahedra ``mesh``; the Green-Lagrange
#: strain's energy (``quadratic_strain``: the axial force's geometric stiffness); the lowest
#: ``bending_modes`` fixed-interface normal modes and the rod's first axial mode, the lowest mode
#: whose displacement lies along the rod by more than ``axial_share`` (of its sum of squares),
#: looked for among the lowest ``axial_search`` (the quadratic strain stiffens the rod with the
#: stress its modes carry: the axial force varies along the rod with its own axial inertia, which
#: only the axial mode carries)
ROD_DEFAULTS: Dict[str, Any] = {"mesh": (32, 2, 2), "quadratic_strain": True, "bending_modes": 8, "axial_share": 0.5,
                                "axial_search": 24}


def spin_up(omega: float, duration: float) -> str:
    """The crank angle of a smooth start (Kane's profile, as for the spin-up beam): the speed
    rises from 0 to ``omega`` over ``duration`` with an acceleration ``omega/T (1 - cos(2 pi
    t/T))`` that starts and ends at zero, then stays at ``omega``. An expression of ``t``
    (``h = min(t, T)`` written with ``abs``), for a rotation driver."""
    T = duration
    h = f"(t + {T!r} - abs(t - {T!r})) / 2"
    return (f"{omega!r} * (({h})^2 / (2 * {T!r}) + {T / (4 * math.pi ** 2)!r} * (cos({2 * math.pi / T!r} * {h}) - 1)"
            f" + t - {h})")


@functools.lru_cache(maxsize=4)
def _rod_data_cached(length: float, mesh: Tuple[int, int, int], modes: Any, section: Tuple[float, float, float, float],
                     stress_stiffening: bool, quadratic_strain: bool = False) -> Any:
    from . import fe3

    side, rho, e, nu = section
    bar = fe3.bar_mesh(length, side, side, mesh)
    return fe3.from_mesh(bar, density=rho, youngs_modulus=e, poisson_ratio=nu, modes=modes,
                         interfaces={"A": lambda x: x[:, 0] < 1e-9 * length, "B": lambda x: x[:, 0] > length * (1 - 1e-9)},
                         frame=("clamped", "A"), reduction="craig-bampton", stress_stiffening=stress_stiffening,
                         quadratic_strain=quadratic_strain)


def clear_rod_data_cache() -> None:
    """Forget the modal rod data :func:`slider_crank_rod_data` and :func:`rod_modes` cached (to
    time a build from scratch)."""
    _rod_data_cached.cache_clear()


def rod_modes(mesh: Tuple[int, int, int], rod: float = 0.3, section: Tuple[float, float, float, float] = ROD_SECTION) -> Tuple[int, ...]:
    """The numbers of the fixed-interface normal modes the default modal rod keeps
    (:data:`ROD_DEFAULTS`): the lowest ``bending_modes`` and the first axial mode (the rod's axis
    is its ``x``)."""
    search = _rod_data_cached(rod, mesh, ROD_DEFAULTS["axial_search"], section, False, False)
    normal = np.asarray(search.info["modes"])[:, 6:]  # after the six constraint modes of the face B
    share = np.sum(normal[0::3] ** 2, axis=0) / np.sum(normal ** 2, axis=0)
    axial = np.nonzero(share > ROD_DEFAULTS["axial_share"])[0]
    if axial.size == 0:
        raise InvalidArgumentError("modes", f"no axial mode among the lowest {ROD_DEFAULTS['axial_search']} fixed-interface modes "
                                   f"of the rod {rod} m, section {section}: give the modes")
    return tuple(sorted(set(range(ROD_DEFAULTS["bending_modes"])) | {int(axial[0])}))


def slider_crank_rod_data(mesh: Optional[Sequence[int]] = None, modes: Any = None, rod: float = 0.3,
                          section: Tuple[float, float, float, float] = ROD_SECTION, stress_stiffening: bool = False,
                          quadratic_strain: Optional[bool] = None) -> Any:
    """The modal data (:func:`ukflex.fe3.from_mesh`) of :func:`flexible_slider_crank`'s rod:
    the square bar (``section = (side, density, E, nu)``) of length ``rod`` along its ``x``,
    meshed with ``mesh`` boxes of P2 tetrahedra, the frame clamped at the crank end's face
    (interface ``A``), Craig-Bampton with the slider end's face (interface ``B``): six static
    constraint modes and the fixed-interface normal modes ``modes`` (a count: the lowest; or
    their numbers). ``stress_stiffening`` and ``quadratic_strain`` those of
    :func:`ukflex.fe3.from_mesh`. The defaults (``None``) are the default modal rod's,
    :data:`ROD_DEFAULTS`: mesh (32, 2, 2), the quadratic strain (unless ``stress_stiffening``),
    the eight lowest modes and the first axial one (:func:`rod_modes`), within 0.5 % of the
    converged beam; a linear rod (``quadratic_strain=False``) bends about 5 % more than the
    beam (docs/spatial-flexible.md). Cached (the same arguments give the same object)."""
    mesh_t = tuple(count("mesh", c) for c in (ROD_DEFAULTS["mesh"] if mesh is None else mesh))
    if len(mesh_t) != 3:
        raise InvalidArgumentError("mesh", f"expected 3 cell counts (x, y, z), got {len(mesh_t)}")
    sec = tuple(positive("section", v) for v in section)
    if len(sec) != 4 or sec[3] >= 0.5:
        raise InvalidArgumentError("section", f"expected (side, density, E, nu) with nu < 0.5, got {section!r}")
    if quadratic_strain is None:
        quadratic_strain = ROD_DEFAULTS["quadratic_strain"] and stress_stiffening is False
    for name, flag in (("stress_stiffening", stress_stiffening), ("quadratic_strain", quadratic_strain)):
        if not isinstance(flag, bool):
            raise InvalidArgumentError(name, f"expected True or False, got {flag!r}")
    length = positive("rod", rod)
    if modes is None:
        modes = rod_modes(mesh_t, length, sec)
    elif isinstance(modes, (Sequence, np.ndarray)) and not isinstance(modes, (str, bytes)):
        modes = tuple(np.asarray(modes, dtype=object).ravel().tolist())  # hashable for the cache; fe3 checks them
    else:
        modes = count("modes", modes)
    return _rod_data_cached(length, mesh_t, modes, sec, stress_stiffening, quadratic_strain)


def flexible_slider_crank(rod_model: str = "beam", *, elements: int = 8, data: Any = None, omega: float = 150.0,
                          spin_up_time: float = 0.05, crank: float = 0.08, rod: float = 0.3,
                          pivot: Tuple[float, float, float] = (0.0, 0.1, 0.12), section: Tuple[float, float, float, float] = ROD_SECTION,
                          masses: Tuple[float, float] = (0.12, 0.1), gravity: float = 0.0,
                          quadratic_strain: Optional[bool] = None) -> SpatialScene:
    """Haug's spatial slider-crank (:func:`slider_crank`'s geometry) with a flexible connecting
    rod: a square steel bar (``section = (side, density, E, nu)``, default 8 mm, first pinned
    bending frequency about 1310 rad/s), the crank driven from rest to ``omega`` (150 rad/s)
    over ``spin_up_time`` by :func:`spin_up`'s smooth profile, then at constant speed. The rod
    sits on a spherical joint at the crank pin and a universal joint at the slider (arms: world
    ``x`` on the slider, the rod's ``y``), as in the rigid scene: the rod's spin about its axis is
    held by the universal joint alone, no row is redundant. ``rod_model``: ``"beam"`` (a
    ``beam3`` of ``elements`` elements, an even number so that the midpoint is a node) or
    ``"modal"`` (a ``flexible3`` body from ``data``, default :func:`slider_crank_rod_data`'s
    default rod, within 0.5 % of the converged beam, with ``quadratic_strain`` that of the rod
    data, the Green-Lagrange strain's energy, on by default: docs/spatial-flexible.md).
    Crank and slider masses ``masses`` (the crank's inertia that of the rigid scene, the
    slider's ``1e-6 I``). Everything starts at rest, undeformed, gravity ``-z`` (default 0).
    Bodies ``crank``, ``rod`` (the beam's nodes ``rod[0] .. rod[N]``), ``slider``."""
    if rod_model not in RODS:
        raise InvalidArgumentError("rod_model", f"expected one of {list(RODS)}, got {rod_model!r}")
    omega, t_up = real("omega", omega), non_negative("spin_up_time", spin_up_time)
    crank, rod = positive("crank", crank), positive("rod", rod)
    mc, ms = (positive("masses", m) for m in masses)
    side, rho, e, nu = section
    pivot = tuple(real("pivot", x) for x in pivot)
    if rod <= math.hypot(pivot[1], pivot[2]) + crank:
        raise InvalidArgumentError("rod", f"{rod} m does not reach the slider's line from every crank pin "
                                   f"(needs more than {math.hypot(pivot[1], pivot[2]) + crank:.6g} m)")
    A, Rc, B, C, Rr = crank_geometry(crank, rod, pivot)
    ex = np.array([1.0, 0.0, 0.0])
    s = SpatialScene(gravity=(0.0, 0.0, -real("gravity", gravity)))
    cc = A + 0.5 * crank * Rc[:, 1]
    crank_b = s.rigid_body("crank", mc, [1e-4, 1e-5, 1e-4], position=cc, orientation=Rc)
    slider_b = s.rigid_body("slider", ms, [1e-6, 1e-6, 1e-6], position=C)
    if rod_model == "beam":
        n = count("elements", elements)
        if n % 2:
            raise InvalidArgumentError("elements", f"must be even (the rod's midpoint a node), got {n}")
        beam = s.beam("rod", B, C, Rectangular(side, side), elements=n, density=rho, youngs_modulus=e,
                      poisson_ratio=nu, y_axis=Rr[:, 1])
        end_b, end_c = beam.node(0), beam.node(-1)
    else:
        if data is None:
            data = slider_crank_rod_data(rod=rod, section=section, quadratic_strain=quadratic_strain)
        elif quadratic_strain is not None:
            raise InvalidArgumentError("quadratic_strain", "given with data: build the data with "
                                       "slider_crank_rod_data(..., quadratic_strain=...) instead")
        if not {"A", "B"} <= set(getattr(data, "interfaces", {})):
            raise InvalidArgumentError("data", "the rod's modal data need interfaces 'A' (crank end) and 'B' (slider end)")
        body = s.flexible_body("rod", data, position=B, orientation=Rr)
        end_b, end_c = body.interface("A"), body.interface("B")
    ground_a = s.ground.marker(A, z=ex, x=(0, 1, 0))
    crank_a = crank_b.marker(Rc.T @ (A - cc), z=Rc.T @ ex, x=Rc.T @ [0.0, 1.0, 0.0])
    s.revolute(ground_a, crank_a, name="crank_ground")
    s.rotation_driver(ground_a, crank_a, spin_up(omega, t_up) if t_up > 0 else ConstantSpeed(omega), name="crank_drive")
    s.spherical(crank_b.marker(Rc.T @ (B - cc)), end_b, name="crank_rod")
    s.universal(slider_b.marker((0, 0, 0), z=np.cross(ex, Rr[:, 1]), x=ex), end_c, name="rod_slider")
    s.prismatic(s.ground.marker((0, 0, 0), z=ex, x=(0, 1, 0)), slider_b.marker((0, 0, 0), z=ex, x=(0, 1, 0)),
                name="slider_ground")
    return s
