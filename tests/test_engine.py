"""The engine example (docs/loads.md, "The engine example"; ``studies/engine.py``): a
single-cylinder four-stroke engine with a flexible connecting rod, a gas-force table, joint
friction in its four joints and a DC motor, on short windows against closed forms."""

import math

import numpy as np
import pytest

import ukflex
from studies.engine import ENGINE, cycle_work, cylinder_pressure, engine_scene, piston_travel


def test_pressure_table_is_the_single_zone_model():
    theta, p = cylinder_pressure()
    e = ENGINE
    area = math.pi * e["bore"] ** 2 / 4
    vc = area * 2 * e["crank"] / (e["compression_ratio"] - 1)
    # before the burn starts (-15 deg) the compression is polytropic: p V^gamma constant
    closed = (theta > -math.pi) & (theta < math.radians(e["burn_start"]))
    v = vc + area * piston_travel(theta)
    np.testing.assert_allclose(p[closed] * v[closed] ** e["gamma"], e["ambient"] * v[0] ** e["gamma"], rtol=1e-9)
    # the burn raises the pressure after the firing top dead centre; after the blowdown,
    # exhaust and intake at ambient
    assert 0.0 < theta[np.argmax(p)] < math.radians(30) and 25e5 < p.max() < 45e5
    assert np.all(p[theta >= math.radians(e["exhaust_opens"] + e["blowdown"])] == e["ambient"])
    assert np.all(np.diff(p[theta >= math.radians(e["exhaust_opens"])]) <= 0.0)
    # the cycle does positive work (a firing engine), below the heat released
    assert 0.3 * e["heat"] < cycle_work() < 0.6 * e["heat"]


def test_engine_at_speed_closes_the_torque_and_energy_balance():
    """Started at 337 rad/s (near its steady speed), over the last whole cycle (720 deg) of a
    0.06 s run with method="auto": the angle average of the crank speed equals the DC motor's
    torque balance ``w = V/k + R/k^2 (T_gas - T_friction - dE/dtheta)`` with the gas torque from
    the pressure table's cycle work (independent of the run), the friction's mean torque and the
    change of kinetic and elastic energy from the run's sensors (the speed still settles: the
    motor's time constant is 0.1 s; ``python -m studies engine`` shows the steady state). The
    energy balance (motor work + gas work = kinetic + elastic + potential + dissipated) closes."""
    e = ENGINE
    t_end = 0.06
    te = np.linspace(0.0, t_end, 2401)
    res = ukflex.simulate(engine_scene(speed=337.0).build(), t_end, t_eval=te)
    assert res.status == 0 and res.extra["auto"]["method"] == "RADAU5M"
    th, w = res.coordinate("crank.theta"), res.velocity("crank.theta")
    bal = res.sensors.energy_balance()
    assert bal["relative_error"] < 1e-4
    # over exactly one cycle, th_end - 4 pi .. th_end (the cumulative quantities interpolated
    # in the crank angle, which grows monotonically)
    start = th[-1] - 4 * math.pi
    assert start > th[0]

    def over_cycle(x):
        return x[-1] - np.interp(start, th, x)

    friction = over_cycle(bal["dissipated"]) / (4 * math.pi)
    d_energy = over_cycle(bal["change"]) / (4 * math.pi)
    w_dtheta = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] ** 2 + w[:-1] ** 2) * np.diff(te))])
    w_angle = over_cycle(w_dtheta) / (4 * math.pi)
    k, r, v = e["motor_k"], e["motor_r"], e["motor_v"]
    gas = cycle_work() / (4 * math.pi)
    assert 0.5 < friction < 2.0 and gas > 5.0
    assert w_angle == pytest.approx(v / k + r / k**2 * (gas - friction - d_energy), rel=1e-4)
    # the motor generates: the engine fires, its speed is above the motor's no-load speed
    assert w_angle > v / k


def test_engine_from_rest_runs_with_the_default_method():
    """From rest every joint is in its friction ramp: the ramp's damping at the rod's pins acts
    on the rod's end rotations (a stiff real eigenvalue of -7e6 1/s and more where the gas
    force loads them, docs/loads.md). method="auto" takes RADAU5M (L-stable), not an explicit
    method, and the first 0.01 s take a few hundred steps."""
    res = ukflex.simulate(engine_scene().build(), 0.01)
    assert res.status == 0 and res.extra["auto"]["method"] == "RADAU5M"
    assert res.extra["naccept"] + res.extra["nreject"] < 2000
    assert res.velocity("crank.theta")[-1] > 20.0
