"""Revolute joints with clearance at the piston pin (docs/loads.md, "Revolute joint with
clearance").

* :func:`flores_scene`: the rigid slider-crank of Flores, Ambrosio et al. (crank 0.05 m, coupler
  0.12 m, 5000 rpm) with a clearance at the piston pin (``clearance=None``: the ideal revolute);
  :func:`flores` runs it for clearances 0.5, 0.25, 0.1 mm and the ideal joint and tabulates the
  slider acceleration and the contact force.
* :func:`coupler_scene`: the paper's flexible slider-crank (``ukflex.scenes.PAPER``: crank
  0.1524 m, FFRF Timoshenko coupler 0.3048 m of 6.35 mm steel rod, 150 rad/s) with a rigid
  slider on a prismatic joint and a clearance between the coupler's end and the slider;
  :func:`study` tabulates the coupler's peak midpoint deflection and peak surface strain
  against the clearance.

Commands (docs/loads.md has the tables and times)::

    python -m studies clearance            # the flexible coupler against the clearance
    python -m studies clearance flores     # the rigid slider-crank of Flores et al.
    python -m studies clearance flores --figure docs/results/clearance/flores.png
"""

from __future__ import annotations

import argparse
import math
import time
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from ukflex import Circular, ConstantSpeed, Scene, scenes, simulate

from . import progress

__all__ = ["hertz_stiffness", "flores_scene", "flores", "figure", "coupler_scene", "study", "main"]

#: Flores et al.'s slider-crank: lengths [m], masses [kg], inertias [kg m^2], crank speed [rad/s].
FLORES = dict(crank=0.05, coupler=0.12, masses=(0.30, 0.21, 0.14), inertias=(0.0001, 0.00025, 0.0001),
              omega=5000 * 2 * math.pi / 60, journal_radius=0.01, restitution=0.9, friction=0.03,
              youngs_modulus=2.07e11, poisson_ratio=0.29)
#: The reference impact velocity of the contact law [m/s] (the impacts of the 0.5 mm case hit at
#: 0.1 to 4 m/s, most near 0.5 to 1.5 m/s).
IMPACT_VELOCITY = 1.0


def hertz_stiffness(journal_radius: float, clearance: float, youngs_modulus: float, poisson_ratio: float) -> float:
    """``K = 4 / (3 (s_J + s_B)) sqrt(R_J R_B / (R_B - R_J))``, ``s = (1 - nu^2) / E``: the
    Hertz stiffness of a journal in a bearing of the same material (Flores et al.)."""
    s = (1 - poisson_ratio**2) / youngs_modulus
    rb = journal_radius + clearance
    return 4 / (3 * 2 * s) * math.sqrt(journal_radius * rb / clearance)


def flores_scene(clearance: Optional[float] = None, *, friction: float = FLORES["friction"],
                 restitution: float = FLORES["restitution"], law: str = "lankarani_nikravesh",
                 impact_velocity: float = IMPACT_VELOCITY) -> Scene:
    """The rigid slider-crank with a clearance of ``clearance`` [m] at the piston pin (between
    the coupler's end and the slider), or the ideal revolute (``None``); crank driven at 5000
    rpm, gravity along -y. At ``t = 0`` crank and coupler lie along +x, the journal centred in
    the bearing."""
    f = FLORES
    l1, l2, w = f["crank"], f["coupler"], f["omega"]
    (m1, m2, m3), (j1, j2, j3) = f["masses"], f["inertias"]
    s = Scene(gravity=(0.0, -9.81))
    crank = s.rigid_body("crank", mass=m1, inertia=j1, com=(l1 / 2, 0), angular_velocity=w)
    rod = s.rigid_body("coupler", mass=m2, inertia=j2, com=(l2 / 2, 0), position=(l1, 0), velocity=(0, l1 * w),
                       angular_velocity=-l1 * w / l2)
    slider = s.rigid_body("slider", mass=m3, inertia=j3, position=(l1 + l2, 0))
    s.revolute(s.ground.point(0, 0), crank.point(0, 0), name="pivot")
    s.revolute(crank.point(l1, 0), rod.point(0, 0), name="crank_pin")
    _piston_pin(s, rod.point(l2, 0), slider.point(0, 0), clearance, f["journal_radius"], friction, restitution, law,
                impact_velocity)
    s.prismatic(slider.point(0, 0), s.ground.point(0, 0), name="guide")
    s.angle_driver(crank.frame(), ConstantSpeed(w, initial=0.0), name="drive")
    return s


def _piston_pin(s: Scene, journal, bearing, clearance, radius, friction, restitution, law, impact_velocity) -> None:
    if clearance is None:
        s.revolute(journal, bearing, name="piston_pin")
        return
    k = hertz_stiffness(radius, clearance, FLORES["youngs_modulus"], FLORES["poisson_ratio"])
    s.revolute_clearance(journal, bearing, clearance=clearance, journal_radius=radius, stiffness=k,
                         restitution=restitution, impact_velocity=impact_velocity, law=law, friction=friction,
                         name="piston_pin")


