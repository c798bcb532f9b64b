"""Built-in scenes: the paper's flexible slider-crank and a few small test mechanisms.

Every function returns a :class:`ukflex.Scene` (call ``.build()`` or pass it to
:func:`ukflex.simulate`).  ``SCENES`` maps the names used by ``ukflex run`` to the functions.

Parameter names are the same in every scene (and in ``ukflex run NAME --param KEY=VALUE``;
``ukflex list`` prints them all): ``theory`` is a beam theory (``"timoshenko"`` or
``"euler-bernoulli"``; on the four-bar ``None`` keeps the coupler rigid), ``elements`` a beam's
element count, ``gravity`` is ``True`` (9.81 m/s^2 along -Y), ``False``, a magnitude along -Y or
a vector (:func:`gravity_vector`), ``<link>_length`` a link length, ``omega`` a crank speed,
``density``, ``youngs_modulus``, ``poisson_ratio``, ``shear_factor`` the material.
"""

from __future__ import annotations

import math
import numbers
from typing import Any, Callable, Dict, List, Optional, Tuple

from ..arguments import integer, real, reals
from ..errors import InvalidSceneError
from .scene import Circular, ConstantSpeed, CustomSection, Harmonic, Polynomial, Rectangular, Scene

__all__ = [
    "slider_crank",
    "pendulum",
    "double_pendulum",
    "four_bar",
    "cantilever",
    "pinned_beam",
    "spin_up",
    "flexible_pendulum",
    "every_joint",
    "chain",
    "rope",
    "lattice",
    "n_four_bar",
    "gravity_vector",
    "scene_parameters",
    "SCENES",
    "PAPER",
    "SPIN_UP",
]

#: Data of the paper's slider-crank (Pennestri, Valentini, de Falco 2010), docs/paper.md.
PAPER = {
    "crank_length": 0.1524,
    "coupler_length": 0.3048,
    "diameter": 0.00635,
    "density": 7834.56,
    "youngs_modulus": 2.06843e11,
    "poisson_ratio": 0.285,
    "shear_factor": 0.8,
    "omega": 124.8,
    "g": 9.81,
}

STEEL = {"density": 7850.0, "youngs_modulus": 2.1e11, "poisson_ratio": 0.3, "shear_factor": 5.0 / 6.0}


#: Largest count argument of a built-in scene (links, elements, rows, ...): a million items take
#: minutes to build and gigabytes to run.
MAX_ITEMS = 10 ** 6


def _checked(fn: Callable[..., Scene]) -> Callable[..., Scene]:
    """Check a built-in scene's numeric arguments (real, finite; integers where the default is one)
    before the function computes with them, and name the scene and arguments when its arithmetic
    fails (a zero length dividing, an overflow): a bad argument is a named error, never a bare
    ``ZeroDivisionError`` or ``unsupported operand type``."""
    import functools
    import inspect

    sig = inspect.signature(fn)

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Scene:
        bound = sig.bind(*args, **kwargs)
        for name, value in bound.arguments.items():
            default = sig.parameters[name].default
            if isinstance(default, bool) or not isinstance(default, (int, float)) or default is value:
                continue
            if isinstance(default, int):
                integer(name, value, at_most=MAX_ITEMS, where=fn.__name__)
            else:
                real(name, value, where=fn.__name__)
        try:
            return fn(*args, **kwargs)
        except (ZeroDivisionError, OverflowError) as exc:
            given = ", ".join(f"{k}={v!r}" for k, v in bound.arguments.items())
            what = "a division by zero" if isinstance(exc, ZeroDivisionError) else "a number beyond the double-precision range"
            raise InvalidSceneError(f"{fn.__name__}({given}): its geometry needs {what} ({exc}); check the arguments") from exc

    return wrapper


def gravity_vector(gravity: Any) -> Optional[Tuple[float, float]]:
    """The gravity vector meant by a scene function's ``gravity=`` argument.

    Parameters
    ----------
    gravity : bool, None, float or (2,) sequence
        ``True``: ``(0, -9.81)``; ``False`` or ``None``: no gravity; a number ``g``:
        ``(0, -g)`` (a magnitude along -Y); a 2-vector: itself [m/s^2].

    Returns
    -------
    (gx, gy) or None
        What :class:`ukflex.Scene` takes (``None``: no gravity term).
    """
    if gravity is True:
        return (0.0, -PAPER["g"])
    if gravity is False or gravity is None:
        return None
    if isinstance(gravity, numbers.Real):
        return (0.0, -real("gravity", gravity, finite=False))
    expected = f"gravity must be True, False, a magnitude or a 2-vector of numbers, got {gravity!r:.60}"
    if isinstance(gravity, (str, bytes)) or not hasattr(gravity, "__iter__") or len(tuple(gravity)) != 2:
        raise ValueError(expected)
    gx, gy = reals("gravity", tuple(gravity), finite=False)
    return (gx, gy)


