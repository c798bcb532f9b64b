"""The paper's slider-crank with its coupler as a general flexible body reduced to ``k`` modes,
against the built-in beam (docs/flexible-bodies.md).

The coupler's FE model is ``elements`` Timoshenko beam elements on the pinned-pinned (chord)
frame, its invariants integrated in NumPy (:mod:`ukflex.reference.fe_invariants`), reduced to its
``k`` lowest modes (:func:`ukflex.fe.reduce`) and built with :meth:`ukflex.Scene.flexible_body`.
The measure is the paper's: peak ``|v(0.5)| / Lb`` over ``0 <= t <= 0.07`` s (``v`` the midpoint
deflection in the chord frame), compared with the built-in beam of the same elements.
"""

from __future__ import annotations

import math
import time
from typing import Any, Dict, List, Optional

import numpy as np

from .. import fe, scenes
from ..flexible import FlexibleData, InterfacePoint
from ..reference import fe_invariants as fi
from ..scene import ConstantSpeed, Scene
from ..simulate import simulate

__all__ = ["coupler_data", "scene", "peak", "study"]

P = scenes.PAPER
WINDOW = 0.07


def coupler_data(elements: int = 8, modes: Optional[int] = None, strain: str = "linear") -> FlexibleData:
    """The paper's coupler (round 6.35 mm steel rod, Timoshenko, rotary inertia) as a flexible
    body: nodal (``modes=None``) or reduced to ``modes`` modes; markers ``"A"`` (xi = 0), ``"M"``
    (xi = 0.5), ``"B"`` (xi = 1)."""
    d = P["diameter"]
    area, i2 = math.pi * d * d / 4, math.pi * d**4 / 64
    g = P["youngs_modulus"] / (2 * (1 + P["poisson_ratio"]))
    inv = fi.beam_invariants(P["coupler_length"], elements, P["density"], P["youngs_modulus"], area, i2,
                             shear_stiffness=P["shear_factor"] * g, rotary_inertia=True, markers=(0.0, 0.5, 1.0),
                             nonlinear=strain == "nonlinear")
    names = dict(zip(["xi=0", "xi=0.5", "xi=1"], "AMB"))
    markers = {names[k]: InterfacePoint(v["point"], v["displacement"], v["rotation"]) for k, v in inv.pop("markers").items()}
    data = FlexibleData(markers=markers, **inv)
    return data if modes is None else fe.reduce(data, modes)


def scene(data: FlexibleData, strain: str = "linear") -> Scene:
    """The paper's slider-crank (scenes.slider_crank) with ``data`` as the coupler."""
    L, Lb, d, om = P["crank_length"], P["coupler_length"], P["diameter"], P["omega"]
    m_crank = P["density"] * math.pi * d * d / 4 * L
    s = Scene(gravity=(0.0, -P["g"]))
    crank = s.rigid_body("crank", mass=m_crank, inertia=m_crank * L * L / 12, com=(L / 2, 0.0), angular_velocity=om)
    cp = s.flexible_body("coupler", data, strain=strain if strain == "nonlinear" else None, position=(L, 0.0),
                         velocity=(0.0, L * om), angular_velocity=-L * om / Lb)
    s.revolute(s.ground.point(0.0, 0.0), crank.point(0.0, 0.0), name="crank_pivot")
    s.revolute(crank.point(L, 0.0), cp.marker("A"), name="crank_coupler")
    s.point_on_line(cp.marker("B"), s.ground.line((0.0, 0.0), angle=0.0), name="slider")
    s.angle_driver(crank.frame(), ConstantSpeed(om, initial=0.0), name="crank_speed")
    return s


def peak(t: np.ndarray, w: np.ndarray) -> float:
    window = t <= WINDOW + 1e-12
    return float(np.max(np.abs(w[window])))


def run_flexible(data: FlexibleData, strain: str = "linear", rtol: float = 1e-8) -> Dict[str, Any]:
    system = scene(data, strain).build()
    t0 = time.perf_counter()
    res = simulate(system, WINDOW, method="DOPRI5", rtol=rtol, atol=1e-3 * rtol)
    wall = time.perf_counter() - t0
    qf = np.array([res.coordinate(f"coupler.qf{i}") for i in range(data.n_f)])
    v = np.asarray(data.markers["M"].displacement)[1] @ qf
    return dict(peak=peak(res.t, v / P["coupler_length"]), wall=wall, nfev=int(getattr(res, "nfev", -1)))


def run_beam(elements: int, strain: str = "linear", rtol: float = 1e-8) -> Dict[str, Any]:
    system = scenes.slider_crank(elements=elements, strain=strain).build()
    t0 = time.perf_counter()
    res = simulate(system, WINDOW, method="DOPRI5", rtol=rtol, atol=1e-3 * rtol)
    wall = time.perf_counter() - t0
    _, v = res.beam_displacement("coupler", 0.5)
    return dict(peak=peak(res.t, v / P["coupler_length"]), wall=wall)


def study(elements: int = 8, ks=(2, 4, 8), strain: str = "linear", rtol: float = 1e-8) -> List[Dict[str, Any]]:
    """Peak error of the k-mode coupler vs the built-in beam (same elements, same strain)."""
    ref = run_beam(elements, strain, rtol)
    rows = [dict(model=f"built-in beam N={elements}", k=None, peak=ref["peak"], error=0.0, wall=ref["wall"], f_max=None)]
    nodal = coupler_data(elements, None, strain)
    for k in ks:
        data = fe.reduce(nodal, k)
        r = run_flexible(data, strain, rtol)
        rows.append(dict(model=f"flexible k={k}", k=k, peak=r["peak"], error=abs(r["peak"] - ref["peak"]) / ref["peak"],
                         wall=r["wall"], f_max=float(data.info["frequencies"][-1] / (2 * math.pi))))
    r = run_flexible(nodal, strain, rtol)
    rows.append(dict(model=f"flexible nodal n_f={nodal.n_f}", k=nodal.n_f, peak=r["peak"],
                     error=abs(r["peak"] - ref["peak"]) / ref["peak"], wall=r["wall"], f_max=None))
    return rows


if __name__ == "__main__":  # pragma: no cover
    import sys

    strain = "nonlinear" if "--nonlinear" in sys.argv else "linear"
    for row in study(strain=strain):
        fmax = "" if row["f_max"] is None else f"  f_max {row['f_max']:.0f} Hz"
        print(f"{row['model']:26s} peak |v(0.5)|/Lb {row['peak']:.6e}  rel. error {row['error']:.2e}  {row['wall']:.2f} s{fmax}")
