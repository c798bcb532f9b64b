"""A catalogue of stiff and extreme scenes: every scene is a plain :class:`ukflex.Scene`.

Seven groups, each a function returning a scene (call ``.build()`` or pass it to
:func:`ukflex.simulate`), and :data:`CASES`, the list the stability report
(:mod:`studies.stability`, ``python -m studies stability``, ``docs/stability.md``) runs, with a full
and a reduced ("quick") size for each.  Parameters follow the built-in scenes:
``theory=`` is the coupler's beam theory, ``gravity=`` is ``True``/``False``, a magnitude or a
vector (:func:`ukflex.scenes.gravity_vector`).

1. **Stiff** -- :func:`stiff`: the paper's slider-crank with ``E x 100``, ``x 10^4`` or a fine
   mesh (``N = 32, 64``: highest coupler frequencies 2.2e6 and 3.7e6 rad/s).
2. **Very flexible** -- :func:`flexible`: a thinner coupler; the linear FFRF model leaves its
   range (``max |v|/Lb > 0.05``, ``|psi| > 0.1``): :func:`ukflex.stability.ffrf_validity`.
3. **High speed** -- :func:`high_speed`: crank speed ``x 3``, ``x 5``; the coupler's compressive
   axial force against its Euler buckling load ``pi^2 E I / Lb^2``
   (:func:`ukflex.stability.axial_force`).
4. **Singular configurations** -- :func:`equal_slider_crank` (crank = coupler: the slider end
   reaches the crank pivot at ``theta = pi/2``, where ``A`` loses rank and two branches of
   motion cross), :func:`parallelogram` (four-bar with ``a = c``, ``b = d`` crossing its flat
   change point).
5. **Redundant constraints** -- :func:`parallelogram` with ``extra_link=True`` (a third
   parallel crank: 12 rows, rank 11, everywhere), :func:`duplicate_joint` (a revolute declared
   twice).
6. **Long runs** -- :func:`long_run`: 100 crank revolutions of the paper's mechanism.
7. **Ill-conditioning** -- :func:`mass_ratio` (double pendulum, masses 1 : ratio),
   :func:`near_massless` (the paper's mechanism with a slider block of 1e-9 kg),
   :func:`stiff` with many elements, :func:`slider_crank_units` (the paper's scene in m or mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Tuple

from ukflex import Circular, ConstantSpeed, Scene, UnknownNameError, scenes

PAPER, double_pendulum, gravity_vector, slider_crank = (scenes.PAPER, scenes.double_pendulum, scenes.gravity_vector,
                                                      scenes.slider_crank)

__all__ = [
    "stiff",
    "flexible",
    "high_speed",
    "equal_slider_crank",
    "parallelogram",
    "duplicate_joint",
    "long_run",
    "mass_ratio",
    "near_massless",
    "slider_crank_units",
    "Case",
    "CASES",
    "case",
    "REVOLUTION",
]

#: Duration of one crank revolution of the paper's mechanism [s] (2 pi / 124.8).
REVOLUTION = 2.0 * math.pi / PAPER["omega"]


# ------------------------------------------------------------------------------------ 1-3, 6
def stiff(factor: float = 100.0, elements: int = 1, theory: str = "timoshenko", **kw: Any) -> Scene:
    """The paper's slider-crank with ``E x factor`` and ``elements`` coupler elements.

    Highest coupler frequency (pinned-pinned elastic block, Timoshenko): 2.9e4 rad/s for
    ``N = 1``; it grows as ``sqrt(factor)`` and with the mesh (2.2e6 rad/s at ``N = 32``,
    3.7e6 at ``N = 64``, saturated by the shear modes).  With no damping the sudden start excites
    these modes and every integrator that meets ``rtol`` must resolve them.
    """
    return slider_crank(theory=theory, elements=elements, youngs_modulus=PAPER["youngs_modulus"] * factor, **kw)


def flexible(diameter_factor: float = 0.25, elements: int = 4, theory: str = "euler-bernoulli", **kw: Any) -> Scene:
    """The paper's slider-crank with a thinner coupler (``d x diameter_factor``).

    The inertial bending load scales as ``a / I ~ 1 / d^2``: ``d/2`` gives ~4 %, ``d/4`` ~15 %
    deflection of the coupler length -- beyond the small-deformation range of the linear FFRF
    model (no geometric stiffening).
    """
    return slider_crank(theory=theory, elements=elements, diameter=PAPER["diameter"] * diameter_factor, **kw)


def high_speed(factor: float = 3.0, elements: int = 2, theory: str = "timoshenko", **kw: Any) -> Scene:
    """The paper's slider-crank at ``omega x factor``.  The coupler's inertial axial force grows
    as ``omega^2``; at ``x 5`` its compressive peak exceeds the Euler load ``pi^2 E I / Lb^2``
    (1.75 kN), where the linear FFRF model (no axial-load effect on the bending stiffness) is
    no longer valid."""
    return slider_crank(theory=theory, elements=elements, omega=PAPER["omega"] * factor, **kw)


def long_run(elements: int = 1, theory: str = "timoshenko", **kw: Any) -> Scene:
    """The paper's mechanism for long runs (100 revolutions = ``100 * REVOLUTION`` = 5.03 s)."""
    return slider_crank(theory=theory, elements=elements, **kw)