def _beam(s: Scene, name: str, formulation: str, theory: Optional[str], strain: Optional[str], poisson_ratio: float,
          shear_factor: float, frame: Optional[str] = None, rotary_inertia: Optional[bool] = None, **common: Any):
    """A scene's beam of ``formulation``: an FFRF :meth:`Scene.beam` with ``frame`` and ``strain``
    (``None``: the core's default), Timoshenko's material constants where the theory needs them;
    or the ANCF :meth:`Scene.cable` (Euler-Bernoulli, no frame, geometrically exact: the FFRF
    options do not apply, and a theory or rotary inertia it does not have is refused)."""
    if formulation == "ancf":
        if theory not in (None, "euler-bernoulli") or rotary_inertia:
            raise InvalidSceneError("formulation: the ANCF cable is an Euler-Bernoulli beam without rotary inertia; "
                                    f"theory={theory!r}, rotary_inertia={rotary_inertia!r} need formulation='ffrf'")
        return s.cable(name, **common)
    if formulation != "ffrf":
        raise InvalidSceneError(f"formulation must be 'ffrf' or 'ancf', got {formulation!r}")
    kw: Dict[str, Any] = {"theory": theory, "frame": frame, "strain": strain, "rotary_inertia": rotary_inertia}
    if theory in (None, "timoshenko"):  # None: the FFRF beam's default theory, Timoshenko
        kw.update(poisson_ratio=poisson_ratio, shear_factor=shear_factor)
    return s.beam(name, **common, **kw)


def _round_beam(s: Scene, name: str, length: float, elements: int, theory: str, diameter: float, density: float,
                youngs_modulus: float, poisson_ratio: float, shear_factor: float, formulation: str = "ffrf",
                strain: Optional[str] = None, **options: Any):
    """A beam of circular section (the paper's coupler; FFRF: pinned-pinned frame);
    ``poisson_ratio`` and ``shear_factor`` go to Timoshenko beams only."""
    return _beam(s, name, formulation, theory, strain, poisson_ratio, shear_factor, length=length, elements=elements,
                 section=Circular(diameter), density=density, youngs_modulus=youngs_modulus, **options)


@_checked
def slider_crank(
    theory: Optional[str] = None,
    elements: int = 1,
    gravity: Any = True,
    omega: float = PAPER["omega"],
    crank_length: float = PAPER["crank_length"],
    coupler_length: float = PAPER["coupler_length"],
    diameter: float = PAPER["diameter"],
    density: float = PAPER["density"],
    youngs_modulus: float = PAPER["youngs_modulus"],
    poisson_ratio: float = PAPER["poisson_ratio"],
    shear_factor: float = PAPER["shear_factor"],
    rotary_inertia: Optional[bool] = None,
    damping: float = 0.0,
    strain: str = "linear",
    formulation: str = "ffrf",
) -> Scene:
    """The paper's flexible slider-crank (section 5, Fig. 3; data: :data:`ukflex.scenes.PAPER`).

    Rigid crank (mass ``rho a L``, inertia ``m L^2 / 12`` about its centre, body frame at the
    ground pivot, centre of mass ``(L/2, 0)``) driven at constant speed ``omega``; coupler = FFRF
    beam with ``elements`` elements, pinned-pinned frame; its end ``xi = 1`` slides on the ground
    X axis (point-on-line).  At ``t = 0`` crank and coupler lie along +X, undeformed, with the
    exactly consistent velocities: crank tip ``(0, L omega)``, coupler angular velocity
    ``-L omega / Lb``.

    Parameters
    ----------
    theory : {"timoshenko", "euler-bernoulli"}, optional
        Coupler beam theory; default ``"timoshenko"`` (the paper's)
        for the FFRF coupler, ``"euler-bernoulli"`` (the only one) for the ANCF coupler.
    elements : int
        Number of coupler elements (the paper: 1).
    gravity : bool, float or (2,) sequence
        ``True``: ``(0, -9.81)``; ``False``: no gravity; a magnitude along -Y; or a vector
        (:func:`gravity_vector`).
    omega : float
        Crank speed [rad/s].
    rotary_inertia : bool, optional
        Coupler rotary inertia (default: the core's default for the theory).
    damping : float
        Coupler stiffness-proportional damping [s] (the paper: none).
    formulation : {"ffrf", "ancf"}
        ``"ffrf"`` (default): the paper's linear floating-frame coupler, which this scene
        reproduces.  ``"ancf"``: the geometrically exact ANCF cable coupler (Euler-Bernoulli):
        the physically right answer at speed, where the axial force couples with bending.
    strain : {"linear", "nonlinear"}
        The FFRF coupler's strain measure.  Default ``"linear"``: this scene reproduces the
        paper, whose linear FFRF model has no geometric stiffening.  At the paper's crank speed
        the coupler's axial force couples with bending and ``strain="nonlinear"`` (the default
        of :meth:`ukflex.Scene.beam`) is the physically right FFRF model; see
        ``docs/geometric-nonlinearity.md``.

    Returns
    -------
    Scene
        Bodies ``crank`` (rigid) and ``coupler`` (beam); ``n = 6 + 3 * elements`` coordinates
        (ANCF: ``3 + 4 (elements + 1)``), 6 constraint rows.
    """
    if theory is None:
        theory = "euler-bernoulli" if formulation == "ancf" else "timoshenko"
    L, Lb, d = crank_length, coupler_length, diameter
    area = math.pi * d * d / 4.0
    m_crank = density * area * L
    s = Scene(gravity=gravity_vector(gravity))
    crank = s.rigid_body(
        "crank",
        mass=m_crank,
        inertia=m_crank * L * L / 12.0,
        com=(L / 2.0, 0.0),
        position=(0.0, 0.0),
        angle=0.0,
        angular_velocity=omega,
    )
    coupler = _round_beam(
        s, "coupler", Lb, elements, theory, d, density, youngs_modulus, poisson_ratio, shear_factor,
        formulation=formulation, strain=strain,
        rotary_inertia=rotary_inertia,
        damping=damping,
        position=(L, 0.0),
        angle=0.0,
        velocity=(0.0, L * omega),
        angular_velocity=-L * omega / Lb,
    )
    s.revolute(s.ground.point(0.0, 0.0), crank.point(0.0, 0.0), name="crank_pivot")
    s.revolute(crank.point(L, 0.0), coupler.at(0.0), name="crank_coupler")
    s.point_on_line(coupler.at(1.0), s.ground.line((0.0, 0.0), angle=0.0), name="slider")
    s.angle_driver(crank.frame(), ConstantSpeed(omega, initial=0.0), name="crank_speed")
    return s


