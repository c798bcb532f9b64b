"""The point-mass body kind and the distance joint (a massless rod), through the public API."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipk

import ukflex
from ukflex import Scene


def _pendulum(theta0, L=0.8, g=9.81, m=0.3):
    s = Scene(gravity=(0.0, -g))
    bob = s.point_mass("bob", mass=m, position=(L * math.sin(theta0), -L * math.cos(theta0)))
    s.distance(s.ground.point(0, 0), bob.point(), name="rod")
    return s


@pytest.mark.parametrize("theta0", [0.3, 1.2, math.pi / 2])
def test_mathematical_pendulum_has_the_elliptic_period(theta0):
    L, g = 0.8, 9.81
    system = _pendulum(theta0, L, g).build()
    assert system.n_coords == 2 and system.n_constraints == 1
    assert system.body_kind("bob") == "point_mass"
    # the rod length was taken from the initial guess
    assert system.description["joints"][0]["length"] == pytest.approx(L, rel=1e-15)

    def bottom(t, y):  # x = 0 going left: a quarter period after release from rest
        return y[0]

    bottom.terminal, bottom.direction = True, -1
    sol = solve_ivp(system.rhs, (0.0, 10.0), system.y0, method="DOP853", rtol=1e-12, atol=1e-14, events=bottom)
    period = 4.0 * sol.t_events[0][0]
    exact = 4.0 * math.sqrt(L / g) * ellipk(math.sin(theta0 / 2) ** 2)  # scipy: K(m), m = k^2
    assert abs(period - exact) / exact < 1e-8
    # constraint and energy on the way
    q, qd = sol.y[:2, -1], sol.y[2:, -1]
    assert abs(system.phi(0.0, q)[0]) < 1e-9
    assert system.energy(q, qd) == pytest.approx(system.energy(system.q0, system.qd0), abs=1e-9)


def test_point_mass_pinned_to_a_rigid_body_and_reactions():
    s = Scene(gravity=(0.0, -9.81))
    arm = s.rigid_body("arm", mass=1.0, inertia=1.0 / 12, com=(0.5, 0.0))
    bob = s.point_mass("bob", mass=0.5, position=(1.0, 0.0))
    s.revolute(s.ground.point(0, 0), arm.point(0, 0))
    s.revolute(arm.point(1.0, 0.0), bob.point())
    system = s.build()
    # the pair is one rigid pendulum: inertia about the pivot 1/3 + 0.5, weight moment at rest
    qdd = system.qdd(0.0, system.q0, system.qd0)
    theta_dd = qdd[system.coordinate_index("arm.theta")]
    assert theta_dd == pytest.approx(-9.81 * (1.0 * 0.5 + 0.5 * 1.0) / (1.0 / 3.0 + 0.5), rel=1e-12)


def test_point_mass_errors_are_named():
    s = Scene()
    bob = s.point_mass("bob", mass=1.0)
    arm = s.rigid_body("arm", mass=1.0, inertia=0.1)
    with pytest.raises(ukflex.InvalidSceneError, match="body 'p'.*mass"):
        s.point_mass("p", mass=0.0)
    with pytest.raises(ukflex.InvalidSceneError, match="joint weld.*point mass 'bob' has no orientation"):
        s.weld(arm.frame(), bob.point())
    with pytest.raises(ukflex.InvalidSceneError, match="driver angle.*no orientation"):
        s.angle_driver(bob.point(), ukflex.ConstantSpeed(1.0))
    with pytest.raises(ukflex.InvalidSceneError, match="force torque.*no orientation"):
        s.torque(bob.point(), 1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="particle itself"):
        s.revolute(arm.frame(), ukflex.Marker("bob", point=(0.1, 0.0)))
    with pytest.raises(ukflex.InvalidSceneError, match="joint distance.*length"):
        s.distance(arm.frame(), bob.point(), length=-1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="joint distance.*length"):
        s.distance(arm.frame(), bob.point())  # both at the origin: no length to take
    assert s.to_dict()["joints"] == [] and s.to_dict()["drivers"] == [] and s.to_dict()["forces"] == []


def test_distance_joint_holds_a_double_pendulum_of_particles():
    s = Scene(gravity=(0.0, -9.81))
    a = s.point_mass("a", mass=1.0, position=(0.5, 0.0))
    b = s.point_mass("b", mass=2.0, position=(0.5, -0.4))
    s.distance(s.ground.point(0, 0), a.point())
    s.distance(a.point(), b.point())
    system = s.build()
    res = ukflex.simulate(system, 1.0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=np.linspace(0, 1, 11))
    assert res.max_residual("position") < 1e-8
    e = res.energy()
    assert np.max(np.abs(e - e[0])) < 1e-7