# ------------------------------------------------------------------------------------ 4, 5
def equal_slider_crank(
    length: float = PAPER["crank_length"],
    omega: float = 20.0,
    coupler: str = "rigid",
    elements: int = 2,
    gravity: Any = False,
) -> Scene:
    """Slider-crank whose crank and coupler have the same length ``L``.

    Start: crank and coupler along +X (slider at ``2 L``), crank driven at ``omega``.  At
    ``theta = pi/2`` (``t = pi / (2 omega)``) the slider end reaches the crank pivot: the
    coupler is vertical, the slider row and the crank-coupler joint rows become dependent
    (``rank A`` drops by one) and two branches of motion cross: the slider branch
    ``x_s = 2 L cos(theta)`` (coupler angle ``-theta``) and the branch ``x_s = 0`` (the slider
    end stays at the pivot, coupler angle ``theta + pi``).  The coupler's angular velocity
    (``-omega`` vs ``+omega``) tells them apart, so a smooth motion stays on the slider branch.

    ``coupler``: ``"rigid"`` (uniform bar, steel, the paper's section) or a beam theory.
    """
    L = length
    d, rho = PAPER["diameter"], PAPER["density"]
    m = rho * math.pi * d * d / 4.0 * L
    s = Scene(gravity=gravity_vector(gravity))
    crank = s.rigid_body("crank", mass=m, inertia=m * L * L / 12.0, com=(L / 2, 0.0), angular_velocity=omega)
    if coupler == "rigid":
        cp = s.rigid_body(
            "coupler", mass=m, inertia=m * L * L / 12.0, com=(L / 2, 0.0), position=(L, 0.0),
            velocity=(0.0, L * omega), angular_velocity=-omega,
        )
        a_start, a_end = cp.point(0.0, 0.0), cp.point(L, 0.0)
    else:
        kw = {"poisson_ratio": PAPER["poisson_ratio"], "shear_factor": PAPER["shear_factor"]} if coupler == "timoshenko" else {}
        cp = s.beam(
            "coupler", length=L, elements=elements, theory=coupler, section=Circular(d), density=rho,
            youngs_modulus=PAPER["youngs_modulus"], frame="pinned-pinned", position=(L, 0.0),
            velocity=(0.0, L * omega), angular_velocity=-omega, **kw,
        )
        a_start, a_end = cp.at(0.0), cp.at(1.0)
    s.revolute(s.ground.point(0.0, 0.0), crank.point(0.0, 0.0), name="crank_pivot")
    s.revolute(crank.point(L, 0.0), a_start, name="crank_coupler")
    s.point_on_line(a_end, s.ground.line((0.0, 0.0), angle=0.0), name="slider")
    s.angle_driver(crank.frame(), ConstantSpeed(omega, initial=0.0), name="crank_speed")
    return s