@_checked
def pendulum(
    length: float = 1.0,
    mass: float = 1.0,
    angle: float = -math.pi / 4,
    angular_velocity: float = 0.0,
    gravity: Any = True,
) -> Scene:
    """Rigid rod pendulum (uniform rod, inertia ``m L^2 / 12`` about its centre) under gravity.

    The body reference point is the rod's centre, so all three coordinates move; the pivot is the
    rod end ``(-L/2, 0)`` pinned to the world origin.  ``angle`` is measured from +X (``-pi/2``
    hangs straight down).  Conservative: ``T + V`` is constant.  ``gravity``: see
    :func:`gravity_vector`.
    """
    s = Scene(gravity=gravity_vector(gravity))
    c, si = math.cos(angle), math.sin(angle)
    h = length / 2.0
    rod = s.rigid_body(
        "rod",
        mass=mass,
        inertia=mass * length * length / 12.0,
        position=(h * c, h * si),
        angle=angle,
        velocity=(-h * si * angular_velocity, h * c * angular_velocity),
        angular_velocity=angular_velocity,
    )
    s.revolute(s.ground.point(0.0, 0.0), rod.point(-h, 0.0), name="pivot")
    return s


@_checked
def double_pendulum(
    lengths: Tuple[float, float] = (1.0, 0.7),
    masses: Tuple[float, float] = (1.0, 0.5),
    angles: Tuple[float, float] = (0.0, math.pi / 3),
    gravity: Any = True,
) -> Scene:
    """Two uniform rigid rods in a chain, released from rest (angles from +X).  ``gravity``: see
    :func:`gravity_vector`."""
    s = Scene(gravity=gravity_vector(gravity))
    (l1, l2), (m1, m2), (a1, a2) = lengths, masses, angles
    p1 = (0.5 * l1 * math.cos(a1), 0.5 * l1 * math.sin(a1))
    tip = (l1 * math.cos(a1), l1 * math.sin(a1))
    p2 = (tip[0] + 0.5 * l2 * math.cos(a2), tip[1] + 0.5 * l2 * math.sin(a2))
    r1 = s.rigid_body("rod1", mass=m1, inertia=m1 * l1 * l1 / 12, position=p1, angle=a1)
    r2 = s.rigid_body("rod2", mass=m2, inertia=m2 * l2 * l2 / 12, position=p2, angle=a2)
    s.revolute(s.ground.point(0, 0), r1.point(-l1 / 2, 0), name="pivot")
    s.revolute(r1.point(l1 / 2, 0), r2.point(-l2 / 2, 0), name="elbow")
    return s


