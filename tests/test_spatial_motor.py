"""Motors in 3D and the spatial point quantities as load inputs (issue 32; docs/loads.md,
"Motors in 3D", "Point quantities in 3D"): ``SpatialScene.motor`` on a revolute about a tilted
axis against the DC motor's closed form and the PI controller's, a spatial slider-crank started
from rest by a DC motor, a linear motor on a prismatic joint, a mass hanging on a load written
from ``z(mass)`` and ``d:z(mass)``, and the named errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ukflex
from ukflex.model.scene import dc_motor_torque
from ukflex.model.spatial import SpatialBodyRef, SpatialScene
from ukflex.model.spatial_scenes import slider_crank

E = np.array([1.0, 2.0, 2.0]) / 3.0  # the tilted axis


def _frame(z):
    """A rotation matrix whose third column is ``z``."""
    z = np.asarray(z, float) / np.linalg.norm(z)
    x = np.cross([0.0, 1.0, 0.0], z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _flywheel(torque, J, Jr=0.0, joint="revolute", **kw):
    """A flywheel (``J`` about its axis, ``J / 2`` across) on a revolute (or cylindrical joint:
    it slides down the axis under gravity) about ``E``."""
    s = SpatialScene(gravity=(0.0, 0.0, -9.81))
    w = s.rigid_body("wheel", 3.0, [J / 2, J / 2, J], position=0.2 * E, orientation=_frame(E))
    # the markers' x axes agree at the start: the motor's angle starts at 0
    getattr(s, joint)(w.marker((0, 0, 0)), s.ground.marker(0.2 * E, z=E, x=_frame(E)[:, 0]), name="hinge")
    s.motor("hinge", torque, rotor_inertia=Jr, **kw)
    return ukflex.System(s)


def _speed(res):
    return res.sensors.body("wheel")["omega"] @ E


def test_dc_motor_spins_a_flywheel_on_a_tilted_axis_up_as_the_closed_form():
    """``tau = k (V - k w) / R`` with the rotor inertia: ``w = V/k (1 - exp(-t k^2 / ((J + J_r) R)))``;
    the motor's work closes the energy balance."""
    k, R, V, J, Jr = 0.05, 0.8, 12.0, 0.02, 0.004
    system = _flywheel(dc_motor_torque(k, R, V), J, Jr)
    t = np.linspace(0.0, 40.0, 801)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    exact = V / k * (1.0 - np.exp(-t * k**2 / ((J + Jr) * R)))
    err = np.max(np.abs(_speed(res) - exact)) / (V / k)
    assert err < 1e-7, err
    # no spin across the axis
    assert np.max(np.abs(np.cross(res.sensors.body("wheel")["omega"], E))) < 1e-7 * V / k
    bal = res.sensors.energy_balance()
    assert bal["relative_error"] < 1e-6, bal["relative_error"]
    assert bal["external_work"][-1] > 0.5 * 0.5 * (J + Jr) * (V / k) ** 2


@pytest.mark.parametrize("joint, method", [("revolute", "DOPRI5"), ("cylindrical", "DOPRI5"), ("revolute", "RADAU5M")])
def test_pi_speed_controller_as_an_expression_on_a_tilted_axis(joint, method):
    """``tau = Kp (w_ref - w) + Ki (w_ref t - angle)``: the angle, counted over the turns, is the
    integral of the speed; ``e = w_ref t - angle`` obeys ``J e'' + Kp e' + Ki e = 0``. RADAU5M's
    Newton matrices take the motor's analytic ``K`` (measured 1.5e-8 at rtol 1e-8)."""
    J, Kp, Ki, wr = 0.05, 0.4, 2.0, 30.0
    system = _flywheel(f"{Kp} * ({wr} - w) + {Ki} * ({wr} * t - angle)", J, joint=joint)
    t = np.linspace(0.0, 2.0, 401)  # 30 rad/s: samples well within half a turn (the sensors count turns)
    rtol = 1e-10 if method == "DOPRI5" else 1e-8
    res = ukflex.simulate(system, t[-1], method=method, rtol=rtol, atol=rtol * 1e-2, t_eval=t)
    sigma, wd = Kp / (2 * J), math.sqrt(Ki / J - (Kp / (2 * J)) ** 2)
    e_dot = wr * np.exp(-sigma * t) * (np.cos(wd * t) - sigma / wd * np.sin(wd * t))
    assert np.max(np.abs(_speed(res) - (wr - e_dot))) < 1e-6 * wr
    # nine turns: the counted angle went on past +-pi
    assert np.trapezoid(_speed(res), t) > 6 * math.pi
    assert res.sensors.energy_balance()["relative_error"] < 1e-6