def parallelogram(
    crank: float = 0.1,
    span: float = 0.3,
    angle: float = math.pi / 2,
    omega: Optional[float] = 10.0,
    extra_link: bool = False,
    gravity: Any = True,
) -> Scene:
    """Parallelogram four-bar (crank = rocker = ``crank``, coupler = ground = ``span``), rigid.

    Ground pivots at ``(0, 0)`` and ``(span, 0)``; crank, rocker (and the ``extra`` crank at
    ``(2 span, 0)``) start at ``angle``; the coupler (length ``2 span`` with ``extra_link``)
    stays horizontal on the parallelogram branch (every crank angle equals the driven one).

    * ``omega`` given: the crank is driven at constant speed and crosses the flat positions
      ``theta = 0, pi`` -- change points where all links are collinear, ``rank A`` drops and the
      mechanism may switch to the anti-parallelogram branch.
    * ``omega=None``: free under gravity (a pendulum linkage; ``T + V`` is conserved).
    * ``extra_link``: a third crank makes the constraints redundant everywhere (Grubler count
      0 DOF, true mobility 1: 12 rows of rank 11) but consistent.
    """
    a, d = crank, span
    mass_per_length = 2.0
    c, si = math.cos(angle), math.sin(angle)
    w = omega or 0.0
    s = Scene(gravity=gravity_vector(gravity))
    pivots = [0.0, d] + ([2.0 * d] if extra_link else [])
    names = ["crank", "rocker", "extra"][: len(pivots)]
    links = []
    for name, px in zip(names, pivots):
        m = mass_per_length * a
        links.append(
            s.rigid_body(name, mass=m, inertia=m * a * a / 12.0, com=(a / 2, 0.0), position=(px, 0.0), angle=angle,
                         angular_velocity=w)
        )
    span_c = pivots[-1]
    mc = mass_per_length * span_c
    cp = s.rigid_body(
        "coupler", mass=mc, inertia=mc * span_c**2 / 12.0, com=(span_c / 2, 0.0), position=(a * c, a * si),
        velocity=(-a * si * w, a * c * w),
    )
    for name, px, link in zip(names, pivots, links):
        s.revolute(s.ground.point(px, 0.0), link.point(0.0, 0.0), name=f"{name}_ground")
        s.revolute(link.point(a, 0.0), cp.point(px, 0.0), name=f"{name}_coupler")
    if omega is not None:
        s.angle_driver(links[0].frame(), ConstantSpeed(omega, initial=angle), name="crank_speed")
    return s


def duplicate_joint(elements: int = 1, **kw: Any) -> Scene:
    """The paper's slider-crank with the crank-coupler revolute declared twice (rows 3-4 and
    rows 7-8 identical: ``m = 8``, rank 6)."""
    s = slider_crank(elements=elements, **kw)
    d = s.to_dict()
    dup = dict(d["joints"][1])
    dup["name"] = "crank_coupler_again"
    d["joints"].append(dup)
    return Scene.from_dict(d)


# ------------------------------------------------------------------------------------ 7
def mass_ratio(ratio: float = 1e-6, lengths: Tuple[float, float] = (1.0, 0.7), angles=(0.0, math.pi / 3)) -> Scene:
    """Double pendulum of uniform rods with masses ``1`` and ``ratio`` kg, released from rest
    (:func:`ukflex.scenes.double_pendulum`).  Conservative; ``cond(M)`` grows like
    ``1 / ratio`` (or ``ratio``)."""
    return double_pendulum(lengths=lengths, masses=(1.0, float(ratio)), angles=angles, gravity=True)


