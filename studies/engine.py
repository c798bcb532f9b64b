"""A single-cylinder four-stroke engine started by a DC motor (docs/loads.md, "The engine
example"): a slider-crank with a flexible connecting rod (an FFRF Timoshenko beam), a gas force
on the piston tabulated against the crank angle over the 720 deg cycle, friction in the main
bearing, the crank pin, the piston pin and the cylinder, a DC motor with rotor inertia on the
crank, from rest.

* :func:`cylinder_pressure`: the pressure against the crank angle from the single-zone model
  with a Wiebe heat release (Heywood, *Internal Combustion Engine Fundamentals*, 1988, sec. 9.2:
  ``dp/dtheta = (gamma - 1)/V dQ/dtheta - gamma p/V dV/dtheta``, ``Q = Q_in x_b``,
  ``x_b = 1 - exp(-a ((theta - theta_s)/dtheta)^(m + 1))``, ``a = 5``, ``m = 2``), intake and
  exhaust at ambient pressure;
* :func:`engine_scene`: the scene; :func:`run` runs it and measures the crank speed's
  fluctuation, the bearing forces and the rod's deflection at steady state.

Command (docs/loads.md has the table, the figure and the time)::

    python -m studies engine [--figure docs/results/engine/engine.png]
"""

from __future__ import annotations

import argparse
import math
import time
from typing import Any, Dict, Optional, Sequence

import numpy as np

from ukflex import Circular, LoadTable, Scene, simulate
from ukflex.model.scene import dc_motor_torque

__all__ = ["ENGINE", "JOINTS", "cylinder_pressure", "piston_travel", "engine_scene", "motor_torque", "cycle_work", "run", "figure", "main"]

#: The engine [SI units]: crank radius, rod length, bore, compression ratio; masses and
#: inertias (the crank with its flywheel about the main bearing); the rod's steel section and
#: its stiffness-proportional damping ``beta`` [s] (2 % of critical at its first bending mode,
#: 1.25e4 rad/s, ``zeta = beta omega / 2``; more for the higher modes); the
#: heat released per cycle (part load of a 170 cm^3 cylinder), the Wiebe burn (start 15 deg
#: before the firing top dead centre, 50 deg long), the polytropic gamma, the exhaust valve's
#: opening (130 deg, 50 deg before the bottom dead centre) and the blowdown's length; the DC motor (torque
#: constant, resistance, voltage, rotor inertia: no-load speed V/k = 300 rad/s); the friction
#: coefficients and pin radii.
ENGINE = dict(crank=0.03, rod=0.11, bore=0.06, compression_ratio=8.0,
              crank_mass=2.0, crank_inertia=0.02, piston_mass=0.15, rod_diameter=0.012, rod_damping=3.2e-6,
              density=7850.0, youngs_modulus=2.07e11, poisson_ratio=0.3, shear_factor=0.9,
              heat=300.0, burn_start=-15.0, burn_duration=50.0, gamma=1.3, ambient=1.0e5,
              exhaust_opens=130.0, blowdown=60.0,
              motor_k=0.5, motor_r=1.0, motor_v=150.0, rotor_inertia=0.005,
              mu_bearing=0.02, main_radius=0.015, crankpin_radius=0.012, pistonpin_radius=0.007,
              mu_cylinder=0.05, start_angle=math.pi + 0.3)


def piston_travel(theta, e: Dict[str, Any] = ENGINE):
    """The piston's distance below its top dead centre at the crank angle ``theta``."""
    r, l = e["crank"], e["rod"]
    return r + l - (r * np.cos(theta) + np.sqrt(l * l - (r * np.sin(theta)) ** 2))