@_checked
def four_bar(
    crank_length: float = 0.1,
    coupler_length: float = 0.3,
    rocker_length: float = 0.25,
    ground_length: float = 0.3,
    crank_angle: float = math.pi / 2,
    omega: Optional[float] = 10.0,
    gravity: Any = True,
    theory: Optional[str] = None,
    elements: int = 2,
    formulation: Optional[str] = None,
) -> Scene:
    """Four-bar linkage (Grashof crank-rocker for the defaults), rigid or with a flexible coupler.

    Pivots at the world origin and at ``(ground, 0)``.  The initial guess is the exact assembly
    (circle intersection, open configuration) perturbed by nothing; velocities are zero except
    the crank's, and :class:`ukflex.System` projects them.  With ``omega=None`` the crank is free
    (a one-degree-of-freedom mechanism under gravity).

    Parameters
    ----------
    crank_length, coupler_length, rocker_length, ground_length : float
        Link lengths [m].
    theory : {None, "timoshenko", "euler-bernoulli"}
        ``None``: rigid coupler; else the coupler is a pinned-pinned steel beam (rectangular
        10 x 5 mm section) with ``elements`` elements of this theory.
    formulation : {None, "ffrf", "ancf"}
        The flexible coupler's formulation: ``"ffrf"`` (the default when ``theory`` is given) or
        ``"ancf"`` (the ANCF cable, Euler-Bernoulli: ``theory`` may stay ``None``).  ``None`` with
        ``theory=None``: the rigid coupler.
    """
    s = Scene(gravity=gravity_vector(gravity))
    a, b, c, d = crank_length, coupler_length, rocker_length, ground_length
    A = (a * math.cos(crank_angle), a * math.sin(crank_angle))
    # B: |B - A| = b, |B - D| = c, D = (d, 0); take the intersection above the line A-D
    D = (d, 0.0)
    dx, dy = D[0] - A[0], D[1] - A[1]
    r = math.hypot(dx, dy)
    if r > b + c or r < abs(b - c):
        raise ValueError("four_bar: the links cannot be assembled at this crank angle")
    x = (b * b - c * c + r * r) / (2 * r)
    h = math.sqrt(max(b * b - x * x, 0.0))
    B = (A[0] + x * dx / r - h * dy / r, A[1] + x * dy / r + h * dx / r)
    th_b = math.atan2(B[1] - A[1], B[0] - A[0])
    th_c = math.atan2(B[1] - D[1], B[0] - D[0])
    m_per_length = 2.0  # kg/m for the rigid links
    cr = s.rigid_body(
        "crank",
        mass=m_per_length * a,
        inertia=m_per_length * a**3 / 12,
        com=(a / 2, 0),
        angle=crank_angle,
        angular_velocity=omega or 0.0,
    )
    if theory is None and formulation is None:
        cp = s.rigid_body(
            "coupler", mass=m_per_length * b, inertia=m_per_length * b**3 / 12, com=(b / 2, 0), position=A, angle=th_b
        )
        cp_start, cp_end = cp.point(0, 0), cp.point(b, 0)
    else:
        cp = _beam(
            s, "coupler", formulation or "ffrf", theory, None, STEEL["poisson_ratio"], STEEL["shear_factor"],
            length=b,
            elements=elements,
            section=Rectangular(0.01, 0.005),
            density=STEEL["density"],
            youngs_modulus=STEEL["youngs_modulus"],
            position=A,
            angle=th_b,
        )
        cp_start, cp_end = cp.at(0.0), cp.at(1.0)
    rk = s.rigid_body(
        "rocker", mass=m_per_length * c, inertia=m_per_length * c**3 / 12, com=(c / 2, 0), position=D, angle=th_c
    )
    s.revolute(s.ground.point(0, 0), cr.point(0, 0), name="A0")
    s.revolute(cr.point(a, 0), cp_start, name="A")
    s.revolute(cp_end, rk.point(c, 0), name="B")
    s.revolute(rk.point(0, 0), s.ground.point(d, 0), name="B0")
    if omega is not None:
        s.angle_driver(cr.frame(), ConstantSpeed(omega, initial=crank_angle), name="crank_speed")
    return s


@_checked
def cantilever(
    length: float = 1.0,
    elements: int = 4,
    theory: str = "euler-bernoulli",
    section=None,
    gravity: Any = True,
    tip_force: Tuple[float, float] = (0.0, 0.0),
    damping: float = 0.0,
    strain: Optional[str] = None,
    formulation: str = "ffrf",
    *,
    density: float = STEEL["density"],
    youngs_modulus: float = STEEL["youngs_modulus"],
    poisson_ratio: float = STEEL["poisson_ratio"],
    shear_factor: float = STEEL["shear_factor"],
) -> Scene:
    """Horizontal cantilever: a beam along +X, welded to the ground at ``xi = 0`` (FFRF: clamped
    frame; ``formulation="ancf"``: the geometrically exact ANCF cable, Euler-Bernoulli).

    Loaded by its weight (``gravity``) and a constant ``tip_force`` [N] at ``xi = 1``.  Default
    section: rectangular 20 x 10 mm steel (``density``, ``youngs_modulus``, ``poisson_ratio``,
    ``shear_factor`` change the material).  Static tip deflection under a tip
    load ``P``: ``P L^3 / (3 E I)`` (linear theory; ``strain`` defaults to the core's
    ``"nonlinear"``, which settles at the same deflection to second order).
    """
    mat = {"density": density, "youngs_modulus": youngs_modulus, "poisson_ratio": poisson_ratio,
           "shear_factor": shear_factor}
    s = Scene(gravity=gravity_vector(gravity))
    b = _beam(
        s, "beam", formulation, theory, strain, mat["poisson_ratio"], mat["shear_factor"], frame="clamped",
        length=length,
        elements=elements,
        section=section if section is not None else Rectangular(0.02, 0.01),
        density=mat["density"],
        youngs_modulus=mat["youngs_modulus"],
        damping=damping,
    )
    s.weld(s.ground.frame(), b.at(0.0), name="clamp")
    if tuple(tip_force) != (0.0, 0.0):
        s.point_force(b.at(1.0), tip_force, name="tip_load")
    return s