def near_massless(slider_mass: float = 1e-9, slider_inertia: Optional[float] = None, elements: int = 1, **kw: Any) -> Scene:
    """The paper's slider-crank with an explicit slider block of (nearly) zero mass.

    The coupler end is pinned to a rigid ``slider`` body guided by a prismatic joint along the
    ground X axis.  ``slider_mass = 0`` would make ``M`` singular (UK needs it positive
    definite): the scene validation refuses it (:class:`ukflex.InvalidSceneError`, "mass must be
    positive").  With 1e-9 kg the
    motion must equal the paper's scene (which has no slider body) to ~1e-9 relative.
    """
    s0 = slider_crank(elements=elements, **kw)
    d = s0.to_dict()
    Lc, Lb = PAPER["crank_length"], PAPER["coupler_length"]
    inertia = slider_mass * 1e-4 if slider_inertia is None else slider_inertia
    d["bodies"].append({"name": "slider", "kind": "rigid", "mass": float(slider_mass), "inertia": float(inertia),
                        "com": [0.0, 0.0], "position": [Lc + Lb, 0.0], "angle": 0.0, "velocity": [0.0, 0.0],
                        "angular_velocity": 0.0})
    d["joints"] = [j for j in d["joints"] if j.get("name") != "slider"]
    d["joints"].append({"kind": "revolute", "name": "coupler_slider", "a": {"body": "coupler", "xi": 1.0, "angle": 0.0},
                        "b": {"body": "slider", "point": [0.0, 0.0], "angle": 0.0}})
    d["joints"].append({"kind": "prismatic", "name": "slide", "a": {"body": "slider", "point": [0.0, 0.0], "angle": 0.0},
                        "b": {"body": "ground", "point": [0.0, 0.0], "angle": 0.0}})
    return Scene.from_dict(d)


#: (length, mass, time) unit scale factors of the supported unit systems relative to SI.
UNITS = {"m": 1.0, "mm": 1e3}


def slider_crank_units(unit: str = "mm", elements: int = 2, theory: str = "timoshenko", gravity: Any = True) -> Scene:
    """The paper's slider-crank in a consistent ``(length unit, kg, s)`` system.

    With lengths in mm (``k = 1000``): lengths ``x k``, mass kg, time s, so force is
    ``kg mm / s^2 = 1e-3 N``; ``E`` and ``G`` (N/m^2 = kg / (m s^2)) ``x 1/k``; density
    (kg/m^3) ``x 1/k^3``; gravity ``x k``; section (area ``x k^2``, ``I x k^4``) from the
    diameter ``x k``.  Angles, the crank speed and every dimensionless output (``v / Lb``)
    are unchanged.  ``gravity`` is given in SI (m/s^2) and scaled here.
    """
    k = UNITS[unit]
    P = PAPER
    g = gravity_vector(gravity)
    return slider_crank(
        theory=theory, elements=elements,
        gravity=(g[0] * k, g[1] * k) if g is not None else False,
        crank_length=P["crank_length"] * k, coupler_length=P["coupler_length"] * k,
        diameter=P["diameter"] * k, density=P["density"] / k**3, youngs_modulus=P["youngs_modulus"] / k,
    )


# ------------------------------------------------------------------------------------ registry
@dataclass
class Case:
    """One entry of the catalogue.

    Attributes
    ----------
    name : str
        Identifier (``studies.extreme.case(name)``).
    group : int
        Issue group 1-7 (stiff, flexible, high speed, singular, redundant, long run,
        ill-conditioning).
    title : str
        One line for the report.
    scene : callable
        ``scene(**params)`` -> :class:`ukflex.Scene`.
    params, quick_params : dict
        Scene parameters at full and reduced size.
    t_end, quick_t_end : float
        Simulated time at full and reduced size [s].
    cp_t_end : float or None
        Simulated time for the (slow, NumPy) coordinate-partitioning run in the report;
        ``None``: CP is not run on this case (said so in the report).
    notes : str
        What to watch.
    """

    name: str
    group: int
    title: str
    scene: Callable[..., Scene]
    params: Dict[str, Any] = field(default_factory=dict)
    quick_params: Optional[Dict[str, Any]] = None
    t_end: float = 0.07
    quick_t_end: Optional[float] = None
    cp_t_end: Optional[float] = 0.005
    notes: str = ""

    def parameters(self, quick: bool = False) -> Dict[str, Any]:
        """The scene parameters at full or reduced size."""
        return self.quick_params if (quick and self.quick_params is not None) else self.params

    def build_scene(self, quick: bool = False) -> Scene:
        return self.scene(**self.parameters(quick))

    def duration(self, quick: bool = False) -> float:
        return self.quick_t_end if (quick and self.quick_t_end is not None) else self.t_end