def cylinder_pressure(points: int = 1441, e: Dict[str, Any] = ENGINE):
    """``(theta, p)``: the cylinder pressure [Pa] over one cycle, ``theta`` from ``-pi``
    (intake closes, bottom dead centre) to ``3 pi``; firing top dead centre at ``theta = 0``:
    compression ``[-pi, 0]``, expansion ``[0, pi]``, exhaust ``[pi, 2 pi]`` and intake
    ``[2 pi, 3 pi]``. The closed part is the single-zone model (module doc) integrated by a
    classical Runge-Kutta rule on ``points`` nodes; from the exhaust valve's opening the
    pressure falls to ambient along a cosine blend over ``e["blowdown"]`` deg."""
    area = math.pi * e["bore"] ** 2 / 4
    vs = area * 2 * e["crank"]
    vc = vs / (e["compression_ratio"] - 1)
    g, q_in = e["gamma"], e["heat"]
    ts, dt = math.radians(e["burn_start"]), math.radians(e["burn_duration"])

    def volume(th):
        return vc + area * piston_travel(th, e)

    def dvol(th, h=1e-6):
        return (volume(th + h) - volume(th - h)) / (2 * h)

    def dheat(th):
        x = (th - ts) / dt
        if x <= 0.0:
            return 0.0
        return q_in * 5.0 * 3.0 * x * x * math.exp(-5.0 * x**3) / dt

    def rate(th, p):
        v = volume(th)
        return (g - 1) / v * dheat(th) - g * p / v * dvol(th)

    theta = np.linspace(-math.pi, 3 * math.pi, points)
    p = np.full(points, e["ambient"])
    h = theta[1] - theta[0]
    evo, blow = math.radians(e["exhaust_opens"]), math.radians(e["blowdown"])
    for i in range(points - 1):
        th = theta[i]
        if th >= evo + blow:  # the cylinder is open to the exhaust from here on
            break
        k1 = rate(th, p[i])
        k2 = rate(th + h / 2, p[i] + h / 2 * k1)
        k3 = rate(th + h / 2, p[i] + h / 2 * k2)
        k4 = rate(th + h, p[i] + h * k3)
        p[i + 1] = p[i] + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    # blowdown: from the exhaust valve's opening the pressure falls to ambient along a cosine
    # blend over `blowdown` (a smooth force: a step would ring the rod and the table's spline)
    x = np.clip((theta - evo) / blow, 0.0, 1.0)
    p = e["ambient"] + (p - e["ambient"]) * 0.5 * (1.0 + np.cos(math.pi * x))
    return theta, p


JOINTS = ("main", "crankpin", "pistonpin", "cylinder")


def engine_scene(*, elements: int = 2, friction: Sequence[str] = JOINTS, gas: bool = True, v_eps: Optional[float] = None,
                 rigid_rod: bool = False, speed: float = 0.0, e: Dict[str, Any] = ENGINE) -> Scene:
    """The engine at rest at the crank angle ``e["start_angle"]`` (past the bottom dead centre
    before the exhaust stroke). The crank turns about the origin; the piston slides along +x,
    the cylinder head beyond it. ``friction``: the joints with friction (of :data:`JOINTS`);
    ``gas``: with the gas force; ``rigid_rod``: the rod as a rigid body of the same mass;
    ``speed``: the crank's initial speed [rad/s] (the rod and piston move with it)."""
    r, l = e["crank"], e["rod"]
    th0 = e["start_angle"]
    pin = (r * math.cos(th0), r * math.sin(th0))
    xp = pin[0] + math.sqrt(l * l - pin[1] ** 2)
    phi = math.atan2(-pin[1], xp - pin[0])
    # velocities of the slider-crank turning at `speed`
    w_rod = -r * math.cos(th0) * speed / (l * math.cos(phi))
    v_pin = (-pin[1] * speed, pin[0] * speed)
    v_piston = v_pin[0] + l * math.sin(phi) * -w_rod
    s = Scene(gravity=(0.0, -9.81))
    crank = s.rigid_body("crank", mass=e["crank_mass"], inertia=e["crank_inertia"], angle=th0, angular_velocity=speed)
    if rigid_rod:
        m_rod = e["density"] * math.pi * e["rod_diameter"] ** 2 / 4 * l
        rod = s.rigid_body("rod", mass=m_rod, inertia=m_rod * l * l / 12, com=(l / 2, 0.0), position=pin, angle=phi,
                           velocity=v_pin, angular_velocity=w_rod)
    else:
        rod = s.beam("rod", length=l, elements=elements, section=Circular(e["rod_diameter"]), density=e["density"],
                 youngs_modulus=e["youngs_modulus"], poisson_ratio=e["poisson_ratio"], shear_factor=e["shear_factor"],
                 strain="nonlinear", damping=e["rod_damping"], position=pin, angle=phi, velocity=v_pin,
                 angular_velocity=w_rod)
    piston = s.rigid_body("piston", mass=e["piston_mass"], inertia=1e-4, position=(xp, 0.0), velocity=(v_piston, 0.0))
    s.revolute(crank.point(0, 0), s.ground.point(0, 0), name="main")
    s.revolute(crank.point(r, 0), rod.point(0, 0) if rigid_rod else rod.at(0.0), name="crankpin")
    s.revolute(rod.point(l, 0) if rigid_rod else rod.at(1.0), piston.point(0, 0), name="pistonpin")
    s.prismatic(piston.point(0, 0), s.ground.point(0, 0), name="cylinder")
    s.motor(crank.frame(), dc_motor_torque(e["motor_k"], e["motor_r"], e["motor_v"]),
            rotor_inertia=e["rotor_inertia"], name="motor")
    if gas:
        theta, p = cylinder_pressure(e=e)
        area = math.pi * e["bore"] ** 2 / 4
        s.point_load(piston.point(0, 0), fx=LoadTable("crank.theta", theta, -(p - e["ambient"]) * area, period=4 * math.pi),
                     name="gas")
    kw = {} if v_eps is None else dict(v_eps=v_eps)
    for joint in friction:
        if joint == "cylinder":
            s.joint_friction(joint, mu=e["mu_cylinder"], name="cylinder_friction", **kw)
        else:
            s.joint_friction(joint, mu=e["mu_bearing"], radius=e[joint + "_radius"], name=f"{joint}_friction", **kw)
    return s


