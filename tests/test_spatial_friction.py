"""Regularized Coulomb and viscous friction in spatial revolute, prismatic and spherical joints,
closed with the reactions (docs/loads.md, "Joint friction in spatial joints"), against closed
forms and an independent solution of the pendulum's equation."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ukflex
from ukflex import SpatialScene

G = 9.81
V_EPS = 1e-3  # the core's default


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def _omega(p, pd):
    """World angular velocity 2 E(p) pd of Euler parameters (rows of p, pd)."""
    e0, e1, e2, e3 = p.T
    E = np.array([[-e1, e0, -e3, e2], [-e2, e3, e0, -e1], [-e3, -e2, e1, e0]])  # 3 x 4 x nt
    return 2.0 * np.einsum("ijt,tj->ti", E, pd)


# -- revolute: a pendulum about an inclined axis with viscous friction ---------------------------
AXIS = _unit([0.5, -0.3, 0.6])            # the hinge axis, 44 degrees off vertical
M, L, J = 1.5, 0.4, 2e-3                   # mass, arm, the (isotropic) inertia about the c.o.m.


def _pendulum(theta0, damping, mu=0.0, radius=0.0):
    g = np.array([0.0, 0.0, -G])
    d0 = _unit(g - g.dot(AXIS) * AXIS)     # the hanging direction
    d1 = np.cross(AXIS, d0)
    s = SpatialScene(gravity=tuple(g))
    com = L * (math.cos(theta0) * d0 + math.sin(theta0) * d1)
    arm = s.rigid_body("arm", M, (J, J, J), com=tuple(com))
    s.revolute(s.ground.marker((0, 0, 0), z=tuple(AXIS)), arm.marker((0, 0, 0), z=tuple(AXIS)), name="hinge")
    s.joint_friction("hinge", mu=mu, radius=radius, damping=damping, name="friction")
    return s, d0, d1


def _angle(res, n, d0, d1):
    r = res.y[:3].T
    return np.arctan2(r @ d1, r @ d0)


def test_inclined_revolute_with_viscous_friction_decays_at_c_over_2_ip():
    # I_p th'' = -m g_perp L sin(th) - c th', I_p = J + m L^2, g_perp = g sin(beta): amplitude
    # envelope exp(-c t / (2 I_p)); the run against the same equation solved apart (DOP853)
    c, th0, T = 0.02, 0.05, 8.0
    s, d0, d1 = _pendulum(th0, c)
    system = ukflex.System(s)
    t = np.linspace(0.0, T, 1601)
    res = ukflex.simulate(system, T, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=t)
    assert res.success, res.message
    th = _angle(res, system.n_coords, d0, d1)
    ip = J + M * L * L
    gp = G * math.sqrt(1.0 - AXIS[2] ** 2)
    ref = solve_ivp(lambda t, y: [y[1], (-M * gp * L * math.sin(y[0]) - c * y[1]) / ip], (0, T), [th0, 0.0],
                    method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t)
    assert np.abs(th - ref.y[0]).max() < 1e-8
    # the decay rate from the peaks: log-amplitude slope -c / (2 I_p)
    k = np.flatnonzero((th[1:-1] > th[:-2]) & (th[1:-1] >= th[2:])) + 1
    rate = -np.polyfit(t[k], np.log(th[k]), 1)[0]
    assert len(k) >= 4
    assert rate == pytest.approx(c / (2.0 * ip), rel=2e-3)


def test_energy_balance_closes_with_the_viscous_dissipation():
    # E(0) - E(T) = int c w^2 dt, w = omega . axis (trapezoid on a fine output)
    c, T = 0.05, 1.5
    s, d0, d1 = _pendulum(1.2, c)
    system = ukflex.System(s)
    t = np.linspace(0.0, T, 6001)
    res = ukflex.simulate(system, T, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=t)
    n = system.n_coords
    q, qd = res.y[:n].T, res.y[n:].T
    w = _omega(q[:, 3:7], qd[:, 3:7]) @ AXIS
    v = np.linalg.norm(qd[:, :3], axis=1)
    kin = 0.5 * M * v ** 2 + 0.5 * J * (_omega(q[:, 3:7], qd[:, 3:7]) ** 2).sum(axis=1)
    energy = kin + M * G * q[:, 2]
    dissipated = np.trapezoid(c * w ** 2, t)
    assert dissipated > 0.3 * (energy[0] - energy.min())
    assert (energy[0] - energy[-1]) == pytest.approx(dissipated, rel=1e-5)


def test_energy_balance_of_the_sensors_counts_coulomb_and_viscous_friction():
    # the pin's Coulomb torque reads the reaction (gravity and the centripetal force): the
    # sensors' balance E(t) - E(0) + dissipated = 0 closes with the friction's power
    s, _, _ = _pendulum(1.2, 0.05, mu=0.3, radius=0.02)
    system = ukflex.System(s)
    t = np.linspace(0.0, 1.5, 3001)
    res = ukflex.simulate(system, 1.5, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=t)
    bal = res.sensors.energy_balance()
    assert bal["dissipated"][-1] > 0.5
    assert np.abs(bal["residual"]).max() < 1e-7 * bal["scale"]


@pytest.mark.parametrize("horizontal", [True, False])
def test_coulomb_pin_and_collar_spin_down_at_constant_rate(horizontal):
    # a disk spinning on its own axis through its c.o.m.: the reaction is its weight, radial
    # (horizontal axis: the pin, lever r) or axial (vertical axis: the collar, lever r_c); the
    # friction torque mu r m g is constant while it slides: w(t) = w0 - mu r m g t / J_axis
    axis = _unit([1.0, 0.5, 0.0]) if horizontal else np.array([0.0, 0.0, 1.0])
    ja, mu, r, rc, w0 = 0.01, 0.1, 0.02, 0.05, 8.0
    s = SpatialScene(gravity=(0.0, 0.0, -G))
    disk = s.rigid_body("disk", 2.0, (ja, ja, ja), angular_velocity=tuple(w0 * axis))
    s.revolute(s.ground.marker((0, 0, 0), z=tuple(axis)), disk.marker((0, 0, 0), z=tuple(axis)), name="hinge")
    s.joint_friction("hinge", mu=mu, radius=r, collar_radius=rc)
    system = ukflex.System(s)
    t = np.linspace(0.0, 0.5, 11)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-12, atol=1e-14, t_eval=t)
    n = system.n_coords
    w = _omega(res.y[3:7].T, res.y[n + 3:n + 7].T) @ axis
    lever = r if horizontal else rc
    # the run's own error (vertical axis: 8e-7 rad/s at rtol 1e-10, 5e-8 at 1e-12)
    np.testing.assert_allclose(w, w0 - mu * lever * 2.0 * G * t / ja, rtol=0, atol=1e-7)


# -- prismatic: a block on an incline, stick and slip ---------------------------------------------
def _incline(alpha, mu, v0=0.0, psi=0.7):
    # the slide axis points down an incline of angle alpha, at the azimuth psi
    down = np.array([math.cos(alpha) * math.cos(psi), math.cos(alpha) * math.sin(psi), -math.sin(alpha)])
    s = SpatialScene(gravity=(0.0, 0.0, -G))
    blk = s.rigid_body("blk", 2.0, (0.1, 0.2, 0.15), velocity=tuple(v0 * down))
    s.prismatic(s.ground.marker((0, 0, 0), z=tuple(down)), blk.marker((0, 0, 0), z=tuple(down)), name="slide")
    s.joint_friction("slide", mu=mu, name="friction")
    return s, down


@pytest.mark.parametrize("ratio", [0.5, 0.99, 1.01, 2.0])
def test_block_on_a_spatial_incline_sticks_below_and_slides_above_the_threshold(ratio):
    # tan(alpha) = ratio mu; the normal force across the axis is m g cos(alpha)
    mu = 0.4
    alpha = math.atan(ratio * mu)
    s, down = _incline(alpha, mu)
    system = ukflex.System(s)
    t = np.linspace(0.0, 0.5, 11)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    n = system.n_coords
    v = res.y[n:n + 3].T @ down
    v_inf, tau = V_EPS * ratio, V_EPS / (mu * G * math.cos(alpha))
    if ratio < 1.0:
        assert np.all(np.abs(v) <= V_EPS)
        np.testing.assert_allclose(v[1:], v_inf, rtol=1e-7)
    else:
        a = G * (math.sin(alpha) - mu * math.cos(alpha))
        t1 = -tau * math.log(1.0 - 1.0 / ratio)
        np.testing.assert_allclose(v[1:], V_EPS + a * (t[1:] - t1), rtol=1e-7)
        assert a > 0.0 and v[-1] > 10 * V_EPS


# -- spherical: spin-down of a ball about any axis ------------------------------------------------
def test_spherical_joint_friction_spins_a_ball_down():
    # a ball on its centre, spinning about an oblique axis: the reaction is its weight, the
    # torque mu r m g + c |w| about the spin axis, the axis stays put (isotropic inertia):
    # J w' = -mu r m g - c w
    axis = _unit([0.2, 0.9, 0.4])
    ja, m, mu, r, c, w0 = 0.02, 3.0, 0.1, 0.03, 0.01, 4.0
    s = SpatialScene(gravity=(0.0, 0.0, -G))
    ball = s.rigid_body("ball", m, (ja, ja, ja), angular_velocity=tuple(w0 * axis))
    s.spherical(s.ground.marker((0, 0, 0)), ball.marker((0, 0, 0)), name="ball_joint")
    s.joint_friction("ball_joint", mu=mu, radius=r, damping=c)
    system = ukflex.System(s)
    t = np.linspace(0.0, 0.5, 11)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    n = system.n_coords
    w = _omega(res.y[3:7].T, res.y[n + 3:n + 7].T)
    k = mu * r * m * G / c
    np.testing.assert_allclose(w @ axis, (w0 + k) * np.exp(-c * t / ja) - k, rtol=1e-8)
    assert np.abs(w - np.outer(w @ axis, axis)).max() < 1e-9


def test_bad_input_is_named():
    def scene():
        s = SpatialScene()
        arm = s.rigid_body("arm", 1.0, (0.1, 0.1, 0.1))
        blk = s.rigid_body("blk", 1.0, (0.1, 0.1, 0.1), position=(1.0, 0.0, 0.0))
        ball = s.rigid_body("ball", 1.0, (0.1, 0.1, 0.1), position=(2.0, 0.0, 0.0))
        cup = s.rigid_body("cup", 1.0, (0.1, 0.1, 0.1), position=(3.0, 0.0, 0.0))
        s.revolute(s.ground.marker((0, 0, 0)), arm.marker((0, 0, 0)), name="pin")
        s.prismatic(s.ground.marker((1, 0, 0)), blk.marker((0, 0, 0)), name="slide")
        s.spherical(s.ground.marker((2, 0, 0)), ball.marker((0, 0, 0)), name="ball_joint")
        s.universal(s.ground.marker((3, 0, 0)), cup.marker((0, 0, 0), x=(0, 1, 0)), name="cross")
        return s

    bad = [
        (dict(joint="pin", mu=-0.1, radius=0.01), "mu must be >= 0"),
        (dict(joint="pin", mu=float("nan"), radius=0.01), "mu must be (>= 0 and )?finite"),
        (dict(joint="pin", mu=0.1, radius=-0.01), "radius must be >= 0"),
        (dict(joint="pin", mu=0.1, radius=0.01, collar_radius=-1.0), "collar_radius must be >= 0"),
        (dict(joint="pin", mu=0.1, radius=float("nan")), "radius must be (>= 0 and )?finite"),
        (dict(joint="pin", mu=0.1), "the pin radius"),
        (dict(joint="pin", mu=0.1, radius=0.01, damping=-1.0), "damping must be >= 0"),
        (dict(joint="pin", mu=0.1, radius=0.01, damping=float("nan")), "damping must be (>= 0 and )?finite"),
        (dict(joint="pin", mu=0.1, radius=0.01, v_eps=0.0), "v_eps must be positive"),
        (dict(joint="slide", mu=0.1, radius=0.01), "'slide' is a spatial prismatic joint"),
        (dict(joint="ball_joint", mu=0.1), "the ball radius"),
        (dict(joint="ball_joint", mu=0.1, radius=0.01, collar_radius=0.1), "'ball_joint' is a spatial spherical joint"),
        (dict(joint="cross", mu=0.1, radius=0.01), "revolute, prismatic and spherical joints; 'cross' is a spatial universal joint"),
    ]
    for kw, msg in bad:
        s = scene()
        s.joint_friction(**kw)
        with pytest.raises(ukflex.InvalidSceneError, match=msg):
            ukflex.System(s)
    s = scene()
    s.joint_friction("hinge", mu=0.1, radius=0.01)
    with pytest.raises(ukflex.UnknownNameError, match="'hinge'"):
        ukflex.System(s)