def test_dc_motor_starts_the_spatial_slider_crank_from_rest_to_its_steady_speed():
    """The spatial slider-crank at rest, its crank driven by a DC motor (rotor inertia on the
    crank), a viscous load on the slider: over the last two revolutions the motor's work equals
    the damper's plus the change of kinetic energy, and the mean speed has settled."""
    s = slider_crank(omega=0.0)
    k, R, V, c = 0.1, 1.0, 3.0, 2.0
    s.motor("crank_ground", dc_motor_torque(k, R, V), rotor_inertia=5e-4, name="motor")
    s.point_load(SpatialBodyRef("slider").marker(), [f"-{c} * d:slider.x", 0, 0], name="damper")
    system = ukflex.System(s)
    t = np.linspace(0.0, 6.0, 3001)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-9, atol=1e-11, t_eval=t)
    sens = res.sensors
    # the ground is the joint's marker a: the crank turns at -w about world x
    w = -sens.body("crank")["omega"][:, 0]
    v = sens.body("slider")["velocity"][:, 0]
    assert w[0] == 0.0 and np.all(np.isfinite(w))
    theta = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t))])
    last = theta >= theta[-1] - 4 * math.pi
    tl, wl = t[last], w[last]
    p_motor = np.trapezoid(k * (V - k * wl) / R * wl, tl)
    p_damper = np.trapezoid(c * v[last] ** 2, tl)
    kinetic = sens.energies()["kinetic"][last]
    grav = sens.energies()["gravity"][last]
    balance = p_motor - p_damper - (kinetic[-1] - kinetic[0]) - (grav[-1] - grav[0])
    assert abs(balance) < 1e-6 * p_motor, (balance, p_motor)  # measured 4.8e-9
    # the mean speed of the last revolution (2 pi over its duration) equals the one before's
    t0, t1, t2 = np.interp(theta[-1] - np.array([4, 2, 0]) * math.pi, theta, t)
    w1, w2 = 2 * math.pi / (t1 - t0), 2 * math.pi / (t2 - t1)
    assert abs(w1 - w2) < 1e-5 * w2 and w2 > 0.5 * V / k, (w1, w2)  # measured 7.5e-8
    assert res.sensors.energy_balance()["relative_error"] < 1e-6


def test_linear_motor_on_a_prismatic_joint():
    """A force ``F0 (1 - v / v0)`` along a tilted slide on a mass ``m``: ``v = v0 (1 - exp(-F0 t / (m v0)))``."""
    m, F0, v0 = 2.0, 4.0, 3.0
    s = SpatialScene()
    b = s.rigid_body("cart", m, [0.1, 0.1, 0.1], orientation=_frame(E))
    s.prismatic(b.marker((0, 0, 0)), s.ground.marker((0, 0, 0), z=E), name="slide")
    s.motor("slide", f"{F0} * (1 - v / {v0})")
    t = np.linspace(0.0, 3.0, 151)  # the balance integrates the motor's power over the samples
    res = ukflex.simulate(ukflex.System(s), t[-1], method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    v = res.sensors.body("cart")["velocity"] @ E
    assert np.max(np.abs(v - v0 * (1 - np.exp(-F0 * t / (m * v0))))) < 1e-8 * v0
    assert res.sensors.energy_balance()["relative_error"] < 1e-6


def test_mass_hanging_on_a_load_of_its_height_has_the_closed_form_frequency_and_decay():
    """A point mass under gravity held by ``F_z = -k (z(m) - z0) - c d:z(m)`` (a spring and a
    damper written from the point quantities): ``z - z_eq = A exp(-zeta w0 t) cos(w_d t)``."""
    m, k, c, g, z0, a0 = 0.5, 80.0, 0.4, 9.81, 1.0, 0.02
    s = SpatialScene(gravity=(0.0, 0.0, -g))
    z_eq = z0 - m * g / k
    mass = s.point_mass("m", m, position=(0.3, -0.2, z_eq + a0))
    s.point_load(mass.marker(), [0, 0, f"-{k} * (z(m) - {z0}) - {c} * d:z(m)"])
    t = np.linspace(0.0, 3.0, 301)
    for method in ("DOPRI5", "RADAU5M"):
        res = ukflex.simulate(ukflex.System(s), t[-1], method=method, rtol=1e-10, atol=1e-12, t_eval=t)
        w0, zeta = math.sqrt(k / m), c / (2 * math.sqrt(k * m))
        wd = w0 * math.sqrt(1 - zeta**2)
        exact = z_eq + a0 * np.exp(-zeta * w0 * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * t))
        assert np.max(np.abs(res.q[2] - exact)) < 1e-7 * a0, method  # measured 1.3e-9, 8.7e-13