@_checked
def pinned_beam(
    length: float = PAPER["coupler_length"],
    elements: int = 1,
    theory: str = "euler-bernoulli",
    diameter: float = PAPER["diameter"],
    density: float = PAPER["density"],
    youngs_modulus: float = PAPER["youngs_modulus"],
    poisson_ratio: float = PAPER["poisson_ratio"],
    shear_factor: float = PAPER["shear_factor"],
    rotary_inertia: Optional[bool] = None,
    gravity: Any = False,
    formulation: str = "ffrf",
) -> Scene:
    """The paper's coupler alone, simply supported: pinned at ``xi = 0`` (revolute to ground) and
    its ``xi = 1`` end on the ground X axis (point-on-line); FFRF frame pinned-pinned, or the
    ANCF cable (``formulation="ancf"``).

    The supports fix the frame's ``x``, ``y`` and ``theta`` at the undeformed state, so the
    elastic block ``M_ff``, ``K_ff`` gives the simply supported beam's natural frequencies.
    """
    s = Scene(gravity=gravity_vector(gravity))
    b = _round_beam(s, "beam", length, elements, theory, diameter, density, youngs_modulus, poisson_ratio,
                    shear_factor, formulation=formulation, rotary_inertia=rotary_inertia)
    s.revolute(s.ground.point(0, 0), b.at(0.0), name="pin")
    s.point_on_line(b.at(1.0), s.ground.line((0, 0), angle=0.0), name="roller")
    return s


#: Kane, Ryan and Banerjee's spin-up beam (J. Guidance 10 (1987) 139-151), the classic test of
#: geometric stiffening: EA = 2.8e7 N, EI = 1.4e4 N m^2, rho A = 1.2 kg/m, L = 10 m
SPIN_UP = {"length": 10.0, "density": 3000.0, "youngs_modulus": 7e10, "area": 4e-4, "second_moment": 2e-7}


@_checked
def spin_up(
    formulation: str = "ffrf",
    elements: int = 4,
    omega: float = 6.0,
    spin_up_time: float = 15.0,
    length: float = SPIN_UP["length"],
    theory: str = "euler-bernoulli",
    strain: Optional[str] = None,
    gravity: Any = False,
) -> Scene:
    """A beam clamped to a hub whose angle is prescribed: Kane's spin-up manoeuvre.

    The hub turns as ``theta(t) = (omega / T) (t^2 / 2 + (T / 2 pi)^2 (cos(2 pi t / T) - 1))``
    for ``t < T = spin_up_time``, then at the constant speed ``omega`` (``theta = omega (t -
    T / 2)``): a smooth spin-up (the acceleration rises from zero and returns to it).  The beam
    (data :data:`SPIN_UP`: ``EA = 2.8e7 N``, ``EI = 1.4e4 N m^2``, ``rho A = 1.2 kg/m``, 10 m) lies
    along the hub's X axis, welded to it at ``xi = 0``, in the horizontal plane (no gravity).

    A linear FFRF beam (``strain="linear"``) has no geometric stiffening and its deflection
    grows without bound at speeds like these (Kane et al.); the default ``strain`` (the core's,
    nonlinear) and the ANCF cable (``formulation="ancf"``) stiffen as they should.

    Returns
    -------
    Scene
        Bodies ``hub`` (rigid, driven) and ``beam``; the hub's driver is ``spin``.
    """
    T, w = spin_up_time, omega
    if not T > 0.0:
        raise ValueError(f"spin_up: spin_up_time must be positive, got {T!r}")
    s = Scene(gravity=gravity_vector(gravity))
    hub = s.rigid_body("hub", mass=1.0, inertia=1.0)
    s.revolute(s.ground.point(0.0, 0.0), hub.point(0.0, 0.0), name="axle")
    # u = min(t, T) = (t + T - |t - T|) / 2 carries the profile past T exactly
    u = f"((t + {T!r} - abs(t - {T!r})) / 2)"
    c = (T / (2.0 * math.pi)) ** 2
    s.angle_driver(hub.frame(), f"{w / T!r} * ({u}^2 / 2 + {c!r} * (cos({2.0 * math.pi / T!r} * {u}) - 1)) + {w!r} * (t - {u})",
                   name="spin")
    beam = _beam(s, "beam", formulation, theory, strain, STEEL["poisson_ratio"], STEEL["shear_factor"], frame="clamped",
                 length=length, elements=elements, density=SPIN_UP["density"], youngs_modulus=SPIN_UP["youngs_modulus"],
                 section=CustomSection(SPIN_UP["area"], SPIN_UP["second_moment"]))
    s.weld(hub.frame(), beam.at(0.0), name="clamp")
    return s