def _slider_acceleration(res) -> np.ndarray:
    names = res.system.coordinate_names
    return res.qdd()[names.index("slider.x")]


def _runs(build, period: float, clearances, revolutions: int, samples: int, method: str, rtol: float, measure):
    """Run ``build(c)`` over ``revolutions`` periods for each clearance; per case a row with the
    clearance, the method, the run time of ``ukflex.simulate``, the peak force at the piston
    pin over the last period (the contact's, or the ideal joint's reaction) and what
    ``measure(res, last)`` adds."""
    t_end = revolutions * period
    te = np.linspace(0.0, t_end, revolutions * samples + 1)
    last = te >= t_end - period * (1 + 1e-9)
    rows = []
    for c in clearances:
        progress("clearance", f"{build.__name__} clearance {c} {method} rtol {rtol:g}")
        system = build(c).build()
        t0 = time.perf_counter()
        res = simulate(system, t_end, method=method, rtol=rtol, t_eval=te)
        row: Dict[str, Any] = dict(clearance=c, method=res.method, run=time.perf_counter() - t0)
        if c is None:
            r = res.sensors.reaction("piston_pin")
            row["force"] = float(np.hypot(r["fx"], r["fy"])[last].max())
        else:
            row["force"] = float(res.sensors.clearance("piston_pin")["force"][last].max())
        row.update(measure(res, last))
        rows.append(row)
    return rows


def flores(clearances: Sequence[Optional[float]] = (None, 0.5e-3, 0.25e-3, 0.1e-3), revolutions: int = 3,
           samples: int = 4000, rtol: float = 1e-8) -> List[Dict[str, Any]]:
    """Run :func:`flores_scene` over ``revolutions`` crank turns for each clearance (default
    method); per case the peak slider acceleration over the last turn, the peak force at the
    piston pin, the number of impacts over the last turn, the share of it in contact and the
    energy balance's relative error."""

    def measure(res, last):
        a = _slider_acceleration(res)
        out = dict(a_max=float(a[last].max()), a_min=float(a[last].min()))
        if not any(j == "piston_pin" for j in res.sensors.joint_names):  # a clearance, not a joint
            pen = res.sensors.clearance("piston_pin")["penetration"][last]
            out.update(impacts=int(np.sum((pen[1:] > 0) & (pen[:-1] <= 0))), contact=float(np.mean(pen > 0)),
                       balance=float(res.sensors.energy_balance()["relative_error"]))
        return out

    return _runs(flores_scene, 2 * math.pi / FLORES["omega"], clearances, revolutions, samples, "auto", rtol, measure)


def coupler_scene(clearance: Optional[float] = None, *, elements: int = 2, slider_mass: float = 0.1,
                  journal_radius: float = 0.005, friction: float = FLORES["friction"],
                  restitution: float = FLORES["restitution"], impact_velocity: float = 0.1) -> Scene:
    """The paper's flexible slider-crank (``ukflex.scenes.PAPER``, FFRF Timoshenko coupler of
    ``elements`` elements with nonlinear strain, gravity) with a rigid slider of
    ``slider_mass`` [kg] on a prismatic joint along x and a clearance of ``clearance`` [m] between
    the coupler's end and the slider (``None``: the ideal revolute)."""
    p = scenes.PAPER
    l1, l2, w = p["crank_length"], p["coupler_length"], p["omega"]
    d = p["diameter"]
    area = math.pi * d * d / 4
    s = Scene(gravity=(0.0, -9.81))
    crank = s.rigid_body("crank", mass=p["density"] * area * l1, inertia=p["density"] * area * l1**3 / 12,
                         com=(l1 / 2, 0), angular_velocity=w)
    coupler = s.beam("coupler", length=l2, elements=elements, section=Circular(d), density=p["density"],
                     youngs_modulus=p["youngs_modulus"], poisson_ratio=p["poisson_ratio"], shear_factor=p["shear_factor"],
                     position=(l1, 0), velocity=(0, l1 * w), angular_velocity=-l1 * w / l2)
    slider = s.rigid_body("slider", mass=slider_mass, inertia=1e-5, position=(l1 + l2, 0))
    s.revolute(s.ground.point(0, 0), crank.point(0, 0), name="pivot")
    s.revolute(crank.point(l1, 0), coupler.at(0.0), name="crank_pin")
    _piston_pin(s, coupler.at(1.0), slider.point(0, 0), clearance, journal_radius, friction, restitution,
                "lankarani_nikravesh", impact_velocity)
    s.prismatic(slider.point(0, 0), s.ground.point(0, 0), name="guide")
    s.angle_driver(crank.frame(), ConstantSpeed(w, initial=0.0), name="drive")
    return s