GROUPS = {1: "stiff", 2: "very flexible", 3: "high speed", 4: "singular configuration",
          5: "redundant constraints", 6: "long run", 7: "ill-conditioning"}

CASES: List[Case] = [
    Case("stiff_E100", 1, "paper coupler, E x 100 (N = 1)", stiff, {"factor": 100.0}, None, 0.07, 0.02, 0.003),
    Case("stiff_E1e4", 1, "paper coupler, E x 10^4 (N = 1)", stiff, {"factor": 1e4}, None, 0.02, 0.005, 0.001),
    Case("stiff_N32", 1, "paper coupler, N = 32 elements", stiff, {"factor": 1.0, "elements": 32},
         {"factor": 1.0, "elements": 32}, 0.01, 0.002, None),
    Case("stiff_N64", 1, "paper coupler, N = 64 elements", stiff, {"factor": 1.0, "elements": 64},
         {"factor": 1.0, "elements": 64}, 0.005, 0.001, None),
    Case("flexible_d2", 2, "coupler diameter / 2 (E-B, N = 4)", flexible, {"diameter_factor": 0.5}, None, 0.07, 0.07, 0.003),
    Case("flexible_d4", 2, "coupler diameter / 4 (E-B, N = 4)", flexible, {"diameter_factor": 0.25}, None, 0.07, 0.07, 0.003),
    Case("speed_x3", 3, "crank speed x 3 (N = 2)", high_speed, {"factor": 3.0}, None, 0.07 / 3, 0.07 / 3, 0.003),
    Case("speed_x5", 3, "crank speed x 5 (N = 2)", high_speed, {"factor": 5.0}, None, 0.07 / 5, 0.07 / 5, 0.003),
    Case("singular_slider_crank", 4, "slider-crank, crank = coupler (rigid), through theta = pi/2",
         equal_slider_crank, {"omega": 20.0}, None, math.pi / 20.0, math.pi / 20.0, math.pi / 20.0),
    Case("singular_slider_crank_flex", 4, "slider-crank, crank = coupler (Timoshenko beam, N = 2)",
         equal_slider_crank, {"omega": 20.0, "coupler": "timoshenko"}, None, math.pi / 20.0, math.pi / 20.0, None),
    Case("flat_parallelogram", 4, "parallelogram four-bar driven through its flat change point",
         parallelogram, {"omega": 10.0}, None, 0.3, 0.3, 0.3),
    Case("redundant_parallelogram", 5, "parallelogram with a third parallel crank (12 rows, rank 11), free",
         parallelogram, {"omega": None, "extra_link": True, "angle": -math.pi / 2 + 0.6}, None, 2.0, 1.0, 1.0),
    Case("duplicate_joint", 5, "paper slider-crank with a revolute declared twice", duplicate_joint, {},
         None, 0.07, 0.02, 0.003),
    Case("long_run", 6, "paper slider-crank, 100 revolutions", long_run, {}, None, 100 * REVOLUTION, 10 * REVOLUTION, None),
    Case("mass_ratio_1e-6", 7, "double pendulum, masses 1 : 1e-6", mass_ratio, {"ratio": 1e-6}, None, 2.0, 1.0, 1.0),
    Case("mass_ratio_1e6", 7, "double pendulum, masses 1 : 1e6", mass_ratio, {"ratio": 1e6}, None, 2.0, 1.0, 1.0),
    Case("near_massless_slider", 7, "paper slider-crank + slider block of 1e-9 kg", near_massless, {}, None, 0.07, 0.02, 0.003),
    Case("units_mm", 7, "paper slider-crank (N = 2) in mm, kg, s", slider_crank_units, {"unit": "mm"}, None, 0.07, 0.02, 0.003),
]


def case(name: str) -> Case:
    """The catalogue entry ``name``."""
    for c in CASES:
        if c.name == name:
            return c
    raise UnknownNameError.of("case", name, [c.name for c in CASES])