@_checked
def flexible_pendulum(
    formulation: str = "ffrf",
    elements: int = 4,
    length: float = 1.0,
    diameter: float = 0.004,
    angle: float = 0.0,
    theory: str = "euler-bernoulli",
    strain: Optional[str] = None,
    gravity: Any = True,
    density: float = STEEL["density"],
    youngs_modulus: float = STEEL["youngs_modulus"],
) -> Scene:
    """A slender steel rod pinned at one end, released from rest at ``angle`` (0: horizontal)
    under gravity: it swings and bends (first bending mode of the pinned-free rod ~80 rad/s at
    the defaults, the swing ~4 rad/s).

    FFRF (default; frame clamped to the root, so its elastic modes are the cantilever's) or the
    ANCF cable (``formulation="ancf"``).  Body ``rod``; joint ``pivot`` at ``xi = 0``.
    """
    s = Scene(gravity=gravity_vector(gravity))
    rod = _beam(s, "rod", formulation, theory, strain, STEEL["poisson_ratio"], STEEL["shear_factor"], frame="clamped",
                length=length, elements=elements, section=Circular(diameter), density=density,
                youngs_modulus=youngs_modulus, angle=angle)
    s.revolute(s.ground.point(0.0, 0.0), rod.at(0.0), name="pivot")
    return s


@_checked
def every_joint(gravity: Any = True) -> Scene:
    """A scene using every joint, driver and force kind, with rigid and beam bodies.

    * ``crank`` (rigid): revolute to ground, angle driver with harmonic motion;
    * ``link`` (Timoshenko beam, 2 elements, pinned-pinned): revolute to the crank tip and to
      the ``slider``;
    * ``slider`` (rigid): prismatic joint along the ground X axis, spring-damper to the ground;
    * ``arm`` (Euler-Bernoulli beam, clamped frame): welded upright on the slider, a point force
      and a torque at its tip;
    * ``lifter`` (rigid pendulum): its pivot runs on a vertical ground line (point-on-line) with
      its height prescribed by a coordinate driver (polynomial), a torque on it.

    Returns
    -------
    Scene
        ``n = 24`` coordinates, 14 constraint rows, 10 degrees of freedom.
    """
    s = Scene(gravity=gravity_vector(gravity))
    Lc, Ll = 0.1, 0.3
    crank = s.rigid_body("crank", mass=0.2, inertia=0.2 * Lc**2 / 12, com=(Lc / 2, 0), angular_velocity=1.5)
    link = s.beam(
        "link",
        length=Ll,
        elements=2,
        theory="timoshenko",
        section=Rectangular(0.01, 0.006),
        density=2700.0,
        youngs_modulus=7.0e10,
        poisson_ratio=0.33,
        shear_factor=5.0 / 6.0,
        frame="pinned-pinned",
        position=(Lc, 0.0),
    )
    slider = s.rigid_body("slider", mass=0.5, inertia=1e-3, position=(Lc + Ll, 0.0))
    arm = s.beam(
        "arm",
        length=0.2,
        elements=1,
        theory="euler-bernoulli",
        section=Rectangular(0.008, 0.004),
        density=2700.0,
        youngs_modulus=7.0e10,
        frame="clamped",
        position=(Lc + Ll, 0.02),
        angle=math.pi / 2,
    )
    lifter = s.rigid_body(
        "lifter", mass=0.3, inertia=0.3 * 0.15**2 / 12, com=(0.075, 0.0), position=(-0.3, 0.1), angle=-math.pi / 2
    )
    s.revolute(s.ground.point(0, 0), crank.point(0, 0), name="crank_pivot")
    s.revolute(crank.point(Lc, 0), link.at(0.0), name="crank_link")
    s.revolute(link.at(1.0), slider.point(0, 0), name="link_slider")
    s.prismatic(slider.frame(), s.ground.line((0, 0), angle=0.0), name="slide")
    s.weld(slider.point(0.0, 0.02, angle=math.pi / 2), arm.at(0.0), name="arm_mount")
    s.point_on_line(lifter.point(0, 0), s.ground.line((-0.3, 0.0), angle=math.pi / 2), name="lifter_rail")
    s.angle_driver(crank.frame(), Harmonic(amplitude=0.3, frequency=5.0), name="crank_motion")
    s.coordinate_driver(lifter.point(0, 0), "y", Polynomial([0.1, 0.0, 0.5]), name="lifter_height")
    s.spring_damper(slider.point(0, 0), s.ground.point(0.6, 0.0), stiffness=200.0, damping=2.0, name="slider_spring")
    s.point_force(arm.at(1.0), (0.5, 0.0), name="arm_push")
    s.torque(arm.at(1.0), 0.01, name="arm_twist")
    s.torque(lifter.frame(), -0.05, name="lifter_torque")
    return s


def _link_chain(s: Scene, angles: Any, link: float, mass: float, prefix: str = "link") -> list:
    """Uniform rigid rods end to end from the origin, rod ``i`` at ``angles[i]`` (from +X), joined
    by revolutes (``pivot`` to the ground, then ``joint{i}``); returns the bodies."""
    bodies = []
    x = y = 0.0
    for i, a in enumerate(angles):
        c, si = math.cos(a), math.sin(a)
        b = s.rigid_body(f"{prefix}{i}", mass=mass, inertia=mass * link**2 / 12.0,
                         position=(x + 0.5 * link * c, y + 0.5 * link * si), angle=a)
        if i == 0:
            s.revolute(s.ground.point(0.0, 0.0), b.point(-0.5 * link, 0.0), name="pivot")
        else:
            s.revolute(bodies[-1].point(0.5 * link, 0.0), b.point(-0.5 * link, 0.0), name=f"joint{i}")
        bodies.append(b)
        x, y = x + link * c, y + link * si
    return bodies