def study(clearances: Sequence[Optional[float]] = (None, 0.01e-3, 0.05e-3, 0.1e-3, 0.25e-3, 0.5e-3),
          revolutions: int = 2, samples: int = 2000, method: str = "DOPRI5", rtol: float = 1e-8) -> List[Dict[str, Any]]:
    """The coupler's peak midpoint deflection ``|v(0.5)| / Lb`` and peak surface strain
    ``|eps| + |kappa| d / 2`` at the midpoint over the last of ``revolutions`` crank turns, the
    peak force at the piston pin and the run time, for each clearance (default: DOPRI5 at rtol
    1e-8, error-controlled for the ideal joint too: the coupler, undamped, keeps the vibration
    its start sets off, which ``method="auto"``'s fixed RADAU5M step damps)."""
    p = scenes.PAPER

    def measure(res, last):
        _, v = res.beam_displacement("coupler", 0.5)
        f = res.sensors.internal_forces("coupler", [0.5])
        strain = np.abs(np.asarray(f["eps"])[:, 0]) + np.abs(np.asarray(f["kappa"])[:, 0]) * p["diameter"] / 2
        return dict(deflection=float(np.abs(v[last]).max() / p["coupler_length"]), strain=float(strain[last].max()))

    return _runs(coupler_scene, 2 * math.pi / p["omega"], clearances, revolutions, samples, method, rtol, measure)


def figure(path: str, clearances: Sequence[Optional[float]] = (None, 0.5e-3, 0.1e-3), revolutions: int = 2,
           samples: int = 4000) -> Dict[str, Any]:
    """Plot the slider acceleration and the contact force of :func:`flores_scene` against the
    crank angle over the last of ``revolutions`` turns (DOPRI5, rtol 1e-8) into ``path``; returns
    per clearance the crank angles [deg] of the impacts over that turn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    period = 2 * math.pi / FLORES["omega"]
    t_end = revolutions * period
    te = np.linspace(0.0, t_end, revolutions * samples + 1)
    last = te >= t_end - period * (1 + 1e-9)
    angle = np.degrees(FLORES["omega"] * (te[last] - (t_end - period)))
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True)
    impacts: Dict[str, Any] = {}
    for c in clearances:
        system = flores_scene(c).build()
        res = simulate(system, t_end, method="DOPRI5", rtol=1e-8, t_eval=te)
        label = _mm(c) + ("" if c is None else " mm")
        ax1.plot(angle, _slider_acceleration(res)[last] / 1e3, lw=0.8 if c else 1.6, label=label)
        if c is None:
            r = res.sensors.reaction("piston_pin")
            ax2.plot(angle, np.hypot(r["fx"], r["fy"])[last] / 1e3, lw=1.6, label="ideal (reaction)")
        else:
            k = res.sensors.clearance("piston_pin")
            ax2.plot(angle, k["force"][last] / 1e3, lw=0.8, label=label)
            pen = k["penetration"][last]
            impacts[label] = [round(float(a), 1) for a in angle[1:][(pen[1:] > 0) & (pen[:-1] <= 0)]]
    ax1.set_ylabel("slider acceleration [km/s^2]")
    ax2.set_ylabel("piston pin force [kN]")
    ax2.set_xlabel("crank angle [deg] (turn %d)" % revolutions)
    ax1.legend(fontsize=8)
    ax2.legend(fontsize=8)
    fig.suptitle("Slider-crank of Flores et al., 5000 rpm, clearance at the piston pin")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return impacts


def _mm(c: Optional[float]) -> str:
    return "ideal" if c is None else f"{c * 1e3:g}"


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m studies clearance", description=__doc__.split("\n\n")[0])
    parser.add_argument("case", nargs="?", choices=("coupler", "flores"), default="coupler",
                        help="coupler (default): the flexible coupler; flores: the rigid slider-crank of Flores et al.")
    parser.add_argument("--figure", metavar="PNG", default=None, help="flores: also plot the second turn into PNG")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    if args.case == "flores":
        print("| clearance [mm] | method | slider acc. min / max [m/s^2] | peak force [N] | impacts / turn | in contact | balance | run [s] |")
        print("|---|---|---:|---:|---:|---:|---:|---:|")
        for r in flores():
            print(f"| {_mm(r['clearance'])} | {r['method']} | {r['a_min']:.4g} / {r['a_max']:.4g} | {r['force']:.4g} | "
                  f"{r.get('impacts', '-')} | {r.get('contact', 1.0):.0%} | {r.get('balance', float('nan')):.1e} | {r['run']:.2f} |")
        if args.figure:
            for label, angles in figure(args.figure).items():
                print(f"impacts over turn 2, {label}: crank angles {angles} deg")
            print(f"wrote {args.figure}")
    else:
        print("| clearance [mm] | peak v(0.5)/Lb | peak strain | change | peak pin force [N] | run [s] | auto: method | peak strain | run [s] |")
        print("|---|---:|---:|---:|---:|---:|---|---:|---:|")
        rows = study()
        check = study(method="auto", rtol=1e-7)
        for r, k in zip(rows, check):
            print(f"| {_mm(r['clearance'])} | {r['deflection']:.4e} | {r['strain']:.4e} | "
                  f"{r['strain'] / rows[0]['strain'] - 1:+.1%} | {r['force']:.4g} | {r['run']:.2f} | "
                  f"{k['method']} | {k['strain']:.4e} | {k['run']:.2f} |")
    print(f"\ntotal {time.perf_counter() - t0:.1f} s")
    return 0