def motor_torque(w, e: Dict[str, Any] = ENGINE):
    """The DC motor's torque at the crank speed ``w`` (the law of :func:`engine_scene`'s motor)."""
    return e["motor_k"] * (e["motor_v"] - e["motor_k"] * np.asarray(w)) / e["motor_r"]


def cycle_work(e: Dict[str, Any] = ENGINE) -> float:
    """The gas work on the piston over one cycle [J], ``-oint (p - p_a) A dx_piston`` of the
    pressure table (trapezoid over its nodes): what the gas force's table does per 720 deg."""
    theta, p = cylinder_pressure(e=e)
    area = math.pi * e["bore"] ** 2 / 4
    travel = piston_travel(theta, e)
    return float(np.trapezoid((p - e["ambient"]) * area, travel))


def run(t_end: float = 1.0, samples_per_second: int = 20000, method: str = "auto", cycles: int = 2,
        e: Dict[str, Any] = ENGINE, **options: Any) -> Dict[str, Any]:
    """Run :func:`engine_scene` from rest to ``t_end`` and measure over its last ``cycles``
    whole cycles (720 deg each): the crank speed's mean (time and angle averages), its
    fluctuation ``(w_max - w_min) / w_mean``, the peak bearing forces (main bearing, crank pin,
    piston pin; the cylinder's side force), the rod's peak transverse midpoint deflection and
    its peak shortening, the motor's mean torque, the friction's mean torque and the torque
    balance's speed ``V/k + R/k^2 (T_gas - T_friction - dE/dtheta)`` (angle averages) against
    the run's; the energy balance. Returns the result too (``"result"``)."""
    te = np.linspace(0.0, t_end, int(round(t_end * samples_per_second)) + 1)
    system = engine_scene(e=e).build()
    t0 = time.perf_counter()
    res = simulate(system, t_end, method=method, t_eval=te, **options)
    wall = time.perf_counter() - t0
    th, w = res.coordinate("crank.theta"), res.velocity("crank.theta")
    # the last whole cycles: the crank angle's window [th_end - cycles 4 pi, th_end]
    win = th >= th[-1] - cycles * 4 * math.pi
    t_w = te[win]
    mean_t = float(np.trapezoid(w[win], t_w) / (t_w[-1] - t_w[0]))
    mean_angle = float(np.trapezoid(w[win] ** 2, t_w) / np.trapezoid(w[win], t_w))
    sens = res.sensors
    forces = {}
    for joint in JOINTS:
        r = sens.reaction(joint)
        forces[joint] = float(np.hypot(r["fx"], r["fy"])[win].max())
    _, v_mid = res.beam_displacement("rod", 0.5)
    u_end, _ = res.beam_displacement("rod", 1.0)
    u_start, _ = res.beam_displacement("rod", 0.0)
    shortening = np.asarray(u_start) - np.asarray(u_end)
    bal = sens.energy_balance()
    # the torque balance over the window (angle averages): motor + gas - friction = dE/dtheta
    d_theta = th[win][-1] - th[win][0]
    i0, i1 = np.flatnonzero(win)[[0, -1]]
    work_motor = float(np.trapezoid(motor_torque(w[win], e) * w[win], t_w))
    work_ext = float(bal["external_work"][i1] - bal["external_work"][i0])
    work_gas = work_ext - work_motor
    dissipated = float(bal["dissipated"][i1] - bal["dissipated"][i0])
    d_energy = float(bal["change"][i1] - bal["change"][i0])
    k, rr, v = e["motor_k"], e["motor_r"], e["motor_v"]
    w_balance = v / k + rr / k**2 * (work_gas - dissipated - d_energy) / d_theta
    return dict(
        result=res, wall=wall, method=res.method, auto=res.extra.get("auto", {}).get("options"),
        steps=res.extra.get("naccept"), rejected=res.extra.get("nreject"),
        w_mean_time=mean_t, w_mean_angle=mean_angle, fluctuation=float((w[win].max() - w[win].min()) / mean_t),
        w_min=float(w[win].min()), w_max=float(w[win].max()), w_no_load=v / k, w_balance=float(w_balance),
        forces=forces, deflection=float(np.abs(v_mid[win]).max()), shortening=float(shortening[win].max()),
        stretch=float(-shortening[win].min()),
        torque_motor=work_motor / d_theta, torque_gas=work_gas / d_theta, torque_friction=dissipated / d_theta,
        gas_per_cycle=work_gas / (d_theta / (4 * math.pi)), gas_table=cycle_work(e),
        balance=bal["relative_error"], window=(float(t_w[0]), float(t_w[-1])),
    )