@_checked
def chain(links: int = 16, length: float = 2.0, mass: float = 1.0, angle: float = 0.0, gravity: Any = True) -> Scene:
    """Pendulum chain of rigid links under gravity.

    ``links`` uniform rigid rods of total ``length`` and ``mass``, pinned end to end
    (revolutes) and to the world origin, released from rest along ``angle`` (from +X; 0 is
    horizontal).  ``n = 3 links`` coordinates, ``m = 2 links`` constraint rows: the scene of the
    sparse UK path (docs/scale.md).  Conservative: ``T + V`` is constant."""
    k = int(links)
    if k < 1 or k != links:
        raise ValueError(f"links must be a positive integer, got {links!r}")
    s = Scene(gravity=gravity_vector(gravity))
    _link_chain(s, [angle] * k, length / k, mass / k)
    return s


@_checked
def rope(links: int = 64, length: float = 2.0, mass: float = 0.5, span: float = 1.6, gravity: Any = True) -> Scene:
    """A rope of short rigid links hung between two pins (a closed loop through the ground).

    ``links`` rods of total ``length`` and ``mass``, pins ``span`` apart: laid out as a symmetric
    V (a consistent state), released from rest, it swings towards the catenary.  ``links`` even,
    ``0 < span < length``."""
    k = int(links)
    if k < 2 or k != links or k % 2:
        raise ValueError(f"links must be an even integer >= 2, got {links!r}")
    if not 0.0 < span < length:
        raise ValueError(f"span must be in (0, length), got span={span!r}, length={length!r}")
    s = Scene(gravity=gravity_vector(gravity))
    a = math.acos(span / length)
    bodies = _link_chain(s, [-a] * (k // 2) + [a] * (k // 2), length / k, mass / k)
    s.revolute(bodies[-1].point(0.5 * length / k, 0.0), s.ground.point(span, 0.0), name="anchor")
    return s


@_checked
def lattice(columns: int = 4, rows: int = 4, cell: float = 0.25, mass: float = 0.1, shear: float = 0.3,
            beams: str = "links", gravity: Any = True, speed: float = 0.0) -> Scene:
    """A shear lattice: ``rows`` levels of ``columns`` square cells of pinned rigid bars, hung
    from ``columns + 1`` ground pins (every cell a closed four-bar loop).

    Level ``r`` has ``columns + 1`` hangers (bars of length ``cell`` pinned at both ends) below
    the level above, their lower ends joined by horizontal bars: with ``beams="links"`` one bar
    per cell (pinned at every node, the constraints independent: ``m = rows (6 columns + 2)``,
    one degree of freedom per level), with ``beams="continuous"`` one bar per level through all
    the nodes (a parallel-crank linkage: ``columns - 1`` redundant rows per level, rank
    ``m - rows (columns - 1)``). Each bar has mass ``mass``; released with every hanger tilted by
    ``shear`` (rad, alternating in sign from level to level) and turning at ``speed`` (rad/s,
    counterclockwise; default 0: from rest), under gravity. A consistent state; conservative:
    ``T + V`` is constant. With ``beams="continuous"`` and enough ``speed`` the hangers pass the
    horizontal, where each level's parallel cranks lie along their beam and the rank of the
    constraints drops (singular configurations, docs/integrators.md)."""
    w, h = int(columns), int(rows)
    if w < 1 or w != columns or h < 1 or h != rows:
        raise ValueError(f"columns and rows must be positive integers, got columns={columns!r}, rows={rows!r}")
    if not cell > 0.0 or not mass > 0.0:
        raise ValueError(f"cell and mass must be positive, got cell={cell!r}, mass={mass!r}")
    if beams not in ("links", "continuous"):
        raise ValueError(f"beams must be 'links' or 'continuous', got {beams!r}")
    if not abs(shear) < 0.5 * math.pi:
        raise ValueError(f"shear must be in (-pi/2, pi/2), got {shear!r}")
    s = Scene(gravity=gravity_vector(gravity))
    inertia = mass * cell**2 / 12.0
    span = w * cell
    x0 = 0.0  # the level's left node
    top = [s.ground.point(i * cell, 0.0) for i in range(w + 1)]
    v_top = (0.0, 0.0)  # velocity of the level above (its bars translate)
    for r in range(h):
        a = shear if r % 2 == 0 else -shear
        # hanger direction: straight down turned by a; its rate `speed` moves the tip by w x d
        dx, dy = cell * math.sin(a), -cell * math.cos(a)
        tip_v = (v_top[0] - speed * dy, v_top[1] + speed * dx)
        y_top = -r * cell * math.cos(shear)
        x_top = x0
        bottom = []
        for i in range(w + 1):
            xt = x_top + i * cell
            hb = s.rigid_body(f"hanger{r}_{i}", mass=mass, inertia=inertia,
                              position=(xt + 0.5 * dx, y_top + 0.5 * dy), angle=math.atan2(dy, dx),
                              velocity=(0.5 * (v_top[0] + tip_v[0]), 0.5 * (v_top[1] + tip_v[1])), angular_velocity=speed)
            s.revolute(top[i], hb.point(-0.5 * cell, 0.0), name=f"hang{r}_{i}")
            bottom.append(hb.point(0.5 * cell, 0.0))
        x0 = x_top + dx
        yb = y_top + dy
        v_top = tip_v
        if beams == "links":
            nodes = []
            for i in range(w):
                b = s.rigid_body(f"bar{r}_{i}", mass=mass, inertia=inertia, position=(x0 + (i + 0.5) * cell, yb),
                                 velocity=tip_v)
                s.revolute(bottom[i], b.point(-0.5 * cell, 0.0), name=f"left{r}_{i}")
                s.revolute(bottom[i + 1], b.point(0.5 * cell, 0.0), name=f"right{r}_{i}")
                nodes.append(b.point(-0.5 * cell, 0.0))
            nodes.append(b.point(0.5 * cell, 0.0))
        else:
            b = s.rigid_body(f"beam{r}", mass=mass * w, inertia=mass * w * span**2 / 12.0, position=(x0 + 0.5 * span, yb),
                             velocity=tip_v)
            nodes = []
            for i in range(w + 1):
                s.revolute(bottom[i], b.point((i - 0.5 * w) * cell, 0.0), name=f"node{r}_{i}")
                nodes.append(b.point((i - 0.5 * w) * cell, 0.0))
        top = nodes
    return s


@_checked
def n_four_bar(loops: int = 2, angle: float = math.pi / 4, velocity: float = 1.0, link: float = 1.0, mass: float = 1.0,
               gravity: Any = True) -> Scene:
    """The N four-bar mechanism of the MBS benchmark library (problem A02): ``loops`` four-bar
    loops in a row, ``2 loops + 1`` uniform rods of length ``link`` and mass ``mass``: ``loops +
    1`` cranks pinned to the ground ``link`` apart, ``loops`` couplers joining their tips.

    The cranks start at ``angle`` (rad from the +X axis; the benchmark's figure: 45 degrees) and
    the first crank's tip, point B0, moves at ``velocity`` along +X (the benchmark: 1 m/s); under
    gravity (-Y). Every time the cranks pass the horizontal the constraint Jacobian loses rank
    and the mobility jumps from 1 to ``loops + 1``: a singular configuration. The physical
    motion is the parallelogram one (every crank at the same angle, the couplers translating):
    one pendulum-like equation in the crank angle (docs/integrators.md).
    """
    n = int(loops)
    if n < 1 or n != loops:
        raise ValueError(f"n_four_bar: loops must be a positive integer, got {loops!r}")
    if not link > 0.0 or not mass > 0.0:
        raise ValueError(f"n_four_bar: link and mass must be positive, got link={link!r}, mass={mass!r}")
    s = Scene(gravity=gravity_vector(gravity))
    L, m = link, mass
    c, sn = math.cos(angle), math.sin(angle)
    if abs(sn) < 1e-9:
        raise ValueError("n_four_bar: the cranks must not start horizontal (a singular configuration)")
    omega = -velocity / (L * sn)  # B0 moves at `velocity` along +X
    cranks = []
    for k in range(n + 1):
        b = s.rigid_body(f"crank{k}", mass=m, inertia=m * L**2 / 12.0, com=(L / 2, 0.0), position=(k * L, 0.0),
                         angle=angle, angular_velocity=omega)
        s.revolute(s.ground.point(k * L, 0.0), b.point(0.0, 0.0), name=f"A{k}")
        cranks.append(b)
    for k in range(n):
        cp = s.rigid_body(f"coupler{k}", mass=m, inertia=m * L**2 / 12.0, com=(L / 2, 0.0),
                          position=(k * L + L * c, L * sn), velocity=(-L * sn * omega, L * c * omega))
        s.revolute(cranks[k].point(L, 0.0), cp.point(0.0, 0.0), name=f"B{k}")
        s.revolute(cranks[k + 1].point(L, 0.0), cp.point(L, 0.0), name=f"C{k}")
    return s


SCENES: Dict[str, Callable[..., Scene]] = {
    "slider_crank": slider_crank,
    "pendulum": pendulum,
    "double_pendulum": double_pendulum,
    "four_bar": four_bar,
    "cantilever": cantilever,
    "pinned_beam": pinned_beam,
    "spin_up": spin_up,
    "flexible_pendulum": flexible_pendulum,
    "every_joint": every_joint,
    "chain": chain,
    "rope": rope,
    "lattice": lattice,
    "n_four_bar": n_four_bar,
}


def scene_parameters(fn: Callable[..., Scene]) -> List[Tuple[str, Any]]:
    """``[(name, default)]`` of a scene function's parameters (``ukflex list``)."""
    import inspect

    return [(p.name, p.default) for p in inspect.signature(fn).parameters.values()
            if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