def test_point_quantities_of_a_body_point():
    """``x(B, [sx, sy, sz])`` reads a body-fixed point (its frame's origin plus ``s`` in body
    axes), ``d:y(B)`` and ``z(B)`` the reference point's velocity and position."""
    s = SpatialScene()
    b = s.rigid_body("b", 1.0, [0.1, 0.2, 0.3], orientation=_frame(E), position=(0.1, 0.2, 0.3))
    s.point_load(b.marker(), ["x(b, [0.1, 0, 0]) + 2 * d:y(b)", 0, "z(b)"])
    system = ukflex.System(s)
    q, qd = system.q0.copy(), system.qd0.copy()
    qd[1] = 0.7
    # a point 0.1 along the body's x: P = r + 0.1 x_body
    expected = 0.1 + 0.1 * _frame(E)[0, 0] + 1.4
    acc = system.qdd(0.0, q, qd)
    assert abs(acc[0] - expected) < 1e-12 and abs(acc[2] - 0.3) < 1e-12


@pytest.mark.parametrize("item, match", [
    (dict(joint="nope", torque=1.0), "nope"),
    (dict(joint="ball", torque=1.0), "no such axis"),
    (dict(joint="hinge", torque=1.0, rotor_inertia=-1.0), "rotor_inertia"),
    (dict(joint="hinge", torque=1.0, rotor_inertia=float("nan")), "rotor_inertia"),
    (dict(joint="hinge", torque=float("nan")), "torque"),
    (dict(joint="hinge", torque="3 * s"), "unknown state quantity 's'"),
    (dict(joint="slide", torque=1.0, rotor_inertia=0.1), "linear motor"),
])
def test_motor_errors_are_named(item, match):
    s = SpatialScene()
    a = s.rigid_body("a", 1.0, [0.1, 0.1, 0.1])
    b = s.rigid_body("b", 1.0, [0.1, 0.1, 0.1], position=(1, 0, 0))
    c = s.rigid_body("c", 1.0, [0.1, 0.1, 0.1], position=(2, 0, 0))
    s.revolute(a.marker(), s.ground.marker(), name="hinge")
    s.spherical(b.marker(), s.ground.marker((1, 0, 0)), name="ball")
    s.prismatic(c.marker(), s.ground.marker((2, 0, 0)), name="slide")
    s.motor(**item)
    with pytest.raises((ukflex.InvalidSceneError, ukflex.ExpressionError, ukflex.UnknownNameError), match=match):
        ukflex.System(s)


def test_motor_from_a_description_dict():
    """A scene dict with ``"dim": 3`` takes the motor (a scene file's ``[[forces]]`` entry)."""
    s = SpatialScene.from_dict({"dim": 3, "bodies": [{"kind": "rigid3", "name": "w", "mass": 1.0, "inertia": [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.2]]}],
                                "joints": [{"kind": "revolute", "name": "h", "a": {"body": "w"}, "b": {"body": "ground"}}],
                                "forces": [{"kind": "motor", "joint": "h", "torque": "0.4", "rotor_inertia": 0.2}]})
    res = ukflex.simulate(ukflex.System(s), 1.0, method="DOPRI5", rtol=1e-10, t_eval=[0.0, 1.0])
    assert abs(res.sensors.body("w")["omega"][-1, 2] - 0.4 / 0.4) < 1e-9