def figure(out: Dict[str, Any], path: str, e: Dict[str, Any] = ENGINE) -> None:
    """Plot a :func:`run`: the crank speed from rest and the motor torque; over the last cycle
    against the crank angle, the gas force and the bearing forces, and the rod's midpoint
    deflection and shortening."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    res = out["result"]
    t, th, w = res.t, res.coordinate("crank.theta"), res.velocity("crank.theta")
    last = th >= th[-1] - 4 * math.pi
    # crank angle in the cycle, 0 at the firing top dead centre
    angle = np.degrees(np.mod(th[last] + math.pi, 4 * math.pi) - math.pi)
    order = np.argsort(angle)
    theta, p = cylinder_pressure(e=e)
    area = math.pi * e["bore"] ** 2 / 4
    gas = np.interp(np.radians(angle), theta, (p - e["ambient"]) * area)
    fig, axes = plt.subplots(3, 1, figsize=(7.5, 9.0))
    ax = axes[0]
    ax.plot(t, w, lw=1.0, label="crank speed")
    ax.axhline(out["w_no_load"], color="0.5", ls=":", lw=0.8, label="motor's no-load speed V/k")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("speed [rad/s]")
    ax2 = ax.twinx()
    ax2.plot(t, motor_torque(w, e), color="C3", lw=0.6, alpha=0.7)
    ax2.set_ylabel("motor torque [N m]", color="C3")
    ax.legend(loc="center right", fontsize=8)
    ax.set_title("single-cylinder four-stroke engine started by a DC motor (flexible rod, joint friction)", fontsize=9)
    ax = axes[1]
    ax.plot(angle[order], gas[order] / 1e3, "k", lw=1.0, label="gas force on the piston")
    for joint in ("main", "crankpin", "pistonpin", "cylinder"):
        r = res.sensors.reaction(joint)
        ax.plot(angle[order], np.hypot(r["fx"], r["fy"])[last][order] / 1e3, lw=0.8, label=f"{joint} reaction")
    ax.set_ylabel("force [kN]")
    ax.legend(fontsize=8)
    ax = axes[2]
    _, v_mid = res.beam_displacement("rod", 0.5)
    u0, _ = res.beam_displacement("rod", 0.0)
    u1, _ = res.beam_displacement("rod", 1.0)
    ax.plot(angle[order], 1e6 * np.asarray(v_mid)[last][order], lw=1.0, label="midpoint transverse deflection")
    ax.plot(angle[order], 1e6 * (np.asarray(u0) - np.asarray(u1))[last][order], lw=1.0, label="shortening")
    ax.set_xlabel("crank angle in the last cycle [deg] (0: firing top dead centre)")
    ax.set_ylabel("rod [um]")
    ax.legend(fontsize=8)
    for ax in axes[1:]:
        ax.set_xlim(-180, 540)
        ax.set_xticks(range(-180, 541, 90))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m studies engine", description=__doc__.split("\n\n")[0])
    parser.add_argument("--t-end", type=float, default=1.0, help="simulated time from rest [s] (default 1)")
    parser.add_argument("--method", default="auto", help="the integrator (default auto)")
    parser.add_argument("--figure", metavar="PNG", default=None, help="also plot the run into PNG")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    out = run(args.t_end, method=args.method)
    e = ENGINE
    print(f"engine: bore {e['bore'] * 1e3:.0f} mm, stroke {2 * e['crank'] * 1e3:.0f} mm, rod {e['rod'] * 1e3:.0f} mm "
          f"(steel, d = {e['rod_diameter'] * 1e3:.0f} mm, FFRF Timoshenko, 2 elements), compression ratio "
          f"{e['compression_ratio']:g}, peak pressure {cylinder_pressure(e=e)[1].max() / 1e5:.1f} bar")
    print(f"run: {out['method']} {out['auto'] or ''}, {out['steps']} steps ({out['rejected']} rejected), "
          f"simulate() {out['wall']:.2f} s for {args.t_end:g} s")
    print(f"last 2 cycles, t = {out['window'][0]:.4f} .. {out['window'][1]:.4f} s:\n")
    print("| quantity | value |\n|---|---:|")
    rows = [
        ("mean crank speed (time average) [rad/s]", f"{out['w_mean_time']:.2f}"),
        ("min / max crank speed [rad/s]", f"{out['w_min']:.2f} / {out['w_max']:.2f}"),
        ("speed fluctuation (max - min) / mean", f"{out['fluctuation']:.2%}"),
        ("motor's no-load speed V/k [rad/s]", f"{out['w_no_load']:.2f}"),
        ("mean torques (angle averages): motor / gas / friction [N m]",
         f"{out['torque_motor']:.3f} / {out['torque_gas']:.3f} / {out['torque_friction']:.3f}"),
        ("speed from the torque balance (angle average) [rad/s]", f"{out['w_balance']:.3f}"),
        ("mean crank speed (angle average) [rad/s]", f"{out['w_mean_angle']:.3f}"),
        ("gas work per cycle: run / pressure table [J]", f"{out['gas_per_cycle']:.2f} / {out['gas_table']:.2f}"),
        *[(f"peak reaction, {j} [N]", f"{f:.0f}") for j, f in out["forces"].items()],
        ("rod: peak midpoint transverse deflection [um]", f"{out['deflection'] * 1e6:.2f}"),
        ("rod: peak shortening / stretch [um]", f"{out['shortening'] * 1e6:.2f} / {out['stretch'] * 1e6:.2f}"),
        ("energy balance, whole run (relative error)", f"{out['balance']:.1e}"),
    ]
    for k, v in rows:
        print(f"| {k} | {v} |")
    if args.figure:
        figure(out, args.figure)
        print(f"\nwrote {args.figure}")
    print(f"\ntotal {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