def test_beam_node_position_is_spelled_as_a_point_quantity():
    """``z(a[1])`` is the node's position, the coordinate ``a[1].z`` (which an expression cannot
    spell); ``d:z(a[1])`` its rate. An unknown body in a point quantity is named."""
    def scene(load):
        s = SpatialScene()
        sec = ukflex.CustomSection3(ea=1e6, ga_y=1e6, ga_z=1e6, gj=1e3, ei_y=1e3, ei_z=1e3, mass_per_length=1.0,
                                    rotary_inertia=(2.0, 1.0, 1.0))
        a = s.beam("a", (0, 0, 0), (1, 0, 0), sec, elements=2)
        s.fixed(s.ground.marker((0, 0, 0)), a.node(0))
        s.point_load(a.node(-1), [0, 0, load])
        return ukflex.System(s)

    plain = scene(0.0)
    spelled = scene("-3e4 * z(a[1]) - 20 * d:z(a[1]) + 5 * x(a[2])")
    names = list(plain.coordinate_names)
    iz, ix = names.index("a[1].z"), names.index("a[2].x")
    q, qd = plain.q0.copy(), np.zeros(len(plain.q0))
    q[iz], qd[iz] = 0.01, 0.3
    # the load at the end node: the difference of the accelerations is its force over the node's
    # mass block, i.e. the same as a constant load of the value the expression takes
    value = -3e4 * 0.01 - 20 * 0.3 + 5 * q[ix]
    np.testing.assert_allclose(spelled.qdd(0.0, q, qd), scene(value).qdd(0.0, q, qd), rtol=1e-12, atol=1e-9)
    with pytest.raises(ukflex.InvalidSceneError, match="nobody"):
        scene("z(nobody)")


def test_scipy_runs_count_the_motor_angle_from_their_start():
    """The counted angle lives in the System's workspace; a scipy run (through ``System.rhs``)
    restarts it, so a second run on the same System is the first's (as a native run is)."""
    system = _flywheel("0.4 * (30 - w) + 2.0 * (30 * t - angle)", 0.05)
    t = np.linspace(0.0, 2.0, 201)
    runs = [_speed(ukflex.simulate(system, 2.0, method=m, rtol=1e-8, atol=1e-10, t_eval=t)) for m in ("RK45", "RK45", "DOPRI5")]
    np.testing.assert_array_equal(runs[0], runs[1])
    assert np.max(np.abs(runs[0] - runs[2])) < 1e-4 * 30


def test_motor_and_point_quantities_from_a_scene_file():
    """A TOML scene file with ``dim = 3`` takes a motor and a load reading point quantities: the
    DC motor's closed form at 2 s (rotor inertia included)."""
    from ukflex.model.scenefile import loads

    text = """dim = 3
[[bodies]]
kind = "rigid3"
name = "wheel"
mass = 2.0
inertia = [0.05, 0.05, 0.1]
[[joints]]
kind = "revolute"
name = "hinge"
a = { body = "wheel" }
b = { body = "ground" }
[[forces]]
kind = "motor"
joint = "hinge"
torque = "0.05 * (12 - 0.05 * w) / 0.8"
rotor_inertia = 0.01
[[forces]]
kind = "point_load"
point = { body = "wheel" }
force = [0.0, 0.0, "-10 * z(wheel) - 0.1 * d:z(wheel)"]
"""
    res = ukflex.simulate(ukflex.System(loads(text).scene), 2.0, method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=[0.0, 2.0])
    exact = 12 / 0.05 * (1 - math.exp(-2.0 * 0.05**2 / ((0.1 + 0.01) * 0.8)))
    assert abs(res.sensors.body("wheel")["omega"][-1, 2] - exact) < 1e-8 * exact
